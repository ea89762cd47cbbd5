//! Bilinear and trilinear MIP filter unit (Williams 1983, "Pyramidal parametrics"; the
//! OpenGL 4.6 section 8.14 LINEAR_MIPMAP_LINEAR rule).
//!
//! Conventions (written down once):
//! - Texel centres: texel `i` of a level of `size` texels covers normalized coordinates
//!   `[i/size, (i+1)/size)`; its centre is at `(i + 1/2)/size`. A coordinate `c` maps to
//!   texel space `s = c * size - 1/2`; the footprint is texels `floor(s)` and `floor(s) + 1`.
//! - Weights: a weight is the weight of the SECOND operand (`i1`, the next level), with
//!   `weight_bits` fraction bits: `lerp(a, b, w) = a + (b - a) w / 2^weight_bits`.
//! - Levels are row-major, top row first: texel (x, y) is `texels[y * width + x]`; `u` runs
//!   along x, `v` along y. Channel values are `texel_bits`-wide unsigned normalized raw values.
//! - Bilinear order: lerp along x on row `y0` and on row `y1`, then along y between the two.
//!   Each lerp rounds ONCE (by `filter_rounding`) back to texel precision. (The simulator
//!   computes two channels per `u64`, one per 32-bit lane: the same integers.)
//! - Trilinear: `lod <= 0` -> level 0 only; `lod >= (levels - 1)` -> last level only; else
//!   levels `floor(lod)` and `floor(lod) + 1` blended with the `lod_frac_bits` LOD fraction as
//!   the weight of the finer-to-coarser lerp (a zero fraction uses one level: same result).
//!
//! ERROR BOUND vs the exact-arithmetic filter with the same coordinates and LOD
//! ([`trilinear_error_bound_q8`]): per lerp the weight error `dw` (< 2^-wb for Truncate,
//! <= 2^-(wb+1) for the nearest modes; 0 when the coordinate has at most `wb - 1` fraction
//! bits) costs `dw * (2^texel_bits - 1)` LSBs and the rounding `h` (1/2, or < 1 for Truncate).
//! Lerps are convex, so errors do not grow through later lerps: bilinear `<= (dw_x + dw_y)
//! (2^T - 1) + 2h`, trilinear `<=` that `+ h`. If the reference uses an unquantized LOD, add
//! `2^-lod_frac_bits * (2^T - 1)` (the LOD is floor-rounded).

use crate::config::TrilinearConfig;
use crate::cost::UnitCost;
use crate::datapath::{Component, Datapath, Stage};
use crate::fixed::{round_shift_right, ConstRounding, LaneRound, Rounding};
use crate::wrap::{wrap_i64_with, wrap_in, wrap_pow2_repeat, WrapMode, WrapOut, WrapShifts};

mod batch;
pub use batch::{BatchFootprints, BatchLevels, SampleBatch, BATCH_LANES};

/// One MIP level (borrowed texels).
#[derive(Clone, Copy, Debug)]
pub struct Level<'a> {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first, at least `width * height` texels.
    pub texels: &'a [[u16; 4]],
}

/// What one bilinear footprint did (for `texsim probe`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BilinearTrace {
    /// Level index (set by `trilinear`; 0 when `bilinear` is called directly).
    pub level: u32,
    /// Texel coordinates (x, y) in the order (x0,y0), (x1,y0), (x0,y1), (x1,y1).
    pub coords: [(u32, u32); 4],
    /// The four texels, same order.
    pub texels: [[u16; 4]; 4],
    /// Horizontal and vertical weights (of x1 and y1), `weight_bits` fraction bits.
    pub weights: [u32; 2],
    /// The filtered value.
    pub result: [u32; 4],
}

impl BilinearTrace {
    /// The footprint's texel columns `[x0, x1]` and rows `[y0, y1]`.
    #[inline(always)]
    #[must_use]
    pub fn columns_rows(&self) -> ([u32; 2], [u32; 2]) {
        let [(x0, y0), (x1, _), (_, y1), _] = self.coords;
        ([x0, x1], [y0, y1])
    }
}

/// What one trilinear sample did (for `texsim probe`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrilinearTrace {
    /// 1 or 2.
    pub levels_used: u32,
    /// Footprints of the used levels (finer first); only `levels_used` entries are valid.
    pub level: [BilinearTrace; 2],
    /// Weight of the coarser level, `lod_frac_bits` fraction bits (0 with one level).
    pub level_weight: u32,
    /// The filtered value.
    pub result: [u16; 4],
}

/// `a + (b - a) w / 2^weight_bits` with exactly one rounding (`w` in `[0, 2^weight_bits]`,
/// `weight_bits <= 30`). The result lies between `a` and `b`; exact for `w` = 0 or 2^wb.
#[inline(always)]
#[must_use]
pub fn lerp(a: u32, b: u32, w: u32, weight_bits: u32, rounding: Rounding) -> u32 {
    let num = (i64::from(a) << weight_bits) + (i64::from(b) - i64::from(a)) * i64::from(w);
    round_shift_right(num, weight_bits, rounding) as u32
}

#[inline(always)]
fn fetch(level: &Level, x: u32, y: u32) -> [u16; 4] {
    let idx = y as usize * level.width as usize + x as usize;
    level.texels.get(idx).copied().unwrap_or([0; 4])
}

/// Receives what a trilinear sample did, footprint by footprint: the filter reports each
/// bilinear footprint it read (finer level first) and then the sample. `()` ignores
/// everything (the filter then builds nothing for it); [`TrilinearTrace`] keeps it all.
pub trait SampleSink {
    /// Footprint `index` (0 = finer level) of the sample.
    fn footprint(&mut self, index: usize, fp: &BilinearTrace);
    /// The sample: levels used, weight of the coarser level, filtered value.
    fn sample(&mut self, levels_used: u32, level_weight: u32, result: [u16; 4]);
}

impl SampleSink for () {
    #[inline(always)]
    fn footprint(&mut self, _: usize, _: &BilinearTrace) {}
    #[inline(always)]
    fn sample(&mut self, _: u32, _: u32, _: [u16; 4]) {}
}

impl SampleSink for TrilinearTrace {
    #[inline(always)]
    fn footprint(&mut self, index: usize, fp: &BilinearTrace) {
        self.level[index] = *fp;
    }
    #[inline(always)]
    fn sample(&mut self, levels_used: u32, level_weight: u32, result: [u16; 4]) {
        if levels_used < 2 {
            self.level[1] = BilinearTrace::default();
        }
        self.levels_used = levels_used;
        self.level_weight = level_weight;
        self.result = result;
    }
}

/// Lanes of one 32-bit half of a `u64` that hold a channel value (< 2^16).
const LANE16: u64 = 0x0000_ffff_0000_ffff;

/// A texel's channels as one word, channel `c` in bits `16c..16c + 16`.
#[inline(always)]
fn texel_word(t: [u16; 4]) -> u64 {
    u64::from(t[0]) | u64::from(t[1]) << 16 | u64::from(t[2]) << 32 | u64::from(t[3]) << 48
}

