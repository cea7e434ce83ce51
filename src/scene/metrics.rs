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
