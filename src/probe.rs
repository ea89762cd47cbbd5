//! `texsim probe`: one sample of one texture through the trilinear unit, fixed and float, with
//! the texels and weights the unit used (to debug a unit, or to check it against an API's
//! precision rules).

use crate::cli::ProbeArgs;
use crate::fixedpoint::{from_raw, to_raw};
use crate::maps::{build_mip_chain, quantize_chain};
use crate::reference::trilinear_f64;
use crate::scene::{decode_texture, WrapMode};
use crate::{hwconfig, Error, Result};
use hw_model::fixed::{Format, Rounding, SatCounter};
use hw_model::trilinear::{trilinear, TrilinearTrace};
use std::fmt::Write;

/// Runs the probe: the report the CLI prints.
pub fn probe_cmd(a: &ProbeArgs) -> Result<String> {
    for (name, v) in [("--u", a.u), ("--v", a.v), ("--lod", a.lod)] {
        if !v.is_finite() {
            return Err(Error::field(name, format!("{v} is not a finite number")));
        }
    }
    let hw = hwconfig::resolve(&a.hw)?;
    let wrap = a.wrap.into();
    let tex = decode_texture(&a.texture)?;
    Ok(probe_report(&tex, &hw, a.u, a.v, a.lod, [wrap, wrap]))
}

/// The probe report for one texture and sample position.
#[must_use]
pub fn probe_report(
    tex: &crate::scene::TextureImage,
    hw: &hw_model::HwConfig,
    u: f64,
    v: f64,
    lod: f64,
    wrap: [WrapMode; 2],
) -> String {
    let chain = build_mip_chain(tex);
    let tb = hw.trilinear.texel_bits;
    let fixed = quantize_chain(&chain, tb);
    let levels = fixed.views();
    let levels_f = chain.views();
    let i = &hw.interp;
    let uv_fmt = Format::signed(i.texcoord_int_bits, i.texcoord_frac_bits, i.interp_rounding)
        .with_overflow(i.texcoord_overflow);
    let lfb = hw.lod.lod_frac_bits;
    let lod_fmt = Format::signed(8, lfb, Rounding::Truncate);
    let mut sat = SatCounter::default();
    // `interp.texcoord_reduce`: the coordinate enters the format less an integer (exact for
    // repeat and mirror), as a triangle's do at setup.
    let off = |x: f64, w: WrapMode| {
        if i.texcoord_reduce {
            crate::pipeline::stages::texcoord_offset([x; 3], w)
        } else {
            0.0
        }
    };
    let (ur, vr, lr) = (
        to_raw(u - off(u, wrap[0]), &uv_fmt, &mut sat),
        to_raw(v - off(v, wrap[1]), &uv_fmt, &mut sat),
        to_raw(lod, &lod_fmt, &mut sat),
    );
    let mut tr = TrilinearTrace::default();
    let out = trilinear(
        &levels,
        ur,
        vr,
        uv_fmt.frac_bits,
        lr,
        lfb,
        wrap,
        &hw.trilinear,
        Some(&mut tr),
    );
    let fl = trilinear_f64(&levels_f, u, v, lod, wrap);
    let scale = ((1u64 << tb) - 1) as f64;

    let mut o = String::new();
    let _ = writeln!(
        o,
        "texture {} ({}x{}, {} levels), hw '{}'",
        tex.name,
        tex.width,
        tex.height,
        chain.levels.len(),
        hw.name
    );
    let _ = writeln!(
        o,
        "input: u={u} v={v} lod={lod} -> fixed u={} v={} ({} frac bits), lod={} ({} frac bits){}",
        from_raw(ur, uv_fmt.frac_bits),
        from_raw(vr, uv_fmt.frac_bits),
        uv_fmt.frac_bits,
        from_raw(lr, lfb),
        lfb,
        match (sat.saturated > 0, sat.wrapped > 0) {
            (true, true) => "  [input saturated and wrapped]",
            (true, false) => "  [input saturated]",
            (false, true) => "  [input wrapped]",
            (false, false) => "",
        }
    );
    for l in 0..tr.levels_used as usize {
        let b = &tr.level[l];
        let _ = writeln!(
            o,
            "level {}: weights s={} t={} (of 2^{}), texels (x,y)=value:",
            b.level, b.weights[0], b.weights[1], hw.trilinear.weight_bits
        );
        for k in 0..4 {
            let _ = writeln!(
                o,
                "  ({:>4},{:>4}) = {:?}",
                b.coords[k].0, b.coords[k].1, b.texels[k]
            );
        }
        let _ = writeln!(o, "  bilinear = {:?}", b.result);
    }
    if tr.levels_used == 2 {
        let _ = writeln!(o, "level blend weight = {} (of 2^{lfb})", tr.level_weight);
    }
    let _ = writeln!(o, "fixed  = {:?} (texel_bits {tb})", out);
    let fixed_n: Vec<String> = out
        .iter()
        .map(|&x| format!("{:.6}", f64::from(x) / scale))
        .collect();
    let float_n: Vec<String> = fl.iter().map(|x| format!("{x:.6}")).collect();
    let diff: Vec<String> = out
        .iter()
        .zip(fl)
        .map(|(&x, f)| format!("{:+.3}", f64::from(x) - f * scale))
        .collect();
    let _ = writeln!(o, "fixed  normalized = [{}]", fixed_n.join(", "));
    let _ = writeln!(o, "float  normalized = [{}]", float_n.join(", "));
    let _ = writeln!(o, "fixed - float in texel LSBs = [{}]", diff.join(", "));
    o
}
