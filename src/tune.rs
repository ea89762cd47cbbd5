//! `texsim tune`: the narrowest machine that keeps every given scene within an error budget.
//!
//! The search (in the spirit of MATLAB Fixed-Point Designer's `fxpopt` word-length search)
//! minimises the machine's area proxy ([`hw_model::datapath::total_area`]; ties: the sum of the
//! knobs' values) over integer knobs (widths, iteration counts) between their least valid
//! value and their value on the base ("widest") machine, subject to every budget on every
//! scene:
//! 1. **bisect**: per knob, the least value that meets the budget with all other knobs at the
//!    base (assumes the error does not grow with more bits);
//! 2. **combine**: all knobs at those minima; when the errors add up past the budget,
//!    **repair** adds a margin of 1, 2, ... bits to every sensitive knob (one whose least
//!    value changed some metric) until the budget holds;
//! 3. **descend**: from the feasible point, lower single knobs by one (largest area saving
//!    first) in rounds, then trade a bit of one knob for a bit of a cheaper one, while a move
//!    meets the budget and saves area;
//! 4. **verify**: the best point rendered again (with the timing model) and checked.
//!
//! Every point is rendered once (a cache holds the results); the search is sequential and
//! deterministic. Library code: no printing; the CLI prints the trials as they come
//! (`progress`).

use crate::hwconfig;
use crate::render::{render, FloatPassCache, Maps, RenderOptions};
use crate::report::{compare, ErrorMetrics};
use crate::scene::Scene;
use crate::{Error, Result};
use hw_model::HwConfig;
use serde::Serialize;
use std::collections::HashMap;

/// An error metric a budget bounds (8-bit LSBs of the RGB channels over the covered pixels).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Metric {
    /// Largest channel error (`max8`).
    Max8,
    /// Percent of pixels whose largest channel error is at most 1 LSB (`within1`).
    Within1,
    /// Mean absolute channel error (`mean8`).
    Mean8,
    /// PSNR in dB (`psnr8`; identical images: infinite).
    Psnr8,
    /// Mean LDR-FLIP over the covered pixels (`flip_mean`, in [0, 1]; `crate::flip`).
    FlipMean,
    /// 99th percentile of the per-pixel LDR-FLIP (`flip_p99`).
    FlipP99,
}

impl Metric {
    /// Every metric with its budget name.
    pub const ALL: [(Self, &'static str); 6] = [
        (Self::Max8, "max8"),
        (Self::Within1, "within1"),
        (Self::Mean8, "mean8"),
        (Self::Psnr8, "psnr8"),
        (Self::FlipMean, "flip_mean"),
        (Self::FlipP99, "flip_p99"),
    ];

    /// The budget name (`max8`, ...).
    #[must_use]
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(m, _)| *m == self)
            .map_or("", |(_, n)| n)
    }

    /// True when larger values are better (the budget is a floor).
    #[must_use]
    pub fn is_floor(self) -> bool {
        matches!(self, Self::Within1 | Self::Psnr8)
    }

    /// True for the FLIP metrics (a render computes FLIP only when a budget uses one).
    #[must_use]
    pub fn is_flip(self) -> bool {
        matches!(self, Self::FlipMean | Self::FlipP99)
    }

    /// The metric's value in `e` and `flip` (`f64::INFINITY` for the PSNR of identical
    /// images; NaN for a FLIP metric without FLIP, which no budget meets).
    #[must_use]
    pub fn of(self, e: &ErrorMetrics, flip: Option<&crate::flip::FlipStats>) -> f64 {
        match self {
            Self::Max8 => f64::from(e.max_abs_lsb),
            Self::Within1 => e.pct_within_1lsb,
            Self::Mean8 => e.mean_abs_lsb,
            Self::Psnr8 => e.psnr_db.unwrap_or(f64::INFINITY),
            Self::FlipMean => flip.map_or(f64::NAN, |f| f.mean),
            Self::FlipP99 => flip.map_or(f64::NAN, |f| f.p99),
        }
    }
}

