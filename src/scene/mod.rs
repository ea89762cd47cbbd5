//! Scenes: what a frame is made of, in world space and float (host side).
//!
//! Loaders (`obj`, `toml_scene`) and the built-in catalogue (`builtin`) all produce a [`Scene`]
//! that has been checked: finite positions, indices in range, at least one triangle overall.

use glam::{DMat4, DVec3};

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
}

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
    /// If set, this exact view matrix is used instead of eye/target/up (the Mesa anchor scenes
    /// reproduce a fixed-function GL modelview this way).
    pub view_override: Option<DMat4>,
}

impl Camera {
    /// World -> view (right-handed, looking down -z).
    #[must_use]
    pub fn view(&self) -> DMat4 {
        if let Some(v) = self.view_override {
            return v;
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