/// The four channels of a texel as two `u64` words of two 32-bit lanes: `(c0, c2)` and
/// `(c1, c3)`, so one multiply by a weight serves two channels (a lane's product of a
/// 16-bit value and a weight of at most 2^16 stays below 2^32).
#[derive(Clone, Copy)]
struct Lanes {
    even: u64,
    odd: u64,
}

impl Lanes {
    /// The channels of a texel.
    #[inline(always)]
    fn of(t: [u16; 4]) -> Self {
        Self::of_word(texel_word(t))
    }

    /// The channels of a texel's [`texel_word`].
    #[inline(always)]
    fn of_word(word: u64) -> Self {
        Self {
            even: word & LANE16,
            odd: (word >> 16) & LANE16,
        }
    }

    #[inline(always)]
    fn channels(self) -> [u32; 4] {
        [
            self.even as u32,
            self.odd as u32,
            (self.even >> 32) as u32,
            (self.odd >> 32) as u32,
        ]
    }

    /// [`lerp`] of every channel (`a` = self, `b` = `b`) by `l` with weight `w`.
    #[inline(always)]
    fn lerp(self, b: Self, w: u32, l: &LaneLerp) -> Self {
        Self {
            even: l.lerp(self.even, b.even, w),
            odd: l.lerp(self.odd, b.odd, w),
        }
    }
}

/// [`lerp`] with `weight_bits` = `wb` (at most 16) and a rounding mode, in both 32-bit lanes of
/// a `u64` (values < 2^16, weights `w < 2^wb`): `a (2^wb - w) + b w`, non-negative and at most
/// `2^32 - 2^16` per lane, rounded by [`LaneRound`] (each lane as [`round_shift_right`] rounds
/// it). Built once per [`UnitSetup`].
#[derive(Clone, Copy, Debug)]
struct LaneLerp {
    one: u32,
    round: LaneRound,
}

impl LaneLerp {
    #[inline(always)]
    fn new(wb: u32, mode: Rounding) -> Self {
        Self {
            one: 1 << wb,
            round: LaneRound::new(wb, mode),
        }
    }

    #[inline(always)]
    fn lerp(&self, a: u64, b: u64, w: u32) -> u64 {
        self.round
            .apply(a * u64::from(self.one - w) + b * u64::from(w))
    }
}

/// The four texels of a footprint: `(x0,y0), (x1,y0), (x0,y1), (x1,y1)`; a quad inside the
/// level (the common case) is read from one bounds-checked slice.
#[inline(always)]
fn fetch_quad(level: &Level, wx: &WrapOut, wy: &WrapOut) -> [[u16; 4]; 4] {
    let w = level.width as usize;
    let i00 = wy.i0 as usize * w + wx.i0 as usize;
    if wx.i1 == wx.i0 + 1 && wy.i1 == wy.i0 + 1 {
        if let Some(q) = level.texels.get(i00..i00 + w + 2) {
            return [q[0], q[1], q[w], q[w + 1]];
        }
    }
    [
        fetch(level, wx.i0, wy.i0),
        fetch(level, wx.i1, wy.i0),
        fetch(level, wx.i0, wy.i1),
        fetch(level, wx.i1, wy.i1),
    ]
}

/// [`fetch_quad`] of indices masked to a level with power-of-two sides (Repeat): the second
/// index of an axis is the first's successor unless the first is the last (`size - 1`), so
/// that test replaces the comparison of both indices. Written out beside [`fetch_quad`]: a
/// shared helper taking the test as an argument cost W1 1.7M more instructions (callgrind).
#[inline(always)]
fn fetch_quad_pow2(level: &Level, wx: &WrapOut, wy: &WrapOut) -> [[u16; 4]; 4] {
    debug_assert!(level.width.is_power_of_two() && level.height.is_power_of_two());
    let w = level.width as usize;
    let i00 = wy.i0 as usize * w + wx.i0 as usize;
    if wx.i0 != level.width - 1 && wy.i0 != level.height - 1 {
        if let Some(q) = level.texels.get(i00..i00 + w + 2) {
            return [q[0], q[1], q[w], q[w + 1]];
        }
    }
    [
        fetch(level, wx.i0, wy.i0),
        fetch(level, wx.i1, wy.i0),
        fetch(level, wx.i0, wy.i1),
        fetch(level, wx.i1, wy.i1),
    ]
}

/// One bilinear footprint in lanes, its wrapped addresses and texels reported to `sink`
/// (as footprint `index` of level `level_index`) when the sink keeps them. `narrow`: `frac
/// <= 30` and both coordinates fit the level's sides ([`crate::wrap::fits_i64_on`]; the
/// caller's test, once for every level of a sample), wrapped with the shifts `k` of `frac`
/// and `weight_bits`; `POW2_REPEAT`: both axes Repeat and both sides of the level powers of
/// two (the caller's test, once per span), wrapped by masks.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn bilinear_lanes<W: ConstRounding, S: SampleSink, const POW2_REPEAT: bool>(
    level: &Level,
    level_index: u32,
    u: i64,
    v: i64,
    frac: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    filter: &LaneLerp,
    index: usize,
    narrow: Option<&WrapShifts>,
    sink: &mut S,
) -> Lanes {
    let (wx, wy) = if let (Some(k), true) = (narrow, POW2_REPEAT) {
        (
            wrap_pow2_repeat::<W>(u, level.width, k),
            wrap_pow2_repeat::<W>(v, level.height, k),
        )
    } else if let Some(k) = narrow {
        (
            wrap_i64_with::<W>(u, level.width, wrap_mode[0], k),
            wrap_i64_with::<W>(v, level.height, wrap_mode[1], k),
        )
    } else {
        (
            wrap_in::<W>(u, frac, level.width, wrap_mode[0], cfg),
            wrap_in::<W>(v, frac, level.height, wrap_mode[1], cfg),
        )
    };
    let [t00, t10, t01, t11] = if POW2_REPEAT && narrow.is_some() {
        fetch_quad_pow2(level, &wx, &wy)
    } else {
        fetch_quad(level, &wx, &wy)
    };
    let top = Lanes::of(t00).lerp(Lanes::of(t10), wx.weight, filter);
    let bot = Lanes::of(t01).lerp(Lanes::of(t11), wx.weight, filter);
    let out = top.lerp(bot, wy.weight, filter);
    sink.footprint(
        index,
        &BilinearTrace {
            level: level_index,
            coords: [
                (wx.i0, wy.i0),
                (wx.i1, wy.i0),
                (wx.i0, wy.i1),
                (wx.i1, wy.i1),
            ],
            texels: [t00, t10, t01, t11],
            weights: [wx.weight, wy.weight],
            result: out.channels(),
        },
    );
    out
}

