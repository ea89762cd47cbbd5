//! Wavefront OBJ + MTL loading (tobj for the geometry, a small MTL reader of our own for `Kd` and
//! `map_Kd`). Texture V is flipped (`t = 1 - v`) because OBJ's v = 0 is the bottom of the image
//! while texel row 0 is its top row.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

use super::geometry::{fit_camera, fit_light, smooth_normals};
use super::texture::decode_texture;
use super::{Material, Mesh, Scene, TextureImage, WrapMode};
use crate::{Error, Result};

/// Default output size of an OBJ scene.
pub const OBJ_DEFAULT_SIZE: (u32, u32) = (1024, 768);
/// Ambient term of an OBJ scene.
pub const OBJ_AMBIENT: f32 = 0.15;
/// Background of an OBJ scene (dark grey, opaque).
pub const OBJ_BACKGROUND: [f32; 4] = [0.12, 0.12, 0.13, 1.0];

/// Meshes, materials and textures read from one OBJ file (material indices local to this set).
pub(crate) struct ObjParts {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
    pub warnings: Vec<String>,
}

/// Opens a regular file of at most a budget's bytes, with errors naming it.
pub(crate) fn open_regular(path: &Path, what: &str) -> Result<File> {
    crate::budget::open_regular(path, what, crate::budget::max_binary_file_bytes())
}

/// One MTL material as read from the file.
struct MtlEntry {
    name: String,
    kd: Option<[f32; 3]>,
    map_kd: Option<String>,
    /// `bump` / `map_Bump`: a height map (with the `-bm` multiplier as bump scale).
    map_bump: Option<String>,
    /// `Ks` and `Ns` (used by per-pixel shading of bump-mapped materials).
    ks: Option<[f32; 3]>,
    ns: Option<f32>,
    /// The bump map came from `norm` (a tangent-space normal map).
    bump_is_normal_map: bool,
}

