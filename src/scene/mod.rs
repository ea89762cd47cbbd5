//! Scenes: what a frame is made of, in world space and float (host side).
//!
//! Loaders (`obj`, `toml_scene`) and the built-in catalogue (`builtin`) all produce a [`Scene`]
//! that has been checked: finite positions, indices in range, at least one triangle overall.

//!
//! Texture coordinate convention: `uv = (s, t)` addresses the texture as OpenGL does with
//! `glTexImage2D` data: `s` runs along a row, `t` across rows, and `t = 0` is texel row 0,
//! which is the *top* row of an image file (`TextureImage` is stored top row first). OBJ files
//! are therefore loaded with `t = 1 - v` (OBJ's v = 0 is the bottom of the image).

use std::path::Path;

use glam::{DMat4, DVec3};

pub mod as_scenes;
mod catalogue;
pub mod env_scenes;
pub mod fit_scenes;
mod geometry;
pub mod gl_matrix;
pub mod lobe_scenes;
mod ndf_scenes;
mod obj;
pub mod rough_scenes;
pub mod shapes;
pub mod texture;
mod toml_scene;

pub use catalogue::{builtin, w1_view, w2_view, BUILTIN};
pub use geometry::{
    bounding_sphere, fit_camera, fit_light, smooth_normals, transform_mesh, validate,
    FALLBACK_NORMAL,
};
pub use obj::load_obj;
pub use texture::decode_texture;
pub use toml_scene::load_toml;

/// Loads a scene file by extension: `.obj` (with its MTL) or `.toml`. Errors name the file.
pub fn load(path: &Path) -> crate::Result<Scene> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "obj" => load_obj(path),
        "toml" => load_toml(path),
        _ => Err(crate::Error::file(
            path,
            "unknown scene file type (expected a .obj or .toml file)",
        )),
    }
}

/// Texture addressing mode per axis.
pub use hw_model::wrap::WrapMode;

/// A decoded texture image, RGBA, 16-bit unsigned normalized per channel (8-bit sources are
/// expanded exactly by x * 257), top row first.
#[derive(Clone, Debug)]
pub struct TextureImage {
    /// Where it came from (file path or procedural name), for messages.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u16; 4]>,
    /// A prebuilt MIP chain (level 1..), when the source defines its own down-filter (the Mesa
    /// anchor workloads do); otherwise `maps` builds one.
    #[allow(clippy::type_complexity)]
    pub prebuilt_levels: Option<Vec<(u32, u32, Vec<[u16; 4]>)>>,
}

/// A surface description. Only what a material uses becomes a pipeline stage.
#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Diffuse colour (linear, 0..1), used alone when there is no texture, and as the
    /// modulation colour when there is.
    pub kd: [f32; 3],
    /// Index into [`Scene::textures`] of the diffuse texture (`map_Kd`).
    pub texture: Option<usize>,
    pub wrap_s: WrapMode,
    pub wrap_t: WrapMode,
    /// Lit with the scene lights (Gouraud, per vertex, host float) if true; unlit (colour = kd x
    /// texture, i.e. GL_REPLACE / MODULATE with white) if false.
    pub lit: bool,
    /// Cull back faces (counter-clockwise front faces, as OpenGL).
    pub cull_back: bool,
    /// Index into [`Scene::textures`] of a height map (channel 0). When set, the material is
    /// bump mapped and shaded per pixel (Blinn-Phong); the height map becomes an offset map
    /// `(f_u, f_v)` when the maps are prepared.
    pub bump: Option<usize>,
    /// Bump height scale (multiplies the height differences per level-0 texel, or the offsets
    /// of a normal map).
    pub bump_scale: f32,
    /// The `bump` texture is a tangent-space normal map, not a height map: OpenGL style, red
    /// along `+s`, green towards the image's top row (`-t`, i.e. OBJ's `+v`), blue out.
    pub bump_normal_map: bool,
    /// Local frame of the bump mapping; `None` uses the hardware's `frame_kind`.
    pub frame: Option<FrameKind>,
    /// Main direction `m` of the main-direction frame.
    pub main_direction: MainDirection,
    /// Specular colour (per-pixel Blinn-Phong of bump-mapped materials).
    pub ks: [f32; 3],
    /// Specular exponent (for NDF materials, the base shininess of the moment maps).
    pub shininess: u32,
    /// Roughness map of a bump material (Schilling 1997 roughness pyramid + modified
    /// Blinn-Phong, `pipeline::rough`); `None`: plain Blinn-Phong.
    pub roughness: Option<RoughChoice>,
    /// Ashikhmin-Shirley anisotropic Phong BRDF: shaded per pixel in the main-direction frame
    /// instead of Gouraud or Blinn-Phong (`pipeline::as_shade`).
    pub brdf: Option<AsBrdf>,
    /// NDF mapping (Olano and North 1997): the `bump` map's normals become moment maps,
    /// shaded by `ndf-fetch` and `ndf-shade` instead of the bump path's Blinn-Phong.
    pub ndf: bool,
    /// Environment map of a bump material (`pipeline::env`): the reflection of the scene's
    /// sky, weighted by `ks`, added to the shading result.
    pub env: Option<EnvMaterial>,
    /// Made-up multiple surface (Fournier 1992, sec. 3.4 and 4): the material's lobes, shaded
    /// per pixel by `lobe-shade` (`pipeline::lobe_shade`) instead of Gouraud or Blinn-Phong.
    pub lobes: Vec<MadeUpLobe>,
    /// How a bump material's specular lobe accounts for the normals under the footprint
    /// (TOML `bump_filter`): `plain` (the filtered bump map alone), `toksvig` (Toksvig
    /// 2005, `pipeline::toksvig`) or `lean` (Olano and Baker 2010, `pipeline::lean`).
    pub bump_filter: BumpFilter,
    /// Fournier lobes fitted to the bump map per texel and MIP level (TOML `fournier_lobes`,
    /// `pipeline::lobe_fit`): shaded by `lobe-fetch` and `lobe-shade` instead of `phong`;
    /// `None`: not fitted.
    pub fournier_lobes: Option<LobeCount>,
}

