//! Loading, printing and editing [`HwConfig`]s: presets, TOML files with a `base` preset and
//! partial overrides, and the by-name field edits that `texsim sweep --vary` uses.

use crate::{Error, Result};
use hw_model::config::PRESETS;
use hw_model::HwConfig;
use std::path::Path;

/// Resolves `spec`: a preset name, or a path to a TOML file. A file may name a `base` preset
/// (default `texram16`) and override any subset of fields; unknown fields are errors.
///
/// ```
/// let hw = texsim::hwconfig::resolve("d3d11")?;
/// assert_eq!(hw.trilinear.weight_bits, 8);
/// assert!(texsim::hwconfig::resolve("no-such-preset").is_err());
/// # Ok::<(), texsim::Error>(())
/// ```
pub fn resolve(spec: &str) -> Result<HwConfig> {
    if let Some(c) = HwConfig::preset(spec) {
        return Ok(c);
    }
    let path = Path::new(spec);
    if !path.exists() {
        return Err(Error::msg(format!(
            "hw config '{spec}' is neither a preset ({}) nor an existing file",
            PRESETS.join(", ")
        )));
    }
    let text = crate::budget::read_text(path, "a hardware TOML file")?;
    parse(&text).map_err(|e| e.context(path.display()))
}

/// Parses a hw config TOML text (see [`resolve`]). Every error names the field and, when the
/// field is in `text`, its line and column.
pub fn parse(text: &str) -> Result<HwConfig> {
    let mut table: toml::Table =
        toml::from_str(text).map_err(|e| Error::msg(crate::error::toml_message(text, &e)))?;
    let spans = key_spans(text);
    let at = |field: &str, e: Error| match locate(&spans, field) {
        Some(offset) => e.context(crate::error::text_position(text, offset)),
        None => e,
    };
    let base_name = match table.remove("base") {
        None => "texram16".to_string(),
        Some(toml::Value::String(s)) => s,
        Some(v) => {
            return Err(at(
                "base",
                Error::field("base", format!("expected a preset name, found {v}")),
            ))
        }
    };
    let base = HwConfig::preset(&base_name).ok_or_else(|| {
        at(
            "base",
            Error::field(
                "base",
                format!(
                    "unknown preset '{base_name}' (presets: {})",
                    PRESETS.join(", ")
                ),
            ),
        )
    })?;
    let given_name = table.get("name").cloned();
    match &given_name {
        None | Some(toml::Value::String(_)) => {}
        Some(v) => {
            return Err(at(
                "name",
                Error::field("name", format!("expected a string, found {v}")),
            ))
        }
    }
    if matches!(&given_name, Some(toml::Value::String(n)) if n.trim().is_empty()) {
        return Err(at("name", Error::field("name", "is empty")));
    }
    let base_table = to_table(&base);
    let mut merged = base_table.clone();
    merge(&mut merged, table.clone(), "").map_err(|(path, e)| at(&path, e))?;
    if !matches!(given_name, Some(toml::Value::String(_))) {
        let custom = toml::Value::String(format!("{base_name}+custom"));
        merged.insert("name".into(), custom);
    }
    let cfg: HwConfig = match toml::Value::Table(merged).try_into() {
        Ok(c) => c,
        Err(e) => return Err(culprit(&base_table, &table, &at, &e)),
    };
    cfg.validate().map_err(|e| {
        let field = e.field.clone();
        at(&field, e.into())
    })?;
    // The name is what every summary reports: a preset's name must mean that preset.
    if let Some(p) = HwConfig::preset(&cfg.name) {
        if given_name.is_some() && p != cfg {
            return Err(at(
                "name",
                Error::field(
                    "name",
                    format!(
                        "'{}' is the name of a preset, but this configuration (base '{base_name}' with its overrides) differs from it; give it a name of its own",
                        cfg.name
                    ),
                ),
            ));
        }
    }
    Ok(cfg)
}