/// The highest `psnr8` floor a budget takes: two 8-bit images of the largest viewport (8192 x
/// 8192) that differ by one LSB in one channel of one pixel have a PSNR of about 131 dB, so a
/// floor above 200 dB could only be met by identical images (`max8=0` says that).
pub const MAX_PSNR8_DB: f64 = 200.0;

/// One budget: a metric and its limit (a ceiling, or a floor for `within1` and `psnr8`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Budget {
    pub metric: Metric,
    pub limit: f64,
}

impl Budget {
    /// Parses `METRIC=LIMIT` (`max8=1`, `within1=99.5`, `mean8=0.1`, `psnr8=45`,
    /// `flip_mean=0.01`, `flip_p99=0.05`; `mean` and `psnr` are accepted for `mean8` and
    /// `psnr8`).
    pub fn parse(s: &str) -> Result<Self> {
        let names: Vec<&str> = Metric::ALL.iter().map(|(_, n)| *n).collect();
        let (m, v) = s.split_once('=').ok_or_else(|| {
            Error::field(
                "--budget",
                format!("'{s}' is not METRIC=LIMIT (METRIC: {})", names.join(", ")),
            )
        })?;
        let m = m.trim();
        let m = match m {
            "mean" => "mean8",
            "psnr" => "psnr8",
            other => other,
        };
        let metric = Metric::ALL
            .iter()
            .find(|(_, n)| *n == m)
            .map(|(k, _)| *k)
            .ok_or_else(|| {
                Error::field(
                    "--budget",
                    format!("unknown metric '{m}' (known: {})", names.join(", ")),
                )
            })?;
        let limit: f64 = v.trim().parse().map_err(|_| {
            Error::field(
                "--budget",
                format!("'{}' in '{s}' is not a number", v.trim()),
            )
        })?;
        if !limit.is_finite()
            || limit < 0.0
            || (metric == Metric::Within1 && limit > 100.0)
            || (metric.is_flip() && limit > 1.0)
            || (metric == Metric::Psnr8 && limit > MAX_PSNR8_DB)
        {
            return Err(Error::field(
                "--budget",
                format!(
                    "{m}={} is out of range (a finite value >= 0{})",
                    v.trim(),
                    if metric == Metric::Within1 {
                        ", at most 100"
                    } else if metric.is_flip() {
                        ", at most 1"
                    } else if metric == Metric::Psnr8 {
                        ", at most 200: different 8-bit images never come that close; max8=0 \
                         asks for identical ones"
                    } else {
                        ""
                    }
                ),
            ));
        }
        Ok(Self { metric, limit })
    }

    /// How far `value` uses up the budget: <= 1 meets it. Ceilings: value / limit; floors:
    /// `within1`: (100 - value) / (100 - limit), `psnr8`: limit / value. A zero allowance
    /// gives 0 when met exactly and infinity otherwise.
    #[must_use]
    pub fn load(&self, value: f64) -> f64 {
        let ratio = |used: f64, allowed: f64| {
            if used <= 0.0 {
                0.0
            } else if allowed <= 0.0 {
                f64::INFINITY
            } else {
                used / allowed
            }
        };
        if value.is_nan() {
            return f64::INFINITY;
        }
        match self.metric {
            Metric::Max8 | Metric::Mean8 | Metric::FlipMean | Metric::FlipP99 => {
                ratio(value, self.limit)
            }
            Metric::Within1 => ratio(100.0 - value, 100.0 - self.limit),
            Metric::Psnr8 => {
                if value.is_infinite() {
                    0.0
                } else {
                    ratio(self.limit, value.max(0.0))
                }
            }
        }
    }

    /// The budget as `max8<=1` / `within1>=99.5`.
    #[must_use]
    pub fn label(&self) -> String {
        let op = if self.metric.is_floor() { ">=" } else { "<=" };
        format!("{}{op}{}", self.metric.name(), self.limit)
    }
}

/// One searched field: its dotted path and its range (least valid value .. base value).
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Knob {
    pub field: String,
    pub lo: u32,
    pub hi: u32,
}