/// How many Fournier lobes a bump material's fit has per texel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeCount {
    /// The hardware's `multi_lobe.fournier_lobes` (so `--vary fournier_lobes=...` switches it).
    Hw,
    /// K lobes, 1..=8.
    Lobes(u32),
}

impl LobeCount {
    /// Parses a `fournier_lobes` value: `hw` or an integer 1..=8.
    pub fn parse(s: &str) -> Result<Self, String> {
        if s.trim() == "hw" {
            return Ok(Self::Hw);
        }
        match s.trim().parse::<u32>() {
            Ok(k) if (1..=8).contains(&k) => Ok(Self::Lobes(k)),
            _ => Err(format!("'{s}' is not hw or a lobe count 1..=8")),
        }
    }

    /// The lobe count on the hardware `hw`.
    #[must_use]
    pub fn resolve(self, hw: &hw_model::config::HwConfig) -> u32 {
        match self {
            Self::Hw => hw.multi_lobe.fournier_lobes,
            Self::Lobes(k) => k,
        }
    }
}

/// One lobe of a made-up multiple surface (Fournier 1992, eq. 12): its direction in the
/// surface's local frame (`x` along the frame's `t_u`, `y` along `t_v`, `z` along the normal;
/// any length, `z > 0`), amplitude `c_i` in `[0, 1]` and Phong exponent `n_i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MadeUpLobe {
    pub direction: [f32; 3],
    pub amplitude: f32,
    pub exponent: u32,
}

/// Largest Phong exponent of a lobe (`2^16 - 1`, the widest `lobe_exp_bits`).
pub const MAX_LOBE_EXPONENT: u32 = 65_535;

impl MadeUpLobe {
    /// Checks one lobe; the error names `field.direction` etc.
    pub fn validate(&self, field: &str) -> crate::Result<()> {
        let d = self.direction;
        if !d.iter().all(|c| c.is_finite()) || d[2] <= 0.0 {
            return Err(crate::Error::field(
                &format!("{field}.direction"),
                format!("{d:?} is not a finite direction above the surface (z > 0)"),
            ));
        }
        if !(0.0..=1.0).contains(&self.amplitude) {
            return Err(crate::Error::field(
                &format!("{field}.amplitude"),
                format!("{} is not in [0, 1]", self.amplitude),
            ));
        }
        if self.exponent > MAX_LOBE_EXPONENT {
            return Err(crate::Error::field(
                &format!("{field}.exponent"),
                format!("{} is above {MAX_LOBE_EXPONENT}", self.exponent),
            ));
        }
        Ok(())
    }

