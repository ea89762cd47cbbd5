//! Whole-frame benchmarks: the demo scene and the Mesa anchor workloads, bit-accurate
//! hardware path vs float reference path (same rasterizer, different stage twins).

use criterion::{criterion_group, criterion_main, Criterion};
use texsim::pipeline::StageImpls;
use texsim::render::{render, Maps, RenderOptions};

fn frame(c: &mut Criterion) {
    let hw = hw_model::HwConfig::texram16();
    for name in ["demo", "w1-plane", "w2-mesh"] {
        let s = texsim::scene::builtin(name).expect("builtin");
        let maps = Maps::new(&s, hw.trilinear.texel_bits);
        let mut g = c.benchmark_group(format!("frame/{name}"));
        g.sample_size(10);
        for (label, im) in [("fixed", StageImpls::FIXED), ("float", StageImpls::FLOAT)] {
            let opts = RenderOptions {
                hw_impls: im,
                reference: false,
                ..Default::default()
            };
            g.bench_function(label, |b| {
                b.iter(|| render(&s, &maps, &hw, &opts).expect("render"))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, frame);
criterion_main!(benches);
