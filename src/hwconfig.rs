//! Loading, printing and editing [`HwConfig`]s: presets, TOML files with a `base` preset and
//! partial overrides, and the by-name field edits that `texsim sweep --vary` uses.

use crate::{Error, Result};
use hw_model::config::PRESETS;
use hw_model::HwConfig;
use std::path::Path;

/// Resolves `spec`: a preset name, or a path to a TOML file. A file may name a `base` preset
/// (default `texram16`) and override any subset of fields; unknown fields are errors.
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
    let text = std::fs::read_to_string(path).map_err(|e| Error::file(path, e))?;
    parse(&text).map_err(|e| e.context(path.display()))
}

/// Parses a hw config TOML text (see [`resolve`]).
pub fn parse(text: &str) -> Result<HwConfig> {
    let mut table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| Error::msg(e.message().to_string()))?;
    let base_name = match table.remove("base") {
        None => "texram16".to_string(),
        Some(toml::Value::String(s)) => s,
        Some(v) => {
            return Err(Error::field(
                "base",
                format!("expected a preset name, found {v}"),
            ))
        }
    };
    let base = HwConfig::preset(&base_name).ok_or_else(|| {
        Error::field(
            "base",
            format!(
                "unknown preset '{base_name}' (presets: {})",
                PRESETS.join(", ")
            ),
        )
    })?;
    let given_name = table.get("name").cloned();
    let mut merged = to_table(&base);
    merge(&mut merged, table, "")?;
    if !matches!(given_name, Some(toml::Value::String(_))) {
        let custom = toml::Value::String(format!("{base_name}+custom"));
        merged.insert("name".into(), custom);
    }
    let cfg: HwConfig = toml::Value::Table(merged)
        .try_into()
        .map_err(|e: toml::de::Error| Error::msg(e.message().to_string()))?;
    cfg.validate()?;
    Ok(cfg)
}

fn to_table(c: &HwConfig) -> toml::Table {
    match toml::Value::try_from(c) {
        Ok(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    }
}

/// Merges `over` into `into`; every key of `over` must exist in `into` with the same shape.
fn merge(into: &mut toml::Table, over: toml::Table, prefix: &str) -> Result<()> {
    for (k, v) in over {
        let path = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match (into.get_mut(&k), v) {
            (Some(toml::Value::Table(dst)), toml::Value::Table(src)) => merge(dst, src, &path)?,
            (Some(toml::Value::Table(_)), other) => {
                return Err(Error::field(
                    &path,
                    format!("expected a table, found {other}"),
                ))
            }
            (Some(dst), v) => *dst = v,
            (None, _) => return Err(Error::field(&path, "unknown field")),
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
    let mut out = Vec::new();
    fn walk(t: &toml::Table, prefix: &str, out: &mut Vec<(String, String)>) {
        for (k, v) in t {
            let path = if prefix.is_empty() {
                k.clone()
            } else {
                format!("{prefix}.{k}")
            };
            match v {
                toml::Value::Table(s) => walk(s, &path, out),
                toml::Value::String(s) => out.push((path, s.clone())),
                other => out.push((path, other.to_string())),
            }
        }
    }
    walk(&to_table(c), "", &mut out);
    out
}

/// Returns `c` with the field `name` (a unique leaf name like `weight_bits`, or a dotted path
/// like `trilinear.weight_bits`) set to `value`, validated.
/// `frame` is an alias of `frame_kind` (`--vary frame=natural,unit,main`).
pub fn set_field(c: &HwConfig, name: &str, value: &str) -> Result<HwConfig> {
    let name = match name {
        "frame" => "frame_kind",
        "roughness" => "rough_variant",
        other => other,
    };
    let all = fields(c);
    let matches: Vec<&String> = all
        .iter()
        .map(|(p, _)| p)
        .filter(|p| *p == name || p.rsplit('.').next() == Some(name))
        .collect();
    let path = match matches.as_slice() {
        [one] => (*one).clone(),
        [] => {
            let names: Vec<&str> = all
                .iter()
                .filter_map(|(p, _)| p.rsplit('.').next())
                .collect();
            return Err(Error::field(
                name,
                format!("no such hw config field (fields: {})", names.join(", ")),
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
    let mut cur = &mut table;
    let parts: Vec<&str> = path.split('.').collect();
    for p in &parts[..parts.len() - 1] {
        cur = match cur.get_mut(*p) {
            Some(toml::Value::Table(t)) => t,
            _ => return Err(Error::field(&path, "not a table")),
        };
    }
    let leaf = parts[parts.len() - 1];
    let new = match cur.get(leaf) {
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
    let cfg: HwConfig = toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| Error::field(&path, format!("'{value}': {}", e.message())))?;
    cfg.validate()?;
    Ok(cfg)
}
