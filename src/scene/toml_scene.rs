//! TOML scene files (see `scenes/example.toml` for every field). Parsed with serde +
//! `deny_unknown_fields`; file paths inside are relative to the scene file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use serde::Deserialize;

use super::geometry::{bounding_sphere, fit_camera, fit_light, transform_mesh};
use super::obj::load_obj_parts;
use super::texture::{decode_texture, procedural, MAX_TEXTURE_SIDE};
use super::{
    shapes, AsBrdf, Camera, FrameKind, Light, MainDirection, Material, Mesh, Scene, TextureImage,
    WrapMode,
};
use crate::{Error, Result};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    output: Option<OutputCfg>,
    camera: Option<CameraCfg>,
    ambient: Option<[f32; 3]>,
    hw: Option<String>,
    lights: Option<Vec<LightCfg>>,
    #[serde(default)]
    textures: Vec<TextureCfg>,
    #[serde(default)]
    materials: Vec<MaterialCfg>,
    #[serde(default)]
    meshes: Vec<MeshCfg>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OutputCfg {
    width: Option<u32>,
    height: Option<u32>,
    background: Option<[f32; 4]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraCfg {
    #[serde(default)]
    fit: bool,
    eye: Option<[f64; 3]>,
    target: Option<[f64; 3]>,
    up: Option<[f64; 3]>,
    fov_y_deg: Option<f64>,
    near: Option<f64>,
    far: Option<f64>,
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase")]
enum LightKind {
    Directional,
    Point,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightCfg {
    kind: LightKind,
    direction: Option<[f32; 3]>,
    position: Option<[f32; 3]>,
    color: Option<[f32; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureCfg {
    name: String,
    file: Option<String>,
    procedural: Option<String>,
    size: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialCfg {
    name: String,
    kd: Option<[f32; 3]>,
    texture: Option<String>,
    wrap_s: Option<WrapMode>,
    wrap_t: Option<WrapMode>,
    lit: Option<bool>,
    cull_back: Option<bool>,
    /// Height map: a texture name of `[[textures]]` or an image file.
    bump: Option<String>,
    bump_scale: Option<f32>,
    /// The bump texture is a tangent-space normal map.
    bump_normal_map: Option<bool>,
    frame: Option<FrameKind>,
    main_direction: Option<MainDirCfg>,
    ks: Option<[f32; 3]>,
    shininess: Option<u32>,
    /// Roughness map: `hw` (the hardware's variant) or a variant name.
    roughness: Option<String>,
    /// `"ashikhmin-shirley"` (with `nu`, `nv`, `rs`, `rd`) or `"phong"` (the default).
    brdf: Option<String>,
    nu: Option<f64>,
    nv: Option<f64>,
    rs: Option<f64>,
    rd: Option<f64>,
    /// Exponent map: a texture name of `[[textures]]` (channel 0 scales `nu`, 1 scales `nv`).
    exponent_map: Option<String>,
    /// NDF mapping of the `bump` map (Olano and North 1997).
    ndf: Option<bool>,
    /// Environment map of a bump material: `"sky"` (the procedural sky cube), one image file
    /// (equirectangular 2:1 or a horizontal cross 4:3) or six face files (+x, -x, +y, -y,
    /// +z, -z).
    env_map: Option<EnvMapCfg>,
    /// Its filter: `hw` (default), `none`, `lambda1` or `ellipse`.
    env_filter: Option<String>,
    /// Face size of the sky cube (a power of two, 1..=2048; default 256).
    env_size: Option<u32>,
    /// Made-up multiple surface (Fournier 1992): `[[materials.lobes]]` with `direction`,
    /// `amplitude`, `exponent`.
    lobes: Option<Vec<LobeCfg>>,
    /// Specular filtering of a bump material: `plain` (default), `toksvig` or `lean`.
    bump_filter: Option<String>,
    /// Fournier lobes fitted to the bump map: `"hw"` or a count 1..=8.
    fournier_lobes: Option<toml::Value>,
}

/// One `[[materials.lobes]]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LobeCfg {
    /// Direction in the surface frame (`x` along `t_u`, `y` along `t_v`, `z` the normal).
    direction: [f32; 3],
    amplitude: Option<f32>,
    exponent: Option<u32>,
}

/// The made-up lobes of material `i` (amplitude 1 and exponent 32 by default), at most
/// `hw_model::multi_lobe::MAX_LOBES`.
fn made_up_lobes(i: usize, m: &MaterialCfg) -> Result<Vec<crate::scene::MadeUpLobe>> {
    let Some(cfgs) = &m.lobes else {
        return Ok(Vec::new());
    };
    let max = hw_model::multi_lobe::MAX_LOBES as usize;
    if cfgs.is_empty() || cfgs.len() > max {
        return Err(Error::field(
            &format!("materials[{i}].lobes"),
            format!("{} lobes (a multiple surface has 1..={max})", cfgs.len()),
        ));
    }
    cfgs.iter()
        .enumerate()
        .map(|(j, c)| {
            let l = crate::scene::MadeUpLobe {
                direction: c.direction,
                amplitude: c.amplitude.unwrap_or(1.0),
                exponent: c.exponent.unwrap_or(32),
            };
            l.validate(&format!("materials[{i}].lobes[{j}]"))?;
            Ok(l)
        })
        .collect()
}

/// The Ashikhmin-Shirley parameters of material `i` (defaults `nu = nv = 100`, `rs = 0.05`,
/// `rd = 0.5`, no exponent map); parameters without `brdf = "ashikhmin-shirley"` are an error.
fn as_brdf(
    i: usize,
    m: &MaterialCfg,
    tex_names: &BTreeMap<String, usize>,
) -> Result<Option<AsBrdf>> {
    let f = |n: &str| format!("materials[{i}].{n}");
    let given = [
        ("nu", m.nu),
        ("nv", m.nv),
        ("rs", m.rs),
        ("rd", m.rd),
        ("exponent_map", m.exponent_map.as_ref().map(|_| 0.0)),
    ];
    let exponent_map = match &m.exponent_map {
        Some(n) => Some(*tex_names.get(n).ok_or_else(|| {
            Error::field(
                &f("exponent_map"),
                format!("no texture named '{n}' in [[textures]]"),
            )
        })?),
        None => None,
    };
    match m.brdf.as_deref() {
        Some("ashikhmin-shirley") => {
            let b = AsBrdf {
                nu: m.nu.unwrap_or(100.0),
                nv: m.nv.unwrap_or(100.0),
                rs: m.rs.unwrap_or(0.05),
                rd: m.rd.unwrap_or(0.5),
                exponent_map,
            };
            b.validate(&format!("materials[{i}]"))?;
            Ok(Some(b))
        }
        None | Some("phong") => match given.iter().find(|(_, v)| v.is_some()) {
            Some((n, _)) => Err(Error::field(
                &f(n),
                "only used with brdf = \"ashikhmin-shirley\"",
            )),
            None => Ok(None),
        },
        Some(other) => Err(Error::field(
            &f("brdf"),
            format!("'{other}' is not \"ashikhmin-shirley\" or \"phong\""),
        )),
    }
}

#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "expected a direction [x, y, z] of three finite numbers, \"p_u\" or \"p_v\""
)]
enum MainDirCfg {
    Vector([f32; 3]),
    Name(String),
}

fn main_direction(field: &str, c: &MainDirCfg) -> Result<MainDirection> {
    match c {
        MainDirCfg::Vector(v) => {
            if v.iter().all(|x| x.is_finite()) && v.iter().any(|&x| x != 0.0) {
                Ok(MainDirection::Constant(*v))
            } else {
                Err(Error::field(field, "must be a finite non-zero vector"))
            }
        }
        MainDirCfg::Name(n) => match n.as_str() {
            "p_u" => Ok(MainDirection::Pu),
            "p_v" => Ok(MainDirection::Pv),
            other => Err(Error::field(
                field,
                format!("'{other}' is not [x, y, z], \"p_u\" or \"p_v\""),
            )),
        },
    }
}

#[derive(Deserialize)]
#[serde(untagged, expecting = "expected a number or [x, y, z]")]
enum ScaleCfg {
    Uniform(f64),
    Axes([f64; 3]),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshCfg {
    obj: Option<String>,
    shape: Option<String>,
    material: Option<String>,
    translate: Option<[f64; 3]>,
    rotate_deg: Option<[f64; 3]>,
    scale: Option<ScaleCfg>,
    // Shape parameters.
    size: Option<f32>,
    uv_scale: Option<f32>,
    radius: Option<f32>,
    segments: Option<u32>,
    rings: Option<u32>,
    major_radius: Option<f32>,
    minor_radius: Option<f32>,
    s_repeat: Option<f32>,
}

/// Default output size of a TOML scene without `[output]` width/height.
pub const TOML_DEFAULT_SIZE: (u32, u32) = (1024, 768);
/// Largest shape tessellation accepted per axis.
const MAX_SEGMENTS: u32 = 4096;

fn resolve(base: &Path, rel: &str) -> PathBuf {
    let p = Path::new(rel);
    let joined = if p.is_absolute() {
        p.to_path_buf()
    } else {
        base.join(p)
    };
    std::path::absolute(&joined).unwrap_or(joined)
}

/// Object -> world: translate * Rz * Ry * Rx * scale (rotations applied X, then Y, then Z).
fn mesh_transform(c: &MeshCfg) -> DMat4 {
    let t = DVec3::from(c.translate.unwrap_or([0.0; 3]));
    let r = c.rotate_deg.unwrap_or([0.0; 3]);
    let s = match c.scale {
        Some(ScaleCfg::Uniform(s)) => DVec3::splat(s),
        Some(ScaleCfg::Axes(a)) => DVec3::from(a),
        None => DVec3::ONE,
    };
    DMat4::from_translation(t)
        * DMat4::from_rotation_z(r[2].to_radians())
        * DMat4::from_rotation_y(r[1].to_radians())
        * DMat4::from_rotation_x(r[0].to_radians())
        * DMat4::from_scale(s)
}

fn positive(field: &str, v: Option<f32>, default: f32) -> Result<f32> {
    let v = v.unwrap_or(default);
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::field(
            field,
            format!("{v} must be a positive number"),
        ))
    }
}

fn count(field: &str, v: Option<u32>, default: u32, min: u32) -> Result<u32> {
    let v = v.unwrap_or(default);
    if (min..=MAX_SEGMENTS).contains(&v) {
        Ok(v)
    } else {
        Err(Error::field(
            field,
            format!("{v} is outside {min}..={MAX_SEGMENTS}"),
        ))
    }
}

/// Builds shape mesh `i`; `tris_before` triangles are already in the scene (the run's triangle
/// budget is checked before the mesh is generated).
fn build_shape(i: usize, c: &MeshCfg, shape: &str, tris_before: usize) -> Result<Mesh> {
    let f = |name: &str| format!("meshes[{i}].{name}");
    let used_params: &[(&str, bool)] = &[
        ("size", c.size.is_some()),
        ("uv_scale", c.uv_scale.is_some()),
        ("radius", c.radius.is_some()),
        ("segments", c.segments.is_some()),
        ("rings", c.rings.is_some()),
        ("major_radius", c.major_radius.is_some()),
        ("minor_radius", c.minor_radius.is_some()),
        ("s_repeat", c.s_repeat.is_some()),
    ];
    let allowed: &[&str] = match shape {
        "plane" => &["size", "uv_scale"],
        "sphere" => &["radius", "segments", "rings"],
        "torus" => &[
            "major_radius",
            "minor_radius",
            "segments",
            "rings",
            "s_repeat",
        ],
        "cube" => &["size"],
        other => {
            return Err(Error::field(
                &f("shape"),
                format!("unknown shape '{other}' (known: plane, sphere, torus, cube)"),
            ))
        }
    };
    if let Some((p, _)) = used_params
        .iter()
        .find(|(p, used)| *used && !allowed.contains(p))
    {
        return Err(Error::field(
            &f(p),
            format!("not a parameter of shape '{shape}'"),
        ));
    }
    let grid = |seg: u32, rings: u32| 2 * u64::from(seg) * u64::from(rings);
    let tris = match shape {
        "plane" => 2,
        "sphere" => grid(
            count(&f("segments"), c.segments, 64, 3)?,
            count(&f("rings"), c.rings, 32, 2)?,
        ),
        "torus" => grid(
            count(&f("segments"), c.segments, 96, 3)?,
            count(&f("rings"), c.rings, 48, 3)?,
        ),
        _ => 12,
    };
    let total = tris + tris_before as u64;
    crate::budget::check(
        &f("segments"),
        &format!("{total} triangles (this mesh: {tris})"),
        // A shape has fewer vertices than triangles (a grid: about half as many).
        crate::budget::mul(
            total,
            crate::budget::BYTES_PER_TRIANGLE + crate::budget::BYTES_PER_VERTEX,
        ),
    )?;
    Ok(match shape {
        "plane" => shapes::plane(
            positive(&f("size"), c.size, 2.0)?,
            positive(&f("uv_scale"), c.uv_scale, 1.0)?,
        ),
        "sphere" => shapes::sphere(
            positive(&f("radius"), c.radius, 1.0)?,
            count(&f("segments"), c.segments, 64, 3)?,
            count(&f("rings"), c.rings, 32, 2)?,
        ),
        "torus" => shapes::torus(
            positive(&f("major_radius"), c.major_radius, 1.0)?,
            positive(&f("minor_radius"), c.minor_radius, 0.4)?,
            count(&f("segments"), c.segments, 96, 3)?,
            count(&f("rings"), c.rings, 48, 3)?,
            positive(&f("s_repeat"), c.s_repeat, 2.0)?,
        ),
        _ => shapes::cube(positive(&f("size"), c.size, 1.0)?),
    })
}

/// Loads a TOML scene. Errors name the file and the field (toml's message carries the line).
pub fn load_toml(path: &Path) -> Result<Scene> {
    let text = crate::budget::read_text(path, "a TOML scene file")?;
    let cfg: SceneFile = toml::from_str(&text)
        .map_err(|e| Error::file(path, crate::error::toml_message(&text, &e)))?;
    build(path, cfg).map_err(|e| e.context(path.display()))
}

fn build(path: &Path, cfg: SceneFile) -> Result<Scene> {
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut warnings = Vec::new();
    let mut textures = Vec::new();
    let mut tex_names: BTreeMap<String, usize> = BTreeMap::new();
    for (i, t) in cfg.textures.iter().enumerate() {
        let f = |n: &str| format!("textures[{i}].{n}");
        if tex_names.insert(t.name.clone(), textures.len()).is_some() {
            return Err(Error::field(
                &f("name"),
                format!("duplicate texture name '{}'", t.name),
            ));
        }
        let tex = match (&t.file, &t.procedural) {
            (Some(file), None) => {
                if t.size.is_some() {
                    return Err(Error::field(&f("size"), "only for procedural textures"));
                }
                decode_texture(&resolve(&base, file))
                    .map_err(|e| e.context(format!("field '{}'", f("file"))))?
            }
            (None, Some(kind)) => {
                let size = t.size.unwrap_or(256);
                if !(1..=MAX_TEXTURE_SIDE).contains(&size) {
                    return Err(Error::field(
                        &f("size"),
                        format!("{size} is outside 1..={MAX_TEXTURE_SIDE}"),
                    ));
                }
                let texels: u64 = textures
                    .iter()
                    .map(|t: &TextureImage| u64::from(t.width) * u64::from(t.height))
                    .sum::<u64>()
                    + u64::from(size) * u64::from(size);
                crate::budget::check(
                    &f("size"),
                    &format!("a procedural texture of {size}x{size} ({texels} texels in all textures so far)"),
                    crate::budget::mul(texels, crate::budget::BYTES_PER_TEXEL),
                )?;
                procedural(kind, size).map_err(|e| Error::field(&f("procedural"), e))?
            }
            _ => {
                return Err(Error::field(
                    &f("file"),
                    "give exactly one of 'file' or 'procedural'",
                ))
            }
        };
        textures.push(tex);
    }
    let mut materials = Vec::new();
    let mut mat_names: BTreeMap<String, usize> = BTreeMap::new();
    for (i, m) in cfg.materials.iter().enumerate() {
        let f = |n: &str| format!("materials[{i}].{n}");
        if mat_names.insert(m.name.clone(), materials.len()).is_some() {
            return Err(Error::field(
                &f("name"),
                format!("duplicate material name '{}'", m.name),
            ));
        }
        let texture = match &m.texture {
            Some(n) => Some(*tex_names.get(n).ok_or_else(|| {
                Error::field(
                    &f("texture"),
                    format!("no texture named '{n}' in [[textures]]"),
                )
            })?),
            None => None,
        };
        let bump = match &m.bump {
            Some(n) => Some(match tex_names.get(n) {
                Some(&t) => t,
                None => {
                    let tex = decode_texture(&resolve(&base, n))
                        .map_err(|e| e.context(format!("field '{}'", f("bump"))))?;
                    tex_names.insert(n.clone(), textures.len());
                    textures.push(tex);
                    textures.len() - 1
                }
            }),
            None => None,
        };
        let def = Material::default();
        let main_dir = match &m.main_direction {
            Some(c) => main_direction(&f("main_direction"), c)?,
            None => def.main_direction,
        };
        let roughness = match &m.roughness {
            Some(r) => Some(
                crate::scene::RoughChoice::parse(r)
                    .map_err(|e| Error::field(&f("roughness"), e))?,
            ),
            None => None,
        };
        materials.push(Material {
            roughness,
            name: m.name.clone(),
            kd: m
                .kd
                .unwrap_or(if texture.is_some() { [1.0; 3] } else { def.kd }),
            texture,
            wrap_s: m.wrap_s.unwrap_or(def.wrap_s),
            wrap_t: m.wrap_t.unwrap_or(def.wrap_t),
            lit: m.lit.unwrap_or(def.lit),
            cull_back: m.cull_back.unwrap_or(def.cull_back),
            bump,
            bump_scale: m.bump_scale.unwrap_or(def.bump_scale),
            bump_normal_map: m.bump_normal_map.unwrap_or(def.bump_normal_map),
            frame: m.frame.or(def.frame),
            main_direction: main_dir,
            ks: m.ks.unwrap_or(def.ks),
            shininess: m.shininess.unwrap_or(def.shininess),
            brdf: as_brdf(i, m, &tex_names)?,
            ndf: m.ndf.unwrap_or(def.ndf),
            env: env_material(m, &f, &base, &mut textures)?,
            lobes: made_up_lobes(i, m)?,
            bump_filter: match &m.bump_filter {
                Some(b) => crate::scene::BumpFilter::parse(b)
                    .map_err(|e| Error::field(&f("bump_filter"), e))?,
                None => def.bump_filter,
            },
            fournier_lobes: match &m.fournier_lobes {
                None => def.fournier_lobes,
                Some(v) => {
                    let text = match v {
                        toml::Value::String(t) => t.clone(),
                        other => other.to_string(),
                    };
                    Some(
                        crate::scene::LobeCount::parse(&text)
                            .map_err(|e| Error::field(&f("fournier_lobes"), e))?,
                    )
                }
            },
        });
    }
    let mut default_mat: Option<usize> = None;
    let mut meshes = Vec::new();
    for (i, c) in cfg.meshes.iter().enumerate() {
        let f = |n: &str| format!("meshes[{i}].{n}");
        let explicit = match &c.material {
            Some(n) => Some(*mat_names.get(n).ok_or_else(|| {
                Error::field(
                    &f("material"),
                    format!("no material named '{n}' in [[materials]]"),
                )
            })?),
            None => None,
        };
        let xf = mesh_transform(c);
        if !xf.is_finite() {
            return Err(Error::field(&f("translate"), "transform is not finite"));
        }
        let mut new_meshes = match (&c.obj, &c.shape) {
            (Some(obj), None) => {
                if c.size
                    .or(c.uv_scale)
                    .or(c.radius)
                    .or(c.major_radius)
                    .or(c.minor_radius)
                    .or(c.s_repeat)
                    .is_some()
                    || c.segments.or(c.rings).is_some()
                {
                    return Err(Error::field(
                        &f("obj"),
                        "shape parameters are not allowed with 'obj'",
                    ));
                }
                let parts = load_obj_parts(&resolve(&base, obj))?;
                warnings.extend(parts.warnings);
                let tex_off = textures.len();
                textures.extend(parts.textures);
                let mat_off = materials.len();
                if explicit.is_none() {
                    materials.extend(parts.materials.into_iter().map(|mut m| {
                        m.texture = m.texture.map(|t| t + tex_off);
                        m
                    }));
                }
                parts
                    .meshes
                    .into_iter()
                    .map(|mut m| {
                        m.material = explicit.unwrap_or(m.material + mat_off);
                        m
                    })
                    .collect()
            }
            (None, Some(shape)) => {
                let tris_before = meshes.iter().map(|m: &Mesh| m.indices.len()).sum();
                let mut m = build_shape(i, c, shape, tris_before)?;
                m.material = match explicit {
                    Some(e) => e,
                    None => *default_mat.get_or_insert_with(|| {
                        materials.push(Material::default());
                        materials.len() - 1
                    }),
                };
                vec![m]
            }
            _ => {
                return Err(Error::field(
                    &f("obj"),
                    "give exactly one of 'obj' or 'shape'",
                ))
            }
        };
        for m in &mut new_meshes {
            transform_mesh(m, &xf);
        }
        meshes.extend(new_meshes);
    }
    if meshes.is_empty() {
        return Err(Error::field("meshes", "the scene has no [[meshes]]"));
    }
    let (def_w, def_h) = TOML_DEFAULT_SIZE;
    let width = cfg.output.as_ref().and_then(|o| o.width).unwrap_or(def_w);
    let height = cfg.output.as_ref().and_then(|o| o.height).unwrap_or(def_h);
    for (n, v) in [("output.width", width), ("output.height", height)] {
        if !(1..=8192).contains(&v) {
            return Err(Error::field(n, format!("{v} is outside 1..=8192")));
        }
    }
    let background = cfg
        .output
        .as_ref()
        .and_then(|o| o.background)
        .unwrap_or(super::obj::OBJ_BACKGROUND);
    let camera = build_camera(cfg.camera.as_ref(), &meshes, width, height)?;
    let lights = match &cfg.lights {
        None => vec![fit_light(&camera)],
        Some(ls) => ls
            .iter()
            .enumerate()
            .map(|(i, l)| build_light(i, l))
            .collect::<Result<Vec<_>>>()?,
    };
    let hw = cfg.hw.map(|h| {
        if h.ends_with(".toml") || h.contains('/') || h.contains('\\') {
            resolve(&base, &h).display().to_string()
        } else {
            h
        }
    });
    let scene = Scene {
        name: cfg.name.unwrap_or_else(|| {
            path.file_stem()
                .map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
        }),
        width,
        height,
        camera,
        lights,
        ambient: cfg.ambient.unwrap_or([super::obj::OBJ_AMBIENT; 3]),
        background,
        meshes,
        materials,
        textures,
        hw,
        warnings,
    };
    super::validate(&scene)?;
    Ok(scene)
}

fn build_light(i: usize, l: &LightCfg) -> Result<Light> {
    let f = |n: &str| format!("lights[{i}].{n}");
    let color = l.color.unwrap_or([1.0; 3]);
    match l.kind {
        LightKind::Directional => {
            if l.position.is_some() {
                return Err(Error::field(
                    &f("position"),
                    "not used by a directional light",
                ));
            }
            let d = l
                .direction
                .ok_or_else(|| Error::field(&f("direction"), "required"))?;
            if d.iter().all(|c| *c == 0.0) {
                return Err(Error::field(&f("direction"), "must not be zero"));
            }
            Ok(Light::Directional {
                direction: d,
                color,
            })
        }
        LightKind::Point => {
            if l.direction.is_some() {
                return Err(Error::field(&f("direction"), "not used by a point light"));
            }
            let p = l
                .position
                .ok_or_else(|| Error::field(&f("position"), "required"))?;
            Ok(Light::Point { position: p, color })
        }
    }
}

fn build_camera(c: Option<&CameraCfg>, meshes: &[Mesh], w: u32, h: u32) -> Result<Camera> {
    let Some(c) = c.filter(|c| !c.fit) else {
        if let Some(c) = c {
            let given = [
                ("camera.eye", c.eye.is_some()),
                ("camera.target", c.target.is_some()),
                ("camera.up", c.up.is_some()),
                ("camera.fov_y_deg", c.fov_y_deg.is_some()),
                ("camera.near", c.near.is_some()),
                ("camera.far", c.far.is_some()),
            ];
            if let Some((n, _)) = given.iter().find(|(_, g)| *g) {
                return Err(Error::field(n, "not used when camera.fit = true"));
            }
        }
        return Ok(fit_camera(meshes, w, h));
    };
    let eye = c
        .eye
        .ok_or_else(|| Error::field("camera.eye", "required unless camera.fit = true"))?;
    let target = c
        .target
        .ok_or_else(|| Error::field("camera.target", "required unless camera.fit = true"))?;
    let (centre, r) = bounding_sphere(meshes);
    let dist = DVec3::from(eye).distance(centre);
    let far = c.far.unwrap_or((dist + 2.0 * r).max(1e-3));
    let near = c.near.unwrap_or_else(|| (dist - 2.0 * r).max(far * 1e-4));
    Ok(Camera {
        eye,
        target,
        up: c.up.unwrap_or([0.0, 1.0, 0.0]),
        fov_y_deg: c.fov_y_deg.unwrap_or(45.0),
        near,
        far,
        view_override: None,
    })
}

/// The `env_map`, `env_filter` and `env_size` keys of a material.
/// An `env_map` value: `"sky"`, one image file, or six face files.
#[derive(Deserialize)]
#[serde(
    untagged,
    expecting = "expected \"sky\", one image file or a list of six face files"
)]
enum EnvMapCfg {
    One(String),
    Six(Vec<String>),
}

