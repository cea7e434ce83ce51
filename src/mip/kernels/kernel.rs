//! Reconstruction kernels for downsampling, behind one interface: a radius
//! (support in source texels at scale 1) and a pointwise evaluation.
//!
//! Box is special: its weights are the exact overlap areas of source texels
//! with the destination footprint (see [`crate::mip::weights`]), which yields the
//! 2×2 average for even sizes and the polyphase 3-tap box for odd sizes. Its
//! `evaluate` is still provided so the interface is uniform.

use std::f64::consts::PI;

/// A separable, symmetric filter kernel.
pub trait Kernel {
    /// Half-width of the support at scale 1 (`evaluate` is 0 beyond it).
    fn radius(&self) -> f64;
    /// Kernel value at offset `x` (in source texels at scale 1).
    fn evaluate(&self, x: f64) -> f64;
}

/// sin(πx)/(πx), 1 at 0.
pub fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-9 {
        1.0
    } else {
        let px = PI * x;
        px.sin() / px
    }
}

/// Modified Bessel function of the first kind, order 0 (power series; the
/// terms fall fast for the arguments Kaiser uses, |x| ≤ 4).
pub fn bessel_i0(x: f64) -> f64 {
    let mut sum = 1.0;
    let mut term = 1.0;
    let q = x * x / 4.0;
    for k in 1..64 {
        term *= q / (k * k) as f64;
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
    }
    sum
}

/// Unit box on (−½, ½).
#[derive(Clone, Copy, Debug)]
pub struct BoxKernel;
impl Kernel for BoxKernel {
    fn radius(&self) -> f64 {
        0.5
    }
    fn evaluate(&self, x: f64) -> f64 {
        if x.abs() < 0.5 { 1.0 } else { 0.0 }
    }
}

/// Tent 1 − |x| on (−1, 1).
#[derive(Clone, Copy, Debug)]
pub struct Triangle;
impl Kernel for Triangle {
    fn radius(&self) -> f64 {
        1.0
    }
    fn evaluate(&self, x: f64) -> f64 {
        (1.0 - x.abs()).max(0.0)
    }
}

/// Kaiser-windowed sinc with NVIDIA texture tools' defaults.
#[derive(Clone, Copy, Debug)]
pub struct Kaiser {
    /// Half-width of the window (3).
    pub width: f64,
    /// Window shape (4).
    pub alpha: f64,
    /// Sinc stretch (1).
    pub stretch: f64,
}
impl Default for Kaiser {
    fn default() -> Self {
        Kaiser {
            width: 3.0,
            alpha: 4.0,
            stretch: 1.0,
        }
    }
}
impl Kernel for Kaiser {
    fn radius(&self) -> f64 {
        self.width
    }
    fn evaluate(&self, x: f64) -> f64 {
        let t = x / self.width;
        if t.abs() >= 1.0 {
            return 0.0;
        }
        sinc(x * self.stretch) * bessel_i0(self.alpha * (1.0 - t * t).sqrt())
            / bessel_i0(self.alpha)
    }
}

/// Lanczos with three lobes: sinc(x)·sinc(x/3) on (−3, 3).
#[derive(Clone, Copy, Debug)]
pub struct Lanczos3;
impl Kernel for Lanczos3 {
    fn radius(&self) -> f64 {
        3.0
    }
    fn evaluate(&self, x: f64) -> f64 {
        if x.abs() >= 3.0 {
            0.0
        } else {
            sinc(x) * sinc(x / 3.0)
        }
    }
}

/// Mitchell–Netravali cubic with B = C = 1/3.
#[derive(Clone, Copy, Debug)]
pub struct Mitchell {
    /// B parameter (1/3).
    pub b: f64,
    /// C parameter (1/3).
    pub c: f64,
}
impl Default for Mitchell {
    fn default() -> Self {
        Mitchell {
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        }
    }
}
impl Kernel for Mitchell {
    fn radius(&self) -> f64 {
        2.0
    }
    fn evaluate(&self, x: f64) -> f64 {
        let (b, c) = (self.b, self.c);
        let x = x.abs();
        let v = if x < 1.0 {
            (12.0 - 9.0 * b - 6.0 * c) * x * x * x
                + (-18.0 + 12.0 * b + 6.0 * c) * x * x
                + (6.0 - 2.0 * b)
        } else if x < 2.0 {
            (-b - 6.0 * c) * x * x * x
                + (6.0 * b + 30.0 * c) * x * x
                + (-12.0 * b - 48.0 * c) * x
                + (8.0 * b + 24.0 * c)
        } else {
            0.0
        };
        v / 6.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_integrate_to_one() {
        let ks: [&dyn Kernel; 5] = [
            &BoxKernel,
            &Triangle,
            &Kaiser::default(),
            &Lanczos3,
            &Mitchell::default(),
        ];
        for k in ks {
            // Midpoint rule over the support.
            let n = 200_000;
            let r = k.radius();
            let h = 2.0 * r / n as f64;
            let s: f64 = (0..n)
                .map(|i| k.evaluate(-r + (i as f64 + 0.5) * h) * h)
                .sum();
            // Kaiser is a windowed sinc: its integral is close to, not
            // exactly, 1 (the weights are normalised per texel anyway).
            assert!((s - 1.0).abs() < 0.02, "integral {s}");
        }
    }

    #[test]
    fn bessel_matches_known_values() {
        assert!((bessel_i0(0.0) - 1.0).abs() < 1e-15);
        assert!((bessel_i0(1.0) - 1.266_065_877_752_008_4).abs() < 1e-13);
        assert!((bessel_i0(4.0) - 11.301_921_952_136_33).abs() < 1e-11);
    }
}
