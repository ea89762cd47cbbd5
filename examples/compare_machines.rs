//! Using texsim from Rust: render a built-in scene on two machines and on a swept variant,
//! and print each one's error against the float reference and its cycles (timing model).
//!
//! `cargo run --release --example compare_machines`

use texsim::hwconfig;
use texsim::render::{render, Maps, RenderOptions};
use texsim::scene;

fn main() -> texsim::Result<()> {
    let mut sc = scene::builtin("demo")?;
    sc.width = 320;
    sc.height = 240;
    scene::validate(&sc)?;
    let texram = hwconfig::resolve("texram16")?;
    let machines = [
        ("texram16", texram.clone()),
        ("vulkan-min", hwconfig::resolve("vulkan-min")?),
        (
            "texram16, weight_bits=4",
            hwconfig::set_field(&texram, "weight_bits", "4")?,
        ),
    ];
    for (label, hw) in &machines {
        // The budget check `texsim` does before it allocates (`render` checks again).
        texsim::budget::check_run(&sc, hw, true, true)?;
        let maps = Maps::new(&sc, hw.trilinear.texel_bits);
        let opts = RenderOptions {
            timing: true,
            ..RenderOptions::default()
        };
        let r = render(&sc, &maps, hw, &opts)?;
        let t = r
            .stats
            .timing
            .as_ref()
            .ok_or_else(|| texsim::Error::msg("no timing report"))?;
        let e = r
            .stats
            .error_8bit
            .as_ref()
            .ok_or_else(|| texsim::Error::msg("no reference rendered"))?;
        println!(
            "{label:<24} {} pixels: max {} mean {:.4} rmse {:.4} (8-bit LSB), {:.2} cycles/px",
            r.stats.covered_pixels, e.max_abs_lsb, e.mean_abs_lsb, e.rmse_lsb, t.cycles_per_pixel
        );
        for w in &r.stats.warnings {
            println!("  warning: {w}");
        }
    }
    Ok(())
}
