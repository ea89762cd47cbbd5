//! The trilinear unit over a batch of samples held as a structure of arrays:
//! [`TrilinearUnit::sample_pow2_repeat`] of [`BATCH_LANES`] samples at once in passes that
//! vectorize (each lane's levels and wrapped addresses, then the texel fetch, then the lerps),
//! the same channels lane by lane (`batch_matches_sample_pow2_repeat`), so the error bound is
//! the unit's (the parent module's ERROR BOUND) and its float twin is the unit's.

use super::{texel_word, LaneLerp, Lanes, Level, TrilinearTrace, TrilinearUnit};
use crate::fixed::ConstRounding;
use crate::wrap::wrap_pow2_repeat_lane;
use std::mem::MaybeUninit;

/// Samples per batch.
pub const BATCH_LANES: usize = 16;

/// Levels a batch takes at most (a chain of power-of-two `u32` sides has at most 32).
const MAX_LEVELS: usize = 32;

/// A batch's samples: each lane's raw coordinates and raw LOD, as [`TrilinearUnit::sample`]
/// takes them.
#[derive(Clone, Copy, Debug, Default)]
pub struct SampleBatch {
    pub u: [i64; BATCH_LANES],
    pub v: [i64; BATCH_LANES],
    pub lod: [i64; BATCH_LANES],
}

/// The footprints of a batch's lanes, as [`TrilinearUnit::sample_pow2_repeat`] reports them
/// to its sink (for the timing model's trace): lane `i` read `levels_used[i]` levels (1 or
/// 2), `level[0][i]` and then `level[1][i]`; level `l`'s footprint has the wrapped columns
/// `x[l][0][i]`, `x[l][1][i]` and rows `y[l][0][i]`, `y[l][1][i]` (texels (x0,y0), (x1,y0),
/// (x0,y1), (x1,y1)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BatchFootprints {
    pub levels_used: [u32; BATCH_LANES],
    pub level: [[u32; BATCH_LANES]; 2],
    pub x: [[[u32; BATCH_LANES]; 2]; 2],
    pub y: [[[u32; BATCH_LANES]; 2]; 2],
}

impl BatchFootprints {
    /// Lane `i`'s footprints, finer level first: each one's level, columns and rows.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> impl Iterator<Item = (u32, [u32; 2], [u32; 2])> + '_ {
        (0..self.levels_used[i] as usize).map(move |l| {
            let (x, y) = (&self.x[l], &self.y[l]);
            (self.level[l][i], [x[0][i], x[1][i]], [y[0][i], y[1][i]])
        })
    }

    /// Lane `i`'s footprints as a sample's trace gives them.
    fn set_lane(&mut self, i: usize, t: &TrilinearTrace) {
        self.levels_used[i] = t.levels_used;
        for (l, b) in t.level.iter().enumerate() {
            self.level[l][i] = b.level;
            let (x, y) = b.columns_rows();
            [self.x[l][0][i], self.x[l][1][i]] = x;
            [self.y[l][0][i], self.y[l][1][i]] = y;
        }
    }
}

/// The shape of a texture's levels checked once for the batch form (e.g. per render): a
/// chain of power-of-two sides ([`super::pow2_chain`]), every level with all its texels (at
/// most 2^32), at most 32 levels; each level's sides as base-2 logarithms. The batch samples
/// the levels it was built from.
#[derive(Clone, Copy, Debug)]
pub struct BatchLevels {
    count: usize,
    log2_w: [u32; MAX_LEVELS],
    log2_h: [u32; MAX_LEVELS],
}

impl BatchLevels {
    /// The shape of `levels` in the batch form, or `None` where it does not apply (the
    /// per-sample path samples them).
    #[must_use]
    pub fn new(levels: &[Level]) -> Option<Self> {
        if levels.is_empty() || levels.len() > MAX_LEVELS || !super::pow2_chain(levels) {
            return None;
        }
        let (mut log2_w, mut log2_h) = ([0; MAX_LEVELS], [0; MAX_LEVELS]);
        for (i, l) in levels.iter().enumerate() {
            // Every texel present, and each index (`y << log2 w | x`) within `u32`.
            let texels = u64::from(l.width) * u64::from(l.height);
            if (l.texels.len() as u64) < texels || texels > 1 << 32 {
                return None;
            }
            log2_w[i] = l.width.trailing_zeros();
            log2_h[i] = l.height.trailing_zeros();
        }
        Some(Self {
            count: levels.len(),
            log2_w,
            log2_h,
        })
    }