    /// The slopes `(x / z, y / z)` of the direction: the lobe as a bump offset.
    #[must_use]
    pub fn slopes(&self) -> [f64; 2] {
        let d = self.direction.map(f64::from);
        [d[0] / d[2], d[1] / d[2]]
    }
}

/// A bump material's environment map (Schilling 1997, "balanced system").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvMaterial {
    /// The filter: `None` = the hardware's `env_filter` (so `--vary env_filter=...` switches it).
    pub filter: Option<hw_model::env_config::EnvFilter>,
    /// Face size of the cube (texels per side, a power of two).
    pub size: u32,
    /// Where the cube's texels come from.
    pub source: EnvSource,
}

/// Where an environment map's texels come from (`maps::cube::env_sampler`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvSource {
    /// The procedural sky (`shading::env::sky_f`).
    Sky,
    /// An equirectangular (latitude-longitude, 2:1) image: the scene texture of this index.
    Equirect(usize),
    /// Six square face images in OpenGL order (+X, -X, +Y, -Y, +Z, -Z), each in OpenGL's face
    /// orientation (OpenGL 4.6 Table 8.19): scene texture indices.
    Faces([usize; 6]),
}

impl EnvMaterial {
    /// Parses an `env_filter` value: `hw`, `none`, `lambda1` or `ellipse`.
    pub fn parse_filter(
        s: &str,
    ) -> std::result::Result<Option<hw_model::env_config::EnvFilter>, String> {
        use hw_model::env_config::EnvFilter;
        match s {
            "hw" => Ok(None),
            "none" => Ok(Some(EnvFilter::None)),
            "lambda1" => Ok(Some(EnvFilter::Lambda1)),
            "ellipse" => Ok(Some(EnvFilter::Ellipse)),
            _ => Err(format!("'{s}' is not hw, none, lambda1 or ellipse")),
        }
    }
}

/// Specular filtering of a bump material beyond the filtered bump map.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BumpFilter {
    /// The filtered bump map and the material's exponent (the baseline).
    #[default]
    Plain,
    /// Toksvig's exponent from the length of the MIP-mapped average normal.
    Toksvig,
    /// LEAN mapping: a Gaussian of the slopes from their filtered first and second moments.
    Lean,
}

impl BumpFilter {
    /// Parses a TOML name; the error lists the names.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        match s {
            "plain" => Ok(Self::Plain),
            "toksvig" => Ok(Self::Toksvig),
            "lean" => Ok(Self::Lean),
            _ => Err(format!("'{s}' is not plain, toksvig or lean")),
        }
    }
}

/// Which modified Blinn-Phong a roughness material uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoughChoice {
    /// The hardware's `rough_variant` (so `--vary roughness=...` switches it).
    Hw,
    /// This variant whatever the hardware says.
    Variant(hw_model::roughness::RoughVariant),
}

impl RoughChoice {
    /// Parses `hw` or a variant name; the error lists the names.
    pub fn parse(s: &str) -> std::result::Result<Self, String> {
        if s == "hw" {
            return Ok(Self::Hw);
        }
        hw_model::roughness::RoughVariant::from_name(s)
            .map(Self::Variant)
            .ok_or_else(|| {
                format!("'{s}' is not hw, none, published, directional, mahalanobis or isotropic")
            })
    }
}

/// Parameters of the Ashikhmin-Shirley BRDF (Ashikhmin & Shirley 2000, eqs. 11, 16, 18) of a
/// material: exponents along `u` (main-direction tangent `e1`) and `v`, Schlick's `R_s` and the
/// diffuse `R_d` (which the material's `kd` tints).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AsBrdf {
    /// Exponent along `u`: an integer in `0..=MAX_AS_EXPONENT`.
    pub nu: f64,
    /// Exponent along `v`.
    pub nv: f64,
    /// Specular reflectance at normal incidence, `[0, 1]`.
    pub rs: f64,
    /// Diffuse reflectance, `[0, 1]`.
    pub rd: f64,
    /// Index into [`Scene::textures`] of an exponent map: per pixel `n_u = t_0 nu` and
    /// `n_v = t_1 nv` from its channels 0 and 1 (unorm `t`; the fixed stage rounds to integers).
    pub exponent_map: Option<usize>,
}

/// Largest exponent a scene may give (`2^20 - 1`, the widest `exponent_max_bits`; a narrower
/// unit clamps and counts a saturation).
pub const MAX_AS_EXPONENT: f64 = 1_048_575.0;