fn parse_mtl(path: &Path) -> Result<Vec<MtlEntry>> {
    let text = crate::budget::read_text(path, "an MTL material library")?;
    let mut out: Vec<MtlEntry> = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.trim();
        let lineno = ln + 1;
        let bad = |what: &str| Error::file(path, format!("line {lineno}: {what}"));
        let (key, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
        let rest = rest.trim();
        match key {
            "" => {}
            k if k.starts_with('#') => {}
            "newmtl" => {
                if rest.is_empty() {
                    return Err(bad("newmtl without a name"));
                }
                out.push(MtlEntry {
                    name: rest.to_string(),
                    kd: None,
                    map_kd: None,
                    map_bump: None,
                    ks: None,
                    ns: None,
                    bump_is_normal_map: false,
                });
            }
            "Kd" => {
                let vals: Vec<f32> = rest
                    .split_whitespace()
                    .map(str::parse::<f32>)
                    .collect::<std::result::Result<_, _>>()
                    .map_err(|_| bad(&format!("Kd needs three numbers, got '{rest}'")))?;
                let kd: [f32; 3] = match vals.as_slice() {
                    [r, g, b] => [*r, *g, *b],
                    [g] => [*g; 3],
                    _ => return Err(bad(&format!("Kd needs three numbers, got '{rest}'"))),
                };
                if !kd.iter().all(|c| c.is_finite()) {
                    return Err(bad("Kd is not finite"));
                }
                let cur = out.last_mut().ok_or_else(|| bad("Kd before any newmtl"))?;
                cur.kd = Some(kd);
            }
            "map_Kd" => {
                if rest.is_empty() {
                    return Err(bad("map_Kd without a file name"));
                }
                let cur = out
                    .last_mut()
                    .ok_or_else(|| bad("map_Kd before any newmtl"))?;
                cur.map_kd = Some(rest.to_string());
            }
            // Ks / Ns only matter to bump-mapped materials: malformed values are ignored
            // (as they were before per-pixel shading existed).
            "Ks" => {
                let vals: Vec<f32> = rest
                    .split_whitespace()
                    .filter_map(|v| v.parse::<f32>().ok())
                    .collect();
                let ks = match vals.as_slice() {
                    [r, g, b] => Some([*r, *g, *b]),
                    [g] => Some([*g; 3]),
                    _ => None,
                };
                if let (Some(ks), Some(cur)) = (ks, out.last_mut()) {
                    if ks.iter().all(|c| c.is_finite() && *c >= 0.0) {
                        cur.ks = Some(ks);
                    }
                }
            }
            "Ns" => {
                if let (Ok(ns), Some(cur)) = (rest.parse::<f32>(), out.last_mut()) {
                    if ns.is_finite() && ns >= 0.0 {
                        cur.ns = Some(ns);
                    }
                }
            }
            "bump" | "map_Bump" | "map_bump" => {
                if rest.is_empty() {
                    return Err(bad("bump map without a file name"));
                }
                let cur = out
                    .last_mut()
                    .ok_or_else(|| bad("bump map before any newmtl"))?;
                cur.map_bump = Some(rest.to_string());
                cur.bump_is_normal_map = false;
            }
            "norm" | "map_Norm" | "map_norm" => {
                if rest.is_empty() {
                    return Err(bad("normal map without a file name"));
                }
                let cur = out
                    .last_mut()
                    .ok_or_else(|| bad("normal map before any newmtl"))?;
                cur.map_bump = Some(rest.to_string());
                cur.bump_is_normal_map = true;
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Splits a `map_Kd` argument into (file name, clamp). Options (`-s u v w`, `-o ...`,
/// `-clamp on`, ...) are skipped; a quoted name is unquoted; an unquoted remainder with spaces
/// is kept whole (names with spaces). Returns also the last token as a fallback candidate.
fn parse_map_arg(arg: &str) -> (String, Option<String>, bool) {
    let toks: Vec<&str> = arg.split_whitespace().collect();
    let mut i = 0;
    let mut clamp = false;
    while i < toks.len() && toks[i].starts_with('-') && toks[i].len() > 1 {
        let opt = toks[i];
        i += 1;
        let max_args = match opt {
            "-o" | "-s" | "-t" => 3,
            "-mm" => 2,
            _ => 1,
        };
        if opt == "-clamp" {
            clamp = toks.get(i).is_some_and(|v| v.eq_ignore_ascii_case("on"));
        }
        let numeric = matches!(
            opt,
            "-o" | "-s" | "-t" | "-mm" | "-boost" | "-bm" | "-texres"
        );
        let mut taken = 0;
        // Leave at least one token for the file name.
        while taken < max_args && i + 1 < toks.len() && (!numeric || toks[i].parse::<f64>().is_ok())
        {
            i += 1;
            taken += 1;
        }
    }
    let rest = toks[i.min(toks.len())..].join(" ");
    let unquoted = rest.trim().trim_matches('"').to_string();
    let last = toks.last().map(|s| s.trim_matches('"').to_string());
    let fallback = last.filter(|l| *l != unquoted);
    (unquoted, fallback, clamp)
}

/// Finds the first `v` line of `path` with a non-finite coordinate: (1-based vertex index, line).
fn find_nonfinite_vertex(path: &Path) -> Option<(usize, usize)> {
    let f = File::open(path).ok()?;
    let mut vi = 0;
    for (ln, line) in BufReader::new(f).lines().enumerate() {
        let line = line.ok()?;
        let mut w = line.split_whitespace();
        if w.next() == Some("v") {
            vi += 1;
            if w.take(3)
                .any(|t| t.parse::<f32>().is_ok_and(|x| !x.is_finite()))
            {
                return Some((vi, ln + 1));
            }
        }
    }
    None
}

/// Finds the (1-based) line of the first statement that makes tobj fail with `err`, by
/// re-reading the file with the same rules (numbers per statement, 1-based or negative
/// relative indices within the counts seen so far).
fn locate_obj_error(path: &Path, err: tobj::LoadError) -> Option<usize> {
    use tobj::LoadError as E;
    let mut text = Vec::new();
    File::open(path).ok()?.read_to_end(&mut text).ok()?;
    let (mut nv, mut nt, mut nn) = (0i64, 0i64, 0i64);
    let in_range = |tok: &str, n: i64| {
        tok.is_empty()
            || tok
                .parse::<i64>()
                .is_ok_and(|i| (i > 0 && i <= n) || (i < 0 && -i <= n))
    };
    for (ln, raw) in text.split(|&b| b == b'\n').enumerate() {
        let Ok(line) = std::str::from_utf8(raw) else {
            return (err == E::ReadError).then_some(ln + 1);
        };
        let mut w = line.split_whitespace();
        let key = w.next();
        let floats_ok = |w: std::str::SplitWhitespace, k: usize| {
            w.take(k).filter(|t| t.parse::<f32>().is_ok()).count() == k
        };
        let bad = match key {
            Some("v") => {
                nv += 1;
                matches!(
                    err,
                    E::PositionParseError | E::ColorParseError | E::ScalingByZeroError
                ) && !floats_ok(w, 3)
            }
            Some("vt") => {
                nt += 1;
                err == E::TexcoordParseError && !floats_ok(w, 2)
            }
            Some("vn") => {
                nn += 1;
                err == E::NormalParseError && !floats_ok(w, 3)
            }
            Some("f") => w.any(|v| {
                let mut parts = v.split('/');
                let (a, b, c) = (
                    parts.next().unwrap_or(""),
                    parts.next().unwrap_or(""),
                    parts.next().unwrap_or(""),
                );
                let parses = |t: &str| t.is_empty() || t.parse::<i64>().is_ok();
                match err {
                    E::FaceParseError => {
                        !(parses(a) && parses(b) && parses(c)) || parts.next().is_some()
                    }
                    E::FaceVertexOutOfBounds => !in_range(a, nv) || a.is_empty(),
                    E::FaceTexCoordOutOfBounds => !in_range(b, nt),
                    E::FaceNormalOutOfBounds => !in_range(c, nn),
                    _ => false,
                }
            }),
            _ => false,
        };
        if bad {
            return Some(ln + 1);
        }
    }
    None
}

pub(crate) fn load_obj_parts(path: &Path) -> Result<ObjParts> {
    let file = open_regular(path, "an OBJ file")?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mtl_warnings: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let mtl_error: RefCell<Option<Error>> = RefCell::new(None);
    let mtl_entries: RefCell<Vec<MtlEntry>> = RefCell::new(Vec::new());
    let mtl_dirs: RefCell<Vec<PathBuf>> = RefCell::new(Vec::new());
    let loader = |mtl: &Path| -> tobj::MTLLoadResult {
        let full = dir.join(mtl);
        match parse_mtl(&full) {
            Ok(entries) => {
                let mut mats = Vec::with_capacity(entries.len());
                let mut store = mtl_entries.borrow_mut();
                for e in entries {
                    mats.push(tobj::Material {
                        name: e.name.clone(),
                        ..tobj::Material::default()
                    });
                    store.push(e);
                    mtl_dirs
                        .borrow_mut()
                        .push(full.parent().map(Path::to_path_buf).unwrap_or_default());
                }
                // Into tobj's own map type (a repeated name keeps its last index).
                let map = (mats.iter().enumerate())
                    .map(|(i, m)| (m.name.clone(), i))
                    .collect();
                Ok((mats, map))
            }
            Err(e) if !full.exists() => {
                mtl_warnings.borrow_mut().push(format!(
                    "{}: material library {} not found ({e}); using a default material",
                    path.display(),
                    full.display()
                ));
                Ok((Vec::new(), Default::default()))
            }
            Err(e) => {
                mtl_error.borrow_mut().get_or_insert(e);
                Err(tobj::LoadError::MaterialParseError)
            }
        }
    };
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = BufReader::new(file);
    let res = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &opts, loader)
    }));
    if let Some(e) = mtl_error.borrow_mut().take() {
        return Err(e.context(format!("material library of {}", path.display())));
    }
    let (models, _) = match res {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            let at = locate_obj_error(path, e).map_or_else(String::new, |l| format!("line {l}: "));
            return Err(Error::file(path, format!("malformed OBJ: {at}{e}")));
        }
        Err(_) => return Err(Error::file(path, "malformed OBJ (index out of range)")),
    };
    let mut warnings = mtl_warnings.into_inner();
    let entries = mtl_entries.into_inner();
    let mtl_dirs = mtl_dirs.into_inner();

    // Materials: one per MTL entry, plus a default appended when some mesh has none.
    let mut materials = Vec::with_capacity(entries.len() + 1);
    let mut textures: Vec<TextureImage> = Vec::new();
    let mut tex_cache: BTreeMap<PathBuf, Option<usize>> = BTreeMap::new();
    for (e, mdir) in entries.iter().zip(&mtl_dirs) {
        let mut m = Material {
            name: e.name.clone(),
            ..Material::default()
        };
        if let Some(kd) = e.kd {
            m.kd = kd;
        }
        if let Some(ks) = e.ks {
            m.ks = ks;
        }
        if let Some(ns) = e.ns {
            m.shininess = ns.round().min(65535.0) as u32;
        }
        if let Some(arg) = &e.map_kd {
            let (name, fallback, clamp) = parse_map_arg(arg);
            let mut file = mdir.join(&name);
            if !file.exists() {
                // Fallbacks: Windows separators, then the last token alone.
                let candidates = [Some(name.replace('\\', "/")), fallback];
                if let Some(fb) = candidates
                    .into_iter()
                    .flatten()
                    .map(|f| mdir.join(f))
                    .find(|f| f.exists())
                {
                    file = fb;
                }
            }
            let idx = match tex_cache.get(&file) {
                Some(i) => *i,
                None => {
                    let i = match decode_texture(&file) {
                        Ok(t) => {
                            textures.push(t);
                            Some(textures.len() - 1)
                        }
                        Err(err) => {
                            warnings.push(format!(
                                "texture '{name}' of material '{}' unusable ({err}); using Kd",
                                e.name
                            ));
                            None
                        }
                    };
                    tex_cache.insert(file.clone(), i);
                    i
                }
            };
            if idx.is_some() {
                m.texture = idx;
                if e.kd.is_none() {
                    m.kd = [1.0; 3];
                }
                if clamp {
                    m.wrap_s = WrapMode::ClampToEdge;
                    m.wrap_t = WrapMode::ClampToEdge;
                }
            }
        }
        if let Some(arg) = &e.map_bump {
            let (name, _, _) = parse_map_arg(arg);
            let toks: Vec<&str> = arg.split_whitespace().collect();
            let bm = toks
                .iter()
                .position(|t| *t == "-bm")
                .and_then(|i| toks.get(i + 1))
                .and_then(|v| v.parse::<f32>().ok())
                .filter(|v| v.is_finite());
            let file = mdir.join(&name);
            let idx = match tex_cache.get(&file) {
                Some(i) => *i,
                None => {
                    let i = match decode_texture(&file) {
                        Ok(t) => {
                            textures.push(t);
                            Some(textures.len() - 1)
                        }
                        Err(err) => {
                            warnings.push(format!(
                                "bump map '{name}' of material '{}' unusable ({err}); no bumps",
                                e.name
                            ));
                            None
                        }
                    };
                    tex_cache.insert(file.clone(), i);
                    i
                }
            };
            m.bump = idx;
            m.bump_normal_map = e.bump_is_normal_map;
            if let Some(bm) = bm {
                m.bump_scale = bm;
            }
        }
        materials.push(m);
    }
    let mut default_idx: Option<usize> = None;
    let mut untextured: BTreeMap<usize, usize> = BTreeMap::new();
    let mut meshes = Vec::with_capacity(models.len());
    for model in models {
        let tm = model.mesh;
        if tm.indices.len() < 3 {
            continue;
        }
        let positions: Vec<[f32; 3]> = tm
            .positions
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        if positions.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            let msg = match find_nonfinite_vertex(path) {
                Some((vi, ln)) => format!("vertex {vi} (line {ln}) is not finite"),
                None => "a vertex is not finite".to_string(),
            };
            return Err(Error::file(path, msg));
        }
        let indices: Vec<[u32; 3]> = tm
            .indices
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        let n = positions.len();
        if let Some(bad) = indices.iter().flatten().find(|&&i| i as usize >= n) {
            return Err(Error::file(
                path,
                format!("face index {bad} out of range in '{}'", model.name),
            ));
        }
        let normals =
            if tm.normals.len() == tm.positions.len() && tm.normals.iter().all(|c| c.is_finite()) {
                let smooth = smooth_normals(&positions, &indices);
                tm.normals
                    .chunks_exact(3)
                    .zip(smooth)
                    .map(|(c, s)| {
                        let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
                        if l > 0.0 && l.is_finite() {
                            [c[0] / l, c[1] / l, c[2] / l]
                        } else {
                            s
                        }
                    })
                    .collect()
            } else {
                smooth_normals(&positions, &indices)
            };
        let uvs: Vec<[f32; 2]> = if tm.texcoords.len() == 2 * n {
            if tm.texcoords.iter().any(|c| !c.is_finite()) {
                return Err(Error::file(
                    path,
                    format!("a texture coordinate of '{}' is not finite", model.name),
                ));
            }
            tm.texcoords
                .chunks_exact(2)
                .map(|c| [c[0], 1.0 - c[1]])
                .collect()
        } else {
            Vec::new()
        };
        let mut material = match tm.material_id.filter(|&i| i < materials.len()) {
            Some(i) => i,
            None => *default_idx.get_or_insert_with(|| {
                materials.push(Material::default());
                materials.len() - 1
            }),
        };
        if uvs.is_empty() && materials[material].texture.is_some() {
            warnings.push(format!(
                "{}: mesh '{}' has no texture coordinates; material '{}' rendered with Kd only",
                path.display(),
                model.name,
                materials[material].name
            ));
            let src = material;
            material = *untextured.entry(src).or_insert_with(|| {
                let mut m = materials[src].clone();
                m.texture = None;
                m.name = format!("{} (no uv)", m.name);
                materials.push(m);
                materials.len() - 1
            });
        }
        meshes.push(Mesh {
            name: model.name,
            positions,
            normals,
            uvs,
            indices,
            material,
        });
    }
    if meshes.iter().all(|m| m.indices.is_empty()) {
        return Err(Error::file(path, "no triangles (empty mesh)"));
    }
    if materials.is_empty() {
        materials.push(Material::default());
    }
    Ok(ObjParts {
        meshes,
        materials,
        textures,
        warnings,
    })
}