/// The error of the first leaf of `user` that does not deserialize on its own over `base`
/// (base values are valid, so a failing leaf is the one at fault), located by `at`.
fn culprit(
    base: &toml::Table,
    user: &toml::Table,
    at: &dyn Fn(&str, Error) -> Error,
    whole: &toml::de::Error,
) -> Error {
    let mut leaves = Vec::new();
    leaf_values(user, "", &mut leaves);
    for (path, value) in leaves {
        let mut one = base.clone();
        let shown = value.to_string();
        let is_str = value.is_str();
        if !set_leaf(&mut one, &path, value) {
            continue;
        }
        if let Err(e) = toml::Value::Table(one).try_into::<HwConfig>() {
            let mut msg = e.message().trim_end().replace('\n', " ");
            // A number or a table where a name belongs: serde's message lists no names.
            if !is_str && msg.contains("variant") {
                if let Some(names) = variant_names(base, &path) {
                    msg = format!("{shown} is not a name: {names}");
                }
            }
            return at(&path, Error::field(&path, msg));
        }
    }
    Error::msg(whole.to_string().trim_end().replace('\n', " "))
}

/// `expected one of `a`, `b`, ...`: the names an enum field at dotted `path` of `base` takes,
/// from serde's message for a name it cannot take.
fn variant_names(base: &toml::Table, path: &str) -> Option<String> {
    let mut one = base.clone();
    set_leaf(&mut one, path, toml::Value::String("\u{1}".into())).then_some(())?;
    let e = toml::Value::Table(one).try_into::<HwConfig>().err()?;
    let msg = e.message().trim_end().replace('\n', " ");
    msg.find("expected one of").map(|i| msg[i..].to_string())
}

/// Sets the leaf at dotted `path` of `t` (its tables must exist); false if they do not.
fn set_leaf(t: &mut toml::Table, path: &str, value: toml::Value) -> bool {
    match path.split_once('.') {
        None => {
            t.insert(path.to_string(), value);
            true
        }
        Some((head, rest)) => match t.get_mut(head) {
            Some(toml::Value::Table(s)) => set_leaf(s, rest, value),
            _ => false,
        },
    }
}

/// Every leaf of `t` (arrays are leaves) as (dotted path, value).
fn leaf_values(t: &toml::Table, prefix: &str, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in t {
        let path = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(s) => leaf_values(s, &path, out),
            other => out.push((path, other.clone())),
        }
    }
}

/// Every key path of `text` with the byte offset of its value (tables: of their header), read
/// line by line: `[table]` headers, `key = value` and dotted keys, one level of inline table.
/// Only used to point an error at a line; a key it cannot find gets no position.
fn key_spans(text: &str) -> Vec<(String, usize)> {
    fn key_path(k: &str) -> String {
        k.split('.')
            .map(|p| p.trim().trim_matches(|c| c == '"' || c == '\''))
            .collect::<Vec<_>>()
            .join(".")
    }
    fn join(a: &str, b: &str) -> String {
        if a.is_empty() {
            b.to_string()
        } else {
            format!("{a}.{b}")
        }
    }
    let mut out = Vec::new();
    let mut header = String::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let t = line.trim_start();
        let lead = line.len() - t.len();
        if t.starts_with('#') {
            continue;
        }
        if let Some(h) = t.strip_prefix('[') {
            let h = h.trim_start_matches('[');
            header = key_path(h.split(']').next().unwrap_or(""));
            out.push((header.clone(), start + lead));
            continue;
        }
        let Some((k, v)) = t.split_once('=') else {
            continue;
        };
        let path = join(&header, &key_path(k));
        let v_at = start + lead + k.len() + 1 + (v.len() - v.trim_start().len());
        out.push((path.clone(), v_at));
        let Some(inner) = v.trim_start().strip_prefix('{') else {
            continue;
        };
        let mut at = v_at + 1;
        for pair in inner.split([',', '}']) {
            if let Some((ik, iv)) = pair.split_once('=') {
                let iv_at = at + ik.len() + 1 + (iv.len() - iv.trim_start().len());
                out.push((join(&path, &key_path(ik)), iv_at));
            }
            at += pair.len() + 1;
        }
    }
    out
}

/// The offset of `field` in the text: its exact dotted path, else the one key whose path ends
/// with it (leaf names are unique, and validation names some fields by a partial path).
fn locate(spans: &[(String, usize)], field: &str) -> Option<usize> {
    if let Some((_, o)) = spans.iter().find(|(p, _)| p == field) {
        return Some(*o);
    }
    let suffix = format!(".{field}");
    let mut hits = spans.iter().filter(|(p, _)| p.ends_with(&suffix));
    match (hits.next(), hits.next()) {
        (Some((_, o)), None) => Some(*o),
        _ => None,
    }
}

