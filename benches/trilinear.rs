//! Per-sample cost of the bit-accurate trilinear filter vs its f64 twin (256x256 RGBA pyramid,
//! 1024 samples per iteration: pseudo-random (cache-missing) and a coherent scanline walk at
//! LOD 1.5).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use hw_model::config::HwConfig;
use hw_model::trilinear::{trilinear, Level};
use hw_model::wrap::WrapMode;
use texsim::reference::{trilinear_f64, LevelF};
use texsim::rng::SplitMix64;

const N: usize = 1024;

fn bench(c: &mut Criterion) {
    let mut rng = SplitMix64(42);
    let mut fixed: Vec<(u32, Vec<[u16; 4]>)> = Vec::new();
    let mut size = 256u32;
    while size >= 1 {
        let t: Vec<[u16; 4]> = (0..size * size)
            .map(|_| [0; 4].map(|_: u16| rng.next_u64() as u16))
            .collect();
        fixed.push((size, t));
        if size == 1 {
            break;
        }
        size /= 2;
    }
    let float: Vec<Vec<[f32; 4]>> = fixed
        .iter()
        .map(|(_, t)| {
            t.iter()
                .map(|x| x.map(|c| (f64::from(c) / 65535.0) as f32))
                .collect()
        })
        .collect();
    let lv: Vec<Level> = fixed
        .iter()
        .map(|(s, t)| Level {
            width: *s,
            height: *s,
            texels: t,
        })
        .collect();
    let lf: Vec<LevelF> = fixed
        .iter()
        .zip(&float)
        .map(|((s, _), t)| LevelF {
            width: *s,
            height: *s,
            texels: t,
        })
        .collect();
    let samples: Vec<(i64, i64, i64)> = (0..N)
        .map(|_| {
            (
                (rng.next_u64() % (4 << 16)) as i64,
                (rng.next_u64() % (4 << 16)) as i64,
                (rng.next_u64() % (6 << 16)) as i64,
            )
        })
        .collect();
    // Coherent: a scanline-like walk (neighbouring samples share texels), as in rasterization.
    let coherent: Vec<(i64, i64, i64)> = (0..N as i64)
        .map(|i| (i * 97 + 12345, (i / 32) * 101 + 777, 3 << 15))
        .collect();
    let cfg = HwConfig::texram16();
    let wrap = [WrapMode::Repeat, WrapMode::Mirror];
    let mut g = c.benchmark_group("trilinear_per_sample");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("fixed_texram16", |b| {
        b.iter(|| {
            let mut acc = 0u32;
            for &(u, v, l) in &samples {
                let r = trilinear(&lv, u, v, 16, l, 16, wrap, &cfg.trilinear, None);
                acc = acc.wrapping_add(u32::from(r[0]));
            }
            black_box(acc)
        })
    });
    g.bench_function("float_f64", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(u, v, l) in &samples {
                let s = 1.0 / 65536.0;
                let r = trilinear_f64(&lf, u as f64 * s, v as f64 * s, l as f64 * s, wrap);
                acc += r[0];
            }
            black_box(acc)
        })
    });
    g.bench_function("fixed_texram16_coherent", |b| {
        b.iter(|| {
            let mut acc = 0u32;
            for &(u, v, l) in &coherent {
                let r = trilinear(&lv, u, v, 16, l, 16, wrap, &cfg.trilinear, None);
                acc = acc.wrapping_add(u32::from(r[0]));
            }
            black_box(acc)
        })
    });
    g.bench_function("float_f64_coherent", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(u, v, l) in &coherent {
                let s = 1.0 / 65536.0;
                let r = trilinear_f64(&lf, u as f64 * s, v as f64 * s, l as f64 * s, wrap);
                acc += r[0];
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
