//! Resource budgets: what a run will need, estimated from its inputs before anything large is
//! allocated, checked against one memory limit.
//!
//! The limit is [`DEFAULT_MAX_MEMORY`] (2 GiB) unless raised or lowered, in this order of
//! precedence, by [`set_max_memory`] (the command line's global `--max-memory SIZE`) or the
//! environment variable `TEXSIM_MAX_MEMORY` (`SIZE` is bytes or a number with `K`, `M`, `G`
//! or `T`, powers of 1024: `4G`, `512M`). The estimates are per item (bytes per triangle, per
//! texel, per pixel, per timing event) measured on this implementation with some headroom;
//! an input whose estimate exceeds the limit fails before it allocates, with an error that
//! names the field, what it needs and the limit.
//!
//! Files are read with caps too: a scene, material or hardware file must be a regular file
//! (not a device, FIFO or socket) and at most [`MAX_TEXT_FILE_BYTES`]; an OBJ file or an
//! image at most an eighth of the memory limit.

use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::scene::Scene;
use crate::{Error, Result};
use hw_model::HwConfig;

/// The memory limit when neither `--max-memory` nor `TEXSIM_MAX_MEMORY` sets one.
pub const DEFAULT_MAX_MEMORY: u64 = 2 << 30;
/// The environment variable that sets the memory limit.
pub const ENV_MAX_MEMORY: &str = "TEXSIM_MAX_MEMORY";
/// Largest scene TOML, MTL or hardware TOML file read, bytes.
pub const MAX_TEXT_FILE_BYTES: u64 = 64 << 20;

/// Bytes per triangle of a whole run, every triangle assumed visible: its set-up screen
/// triangle, its attributes in the units' formats and in float (the per-triangle arrays the
/// shading passes read; the float ones only when a float pass or twin reads them, counted
/// always), and [`BYTES_PER_DRAW`] for its indices, draw, plan index and setup outcome.
/// The sizes are the types' own, so the estimate follows them (544 B in all today). With
/// [`BYTES_PER_VERTEX`] a grid mesh is estimated at 640 B per triangle; measured, the peak
/// resident memory grows by 584 B per triangle of a fully visible grid at 256x256 (3,200 to
/// 180,000 triangles) and by 528 B at 1024x1024 (250k to 1M triangles), with the float vertex
/// data (without a float pass or twin reading it, about 140 B less: 555 -> 415 MB for 1M).
pub const BYTES_PER_TRIANGLE: u64 = (std::mem::size_of::<crate::raster::ScreenTri>()
    + std::mem::size_of::<crate::pipeline::stages::TriAttrs>()
    + std::mem::size_of::<crate::pipeline::stages::TriFloat>())
    as u64
    + BYTES_PER_DRAW;
/// ...of which the input triangle's indices (12 B), draw (16 B), plan index (4 B), the
/// setup's outcome and output order (16 B), the marks of the triangles the hardware pass
/// shades (2 B while they are built) and the loader's working copies, with headroom.
pub const BYTES_PER_DRAW: u64 = 96;
/// Bytes per vertex of a whole run: the mesh (32 B), the transformed and lit vertex of the
/// geometry (84 B) and its projection in the setup (48 B), with headroom.
pub const BYTES_PER_VERTEX: u64 = 192;
/// Extra bytes per triangle of a bump-mapped material (its per-triangle bump attributes)...
pub const BYTES_PER_BUMP_TRIANGLE: u64 =
    std::mem::size_of::<crate::pipeline::bump::BumpAttrs>() as u64;
/// ...and per vertex of a scene with a bump-mapped material (its bump vertex).
pub const BYTES_PER_BUMP_VERTEX: u64 =
    std::mem::size_of::<crate::pipeline::bump::BumpVertex>() as u64;
