//! Bright-source extraction: the compact regions of an environment map that hold
//! a large share of its energy (a sun, a studio softbox, a window) are taken out
//! of the map, each to be lit as a shadowed directional light of the same power
//! and colour; the smooth residual is what the SH projection and the specular
//! prefilter see. Nine SH coefficients cannot represent such a source
//! (docs/design/lighting.md, "Bright-source extraction", has the reasoning behind every
//! threshold and what it gives on the CC0 maps).
//!
//! # Algorithm
//! 1. **Typical radiance.** Luminance `Y` (Rec. 709) per texel; the map's typical
//!    radiance `Ỹ` is the solid-angle-weighted median of `Y`.
//! 2. **Cores.** Texels with `Y > CORE_CONTRAST · Ỹ`, joined into connected
//!    components. Texels are neighbours when they lie in adjacent rows (or the
//!    same row) and within about one texel height `π/H` of each other along the
//!    row: one texel at the equator, `≈ 1/sin θ` texels towards the poles, the
//!    whole row at a pole. Rows wrap in u, so a source on the u = 0/1 seam or
//!    over a pole stays one component.
//! 3. **Candidates** in order of their core's energy `∫ Y dω`: `Auto` examines
//!    the cores holding at least [`MIN_SHARE`] of the map's energy, `Count(n)` the
//!    first `n`.
//! 4. **Halo.** A candidate grows ring by ring (one neighbourhood step, about one
//!    texel height, each) while its outermost ring's mean `Y` exceeds the next
//!    ring's by more than `HALO_FALLOFF_PER_DEG` per degree of the step, i.e.
//!    while radiance still falls steeply away from the source: the glow around
//!    a sun or lamp goes with it, a flat surrounding stops it at once. At most
//!    `MAX_HALO_DEG` of rings.
//! 5. **Fill.** The region's radiance is replaced by the solution of Laplace's
//!    equation on the sphere (the finite-volume Laplace–Beltrami operator of the
//!    lat-long grid) with the texels around the region as boundary values: the
//!    smoothest surface that meets its surroundings. It is clamped per channel to
//!    the original radiance, so extraction never adds light. The light's `power`
//!    is what was removed, `Σ (L − residual)·dω` with exact texel solid angles,
//!    so residual energy + Σ power = the map's energy.
//! 6. **Decision.** `Auto` keeps a region whose power holds at least
//!    [`MIN_SHARE`] of the map's energy in at most [`MAX_SOLID_ANGLE_SR`];
//!    `Count(n)` keeps every region it examined. Lights are sorted by power,
//!    at most [`MAX_EXTRACTED_LIGHTS`].
//!
//! Directions are in the map's own frame (`scene::env::map`); a map turned by
//! `rotation_deg` about +Y sends them to [`ExtractedLight::world_direction`].

use glam::{DVec3, Mat3, Vec3};

use crate::scene::env::{texel_solid_angle_f64, EnvMap};
pub use crate::scene::file::{LightsMode, MAX_EXTRACTED_LIGHTS};
use crate::scene::texture::LUMINANCE;

/// A core texel is this many times brighter than the map's median radiance.
/// On the CC0 maps the sources peak at 2.6·10⁴ (studio's lamps, 110 over a
/// median of 0.0043) to 5·10⁵ (suns, ceiling lights) times their median, while
/// the studio's white floor and lit curtain, 50–100× its dark median, must not
/// join the lamps they touch. 100 to 1000 give the same lights.
pub const CORE_CONTRAST: f32 = 100.0;
/// The least share of the map's energy (luminance of `∫ L dω`) an `Auto` light
/// holds. A point source of share `s` costs SH9 up to 0.375·s of the map's mean
/// irradiance (docs/design/lighting.md): below 5 % that is under the 2 % SH9 already
/// misses on the smooth maps (sunset, venice_sunset).
pub const MIN_SHARE: f32 = 0.05;
/// The largest solid angle of an `Auto` light: a disc of 10.2° radius, whose
/// irradiance at normal incidence, `(1 + cos r)/2` of its power, is within
/// 0.8 % of a point source's. A bright sky or a lit floor is larger.
pub const MAX_SOLID_ANGLE_SR: f32 = 0.1;
/// The halo grows while radiance falls by more than this factor per degree
/// outward (10 % per texel height of a 1024 × 512 map). The glare around the
/// CC0 maps' lamps and suns falls faster and ends within 3°; a circumsolar sky
/// falling as θ^−1.5 reaches this slope at θ ≈ 5°.
const HALO_FALLOFF_PER_DEG: f64 = 1.31;
/// The halo reaches at most this far beyond the core, degrees.
const MAX_HALO_DEG: f64 = 5.0;
/// Upper bound on the fill's relaxation sweeps (the CC0 maps need 48–282).
const MAX_FILL_SWEEPS: usize = 20_000;