/// Bilinear filter of one level at normalized (u, v) with `frac` fraction bits. A level with
/// too few texels reads zeros for the missing ones.
#[inline]
#[must_use]
pub fn bilinear(
    level: &Level,
    u: i64,
    v: i64,
    frac: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: Option<&mut BilinearTrace>,
) -> [u32; 4] {
    /// Keeps the one footprint of a bilinear filter.
    struct One<'a>(&'a mut BilinearTrace);
    impl SampleSink for One<'_> {
        fn footprint(&mut self, _: usize, fp: &BilinearTrace) {
            *self.0 = *fp;
        }
        fn sample(&mut self, _: u32, _: u32, _: [u16; 4]) {}
    }
    let fits = |u, v| {
        crate::wrap::fits_i64(u, frac, level.width) && crate::wrap::fits_i64(v, frac, level.height)
    };
    crate::with_rounding!(cfg.filter_rounding, F => {
        crate::with_rounding!(cfg.weight_rounding, W => match trace {
            None => {
                let f = LaneLerp::new(cfg.weight_bits.min(16), F::MODE);
                let k = WrapShifts::new(frac, cfg.weight_bits.min(16));
                let narrow = fits(u, v).then_some(&k);
                bilinear_lanes::<W, (), false>(level, 0, u, v, frac, wrap_mode, cfg, &f, 0, narrow, &mut ())
            }
            Some(t) => {
                let mut one = One(t);
                let f = LaneLerp::new(cfg.weight_bits.min(16), F::MODE);
                let k = WrapShifts::new(frac, cfg.weight_bits.min(16));
                let narrow = fits(u, v).then_some(&k);
                bilinear_lanes::<W, One, false>(level, 0, u, v, frac, wrap_mode, cfg, &f, 0, narrow, &mut one)
            }
        }
        .channels())
    })
}

/// Trilinear filter: the LOD rule and conventions of the module doc. `lod` has
/// `lod_frac_bits` fraction bits. No levels gives zeros.
#[allow(clippy::too_many_arguments)]
#[inline]
#[must_use]
pub fn trilinear(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    trace: Option<&mut TrilinearTrace>,
) -> [u16; 4] {
    match trace {
        None => trilinear_to(
            levels,
            u,
            v,
            frac,
            lod,
            lod_frac_bits,
            wrap_mode,
            cfg,
            &mut (),
        ),
        Some(t) => trilinear_to(levels, u, v, frac, lod, lod_frac_bits, wrap_mode, cfg, t),
    }
}

/// [`trilinear`] reporting its footprints to `sink` (e.g. the timing model's trace), with
/// nothing built for a sink that keeps nothing.
#[allow(clippy::too_many_arguments)]
#[inline]
#[must_use]
pub fn trilinear_to<S: SampleSink>(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    sink: &mut S,
) -> [u16; 4] {
    crate::with_rounding!(cfg.filter_rounding, F => {
        crate::with_rounding!(cfg.weight_rounding, W => {
            trilinear_in::<F, W, S>(levels, u, v, frac, lod, lod_frac_bits, wrap_mode, cfg, sink)
        })
    })
}

/// [`trilinear`] compiled for the filter rounding `F` and the weight rounding `W`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn trilinear_in<F: ConstRounding, W: ConstRounding, S: SampleSink>(
    levels: &[Level],
    u: i64,
    v: i64,
    frac: u32,
    lod: i64,
    lod_frac_bits: u32,
    wrap_mode: [WrapMode; 2],
    cfg: &TrilinearConfig,
    sink: &mut S,
) -> [u16; 4] {
    let setup = UnitSetup::new(cfg, frac, lod_frac_bits);
    let out = TrilinearUnit::<F, W>::new(cfg, &setup, wrap_mode).sample(levels, u, v, lod, sink);
    out.map(|c| c as u16)
}

/// The constants of a [`TrilinearUnit`] for one configuration, coordinate format and LOD
/// format (the lerps' rounding constants, the wrap's shifts), built once, e.g. per render,
/// for the units of every span.
#[derive(Clone, Copy, Debug)]
pub struct UnitSetup {
    frac: u32,
    /// `lod_frac_bits`, at most 30.
    lf: u32,
    /// The LOD's fraction bits: `2^lf - 1`.
    lod_mask: i64,
    /// The bilinear lerps (`weight_bits`, at most 16).
    filter: LaneLerp,
    /// The level blend in lanes (`lf <= 16`).
    blend: LaneLerp,
    /// The wrap's shifts (`frac`, `weight_bits`) for coordinates that fit `i64`.
    shifts: WrapShifts,
    /// `frac <= 30`: coordinates that [`crate::wrap::fits_i64_on`] a level wrap in `i64`.
    narrow_frac: bool,
    /// The filter and weight roundings it was built for.
    modes: (Rounding, Rounding),
}

impl UnitSetup {
    /// The constants for `cfg`, coordinates with `frac` fraction bits and LODs with
    /// `lod_frac_bits`.
    #[must_use]
    pub fn new(cfg: &TrilinearConfig, frac: u32, lod_frac_bits: u32) -> Self {
        let lf = lod_frac_bits.min(30);
        let wb = cfg.weight_bits.min(16);
        Self {
            frac,
            lf,
            lod_mask: (1 << lf) - 1,
            filter: LaneLerp::new(wb, cfg.filter_rounding),
            blend: LaneLerp::new(lf.min(16), cfg.filter_rounding),
            shifts: WrapShifts::new(frac, wb),
            narrow_frac: frac <= 30,
            modes: (cfg.filter_rounding, cfg.weight_rounding),
        }
    }
}

/// The trilinear unit set up for a run of samples with one configuration, coordinate
/// format, LOD format ([`UnitSetup`]) and wrap mode, the filter rounding `F` and the weight
/// rounding `W` as types: [`TrilinearUnit::sample`] gives the bits and the footprints of
/// [`trilinear_to`] with the same arguments (it is what [`trilinear_to`] runs, and the unit
/// tests check [`trilinear_to`] against the scalar filter it replaced).
#[derive(Clone, Copy)]
pub struct TrilinearUnit<'a, F, W> {
    cfg: &'a TrilinearConfig,
    setup: &'a UnitSetup,
    wrap_mode: [WrapMode; 2],
    modes: std::marker::PhantomData<(F, W)>,
}

impl<'a, F: ConstRounding, W: ConstRounding> TrilinearUnit<'a, F, W> {
    /// The unit for `cfg` (its rounding modes must be `F` and `W`) with the constants `setup`
    /// built for `cfg`, and `wrap_mode`.
    #[inline(always)]
    #[must_use]
    pub fn new(cfg: &'a TrilinearConfig, setup: &'a UnitSetup, wrap_mode: [WrapMode; 2]) -> Self {
        debug_assert!(cfg.filter_rounding == F::MODE && cfg.weight_rounding == W::MODE);
        debug_assert!(setup.modes == (F::MODE, W::MODE));
        Self {
            cfg,
            setup,
            wrap_mode,
            modes: std::marker::PhantomData,
        }
    }

    /// One sample of `levels` at (`u`, `v`) and LOD `lod`, its footprints reported to `sink`:
    /// the channels of [`trilinear_to`] (each below 2^16).
    #[inline(always)]
    pub fn sample<S: SampleSink>(
        &self,
        levels: &[Level],
        u: i64,
        v: i64,
        lod: i64,
        sink: &mut S,
    ) -> [u32; 4] {
        self.sample_in::<S, false>(levels, u, v, lod, sink)
    }

    /// Whether [`TrilinearUnit::sample_pow2_repeat`] may sample `levels`: both axes Repeat
    /// and [`pow2_chain`] (decided once per span).
    #[inline]
    #[must_use]
    pub fn pow2_repeat(&self, levels: &[Level]) -> bool {
        self.repeats() && pow2_chain(levels)
    }