/// Bytes per texel of level 0 of a texture: the decoded image (8 B), its float (16 B) and
/// quantized (8 B) MIP chains (4/3 of level 0 each) and the working copies while they are
/// built.
pub const BYTES_PER_TEXEL: u64 = 48;
/// Bytes per bump-map texel and fitted Fournier lobe (`pipeline::lobe_fit`): its float (16 B)
/// and stored (8 B) lobe pyramids (4/3 of level 0 each).
pub const BYTES_PER_LOBE_TEXEL: u64 = 32;
/// Bytes per pixel of a render: visibility buffer and depth, the hardware image, coverage
/// mask, its PNG...
pub const BYTES_PER_PIXEL: u64 = 32;
/// ...and with the float reference: the reference (and truth) image, the error heat map, the
/// side-by-side sheet and their PNGs (measured in all: about 45 B per pixel on w2-mesh at
/// 2048x2048).
pub const BYTES_PER_REFERENCE_PIXEL: u64 = 32;
/// Bytes per triangle, vertex and pixel of the float passes' exact depth test when the
/// machine's depth buffer is narrower (`render`'s `exact_depth_vis`): the triangles set up
/// again with 30-bit depths (the screen triangle, its outcome and order), the vertices'
/// projections, and the second visibility buffer with its depth while it is rasterized.
pub const BYTES_PER_EXACT_DEPTH_TRIANGLE: u64 =
    std::mem::size_of::<crate::raster::ScreenTri>() as u64 + 16;
/// ...per vertex...
pub const BYTES_PER_EXACT_DEPTH_VERTEX: u64 = 48;
/// ...and per pixel.
pub const BYTES_PER_EXACT_DEPTH_PIXEL: u64 = 8;
/// Bytes per pixel of the timing model's event stream: the pixel event and its bookkeeping...
pub const BYTES_PER_EVENT_PIXEL: u64 = 16;
/// ...and per texture lookup of the most demanding material, two bilinear footprints (24 B
/// each, one per MIP level blended).
pub const BYTES_PER_EVENT_LOOKUP: u64 = 48;
/// Bytes per row of a sweep grid (the setting and its resolved configuration) held before the
/// first render, for the whole grid (every shard's rows).
pub const BYTES_PER_SWEEP_ROW: u64 = 8 << 10;
/// Bytes per row a sweep renders and keeps until it writes its outputs: the result row, its
/// JSON with the full configuration, the report's thumbnails. Measured as the growth of the
/// peak resident memory per row between grids of 276 and 1,104 rows: 96-98 KB at 1x1 pixels
/// (demo and bumps, cycles on and off, `--flip`), 157 KB at 160x120 and 169 KB at 400x300
/// (92 and 276 rows), about 155 KB at 1024x768 (23 and 69 rows: 21.3 MB, less the 14.2 MB of
/// the two more float passes kept, which have their own budget); with headroom.
pub const BYTES_PER_SWEEP_RESULT: u64 = 256 << 10;

/// 0: not set by [`set_max_memory`].
static LIMIT: AtomicU64 = AtomicU64::new(0);

/// Sets the memory limit of this process (the CLI's `--max-memory`); overrides
/// `TEXSIM_MAX_MEMORY`.
pub fn set_max_memory(bytes: u64) {
    LIMIT.store(bytes.max(1), Ordering::Relaxed);
}

/// The memory limit in force: [`set_max_memory`], else `TEXSIM_MAX_MEMORY`, else
/// [`DEFAULT_MAX_MEMORY`]. An unparsable environment value is reported by [`check_env`].
#[must_use]
pub fn max_memory() -> u64 {
    match LIMIT.load(Ordering::Relaxed) {
        0 => std::env::var(ENV_MAX_MEMORY)
            .ok()
            .and_then(|v| parse_size(&v).ok())
            .unwrap_or(DEFAULT_MAX_MEMORY),
        n => n,
    }
}

/// Checks that `TEXSIM_MAX_MEMORY`, when set, is a valid size.
pub fn check_env() -> Result<()> {
    match std::env::var(ENV_MAX_MEMORY) {
        Ok(v) => parse_size(&v)
            .map(|_| ())
            .map_err(|e| e.context(format!("environment variable {ENV_MAX_MEMORY}"))),
        Err(_) => Ok(()),
    }
}

