//! [`Query`]: one texture lookup as a rasterizer issues it.

/// A texture coordinate and its screen-space derivatives (SPEC.md
/// "Coordinates").
///
/// `(u, v)` are normalized: texel `(i, j)` of a `w × h` level has its centre
/// at `((i + 0.5) / w, (j + 0.5) / h)`, row 0 at `v = 0`. The derivatives
/// are in normalized units per pixel: `(dudx, dvdx)` is the change of the
/// coordinate from one pixel to the next along screen x, `(dudy, dvdy)`
/// along screen y. Any value may be NaN or infinite; every filter defines
/// what it does then (see the [`crate::sample`] module docs).
///
/// `repr(C)`: six `f32` in field order, so a slice of queries can be read
/// as a flat array of floats (the SIMD paths load eight queries at once).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[repr(C)]
pub struct Query {
    /// Horizontal texture coordinate.
    pub u: f32,
    /// Vertical texture coordinate (0 = first row).
    pub v: f32,
    /// ∂u/∂x: change of u per pixel along screen x.
    pub dudx: f32,
    /// ∂v/∂x: change of v per pixel along screen x.
    pub dvdx: f32,
    /// ∂u/∂y: change of u per pixel along screen y.
    pub dudy: f32,
    /// ∂v/∂y: change of v per pixel along screen y.
    pub dvdy: f32,
}

impl Query {
    /// A query from its six numbers, in the CLI's order.
    pub const fn new(u: f32, v: f32, dudx: f32, dvdx: f32, dudy: f32, dvdy: f32) -> Self {
        Query {
            u,
            v,
            dudx,
            dvdx,
            dudy,
            dvdy,
        }
    }

    /// A point lookup: zero derivatives (always magnification).
    pub const fn point(u: f32, v: f32) -> Self {
        Query::new(u, v, 0.0, 0.0, 0.0, 0.0)
    }

    /// An axis-aligned isotropic footprint: `d` in u per pixel along x and
    /// `d` in v per pixel along y.
    pub const fn isotropic(u: f32, v: f32, d: f32) -> Self {
        Query::new(u, v, d, 0.0, 0.0, d)
    }

    /// The same query with `(u, v)` replaced.
    pub const fn at(mut self, u: f32, v: f32) -> Self {
        self.u = u;
        self.v = v;
        self
    }
}