/// What `tune` is asked.
#[derive(Clone, Debug)]
pub struct TuneSpec {
    /// The scenes (sizes already set); every budget must hold on each.
    pub scenes: Vec<Scene>,
    /// The widest machine: the knobs' upper bounds and every other field.
    pub base: HwConfig,
    pub budgets: Vec<Budget>,
    /// Fields to search (leaf names or dotted paths); empty = every width of the machine
    /// ([`default_knobs`]).
    pub knobs: Vec<String>,
    /// Compare against the ground truth with this many sub-samples per pixel axis instead
    /// of the float reference (0 = the float reference).
    pub truth: u32,
}

/// The metrics of one scene at one point.
#[derive(Clone, Debug, Serialize)]
pub struct SceneError {
    pub scene: String,
    pub max8: u32,
    pub mean8: f64,
    pub within1_pct: f64,
    /// `None`: identical images.
    pub psnr8_db: Option<f64>,
    /// LDR-FLIP mean and 99th percentile (computed only when a budget uses FLIP).
    pub flip_mean: Option<f64>,
    pub flip_p99: Option<f64>,
    /// The largest budget load ([`Budget::load`]) on this scene.
    pub load: f64,
}

/// One setting the search rendered.
#[derive(Clone, Debug, Serialize)]
pub struct Trial {
    /// Order of the trial (0 = the base machine).
    pub index: usize,
    /// `base`, `bisect`, `combine`, `repair`, `descend`, `trade`, `verify`.
    pub phase: &'static str,
    /// The knobs' values, in [`TuneResult::knobs`] order.
    pub values: Vec<u32>,
    pub area_ge: u64,
    /// Sum of the knobs' values.
    pub total_bits: u64,
    pub scenes: Vec<SceneError>,
    /// Every budget met on every scene.
    pub meets: bool,
    /// Every scene rendered (a point that misses the budget on one scene may skip the rest).
    pub complete: bool,
}

impl Trial {
    /// The largest budget load over the scenes.
    #[must_use]
    pub fn load(&self) -> f64 {
        self.scenes.iter().map(|s| s.load).fold(0.0, f64::max)
    }
}

/// The outcome of [`tune`].
#[derive(Clone, Debug, Serialize)]
pub struct TuneResult {
    pub knobs: Vec<Knob>,
    pub budgets: Vec<Budget>,
    /// `reference` (hardware vs float reference) or `truth` (hardware vs ground truth).
    pub against: &'static str,
    pub scenes: Vec<String>,
    /// Every trial, in order (the last is the verification).
    pub trials: Vec<Trial>,
    /// Renders used (one per scene per distinct point, plus the verification).
    pub renders: u64,
    /// Points of the full grid of the knobs' ranges and the renders it would take (one per
    /// scene per point); floating point, exact below 2^53.
    pub grid_points: f64,
    pub grid_renders: f64,
    /// The base machine's and the found machine's area.
    pub base_area_ge: u64,
    /// The index into `trials` of the verified best point.
    pub best: usize,
    /// Per knob: whether its least value changed some metric of some scene (false: the
    /// scenes do not exercise it, so it went to its least value at no error).
    pub exercised: Vec<bool>,
    /// The found machine (`name = "tuned"`).
    #[serde(skip)]
    pub machine: HwConfig,
}

impl TuneResult {
    /// The verified best trial.
    #[must_use]
    pub fn best_trial(&self) -> &Trial {
        &self.trials[self.best]
    }
}

/// The dotted paths of every integer width of `base` with room to search (its least valid
/// value below its value), in the config's order.
pub fn default_knobs(base: &HwConfig) -> Result<Vec<Knob>> {
    let mut out = Vec::new();
    for (path, v) in hwconfig::fields(base) {
        if !hwconfig::is_width(&path) {
            continue;
        }
        if let Ok(hi) = v.parse::<u32>() {
            let k = knob_range(base, &path, hi)?;
            if k.lo < k.hi {
                out.push(k);
            }
        }
    }
    Ok(out)
}