/// Parses a size: bytes, or a number followed by `K`, `M`, `G` or `T` (powers of 1024; an
/// optional `B`/`iB` after the letter is accepted).
///
/// ```
/// assert_eq!(texsim::budget::parse_size("4G").unwrap(), 4 << 30);
/// assert_eq!(texsim::budget::parse_size("1536").unwrap(), 1536);
/// assert!(texsim::budget::parse_size("lots").is_err());
/// ```
pub fn parse_size(s: &str) -> Result<u64> {
    let t = s.trim();
    let upper = t.to_ascii_uppercase();
    let body = upper
        .strip_suffix("IB")
        .or_else(|| upper.strip_suffix('B'))
        .unwrap_or(&upper);
    let (num, shift) = match body.chars().last() {
        Some('K') => (&body[..body.len() - 1], 10),
        Some('M') => (&body[..body.len() - 1], 20),
        Some('G') => (&body[..body.len() - 1], 30),
        Some('T') => (&body[..body.len() - 1], 40),
        _ => (body, 0),
    };
    let bad = || {
        Error::field(
            "max memory",
            format!("'{s}' is not a size (bytes, or a number with K, M, G or T: 4G, 512M)"),
        )
    };
    let n: u64 = num.trim().parse().map_err(|_| bad())?;
    let v = n.checked_mul(1u64 << shift).ok_or_else(bad)?;
    if v == 0 {
        return Err(bad());
    }
    Ok(v)
}

/// A byte count for messages: `1.50 GiB`, `12.0 MiB`, `900 B`.
#[must_use]
pub fn human(bytes: u64) -> String {
    const UNITS: [(&str, u64); 4] = [
        ("TiB", 1 << 40),
        ("GiB", 1 << 30),
        ("MiB", 1 << 20),
        ("KiB", 1 << 10),
    ];
    for (u, s) in UNITS {
        if bytes >= s {
            #[allow(clippy::cast_precision_loss)]
            return format!("{:.2} {u}", bytes as f64 / s as f64);
        }
    }
    format!("{bytes} B")
}

/// The error of a need over the limit: names the field, the need, the limit and how to raise it.
#[must_use]
pub fn over_budget(field: &str, what: &str, need: u64, limit: u64) -> Error {
    Error::field(
        field,
        format!(
            "{what} needs about {} of memory, over the limit of {} (raise it with --max-memory SIZE or {ENV_MAX_MEMORY}=SIZE, e.g. 8G)",
            human(need),
            human(limit)
        ),
    )
}

/// Fails with [`over_budget`] when `need` exceeds the limit in force.
pub fn check(field: &str, what: &str, need: u64) -> Result<()> {
    let limit = max_memory();
    if need > limit {
        return Err(over_budget(field, what, need, limit));
    }
    Ok(())
}

/// `a * b`, saturating (a need that overflows is over any limit).
#[must_use]
pub fn mul(a: u64, b: u64) -> u64 {
    a.saturating_mul(b)
}

/// What one run needs, by kind, in bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunNeed {
    pub triangles: u64,
    pub texels: u64,
    pub framebuffer: u64,
    pub events: u64,
}