    /// Whether `levels` have this shape.
    fn fits(&self, levels: &[Level]) -> bool {
        levels.len() == self.count
            && levels
                .iter()
                .zip(&self.log2_w)
                .zip(&self.log2_h)
                .all(|((l, &w), &h)| l.width == 1 << w && l.height == 1 << h)
    }
}

/// A batch's levels and their shape.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(super) struct Levels<'a, 'l> {
    pub(super) levels: &'a [Level<'l>],
    pub(super) shape: &'a BatchLevels,
}

/// The per-lane state between a batch's passes: the two levels and their sides' logarithms,
/// the LOD weight, the four texel indices and two weights of each level's footprint, the
/// texels as words. Every pass writes all its lanes before the next reads them.
pub(super) struct Passes {
    level: [[u32; BATCH_LANES]; 2],
    log2_side: [[[u32; 2]; BATCH_LANES]; 2],
    lod_weight: [u32; BATCH_LANES],
    index: [[[u32; BATCH_LANES]; 4]; 2],
    weight: [[[u32; BATCH_LANES]; 2]; 2],
    texel: [[[MaybeUninit<u64>; BATCH_LANES]; 4]; 2],
}

impl Passes {
    /// Every lane zero but the texels' (1 KB of the 2.3 KB), which the fetch pass writes:
    /// zeroing all of it took 1.2 points more of W1's frame in `memset` (perf, 3 pairs).
    #[inline(always)]
    fn new() -> Self {
        Self {
            level: Default::default(),
            log2_side: Default::default(),
            lod_weight: Default::default(),
            index: Default::default(),
            weight: Default::default(),
            texel: [[[MaybeUninit::uninit(); BATCH_LANES]; 4]; 2],
        }
    }
}

impl<F: ConstRounding, W: ConstRounding> TrilinearUnit<'_, F, W> {
    /// Whether [`TrilinearUnit::sample_batch_pow2_repeat`] samples for this unit: Repeat on
    /// both axes, coordinates with at most 30 fraction bits, an LOD with at most 16, and vector
    /// batches ([`crate::vector_isa`]: AVX2 or AVX-512). The portable build of the passes
    /// compiles to scalar code that took more instructions than sample by sample (callgrind,
    /// W1, one frame: 1,037M instructions sample by sample, 1,210M in batches); the AVX2 build
    /// took as long as sample by sample (perf, W1 on Zen 3: 23% of the samples against 21%).
    #[inline]
    #[must_use]
    pub fn batch_form(&self) -> bool {
        let k = self.setup;
        crate::vector_batches() && self.repeats() && k.narrow_frac && k.lf <= 16
    }

    /// [`TrilinearUnit::sample_pow2_repeat`] of `levels` (of the shape `shape`) at the first
    /// `n` lanes of `batch` into `out`, and their footprints into `footprints` where given:
    /// the same channels and footprints, lane by lane. `false`, with nothing written, where
    /// the batch form does not apply ([`TrilinearUnit::batch_form`]) or `levels` have another
    /// number of levels than `shape`. A lane whose coordinates leave `[-2^29, 2^29)` is
    /// sampled by itself.
    #[inline]
    pub fn sample_batch_pow2_repeat(
        &self,
        levels: &[Level],
        shape: &BatchLevels,
        batch: &SampleBatch,
        n: usize,
        out: &mut [[u32; 4]; BATCH_LANES],
        mut footprints: Option<&mut BatchFootprints>,
    ) -> bool {
        if !self.batch_form() || levels.len() != shape.count {
            return false;
        }
        debug_assert!(shape.fits(levels), "levels of another shape");
        let levels = &Levels { levels, shape };
        if !batch_vector(self, levels, batch, n, out, footprints.as_deref_mut()) {
            return false;
        }
        self.wide_lanes(levels, batch, n, out, footprints);
        true
    }

    /// The lanes among the first `n` whose coordinates leave `[-2^29, 2^29)`, sampled by
    /// themselves.
    #[inline(always)]
    fn wide_lanes(
        &self,
        levels: &Levels,
        batch: &SampleBatch,
        n: usize,
        out: &mut [[u32; 4]; BATCH_LANES],
        mut footprints: Option<&mut BatchFootprints>,
    ) {
        for (i, o) in out.iter_mut().enumerate().take(n) {
            let (u, v, lod) = (batch.u[i], batch.v[i], batch.lod[i]);
            if ((u as u64).wrapping_add(1 << 29) | (v as u64).wrapping_add(1 << 29)) >= 1 << 30 {
                let Some(fps) = footprints.as_deref_mut() else {
                    *o = self.sample_pow2_repeat(levels.levels, u, v, lod, &mut ());
                    continue;
                };
                let mut t = TrilinearTrace::default();
                *o = self.sample_pow2_repeat(levels.levels, u, v, lod, &mut t);
                fps.set_lane(i, &t);
            }
        }
    }
}

