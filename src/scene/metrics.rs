//! Accuracy metrics over images of linear-light RGBA results (SPEC.md,
//! "Scenes, raster orders and the reference image": R, G, B only).

/// Root-mean-square difference over the colour channels (R, G, B) of two
/// equally long lists of results.
pub fn rmse(reference: &[[f32; 4]], got: &[[f32; 4]]) -> f64 {
    let n = reference.len().min(got.len());
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = reference
        .iter()
        .zip(got)
        .map(|(a, b)| {
            (0..3)
                .map(|c| (a[c] as f64 - b[c] as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    (sum / (3 * n) as f64).sqrt()
}

/// The pixels of an image (row-major linear RGBA, `None` where the scene
/// shows nothing).
pub type Pixels = [Option<[f32; 4]>];

/// Accuracy of an image against the reference, over the pixels both have,
/// in linear light over R, G, B (SPEC.md).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Scores {
    /// Root-mean-square error.
    pub rmse: f64,
    /// 10·log10(1 / MSE), peak 1 (infinite for identical images).
    pub psnr_db: f64,
    /// Largest absolute error of any channel.
    pub max_error: f64,
    /// Pixels compared.
    pub pixels: usize,
}

/// [`Scores`] of `got` against `reference` (row-major, `None` skipped).
pub fn scores(reference: &Pixels, got: &Pixels) -> Scores {
    let (mut sum, mut max, mut n) = (0f64, 0f64, 0usize);
    for (r, g) in reference.iter().zip(got) {
        if let (Some(r), Some(g)) = (r, g) {
            for c in 0..3 {
                let d = (r[c] as f64 - g[c] as f64).abs();
                sum += d * d;
                max = max.max(d);
            }
            n += 1;
        }
    }
    let mse = if n == 0 { 0.0 } else { sum / (3 * n) as f64 };
    Scores {
        rmse: mse.sqrt(),
        psnr_db: 10.0 * (1.0 / mse).log10(),
        max_error: max,
        pixels: n,
    }
}

/// RMS over pixels (and R, G, B) of the change between two frames.
pub fn rms_change(a: &Pixels, b: &Pixels) -> f64 {
    scores(a, b).rmse
}

/// Flicker (SPEC.md): the RMS change of a filter's image between two
/// frames a quarter pixel apart, minus the reference's own change.
pub fn flicker(filter: (&Pixels, &Pixels), reference: (&Pixels, &Pixels)) -> f64 {
    rms_change(filter.0, filter.1) - rms_change(reference.0, reference.1)
}

/// The error-map scale: the 99th percentile of the per-pixel absolute
/// error (the mean over R, G, B of pixels both images have), so a few
/// outliers do not wash an error map out; at least 1e-4, and 1 when no
/// pixel is compared.
pub fn error_scale(img: &Pixels, reference: &Pixels) -> f64 {
    let mut e: Vec<f64> = img
        .iter()
        .zip(reference)
        .filter_map(|(a, r)| {
            let (a, r) = (a.as_ref()?, r.as_ref()?);
            Some((0..3).map(|c| (a[c] - r[c]).abs() as f64).sum::<f64>() / 3.0)
        })
        .collect();
    if e.is_empty() {
        return 1.0;
    }
    e.sort_by(f64::total_cmp);
    e[(e.len() * 99 / 100).min(e.len() - 1)].max(1e-4)
}