    /// Both axes wrap by Repeat.
    #[inline(always)]
    #[must_use]
    pub fn repeats(&self) -> bool {
        self.wrap_mode == [WrapMode::Repeat; 2]
    }

    /// [`TrilinearUnit::sample`] for `levels` that [`TrilinearUnit::pow2_repeat`] accepts:
    /// the same bits and footprints, each axis's two indices masked (no test of the wrap mode
    /// or the level's size).
    #[inline(always)]
    pub fn sample_pow2_repeat<S: SampleSink>(
        &self,
        levels: &[Level],
        u: i64,
        v: i64,
        lod: i64,
        sink: &mut S,
    ) -> [u32; 4] {
        debug_assert!(self.pow2_repeat(levels));
        self.sample_in::<S, true>(levels, u, v, lod, sink)
    }

    /// [`TrilinearUnit::sample`], with `POW2_REPEAT` as for [`bilinear_lanes`].
    #[inline(always)]
    fn sample_in<S: SampleSink, const POW2_REPEAT: bool>(
        &self,
        levels: &[Level],
        u: i64,
        v: i64,
        lod: i64,
        sink: &mut S,
    ) -> [u32; 4] {
        let n = levels.len();
        if n == 0 {
            return [0; 4];
        }
        let k = self.setup;
        let lf = k.lf;
        let last = (n - 1) as i64;
        let (l0, lw) = if lod <= 0 {
            (0usize, 0u32)
        } else if (lod >> lf) >= last {
            (n - 1, 0)
        } else {
            ((lod >> lf) as usize, (lod & k.lod_mask) as u32)
        };
        let (frac, wm, cfg, f) = (k.frac, self.wrap_mode, self.cfg, &k.filter);
        // Both coordinates `fits_i64_on` every side of both levels: at once when both are in
        // [-2^29, 2^29) (which fits any `u32` side), else tested against the sides' bitwise or
        // (at least each side).
        let both = (u as u64).wrapping_add(1 << 29) | (v as u64).wrapping_add(1 << 29);
        let fits = both < 1 << 30 || {
            let l1 = (l0 + 1).min(n - 1);
            let sides = levels[l0].width | levels[l0].height | levels[l1].width | levels[l1].height;
            crate::wrap::fits_i64_on(u, sides) && crate::wrap::fits_i64_on(v, sides)
        };
        let nw = (k.narrow_frac && fits).then_some(&k.shifts);
        let c0 = bilinear_lanes::<W, S, POW2_REPEAT>(
            &levels[l0],
            l0 as u32,
            u,
            v,
            frac,
            wm,
            cfg,
            f,
            0,
            nw,
            sink,
        );
        if lw == 0 {
            let out = c0.channels();
            sink.sample(1, 0, out.map(|c| c as u16));
            return out;
        }
        let l1 = l0 + 1;
        let c1 = bilinear_lanes::<W, S, POW2_REPEAT>(
            &levels[l1],
            l1 as u32,
            u,
            v,
            frac,
            wm,
            cfg,
            f,
            1,
            nw,
            sink,
        );
        let out = if lf <= 16 {
            c0.lerp(c1, lw, &k.blend).channels()
        } else {
            let (a, b) = (c0.channels(), c1.channels());
            std::array::from_fn(|c| lerp(a[c], b[c], lw, lf, F::MODE))
        };
        sink.sample(2, lw, out.map(|c| c as u16));
        out
    }
}

/// Every level's width and height are powers of two (Repeat of such a chain wraps by masks).
#[must_use]
pub fn pow2_chain(levels: &[Level]) -> bool {
    levels
        .iter()
        .all(|l| l.width.is_power_of_two() && l.height.is_power_of_two())
}

/// Cost of one trilinear sample using `levels_used` (1 or 2) levels: per level the two wraps,
/// 4 fetches and 3 lerps per channel; plus the level blend (4 lerps) when two levels are used.
/// Cycles from [`datapath`] at `gate_levels_per_cycle`.
#[must_use]
pub fn trilinear_cost(
    cfg: &TrilinearConfig,
    levels_used: u32,
    gate_levels_per_cycle: u32,
) -> UnitCost {
    let per_level = UnitCost {
        ops: 2 * 5 + 12,
        cycles: 0,
        texels: 4,
    };
    let blend = if levels_used > 1 {
        UnitCost {
            ops: 4,
            cycles: 0,
            texels: 0,
        }
    } else {
        UnitCost::default()
    };
    let mut c = per_level.times(levels_used).plus(blend);
    c.cycles = datapath(cfg, levels_used).latency(gate_levels_per_cycle);
    c
}

/// Appends `n` lerps side by side (T = `texel_bits`, W = `weight_bits`): the difference
/// `b - a`, its product with the `W + 1`-bit weight, the add of `a 2^W` with the rounding.
fn lerp_steps(s: Stage, cfg: &TrilinearConfig, n: u32) -> Stage {
    let (t, w) = (cfg.texel_bits, cfg.weight_bits);
    s.then_n(n, Component::Adder { width: t + 1 })
        .then_n(n, Component::Multiplier { a: t + 1, b: w + 1 })
        .then_n(n, Component::Adder { width: t + w + 2 })
}

/// One bilinear footprint (`bilinear_cycles`): the address unit of both axes, the 4-channel
/// lerps along x on both rows side by side, the lerps along y, the result register.
#[must_use]
pub fn bilinear_datapath(cfg: &TrilinearConfig) -> Datapath {
    let s = crate::wrap::address_steps(Stage::new("bilinear footprint"), cfg, 2);
    let s = lerp_steps(lerp_steps(s, cfg, 8), cfg, 4)
        .then(Component::Register {
            bits: 4 * cfg.texel_bits,
        })
        .cycles(cfg.bilinear_cycles);
    Datapath::new().stage(s)
}

/// The trilinear unit with `levels_used` levels: a bilinear footprint per level, then
/// (two levels) the 4-channel level blend (`level_lerp_cycles`).
#[must_use]
pub fn datapath(cfg: &TrilinearConfig, levels_used: u32) -> Datapath {
    let blend = lerp_steps(Stage::new("level blend"), cfg, 4)
        .then(Component::Register {
            bits: 4 * cfg.texel_bits,
        })
        .cycles(cfg.level_lerp_cycles)
        .times(u32::from(levels_used > 1));
    bilinear_datapath(cfg).times(levels_used).stage(blend)
}

/// The module's error bound vs exact arithmetic (same coordinates, same quantized LOD), in
/// 1/256 LSBs of the `texel_bits` output, for coordinates with `coord_frac` fraction bits.
#[must_use]
pub fn trilinear_error_bound_q8(cfg: &TrilinearConfig, coord_frac: u32, two_levels: bool) -> u64 {
    let wb = cfg.weight_bits.min(16);
    let range = (1u64 << cfg.texel_bits.min(16)) - 1;
    // dw in units of 2^-(wb+1): 2 for Truncate (< 2^-wb), 1 for nearest, 0 if exact.
    let dw_units: u64 = if coord_frac < wb {
        0
    } else {
        match cfg.weight_rounding {
            Rounding::Truncate => 2,
            Rounding::HalfUp | Rounding::HalfEven => 1,
        }
    };
    // h in 1/256 LSB: 128 for nearest, 256 for Truncate.
    let h: u64 = match cfg.filter_rounding {
        Rounding::Truncate => 256,
        Rounding::HalfUp | Rounding::HalfEven => 128,
    };
    let weight_term = (2 * dw_units * range * 256) >> (wb + 1);
    let weight_term = weight_term + 1; // round the shifted term up
    weight_term + h * if two_levels { 3 } else { 2 }
}

