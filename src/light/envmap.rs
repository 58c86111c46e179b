//! Environment maps: loading (Radiance `.hdr`, OpenEXR `.exr`, cube crosses,
//! six cube faces), sanitizing, procedural sources and resampling.
//!
//! # Direction convention (the GPU shaders copy this exactly)
//! An [`EnvMap`] is an equirectangular (lat-long) image of linear RGB radiance,
//! row-major, row 0 at the top. World space is right-handed with **+Y up**.
//! For texture coordinates `(u, v)` in `[0, 1]²` (texel `(x, y)` has its centre
//! at `u = (x + 0.5) / W`, `v = (y + 0.5) / H`):
//! ```text
//! θ = π·v            (polar angle measured from +Y)
//! φ = 2π·(u − 0.5)
//! dir = (sin θ · sin φ,  cos θ,  −sin θ · cos φ)
//! ```
//! so `u = 0.5` looks toward −Z, `u = 0.75` toward +X, `u = 0.25` toward −X and
//! the left/right edge (`u = 0 ≡ 1`) toward +Z; `v = 0` is straight up. The
//! inverse is `u = atan2(x, −z) / 2π + 0.5`, `v = acos(y) / π`.
//!
//! A texel in row `y` subtends exactly `(2π / W)·(cos θ0 − cos θ1)` steradians,
//! `θ0 = π·y / H`, `θ1 = π·(y + 1) / H` ([`texel_solid_angle`]); the whole map sums
//! to 4π.
//!
//! # Cube maps
//! Cube faces use the standard OpenGL / Vulkan cube-map convention (OpenGL 4.6
//! spec, table 8.19; Vulkan spec "Cube Map Face Selection"): for a direction
//! `(rx, ry, rz)` the face is chosen by the major axis and
//! ```text
//! face  sc   tc   ma        face  sc   tc   ma
//! +X   −rz  −ry   rx        −X   +rz  −ry   rx
//! +Y   +rx  +rz   ry        −Y   +rx  −rz   ry
//! +Z   +rx  −ry   rz        −Z   −rx  −ry   rz
//! s = (sc/|ma| + 1)/2,  t = (tc/|ma| + 1)/2,  t = 0 is the face image's top row.
//! ```
//! Crosses are unfolded so that every face keeps this orientation, except the −Z
//! face of the vertical cross, which is stored rotated by 180° (the usual
//! HDRShop / light-probe layout, so it joins −Y below it):
//! ```text
//! horizontal cross (4:3)          vertical cross (3:4)
//!       [+Y]                            [+Y]
//! [−X] [+Z] [+X] [−Z]             [−X] [+Z] [+X]
//!       [−Y]                            [−Y]
//!                                       [−Z]  (rotated 180°)
//! ```
//! Cube maps are resampled to an equirect map of `4s × 2s` texels (face size
//! `s`) with bilinear filtering inside each face (clamped at face edges).
//!
//! # Rotation
//! [`EnvMap::rotated_y`] rotates the *content* about +Y by a right-handed angle:
//! positive degrees turn counter-clockwise when seen from above (+X toward −Z),
//! i.e. the rotation `glam::Mat3::from_rotation_y(deg.to_radians())`; radiance
//! that arrived from `d` now arrives from `R·d`. `sh::rotate_y` matches it.

use std::fmt;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec2, Vec3};

use crate::light::sky::{render_sky, SkyError, SkyParams};

/// Widest accepted image (texels).
pub const MAX_WIDTH: u32 = 16384;
/// Most texels accepted in one image (a 16384 × 8192 equirect map, 1.5 GiB as f32).
pub const MAX_TEXELS: u64 = 16384 * 8192;
/// Largest finite IEEE half float. +Inf is clamped to this because the GPU keeps
/// radiance in RGBA16F: anything larger would turn back into Inf on upload, while
/// 65504 still reads as "extremely bright" and keeps SH sums finite.
pub const HALF_MAX: f32 = 65504.0;

/// Equirectangular linear-RGB radiance map (see the module doc for the convention).
/// Invariant (kept by every constructor here): `texels.len() == width * height`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

/// How many channel values were replaced by [`sanitize`]. Counts are per channel
/// value (a texel with NaN in R and G counts 2). −Inf counts as `inf` and becomes 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SanitizeReport {
    pub nan: usize,
    pub inf: usize,
    pub negative: usize,
}

impl SanitizeReport {
    /// Total number of replaced channel values.
    pub fn total(&self) -> usize {
        self.nan + self.inf + self.negative
    }

    fn add(&mut self, other: SanitizeReport) {
        self.nan += other.nan;
        self.inf += other.inf;
        self.negative += other.negative;
    }
}

/// Errors from loading or resolving an environment. Every message is one line
/// and names the file (or the source string) and the problem.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    #[error("{path}: file not found")]
    NotFound { path: PathBuf },
    #[error("{path}: cannot read file: {detail}")]
    Io { path: PathBuf, detail: String },
    #[error("{path}: unknown extension (expected .hdr or .exr)")]
    UnknownExtension { path: PathBuf },
    #[error("{path}: truncated or corrupt data: {detail}")]
    Corrupt { path: PathBuf, detail: String },
    #[error(
        "{path}: unsupported aspect ratio {width}x{height} \
         (expected 2:1 equirect, 4:3 horizontal cross or 3:4 vertical cross)"
    )]
    Aspect {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error(
        "{path}: image size {width}x{height} is too large \
         (at most {MAX_WIDTH} wide and {MAX_TEXELS} texels)"
    )]
    TooLarge {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error("{path}: no R, G, B channels found in any layer")]
    NoRgb { path: PathBuf },
    #[error("{path}: bad cube face: {detail}")]
    CubeFace { path: PathBuf, detail: String },
    #[error("environment source '{source_str}': {detail}")]
    BadSource { source_str: String, detail: String },
    #[error("environment size {width}x{height} is invalid (need 1..={MAX_WIDTH} wide, at most {MAX_TEXELS} texels)")]
    BadSize { width: u32, height: u32 },
    #[error("sky: {0}")]
    Sky(#[from] SkyError),
}

/// Where an environment comes from (see [`parse_source`]).
#[derive(Clone, Debug, PartialEq)]
pub enum EnvSource {
    /// `uniform:R,G,B` (or `uniform:V` for grey): constant radiance.
    Uniform(Vec3),
    /// `sky` or `sky:elevation=30,azimuth=120,turbidity=3,intensity=1`.
    Sky(SkyParams),
    /// `cube:PX,NX,PY,NY,PZ,NZ`: six face files (+X, −X, +Y, −Y, +Z, −Z).
    CubeFaces([PathBuf; 6]),
    /// Anything else: a `.hdr` / `.exr` file.
    File(PathBuf),
}

