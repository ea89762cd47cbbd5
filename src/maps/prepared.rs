//! The prepared maps of a scene: its textures' MIP chains, one offset map per distinct bump
//! source, the NDF moment chains, each in float (host) and quantized to the machine's texel
//! width. Map `i` of [`Maps`] is the same map in `float[i]` and `fixed[i]`.

use super::{
    build_chains, quantize_chain, quantize_unorm, FixedMipChain, MipChain, OFFSET_CHANNELS,
};
use crate::scene::{Scene, TextureImage};
use crate::shading::bump::{
    height_to_offsets, heights_from_texture, normal_map_to_offsets, offsets_to_image, BumpParams,
    OffsetEncoding,
};
use glam::DVec3;
use rayon::prelude::*;

/// The prepared texture maps of a scene: float MIP chains (host) and their quantization to the
/// texel width of the machine. The scene's textures come first, then one offset map per
/// distinct (height map, bump scale) of the bump materials ([`bump_sources`]).
#[derive(Clone)]
pub struct Maps {
    pub float: Vec<MipChain>,
    pub fixed: Vec<FixedMipChain>,
    /// Per offset map: its level-0 offsets `(f_u, f_v)` before encoding (size, values).
    #[allow(clippy::type_complexity)]
    pub bump_offsets: Vec<(u32, u32, String, Vec<[f32; 2]>)>,
    /// `offset_int_bits` of the offset encoding (range `2^bits`).
    pub offset_int_bits: u32,
    /// Offsets clamped (all offset maps): by the encoding, plus `normal_nz_clamped`.
    pub bump_clamped: u64,
    /// Normal-map texels whose `n_z` was clamped to `shading::bump::NORMAL_MAP_MIN_Z` (all
    /// normal maps), which bounds their offsets before the encoding.
    pub normal_nz_clamped: u64,
    /// NDF moment maps ([`ndf_sources`]): four chains each (A, B, C, normalization) after the
    /// offset maps, quantized to `moment_bits`, and the config they were built for.
    pub ndf: Vec<(usize, u32)>,
    pub ndf_cfg: hw_model::ndf::NdfConfig,
    /// Moment channels clamped by the encoding (all moment maps).
    pub ndf_clamped: u64,
}

/// One offset map to prepare: the source texture, the bump scale, and whether the source is
/// a tangent-space normal map (else a height map, channel 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BumpSource {
    pub texture: usize,
    pub scale: f32,
    pub normal_map: bool,
}

impl BumpSource {
    /// The offset map a material's bump fields ask for (`None` without a bump map).
    #[must_use]
    pub fn of(m: &crate::scene::Material) -> Option<Self> {
        m.bump.map(|texture| Self {
            texture,
            scale: m.bump_scale,
            normal_map: m.bump_normal_map,
        })
    }

    /// The same offset map (bit-identical scale).
    #[must_use]
    pub fn same(&self, o: &Self) -> bool {
        self.texture == o.texture
            && self.scale.to_bits() == o.scale.to_bits()
            && self.normal_map == o.normal_map
    }
}

/// The distinct offset maps of the scene's bump materials, in material order; offset map `k`
/// is map `scene.textures.len() + k`.
#[must_use]
pub fn bump_sources(scene: &Scene) -> Vec<BumpSource> {
    let mut out: Vec<BumpSource> = Vec::new();
    for m in &scene.materials {
        if let Some(b) = BumpSource::of(m) {
            if !out.iter().any(|o| o.same(&b)) {
                out.push(b);
            }
        }
    }
    out
}

/// The distinct (offset map, base shininess) pairs of the scene's NDF materials, in material
/// order; pair `j` is prepared as maps `scene.textures.len() + bump_sources.len() + 4 j ..+4`.
#[must_use]
pub fn ndf_sources(scene: &Scene) -> Vec<(usize, u32)> {
    let sources = bump_sources(scene);
    let mut out: Vec<(usize, u32)> = Vec::new();
    for m in scene.materials.iter().filter(|m| m.ndf) {
        let Some(b) = BumpSource::of(m) else { continue };
        let Some(k) = sources.iter().position(|o| o.same(&b)) else {
            continue;
        };
        if !out.contains(&(k, m.shininess)) {
            out.push((k, m.shininess));
        }
    }
    out
}