crate::isa_kernel! {
    /// [`batch_passes`] built for the vector instruction set in force (`false`, with nothing
    /// written, under [`crate::VectorIsa::Portable`]).
    vector fn batch_vector[F: ConstRounding, W: ConstRounding](
        unit: &TrilinearUnit<F, W>,
        levels: &Levels,
        batch: &SampleBatch,
        n: usize,
        out: &mut [[u32; 4]; BATCH_LANES],
        footprints: Option<&mut BatchFootprints>,
    ) = batch_passes::<F, W>;
}

/// The passes of [`TrilinearUnit::sample_batch_pow2_repeat`]: the levels and LOD weight as
/// [`TrilinearUnit::sample_pow2_repeat`] chooses them, each level's footprint by
/// [`wrap_pow2_repeat_lane`], the texels, the three lerps of each level
/// ([`Lanes`]) and the blend (the finer level's result where the LOD weight is 0). The
/// arithmetic runs over every lane (a fixed count vectorizes whole; the lanes past `n` hold
/// earlier inputs and give results nobody reads), the fetch over the first `n` (zero texels
/// elsewhere); where `footprints` is given, each lane's levels and its footprints' columns and
/// rows (taken apart from the texel indices). Where none of the first `n` lanes has a LOD
/// weight, the passes take the finer level only ([`level_passes`] with one level: a magnified
/// surface's batches: W1's fastest frame -5.5% at stop 61).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
#[inline(always)]
pub(super) fn batch_passes<F: ConstRounding, W: ConstRounding>(
    unit: &TrilinearUnit<F, W>,
    levels: &Levels,
    batch: &SampleBatch,
    n: usize,
    out: &mut [[u32; 4]; BATCH_LANES],
    footprints: Option<&mut BatchFootprints>,
) {
    let p = &mut Passes::new();
    let k = unit.setup;
    let last = (levels.shape.count - 1) as i64;
    let n = n.min(BATCH_LANES);
    for i in 0..BATCH_LANES {
        let lod = batch.lod[i];
        let q = lod >> k.lf;
        let (l0, w) = if lod <= 0 {
            (0, 0)
        } else if q >= last {
            (last, 0)
        } else {
            (q, lod & k.lod_mask)
        };
        p.level[0][i] = l0 as u32;
        p.level[1][i] = (l0 + 1).min(last) as u32;
        p.lod_weight[i] = w as u32;
    }
    // A batch whose lanes all have LOD weight 0 (magnified, or at either end of the chain)
    // reads one level: the coarser level's addresses, fetch and lerps are skipped.
    if p.lod_weight[..n].iter().fold(0, |a, &w| a | w) == 0 {
        level_passes::<F, W, 1>(unit, levels, batch, n, out, footprints, p);
    } else {
        level_passes::<F, W, 2>(unit, levels, batch, n, out, footprints, p);
    }
}