/// Decodes an environment image (a texture file) for `field`, appends it to `textures` and
/// returns its index.
fn env_image(
    base: &Path,
    file: &str,
    field: &str,
    textures: &mut Vec<TextureImage>,
) -> Result<usize> {
    let t =
        decode_texture(&resolve(base, file)).map_err(|e| e.context(format!("field '{field}'")))?;
    textures.push(t);
    Ok(textures.len() - 1)
}

/// Checks that six faces are square, of one power-of-two size up to the cube limit; returns it.
fn face_size(faces: &[&TextureImage], field: &str) -> Result<u32> {
    let n = faces[0].width;
    for t in faces {
        if t.width != t.height || t.width != n {
            return Err(Error::field(
                field,
                format!(
                    "face '{}' is {}x{}: the six faces must be square and of one size ({n}x{n})",
                    t.name, t.width, t.height
                ),
            ));
        }
    }
    if !n.is_power_of_two() || n > crate::maps::cube::MAX_FACE_SIZE {
        return Err(Error::field(
            field,
            format!(
                "faces of {n}x{n}: a face side must be a power of two in 1..={}",
                crate::maps::cube::MAX_FACE_SIZE
            ),
        ));
    }
    Ok(n)
}

fn env_material(
    m: &MaterialCfg,
    f: &dyn Fn(&str) -> String,
    base: &Path,
    textures: &mut Vec<TextureImage>,
) -> Result<Option<crate::scene::EnvMaterial>> {
    use crate::scene::EnvSource;
    let Some(src) = &m.env_map else {
        if m.env_filter.is_some() || m.env_size.is_some() {
            return Err(Error::field(
                &f("env_map"),
                "env_filter and env_size need env_map (\"sky\", an image file or six face files)",
            ));
        }
        return Ok(None);
    };
    let field = f("env_map");
    let (source, own_size) = match src {
        EnvMapCfg::One(s) if s == "sky" => (EnvSource::Sky, None),
        EnvMapCfg::One(file) => {
            let i = env_image(base, file, &field, textures)?;
            let (w, h) = (textures[i].width, textures[i].height);
            if w == 2 * h {
                (EnvSource::Equirect(i), None)
            } else if 3 * w == 4 * h && w % 4 == 0 {
                let faces = crate::maps::cube::split_cross(&textures[i]);
                let n = face_size(&faces.iter().collect::<Vec<_>>(), &field)?;
                let first = textures.len();
                textures.extend(faces);
                (
                    EnvSource::Faces(std::array::from_fn(|k| first + k)),
                    Some(n),
                )
            } else {
                return Err(Error::field(
                    &field,
                    format!(
                        "'{file}' is {w}x{h}: an environment image is equirectangular (2:1) or a horizontal cross (4:3)"
                    ),
                ));
            }
        }
        EnvMapCfg::Six(files) => {
            if files.len() != 6 {
                return Err(Error::field(
                    &field,
                    format!(
                        "{} files: a cube is six faces (+x, -x, +y, -y, +z, -z)",
                        files.len()
                    ),
                ));
            }
            let mut ix = [0usize; 6];
            for (k, file) in files.iter().enumerate() {
                ix[k] = env_image(base, file, &format!("{field}[{k}]"), textures)?;
            }
            let faces: Vec<&TextureImage> = ix.iter().map(|&i| &textures[i]).collect();
            let n = face_size(&faces, &field)?;
            (EnvSource::Faces(ix), Some(n))
        }
    };
    let filter = match &m.env_filter {
        Some(s) => crate::scene::EnvMaterial::parse_filter(s)
            .map_err(|e| Error::field(&f("env_filter"), e))?,
        None => None,
    };
    let size = match (own_size, m.env_size) {
        (Some(n), Some(s)) if s != n => {
            return Err(Error::field(
                &f("env_size"),
                format!("{s}: the faces of env_map are {n}x{n} (leave env_size out)"),
            ))
        }
        (Some(n), _) => n,
        (None, s) => s.unwrap_or(256),
    };
    if !size.is_power_of_two() || size > crate::maps::cube::MAX_FACE_SIZE {
        return Err(Error::field(
            &f("env_size"),
            format!(
                "{size} is not a power of two in 1..={}",
                crate::maps::cube::MAX_FACE_SIZE
            ),
        ));
    }
    Ok(Some(crate::scene::EnvMaterial {
        filter,
        size,
        source,
    }))
}