/// The knob of `name` (a leaf name or a dotted path) on `base`.
pub fn knob(base: &HwConfig, name: &str) -> Result<Knob> {
    let fields = hwconfig::fields(base);
    let found = fields
        .iter()
        .find(|(p, _)| p == name)
        .or_else(|| {
            fields
                .iter()
                .find(|(p, _)| p.rsplit('.').next() == Some(name))
        })
        .ok_or_else(|| {
            Error::field(
                "--knob",
                format!(
                    "'{name}' is not a hw config field{}",
                    hwconfig::did_you_mean(
                        name,
                        fields
                            .iter()
                            .map(|(p, _)| p.rsplit('.').next().unwrap_or(p))
                    )
                ),
            )
        })?;
    let hi: u32 = found.1.parse().map_err(|_| {
        Error::field(
            "--knob",
            format!("'{}' = {} is not an integer field", found.0, found.1),
        )
    })?;
    knob_range(base, &found.0, hi)
}

fn knob_range(base: &HwConfig, path: &str, hi: u32) -> Result<Knob> {
    let mut fields = hwconfig::IntFields::of(base);
    let mut lo = hi;
    while lo > 0 && fields.set(path, i64::from(lo - 1)).is_ok() {
        lo -= 1;
    }
    Ok(Knob {
        field: path.to_string(),
        lo,
        hi,
    })
}

/// The machine of `base` with the knobs at `values`, set one after another in knob order,
/// each change validated; `None` when one does not validate (a field range that depends on
/// another field).
fn machine(base: &HwConfig, knobs: &[Knob], values: &[u32]) -> Option<HwConfig> {
    let mut fields = hwconfig::IntFields::of(base);
    let mut c = None;
    for (k, v) in knobs.iter().zip(values) {
        let v = i64::from(*v);
        if v != fields.get(&k.field)? {
            c = Some(fields.set(&k.field, v).ok()?);
        }
    }
    Some(c.unwrap_or_else(|| base.clone()))
}

fn area(c: &HwConfig) -> u64 {
    hw_model::datapath::total_area(&hw_model::datapath::units(c))
}

/// The search state: the scenes' prepared maps and the cache of rendered points.
struct Search<'a> {
    spec: &'a TuneSpec,
    knobs: Vec<Knob>,
    maps: Vec<Maps>,
    cache: HashMap<Vec<u32>, Option<usize>>,
    /// Per knob: it reaches the float passes (not [`crate::render::float_blind`]).
    reaches: Vec<bool>,
    /// Per scene: its float passes, by the values of the knobs that reach them.
    float_passes: Vec<FloatPassCache<Vec<u32>>>,
    trials: Vec<Trial>,
    renders: u64,
    progress: &'a mut dyn FnMut(&Trial),
}

