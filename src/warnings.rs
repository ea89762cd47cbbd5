//! Warnings about results that are valid but probably not what was meant, found from a render's
//! counters. They go into `RenderStats::warnings` (and `summary.json`); the CLI prints them.

use glam::DVec3;

use crate::raster::RasterStats;
use crate::scene::Scene;

/// The warning when every fragment failed the depth test (`raster.fragments > 0`, no pixel
/// covered): with `near` tiny against the scene's depths, every depth rounds to the cleared
/// maximum of the `depth_bits` buffer. Names `camera.near` and a value that would work.
#[must_use]
pub fn depth_warning(scene: &Scene, depth_bits: u32, raster: &RasterStats) -> Option<String> {
    if raster.fragments == 0 || raster.visible > 0 {
        return None;
    }
    let cam = &scene.camera;
    let view = cam.view();
    let mut far_z = 0.0f64;
    for m in &scene.meshes {
        for p in &m.positions {
            let z = -view.transform_point3(DVec3::from(p.map(f64::from))).z;
            if z.is_finite() && z > far_z {
                far_z = z;
            }
        }
    }
    let far_z = far_z.min(cam.far);
    // 256 depth steps at the farthest geometry: n / z >= 2^(8 - depth_bits).
    let bits = depth_bits.clamp(8, 30);
    let need = far_z * (2.0f64).powi(8 - bits as i32);
    let suggest = round_up_1sig(need.max(cam.near * 2.0));
    Some(format!(
        "field 'camera.near': every one of the {} fragments failed the {bits}-bit depth test, so the hardware image is empty: near = {:e} against depths up to {far_z:.4} leaves no depth step between the geometry and the cleared buffer; near >= {suggest:e} would work (256 depth steps at the farthest geometry)",
        raster.fragments, cam.near
    ))
}

/// `x` rounded up to one significant digit (`0.000123` -> `0.0002`).
fn round_up_1sig(x: f64) -> f64 {
    if !(x.is_finite() && x > 0.0) {
        return x;
    }
    let e = x.log10().floor();
    let scale = 10f64.powf(e);
    let r = (x / scale).ceil() * scale;
    // Normalize through the decimal text so the printed value is short.
    format!("{r:.0e}").parse().unwrap_or(r)
}
