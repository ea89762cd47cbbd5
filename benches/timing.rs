//! Timing-model benchmarks: the model's own speed in events per second (pixels + footprints +
//! triangles + spans), and what collecting events costs a render (timing off vs on).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use texsim::render::{render, Maps, RenderOptions};
use texsim::timing::{cycles, simulate};

fn model(c: &mut Criterion) {
    for (name, preset) in [
        ("demo", "texram16"),
        ("w1-plane", "texram16"),
        ("demo", "d3d11"),
        ("w2-mesh", "d3d11"),
    ] {
        let s = texsim::scene::builtin(name).expect("builtin");
        let hw = hw_model::HwConfig::preset(preset).expect("preset");
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        let (r, _) = cycles(&s, &maps, &hw).expect("cycles");
        let ev = r.events.expect("events");
        let mut g = c.benchmark_group(format!("timing-model/{name}/{preset}"));
        g.sample_size(10);
        g.throughput(Throughput::Elements(ev.len()));
        g.bench_function("simulate", |b| b.iter(|| simulate(&ev, &hw, name)));
        g.finish();
    }
}

fn render_cost(c: &mut Criterion) {
    let hw = hw_model::HwConfig::texram16();
    for name in ["demo", "w1-plane"] {
        let s = texsim::scene::builtin(name).expect("builtin");
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        let mut g = c.benchmark_group(format!("render-timing-cost/{name}"));
        g.sample_size(10);
        for (label, timing) in [("timing-off", false), ("timing-on", true)] {
            let opts = RenderOptions {
                reference: false,
                timing,
                ..Default::default()
            };
            g.bench_function(label, |b| {
                b.iter(|| render(&s, &maps, &hw, &opts).expect("render"))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, model, render_cost);
criterion_main!(benches);