impl AsBrdf {
    /// Checks the parameters; the error names `field.nu` etc.
    pub fn validate(&self, field: &str) -> crate::Result<()> {
        for (n, v) in [("nu", self.nu), ("nv", self.nv)] {
            if !((0.0..=MAX_AS_EXPONENT).contains(&v) && v.fract() == 0.0) {
                return Err(crate::Error::field(
                    &format!("{field}.{n}"),
                    format!("{v} is not an integer in 0..={MAX_AS_EXPONENT}"),
                ));
            }
        }
        for (n, v) in [("rs", self.rs), ("rd", self.rd)] {
            if !(0.0..=1.0).contains(&v) {
                return Err(crate::Error::field(
                    &format!("{field}.{n}"),
                    format!("{v} is not in [0, 1]"),
                ));
            }
        }
        Ok(())
    }
}

/// The main direction `m` of the main-direction frame (Schilling 1997, frame 3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MainDirection {
    /// A constant world-space direction per object; it stands for the texture's v direction
    /// (`hw_model::frame::MainRole`).
    Constant([f32; 3]),
    /// The surface derivative `p_u` (tangent), interpolated per pixel.
    Pu,
    /// The surface derivative `p_v` (bitangent), interpolated per pixel.
    Pv,
}

pub use hw_model::frame::FrameKind;

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            kd: [0.8, 0.8, 0.8],
            texture: None,
            wrap_s: WrapMode::Repeat,
            wrap_t: WrapMode::Repeat,
            lit: true,
            cull_back: false,
            bump: None,
            bump_scale: 1.0,
            bump_normal_map: false,
            frame: None,
            main_direction: MainDirection::Pv,
            ks: [0.0; 3],
            shininess: 32,
            roughness: None,
            brdf: None,
            ndf: false,
            env: None,
            lobes: Vec::new(),
            bump_filter: BumpFilter::Plain,
            fournier_lobes: None,
        }
    }
}

/// A triangle mesh in world space (transforms already applied). `normals` has one entry per
/// position (generated if the source had none); `uvs` is either empty or one per position.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<[u32; 3]>,
    /// Index into [`Scene::materials`].
    pub material: usize,
}

/// A light source; intensities are linear RGB.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// Light travelling along `direction` (towards the scene).
    Directional {
        direction: [f32; 3],
        color: [f32; 3],
    },
    /// A point light without falloff.
    Point { position: [f32; 3], color: [f32; 3] },
}

/// A pinhole camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f64; 3],
    /// Vertical field of view in degrees.
    pub fov_y_deg: f64,
    pub near: f64,
    pub far: f64,
    /// If set, this fixed-function GL camera is used instead of eye/target/up (the Mesa
    /// anchor scenes reproduce their GL modelview this way).
    pub view_override: Option<GlView>,
}

/// A fixed-function GL camera: its exact view matrix and, when the scene reproduces a GL
/// program, the binary32 model-view-projection that program's matrix stack computes
/// ([`gl_matrix`]), which llvmpipe's float32 vertex transform starts from
/// (`interp.coord_arith = "float32"`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlView {
    pub view: DMat4,
    pub mvp_f32: Option<gl_matrix::Mat4f>,
}

impl Camera {
    /// World -> view (right-handed, looking down -z).
    #[must_use]
    pub fn view(&self) -> DMat4 {
        if let Some(v) = self.view_override {
            return v.view;
        }
        DMat4::look_at_rh(
            DVec3::from(self.eye),
            DVec3::from(self.target),
            DVec3::from(self.up),
        )
    }

    /// View -> clip, OpenGL conventions (z_ndc in [-1, 1]).
    #[must_use]
    pub fn projection(&self, aspect: f64) -> DMat4 {
        DMat4::perspective_rh_gl(self.fov_y_deg.to_radians(), aspect, self.near, self.far)
    }
}

/// Everything one frame needs.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// Ambient term added to lit materials (linear RGB).
    pub ambient: [f32; 3],
    /// Clear colour (RGBA, 0..1).
    pub background: [f32; 4],
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<TextureImage>,
    /// Hardware config named by the scene file (preset name or path), if any.
    pub hw: Option<String>,
    /// Non-fatal problems met while loading (missing texture files, generated normals...).
    pub warnings: Vec<String>,
}

impl Scene {
    /// Total triangle count.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }
}