impl fmt::Display for EnvSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvSource::Uniform(c) => write!(f, "uniform:{},{},{}", c.x, c.y, c.z),
            EnvSource::Sky(p) => write!(
                f,
                "sky:elevation={},azimuth={},turbidity={},intensity={}",
                p.elevation_deg, p.azimuth_deg, p.turbidity, p.intensity
            ),
            EnvSource::CubeFaces(faces) => {
                let names: Vec<String> = faces.iter().map(|p| p.display().to_string()).collect();
                write!(f, "cube:{}", names.join(","))
            }
            EnvSource::File(p) => write!(f, "{}", p.display()),
        }
    }
}

// ---------------------------------------------------------------------------
// Direction convention
// ---------------------------------------------------------------------------

/// World direction for equirect coordinates `(u, v)` (module doc convention).
pub fn direction(u: f32, v: f32) -> Vec3 {
    let theta = std::f32::consts::PI * v;
    let phi = std::f32::consts::TAU * (u - 0.5);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * sp, ct, -st * cp)
}

/// Inverse of [`direction`]: `u ∈ [0, 1]`, `v ∈ [0, 1]`. `d` need not be unit
/// length; a zero or non-finite `d` gives `(0.5, 0.5)`.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let d = d.normalize_or_zero();
    if d == Vec3::ZERO {
        return Vec2::new(0.5, 0.5);
    }
    let u = d.x.atan2(-d.z) / std::f32::consts::TAU + 0.5;
    let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    Vec2::new(u, v)
}

/// Exact solid angle (sr) of any texel in row `y` of a `width × height` map:
/// `(2π/W)(cos θ0 − cos θ1)`. Zero for empty maps or rows outside the map.
pub fn texel_solid_angle(y: u32, width: u32, height: u32) -> f32 {
    texel_solid_angle_f64(y, width, height) as f32
}

pub(crate) fn texel_solid_angle_f64(y: u32, width: u32, height: u32) -> f64 {
    if width == 0 || height == 0 || y >= height {
        return 0.0;
    }
    let pi = std::f64::consts::PI;
    let t0 = pi * f64::from(y) / f64::from(height);
    let t1 = pi * (f64::from(y) + 1.0) / f64::from(height);
    std::f64::consts::TAU / f64::from(width) * (t0.cos() - t1.cos())
}

/// Clamp a requested size into `[1, MAX_WIDTH] × [1, …]` with at most
/// `MAX_TEXELS` texels.
fn clamp_size(width: u32, height: u32) -> (u32, u32) {
    let w = width.clamp(1, MAX_WIDTH);
    let max_h = (MAX_TEXELS / u64::from(w)).min(u64::from(u32::MAX)) as u32;
    (w, height.clamp(1, max_h))
}

fn size_ok(width: u32, height: u32) -> bool {
    width >= 1
        && height >= 1
        && width <= MAX_WIDTH
        && u64::from(width) * u64::from(height) <= MAX_TEXELS
}

// ---------------------------------------------------------------------------
// EnvMap
// ---------------------------------------------------------------------------

impl EnvMap {
    /// Constant radiance `rgb` everywhere. Sizes are clamped to at least 1 and at
    /// most [`MAX_WIDTH`] / [`MAX_TEXELS`].
    pub fn uniform(rgb: Vec3, width: u32, height: u32) -> EnvMap {
        let (width, height) = clamp_size(width, height);
        EnvMap {
            width,
            height,
            texels: vec![rgb; width as usize * height as usize],
        }
    }

    /// Build a map by evaluating `f(direction)` at every texel centre. Sizes are
    /// clamped like [`EnvMap::uniform`].
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(Vec3) -> Vec3) -> EnvMap {
        let (width, height) = clamp_size(width, height);
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            let v = (y as f32 + 0.5) / height as f32;
            for x in 0..width {
                let u = (x as f32 + 0.5) / width as f32;
                texels.push(f(direction(u, v)));
            }
        }
        EnvMap {
            width,
            height,
            texels,
        }
    }

    /// Texel `(x, y)`; zero outside the map.
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        if x >= self.width || y >= self.height {
            return Vec3::ZERO;
        }
        let i = y as usize * self.width as usize + x as usize;
        self.texels.get(i).copied().unwrap_or(Vec3::ZERO)
    }

    /// Direction through the centre of texel `(x, y)`.
    pub fn texel_direction(&self, x: u32, y: u32) -> Vec3 {
        let u = (x as f32 + 0.5) / self.width.max(1) as f32;
        let v = (y as f32 + 0.5) / self.height.max(1) as f32;
        direction(u, v)
    }

    /// Bilinear lookup at `(u, v)`: wraps in u, clamps in v (texel centres at
    /// `(x + 0.5) / W`).
    pub fn sample_uv(&self, uv: Vec2) -> Vec3 {
        if self.width == 0 || self.height == 0 || !uv.is_finite() {
            return Vec3::ZERO;
        }
        let w = self.width as f32;
        let h = self.height as f32;
        let fx = uv.x * w - 0.5;
        let fy = (uv.y * h - 0.5).clamp(0.0, h - 1.0);
        let x0f = fx.floor();
        let y0f = fy.floor();
        let tx = fx - x0f;
        let ty = fy - y0f;
        let wrap = |x: f32| -> u32 { (x.rem_euclid(w) as u32).min(self.width - 1) };
        let x0 = wrap(x0f);
        let x1 = wrap(x0f + 1.0);
        let y0 = (y0f as u32).min(self.height - 1);
        let y1 = (y0 + 1).min(self.height - 1);
        let top = self.texel(x0, y0).lerp(self.texel(x1, y0), tx);
        let bottom = self.texel(x0, y1).lerp(self.texel(x1, y1), tx);
        top.lerp(bottom, ty)
    }

    /// Bilinear lookup of the radiance arriving from direction `d`.
    pub fn sample_dir(&self, d: Vec3) -> Vec3 {
        self.sample_uv(direction_to_uv(d))
    }

    /// Solid-angle weighted mean radiance (irradiance-free average over 4π).
    pub fn mean(&self) -> Vec3 {
        let mut acc = [0.0f64; 3];
        for y in 0..self.height {
            let w = texel_solid_angle_f64(y, self.width, self.height);
            for x in 0..self.width {
                let t = self.texel(x, y);
                acc[0] += f64::from(t.x) * w;
                acc[1] += f64::from(t.y) * w;
                acc[2] += f64::from(t.z) * w;
            }
        }
        let s = 1.0 / (4.0 * std::f64::consts::PI);
        Vec3::new(
            (acc[0] * s) as f32,
            (acc[1] * s) as f32,
            (acc[2] * s) as f32,
        )
    }

    /// The content rotated about +Y by `degrees` (right-handed: positive is
    /// counter-clockwise seen from above, +X toward −Z). Radiance from `d` moves
    /// to `Mat3::from_rotation_y(degrees.to_radians()) · d`. A rotation about the
    /// pole is a pure shift in u, so each row is resampled with linear
    /// interpolation along u (exact for whole-texel shifts).
    pub fn rotated_y(&self, degrees: f32) -> EnvMap {
        if self.width == 0 || self.height == 0 || !degrees.is_finite() {
            return self.clone();
        }
        // R_y(α) maps φ → φ − α, so new(φ) = old(φ + α): source x = x + α/2π · W.
        let shift = f64::from(degrees).to_radians() / std::f64::consts::TAU * f64::from(self.width);
        let shift = shift.rem_euclid(f64::from(self.width));
        let whole = shift.floor();
        let frac = (shift - whole) as f32;
        let whole = whole as u32;
        let mut texels = Vec::with_capacity(self.texels.len());
        for y in 0..self.height {
            for x in 0..self.width {
                let x0 = ((u64::from(x) + u64::from(whole)) % u64::from(self.width)) as u32;
                let x1 = ((u64::from(x0) + 1) % u64::from(self.width)) as u32;
                texels.push(self.texel(x0, y).lerp(self.texel(x1, y), frac));
            }
        }
        EnvMap {
            width: self.width,
            height: self.height,
            texels,
        }
    }

    /// The content rotated by the 3×3 rotation `r` (radiance from `d` moves to
    /// `r·d`), bilinear resampling. Prefer [`EnvMap::rotated_y`] for yaw.
    pub fn rotated(&self, r: Mat3) -> EnvMap {
        let inv = r.transpose();
        EnvMap::from_fn(self.width, self.height, |d| self.sample_dir(inv * d))
    }

    /// Replace NaN / ±Inf / negative channel values in place (see [`sanitize`]).
    pub fn sanitize(&mut self) -> SanitizeReport {
        sanitize(&mut self.texels)
    }
}