fn to_table(c: &HwConfig) -> toml::Table {
    match toml::Value::try_from(c) {
        Ok(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    }
}

/// Merges `over` into `into`; every key of `over` must exist in `into` with the same shape.
/// An error comes with the dotted path at fault.
fn merge(
    into: &mut toml::Table,
    over: toml::Table,
    prefix: &str,
) -> std::result::Result<(), (String, Error)> {
    for (k, v) in over {
        let path = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match (into.get_mut(&k), v) {
            (Some(toml::Value::Table(dst)), toml::Value::Table(src)) => merge(dst, src, &path)?,
            (Some(toml::Value::Table(_)), other) => {
                let e = Error::field(&path, format!("expected a table, found {other}"));
                return Err((path, e));
            }
            (Some(dst), v) => *dst = v,
            (None, _) => {
                if let Some(why) = removed_field(&path) {
                    return Err((path.clone(), Error::field(&path, why)));
                }
                let hint = did_you_mean(&k, into.keys().map(String::as_str));
                let e = Error::field(&path, format!("unknown field{hint}"));
                return Err((path, e));
            }
        }
    }
    Ok(())
}

/// The config as TOML text (what `texsim hw show` prints).
pub fn to_toml(c: &HwConfig) -> String {
    toml::to_string_pretty(c).unwrap_or_default()
}

/// Every leaf field as (dotted path, value).
pub fn fields(c: &HwConfig) -> Vec<(String, String)> {
    let mut leaves = Vec::new();
    leaf_values(&to_table(c), "", &mut leaves);
    leaves
        .into_iter()
        .map(|(path, v)| match v {
            toml::Value::String(s) => (path, s),
            other => (path, other.to_string()),
        })
        .collect()
}

/// True for the dotted paths of the widths and iteration counts of a unit (`*_bits` except
/// the timing model's `*_bits_per_cycle`, and `*_iterations`).
#[must_use]
pub fn is_width(path: &str) -> bool {
    let leaf = path.rsplit('.').next().unwrap_or(path);
    (leaf.ends_with("_bits") || leaf.ends_with("_iterations")) && !path.starts_with("timing.")
}

/// The field an alias names (`frame` is `frame_kind`, `roughness` is `rough_variant`), or
/// `name` itself.
fn unalias(name: &str) -> &str {
    match name {
        "frame" => "frame_kind",
        "roughness" => "rough_variant",
        other => other,
    }
}

/// The dotted path of the field `name` (a leaf name, a dotted path or an alias, [`unalias`])
/// among `fields` ([`fields`]); `name` itself when no field has it.
#[must_use]
pub fn dotted_path(fields: &[(String, String)], name: &str) -> String {
    let name = unalias(name);
    fields
        .iter()
        .find(|(p, _)| p == name || p.rsplit('.').next() == Some(name))
        .map_or_else(|| name.to_string(), |(p, _)| p.clone())
}

/// Returns `c` with the field `name` (a unique leaf name like `weight_bits`, or a dotted path
/// like `trilinear.weight_bits`) set to `value`, validated.
/// `frame` is an alias of `frame_kind` (`--vary frame=natural,unit,main`).
///
/// ```
/// let hw = texsim::hwconfig::resolve("texram16")?;
/// let c = texsim::hwconfig::set_field(&hw, "trilinear.weight_bits", "6")?;
/// assert_eq!(c.trilinear.weight_bits, 6);
/// let e = texsim::hwconfig::set_field(&hw, "weight_bit", "6").unwrap_err();
/// assert!(e.to_string().contains("did you mean 'weight_bits'"));
/// # Ok::<(), texsim::Error>(())
/// ```
pub fn set_field(c: &HwConfig, name: &str, value: &str) -> Result<HwConfig> {
    let name = unalias(name);
    if let Some(why) = removed_field(name) {
        return Err(Error::field(name, why));
    }
    let all = fields(c);
    let matches: Vec<&String> = all
        .iter()
        .map(|(p, _)| p)
        .filter(|p| *p == name || p.rsplit('.').next() == Some(name))
        .collect();
    let path = match matches.as_slice() {
        [one] => (*one).clone(),
        [] => {
            let leaf_names = all.iter().filter_map(|(p, _)| p.rsplit('.').next());
            let paths = all.iter().map(|(p, _)| p.as_str());
            let hint = if name.contains('.') {
                did_you_mean(name, paths)
            } else {
                did_you_mean(name, leaf_names)
            };
            return Err(Error::field(
                name,
                format!("no such hw config field{hint} (`texsim hw show texram16` lists them all)"),
            ));
        }
        many => {
            let names: Vec<&str> = many.iter().map(|s| s.as_str()).collect();
            return Err(Error::field(
                name,
                format!("ambiguous, use one of {}", names.join(", ")),
            ));
        }
    };
    let mut table = to_table(c);
    let (cur, leaf) =
        parent_table(&mut table, &path).ok_or_else(|| Error::field(&path, "not a table"))?;
    let new = match cur.get(leaf) {
        // A hand-set cycle field going back to its derived value.
        Some(toml::Value::Integer(_)) if value.trim() == "derived" => {
            toml::Value::String("derived".into())
        }
        Some(toml::Value::Integer(_)) => toml::Value::Integer(
            value
                .trim()
                .parse()
                .map_err(|_| Error::field(&path, format!("'{value}' is not an integer")))?,
        ),
        Some(toml::Value::Boolean(_)) => toml::Value::Boolean(
            value
                .trim()
                .parse()
                .map_err(|_| Error::field(&path, format!("'{value}' is not true/false")))?,
        ),
        _ => toml::Value::String(value.trim().to_string()),
    };
    cur.insert(leaf.to_string(), new);
    config_of(table, &path, value)
}

/// The table holding the field at the dotted `path`, and the field's own name; `None` when a
/// part of the path before it is not a table.
fn parent_table<'t, 'p>(
    table: &'t mut toml::Table,
    path: &'p str,
) -> Option<(&'t mut toml::Table, &'p str)> {
    let (tables, leaf) = split_path(path);
    let mut cur = table;
    for p in tables {
        cur = cur.get_mut(p)?.as_table_mut()?;
    }
    Some((cur, leaf))
}

/// The dotted `path` as the names of the tables it walks through and the field's own name.
fn split_path(path: &str) -> (impl Iterator<Item = &str>, &str) {
    let (tables, leaf) = path.rsplit_once('.').unwrap_or(("", path));
    (tables.split('.').filter(|p| !p.is_empty()), leaf)
}

/// The configuration `table` describes, validated; an error names `path`, the field just set
/// to `value`.
fn config_of(table: toml::Table, path: &str, value: &str) -> Result<HwConfig> {
    let cfg: HwConfig = toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| Error::field(path, format!("'{value}': {}", e.message())))?;
    cfg.validate()?;
    Ok(cfg)
}

