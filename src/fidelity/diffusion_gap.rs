//! `dermis reference --diffusion`: the texture-space chain against the exact
//! diffusion over the surface (skin::reference). The scene's irradiance and
//! blur levels are rendered and read back as stored; at the covered texels of
//! the irradiance's resolution (every `stride`-th), the reference convolves the
//! light that enters the skin (the same irradiance, less the sky's light through
//! thin skin, which its chords carry themselves) with the same profile in 3-D,
//! and both give the diffused irradiance the final pass shades,
//! `mix(E, Σ wₖ·blurₖ, blur_amount)` (the chain's texels with the lights'
//! transmitted light the final pass adds). The relative error of luminance
//! (sweep::metric::relative) is reported per face region of the region map,
//! near UV seams, where scattering changes the light by more than 20 %, and over
//! the face, at texels and through the camera. docs/records/2026-11-26-exact-diffusion.md, "Exact diffusion".

use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::light::occlusion::Bvh;
use crate::light::reference::{bilinear, rgba8};
use crate::render::output::{write_exr, write_rgba8_png};
use crate::render::progress::Task;
use crate::render::{render_scene, stored_images, RenderOptions, View};
use crate::scene::file::{Chain, SceneFile};
use crate::scene::texture::LUMINANCE;
use crate::scene::Scene;
use crate::skin::reference::{texels, Diffusion, MeshEdges, Texel};
use crate::skin::specular::REGION_NAMES;
use crate::skin::SkinSettings;
use crate::sweep::metric::{relative, RelativeError};
use crate::sweep::output::write_side_by_side;
use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Texels within this distance (mm) of a UV seam are the seam region.
pub const SEAM_MM: f32 = 2.0;
/// Where |D_ref − E| > this share of D_ref, scattering changes the light
/// visibly: shadow edges, the terminator.
pub const SCATTERING_CHANGE: f32 = 0.2;
/// Below this coverage a level's texel has no value of its own.
const MIN_COVERAGE: f32 = 1e-3;

#[derive(Clone, Debug)]
pub struct DiffusionOptions {
    pub scene: SceneFile,
    /// The chains compared, each with or without the fold term (skin::fold).
    pub chains: Vec<(Chain, bool)>,
    /// Every `stride`-th texel in u and v is compared.
    pub stride: u32,
    /// Where to write the reference's and each chain's diffused irradiance and
    /// error (EXR, UV space at resolution / stride).
    pub out_dir: Option<PathBuf>,
}