/// A bright source taken out of the map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractedLight {
    /// Unit vector towards the source (power-weighted mean direction) in the
    /// map's own frame (`scene::env::map`).
    pub direction: Vec3,
    /// Solid angle of the region taken out, sr.
    pub solid_angle_sr: f32,
    /// Angular radius of the disc of the same solid angle, radians.
    pub angular_radius_rad: f32,
    /// `∫ (L − L_fill) dω` over the region, in the map's radiance units × sr:
    /// the irradiance the source delivers to a surface facing it.
    pub power: Vec3,
    /// Luminance of `power` over the luminance of `∫ L dω` over the whole map.
    pub share: f32,
    /// Texels in the region.
    pub texels: u32,
}

impl ExtractedLight {
    /// The direction towards the source in world space when the map is turned
    /// by `rotation_deg` about +Y: the GPU's `env_dir` (common/envmap.glsl)
    /// takes world directions into the map by `R_y(−angle)`, so this is
    /// `R_y(rotation)·direction` (as `EnvMap::rotated_y` moves content).
    pub fn world_direction(&self, rotation_deg: f32) -> Vec3 {
        Mat3::from_rotation_y(rotation_deg.to_radians()) * self.direction
    }
}

/// Elevation above the horizon and azimuth about +Y from +Z toward +X (the
/// convention of `sky:azimuth=`), both in degrees, azimuth in [0, 360).
pub fn elevation_azimuth_deg(d: Vec3) -> (f32, f32) {
    let d = d.normalize_or_zero();
    let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
    let azimuth = d.x.atan2(d.z).to_degrees().rem_euclid(360.0);
    (elevation, azimuth)
}

/// The lights and what is left of the map.
#[derive(Clone, Debug, PartialEq)]
pub struct Extraction {
    /// Sorted by power (luminance), strongest first.
    pub lights: Vec<ExtractedLight>,
    /// The map with every light's region filled from its surroundings.
    pub residual: EnvMap,
}

/// Takes the bright sources `mode` asks for out of `env` (module doc).
pub fn extract(env: &EnvMap, mode: LightsMode) -> Extraction {
    let most = match mode {
        LightsMode::Auto => MAX_EXTRACTED_LIGHTS,
        LightsMode::Count(n) => n.min(MAX_EXTRACTED_LIGHTS),
    };
    let mut residual = env.clone();
    let grid = Grid::new(env.width as usize, env.height as usize);
    if most == 0 || env.texels.len() != grid.w * grid.h {
        return Extraction {
            lights: Vec::new(),
            residual,
        };
    }
    let lum: Vec<f32> = env.texels.iter().map(|&c| c.dot(LUMINANCE)).collect();
    let total = energy(&grid, &env.texels, 0..env.texels.len());
    let total_lum = total.dot(LUMINANCE.as_dvec3());
    if !(total_lum > 0.0 && total_lum.is_finite()) {
        return Extraction {
            lights: Vec::new(),
            residual,
        };
    }

    let threshold = CORE_CONTRAST * weighted_median(&grid, &lum);
    let core_energy = |core: &[usize]| -> f64 {
        core.iter()
            .map(|&i| f64::from(lum[i]) * grid.d_omega[i / grid.w])
            .sum()
    };
    let mut ranked: Vec<(f64, Vec<usize>)> = components(&grid, &lum, threshold)
        .into_iter()
        .map(|c| (core_energy(&c), c))
        .collect();
    ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
    let candidates: Vec<Vec<usize>> = match mode {
        LightsMode::Auto => ranked
            .into_iter()
            .take_while(|(e, _)| *e >= f64::from(MIN_SHARE) * total_lum)
            .map(|(_, c)| c)
            .collect(),
        LightsMode::Count(_) => ranked.into_iter().take(most).map(|(_, c)| c).collect(),
    };

    let mut state = vec![State::Free; grid.w * grid.h];
    let mut lights = Vec::new();
    for core in candidates {
        let region = grow(&grid, &lum, &core, &mut state);
        let Some(fill) = harmonic_fill(&grid, &residual, &region) else {
            region.iter().for_each(|&i| state[i] = State::Free);
            continue;
        };
        let filled: Vec<Vec3> = region
            .iter()
            .zip(&fill)
            .map(|(&i, f)| residual.texels[i].min(*f))
            .collect();
        let light = measure(&grid, &residual, &region, &filled, total_lum);
        let keep = match mode {
            LightsMode::Auto => {
                light.share >= MIN_SHARE && light.solid_angle_sr <= MAX_SOLID_ANGLE_SR
            }
            LightsMode::Count(_) => true,
        };
        let mark = if keep { State::Taken } else { State::Free };
        region.iter().for_each(|&i| state[i] = mark);
        if keep {
            for (&i, f) in region.iter().zip(filled) {
                residual.texels[i] = f;
            }
            lights.push(light);
            if lights.len() == most {
                break;
            }
        }
    }
    lights.sort_by(|a, b| b.power.dot(LUMINANCE).total_cmp(&a.power.dot(LUMINANCE)));
    Extraction { lights, residual }
}

