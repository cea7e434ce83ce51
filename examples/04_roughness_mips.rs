//! Roughness from normal variance, validated against shading: for each
//! procedural normal map, BRDF and level, the RMSE and the peak highlight
//! (divided by the ground truth's) of the renormalised normal shaded with
//! the base roughness, and with the adjusted roughness (Cook-Torrance:
//! α' = sqrt(α² + 2/κ); Blinn-Phong: Toksvig's s'), against the ground
//! truth: every level-0 normal of the texel's footprint shaded and
//! averaged. Printed as the README's markdown table:
//!
//! ```text
//! cargo run --release --example 04_roughness_mips
//! ```
//!
//! Maps (256², float): Gaussian bumps of σ = 1.5 and σ = 4 texels, a
//! V-groove pattern (period 8 texels, 30° walls) and a multi-octave height
//! field. Base roughness α = 0.2 (Blinn-Phong exponent 48). Light/view
//! pairs: `parvo::shade::default_directions` (viewer at 0°, 30°, 60°, 80°;
//! light at the mirror direction and 20° off it).

use parvo::shade::{Brdf, bumps, compare, default_directions, height_field, v_grooves};

fn main() -> Result<(), parvo::Error> {
    let maps = [
        ("bumps σ 1.5", bumps(256, 1.5, 1.0, 2500, 1)?),
        ("bumps σ 4", bumps(256, 4.0, 1.0, 400, 2)?),
        ("V-grooves", v_grooves(256, 8.0, 30.0)?),
        ("height field", height_field(256, 0.35, 3)?),
    ];
    let dirs = default_directions();
    println!(
        "| map | BRDF | level | RMSE, renormalised | RMSE, adjusted | ratio | peak, renormalised | peak, adjusted |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    for (name, map) in &maps {
        for brdf in [Brdf::BlinnPhong, Brdf::CookTorrance] {
            for s in compare(map, 0.2, brdf, &dirs)?.iter().take(7) {
                println!(
                    "| {name} | {brdf} | {} | {:.4} | {:.4} | {:.2} | {:.2} | {:.2} |",
                    s.level,
                    s.rmse_base,
                    s.rmse_adjusted,
                    s.rmse_adjusted / s.rmse_base,
                    s.peak_base,
                    s.peak_adjusted
                );
            }
        }
    }
    Ok(())
}