/// A configuration held as its TOML table for setting integer fields one after another
/// (`texsim tune`'s knobs): [`IntFields::set`] is [`set_field`] of an integer field given by
/// its dotted path, without serialising the configuration and listing its fields again per
/// field.
#[derive(Clone, Debug)]
pub struct IntFields {
    table: toml::Table,
}

impl IntFields {
    /// The fields of `c`.
    #[must_use]
    pub fn of(c: &HwConfig) -> Self {
        Self { table: to_table(c) }
    }

    /// The integer at the dotted `path`; `None` when there is none.
    #[must_use]
    pub fn get(&self, path: &str) -> Option<i64> {
        let (tables, leaf) = split_path(path);
        let mut cur = &self.table;
        for p in tables {
            cur = cur.get(p)?.as_table()?;
        }
        cur.get(leaf)?.as_integer()
    }

    /// The integer at the dotted `path`, to change it.
    fn get_mut(&mut self, path: &str) -> Option<&mut i64> {
        let (t, leaf) = parent_table(&mut self.table, path)?;
        match t.get_mut(leaf)? {
            toml::Value::Integer(v) => Some(v),
            _ => None,
        }
    }

    /// Sets the integer at the dotted `path` to `value` and returns the configuration it makes,
    /// validated, as [`set_field`] does; an error, the field left as it was, when `path` is
    /// not an integer field or the configuration does not validate.
    pub fn set(&mut self, path: &str, value: i64) -> Result<HwConfig> {
        let slot = self
            .get_mut(path)
            .ok_or_else(|| Error::field(path, "not an integer field"))?;
        let old = std::mem::replace(slot, value);
        let made = config_of(self.table.clone(), path, &value.to_string());
        if made.is_err() {
            if let Some(slot) = self.get_mut(path) {
                *slot = old;
            }
        }
        made
    }
}