/// What a texel is while lights are extracted.
#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    Free,
    /// In the region being grown.
    Region,
    /// In a ring around it, not (yet) taken into it.
    Ring,
    /// In an earlier light's region.
    Taken,
}

/// The lat-long grid: texel solid angles and neighbourhoods.
struct Grid {
    w: usize,
    h: usize,
    /// Solid angle of a texel of each row, sr.
    d_omega: Vec<f64>,
    /// How many texels along each row the neighbourhood reaches: one texel
    /// height `π/H` is `(π/H) / (2π/W · sin θ)` texels long there.
    reach: Vec<usize>,
}

impl Grid {
    fn new(w: usize, h: usize) -> Grid {
        let d_omega = (0..h)
            .map(|y| texel_solid_angle_f64(y as u32, w as u32, h as u32))
            .collect();
        let reach = (0..h)
            .map(|y| {
                let theta = std::f64::consts::PI * (y as f64 + 0.5) / h as f64;
                let r = (w as f64 / (2.0 * h as f64 * theta.sin())).round() as usize;
                r.min(w / 2).max(1)
            })
            .collect();
        Grid {
            w,
            h,
            d_omega,
            reach,
        }
    }

    /// Calls `f` on every neighbour of texel `i` (not `i` itself): the texels of
    /// rows `y − 1 ..= y + 1` within the larger of the two rows' reach, wrapping in u.
    fn for_each_neighbour(&self, i: usize, mut f: impl FnMut(usize)) {
        let (x, y) = (i % self.w, i / self.w);
        for ny in y.saturating_sub(1)..=(y + 1).min(self.h - 1) {
            let r = self.reach[y].max(self.reach[ny]);
            let row = ny * self.w;
            if 2 * r + 1 >= self.w {
                (0..self.w)
                    .filter(|&nx| row + nx != i)
                    .for_each(|nx| f(row + nx));
            } else {
                for nx in (x + self.w - r..=x + self.w + r).map(|nx| nx % self.w) {
                    if row + nx != i {
                        f(row + nx);
                    }
                }
            }
        }
    }
}

/// `Σ L·dω` over the texels `indices`, f64.
fn energy(grid: &Grid, texels: &[Vec3], indices: impl IntoIterator<Item = usize>) -> DVec3 {
    indices
        .into_iter()
        .map(|i| texels[i].as_dvec3() * grid.d_omega[i / grid.w])
        .sum()
}

/// The luminance below which half of the sphere's solid angle lies.
fn weighted_median(grid: &Grid, lum: &[f32]) -> f32 {
    let mut v: Vec<(f32, f64)> = lum
        .iter()
        .enumerate()
        .map(|(i, &y)| (y, grid.d_omega[i / grid.w]))
        .collect();
    v.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let half = 0.5 * v.iter().map(|p| p.1).sum::<f64>();
    let mut acc = 0.0;
    for (y, dw) in &v {
        acc += dw;
        if acc >= half {
            return *y;
        }
    }
    v.last().map_or(0.0, |p| p.0)
}