/// Quantizes the scene's textures (stored RGBA) and, from `first_offset` on, the offset maps
/// (stored as their two channels) to `texel_bits`.
fn quantize_host_maps(
    float: &[MipChain],
    first_offset: usize,
    texel_bits: u32,
) -> Vec<FixedMipChain> {
    float
        .par_iter()
        .enumerate()
        .map(|(i, c)| {
            let q = quantize_chain(c, texel_bits);
            if i >= first_offset {
                let bits = q.texel_bits;
                q.stored_as(OFFSET_CHANNELS, bits)
            } else {
                q
            }
        })
        .collect()
}

/// Encodes offsets (range `2^offset_int_bits`) and builds the offset map's MIP chain with the
/// ordinary texture path (16-bit unorm level 0, box-filtered levels). Returns the chain, its
/// quantization to `texel_bits` (stored as the two offset channels) and the number of clamped
/// offsets.
fn offset_chain(
    w: u32,
    h: u32,
    name: &str,
    offs: &[[f32; 2]],
    bits: u32,
    texel_bits: u32,
) -> (MipChain, FixedMipChain, u64) {
    let enc = OffsetEncoding::for_offset_int_bits(bits);
    let img = offsets_to_image(offs, w, h, &enc);
    let tex = TextureImage {
        name: format!("{name} (offsets)"),
        width: w,
        height: h,
        texels: img
            .texels
            .iter()
            .map(|t| t.map(|c| quantize_unorm(c, 16)))
            .collect(),
        prebuilt_levels: None,
    };
    let (c, q) = build_chains(&tex, texel_bits);
    let tb = q.texel_bits;
    (c, q.stored_as(OFFSET_CHANNELS, tb), img.clamped)
}

impl Maps {
    /// Builds every texture's MIP chain and quantizes it to `texel_bits`; bump height maps
    /// become offset maps encoded for the default (texram16) `offset_int_bits`.
    #[must_use]
    pub fn new(scene: &Scene, texel_bits: u32) -> Self {
        Self::with_offset_bits(
            scene,
            texel_bits,
            hw_model::vector::VectorConfig::texram16().offset_int_bits,
        )
    }

    /// As [`Maps::new`] with the offset encoding of `offset_int_bits`. A height map that
    /// cannot be converted (bad size) gives a flat offset map.
    #[must_use]
    pub fn with_offset_bits(scene: &Scene, texel_bits: u32, offset_int_bits: u32) -> Self {
        let (mut float, mut fixed): (Vec<MipChain>, Vec<FixedMipChain>) = scene
            .textures
            .par_iter()
            .map(|t| build_chains(t, texel_bits))
            .unzip();
        let mut bump_offsets = Vec::new();
        let mut normal_nz_clamped = 0;
        for b in bump_sources(scene) {
            let tex = &scene.textures[b.texture];
            let p = BumpParams {
                scale: b.scale,
                v_up: false,
            };
            let offs = if b.normal_map {
                normal_map_to_offsets(tex, true).map(|(o, nz)| {
                    normal_nz_clamped += nz;
                    o.into_iter()
                        .map(|f| f.map(|x| x * b.scale))
                        .collect::<Vec<_>>()
                })
            } else {
                heights_from_texture(tex, 0)
                    .and_then(|h| height_to_offsets(&h, tex.width, tex.height, &p))
            }
            .unwrap_or_else(|_| vec![[0.0; 2]; tex.texels.len()]);
            bump_offsets.push((tex.width, tex.height, tex.name.clone(), offs));
        }
        let mut bump_clamped = normal_nz_clamped;
        for (w, h, name, offs) in &bump_offsets {
            let (c, q, cl) = offset_chain(*w, *h, name, offs, offset_int_bits, texel_bits);
            float.push(c);
            fixed.push(q);
            bump_clamped += cl;
        }
        let mut maps = Self {
            float,
            fixed,
            bump_offsets,
            offset_int_bits,
            bump_clamped,
            normal_nz_clamped,
            ndf: ndf_sources(scene),
            ndf_cfg: hw_model::ndf::NdfConfig::texram16(),
            ndf_clamped: 0,
        };
        let cfg = maps.ndf_cfg.clone();
        maps.build_ndf(&cfg, false);
        maps
    }