impl Search<'_> {
    /// Renders every scene at `values` (unless cached); the trial's index, `None` when the
    /// point is not a valid machine.
    /// `full`: render every scene even after one misses the budget (the repair compares
    /// loads); otherwise stop at the first scene that misses it.
    fn eval(&mut self, phase: &'static str, values: &[u32], full: bool) -> Result<Option<usize>> {
        if let Some(&t) = self.cache.get(values) {
            match t {
                Some(i) if full && !self.trials[i].complete => {}
                _ => return Ok(t),
            }
        }
        let Some(cfg) = machine(&self.spec.base, &self.knobs, values) else {
            self.cache.insert(values.to_vec(), None);
            return Ok(None);
        };
        let t = self.run(phase, values, &cfg, false, full)?;
        self.cache.insert(values.to_vec(), Some(t));
        Ok(Some(t))
    }

    /// Renders every scene on `cfg` and records the trial.
    fn run(
        &mut self,
        phase: &'static str,
        values: &[u32],
        cfg: &HwConfig,
        timing: bool,
        full: bool,
    ) -> Result<usize> {
        let spec = self.spec;
        let mut scenes = Vec::with_capacity(spec.scenes.len());
        let key: Vec<u32> = values
            .iter()
            .zip(&self.reaches)
            .filter(|(_, &r)| r)
            .map(|(&v, _)| v)
            .collect();
        for ((sc, maps), kept) in spec
            .scenes
            .iter()
            .zip(&mut self.maps)
            .zip(&mut self.float_passes)
        {
            maps.ensure_texel_bits(cfg.trilinear.texel_bits);
            maps.ensure_offset_bits(cfg.shading.vector.offset_int_bits);
            let opts = RenderOptions {
                truth: spec.truth,
                timing,
                keep_events: false,
                float_passes: kept.get(&key),
                ..RenderOptions::default()
            };
            let r = render(sc, maps, cfg, &opts)?;
            kept.keep(key.clone(), sc, &r, &opts);
            self.renders += 1;
            let e = if spec.truth > 0 {
                match &r.truth_image {
                    Some(t) => compare(&r.hw_image, t, 8, Some(&r.mask)),
                    None => {
                        return Err(Error::field(
                            "--truth",
                            format!(
                                "scene '{}' has no roughness or NDF material, so its ground truth is its float reference: drop --truth",
                                sc.name
                            ),
                        ))
                    }
                }
            } else {
                r.stats
                    .error_8bit
                    .clone()
                    .ok_or_else(|| Error::msg(format!("scene '{}': no reference", sc.name)))?
            };
            let flip = if spec.budgets.iter().any(|b| b.metric.is_flip()) {
                let target = if spec.truth > 0 {
                    r.truth_image.as_ref()
                } else {
                    r.ref_image.as_ref()
                };
                target
                    .and_then(|t| crate::flip::flip(&r.hw_image, t, Some(&r.mask)))
                    .map(|f| f.stats)
            } else {
                None
            };
            let load = spec
                .budgets
                .iter()
                .map(|b| b.load(b.metric.of(&e, flip.as_ref())))
                .fold(0.0, f64::max);
            scenes.push(SceneError {
                scene: sc.name.clone(),
                max8: e.max_abs_lsb,
                mean8: e.mean_abs_lsb,
                within1_pct: e.pct_within_1lsb,
                psnr8_db: e.psnr_db,
                flip_mean: flip.as_ref().map(|f| f.mean),
                flip_p99: flip.as_ref().map(|f| f.p99),
                load,
            });
            if !full && load > 1.0 {
                break;
            }
        }
        let complete = scenes.len() == spec.scenes.len();
        let meets = complete && scenes.iter().all(|s| s.load <= 1.0);
        let t = Trial {
            index: self.trials.len(),
            phase,
            values: values.to_vec(),
            area_ge: area(cfg),
            total_bits: values.iter().map(|&v| u64::from(v)).sum(),
            scenes,
            meets,
            complete,
        };
        (self.progress)(&t);
        self.trials.push(t);
        Ok(self.trials.len() - 1)
    }

    fn meets(&mut self, phase: &'static str, values: &[u32]) -> Result<bool> {
        Ok(self
            .eval(phase, values, false)?
            .is_some_and(|t| self.trials[t].meets))
    }

    /// Objective: area, then total bits.
    fn cost(&self, t: usize) -> (u64, u64) {
        (self.trials[t].area_ge, self.trials[t].total_bits)
    }
}

/// Trades (one bit off a knob, one onto a sensitive knob) tried per descent round at most.
const MAX_TRADES_PER_ROUND: usize = 32;

/// The largest budget load of a one-bit-lower point for which a trade is tried.
const TRADE_LOAD: f64 = 2.0;