/// Cycles of one bilinear footprint and of the level blend at `gate_levels_per_cycle` (the
/// timing model's filter latency: footprints x the first + the second when two levels).
#[must_use]
pub fn filter_latencies(cfg: &TrilinearConfig, gate_levels_per_cycle: u32) -> (u32, u32) {
    let bilinear = bilinear_datapath(cfg).latency(gate_levels_per_cycle);
    let both = datapath(cfg, 2).latency(gate_levels_per_cycle);
    (bilinear, both - 2 * bilinear)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::HwConfig;
    use crate::wrap::tests::wrap_before;
    use crate::wrap::{fits_i64, wrap};

    const MODES: [Rounding; 3] = [Rounding::Truncate, Rounding::HalfUp, Rounding::HalfEven];

    use crate::test_rng::splitmix64 as next;

    /// The bilinear footprint as it was composed before the unit was compiled per rounding
    /// mode (each reduction reading its mode from the config): the oracle.
    fn bilinear_before(
        level: &Level,
        u: i64,
        v: i64,
        frac: u32,
        wm: [WrapMode; 2],
        cfg: &TrilinearConfig,
    ) -> [u32; 4] {
        let wx = wrap(u, frac, level.width, wm[0], cfg);
        let wy = wrap(v, frac, level.height, wm[1], cfg);
        let t = |x: u32, y: u32| fetch(level, x, y);
        let (t00, t10, t01, t11) = (
            t(wx.i0, wy.i0),
            t(wx.i1, wy.i0),
            t(wx.i0, wy.i1),
            t(wx.i1, wy.i1),
        );
        let (wb, r) = (cfg.weight_bits.min(16), cfg.filter_rounding);
        std::array::from_fn(|c| {
            let top = lerp(u32::from(t00[c]), u32::from(t10[c]), wx.weight, wb, r);
            let bot = lerp(u32::from(t01[c]), u32::from(t11[c]), wx.weight, wb, r);
            lerp(top, bot, wy.weight, wb, r)
        })
    }

    /// 1.8M seeded samples over the nine (filter, weight) rounding pairs, three wrap modes,
    /// weight widths 0 to 16 and coordinates in and far outside [0, 1]: `bilinear` and
    /// `trilinear` give the bits of the composition from `wrap` and `lerp`.
    #[test]
    fn compiled_modes_match_the_composed_filter() {
        let mut s = 0x5eed_0006;
        let (w, h) = (13u32, 8u32);
        let texels: Vec<[u16; 4]> = (0..w * h * 2)
            .map(|_| [0; 4].map(|_| next(&mut s) as u16))
            .collect();
        let l0 = Level {
            width: w,
            height: h,
            texels: &texels[..(w * h) as usize],
        };
        let l1 = Level {
            width: 7,
            height: 4,
            texels: &texels[(w * h) as usize..],
        };
        let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
        for f in MODES {
            for wr in MODES {
                let mut cfg = HwConfig::texram16().trilinear;
                cfg.filter_rounding = f;
                cfg.weight_rounding = wr;
                for i in 0..200_000u32 {
                    cfg.weight_bits = [16, 8, 4, 0, 12][(i % 5) as usize];
                    let frac = [24, 16, 8, 30][(i / 5 % 4) as usize];
                    let sh = [34, 30, 10][(i % 3) as usize];
                    let u = (next(&mut s) as i64) >> sh;
                    let v = (next(&mut s) as i64) >> sh;
                    let wm = [modes[(i % 3) as usize], modes[(i / 3 % 3) as usize]];
                    let want = bilinear_before(&l0, u, v, frac, wm, &cfg);
                    assert_eq!(bilinear(&l0, u, v, frac, wm, &cfg, None), want);
                    let lod = (next(&mut s) % (3 << 16)) as i64 - (1 << 16);
                    let lw = (lod.clamp(0, 1 << 16) & 0xffff) as u32;
                    let want = if lod <= 0 {
                        want.map(|c| c as u16)
                    } else if lod >> 16 >= 1 {
                        bilinear_before(&l1, u, v, frac, wm, &cfg).map(|c| c as u16)
                    } else {
                        let c1 = bilinear_before(&l1, u, v, frac, wm, &cfg);
                        std::array::from_fn(|c| lerp(want[c], c1[c], lw, 16, f) as u16)
                    };
                    let got = trilinear(&[l0, l1], u, v, frac, lod, 16, wm, &cfg, None);
                    assert_eq!(got, want, "{u} {v} {lod} {cfg:?}");
                }
            }
        }
    }
    /// The bilinear footprint before it was computed in lanes (scalar lerps, its trace built
    /// field by field), its wraps by the previous wrap routine: the oracle.
    fn bilinear_in_before<F: ConstRounding, W: ConstRounding>(
        level: &Level,
        u: i64,
        v: i64,
        frac: u32,
        wrap_mode: [WrapMode; 2],
        cfg: &TrilinearConfig,
        trace: Option<&mut BilinearTrace>,
    ) -> [u32; 4] {
        let wx = wrap_before(u, frac, level.width, wrap_mode[0], W::MODE, cfg.weight_bits);
        let wy = wrap_before(
            v,
            frac,
            level.height,
            wrap_mode[1],
            W::MODE,
            cfg.weight_bits,
        );
        let t00 = fetch(level, wx.i0, wy.i0);
        let t10 = fetch(level, wx.i1, wy.i0);
        let t01 = fetch(level, wx.i0, wy.i1);
        let t11 = fetch(level, wx.i1, wy.i1);
        let wb = cfg.weight_bits.min(16);
        let r = F::MODE;
        let mut out = [0u32; 4];
        for c in 0..4 {
            let top = lerp(u32::from(t00[c]), u32::from(t10[c]), wx.weight, wb, r);
            let bot = lerp(u32::from(t01[c]), u32::from(t11[c]), wx.weight, wb, r);
            out[c] = lerp(top, bot, wy.weight, wb, r);
        }
        if let Some(t) = trace {
            t.coords = [
                (wx.i0, wy.i0),
                (wx.i1, wy.i0),
                (wx.i0, wy.i1),
                (wx.i1, wy.i1),
            ];
            t.texels = [t00, t10, t01, t11];
            t.weights = [wx.weight, wy.weight];
            t.result = out;
        }
        out
    }

    /// The trilinear filter before it was computed in lanes and reported to a sink: the oracle.
    #[allow(clippy::too_many_arguments)]
    fn trilinear_in_before<F: ConstRounding, W: ConstRounding>(
        levels: &[Level],
        u: i64,
        v: i64,
        frac: u32,
        lod: i64,
        lod_frac_bits: u32,
        wrap_mode: [WrapMode; 2],
        cfg: &TrilinearConfig,
        mut trace: Option<&mut TrilinearTrace>,
    ) -> [u16; 4] {
        let n = levels.len();
        if n == 0 {
            return [0; 4];
        }
        let lf = lod_frac_bits.min(30);
        let last = (n - 1) as i64;
        let (l0, lw) = if lod <= 0 {
            (0usize, 0u32)
        } else if (lod >> lf) >= last {
            (n - 1, 0)
        } else {
            ((lod >> lf) as usize, (lod & ((1i64 << lf) - 1)) as u32)
        };
        let mut bt0 = BilinearTrace {
            level: l0 as u32,
            ..BilinearTrace::default()
        };
        let c0 = bilinear_in_before::<F, W>(
            &levels[l0],
            u,
            v,
            frac,
            wrap_mode,
            cfg,
            trace.as_ref().map(|_| &mut bt0),
        );
        let mut out = [0u16; 4];
        if lw == 0 {
            for c in 0..4 {
                out[c] = c0[c] as u16;
            }
            if let Some(t) = trace.as_deref_mut() {
                *t = TrilinearTrace {
                    levels_used: 1,
                    level: [bt0, BilinearTrace::default()],
                    level_weight: 0,
                    result: out,
                };
            }
            return out;
        }
        let mut bt1 = BilinearTrace {
            level: l0 as u32 + 1,
            ..BilinearTrace::default()
        };
        let c1 = bilinear_in_before::<F, W>(
            &levels[l0 + 1],
            u,
            v,
            frac,
            wrap_mode,
            cfg,
            trace.as_ref().map(|_| &mut bt1),
        );
        for c in 0..4 {
            out[c] = lerp(c0[c], c1[c], lw, lf, F::MODE) as u16;
        }
        if let Some(t) = trace {
            *t = TrilinearTrace {
                levels_used: 2,
                level: [bt0, bt1],
                level_weight: lw,
                result: out,
            };
        }
        out
    }

    /// [`trilinear_in_before`] for run-time modes.
    #[allow(clippy::too_many_arguments)]
    fn trilinear_before(
        levels: &[Level],
        u: i64,
        v: i64,
        frac: u32,
        lod: i64,
        lfb: u32,
        wm: [WrapMode; 2],
        cfg: &TrilinearConfig,
        trace: Option<&mut TrilinearTrace>,
    ) -> [u16; 4] {
        crate::with_rounding!(cfg.filter_rounding, F => {
            crate::with_rounding!(cfg.weight_rounding, W => {
                trilinear_in_before::<F, W>(levels, u, v, frac, lod, lfb, wm, cfg, trace)
            })
        })
    }

    /// MIP chains of the given level sizes cut one after another from `texels`, starting at
    /// `start` and back to 0 where a level reaches the end (that level is short: its missing
    /// texels read zero).
    fn chains_of<'a>(
        texels: &'a [[u16; 4]],
        sizes: &[&[(u32, u32)]],
        start: usize,
    ) -> Vec<Vec<Level<'a>>> {
        sizes
            .iter()
            .map(|c| {
                let mut at = start;
                c.iter()
                    .map(|&(width, height)| {
                        let end = (at + (width * height) as usize).min(texels.len());
                        let l = Level {
                            width,
                            height,
                            texels: &texels[at..end],
                        };
                        at = if end == texels.len() { 0 } else { end };
                        l
                    })
                    .collect()
            })
            .collect()
    }

    /// The whole trace of [`trilinear_before`]'s sample.
    #[allow(clippy::too_many_arguments)]
    fn trace_before(
        levels: &[Level],
        u: i64,
        v: i64,
        frac: u32,
        lod: i64,
        lfb: u32,
        wm: [WrapMode; 2],
        cfg: &TrilinearConfig,
    ) -> TrilinearTrace {
        let mut t = TrilinearTrace::default();
        let _ = trilinear_before(levels, u, v, frac, lod, lfb, wm, cfg, Some(&mut t));
        t
    }

    /// A reused trace holding a stale second level (from a two-level sample): a sample
    /// must overwrite all of it.
    fn stale_trace() -> TrilinearTrace {
        TrilinearTrace {
            levels_used: 2,
            level: [BilinearTrace {
                level: 9,
                ..BilinearTrace::default()
            }; 2],
            ..TrilinearTrace::default()
        }
    }

    /// 3M seeded samples against the scalar filter it replaced: the nine (filter, weight)
    /// rounding pairs, the nine wrap-mode pairs, weight widths 0 to 16, LOD fractions 0 to 16
    /// (lanes) and 17 to 30 (the scalar level blend), chains of square, non-square, 1x1 and
    /// short (missing texels read zero) levels, coordinates inside and far outside [0, 1],
    /// LODs below 0, inside and past the chain; the untraced result, the traced result and
    /// the whole trace (coordinates, texels, weights, per-level results) are identical.
    #[test]
    fn lanes_match_the_previous_filter() {
        let mut s = 0x5eed_0012;
        let texels: Vec<[u16; 4]> = (0..4096)
            .map(|_| [0; 4].map(|_| next(&mut s) as u16))
            .collect();
        let sizes: [&[(u32, u32)]; 5] = [
            &[(16, 16), (8, 8), (4, 4), (2, 2), (1, 1)],
            &[(13, 5), (6, 2), (3, 1), (1, 1)],
            &[(1, 1)],
            &[(1, 40), (1, 20), (1, 10)],
            &[(64, 64), (32, 32)],
        ];
        // The 64x64 level is short: its last 16 rows read zeros.
        let chains = chains_of(&texels, &sizes, 1024);
        let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
        let (mut lanes_blend, mut scalar_blend, mut one_level) = (0u32, 0u32, 0u32);
        let (mut inside, mut wrapped, mut missing) = (0u32, 0u32, 0u32);
        for i in 0..3_000_000u32 {
            let cfg = cycled_config(i);
            let levels = &chains[(i / 153 % 5) as usize];
            let wm = [modes[(i % 3) as usize], modes[(i / 7 % 3) as usize]];
            let frac = [24, 16, 8, 30, 12][(i / 11 % 5) as usize];
            let lfb = if i % 13 == 0 {
                17 + i / 13 % 14
            } else {
                i / 17 % 17
            };
            let (u, v) = if i % 4 == 0 {
                let sh = (next(&mut s) % 64) as u32;
                ((next(&mut s) as i64) >> sh, (next(&mut s) as i64) >> sh)
            } else {
                // Mostly inside [-1/4, 5/4): the common interior footprints.
                let one = 1i64 << frac;
                let r = |x: u64| (x % (3 * one as u64 / 2)) as i64 - one / 4;
                (r(next(&mut s)), r(next(&mut s)))
            };
            let lod = (next(&mut s) % ((levels.len() as u64 + 1) << lfb)) as i64 - (1 << lfb >> 1);
            let want = trilinear_before(levels, u, v, frac, lod, lfb, wm, &cfg, None);
            assert_eq!(
                trilinear(levels, u, v, frac, lod, lfb, wm, &cfg, None),
                want,
                "{u} {v} {frac} {lod} {lfb} {wm:?} {cfg:?}"
            );
            let want_trace = trace_before(levels, u, v, frac, lod, lfb, wm, &cfg);
            let mut got_trace = stale_trace();
            let got = trilinear(levels, u, v, frac, lod, lfb, wm, &cfg, Some(&mut got_trace));
            assert_eq!(got, want);
            assert_eq!(got_trace, want_trace, "{u} {v} {lod} {lfb} {cfg:?}");
            match (want_trace.levels_used, lfb <= 16) {
                (1, _) => one_level += 1,
                (_, true) => lanes_blend += 1,
                (_, false) => scalar_blend += 1,
            }
            for b in &want_trace.level[..want_trace.levels_used as usize] {
                let l = &levels[b.level as usize];
                if b.coords[3].1 * l.width + b.coords[3].0 >= l.texels.len() as u32 {
                    missing += 1;
                }
                if b.coords[1].0 == b.coords[0].0 + 1 && b.coords[2].1 == b.coords[0].1 + 1 {
                    inside += 1;
                } else {
                    wrapped += 1;
                }
            }
            let l = &levels[(i % levels.len() as u32) as usize];
            let mut bt = BilinearTrace::default();
            let want = bilinear_before(l, u, v, frac, wm, &cfg);
            assert_eq!(bilinear(l, u, v, frac, wm, &cfg, Some(&mut bt)), want);
            assert_eq!(bt.result, want);
        }
        assert!(
            lanes_blend > 1_000_000 && scalar_blend > 50_000 && one_level > 500_000,
            "{lanes_blend} {scalar_blend} {one_level}"
        );
        assert!(
            inside > 500_000 && wrapped > 500_000 && missing > 10_000,
            "{inside} {wrapped} {missing}"
        );
    }

    /// The chains of the power-of-two tests: square, non-square, 1xN, one texel; short (the
    /// 64x64 level's last rows read zeros; the batch form refuses it); not powers of two
    /// (refused).
    const POW2_TEST_CHAINS: [&[(u32, u32)]; 6] = [
        &[(32, 32), (16, 16), (8, 8), (4, 4), (2, 2), (1, 1)],
        &[(16, 4), (8, 2), (4, 1), (2, 1), (1, 1)],
        &[(1, 1)],
        &[(1, 64), (1, 32), (1, 16)],
        &[(64, 64), (32, 32)],
        &[(12, 8), (6, 4), (3, 2), (1, 1)],
    ];

    /// The texram16 filter with case `i`'s (filter, weight) rounding pair (the nine in turn)
    /// and weight width (0 to 16, changing every nine cases).
    fn cycled_config(i: u32) -> TrilinearConfig {
        let mut cfg = HwConfig::texram16().trilinear;
        cfg.filter_rounding = MODES[(i % 3) as usize];
        cfg.weight_rounding = MODES[(i / 3 % 3) as usize];
        cfg.weight_bits = i / 9 % 17;
        cfg
    }

    /// Case `i`'s coordinate fraction bits and its `1.0` (`2^frac`, capped at `2^62`): 4 to 30
    /// in turn, and every `wide_every`-th case one of the `wide_kinds` formats from 31 up
    /// (beyond the 64-bit path and the batch form).
    fn cycled_frac(i: u32, wide_every: u32, wide_kinds: u32) -> (u32, i64) {
        let frac = if i.is_multiple_of(wide_every) {
            31 + i / wide_every % wide_kinds
        } else {
            4 + i / 11 % 27
        };
        (frac, 1i64 << frac.min(62))
    }

    /// 6000 seeded texels.
    fn random_texels(s: &mut u64) -> Vec<[u16; 4]> {
        (0..6000).map(|_| [0; 4].map(|_| next(s) as u16)).collect()
    }

    /// 2M seeded samples: a unit's `sample_pow2_repeat`, where `pow2_repeat` accepts the
    /// chain (Repeat on both axes, power-of-two sides), gives the bits and the whole trace of
    /// its general `sample` and of the scalar filter it replaced; the nine rounding pairs,
    /// weight widths 0 to 16, LOD fractions 0 to 30, coordinate formats with 4 to 30 fraction
    /// bits and wider ones (the 128-bit wrap), coordinates inside and far outside [0, 1] and at
    /// the ends of the 64-bit path on a level's sides; square, non-square, 1xN and short
    /// power-of-two chains, and non-power-of-two chains and other wrap modes (refused, counted).
    #[test]
    fn pow2_repeat_matches_the_general_sample() {
        let mut s = 0x5eed_0016;
        let texels = random_texels(&mut s);
        let chains = chains_of(&texels, &POW2_TEST_CHAINS, 2000);
        let modes = [WrapMode::Repeat, WrapMode::ClampToEdge, WrapMode::Mirror];
        let (mut fast, mut refused, mut wide, mut two) = (0u32, 0u32, 0u32, 0u32);
        for i in 0..2_000_000u32 {
            let cfg = cycled_config(i);
            let levels = &chains[(i / 153 % 6) as usize];
            let wm = if i % 8 == 0 {
                [modes[(i / 8 % 3) as usize], modes[(i / 24 % 3) as usize]]
            } else {
                [WrapMode::Repeat; 2]
            };
            let (frac, one) = cycled_frac(i, 16, 30);
            let lfb = i / 17 % 31;
            let (u, v) = match i % 5 {
                0 => {
                    let sh = (next(&mut s) % 64) as u32;
                    ((next(&mut s) as i64) >> sh, (next(&mut s) as i64) >> sh)
                }
                1 => {
                    // The ends of the 64-bit path on a level's sides (`fits_i64_on`).
                    let l = &levels[(next(&mut s) % levels.len() as u64) as usize];
                    let e = |x: u64, side: u32| {
                        let end = ((1u64 << 61).div_ceil(u64::from(side.max(1)))) as i64;
                        [-end - 1, -end, end, end - 1][(x % 4) as usize] + (x / 4 % 3) as i64 - 1
                    };
                    (e(next(&mut s), l.width), e(next(&mut s), l.height))
                }
                _ => {
                    let r = |x: u64| (x % (4 * one as u64)) as i64 - 3 * one / 2;
                    (r(next(&mut s)), r(next(&mut s)))
                }
            };
            let lod = (next(&mut s) % ((levels.len() as u64 + 1) << lfb)) as i64 - (1 << lfb >> 1);
            let setup = UnitSetup::new(&cfg, frac, lfb);
            let want = trilinear_before(levels, u, v, frac, lod, lfb, wm, &cfg, None);
            let want_trace = trace_before(levels, u, v, frac, lod, lfb, wm, &cfg);
            crate::with_rounding!(cfg.filter_rounding, F => {
                crate::with_rounding!(cfg.weight_rounding, W => {
                    let unit = TrilinearUnit::<F, W>::new(&cfg, &setup, wm);
                    let want = want.map(u32::from);
                    assert_eq!(unit.sample(levels, u, v, lod, &mut ()), want);
                    if unit.pow2_repeat(levels) {
                        fast += 1;
                        let got = unit.sample_pow2_repeat(levels, u, v, lod, &mut ());
                        assert_eq!(got, want, "{u} {v} {frac} {lod} {lfb} {cfg:?}");
                        let mut got_trace = stale_trace();
                        let got = unit.sample_pow2_repeat(levels, u, v, lod, &mut got_trace);
                        assert_eq!(got, want);
                        assert_eq!(got_trace, want_trace, "{u} {v} {frac} {lod} {lfb} {cfg:?}");
                        if !(fits_i64(u, frac, levels[0].width)
                            && fits_i64(v, frac, levels[0].height))
                        {
                            wide += 1;
                        }
                        if want_trace.levels_used == 2 {
                            two += 1;
                        }
                    } else {
                        assert!(wm != [WrapMode::Repeat; 2] || !pow2_chain(levels));
                        refused += 1;
                    }
                })
            });
        }
        assert!(
            fast > 1_400_000 && refused > 300_000 && wide > 300_000 && two > 400_000,
            "{fast} {refused} {wide} {two}"
        );
    }

    /// 2.4M seeded lanes (300,000 batches of 1 to 16) of the batch form against
    /// [`TrilinearUnit::sample_pow2_repeat`] lane by lane (channels, and in every other batch
    /// the footprints its sink receives): the nine rounding pairs, every
    /// weight width, coordinates with 4 to 30 fraction bits (and 31 or more, refused), LOD
    /// fractions of 0 to 20 bits (above 16 refused), LODs below the first level and beyond the
    /// last, coordinates near 0 and past `2^29` (sampled by themselves), batches of 1 to 16
    /// lanes (77k batches whose lanes all read one level, which skip the second); short and
    /// non-power-of-two chains refused by [`BatchLevels::new`].
    #[test]
    fn batch_matches_sample_pow2_repeat() {
        let mut s = 0x5eed_0b17;
        let texels = random_texels(&mut s);
        let chains = chains_of(&texels, &POW2_TEST_CHAINS, 2000);
        let batch_levels: Vec<_> = chains.iter().map(|c| BatchLevels::new(c)).collect();
        assert!(batch_levels[..4].iter().all(Option::is_some));
        assert!(batch_levels[4..].iter().all(Option::is_none));
        let (mut lanes, mut refused, mut wide, mut two) = (0u32, 0u32, 0u32, 0u32);
        // Batches whose lanes all read one level (the passes then skip the second).
        let (mut fp_lanes, mut one_level) = (0u32, 0u32);
        for i in 0..300_000u32 {
            let cfg = cycled_config(i);
            let c = (i / 153 % 4) as usize;
            let (levels, bl) = (&chains[c], batch_levels[c].as_ref().unwrap());
            let (frac, one) = cycled_frac(i, 32, 4);
            let lfb = i / 17 % 21;
            let mut batch = SampleBatch::default();
            for j in 0..BATCH_LANES {
                let (u, v) = match next(&mut s) % 8 {
                    0 => {
                        let sh = (next(&mut s) % 64) as u32;
                        ((next(&mut s) as i64) >> sh, (next(&mut s) as i64) >> sh)
                    }
                    1 => {
                        // Either side of the batch's range `[-2^29, 2^29)`.
                        let e = |x: u64| {
                            [-(1 << 29) - 1, -(1 << 29), (1 << 29) - 1, 1 << 29][(x % 4) as usize]
                        };
                        (e(next(&mut s)), e(next(&mut s)))
                    }
                    _ => {
                        let r = |x: u64| (x % (4 * one as u64)) as i64 - 3 * one / 2;
                        (r(next(&mut s)), r(next(&mut s)))
                    }
                };
                let lod =
                    (next(&mut s) % ((levels.len() as u64 + 1) << lfb)) as i64 - (1 << lfb >> 1);
                (batch.u[j], batch.v[j], batch.lod[j]) = (u, v, lod);
            }
            let n = 1 + (next(&mut s) % BATCH_LANES as u64) as usize;
            let setup = UnitSetup::new(&cfg, frac, lfb);
            crate::with_rounding!(cfg.filter_rounding, F => {
                crate::with_rounding!(cfg.weight_rounding, W => {
                    let unit = TrilinearUnit::<F, W>::new(&cfg, &setup, [WrapMode::Repeat; 2]);
                    let stale = [[0xdead_beef; 4]; BATCH_LANES];
                    let mut out = stale;
                    // Every other batch also gives its footprints.
                    let traced = i % 2 == 1;
                    let (mut fps, mut portable_fps) = Default::default();
                    let vector = unit.sample_batch_pow2_repeat(
                        levels,
                        bl,
                        &batch,
                        n,
                        &mut out,
                        traced.then_some(&mut fps),
                    );
                    assert_eq!(vector, unit.batch_form());
                    if !(frac <= 30 && lfb <= 16) {
                        assert!(!vector);
                        assert_eq!(out, stale);
                        assert_eq!(fps, BatchFootprints::default());
                        refused += 1;
                    } else {
                        // The portable passes (what the vector ones are compiled from) on every
                        // CPU; they leave the wide lanes to the caller.
                        let mut portable = stale;
                        let at = batch::Levels { levels, shape: bl };
                        let pfps = traced.then_some(&mut portable_fps);
                        batch::batch_passes(&unit, &at, &batch, n, &mut portable, pfps);
                        let mut any_two = false;
                        for j in 0..n {
                            let (u, v, lod) = (batch.u[j], batch.v[j], batch.lod[j]);
                            let mut trace = TrilinearTrace::default();
                            let want = unit.sample_pow2_repeat(levels, u, v, lod, &mut trace);
                            let want_fps = traced.then(|| footprints_of(&trace));
                            let lane_fps = |f: &BatchFootprints| {
                                traced.then(|| f.lane(j).collect::<Vec<_>>())
                            };
                            if vector {
                                assert_eq!(out[j], want, "{u} {v} {frac} {lod} {lfb} {cfg:?}");
                                assert_eq!(lane_fps(&fps), want_fps, "{u} {v} {frac} {lod}");
                            }
                            let narrow = |x: i64| (-(1 << 29)..1 << 29).contains(&x);
                            if narrow(u) && narrow(v) {
                                assert_eq!(portable[j], want, "{u} {v} {frac} {lod} {lfb} {cfg:?}");
                                assert_eq!(lane_fps(&portable_fps), want_fps, "{u} {v} {lod}");
                                lanes += 1;
                                fp_lanes += u32::from(traced);
                            } else {
                                wide += 1;
                            }
                            let lf_mask = (1 << lfb) - 1;
                            let inner = lod > 0 && (lod >> lfb) < levels.len() as i64 - 1;
                            let blends = inner && lod & lf_mask != 0;
                            two += u32::from(blends);
                            any_two |= blends;
                        }
                        one_level += u32::from(!any_two);
                    }
                })
            });
        }
        assert!(
            lanes > 1_400_000 && refused > 40_000 && wide > 300_000 && two > 600_000,
            "{lanes} {refused} {wide} {two}"
        );
        assert!(fp_lanes > 700_000, "{fp_lanes}");
        assert!(one_level > 60_000, "{one_level}");
    }

    /// A sample's footprints: (level, columns, rows) of each level it used.
    fn footprints_of(t: &TrilinearTrace) -> Vec<(u32, [u32; 2], [u32; 2])> {
        let fp = |b: &BilinearTrace| {
            let (x, y) = b.columns_rows();
            (b.level, x, y)
        };
        t.level
            .iter()
            .take(t.levels_used as usize)
            .map(fp)
            .collect()
    }
}