/// The passes of [`batch_passes`] after the levels and LOD weights of `p`, over the first
/// `LEVELS` levels of each lane (1 where every lane's LOD weight is 0, else 2).
#[inline(always)]
fn level_passes<F: ConstRounding, W: ConstRounding, const LEVELS: usize>(
    unit: &TrilinearUnit<F, W>,
    levels: &Levels,
    batch: &SampleBatch,
    n: usize,
    out: &mut [[u32; 4]; BATCH_LANES],
    footprints: Option<&mut BatchFootprints>,
    p: &mut Passes,
) {
    let k = unit.setup;
    for lev in 0..LEVELS {
        for i in 0..BATCH_LANES {
            let l = p.level[lev][i] as usize & (MAX_LEVELS - 1);
            p.log2_side[lev][i] = [levels.shape.log2_w[l], levels.shape.log2_h[l]];
        }
    }
    let (indices, weights) = (&mut p.index[..LEVELS], &mut p.weight[..LEVELS]);
    for (lev, (index, weight)) in indices.iter_mut().zip(weights).enumerate() {
        for i in 0..BATCH_LANES {
            let [lw, lh] = p.log2_side[lev][i];
            let (x0, x1, wx) = wrap_pow2_repeat_lane::<W>(batch.u[i], lw, &k.shifts);
            let (y0, y1, wy) = wrap_pow2_repeat_lane::<W>(batch.v[i], lh, &k.shifts);
            index[0][i] = y0 << lw | x0;
            index[1][i] = y0 << lw | x1;
            index[2][i] = y1 << lw | x0;
            index[3][i] = y1 << lw | x1;
            weight[0][i] = wx;
            weight[1][i] = wy;
        }
    }
    if let Some(fps) = footprints {
        addresses::<LEVELS>(p, fps);
    }
    // The fetch: each index is below its level's `width * height` (`BatchLevels::new`).
    // A lane past `n`, and the coarser level of a lane with LOD weight 0, read no texels.
    let texels = &mut p.texel[..LEVELS];
    for (lev, (texel, index)) in texels.iter_mut().zip(&p.index).enumerate() {
        for i in 0..BATCH_LANES {
            let fetch = i < n && (lev == 0 || p.lod_weight[i] != 0);
            let texels = match levels.levels.get(p.level[lev][i] as usize) {
                Some(l) if fetch => l.texels,
                _ => &[],
            };
            for c in 0..4 {
                texel[c][i] = MaybeUninit::new(
                    texels
                        .get(index[c][i] as usize)
                        .map_or(0, |&t| texel_word(t)),
                );
            }
        }
    }
    let (f, blend) = (&k.filter, &k.blend);
    for (i, o) in out.iter_mut().enumerate() {
        let c0 = bilinear_lane(p, 0, i, f);
        let w = p.lod_weight[i];
        let c = if LEVELS == 1 || w == 0 {
            c0
        } else {
            c0.lerp(bilinear_lane(p, 1, i, f), w, blend)
        };
        *o = c.channels();
    }
}

/// Each lane's levels and footprints from the texel indices of `p` (`y << log2 w | x`) of its
/// first `LEVELS` levels (a lane reads its second level only with a LOD weight, so
/// [`BatchFootprints::lane`] reads no other).
#[inline(always)]
fn addresses<const LEVELS: usize>(p: &Passes, fps: &mut BatchFootprints) {
    for i in 0..BATCH_LANES {
        fps.levels_used[i] = 1 + u32::from(p.lod_weight[i] != 0);
    }
    fps.level = p.level;
    for lev in 0..LEVELS {
        for i in 0..BATCH_LANES {
            let lw = p.log2_side[lev][i][0];
            let index = &p.index[lev];
            let mask = (1 << lw) - 1;
            fps.x[lev][0][i] = index[0][i] & mask;
            fps.x[lev][1][i] = index[1][i] & mask;
            fps.y[lev][0][i] = index[0][i] >> lw;
            fps.y[lev][1][i] = index[2][i] >> lw;
        }
    }
}

/// The three lerps of lane `i`'s footprint in level `lev` (x on both rows, then y).
#[inline(always)]
fn bilinear_lane(p: &Passes, lev: usize, i: usize, f: &LaneLerp) -> Lanes {
    let t = &p.texel[lev];
    let [wx, wy] = [p.weight[lev][0][i], p.weight[lev][1][i]];
    // SAFETY: the fetch pass of `level_passes` has written every lane of every corner of
    // each level it takes, and a lane's second level is read only when it takes two.
    let q = |c: usize| Lanes::of_word(unsafe { t[c][i].assume_init() });
    let top = q(0).lerp(q(1), wx, f);
    let bot = q(2).lerp(q(3), wx, f);
    top.lerp(bot, wy, f)
}