impl RunNeed {
    /// The total, saturating.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.triangles
            .saturating_add(self.texels)
            .saturating_add(self.framebuffer)
            .saturating_add(self.events)
    }

    /// The estimate of a render of `scene` on `hw` (with the float reference when
    /// `reference`, the timing event stream when `timing`).
    #[must_use]
    pub fn of(scene: &Scene, hw: &HwConfig, reference: bool, timing: bool) -> Self {
        let pixels = u64::from(scene.width) * u64::from(scene.height);
        let texels = scene
            .textures
            .iter()
            .map(|t| u64::from(t.width) * u64::from(t.height))
            .fold(0u64, u64::saturating_add);
        // Fitted Fournier lobes: K float and stored lobe pyramids per bump map texel.
        let lobe_texels = scene
            .materials
            .iter()
            .filter_map(|m| {
                let t = scene.textures.get(m.bump?)?;
                let k = u64::from(m.fournier_lobes?.resolve(hw));
                Some(mul(u64::from(t.width) * u64::from(t.height), k))
            })
            .fold(0u64, u64::saturating_add);
        // The float passes' exact depth test sets the scene up and rasterizes it again.
        let exact_depth = reference && hw.raster.depth_bits < crate::raster::MAX_DEPTH_BITS;
        let (exact_tris, exact_pixels) = if exact_depth {
            let (tris, verts) = scene.meshes.iter().fold((0u64, 0u64), |(t, v), m| {
                (
                    t.saturating_add(m.indices.len() as u64),
                    v.saturating_add(m.positions.len() as u64),
                )
            });
            (
                mul(tris, BYTES_PER_EXACT_DEPTH_TRIANGLE)
                    .saturating_add(mul(verts, BYTES_PER_EXACT_DEPTH_VERTEX)),
                mul(pixels, BYTES_PER_EXACT_DEPTH_PIXEL),
            )
        } else {
            (0, 0)
        };
        Self {
            triangles: mesh_bytes(scene).saturating_add(exact_tris),
            texels: mul(texels, BYTES_PER_TEXEL)
                .saturating_add(mul(lobe_texels, BYTES_PER_LOBE_TEXEL)),
            framebuffer: mul(
                pixels,
                BYTES_PER_PIXEL
                    + if reference {
                        BYTES_PER_REFERENCE_PIXEL
                    } else {
                        0
                    },
            )
            .saturating_add(exact_pixels),
            events: if timing {
                let per_pixel = BYTES_PER_EVENT_PIXEL
                    + BYTES_PER_EVENT_LOOKUP * u64::from(max_lookups(scene, hw));
                mul(pixels, per_pixel)
            } else {
                0
            },
        }
    }

    /// Fails when the total exceeds the limit in force; the error names the largest part.
    pub fn check(&self, scene: &Scene) -> Result<()> {
        let limit = max_memory();
        let total = self.total();
        if total <= limit {
            return Ok(());
        }
        let parts = [
            (
                "triangles",
                self.triangles,
                format!("{} triangles", scene.triangle_count()),
            ),
            (
                "textures",
                self.texels,
                format!("{} textures", scene.textures.len()),
            ),
            (
                "width x height",
                self.framebuffer,
                format!("a {}x{} framebuffer", scene.width, scene.height),
            ),
            (
                "width x height",
                self.events,
                format!(
                    "the timing events of {}x{} pixels",
                    scene.width, scene.height
                ),
            ),
        ];
        let (field, _, what) = parts
            .iter()
            .max_by_key(|p| p.1)
            .cloned()
            .unwrap_or_default();
        // `render` and `sweep` collect timing events by default: say when skipping them fits.
        let hint = if self.events > 0 && total - self.events <= limit {
            format!(
                "; without the timing events it needs {}: `render` and `sweep` skip them with --no-cycles",
                human(total - self.events)
            )
        } else {
            String::new()
        };
        Err(over_budget(
            field,
            &format!(
                "the run ({what}; in all: triangles {}, textures {}, framebuffer {}, timing events {}{hint})",
                human(self.triangles),
                human(self.texels),
                human(self.framebuffer),
                human(self.events)
            ),
            total,
            limit,
        ))
    }
}

/// The bytes of `scene`'s meshes through a run: [`BYTES_PER_TRIANGLE`] and
/// [`BYTES_PER_VERTEX`] each, plus [`BYTES_PER_BUMP_TRIANGLE`] per triangle of a bump-mapped
/// mesh and [`BYTES_PER_BUMP_VERTEX`] per vertex when any mesh is bump mapped.
#[must_use]
pub fn mesh_bytes(scene: &Scene) -> u64 {
    let bumped = |m: &crate::scene::Mesh| {
        scene
            .materials
            .get(m.material)
            .is_some_and(|mat| mat.bump.is_some())
    };
    let any_bump = scene.meshes.iter().any(bumped);
    scene
        .meshes
        .iter()
        .map(|m| {
            let per_tri = BYTES_PER_TRIANGLE
                + if bumped(m) {
                    BYTES_PER_BUMP_TRIANGLE
                } else {
                    0
                };
            let per_vertex = BYTES_PER_VERTEX + if any_bump { BYTES_PER_BUMP_VERTEX } else { 0 };
            mul(m.indices.len() as u64, per_tri)
                .saturating_add(mul(m.positions.len() as u64, per_vertex))
        })
        .fold(0u64, u64::saturating_add)
}