    /// Number of chains of the NDF moment maps (at the end of the lists).
    #[must_use]
    pub fn ndf_chains(&self) -> usize {
        4 * self.ndf.len()
    }

    /// True when the moment maps must be rebuilt for `cfg` (encoding, or the normalization
    /// map's density and regularization when `cfg` uses it).
    #[must_use]
    pub fn ndf_stale(&self, cfg: &hw_model::ndf::NdfConfig) -> bool {
        use hw_model::ndf::NdfNorm;
        let o = &self.ndf_cfg;
        let map = cfg.ndf_norm == NdfNorm::Map;
        !self.ndf.is_empty()
            && (o.moment_bits != cfg.moment_bits
                || o.moment_scale_bits != cfg.moment_scale_bits
                || (map
                    && (o.ndf_norm != NdfNorm::Map
                        || o.ndf_density != cfg.ndf_density
                        || o.pearson_m != cfg.pearson_m
                        || o.min_variance_bits() != cfg.min_variance_bits())))
    }

    /// Rebuilds the moment maps for `cfg` if [`Maps::ndf_stale`].
    pub fn ensure_ndf(&mut self, cfg: &hw_model::ndf::NdfConfig) {
        if self.ndf_stale(cfg) {
            self.build_ndf(cfg, true);
        }
    }

    fn build_ndf(&mut self, cfg: &hw_model::ndf::NdfConfig, replace: bool) {
        if replace {
            let keep = self.float.len() - self.ndf_chains();
            self.float.truncate(keep);
            self.fixed.truncate(keep);
        }
        self.ndf_cfg = cfg.clone();
        self.ndf_clamped = 0;
        for &(k, s) in &self.ndf {
            let (w, h, _, offs) = &self.bump_offsets[k];
            let normals: Vec<DVec3> = offs
                .iter()
                .map(|o| DVec3::new(f64::from(o[0]), f64::from(o[1]), 1.0).normalize())
                .collect();
            match crate::shading::ndf::build_ndf_maps(&normals, *w, *h, f64::from(s), cfg) {
                Ok(nm) => {
                    self.ndf_clamped += nm.clamped;
                    self.float.extend(nm.float);
                    self.fixed.extend([nm.mean, nm.diag, nm.off, nm.norm]);
                }
                Err(_) => {
                    let flat = vec![DVec3::Z; normals.len()];
                    let nm = crate::shading::ndf::build_ndf_maps(&flat, *w, *h, 1.0, cfg)
                        .expect("flat maps of a valid size");
                    self.float.extend(nm.float);
                    self.fixed.extend([nm.mean, nm.diag, nm.off, nm.norm]);
                }
            }
        }
    }

    /// Re-encodes the offset maps for another `offset_int_bits` if needed.
    pub fn ensure_offset_bits(&mut self, offset_int_bits: u32) {
        if self.offset_int_bits == offset_int_bits || self.bump_offsets.is_empty() {
            self.offset_int_bits = offset_int_bits;
            return;
        }
        let first = self.float.len() - self.bump_offsets.len() - self.ndf_chains();
        let texel_bits = self.fixed.first().map_or(16, |f| f.texel_bits);
        self.bump_clamped = self.normal_nz_clamped;
        for (k, (w, h, name, offs)) in self.bump_offsets.iter().enumerate() {
            let (c, q, cl) = offset_chain(*w, *h, name, offs, offset_int_bits, texel_bits);
            self.fixed[first + k] = q;
            self.float[first + k] = c;
            self.bump_clamped += cl;
        }
        self.offset_int_bits = offset_int_bits;
    }

    /// Re-quantizes for another texel width if needed (sweeps reuse the float chains).
    pub fn ensure_texel_bits(&mut self, texel_bits: u32) {
        if self
            .fixed
            .first()
            .is_some_and(|f| f.texel_bits != texel_bits)
        {
            let keep = self.float.len() - self.ndf_chains();
            let ndf = self.fixed.split_off(keep);
            let first_offset = keep - self.bump_offsets.len();
            self.fixed = quantize_host_maps(&self.float[..keep], first_offset, texel_bits);
            self.fixed.extend(ndf);
        }
    }
}
