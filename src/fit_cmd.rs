//! `texsim fit`: the host-side Fournier lobe fit (`shading::fournier_fit`) of a procedural
//! normal map, per K and per MIP level: texels, lobes per texel, EM iterations, fallbacks,
//! mean residual and fitting time. Returns the text; the CLI prints it.

use crate::shading::fournier_fit::{fit_pyramid, FitConfig};
use crate::shading::ndf::procedural_normals;
use crate::{Error, Result};
use clap::Args;
use std::fmt::Write;

/// Largest map side `texsim fit` accepts (the fit is quadratic in nothing, but every level
/// visits every finest normal once).
pub const MAX_FIT_SIZE: u32 = 2048;

/// Arguments of `texsim fit`.
#[derive(Args, Debug, Clone)]
pub struct FitArgs {
    /// Procedural normal map: grooves (two slopes per texel), ripple, waves, foil.
    #[arg(long, default_value = "grooves")]
    pub normals: String,
    /// Map side in texels (a power of two up to 2048).
    #[arg(long, default_value_t = 64)]
    pub size: u32,
    /// Largest slope of the map.
    #[arg(long, default_value_t = 0.5)]
    pub amplitude: f64,
    /// Lobes per texel, one fit per value (1..=8), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8")]
    pub lobes: Vec<usize>,
    /// The material's Phong exponent (conversion to Phong peaks, residual).
    #[arg(long, default_value_t = 32.0)]
    pub shininess: f64,
    /// EM iterations at most (more: the texel falls back to one moments lobe).
    #[arg(long, default_value_t = 200)]
    pub max_iterations: u32,
}

/// Runs the fits and formats the table.
pub fn fit_cmd(a: &FitArgs) -> Result<String> {
    if !a.size.is_power_of_two() || a.size > MAX_FIT_SIZE {
        return Err(Error::field(
            "--size",
            format!("{} is not a power of two up to {MAX_FIT_SIZE}", a.size),
        ));
    }
    if !(a.amplitude.is_finite() && a.amplitude >= 0.0) {
        return Err(Error::field(
            "--amplitude",
            format!("{} is not a slope >= 0", a.amplitude),
        ));
    }
    let normals = procedural_normals(&a.normals, a.size, a.size, a.amplitude)
        .map_err(|e| e.context("--normals"))?;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Fournier lobe fit of '{}' {}x{} (amplitude {}, shininess {}): EM of vMF lobes per texel from the finest normals",
        a.normals, a.size, a.size, a.amplitude, a.shininess
    );
    let _ = writeln!(
        out,
        "{:>2} {:>5} {:>9} {:>7} {:>10} {:>9} {:>12} {:>9}",
        "K", "level", "texels", "lobes", "iterations", "fallbacks", "residual", "time_ms"
    );
    for &k in &a.lobes {
        let cfg = FitConfig {
            lobes: k,
            shininess: a.shininess,
            max_iterations: a.max_iterations,
            ..FitConfig::default()
        };
        for l in fit_pyramid(&normals, a.size, a.size, &cfg)? {
            let n = l.texels.len() as f64;
            let lobes = l.texels.iter().map(|t| t.lobes.len()).sum::<usize>() as f64 / n;
            let its = l
                .texels
                .iter()
                .map(|t| f64::from(t.iterations))
                .sum::<f64>()
                / n;
            let _ = writeln!(
                out,
                "{k:>2} {:>5} {:>9} {lobes:>7.2} {its:>10.1} {:>9} {:>12.3e} {:>9.2}",
                l.level,
                l.texels.len(),
                l.fallbacks,
                l.mean_residual,
                l.seconds * 1e3
            );
        }
    }
    Ok(out)
}