/// Texture lookups per pixel of the scene's most demanding material on `hw` (at least 1):
/// its texture (`aniso_probes` each), bump and roughness maps, NDF moment maps, exponent map,
/// fitted Fournier lobe maps (one each).
#[must_use]
pub fn max_lookups(scene: &Scene, hw: &HwConfig) -> u32 {
    scene
        .materials
        .iter()
        .map(|m| {
            let tex = if m.texture.is_some() {
                hw.trilinear.aniso_probes.max(1)
            } else {
                0
            };
            let bump = u32::from(m.bump.is_some());
            let rough = u32::from(m.roughness.is_some());
            let ndf = if m.ndf {
                hw_model::ndf::ndf_lookups(&hw.ndf)
            } else {
                0
            };
            let exp = u32::from(m.brdf.is_some_and(|b| b.exponent_map.is_some()));
            let lobes = m
                .fournier_lobes
                .map_or(0, |c| c.resolve(hw).min(hw.multi_lobe.lobe_max_lobes));
            tex + bump + rough + ndf + exp + lobes
        })
        .max()
        .unwrap_or(0)
        .max(1)
}

/// Checks the whole run of `scene` on `hw` (with the float reference when `reference`, the
/// timing events when `timing`) against the limit before anything of it is allocated.
pub fn check_run(scene: &Scene, hw: &HwConfig, reference: bool, timing: bool) -> Result<()> {
    RunNeed::of(scene, hw, reference, timing).check(scene)
}

/// Opens `path` for reading if it is a regular file of at most `cap` bytes; `what` names the
/// kind of file in errors ("an OBJ file"). A directory, device, FIFO or socket is refused
/// before it is opened (so a FIFO never blocks).
pub fn open_regular(path: &Path, what: &str, cap: u64) -> Result<File> {
    let meta = std::fs::metadata(path)
        .map_err(|e| Error::file(path, format!("cannot open {what}: {e}")))?;
    if meta.is_dir() {
        return Err(Error::file(
            path,
            format!("is a directory, expected {what}"),
        ));
    }
    if !meta.is_file() {
        return Err(Error::file(
            path,
            format!("is not a regular file (a device, FIFO or socket), expected {what}"),
        ));
    }
    if meta.len() > cap {
        return Err(Error::file(
            path,
            format!(
                "{what} of {} is over the limit of {} for this kind of file (raise it with --max-memory SIZE or {ENV_MAX_MEMORY}=SIZE)",
                human(meta.len()),
                human(cap)
            ),
        ));
    }
    File::open(path).map_err(|e| Error::file(path, format!("cannot open {what}: {e}")))
}

/// Reads a regular file of at most `cap` bytes (see [`open_regular`]); a file that grows past
/// `cap` while it is read is refused too.
pub fn read_capped(path: &Path, what: &str, cap: u64) -> Result<Vec<u8>> {
    let f = open_regular(path, what, cap)?;
    let mut bytes = Vec::new();
    f.take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| Error::file(path, format!("cannot read {what}: {e}")))?;
    if bytes.len() as u64 > cap {
        return Err(Error::file(
            path,
            format!("{what} is over the limit of {} bytes", cap),
        ));
    }
    Ok(bytes)
}

/// Reads a UTF-8 text file of at most [`MAX_TEXT_FILE_BYTES`] (see [`read_capped`]).
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let bytes = read_capped(path, what, MAX_TEXT_FILE_BYTES)?;
    String::from_utf8(bytes).map_err(|e| {
        Error::file(
            path,
            format!(
                "cannot read {what}: not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// Largest OBJ or image file read: an eighth of the memory limit.
#[must_use]
pub fn max_binary_file_bytes() -> u64 {
    max_memory() / 8
}