/// Fields that earlier versions had, with what replaced them: (dotted path, message).
pub const REMOVED_FIELDS: &[(&str, &str)] = &[(
    "timing.texel_bytes",
    "was removed: bytes per texel now follow each map's stored format (texel_bits and the map's channels, e.g. RGBA 16-bit = 8 bytes, see docs/TIMING.md); delete this line, and vary texel_bits (or moment_bits, rough_d_bits) instead",
)];

/// The message of a removed field named by its dotted path or its leaf name.
fn removed_field(name: &str) -> Option<&'static str> {
    REMOVED_FIELDS
        .iter()
        .find(|(p, _)| *p == name || p.rsplit('.').next() == Some(name))
        .map(|(_, why)| *why)
}

/// `; did you mean 'X'?` with the candidate nearest to `name` (Jaro-Winkler similarity at
/// least 0.8, ties to the first), or an empty string.
#[must_use]
pub fn did_you_mean<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> String {
    let mut best: Option<(f64, &str)> = None;
    for c in candidates {
        let score = strsim::jaro_winkler(name, c);
        let better = match best {
            None => true,
            Some((b, _)) => score > b,
        };
        if score >= 0.8 && better {
            best = Some((score, c));
        }
    }
    best.map_or_else(String::new, |(_, c)| format!("; did you mean '{c}'?"))
}

/// `texsim hw cost`: every unit's datapath, delay, latency and area at `c`'s widths and clock
/// target (`hw_model::datapath`), then the totals.
#[must_use]
pub fn cost_text(c: &HwConfig) -> String {
    use hw_model::datapath::{max_latency, total_area, units, Cycles, TOP_LEVEL};
    use std::fmt::Write as _;
    let g = c.timing.gate_levels_per_cycle;
    let reports = units(c);
    let mut t = String::new();
    let _ = writeln!(
        t,
        "hw '{}': gate_levels_per_cycle = {g}; a stage takes ceil(delay / {g}) cycles unless its \
         cycle field is hand-set (marked 'set'); area in gate equivalents (NAND2), a proxy; \
         a stage line is one copy (xN: N copies in series)",
        c.name
    );
    let _ = writeln!(
        t,
        "{:<26} {:>6} {:>8} {:>10}",
        "unit", "delay", "latency", "area"
    );
    for r in &reports {
        let star = if TOP_LEVEL.contains(&r.name) {
            " *"
        } else {
            ""
        };
        let _ = writeln!(
            t,
            "{:<26} {:>6} {:>8} {:>10}{star}",
            r.name, r.delay, r.latency, r.area
        );
        // Consecutive identical stages (a unit instantiated twice in series) print once.
        let stages = &r.datapath.stages;
        let mut i = 0;
        while i < stages.len() {
            let s = &stages[i];
            let same = stages[i..].iter().take_while(|t| *t == s).count();
            i += same;
            let steps: Vec<String> = s
                .steps
                .iter()
                .map(|step| {
                    step.iter()
                        .map(|p| {
                            if p.count == 1 {
                                p.component.to_string()
                            } else {
                                format!("{}x {}", p.count, p.component)
                            }
                        })
                        .collect::<Vec<_>>()
                        .join(" + ")
                })
                .collect();
            let copies = s.repeat * same as u32;
            let rep = if copies == 1 {
                String::new()
            } else {
                format!(" (x{copies})")
            };
            let how = match s.cycles {
                Cycles::Derived => "",
                Cycles::Fixed(_) => " set",
            };
            let _ = writeln!(
                t,
                "    {}{rep}: {}; delay {}, {} cycle(s){how}, area {}",
                s.name,
                steps.join(" -> "),
                s.delay_once(),
                s.latency_once(g),
                s.area() / u64::from(s.repeat.max(1)),
            );
        }
    }
    let longest = reports.iter().max_by_key(|r| r.latency);
    let _ = writeln!(
        t,
        "total area (units marked *, one per pipeline stage kind): {} GE",
        total_area(&reports)
    );
    if let Some(l) = longest {
        let _ = writeln!(
            t,
            "longest latency: {} cycles ({}); delays in gate levels, latencies in cycles",
            max_latency(&reports),
            l.name
        );
    }
    t
}