/// Loads an OBJ (+ MTL) file as a scene: 1024x768, fitted camera and key light, ambient 0.15,
/// dark grey opaque background. Errors name the file (and vertex/line where known).
pub fn load_obj(path: &Path) -> Result<Scene> {
    let parts = load_obj_parts(path)?;
    let (w, h) = OBJ_DEFAULT_SIZE;
    let camera = fit_camera(&parts.meshes, w, h);
    let light = fit_light(&camera);
    let scene = Scene {
        name: path
            .file_stem()
            .map_or_else(|| "obj".to_string(), |s| s.to_string_lossy().into_owned()),
        width: w,
        height: h,
        camera,
        lights: vec![light],
        ambient: [OBJ_AMBIENT; 3],
        background: OBJ_BACKGROUND,
        meshes: parts.meshes,
        materials: parts.materials,
        textures: parts.textures,
        hw: None,
        warnings: parts.warnings,
    };
    super::validate(&scene).map_err(|e| e.context(path.display()))?;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::parse_map_arg;

    #[test]
    fn map_args() {
        assert_eq!(parse_map_arg("tex.png"), ("tex.png".into(), None, false));
        assert_eq!(parse_map_arg("-s 2 2 1 -o 0.5 0 tex.png").0, "tex.png");
        assert_eq!(
            parse_map_arg("-clamp on tex.png"),
            ("tex.png".into(), None, true)
        );
        assert_eq!(parse_map_arg("my tex.png").0, "my tex.png");
        assert_eq!(parse_map_arg("\"my tex.png\"").0, "my tex.png");
        assert_eq!(parse_map_arg("-bm 0.5 -s 2 tex.png").0, "tex.png");
    }
}