/// Replace bad channel values in place: NaN → 0, negative (incl. −Inf) → 0,
/// +Inf → [`HALF_MAX`]. Returns per-kind counts (per channel value).
pub fn sanitize(texels: &mut [Vec3]) -> SanitizeReport {
    let mut r = SanitizeReport::default();
    for t in texels.iter_mut() {
        for c in [&mut t.x, &mut t.y, &mut t.z] {
            if c.is_nan() {
                r.nan += 1;
                *c = 0.0;
            } else if c.is_infinite() {
                r.inf += 1;
                *c = if *c > 0.0 { HALF_MAX } else { 0.0 };
            } else if *c < 0.0 {
                r.negative += 1;
                *c = 0.0;
            }
        }
    }
    r
}

// ---------------------------------------------------------------------------
// Loading
// ---------------------------------------------------------------------------

/// A decoded RGB image before layout interpretation.
struct RawImage {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl RawImage {
    fn get(&self, x: u32, y: u32) -> Vec3 {
        if x >= self.width || y >= self.height {
            return Vec3::ZERO;
        }
        let i = y as usize * self.width as usize + x as usize;
        self.texels.get(i).copied().unwrap_or(Vec3::ZERO)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    Equirect,
    HorizontalCross,
    VerticalCross,
}

fn detect_layout(path: &Path, width: u64, height: u64) -> Result<Layout, EnvError> {
    if width > 0 && width == 2 * height {
        Ok(Layout::Equirect)
    } else if width > 0 && width.is_multiple_of(4) && 3 * width == 4 * height {
        Ok(Layout::HorizontalCross)
    } else if width > 0 && width.is_multiple_of(3) && 4 * width == 3 * height {
        Ok(Layout::VerticalCross)
    } else {
        Err(EnvError::Aspect {
            path: path.to_path_buf(),
            width,
            height,
        })
    }
}

/// Size limits shared by all decoders, checked before any pixel allocation.
fn check_size(path: &Path, width: u64, height: u64) -> Result<(), EnvError> {
    if width == 0 || height == 0 {
        return Err(corrupt(path, format!("empty image ({width}x{height})")));
    }
    if width > u64::from(MAX_WIDTH) || width.saturating_mul(height) > MAX_TEXELS {
        return Err(EnvError::TooLarge {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    Ok(())
}

fn corrupt(path: &Path, detail: impl fmt::Display) -> EnvError {
    // Keep messages on one line whatever the decoder says.
    let detail = detail.to_string().replace(['\n', '\r'], " ");
    EnvError::Corrupt {
        path: path.to_path_buf(),
        detail,
    }
}

/// Allocate a zeroed vector without aborting the process on failure.
fn try_zeroed<T: Clone + Default>(path: &Path, len: usize) -> Result<Vec<T>, EnvError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| corrupt(path, format!("cannot allocate {len} texels")))?;
    v.resize(len, T::default());
    Ok(v)
}

/// Read and decode an `.hdr` / `.exr` file into a raw RGB image. `check` sees
/// the header size before pixel memory is allocated.
fn read_raw(
    path: &Path,
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            return Err(EnvError::Io {
                path: path.to_path_buf(),
                detail: "not a regular file".into(),
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(EnvError::NotFound {
                path: path.to_path_buf(),
            })
        }
        Err(e) => {
            return Err(EnvError::Io {
                path: path.to_path_buf(),
                detail: e.to_string(),
            })
        }
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let is_hdr = match ext.as_deref() {
        Some("hdr") => true,
        Some("exr") => false,
        _ => {
            return Err(EnvError::UnknownExtension {
                path: path.to_path_buf(),
            })
        }
    };
    let bytes = std::fs::read(path).map_err(|e| EnvError::Io {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;
    // The decoders are third-party code fed with untrusted bytes: a panic in
    // them must become an error, never take the renderer down.
    let decoded = catch_unwind(AssertUnwindSafe(|| {
        if is_hdr {
            decode_hdr(path, &bytes, check)
        } else {
            decode_exr(path, &bytes, check)
        }
    }));
    match decoded {
        Ok(r) => r,
        Err(_) => Err(corrupt(path, "decoder panicked on malformed data")),
    }
}

fn decode_hdr(
    path: &Path,
    bytes: &[u8],
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    use image::codecs::hdr::HdrDecoder;
    use image::ImageDecoder;

    let decoder = HdrDecoder::new(Cursor::new(bytes)).map_err(|e| corrupt(path, e))?;
    let (w, h) = decoder.dimensions();
    check_size(path, u64::from(w), u64::from(h))?;
    check(path, u64::from(w), u64::from(h))?;
    let n = w as usize * h as usize;
    let total = usize::try_from(decoder.total_bytes()).unwrap_or(usize::MAX);
    if Some(total) != n.checked_mul(12) {
        return Err(corrupt(path, "unexpected decoded size"));
    }
    let mut buf: Vec<u8> = try_zeroed(path, total)?;
    decoder.read_image(&mut buf).map_err(|e| corrupt(path, e))?;
    let mut texels: Vec<Vec3> = Vec::new();
    texels
        .try_reserve_exact(n)
        .map_err(|_| corrupt(path, format!("cannot allocate {n} texels")))?;
    // The decoder writes Rgb<f32> in native byte order.
    for px in buf.chunks_exact(12) {
        let f = |i: usize| -> f32 {
            let mut b = [0u8; 4];
            if let Some(s) = px.get(i..i + 4) {
                b.copy_from_slice(s);
            }
            f32::from_ne_bytes(b)
        };
        texels.push(Vec3::new(f(0), f(4), f(8)));
    }
    Ok(RawImage {
        width: w,
        height: h,
        texels,
    })
}

fn decode_exr(
    path: &Path,
    bytes: &[u8],
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    use exr::prelude::{read, ReadChannels, ReadLayers, ReadSpecificChannel};

    // Read the headers first: find the RGB layer and check its size before the
    // decoder allocates pixel storage.
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| corrupt(path, e))?;
    let header = meta
        .headers
        .iter()
        .find(|h| {
            ["R", "G", "B"]
                .iter()
                .all(|c| h.channels.list.iter().any(|ch| ch.name.eq(c)))
        })
        .ok_or_else(|| EnvError::NoRgb {
            path: path.to_path_buf(),
        })?;
    let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    check_size(path, w, h)?;
    check(path, w, h)?;
    check_dwa_chunks(path, bytes, &meta)?;
    let (w, h) = (w as u32, h as u32);
    let n = w as usize * h as usize;

    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("R")
        .required("G")
        .required("B")
        .collect_pixels(
            move |size, _channels| {
                // The size was checked above; a layer of another size or a
                // failed allocation gives an empty buffer, reported below.
                let mut v: Vec<Vec3> = Vec::new();
                if size.0 == w as usize && size.1 == h as usize && v.try_reserve_exact(n).is_ok() {
                    v.resize(n, Vec3::ZERO);
                }
                (size.0, v)
            },
            |px: &mut (usize, Vec<Vec3>), pos, (r, g, b): (f32, f32, f32)| {
                let i = pos.1 * px.0 + pos.0;
                if let Some(t) = px.1.get_mut(i) {
                    *t = Vec3::new(r, g, b);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| corrupt(path, e))?;
    let (stride, pixels) = image.layer_data.channel_data.pixels;
    if stride != w as usize || pixels.len() != n {
        return Err(corrupt(path, "decoded layer size differs from header"));
    }
    Ok(RawImage {
        width: w,
        height: h,
        texels: pixels,
    })
}

/// Guard for the `exr` crate's DWAA/DWAB decoder (1.74), which allocates
/// whatever sizes a chunk's DWA leader declares: one flipped bit in
/// `studio.exr` asked for 34 GB and aborted the process (found by the bit-flip
/// test). Before decoding, every DWA chunk's eleven u64 counters are checked
/// against the block's uncompressed size. Only single-part scan-line files are
/// walked; DWA in multi-part or tiled files is refused.
fn check_dwa_chunks(path: &Path, bytes: &[u8], meta: &exr::meta::MetaData) -> Result<(), EnvError> {
    use exr::compression::Compression;
    use exr::meta::BlockDescription;

    let is_dwa = |c: Compression| matches!(c, Compression::DWAA(_) | Compression::DWAB(_));
    if !meta.headers.iter().any(|h| is_dwa(h.compression)) {
        return Ok(());
    }
    let header = match meta.headers.as_slice() {
        [h] if !h.deep && matches!(h.blocks, BlockDescription::ScanLines) => h,
        _ => {
            return Err(corrupt(
                path,
                "DWA compression is only supported in single-part scan-line files",
            ))
        }
    };
    let rd = |at: usize, n: usize| -> Result<&[u8], EnvError> {
        at.checked_add(n)
            .and_then(|end| bytes.get(at..end))
            .ok_or_else(|| corrupt(path, "unexpected end of file"))
    };
    let cstr_end = |at: usize| -> Result<usize, EnvError> {
        let rest = bytes.get(at..).unwrap_or(&[]);
        rest.iter()
            .take(256)
            .position(|&b| b == 0)
            .map(|i| at + i)
            .ok_or_else(|| corrupt(path, "bad attribute name in header"))
    };
    // Header attributes: name\0 type\0 size:i32 value; an empty name ends it.
    let mut at = 8; // magic + version
    loop {
        let name_end = cstr_end(at)?;
        if name_end == at {
            at += 1;
            break;
        }
        let type_end = cstr_end(name_end + 1)?;
        let size_bytes = rd(type_end + 1, 4)?;
        let size = i32::from_le_bytes([size_bytes[0], size_bytes[1], size_bytes[2], size_bytes[3]]);
        let size = usize::try_from(size).map_err(|_| corrupt(path, "negative attribute size"))?;
        at = type_end + 5;
        rd(at, size)?;
        at += size;
    }
    let width = header.layer_size.0;
    let lines = header.compression.scan_lines_per_block();
    let channels = header.channels.list.len();
    // Upper bound on a block's uncompressed bytes (4-byte samples, no
    // subsampling), with slack for RLE token expansion.
    let block = width
        .saturating_mul(lines)
        .saturating_mul(channels)
        .saturating_mul(4);
    let limit = block.saturating_mul(2).saturating_add(4096) as u64;
    for k in 0..header.chunk_count {
        let o = rd(at + 8 * k, 8)?;
        let offset = u64::from_le_bytes([o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7]]);
        let offset = usize::try_from(offset).unwrap_or(usize::MAX);
        let size = rd(offset.saturating_add(4), 4)?;
        let size = u32::from_le_bytes([size[0], size[1], size[2], size[3]]) as usize;
        let data = rd(offset.saturating_add(8), size)?;
        if data.len() < 88 {
            continue; // stored raw or too short: the decoder rejects or copies it
        }
        for (i, c) in data.chunks_exact(8).take(11).enumerate() {
            let v = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
            if i > 0 && v > limit {
                return Err(corrupt(
                    path,
                    format!("DWA block {k} declares {v} bytes (block holds at most {block})"),
                ));
            }
        }
    }
    Ok(())
}

/// Load an environment map by extension (`.hdr` Radiance RGBE, `.exr` OpenEXR:
/// first layer with R, G, B, any compression, half or float). The layout comes
/// from the aspect ratio: 2:1 equirect, 4:3 horizontal cross, 3:4 vertical
/// cross (crosses are resampled to a `4s × 2s` equirect map). Bad values are
/// sanitized and reported (and logged with the file name).
pub fn load(path: &Path) -> Result<(EnvMap, SanitizeReport), EnvError> {
    let check = |p: &Path, w: u64, h: u64| detect_layout(p, w, h).map(|_| ());
    let mut raw = read_raw(path, &check)?;
    let report = sanitize(&mut raw.texels);
    let layout = detect_layout(path, u64::from(raw.width), u64::from(raw.height))?;
    let env = match layout {
        Layout::Equirect => EnvMap {
            width: raw.width,
            height: raw.height,
            texels: raw.texels,
        },
        Layout::HorizontalCross => cube_to_equirect(&cross_faces(&raw, layout)),
        Layout::VerticalCross => cube_to_equirect(&cross_faces(&raw, layout)),
    };
    warn_if_sanitized(path, &report);
    Ok((env, report))
}

/// Load six square cube faces, in the order +X, −X, +Y, −Y, +Z, −Z (OpenGL /
/// Vulkan orientation, see the module doc), and resample to equirect `4s × 2s`.
pub fn load_cube_faces(paths: [&Path; 6]) -> Result<(EnvMap, SanitizeReport), EnvError> {
    let square = |p: &Path, w: u64, h: u64| {
        if w != h {
            return Err(EnvError::CubeFace {
                path: p.to_path_buf(),
                detail: format!("face is {w}x{h}, not square"),
            });
        }
        if w > u64::from(MAX_WIDTH / 4) {
            return Err(EnvError::TooLarge {
                path: p.to_path_buf(),
                width: w,
                height: h,
            });
        }
        Ok(())
    };
    let mut report = SanitizeReport::default();
    let mut faces: Vec<Face> = Vec::with_capacity(6);
    for p in paths {
        let mut raw = read_raw(p, &square)?;
        let r = sanitize(&mut raw.texels);
        warn_if_sanitized(p, &r);
        report.add(r);
        if let Some(first) = faces.first() {
            if first.size != raw.width {
                return Err(EnvError::CubeFace {
                    path: p.to_path_buf(),
                    detail: format!(
                        "face is {}x{}, other faces are {}x{}",
                        raw.width, raw.height, first.size, first.size
                    ),
                });
            }
        }
        faces.push(Face {
            size: raw.width,
            texels: raw.texels,
        });
    }
    let faces: [Face; 6] = faces.try_into().map_err(|_| EnvError::CubeFace {
        path: paths[0].to_path_buf(),
        detail: "expected six faces".into(),
    })?;
    Ok((cube_to_equirect(&faces), report))
}

fn warn_if_sanitized(path: &Path, r: &SanitizeReport) {
    if r.total() > 0 {
        log::warn!(
            "{}: replaced {} NaN, {} Inf and {} negative channel values",
            path.display(),
            r.nan,
            r.inf,
            r.negative
        );
    }
}

// ---------------------------------------------------------------------------
// Cube maps
// ---------------------------------------------------------------------------

/// One square cube face in OpenGL orientation (row 0 = t = 0).
struct Face {
    size: u32,
    texels: Vec<Vec3>,
}

impl Face {
    fn get(&self, x: u32, y: u32) -> Vec3 {
        let i = y as usize * self.size as usize + x as usize;
        self.texels.get(i).copied().unwrap_or(Vec3::ZERO)
    }

    /// Bilinear lookup at face coordinates `(s, t) ∈ [0, 1]²`, clamped to edges.
    fn sample(&self, s: f32, t: f32) -> Vec3 {
        if self.size == 0 {
            return Vec3::ZERO;
        }
        let n = self.size as f32;
        let fx = (s * n - 0.5).clamp(0.0, n - 1.0);
        let fy = (t * n - 0.5).clamp(0.0, n - 1.0);
        let x0 = fx.floor() as u32;
        let y0 = fy.floor() as u32;
        let x1 = (x0 + 1).min(self.size - 1);
        let y1 = (y0 + 1).min(self.size - 1);
        let tx = fx - x0 as f32;
        let ty = fy - y0 as f32;
        let top = self.get(x0, y0).lerp(self.get(x1, y0), tx);
        let bottom = self.get(x0, y1).lerp(self.get(x1, y1), tx);
        top.lerp(bottom, ty)
    }
}

/// Face index (0..6 = +X, −X, +Y, −Y, +Z, −Z) and `(s, t)` for direction `d`
/// (OpenGL 4.6 table 8.19).
pub fn cube_face_st(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    if ma.is_nan() || ma <= 0.0 {
        return (4, 0.5, 0.5);
    }
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

/// Cut the six faces out of a cross image (layout in the module doc).
fn cross_faces(raw: &RawImage, layout: Layout) -> [Face; 6] {
    // (block column, block row, rotated 180°) for +X, −X, +Y, −Y, +Z, −Z.
    let (s, blocks) = match layout {
        Layout::VerticalCross => (
            raw.width / 3,
            [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (1, 3, true),
            ],
        ),
        _ => (
            raw.width / 4,
            [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (3, 1, false),
            ],
        ),
    };
    blocks.map(|(bx, by, flip)| {
        let mut texels = Vec::with_capacity(s as usize * s as usize);
        for j in 0..s {
            for i in 0..s {
                let (fi, fj) = if flip { (s - 1 - i, s - 1 - j) } else { (i, j) };
                texels.push(raw.get(bx * s + fi, by * s + fj));
            }
        }
        Face { size: s, texels }
    })
}

/// Resample a cube map to an equirect map of `4s × 2s` texels.
fn cube_to_equirect(faces: &[Face; 6]) -> EnvMap {
    let s = faces[0].size.max(1);
    EnvMap::from_fn(4 * s, 2 * s, |d| {
        let (f, fs, ft) = cube_face_st(d);
        faces.get(f).map_or(Vec3::ZERO, |face| face.sample(fs, ft))
    })
}

// ---------------------------------------------------------------------------
// Sources
// ---------------------------------------------------------------------------

/// Parse an environment source string:
/// `uniform:R,G,B` / `uniform:V`, `sky`, `sky:elevation=30,azimuth=120,
/// turbidity=3,intensity=1` (keys optional, defaults from [`SkyParams`]), or a
/// file path (anything else).
pub fn parse_source(s: &str) -> Result<EnvSource, EnvError> {
    let bad = |detail: String| EnvError::BadSource {
        source_str: s.to_string(),
        detail,
    };
    let t = s.trim();
    if t.is_empty() {
        return Err(bad("empty source".into()));
    }
    if let Some(rest) = t.strip_prefix("uniform:") {
        let vals: Vec<&str> = rest.split(',').map(str::trim).collect();
        let mut v = Vec::with_capacity(3);
        for p in &vals {
            let x: f32 = p
                .parse()
                .map_err(|_| bad(format!("'{p}' is not a number")))?;
            if !x.is_finite() || x < 0.0 {
                return Err(bad(format!("radiance {x} must be finite and >= 0")));
            }
            v.push(x);
        }
        return match v.as_slice() {
            [g] => Ok(EnvSource::Uniform(Vec3::splat(*g))),
            [r, g, b] => Ok(EnvSource::Uniform(Vec3::new(*r, *g, *b))),
            _ => Err(bad("expected uniform:R,G,B or uniform:V".into())),
        };
    }
    if t == "uniform" {
        return Err(bad("expected uniform:R,G,B or uniform:V".into()));
    }
    if t == "sky" {
        return Ok(EnvSource::Sky(SkyParams::default()));
    }
    if let Some(rest) = t.strip_prefix("cube:") {
        let faces: Vec<PathBuf> = rest.split(',').map(|p| PathBuf::from(p.trim())).collect();
        return <[PathBuf; 6]>::try_from(faces)
            .map(EnvSource::CubeFaces)
            .map_err(|v| {
                bad(format!(
                    "expected six face files (+X,-X,+Y,-Y,+Z,-Z), got {}",
                    v.len()
                ))
            });
    }
    if let Some(rest) = t.strip_prefix("sky:") {
        let mut p = SkyParams::default();
        for kv in rest.split(',').map(str::trim).filter(|kv| !kv.is_empty()) {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| bad(format!("'{kv}' is not key=value")))?;
            let x: f32 = v
                .trim()
                .parse()
                .map_err(|_| bad(format!("'{}' is not a number", v.trim())))?;
            match k.trim() {
                "elevation" => p.elevation_deg = x,
                "azimuth" => p.azimuth_deg = x,
                "turbidity" => p.turbidity = x,
                "intensity" => p.intensity = x,
                other => {
                    return Err(bad(format!(
                        "unknown key '{other}' (elevation, azimuth, turbidity, intensity)"
                    )))
                }
            }
        }
        p.validate()?;
        return Ok(EnvSource::Sky(p));
    }
    Ok(EnvSource::File(PathBuf::from(t)))
}

/// Produce the environment for a source. `width × height` is the size of
/// procedural maps (uniform, sky); files load at their own resolution.
pub fn resolve(
    src: &EnvSource,
    width: u32,
    height: u32,
) -> Result<(EnvMap, SanitizeReport), EnvError> {
    match src {
        EnvSource::File(p) => load(p),
        EnvSource::CubeFaces(faces) => load_cube_faces(faces.each_ref().map(PathBuf::as_path)),
        _ if !size_ok(width, height) => Err(EnvError::BadSize { width, height }),
        EnvSource::Uniform(c) => {
            let mut env = EnvMap::uniform(*c, width, height);
            let r = env.sanitize();
            Ok((env, r))
        }
        EnvSource::Sky(p) => {
            p.validate()?;
            Ok((render_sky(p, width, height), SanitizeReport::default()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    fn assets() -> Option<PathBuf> {
        let dir = std::env::var("DERMIS_ASSETS")
            .map(PathBuf::from)
            .unwrap_or_else(|_| {
                PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/assets"))
            });
        if dir.join("env").is_dir() {
            Some(dir)
        } else {
            println!("SKIP: test assets not found at {}", dir.display());
            None
        }
    }

    fn temp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-envmap-{}-{name}", std::process::id()));
        let _ = std::fs::create_dir_all(&d);
        d
    }

    #[test]
    fn direction_convention() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        assert!(close(direction(0.5, 0.5), Vec3::NEG_Z));
        assert!(close(direction(0.75, 0.5), Vec3::X));
        assert!(close(direction(0.25, 0.5), Vec3::NEG_X));
        assert!(close(direction(0.0, 0.5), Vec3::Z));
        assert!(close(direction(0.3, 0.0), Vec3::Y));
        assert!(close(direction(0.3, 1.0), Vec3::NEG_Y));
        for i in 0..50 {
            let u = (i as f32 * 0.137).fract() * 0.98 + 0.01;
            let v = (i as f32 * 0.291).fract() * 0.98 + 0.01;
            let uv = direction_to_uv(direction(u, v));
            assert!((uv - Vec2::new(u, v)).length() < 1e-4, "{u} {v} {uv}");
        }
    }

    #[test]
    fn solid_angles_sum_to_4pi() {
        let (w, h) = (64, 32);
        let total: f64 = (0..h)
            .map(|y| texel_solid_angle_f64(y, w, h) * w as f64)
            .sum();
        assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        // Against the small-texel approximation sinθ·dθ·dφ at the equator row.
        let y = h / 2;
        let approx =
            (PI / h as f32) * (2.0 * PI / w as f32) * (PI * (y as f32 + 0.5) / h as f32).sin();
        assert!((texel_solid_angle(y, w, h) - approx).abs() / approx < 1e-3);
        assert_eq!(texel_solid_angle(0, 0, 0), 0.0);
        assert_eq!(texel_solid_angle(40, 64, 32), 0.0);
    }

    #[test]
    fn rotated_y_moves_features() {
        // A bright texel at d0 must reappear at R·d0.
        let (w, h) = (72, 36);
        let mut env = EnvMap::uniform(Vec3::ZERO, w, h);
        let (x0, y0) = (10u32, 12u32);
        env.texels[(y0 * w + x0) as usize] = Vec3::ONE;
        let d0 = env.texel_direction(x0, y0);
        let deg = 50.0; // 10 texels at 5° each: a whole-texel shift
        let rot = env.rotated_y(deg);
        let (mut best, mut bx, mut by) = (0.0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                if rot.texel(x, y).x > best {
                    (best, bx, by) = (rot.texel(x, y).x, x, y);
                }
            }
        }
        let expect = Mat3::from_rotation_y(deg.to_radians()) * d0;
        assert!((rot.texel_direction(bx, by) - expect).length() < 1e-4);
        assert!((best - 1.0).abs() < 1e-5);
        // Positive angle: +X goes toward −Z (counter-clockwise seen from above).
        assert!((Mat3::from_rotation_y(0.5 * PI) * Vec3::X - Vec3::NEG_Z).length() < 1e-6);
        // Fractional shifts keep energy.
        let frac = env.rotated_y(37.3);
        let s0: f32 = env.texels.iter().map(|t| t.x).sum();
        let s1: f32 = frac.texels.iter().map(|t| t.x).sum();
        assert!((s0 - s1).abs() < 1e-5);
    }

    #[test]
    fn sanitize_counts() {
        let mut env = EnvMap::uniform(Vec3::splat(0.5), 8, 4);
        env.texels[0] = Vec3::new(f32::NAN, 1.0, f32::NAN);
        env.texels[1] = Vec3::new(f32::INFINITY, -2.0, f32::NEG_INFINITY);
        env.texels[2] = Vec3::new(-0.0, -1e-9, 3.0);
        let r = env.sanitize();
        assert_eq!(
            r,
            SanitizeReport {
                nan: 2,
                inf: 2,
                negative: 2
            }
        );
        assert_eq!(env.texels[0], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(env.texels[1], Vec3::new(HALF_MAX, 0.0, 0.0));
        assert_eq!(env.texels[2].y, 0.0);
        assert!(env
            .texels
            .iter()
            .all(|t| t.is_finite() && t.min_element() >= 0.0));
        // Through the loader: an EXR with bad values.
        let dir = temp_dir("sanitize");
        let p = dir.join("bad_values.exr");
        exr::prelude::write_rgb_file(&p, 8, 4, |x, y| {
            if (x, y) == (1, 1) {
                (f32::NAN, f32::INFINITY, -1.0f32)
            } else {
                (1.0f32, 1.0f32, 1.0f32)
            }
        })
        .unwrap();
        let (env, r) = load(&p).unwrap();
        assert_eq!(
            r,
            SanitizeReport {
                nan: 1,
                inf: 1,
                negative: 1
            }
        );
        assert_eq!(env.texel(1, 1), Vec3::new(0.0, HALF_MAX, 0.0));
    }

    #[test]
    fn load_real_maps() {
        let Some(dir) = assets() else { return };
        for name in [
            "studio.exr",
            "sunset.exr",
            "royal_esplanade_1k.hdr",
            "venice_sunset_1k.hdr",
            "pedestrian_overpass_1k.hdr",
            "quarry_01_1k.hdr",
        ] {
            let t = std::time::Instant::now();
            let (env, r) = load(&dir.join("env").join(name)).unwrap();
            assert_eq!((env.width, env.height), (1024, 512), "{name}");
            assert_eq!(env.texels.len(), 1024 * 512);
            assert!(env
                .texels
                .iter()
                .all(|t| t.is_finite() && t.min_element() >= 0.0));
            let m = env.mean();
            let max = env
                .texels
                .iter()
                .fold(0.0f32, |a, t| a.max(t.max_element()));
            println!(
                "{name}: mean {:.4} {:.4} {:.4}, max {max:.1}, sanitized {r:?}, {:.0} ms",
                m.x,
                m.y,
                m.z,
                t.elapsed().as_secs_f64() * 1e3
            );
            assert!(
                m.min_element() > 1e-3 && m.max_element() < 1e3,
                "{name}: {m}"
            );
        }
    }

    /// Direction of face texel coordinates (s, t), written from the inverse of
    /// the OpenGL table (independent of `cube_face_st`).
    fn face_dir(face: usize, s: f32, t: f32) -> Vec3 {
        let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
        let d = match face {
            0 => Vec3::new(1.0, -tc, -sc),
            1 => Vec3::new(-1.0, -tc, sc),
            2 => Vec3::new(sc, 1.0, tc),
            3 => Vec3::new(sc, -1.0, -tc),
            4 => Vec3::new(sc, -tc, 1.0),
            _ => Vec3::new(-sc, -tc, -1.0),
        };
        d.normalize()
    }

    /// A smooth, asymmetric test function of direction.
    fn probe(d: Vec3) -> Vec3 {
        Vec3::new(
            1.5 + d.x + 0.3 * d.y * d.z,
            1.2 + 0.8 * d.y - 0.2 * d.x,
            1.1 + 0.9 * d.z,
        )
    }

    fn write_cross(path: &Path, vertical: bool, s: usize) {
        let (w, h) = if vertical {
            (3 * s, 4 * s)
        } else {
            (4 * s, 3 * s)
        };
        let blocks: [(usize, usize, usize, bool); 6] = if vertical {
            [
                (0, 2, 1, false),
                (1, 0, 1, false),
                (2, 1, 0, false),
                (3, 1, 2, false),
                (4, 1, 1, false),
                (5, 1, 3, true),
            ]
        } else {
            [
                (0, 2, 1, false),
                (1, 0, 1, false),
                (2, 1, 0, false),
                (3, 1, 2, false),
                (4, 1, 1, false),
                (5, 3, 1, false),
            ]
        };
        exr::prelude::write_rgb_file(path, w, h, |x, y| {
            let (bx, by) = (x / s, y / s);
            for (f, cx, cy, flip) in blocks {
                if (cx, cy) == (bx, by) {
                    let (mut i, mut j) = (x % s, y % s);
                    if flip {
                        (i, j) = (s - 1 - i, s - 1 - j);
                    }
                    let d = face_dir(f, (i as f32 + 0.5) / s as f32, (j as f32 + 0.5) / s as f32);
                    let c = probe(d);
                    return (c.x, c.y, c.z);
                }
            }
            (0.0f32, 0.0f32, 0.0f32)
        })
        .unwrap();
    }

    #[test]
    fn cross_layouts_round_trip() {
        let dir = temp_dir("cross");
        for vertical in [false, true] {
            let s = 64;
            let p = dir.join(if vertical { "vcross.exr" } else { "hcross.exr" });
            write_cross(&p, vertical, s);
            let (env, _) = load(&p).unwrap();
            assert_eq!((env.width, env.height), (4 * s as u32, 2 * s as u32));
            let mut max_err = 0.0f32;
            for i in 0..500 {
                // Fibonacci sphere directions.
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 500.0;
                let r = (1.0 - z * z).sqrt();
                let a = i as f32 * 2.399_963;
                let d = Vec3::new(r * a.cos(), r * a.sin(), z);
                let e = (env.sample_dir(d) - probe(d)).abs().max_element();
                max_err = max_err.max(e);
            }
            println!("cross vertical={vertical}: max error {max_err:.4}");
            assert!(max_err < 0.03, "vertical={vertical}: {max_err}");
        }
    }

    #[test]
    fn cube_faces_load() {
        let dir = temp_dir("faces");
        let s = 32usize;
        let names = ["px", "nx", "py", "ny", "pz", "nz"];
        let paths: Vec<PathBuf> = names.iter().map(|n| dir.join(format!("{n}.exr"))).collect();
        for (f, p) in paths.iter().enumerate() {
            exr::prelude::write_rgb_file(p, s, s, |x, y| {
                let c = probe(face_dir(
                    f,
                    (x as f32 + 0.5) / s as f32,
                    (y as f32 + 0.5) / s as f32,
                ));
                (c.x, c.y, c.z)
            })
            .unwrap();
        }
        let refs: [&Path; 6] = std::array::from_fn(|i| paths[i].as_path());
        let (env, _) = load_cube_faces(refs).unwrap();
        for d in [Vec3::X, Vec3::NEG_Y, Vec3::new(0.3, 0.5, -0.8).normalize()] {
            assert!((env.sample_dir(d) - probe(d)).abs().max_element() < 0.03);
        }
        // Mismatched sizes are an error naming the file.
        exr::prelude::write_rgb_file(&paths[3], 16, 16, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
        let e = load_cube_faces(refs).unwrap_err().to_string();
        assert!(e.contains("ny.exr"), "{e}");
    }

    fn err_of(p: &Path) -> String {
        match load(p) {
            Ok(_) => panic!("{} loaded but should fail", p.display()),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_inputs_are_errors_naming_the_file() {
        let dir = temp_dir("bad");
        let missing = dir.join("no_such_map.hdr");
        let e = err_of(&missing);
        assert!(
            e.contains("no_such_map.hdr") && e.contains("not found"),
            "{e}"
        );

        let txt = dir.join("notes.png");
        std::fs::write(&txt, b"hello").unwrap();
        let e = err_of(&txt);
        assert!(e.contains("notes.png") && e.contains("extension"), "{e}");

        let aspect = dir.join("square_map.exr");
        exr::prelude::write_rgb_file(&aspect, 16, 16, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
        let e = err_of(&aspect);
        assert!(e.contains("square_map.exr") && e.contains("aspect"), "{e}");

        let garbage = dir.join("garbage.hdr");
        std::fs::write(
            &garbage,
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 99999\n",
        )
        .unwrap();
        let e = err_of(&garbage);
        assert!(e.contains("garbage.hdr") && e.contains("too large"), "{e}");

        let empty = dir.join("empty.exr");
        std::fs::write(&empty, b"").unwrap();
        let e = err_of(&empty);
        assert!(e.contains("empty.exr"), "{e}");

        for e in [
            err_of(&missing),
            err_of(&txt),
            err_of(&aspect),
            err_of(&garbage),
        ] {
            assert!(!e.contains('\n'));
        }
    }

    /// Source files for truncation / bit flips: the real maps when present,
    /// plus small synthetic ones (fast to decode).
    fn fuzz_sources(dir: &Path) -> Vec<PathBuf> {
        let mut v = Vec::new();
        let small_exr = dir.join("small.exr");
        exr::prelude::write_rgb_file(&small_exr, 32, 16, |x, y| (x as f32, y as f32, 0.5f32))
            .unwrap();
        v.push(small_exr);
        let small_hdr = dir.join("small.hdr");
        let px: Vec<image::Rgb<f32>> = (0..32 * 16)
            .map(|i| image::Rgb([i as f32 * 0.01, 0.5, 1.0]))
            .collect();
        let f = std::fs::File::create(&small_hdr).unwrap();
        image::codecs::hdr::HdrEncoder::new(f)
            .encode(&px, 32, 16)
            .unwrap();
        v.push(small_hdr);
        if let Some(a) = assets() {
            v.push(a.join("env/studio.exr"));
            v.push(a.join("env/royal_esplanade_1k.hdr"));
        }
        v
    }

    #[test]
    fn truncated_files_are_errors() {
        let dir = temp_dir("trunc");
        for src in fuzz_sources(&dir) {
            let bytes = std::fs::read(&src).unwrap();
            let name = src.file_name().unwrap().to_string_lossy().to_string();
            for frac in [0.0, 0.01, 0.1, 0.3, 0.5, 0.9, 0.999] {
                let n = (bytes.len() as f64 * frac) as usize;
                let p = dir.join(format!("cut{}_{name}", (frac * 1000.0) as u32));
                std::fs::write(&p, &bytes[..n]).unwrap();
                let e = err_of(&p);
                assert!(
                    e.contains(&format!("cut{}_{name}", (frac * 1000.0) as u32)),
                    "{e}"
                );
            }
        }
    }

    #[test]
    fn bit_flipped_files_never_panic() {
        let dir = temp_dir("flip");
        let mut n_err = 0;
        let mut n_ok = 0;
        // xorshift: deterministic positions.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for src in fuzz_sources(&dir) {
            let bytes = std::fs::read(&src).unwrap();
            let big = bytes.len() > 100_000;
            let variants = if big { 30 } else { 150 };
            let name = src.file_name().unwrap().to_string_lossy().to_string();
            for k in 0..variants {
                let mut b = bytes.clone();
                for _ in 0..1 + next() % 4 {
                    // Mostly headers and offset tables (first 2 KiB), sometimes anywhere.
                    let span = if next() % 4 == 0 {
                        b.len()
                    } else {
                        b.len().min(2048)
                    };
                    let i = (next() as usize) % span;
                    b[i] ^= 1 << (next() % 8);
                }
                let p = dir.join(format!("flip{k}_{name}"));
                std::fs::write(&p, &b).unwrap();
                let r = catch_unwind(|| load(&p).map(|(env, _)| env.texels.len()));
                match r {
                    Err(_) => panic!("panic on {}", p.display()),
                    Ok(Ok(_)) => n_ok += 1,
                    Ok(Err(e)) => {
                        let msg = e.to_string();
                        assert!(
                            msg.contains(&format!("flip{k}_{name}")) && !msg.contains('\n'),
                            "{msg}"
                        );
                        n_err += 1;
                    }
                }
                let _ = std::fs::remove_file(&p);
            }
        }
        println!("bit flips: {n_ok} loaded, {n_err} errors, 0 panics");
        assert!(n_ok + n_err >= 300);
    }

    #[test]
    fn dwa_leader_guard() {
        // Regression: one flipped bit in the first DWA chunk leader of
        // studio.exr made the exr crate allocate 34 GB and abort the process.
        let Some(a) = assets() else { return };
        let mut b = std::fs::read(a.join("env/studio.exr")).unwrap();
        b[0x385] ^= 0x04;
        let p = temp_dir("dwa").join("dwa_flip.exr");
        std::fs::write(&p, &b).unwrap();
        let e = err_of(&p);
        assert!(e.contains("dwa_flip.exr") && e.contains("DWA"), "{e}");
    }

    #[test]
    fn parse_sources() {
        assert_eq!(
            parse_source("uniform:1,0.5,0.25").unwrap(),
            EnvSource::Uniform(Vec3::new(1.0, 0.5, 0.25))
        );
        assert_eq!(
            parse_source("uniform:2").unwrap(),
            EnvSource::Uniform(Vec3::splat(2.0))
        );
        assert_eq!(
            parse_source("sky").unwrap(),
            EnvSource::Sky(SkyParams::default())
        );
        let EnvSource::Sky(p) = parse_source("sky:elevation=30,azimuth=120,turbidity=3").unwrap()
        else {
            panic!()
        };
        assert_eq!(
            (p.elevation_deg, p.azimuth_deg, p.turbidity),
            (30.0, 120.0, 3.0)
        );
        assert_eq!(
            parse_source("maps/a.hdr").unwrap(),
            EnvSource::File(PathBuf::from("maps/a.hdr"))
        );
        for bad in [
            "uniform:1,2",
            "uniform:a,b,c",
            "uniform:-1,0,0",
            "sky:foo=1",
            "sky:elevation=95",
            "sky:turbidity=1",
            "sky:elevation",
            "",
        ] {
            let e = parse_source(bad);
            assert!(e.is_err(), "{bad} should fail");
        }
        let (env, _) = resolve(&parse_source("uniform:1,2,3").unwrap(), 16, 8).unwrap();
        assert_eq!(env.texel(3, 3), Vec3::new(1.0, 2.0, 3.0));
        assert!(resolve(&EnvSource::Uniform(Vec3::ONE), 0, 8).is_err());
        let (sky, _) = resolve(&EnvSource::Sky(SkyParams::default()), 64, 32).unwrap();
        assert_eq!((sky.width, sky.height), (64, 32));
        let e = resolve(&EnvSource::File(PathBuf::from("/nonexistent/x.exr")), 1, 1).unwrap_err();
        assert!(e.to_string().contains("x.exr"));
    }

    #[test]
    fn cube_face_sources_parse() {
        let src = parse_source("cube:px.hdr, nx.hdr,py.hdr,ny.hdr,pz.hdr,nz.hdr").unwrap();
        let EnvSource::CubeFaces(faces) = &src else {
            panic!("{src:?}")
        };
        assert_eq!(faces[1], PathBuf::from("nx.hdr"));
        assert_eq!(parse_source(&src.to_string()).unwrap(), src);
        let e = parse_source("cube:a.hdr,b.hdr").unwrap_err().to_string();
        assert!(e.contains("six face files"), "{e}");
        // Missing faces are a load error naming the file.
        let e = resolve(&src, 8, 4).unwrap_err().to_string();
        assert!(e.contains("px.hdr"), "{e}");
    }
}