/// One chain's errors against the reference.
#[derive(Clone, Debug, Serialize)]
pub struct DiffusionRow {
    pub environment: String,
    pub chain: String,
    /// With the fold term (skin.fold_correction).
    pub fold_correction: bool,
    pub resolution: u32,
    pub stride: u32,
    /// Per region: name, error, and the bias per channel (R, G, B).
    pub regions: Vec<RegionRow>,
    pub reference_seconds: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct RegionRow {
    pub region: String,
    /// Against the reference with every path (skin::reference::Scattered).
    pub error: RelativeError,
    /// Against the reference without the paths through the air.
    pub error_inside: RelativeError,
    /// Share of texels whose luminance lies between the two references (± 1 %).
    pub bracketed: f64,
    /// Σ(chain − reference)/Σ reference per channel: the colour's bias.
    pub bias_rgb: [f64; 3],
}

/// Share by which a value may stand outside the references' bracket and count
/// as within it.
const BRACKET_SLACK: f32 = 0.01;

impl RegionRow {
    /// The chain's values `got` against the references `upper` (every path) and
    /// `lower` (none through the air) over `mask`.
    fn new(
        region: String,
        upper: &[Vec3],
        lower: &[Vec3],
        got: &[Vec3],
        mask: &[bool],
    ) -> Result<Self> {
        let rgba =
            |v: &[Vec3]| -> Vec<f32> { v.iter().flat_map(|c| c.extend(1.0).to_array()).collect() };
        let got_rgba = rgba(got);
        let lum = |c: Vec3| c.dot(LUMINANCE);
        let inside = upper
            .iter()
            .zip(lower)
            .zip(got)
            .zip(mask)
            .filter(|(_, &m)| m)
            .filter(|(((u, l), g), _)| {
                let (u, l, g) = (lum(**u), lum(**l), lum(**g));
                g >= l * (1.0 - BRACKET_SLACK) && g <= u * (1.0 + BRACKET_SLACK)
            })
            .count();
        Ok(RegionRow {
            error: relative(&rgba(upper), &got_rgba, mask)?,
            error_inside: relative(&rgba(lower), &got_rgba, mask)?,
            bracketed: inside as f64 / mask.iter().filter(|&&m| m).count().max(1) as f64,
            bias_rgb: bias(upper, got, mask),
            region,
        })
    }
}

/// The reference at every texel, and what the comparison needs of the mesh.
struct Reference {
    texels: Vec<Texel>,
    irradiance: Vec<Vec3>,
    /// With every path, and without those through the air.
    diffused: Vec<Vec3>,
    inside: Vec<Vec3>,
    masks: Vec<(String, Vec<bool>)>,
    /// Each texel's face region.
    region: Vec<usize>,
    /// The mesh's pixels through the scene's camera, and the exact diffusion
    /// there.
    pixels: Vec<Pixel>,
    pixel_diffused: Vec<Vec3>,
    pixel_inside: Vec<Vec3>,
    /// The face, the ears and every pixel.
    pixel_masks: Vec<(String, Vec<bool>)>,
    seconds: f64,
}

/// A pixel of the scene's camera that sees the mesh.
struct Pixel {
    index: usize,
    uv: Vec2,
    position: Vec3,
    normal: Vec3,
    /// albedo^(1−mix)/π: what the final pass multiplies the diffused irradiance by.
    shade: Vec3,
}

/// Runs the comparison for every chain of `opts`.
pub fn run(
    ctx: &Arc<Context>,
    opts: &DiffusionOptions,
    mut progress: impl FnMut(&DiffusionRow),
) -> Result<Vec<DiffusionRow>> {
    if opts.chains.is_empty() || opts.stride == 0 {
        return Err(Error::Input(
            "reference --diffusion: give at least one chain and a stride ≥ 1".into(),
        ));
    }
    if let Some(dir) = &opts.out_dir {
        crate::sweep::output::create_dir(dir)?;
    }
    let mut scene = crate::skin::with_medium_albedo(Scene::load(opts.scene.clone())?);
    let skin = SkinSettings::resolve(&scene.file.skin, &scene.file.render)?;
    if skin.profile.gaussians.iter().any(|g| g.variance_mm2 <= 0.0) {
        return Err(Error::Input(format!(
            "reference --diffusion: skin.blur_width {} leaves no scattering to compare",
            scene.file.skin.blur_width
        )));
    }
    let weights: Vec<Vec3> = skin.profile.gaussians.iter().map(|g| g.weights).collect();
    let mut reference = None;
    let mut rows = Vec::new();
    for &(chain, fold) in &opts.chains {
        scene.file.skin.chain = chain;
        scene.file.skin.fold_correction = fold;
        let names: Vec<String> = std::iter::once("irradiance".to_string())
            .chain((1..=6).map(|k| format!("blur{k}")))
            .chain(std::iter::once("translucent_front".to_string()))
            .collect();
        let images = stored_images(ctx, &scene, &names)?;
        let mut levels: Vec<Level> = images.into_iter().map(Level::from).collect();
        let translucent = levels.pop().expect("translucent_front");
        let reference = match &mut reference {
            Some(r) => r,
            None => {
                let entering = entering_irradiance(ctx, &scene, &levels[0])?;
                reference.insert(exact(&scene, &skin, &entering, opts.stride)?)
            }
        };
        // The chain's diffused irradiance as the final pass combines its levels.
        let chain_at = |uv: Vec2, e: Vec3| {
            let blurred: Vec3 = levels[1..]
                .iter()
                .zip(&weights)
                .map(|(level, w)| *w * level.at(uv).unwrap_or(e))
                .sum();
            e.lerp(blurred, skin.blur_amount)
        };
        // At a texel, the shadowed lights' light through thin skin too, as
        // the final pass adds it (skin.frag: the translucent texture of the
        // front side × skin.transmission × albedo^mix; 1×1 and empty when the
        // term is off). Through the camera it comes with the transmission view.
        let through = |uv: Vec2| {
            let t = translucent.at(uv).unwrap_or(Vec3::ZERO);
            t * skin.transmission * rgba8(&scene.albedo, uv).truncate().powf(skin.mix)
        };
        let diffused: Vec<Vec3> = reference
            .texels
            .iter()
            .zip(&reference.irradiance)
            .map(|(t, &e)| chain_at(t.uv, levels[0].at(t.uv).unwrap_or(e)) + through(t.uv))
            .collect();
        let pixel_diffused: Vec<Vec3> = reference
            .pixels
            .iter()
            .map(|p| chain_at(p.uv, levels[0].at(p.uv).unwrap_or(Vec3::ZERO)))
            .collect();
        let name = format!("{chain:?}{}", if fold { "+fold" } else { "" }).to_lowercase();
        let mut regions = reference
            .masks
            .iter()
            .filter(|(_, mask)| mask.contains(&true))
            .map(|(region, mask)| {
                RegionRow::new(
                    region.clone(),
                    &reference.diffused,
                    &reference.inside,
                    &diffused,
                    mask,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let transmitted = transmitted(ctx, &scene, &skin)?;
        let screen = Screen::new(&scene, reference, &pixel_diffused, &transmitted);
        regions.extend(screen.rows(reference)?);
        if let Some(dir) = &opts.out_dir {
            let first = rows.is_empty();
            screen.write(dir, &name, first, &scene)?;
            write_uv(
                dir,
                &name,
                first,
                reference,
                &diffused,
                skin.resolution,
                opts.stride,
            )?;
        }
        let row = DiffusionRow {
            environment: scene.file.environment.source.to_string(),
            chain: name,
            fold_correction: fold,
            resolution: skin.resolution,
            stride: opts.stride,
            regions,
            reference_seconds: reference.seconds,
        };
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// The diffuse term through the camera, shaded as the final pass: the exact
/// (with and without the paths through the air) and the chain's, with the
/// transmitted light the final pass adds (its view), per mesh pixel.
struct Screen {
    width: u32,
    height: u32,
    exact: Vec<Vec3>,
    inside: Vec<Vec3>,
    chain: Vec<Vec3>,
    /// Pixel index of each.
    index: Vec<usize>,
}

impl Screen {
    fn new(scene: &Scene, reference: &Reference, chain: &[Vec3], transmitted: &[f32]) -> Screen {
        let shaded = |values: &[Vec3], plus: &[f32]| -> Vec<Vec3> {
            reference
                .pixels
                .iter()
                .zip(values)
                .map(|(p, v)| {
                    let extra = plus
                        .get(4 * p.index..4 * p.index + 3)
                        .map_or(Vec3::ZERO, Vec3::from_slice);
                    p.shade * *v + extra
                })
                .collect()
        };
        Screen {
            width: scene.file.render.width,
            height: scene.file.render.height,
            exact: shaded(&reference.pixel_diffused, &[]),
            inside: shaded(&reference.pixel_inside, &[]),
            chain: shaded(chain, transmitted),
            index: reference.pixels.iter().map(|p| p.index).collect(),
        }
    }

    /// A row per pixel mask of the reference.
    fn rows(&self, reference: &Reference) -> Result<Vec<RegionRow>> {
        let (w, h) = (self.width, self.height);
        reference
            .pixel_masks
            .iter()
            .filter(|(_, mask)| mask.contains(&true))
            .map(|(label, mask)| {
                let label = format!("screen {w}×{h}: {label}");
                RegionRow::new(label, &self.exact, &self.inside, &self.chain, mask)
            })
            .collect()
    }

    /// RGBA image of `values` (alpha: the mesh's coverage).
    fn image(&self, values: &[Vec3]) -> Vec<f32> {
        let mut out = vec![0.0f32; 4 * (self.width * self.height) as usize];
        for (&i, v) in self.index.iter().zip(values) {
            out[4 * i..4 * i + 4].copy_from_slice(&v.extend(1.0).to_array());
        }
        out
    }

    /// `screen-exact.exr` (with `first`), `screen-NAME.exr` and exact | chain |
    /// 10 × |difference| as a PNG at the exact image's exposure.
    fn write(&self, dir: &Path, name: &str, first: bool, scene: &Scene) -> Result<()> {
        let (w, h) = (self.width, self.height);
        let (exact, chain) = (self.image(&self.exact), self.image(&self.chain));
        if first {
            write_exr(&dir.join("screen-exact.exr"), w, h, &exact)?;
        }
        write_exr(&dir.join(format!("screen-{name}.exr")), w, h, &chain)?;
        let difference: Vec<f32> = exact
            .iter()
            .zip(&chain)
            .enumerate()
            .map(|(i, (a, b))| if i % 4 == 3 { *a } else { 10.0 * (a - b).abs() })
            .collect();
        let images: [&[f32]; 3] = [&exact, &chain, &difference];
        let path = dir.join(format!("screen-exact-{name}-difference.png"));
        write_side_by_side(&path, (w, h), &images, &scene.file.render)
    }
}

/// The UV-space images (resolution / stride a side): `reference.exr` and
/// `regions.png` (with `first`), the chain's `NAME.exr` and its relative error
/// per channel `NAME-error.exr`.
fn write_uv(
    dir: &Path,
    name: &str,
    first: bool,
    reference: &Reference,
    diffused: &[Vec3],
    resolution: u32,
    stride: u32,
) -> Result<()> {
    let side = resolution.div_ceil(stride);
    let image = |values: &[Vec3]| {
        let mut out = vec![0.0f32; 4 * (side * side) as usize];
        for (t, v) in reference.texels.iter().zip(values) {
            let i = 4 * ((t.y / stride) * side + t.x / stride) as usize;
            out[i..i + 4].copy_from_slice(&v.extend(1.0).to_array());
        }
        out
    };
    let error: Vec<Vec3> = reference
        .diffused
        .iter()
        .zip(diffused)
        .map(|(r, d)| (*d - *r) / r.max(Vec3::splat(1e-6)))
        .collect();
    if first {
        write_exr(
            &dir.join("reference.exr"),
            side,
            side,
            &image(&reference.diffused),
        )?;
        let colours = region_colours(reference, side, stride);
        write_rgba8_png(&dir.join("regions.png"), side, side, &colours)?;
    }
    write_exr(
        &dir.join(format!("{name}.exr")),
        side,
        side,
        &image(diffused),
    )?;
    write_exr(
        &dir.join(format!("{name}-error.exr")),
        side,
        side,
        &image(&error),
    )
}

/// A read-back level: coverage-premultiplied RGBA, sampled as the final pass
/// does (bilinear at the texel's UV, divided by coverage).
#[derive(Clone)]
struct Level {
    width: u32,
    height: u32,
    rgba: Vec<f32>,
}

impl From<(u32, u32, Vec<f32>)> for Level {
    fn from((width, height, rgba): (u32, u32, Vec<f32>)) -> Self {
        Level {
            width,
            height,
            rgba,
        }
    }
}

impl Level {
    fn at(&self, uv: Vec2) -> Option<Vec3> {
        let c = bilinear(self.width, self.height, uv, |x, y| {
            let i = 4 * (y as usize * self.width as usize + x as usize);
            Vec4::from_slice(&self.rgba[i..i + 4])
        });
        (c.w > MIN_COVERAGE).then(|| c.truncate() / c.w)
    }
}

/// The irradiance the reference convolves: the chain's, less the sky's light
/// through thin skin (light::transmission), which the chain adds to its
/// irradiance as its stand-in for the far side of a thin part and which the
/// reference carries itself, by its chords through the skin (docs/records/2026-11-26-exact-diffusion.md,
/// "Exact diffusion"). Without transmission, the chain's own irradiance.
fn entering_irradiance(ctx: &Arc<Context>, scene: &Scene, irradiance: &Level) -> Result<Level> {
    if scene.file.skin.transmission <= 0.0 {
        return Ok(irradiance.clone());
    }
    let mut scene = scene.clone();
    scene.file.skin.transmission = 0.0;
    let mut images = stored_images(ctx, &scene, &["irradiance".to_string()])?;
    Ok(Level::from(images.remove(0)))
}

/// The exact diffusion at the covered texels of the irradiance, and the masks.
fn exact(scene: &Scene, skin: &SkinSettings, irradiance: &Level, stride: u32) -> Result<Reference> {
    let mesh = &scene.mesh;
    let texels = texels(
        &mesh.positions,
        &mesh.normals,
        &mesh.uvs,
        &mesh.indices,
        irradiance.width,
        stride,
    );
    if texels.is_empty() {
        return Err(Error::Input(
            "reference --diffusion: the mesh covers no texel".into(),
        ));
    }
    // A medium's dense fit of its R(r): the reference measures the chain's
    // six-Gaussian fit too.
    let profile = &skin.reference_profile;
    let variances: Vec<f32> = profile.gaussians.iter().map(|g| g.variance_mm2).collect();
    let weights: Vec<Vec3> = profile.gaussians.iter().map(|g| g.weights).collect();
    let e: Vec<Vec3> = texels
        .iter()
        .map(|t| irradiance.at(t.uv).unwrap_or(Vec3::ZERO))
        .collect();
    let scale = e.iter().map(|e| e.max_element()).sum::<f32>() / e.len() as f32;
    let diffusion = Diffusion::new(&mesh.positions, &mesh.uvs, &mesh.indices, &variances)?
        .with_irradiance_scale(scale);
    let edges = MeshEdges::new(
        &mesh.positions,
        &mesh.uvs,
        &mesh.indices,
        diffusion.extent(),
    );
    let pixels = pixels(scene, skin);
    let task = Task::new("exact diffusion", (texels.len() + pixels.len()) as u64);
    let start = Instant::now();
    let lookup = |uv: Vec2| irradiance.at(uv);
    // (every path, none through the air)
    let exact = |position: Vec3, normal: Vec3, e: Vec3| {
        let s = diffusion.at(position, normal, &lookup);
        let open = edges.to_open(position);
        let reach = diffusion.reach();
        let normalised = |k: usize| open.is_some_and(|o| o < reach[k]);
        task.add(1);
        let d = |air| e.lerp(s.diffuse(&weights, air, normalised), skin.blur_amount);
        (d(true), d(false))
    };
    let (diffused, inside): (Vec<Vec3>, Vec<Vec3>) = texels
        .par_iter()
        .zip(&e)
        .map(|(t, &e)| exact(t.position, t.normal, e))
        .unzip();
    let pixel_e: Vec<Vec3> = pixels
        .iter()
        .map(|p| irradiance.at(p.uv).unwrap_or(Vec3::ZERO))
        .collect();
    let (pixel_diffused, pixel_inside): (Vec<Vec3>, Vec<Vec3>) = pixels
        .par_iter()
        .zip(&pixel_e)
        .map(|(p, &e)| exact(p.position, p.normal, e))
        .unzip();
    let seconds = start.elapsed().as_secs_f64();
    drop(task);
    let ids = region_ids(scene, texels.iter().map(|t| (t.uv, t.position)));
    let pixel_ids = region_ids(scene, pixels.iter().map(|p| (p.uv, p.position)));
    let masks = texel_masks(&ids, &texels, &edges, &diffused, &e);
    let pixel_masks = pixel_masks(&pixel_ids, &pixel_diffused, &pixel_e);
    Ok(Reference {
        texels,
        irradiance: e,
        diffused,
        masks,
        region: ids,
        pixel_masks,
        pixels,
        pixel_diffused,
        pixel_inside,
        inside,
        seconds,
    })
}

/// The pixels of the scene's camera (render.width × render.height) that see
/// the mesh, by ray casting (light::occlusion::Bvh), as the final pass shades
/// them.
fn pixels(scene: &Scene, skin: &SkinSettings) -> Vec<Pixel> {
    let (w, h) = (scene.file.render.width, scene.file.render.height);
    let mesh = &scene.mesh;
    let bvh = Bvh::from_mesh(mesh);
    let inv = scene.camera.view_projection(w as f32 / h as f32).inverse();
    (0..w * h)
        .into_par_iter()
        .filter_map(|i| {
            let ndc = Vec2::new(
                ((i % w) as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                ((i / w) as f32 + 0.5) / h as f32 * 2.0 - 1.0,
            );
            let near = inv.project_point3(ndc.extend(0.0));
            let far = inv.project_point3(ndc.extend(1.0));
            let hit = bvh.closest_hit(near, far - near, 1.0)?;
            let k = 3 * hit.triangle as usize;
            let corner = |c: usize| mesh.indices[k + c] as usize;
            let b = hit.barycentric.to_array();
            let uv: Vec2 = (0..3).map(|c| b[c] * mesh.uvs[corner(c)]).sum();
            let position: Vec3 = (0..3).map(|c| b[c] * mesh.positions[corner(c)]).sum();
            let normal: Vec3 = (0..3).map(|c| b[c] * mesh.normals[corner(c)]).sum();
            let albedo = rgba8(&scene.albedo, uv).truncate();
            Some(Pixel {
                index: i as usize,
                uv,
                position,
                normal: normal.normalize_or_zero(),
                shade: albedo.powf(1.0 - skin.mix) / std::f32::consts::PI,
            })
        })
        .collect()
}

/// The transmitted radiance the final pass adds (the `transmission` view, RGBA
/// through the scene's camera, no glow); empty when `skin.transmission` is 0.
fn transmitted(ctx: &Arc<Context>, scene: &Scene, skin: &SkinSettings) -> Result<Vec<f32>> {
    if skin.transmission <= 0.0 {
        return Ok(Vec::new());
    }
    let mut scene = scene.clone();
    scene.file.render.glow = false;
    let out = render_scene(
        ctx,
        &scene,
        &RenderOptions {
            view: View::named("transmission"),
            hdr: true,
            ..RenderOptions::default()
        },
    )?;
    Ok(out.hdr.unwrap_or_default())
}

/// The comparison's texel masks: the face, each region, the seams, where
/// scattering changes the light by more than SCATTERING_CHANGE, all.
fn texel_masks(
    ids: &[usize],
    texels: &[Texel],
    edges: &MeshEdges,
    diffused: &[Vec3],
    irradiance: &[Vec3],
) -> Vec<(String, Vec<bool>)> {
    let mut masks = region_masks(ids);
    masks.push((
        format!("UV seams (≤ {SEAM_MM} mm)"),
        texels
            .iter()
            .map(|t| edges.to_seam(t.position).is_some_and(|d| d <= SEAM_MM))
            .collect(),
    ));
    masks.push(scattering_mask(diffused, irradiance));
    masks.push(("all".to_string(), vec![true; texels.len()]));
    masks
}

/// Where scattering changes the light by more than SCATTERING_CHANGE: the
/// reference's diffused luminance D against the irradiance's E, |D − E| > share · D.
fn scattering_mask(diffused: &[Vec3], irradiance: &[Vec3]) -> (String, Vec<bool>) {
    let lum = |c: Vec3| c.dot(LUMINANCE);
    (
        format!("scattering > {:.0} %", 100.0 * SCATTERING_CHANGE),
        diffused
            .iter()
            .zip(irradiance)
            .map(|(&d, &e)| (lum(d) - lum(e)).abs() > SCATTERING_CHANGE * lum(d))
            .collect(),
    )
}

/// The face (every region but the last, neck/other) and each region.
fn region_masks(ids: &[usize]) -> Vec<(String, Vec<bool>)> {
    let neck = REGION_NAMES.len() - 1;
    std::iter::once(("face".to_string(), ids.iter().map(|&i| i != neck).collect()))
        .chain(
            REGION_NAMES
                .iter()
                .enumerate()
                .map(|(k, name)| (name.to_string(), ids.iter().map(|&i| i == k).collect())),
        )
        .collect()
}

/// The camera's pixel masks: the face, each region, where scattering changes
/// the light by more than SCATTERING_CHANGE, all.
fn pixel_masks(ids: &[usize], diffused: &[Vec3], irradiance: &[Vec3]) -> Vec<(String, Vec<bool>)> {
    let mut masks = region_masks(ids);
    masks.push(scattering_mask(diffused, irradiance));
    masks.push(("all".to_string(), vec![true; ids.len()]));
    masks
}

/// The face region (skin::specular::REGION_NAMES) of each (uv, position): from the
/// scene's region map where it has one (a file's, or the built-in head's), else
/// from the mesh by [`landmark_region`].
fn region_ids(scene: &Scene, points: impl Iterator<Item = (Vec2, Vec3)>) -> Vec<usize> {
    let last = REGION_NAMES.len() - 1;
    if scene.file.textures.regions.is_none() && scene.file.mesh.is_some() {
        let nose = scene
            .mesh
            .positions
            .iter()
            .copied()
            .reduce(|a, b| if b.z > a.z { b } else { a })
            .unwrap_or_default();
        return points.map(|(_, x)| landmark_region(x - nose)).collect();
    }
    let r = &scene.regions;
    points
        .map(|(uv, _)| {
            let p = (uv * Vec2::new(r.width as f32, r.height as f32)).as_uvec2();
            let i = 4 * (p.y.min(r.height - 1) * r.width + p.x.min(r.width - 1)) as usize;
            (r.rgba8[i] as usize).min(last)
        })
        .collect()
}

/// The face region of a point `d` mm from the nose tip (the mesh's most +z
/// point) of a head looking along +z, y up: boxes about the tip sized for an
/// adult face (nasal bridge ~50 mm, tip to mouth ~35 mm, ears ~75 mm to the
/// side), checked by eye on the scan (docs/design/skin.md shows the masks).
pub fn landmark_region(d: Vec3) -> usize {
    let (x, y, z) = (d.x.abs(), d.y, d.z);
    let within = |v: f32, lo: f32, hi: f32| (lo..=hi).contains(&v);
    let region = |name: &str| {
        REGION_NAMES
            .iter()
            .position(|n| *n == name)
            .expect("a region")
    };
    if x > 75.0 && within(y, -25.0, 50.0) && within(z, -180.0, -95.0) {
        region("ears")
    } else if x < 17.0 && within(y, -22.0, 32.0) && z > -32.0 {
        region("nose")
    } else if within(x, 12.0, 52.0) && within(y, 22.0, 50.0) && z > -55.0 {
        region("eyelids/around eyes")
    } else if x < 50.0 && within(y, 50.0, 110.0) && z > -65.0 {
        region("forehead")
    } else if x < 27.0 && within(y, -35.0, -18.0) && z > -40.0 {
        region("upper lip")
    } else if x < 27.0 && within(y, -52.0, -35.0) && z > -45.0 {
        region("lower lip")
    } else if x < 30.0 && within(y, -90.0, -52.0) && z > -60.0 {
        region("chin")
    } else if within(x, 17.0, 65.0) && within(y, -40.0, 22.0) && z > -75.0 {
        region(if d.x > 0.0 {
            "left cheek"
        } else {
            "right cheek"
        })
    } else {
        REGION_NAMES.len() - 1
    }
}

/// Each texel's region as a colour (UV space, rows in v's order; uncovered
/// texels black), to check the masks by eye.
fn region_colours(reference: &Reference, side: u32, stride: u32) -> Vec<u8> {
    const PALETTE: [[u8; 3]; 10] = [
        [230, 25, 75],
        [60, 180, 75],
        [255, 225, 25],
        [0, 130, 200],
        [245, 130, 48],
        [145, 30, 180],
        [70, 240, 240],
        [240, 50, 230],
        [210, 245, 60],
        [128, 128, 128],
    ];
    let mut out = vec![0u8; 4 * (side * side) as usize];
    for (t, &id) in reference.texels.iter().zip(&reference.region) {
        let i = 4 * ((t.y / stride) * side + t.x / stride) as usize;
        out[i..i + 3].copy_from_slice(&PALETTE[id % PALETTE.len()]);
        out[i + 3] = 255;
    }
    out
}

/// Σ(got − want)/Σ want per channel over `mask`: the chain's colour bias.
fn bias(want: &[Vec3], got: &[Vec3], mask: &[bool]) -> [f64; 3] {
    let (w, g) = want.iter().zip(got).zip(mask).filter(|(_, &m)| m).fold(
        (glam::DVec3::ZERO, glam::DVec3::ZERO),
        |(w, g), ((a, b), _)| (w + a.as_dvec3(), g + b.as_dvec3()),
    );
    ((g - w) / w.max(glam::DVec3::splat(1e-30))).to_array()
}

/// The rows as a Markdown table (percentages).
pub fn table(rows: &[DiffusionRow]) -> String {
    let pct = |v: f64| format!("{:.1} %", 100.0 * v);
    let mut out = String::from(
        "| environment | chain | region | texels | mean | median | p90 | bias R | bias G | bias B | mean, no air paths | in bracket |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        for g in &r.regions {
            out += &format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                r.environment,
                r.chain,
                g.region,
                g.error.pixels,
                pct(g.error.mean),
                pct(g.error.median),
                pct(g.error.p90),
                pct(g.bias_rgb[0]),
                pct(g.bias_rgb[1]),
                pct(g.bias_rgb[2]),
                pct(g.error_inside.mean),
                pct(g.bracketed),
            );
        }
    }
    out
}
