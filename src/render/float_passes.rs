//! The float passes of a render (the reference and the ground truth) kept for the next
//! render of the same scene on a machine that differs only in fields they do not read: a
//! sweep of widths or `texsim tune` runs them once per scene and such machine.

use super::{CoverageMode, RenderOptions, Rendered};
use crate::report::Image;
use crate::scene::Scene;
use std::collections::HashMap;
use std::hash::Hash;
use std::sync::Arc;

/// The widths that reach the float passes: the stored encodings both passes read (bump
/// offsets, NDF moments and their variance floor) and the degenerate-frame threshold, which
/// the float frame applies too. The rasterizer's fields reach them as well (they pick the
/// fragments both passes shade), but for `depth_bits`: the float passes' depth test is exact
/// (`render::exact_depth_vis`).
const FLOAT_WIDTHS: [&str; 5] = [
    "shading.vector.offset_int_bits",
    "ndf.moment_bits",
    "ndf.moment_scale_bits",
    "ndf.ndf_min_variance_bits",
    "shading.frame.frame_min_sin_bits",
];

/// True for the hw config fields (dotted paths) that do not reach the float passes (the
/// reference and the ground truth): the timing model's, the depth buffer's width, and every
/// width ([`crate::hwconfig::is_width`]) but the rasterizer's and [`FLOAT_WIDTHS`]. Two machines
/// that differ only in such fields have the same float passes, so a sweep or a search over
/// them renders those once ([`FloatPasses`]). `tests/scenes/float_passes.rs` renders every
/// built-in scene with all of them changed at once and checks that both passes keep their
/// bits, and that each width left out does change one.
#[must_use]
pub fn float_blind(path: &str) -> bool {
    path.starts_with("timing.")
        || path == "raster.depth_bits"
        || (crate::hwconfig::is_width(path)
            && !path.starts_with("raster.")
            && !FLOAT_WIDTHS.contains(&path))
}

/// The float passes of a render: the reference image with its count of non-finite float
/// results, and the ground truth. A caller that renders one scene on machines differing only
/// in [`float_blind`] fields keeps them from the first render ([`FloatPasses::of`]) and hands
/// them to the others ([`RenderOptions::float_passes`]), which then skip both passes: a
/// sweep of widths or `texsim tune` renders each float pass once per scene. Shared coverage
/// only (independent coverage changes the compared pixels too).
#[derive(Clone, Debug)]
pub struct FloatPasses {
    scene: (String, u32, u32),
    truth_samples: u32,
    pub(super) reference: Option<(Image, u64)>,
    pub(super) truth: Option<Image>,
    /// The pixels compared with them: those the hardware or the float passes covered (the
    /// float passes' depth test is exact, so they may cover more).
    pub(super) mask: Vec<bool>,
}

impl FloatPasses {
    /// The float passes that `r` (a render of `scene` with `opts`) made; `None` when it made
    /// none or used independent coverage.
    #[must_use]
    pub fn of(scene: &Scene, r: &Rendered, opts: &RenderOptions) -> Option<Self> {
        if opts.coverage != CoverageMode::Shared || (!opts.reference && opts.truth == 0) {
            return None;
        }
        Some(Self {
            scene: (scene.name.clone(), scene.width, scene.height),
            truth_samples: opts.truth,
            reference: r
                .ref_image
                .clone()
                .map(|img| (img, r.stats.bump.ref_nonfinite)),
            truth: r.truth_image.clone(),
            mask: r.mask.clone(),
        })
    }

    /// True when these passes are what a render of `scene` with `opts` would make (the caller
    /// vouches for the machine: it differs only in [`float_blind`] fields).
    pub(super) fn fits(&self, scene: &Scene, opts: &RenderOptions) -> bool {
        let (name, width, height) = &self.scene;
        (name.as_str(), *width, *height) == (scene.name.as_str(), scene.width, scene.height)
            && opts.coverage == CoverageMode::Shared
            && self.truth_samples == opts.truth
            && self.reference.is_some() == opts.reference
    }
}

/// [`FloatPasses`] kept per key (the values of the varied fields that reach the float
/// passes: renders with the same key differ only in [`float_blind`] fields), within a budget
/// of image bytes. Past it the cache keeps what it has and a new key's renders run their own
/// passes; a budget of 0 keeps nothing.
#[derive(Debug)]
pub struct FloatPassCache<K> {
    kept: HashMap<K, Arc<FloatPasses>>,
    bytes: u64,
    budget: u64,
}

/// The bytes of images all the [`FloatPassCache`]s of one command may keep together: a
/// quarter of the memory budget ([`crate::budget::max_memory`]).
#[must_use]
pub fn float_pass_budget() -> u64 {
    crate::budget::max_memory() / 4
}

impl<K: Hash + Eq> FloatPassCache<K> {
    /// An empty cache that keeps at most `budget` bytes of images.
    #[must_use]
    pub fn new(budget: u64) -> Self {
        Self {
            kept: HashMap::new(),
            bytes: 0,
            budget,
        }
    }

    /// The passes kept for `key`.
    #[must_use]
    pub fn get(&self, key: &K) -> Option<Arc<FloatPasses>> {
        self.kept.get(key).cloned()
    }

    /// Keeps the passes `r` (a render of `scene` with `opts`) made, for `key`, unless the
    /// key has some or they do not fit the budget.
    pub fn keep(&mut self, key: K, scene: &Scene, r: &Rendered, opts: &RenderOptions) {
        let px = |img: &Image| (img.px.len() * std::mem::size_of::<[u16; 4]>()) as u64;
        let bytes = r.ref_image.as_ref().map_or(0, px)
            + r.truth_image.as_ref().map_or(0, px)
            + r.mask.len() as u64;
        if self.kept.contains_key(&key) || self.bytes + bytes > self.budget {
            return;
        }
        if let Some(fp) = FloatPasses::of(scene, r, opts) {
            self.bytes += bytes;
            self.kept.insert(key, Arc::new(fp));
        }
    }
}