/// Searches the least-area machine meeting `spec`'s budgets on every scene; `progress` sees
/// each trial as it is rendered.
pub fn tune(spec: &TuneSpec, progress: &mut dyn FnMut(&Trial)) -> Result<TuneResult> {
    if spec.scenes.is_empty() {
        return Err(Error::field("--scene", "give at least one scene"));
    }
    if spec.budgets.is_empty() {
        return Err(Error::field(
            "--budget",
            "give at least one budget, e.g. max8=1",
        ));
    }
    let knobs = if spec.knobs.is_empty() {
        default_knobs(&spec.base)?
    } else {
        let mut v: Vec<Knob> = Vec::new();
        for n in &spec.knobs {
            let k = knob(&spec.base, n)?;
            if v.iter().any(|o| o.field == k.field) {
                return Err(Error::field("--knob", format!("'{}' given twice", k.field)));
            }
            v.push(k);
        }
        v
    };
    if knobs.is_empty() {
        return Err(Error::field("--knob", "no knob has room to search"));
    }
    let grid_points = knobs
        .iter()
        .map(|k| f64::from(k.hi - k.lo + 1))
        .product::<f64>();
    let grid_renders = grid_points * spec.scenes.len() as f64;
    let reaches: Vec<bool> = knobs
        .iter()
        .map(|k| !crate::render::float_blind(&k.field))
        .collect();
    // The scenes share the command's budget for kept float passes; none are kept when every
    // knob reaches them (every trial would have its own key).
    let scene_budget = if reaches.contains(&false) {
        crate::render::float_pass_budget() / spec.scenes.len().max(1) as u64
    } else {
        0
    };
    let mut s = Search {
        spec,
        maps: spec
            .scenes
            .iter()
            .map(|sc| Maps::new(sc, spec.base.trilinear.texel_bits))
            .collect(),
        knobs: knobs.clone(),
        cache: HashMap::new(),
        reaches,
        float_passes: spec
            .scenes
            .iter()
            .map(|_| FloatPassCache::new(scene_budget))
            .collect(),
        trials: Vec::new(),
        renders: 0,
        progress,
    };
    let hi: Vec<u32> = knobs.iter().map(|k| k.hi).collect();
    let base_t = s
        .eval("base", &hi, true)?
        .ok_or_else(|| Error::msg("the base machine does not validate"))?;
    if !s.trials[base_t].meets {
        let worst = &s.trials[base_t];
        return Err(Error::field(
            "--budget",
            format!(
                "the base machine '{}' itself misses the budget (largest load {:.3} > 1): no narrower machine can meet it; relax the budget{}",
                spec.base.name,
                worst.load(),
                if spec.truth > 0 { " (against the truth the float model's own error counts)" } else { "" }
            ),
        ));
    }
    let base_metrics = metrics_key(&s.trials[base_t]);

    // 1. Per-knob bisection from the base: the least value first (a knob the scenes do not
    // exercise passes there at once), then bisection above it.
    let mut minima = hi.clone();
    let mut sensitive = vec![false; knobs.len()];
    for (i, k) in knobs.iter().enumerate() {
        let mut p = hi.clone();
        p[i] = k.lo;
        if s.meets("bisect", &p)? {
            minima[i] = k.lo;
            sensitive[i] = s
                .cache
                .get(&p)
                .copied()
                .flatten()
                .map(|t| metrics_key(&s.trials[t]))
                != Some(base_metrics.clone());
            continue;
        }
        sensitive[i] = true;
        let (mut lo, mut up) = (k.lo + 1, k.hi);
        while lo < up {
            let mid = lo + (up - lo) / 2;
            p[i] = mid;
            if s.meets("bisect", &p)? {
                up = mid;
            } else {
                lo = mid + 1;
            }
        }
        minima[i] = up;
    }

    // 2. Combine; when the errors add up past the budget, repair: a margin of m bits over
    // the minima on every sensitive knob (m = 1, 2, ...; capped at the base).
    let mut cur = minima.clone();
    let mut cur_t = s.eval("combine", &cur, true)?;
    let mut margin = 0;
    while !cur_t.is_some_and(|t| s.trials[t].meets) {
        margin += 1;
        let p: Vec<u32> = (0..knobs.len())
            .map(|i| {
                if sensitive[i] {
                    (minima[i] + margin).min(knobs[i].hi)
                } else {
                    minima[i]
                }
            })
            .collect();
        if p == cur {
            // Every sensitive knob is back at the base: fall back to the base machine.
            cur = hi.clone();
            cur_t = Some(base_t);
            break;
        }
        cur_t = s.eval("repair", &p, true)?;
        cur = p;
    }
    let mut cur_t = cur_t.unwrap_or(base_t);

    // 3. Descent in rounds: each knob one bit lower (largest area saving first), kept when
    // the budget holds; then one-for-one trades of a bit whose loss costs little error for
    // a bit of a cheaper sensitive knob; until a round changes nothing.
    loop {
        let mut moved = false;
        for i in order_by_saving(&s, &cur) {
            if cur[i] == knobs[i].lo {
                continue;
            }
            let mut p = cur.clone();
            p[i] -= 1;
            if let Some(t) = s.eval("descend", &p, false)? {
                if s.trials[t].meets && s.cost(t) < s.cost(cur_t) {
                    cur = p;
                    cur_t = t;
                    moved = true;
                }
            }
        }
        if moved {
            continue;
        }
        let mut attempts = 0;
        'trade: for i in order_by_saving(&s, &cur) {
            let mut down = cur.clone();
            down[i] -= 1;
            // Only a bit whose loss alone stays near the budget is worth a trade.
            let near = s
                .cache
                .get(&down)
                .copied()
                .flatten()
                .is_some_and(|t| s.trials[t].load() <= TRADE_LOAD);
            if !near {
                continue;
            }
            for j in 0..knobs.len() {
                if j == i || !sensitive[j] || cur[j] >= knobs[j].hi {
                    continue;
                }
                if attempts == MAX_TRADES_PER_ROUND {
                    break 'trade;
                }
                let mut p = down.clone();
                p[j] += 1;
                let Some(c) = machine(&spec.base, &knobs, &p) else {
                    continue;
                };
                if area(&c) >= s.trials[cur_t].area_ge {
                    continue;
                }
                attempts += 1;
                if let Some(t) = s.eval("trade", &p, false)? {
                    if s.trials[t].meets && s.cost(t) < s.cost(cur_t) {
                        cur = p;
                        cur_t = t;
                        moved = true;
                        break 'trade;
                    }
                }
            }
        }
        if !moved {
            break;
        }
    }

    // 4. Verify: a fresh full run (with the timing model) of the best point.
    let mut found = machine(&spec.base, &knobs, &cur)
        .ok_or_else(|| Error::msg("the found point does not validate"))?;
    found.name = "tuned".into();
    let v = s.run("verify", &cur, &found, true, true)?;
    if !s.trials[v].meets || metrics_key(&s.trials[v]) != metrics_key(&s.trials[cur_t]) {
        return Err(Error::msg(
            "verification failed: the final run of the found machine differs from its search run",
        ));
    }
    Ok(TuneResult {
        knobs,
        budgets: spec.budgets.clone(),
        against: if spec.truth > 0 { "truth" } else { "reference" },
        scenes: spec.scenes.iter().map(|sc| sc.name.clone()).collect(),
        renders: s.renders,
        grid_points,
        grid_renders,
        base_area_ge: s.trials[base_t].area_ge,
        best: v,
        exercised: sensitive,
        trials: s.trials,
        machine: found,
    })
}

/// The metrics of a trial, bit for bit (to compare two renders).
fn metrics_key(t: &Trial) -> Vec<(u32, u64, u64, Option<u64>)> {
    t.scenes
        .iter()
        .map(|e| {
            (
                e.max8,
                e.mean8.to_bits(),
                e.within1_pct.to_bits(),
                e.psnr8_db.map(f64::to_bits),
            )
        })
        .collect()
}

/// The knobs above their least value, by the area one bit less saves (largest first, then
/// in knob order).
fn order_by_saving(s: &Search<'_>, cur: &[u32]) -> Vec<usize> {
    let here = machine(&s.spec.base, &s.knobs, cur).map_or(0, |c| area(&c));
    let mut v: Vec<(u64, usize)> = (0..s.knobs.len())
        .filter(|&i| cur[i] > s.knobs[i].lo)
        .map(|i| {
            let mut p = cur.to_vec();
            p[i] -= 1;
            let saving =
                machine(&s.spec.base, &s.knobs, &p).map_or(0, |c| here.saturating_sub(area(&c)));
            (saving, i)
        })
        .collect();
    v.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    v.into_iter().map(|(_, i)| i).collect()
}