/// Connected components of the texels brighter than `threshold` (texel
/// indices, each component in scan order).
fn components(grid: &Grid, lum: &[f32], threshold: f32) -> Vec<Vec<usize>> {
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let bright = |i: usize| lum[i] > threshold;
    let mut parent: Vec<usize> = (0..lum.len()).collect();
    for i in (0..lum.len()).filter(|&i| bright(i)) {
        grid.for_each_neighbour(i, |j| {
            if j > i && bright(j) {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        });
    }
    let mut index = vec![usize::MAX; lum.len()];
    let mut out: Vec<Vec<usize>> = Vec::new();
    for i in (0..lum.len()).filter(|&i| bright(i)) {
        let r = root(&mut parent, i);
        if index[r] == usize::MAX {
            index[r] = out.len();
            out.push(Vec::new());
        }
        out[index[r]].push(i);
    }
    out
}

/// The free texels of `core` plus its halo rings (module doc, step 4), marked
/// [`State::Region`].
fn grow(grid: &Grid, lum: &[f32], core: &[usize], state: &mut [State]) -> Vec<usize> {
    let mut region: Vec<usize> = core
        .iter()
        .copied()
        .filter(|&i| state[i] == State::Free)
        .collect();
    region.iter().for_each(|&i| state[i] = State::Region);
    let mean = |ring: &[usize]| -> f64 {
        let (e, w) = ring.iter().fold((0.0, 0.0), |(e, w), &i| {
            let dw = grid.d_omega[i / grid.w];
            (e + f64::from(lum[i]) * dw, w + dw)
        });
        e / w
    };
    let step_deg = 180.0 / grid.h as f64;
    let falloff = HALO_FALLOFF_PER_DEG.powf(step_deg);
    let rings = (MAX_HALO_DEG / step_deg).round() as usize;
    let mut ring = dilate(grid, &region, state);
    for _ in 0..rings {
        let next = dilate(grid, &ring, state);
        let falling = !ring.is_empty() && !next.is_empty() && mean(&ring) > falloff * mean(&next);
        if !falling {
            next.iter().for_each(|&i| state[i] = State::Free);
            break;
        }
        ring.iter().for_each(|&i| state[i] = State::Region);
        region.append(&mut ring);
        ring = next;
    }
    ring.iter().for_each(|&i| state[i] = State::Free);
    region
}

/// The free neighbours of `frontier`, marked [`State::Ring`].
fn dilate(grid: &Grid, frontier: &[usize], state: &mut [State]) -> Vec<usize> {
    let mut ring = Vec::new();
    for &i in frontier {
        grid.for_each_neighbour(i, |j| {
            if state[j] == State::Free {
                state[j] = State::Ring;
                ring.push(j);
            }
        });
    }
    ring
}

/// Radiance over `region` (texel indices) that solves Laplace's equation on the
/// sphere with the map's texels around the region as boundary values. The
/// finite-volume Laplace–Beltrami operator couples a texel to its four
/// neighbours with the length of the shared edge over the distance between
/// centres: `sin θ_edge · Δφ/Δθ` north and south (0 at a pole), `Δθ/(sin θ · Δφ)`
/// east and west (wrapping in u). Solved by successive over-relaxation.
/// `None` when nothing borders the region.
fn harmonic_fill(grid: &Grid, map: &EnvMap, region: &[usize]) -> Option<Vec<Vec3>> {
    let (w, h) = (grid.w, grid.h);
    let d_theta = std::f64::consts::PI / h as f64;
    let d_phi = std::f64::consts::TAU / w as f64;
    let local: std::collections::HashMap<usize, usize> =
        region.iter().enumerate().map(|(k, &i)| (i, k)).collect();
    // Per unknown: Σ w·L over known neighbours, the unknown neighbours with
    // their weights, and Σ w.
    struct Row {
        known: Vec3,
        inner: Vec<(usize, f32)>,
        weight: f32,
    }
    let (mut boundary, mut boundary_weight, mut brightest) = (Vec3::ZERO, 0.0f32, 0.0f32);
    let rows: Vec<Row> = region
        .iter()
        .map(|&i| {
            let (x, y) = (i % w, i / w);
            let theta = (y as f64 + 0.5) * d_theta;
            let ns = |edge: f64| (edge.sin() * d_phi / d_theta) as f32;
            let ew = (d_theta / (theta.sin() * d_phi)) as f32;
            let mut links = Vec::with_capacity(4);
            if y > 0 {
                links.push((i - w, ns(y as f64 * d_theta)));
            }
            if y + 1 < h {
                links.push((i + w, ns((y + 1) as f64 * d_theta)));
            }
            if w > 1 {
                links.push((y * w + (x + 1) % w, ew));
                links.push((y * w + (x + w - 1) % w, ew));
            }
            let mut row = Row {
                known: Vec3::ZERO,
                inner: Vec::with_capacity(4),
                weight: 0.0,
            };
            for (j, wt) in links {
                row.weight += wt;
                match local.get(&j) {
                    Some(&k) => row.inner.push((k, wt)),
                    None => {
                        row.known += map.texels[j] * wt;
                        boundary += map.texels[j] * wt;
                        boundary_weight += wt;
                        brightest = brightest.max(map.texels[j].max_element());
                    }
                }
            }
            row
        })
        .collect();
    if boundary_weight <= 0.0 {
        return None;
    }
    let mut f = vec![boundary / boundary_weight; region.len()];
    // SOR with the optimal factor of a square of side √n (Young 1954).
    let side = (region.len() as f64).sqrt().max(2.0);
    let omega = (2.0 / (1.0 + (std::f64::consts::PI / side).sin())) as f32;
    let tolerance = 1e-5 * brightest.max(f32::MIN_POSITIVE);
    for _ in 0..MAX_FILL_SWEEPS {
        let mut change = 0.0f32;
        for (k, row) in rows.iter().enumerate() {
            let sum = row
                .inner
                .iter()
                .fold(row.known, |s, &(j, wt)| s + f[j] * wt);
            let new = f[k] + (sum / row.weight - f[k]) * omega;
            change = change.max((new - f[k]).abs().max_element());
            f[k] = new.max(Vec3::ZERO);
        }
        if change <= tolerance {
            break;
        }
    }
    Some(f)
}

/// The light of `region` once its texels become `filled`.
fn measure(
    grid: &Grid,
    map: &EnvMap,
    region: &[usize],
    filled: &[Vec3],
    total_lum: f64,
) -> ExtractedLight {
    let (mut power, mut towards, mut omega) = (DVec3::ZERO, DVec3::ZERO, 0.0f64);
    for (&i, f) in region.iter().zip(filled) {
        let dw = grid.d_omega[i / grid.w];
        // Exact in f64: residual + removed = map, texel by texel.
        let removed = (map.texels[i].as_dvec3() - f.as_dvec3()) * dw;
        let d = map.texel_direction((i % grid.w) as u32, (i / grid.w) as u32);
        power += removed;
        towards += d.as_dvec3() * removed.dot(LUMINANCE.as_dvec3());
        omega += dw;
    }
    let cos_r = 1.0 - omega / std::f64::consts::TAU;
    ExtractedLight {
        direction: towards.normalize_or_zero().as_vec3(),
        solid_angle_sr: omega as f32,
        angular_radius_rad: cos_r.clamp(-1.0, 1.0).acos() as f32,
        power: power.as_vec3(),
        share: (power.dot(LUMINANCE.as_dvec3()) / total_lum) as f32,
        texels: region.len() as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::env::sky::{render_sky, render_sky_impl, sun_irradiance};
    use crate::scene::env::{direction, load, SkyParams};
    use std::f32::consts::PI;

    /// The CC0 maps' size.
    const W: u32 = 1024;
    const H: u32 = 512;

    /// Unit vector at `elevation` above the horizon, `azimuth` about +Y from +Z
    /// toward +X (degrees; the sky's convention).
    fn towards(elevation: f32, azimuth: f32) -> Vec3 {
        let (e, a) = (elevation.to_radians(), azimuth.to_radians());
        Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos())
    }

    /// Adds a disc of `radiance` and angular `radius` (radians) around `dir`,
    /// each texel weighted by its covered fraction (16 × 16 samples).
    fn add_disc(env: &mut EnvMap, dir: Vec3, radius: f32, radiance: Vec3) {
        let (w, h) = (env.width, env.height);
        let reach = (radius + PI / h as f32).cos();
        for y in 0..h {
            for x in 0..w {
                if env.texel_direction(x, y).dot(dir) < reach {
                    continue;
                }
                // Samples weighted by sin θ, the area element.
                let (mut covered, mut all) = (0.0, 0.0);
                for sy in 0..16 {
                    for sx in 0..16 {
                        let u = (x as f32 + (sx as f32 + 0.5) / 16.0) / w as f32;
                        let v = (y as f32 + (sy as f32 + 0.5) / 16.0) / h as f32;
                        let area = (PI * v).sin();
                        all += area;
                        if direction(u, v).dot(dir) >= radius.cos() {
                            covered += area;
                        }
                    }
                }
                env.texels[(y * w + x) as usize] += radiance * (covered / all);
            }
        }
    }

    /// `∫ L dω` of a disc: radiance × 2π(1 − cos r).
    fn disc_power(radius: f32, radiance: Vec3) -> Vec3 {
        radiance * (2.0 * PI * (1.0 - radius.cos()))
    }

    fn angle_deg(a: Vec3, b: Vec3) -> f32 {
        a.cross(b).length().atan2(a.dot(b)).to_degrees()
    }

    fn worst_relative(got: Vec3, want: Vec3) -> f32 {
        ((got - want) / want).abs().max_element()
    }

    /// `Σ L dω` per channel, f64.
    fn map_energy(env: &EnvMap) -> DVec3 {
        let grid = Grid::new(env.width as usize, env.height as usize);
        energy(&grid, &env.texels, 0..env.texels.len())
    }

    /// One disc sun on a uniform sky (L = 1) is found within 1° and 2 % power.
    fn assert_recovers_one_sun(name: &str, dir: Vec3) -> ExtractedLight {
        let radius = 1.5f32.to_radians();
        let radiance = Vec3::new(1200.0, 1000.0, 800.0);
        let mut env = EnvMap::uniform(Vec3::ONE, W, H);
        add_disc(&mut env, dir, radius, radiance);
        let ex = extract(&env, LightsMode::Auto);
        assert_eq!(ex.lights.len(), 1, "{name}: {:?}", ex.lights);
        let l = ex.lights[0];
        let want = disc_power(radius, radiance);
        let (angle, power) = (angle_deg(l.direction, dir), worst_relative(l.power, want));
        println!(
            "{name}: direction off by {angle:.4}°, power off by {:.3} %, radius {:.2}° \
             (disc 1.5°), {} texels, share {:.2} %",
            100.0 * power,
            l.angular_radius_rad.to_degrees(),
            l.texels,
            100.0 * l.share
        );
        assert!(angle < 1.0, "{name}: {angle}°");
        assert!(power < 0.02, "{name}: power {} vs {want}", l.power);
        let share = want.dot(LUMINANCE) / (4.0 * PI + want.dot(LUMINANCE));
        assert!(
            (l.share - share).abs() < 0.02 * share,
            "{name}: {}",
            l.share
        );
        // What is left near the sun is the sky: L = 1, never more.
        let near = (3.0f32).to_radians().cos();
        for (i, t) in ex.residual.texels.iter().enumerate() {
            let d = env.texel_direction(i as u32 % W, i as u32 / W);
            if d.dot(dir) > near {
                assert!(
                    t.max_element() < 1.0 + 1e-3,
                    "{name}: residual {t} near the sun"
                );
            }
        }
        l
    }

    #[test]
    fn a_disc_sun_is_recovered() {
        // Elevation 37°, azimuth 71°: on no texel centre.
        assert_recovers_one_sun("el 37° az 71°", towards(37.0, 71.0));
    }

    #[test]
    fn a_sun_on_the_seam_is_one_light() {
        // Azimuth 0 is +Z: u = 0 ≡ 1, the disc straddles the seam.
        let dir = towards(20.0, 0.1);
        let uv = crate::scene::env::direction_to_uv(dir);
        assert!(uv.x < 0.01 || uv.x > 0.99, "{uv}");
        assert_recovers_one_sun("seam", dir);
    }

    #[test]
    fn a_sun_over_the_pole_is_one_light() {
        // Within 1° of the zenith the disc covers whole rows at the top.
        assert_recovers_one_sun("pole", towards(89.2, 200.0));
    }

    /// A smooth sky: blue, brighter towards the zenith and towards +X.
    fn gradient_sky() -> EnvMap {
        EnvMap::from_fn(W, H, |d| {
            Vec3::new(0.4, 0.5, 0.7) * (1.0 + 2.0 * (0.5 + 0.5 * d.y).powi(2)) + 0.1 * d.x
        })
    }

    #[test]
    fn the_fill_continues_a_gradient_sky() {
        let (dir, radius) = (towards(37.0, 71.0), 1.5f32.to_radians());
        let radiance = Vec3::new(1200.0, 1000.0, 800.0);
        let sky = gradient_sky();
        let mut env = sky.clone();
        add_disc(&mut env, dir, radius, radiance);
        let ex = extract(&env, LightsMode::Auto);
        assert_eq!(ex.lights.len(), 1, "{:?}", ex.lights);
        let l = ex.lights[0];
        let (angle, power) = (
            angle_deg(l.direction, dir),
            worst_relative(l.power, disc_power(radius, radiance)),
        );
        // Within 3° of the sun the residual is the sky: no texel brighter than
        // 1.01 × the sky there, none more than 1 % off.
        let near = 3.0f32.to_radians().cos();
        let (mut worst, mut ratio) = (0.0f32, 0.0f32);
        let sky_max = (0..sky.texels.len())
            .filter(|&i| sky.texel_direction(i as u32 % W, i as u32 / W).dot(dir) > near)
            .map(|i| sky.texels[i].max_element())
            .fold(0.0, f32::max);
        for (i, (r, s)) in ex.residual.texels.iter().zip(&sky.texels).enumerate() {
            if sky.texel_direction(i as u32 % W, i as u32 / W).dot(dir) > near {
                worst = worst.max(worst_relative(*r, *s));
                ratio = ratio.max(r.max_element() / sky_max);
            }
        }
        println!(
            "gradient sky: direction off by {angle:.4}°, power off by {:.3} %, residual within \
             {:.3} % of the sky near the sun, at most {ratio:.4} × its brightest texel there",
            100.0 * power,
            100.0 * worst
        );
        assert!(angle < 1.0 && power < 0.02, "{l:?}");
        assert!(worst < 0.01 && ratio < 1.01, "{worst} {ratio}");
    }

    #[test]
    fn maps_without_a_compact_source_give_no_lights() {
        let gradient = gradient_sky();
        let dome = render_sky_impl(&SkyParams::default(), W, H, false);
        let (sunset, _) = load(&crate::assets::path("env/sunset.exr")).unwrap();
        for (name, env) in [
            ("uniform", EnvMap::uniform(Vec3::splat(0.7), W, H)),
            ("gradient", gradient),
            ("Preetham sky without its sun", dome),
            ("sunset.exr", sunset),
        ] {
            let ex = extract(&env, LightsMode::Auto);
            assert!(ex.lights.is_empty(), "{name}: {:?}", ex.lights);
            assert_eq!(ex.residual, env, "{name}");
        }
    }

    #[test]
    fn the_built_in_sky_gives_its_sun() {
        let p = SkyParams::default();
        let env = render_sky(&p, W, H);
        let ex = extract(&env, LightsMode::Auto);
        assert_eq!(ex.lights.len(), 1, "{:?}", ex.lights);
        let l = ex.lights[0];
        let angle = angle_deg(l.direction, p.sun_direction());
        let power = worst_relative(l.power, sun_irradiance(&p));
        println!(
            "sky: direction off by {angle:.4}°, power off by {:.5} % of the sun's irradiance, \
             share {:.1} %",
            100.0 * power,
            100.0 * l.share
        );
        assert!(angle < 0.5, "{angle}°");
        assert!(power < 0.02, "{} vs {}", l.power, sun_irradiance(&p));
    }

    #[test]
    fn energy_is_conserved() {
        let (studio, _) = load(&crate::assets::path("env/studio.exr")).unwrap();
        let mut suns = EnvMap::uniform(Vec3::splat(0.5), W, H);
        add_disc(&mut suns, towards(10.0, 30.0), 0.03, Vec3::splat(3000.0));
        add_disc(
            &mut suns,
            towards(60.0, 250.0),
            0.05,
            Vec3::new(900.0, 700.0, 500.0),
        );
        for (name, env, mode) in [
            ("studio.exr", studio, LightsMode::Auto),
            ("two suns", suns, LightsMode::Count(2)),
        ] {
            let ex = extract(&env, mode);
            assert!(!ex.lights.is_empty(), "{name}");
            let lights: DVec3 = ex.lights.iter().map(|l| l.power.as_dvec3()).sum();
            let (before, after) = (map_energy(&env), map_energy(&ex.residual) + lights);
            let error = ((after - before) / before).abs().max_element();
            println!("{name}: residual + lights = map within {error:.2e}");
            assert!(error < 1e-6, "{name}: {after} vs {before}");
            // Extraction never adds light.
            for (r, m) in ex.residual.texels.iter().zip(&env.texels) {
                assert!(r.cmple(*m).all(), "{name}: {r} > {m}");
            }
        }
    }

    /// A uniform sky (L = 1) with suns of 1.5° radius and these radiances at
    /// these (elevation, azimuth).
    fn suns(list: &[(f32, f32, f32)]) -> EnvMap {
        let mut env = EnvMap::uniform(Vec3::ONE, W, H);
        for &(e, a, radiance) in list {
            add_disc(
                &mut env,
                towards(e, a),
                1.5f32.to_radians(),
                Vec3::splat(radiance),
            );
        }
        env
    }

    #[test]
    fn count_takes_the_strongest() {
        let list = [
            (20.0, 40.0, 1000.0),
            (50.0, 160.0, 3000.0),
            (5.0, 280.0, 2000.0),
        ];
        let env = suns(&list);
        let ex = extract(&env, LightsMode::Count(2));
        assert_eq!(ex.lights.len(), 2);
        for (l, (e, a, radiance)) in ex.lights.iter().zip([list[1], list[2]]) {
            assert!(angle_deg(l.direction, towards(e, a)) < 1.0, "{l:?}");
            let want = disc_power(1.5f32.to_radians(), Vec3::splat(radiance));
            assert!(worst_relative(l.power, want) < 0.02, "{l:?}");
        }
        // The weakest is still in the residual.
        assert!(ex.residual.sample_dir(towards(20.0, 40.0)).x > 500.0);
        let none = extract(&env, LightsMode::Count(0));
        assert!(none.lights.is_empty());
        assert_eq!(none.residual, env);
        assert_eq!(extract(&env, LightsMode::Count(3)).lights.len(), 3);
        // Count takes candidates too weak for Auto: a sun of 2.5 % of the energy.
        let weak = suns(&[(30.0, 90.0, 150.0)]);
        assert!(extract(&weak, LightsMode::Auto).lights.is_empty());
        let one = extract(&weak, LightsMode::Count(1)).lights;
        assert_eq!(one.len(), 1);
        assert!(one[0].share < MIN_SHARE, "{:?}", one[0]);
    }

    #[test]
    fn at_most_eight_lights() {
        // Twelve equal suns of 6.7 % each: Auto and Count(12) stop at eight.
        let list: Vec<(f32, f32, f32)> = (0..12)
            .map(|i| {
                (
                    if i % 2 == 0 { 15.0 } else { -25.0 },
                    30.0 * i as f32,
                    2000.0,
                )
            })
            .collect();
        let env = suns(&list);
        let auto = extract(&env, LightsMode::Auto);
        assert!(auto.lights.iter().all(|l| l.share > MIN_SHARE));
        assert_eq!(auto.lights.len(), MAX_EXTRACTED_LIGHTS);
        assert_eq!(
            extract(&env, LightsMode::Count(12)).lights.len(),
            MAX_EXTRACTED_LIGHTS
        );
        let powers: Vec<f32> = auto.lights.iter().map(|l| l.power.dot(LUMINANCE)).collect();
        assert!(powers.windows(2).all(|p| p[0] >= p[1]), "{powers:?}");
    }

    #[test]
    fn world_directions_undo_the_gpu_rotation() {
        // common/envmap.glsl: env_dir(d, angle) takes a world direction into the map.
        let env_dir = |d: Vec3, angle: f32| {
            let (s, c) = angle.sin_cos();
            Vec3::new(c * d.x - s * d.z, d.y, s * d.x + c * d.z)
        };
        let light = ExtractedLight {
            direction: towards(25.0, 300.0),
            solid_angle_sr: 0.0,
            angular_radius_rad: 0.0,
            power: Vec3::ONE,
            share: 0.0,
            texels: 0,
        };
        for deg in [0.0f32, 37.0, -120.0, 400.0] {
            let world = light.world_direction(deg);
            assert!((env_dir(world, deg.to_radians()) - light.direction).length() < 1e-5);
            // Turning the map by DEG about +Y adds DEG to the azimuth.
            let (e, a) = elevation_azimuth_deg(world);
            assert!((e - 25.0).abs() < 1e-3, "{e}");
            assert!(
                ((a - 300.0 - deg).rem_euclid(360.0) + 1e-3) % 360.0 < 2e-3,
                "{deg}: {a}"
            );
        }
    }

    /// Per-normal relative error (mean, max) of the irradiance of SH9 of
    /// `residual` plus `lights` as point sources against brute-force
    /// integration of `env`, over 256 well-spread normals (the metric of
    /// `light::sh`'s table in docs/design/lighting.md).
    fn sh9_error(env: &EnvMap, residual: &EnvMap, lights: &[ExtractedLight]) -> (f32, f32) {
        use crate::light::sh;
        let normals: Vec<Vec3> = (0..256)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 256.0;
                let a = i as f32 * 2.399_963_2; // golden angle
                let r = (1.0 - z * z).max(0.0).sqrt();
                Vec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect();
        let coefficients = sh::project(residual);
        let reference = sh::brute_force_irradiance_many(env, &normals);
        let errors: Vec<f32> = normals
            .iter()
            .zip(&reference)
            .map(|(n, want)| {
                let got = lights
                    .iter()
                    .fold(sh::irradiance(&coefficients, *n), |e, l| {
                        e + l.power * n.dot(l.direction).max(0.0)
                    });
                (got - *want).length() / want.length()
            })
            .collect();
        let mean = errors.iter().sum::<f32>() / errors.len() as f32;
        (mean, errors.iter().fold(0.0, |a, &b| a.max(b)))
    }

    /// What `Auto` takes from the six CC0 maps (the table of docs/design/lighting.md),
    /// and the SH9 irradiance error with and without the lights taken out:
    /// `cargo test --release --lib light::extract::tests::cc0 -- --nocapture`.
    #[test]
    fn cc0_maps() {
        for (name, count) in [
            ("royal_esplanade_1k.hdr", 2),
            ("venice_sunset_1k.hdr", 0),
            ("pedestrian_overpass_1k.hdr", 1),
            ("quarry_01_1k.hdr", 1),
            ("studio.exr", 4),
            ("sunset.exr", 0),
        ] {
            let (env, _) = load(&crate::assets::path(&format!("env/{name}"))).unwrap();
            let ex = extract(&env, LightsMode::Auto);
            let residual = 1.0 - ex.lights.iter().map(|l| l.share).sum::<f32>();
            let (before, after) = (
                sh9_error(&env, &env, &[]),
                sh9_error(&env, &ex.residual, &ex.lights),
            );
            println!(
                "{name}: {} lights, residual {:.1} %; SH9 irradiance error mean {:.2} % max {:.1} % \
                 (without extraction {:.2} %, {:.1} %)",
                ex.lights.len(),
                100.0 * residual,
                100.0 * after.0,
                100.0 * after.1,
                100.0 * before.0,
                100.0 * before.1
            );
            for l in &ex.lights {
                let (e, a) = elevation_azimuth_deg(l.direction);
                println!(
                    "  elevation {e:5.1}°, azimuth {a:5.1}°, {:.4} sr (radius {:.1}°), \
                     share {:.1} %, power {:.3} {:.3} {:.3}",
                    l.solid_angle_sr,
                    l.angular_radius_rad.to_degrees(),
                    100.0 * l.share,
                    l.power.x,
                    l.power.y,
                    l.power.z
                );
            }
            assert_eq!(ex.lights.len(), count, "{name}");
            // Taking the sources out brings SH9 to the 3 % it reaches on smooth maps.
            assert!(after.0 < 0.03, "{name}: {after:?}");
            assert!(
                count == 0 || after.0 < 0.5 * before.0,
                "{name}: {after:?} {before:?}"
            );
        }
    }
}
