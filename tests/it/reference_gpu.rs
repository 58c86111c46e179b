//! The CPU reference image (`light::reference::render_view`) covers the same
//! pixels as the GPU's `--view direct` of the default scene (the Lee Perry-Smith
//! scan): the camera, pixel-centre and y conventions agree.

use crate::common;

use dermis::light::reference::{render_view, Settings};
use dermis::render::{render_scene, RenderOptions, View};
use dermis::scene::file::{scene_by_name, Occlusion};
use dermis::scene::Scene;

#[test]
fn reference_coverage_matches_the_gpu() {
    let (w, h) = (96, 120);
    let mut file = scene_by_name(None).unwrap();
    file.render.width = w;
    file.render.height = h;
    file.render.skybox = false; // alpha is then the mesh's coverage on both sides
    file.render.irradiance_resolution = 256;
    file.skin.occlusion = Occlusion::Off; // coverage does not depend on it
    let scene = Scene::load(file).unwrap();
    let gpu = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            hdr: true,
            view: View::named("direct"),
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    });
    let gpu_alpha: Vec<f32> = gpu.hdr.unwrap().chunks_exact(4).map(|p| p[3]).collect();
    // Coverage only: one MIS pair per pixel is enough.
    let cheap = Settings {
        strata: 1,
        min_batches: 1,
        max_samples: 2,
        ..Settings::default()
    };
    let reference = render_view(&scene, w, h, &cheap).unwrap();
    let cpu_alpha: Vec<f32> = reference.rgba.chunks_exact(4).map(|p| p[3]).collect();
    assert_eq!((gpu.width, gpu.height), (w, h));
    let (mut both, mut either) = (0, 0);
    for (g, c) in gpu_alpha.iter().zip(&cpu_alpha) {
        let (g, c) = (*g > 0.5, *c > 0.5);
        both += u32::from(g && c);
        either += u32::from(g || c);
    }
    let iou = both as f32 / either as f32;
    println!(
        "coverage at {w}×{h}: GPU {} pixels, reference {}, IoU {iou:.4}",
        gpu_alpha.iter().filter(|a| **a > 0.5).count(),
        reference.mesh_pixels
    );
    assert!(
        reference.mesh_pixels > (w * h) / 5,
        "{}",
        reference.mesh_pixels
    );
    // Measured 0.9998; sampling pixel corners instead of centres (half a pixel
    // off) gives 0.981, a flipped y 0.53.
    assert!(iou >= 0.995, "{iou}");
}

/// The sunny case: on the scan under quarry_01 (one sun, half the map's
/// energy), the direct term with the sun taken out as a shadowed light is at
/// least 3× closer to the reference than SH9 alone, and within 8 % on average
/// (docs/records/2026-11-25-sh9-against-reference.md). The reference converges to
/// 1 % here (0.5 % in the docs' table) to stay quick.
#[test]
fn extracted_lights_beat_sh9_alone_under_a_sunny_map() {
    use dermis::fidelity::lighting_gap::{run, LightingOptions};
    use dermis::scene::env::EnvSource;
    let opts = LightingOptions {
        scene: scene_by_name(None).unwrap(),
        environments: vec![EnvSource::File(dermis::assets::path(
            "env/quarry_01_1k.hdr",
        ))],
        width: 64,
        height: 80,
        settings: Settings {
            target_rel_err: 0.01,
            ..Settings::default()
        },
        out_dir: None,
    };
    let rows = common::with_gpu(|ctx| run(ctx, &opts, |_| {}).unwrap());
    let r = &rows[0];
    println!(
        "quarry_01, 64×80: SH9 mean {:.1} % (median {:.1} %, p90 {:.1} %), SH9 + {} light(s) \
         mean {:.1} % (median {:.1} %, p90 {:.1} %); reference {:.0} % converged",
        100.0 * r.sh9.mean,
        100.0 * r.sh9.median,
        100.0 * r.sh9.p90,
        r.extracted,
        100.0 * r.sh9_lights.mean,
        100.0 * r.sh9_lights.median,
        100.0 * r.sh9_lights.p90,
        100.0 * r.reference_converged
    );
    assert_eq!(r.extracted, 1);
    assert!(r.sh9_lights.pixels > 1000, "{}", r.sh9_lights.pixels);
    assert!(r.sh9_lights.mean <= 0.08, "{:?}", r.sh9_lights);
    assert!(3.0 * r.sh9_lights.mean <= r.sh9.mean, "{r:?}");
}

/// The texture-space chain against the exact diffusion over the scan's surface
/// (skin::reference, checked against closed forms in its unit tests): every
/// face region of the landmark masks is populated, and the chain (full,
/// adaptive, adaptive with the fold term) is close to the reference over the
/// face, the seams and the mesh.
/// The docs' figures (docs/records/2026-11-26-exact-diffusion.md) come from 1024².
#[test]
fn texture_space_diffusion_against_the_exact_reference() {
    use dermis::fidelity::diffusion_gap::{run, table, DiffusionOptions};
    use dermis::scene::file::Chain;
    use dermis::skin::specular::REGION_NAMES;
    let mut scene = scene_by_name(None).unwrap();
    scene.render.irradiance_resolution = 512;
    (scene.render.width, scene.render.height) = (48, 60);
    let opts = DiffusionOptions {
        scene,
        chains: vec![
            (Chain::Full, false),
            (Chain::Adaptive, false),
            (Chain::Adaptive, true),
        ],
        stride: 8,
        out_dir: None,
    };
    let rows = common::with_gpu(|ctx| run(ctx, &opts, |_| {}).unwrap());
    println!("{}", table(&rows));
    assert_eq!(rows.len(), 3);
    for r in &rows {
        let region = |name: &str| {
            r.regions
                .iter()
                .find(|g| g.region.starts_with(name))
                .unwrap_or_else(|| panic!("{}: no texels in {name}", r.chain))
        };
        for name in REGION_NAMES
            .iter()
            .chain(&["face", "UV seams", "scattering", "all"])
        {
            assert!(region(name).error.pixels >= 10, "{}: {name}", r.chain);
        }
        assert!(region("all").error.pixels > 2000);
        assert!(
            region("all").error.mean < 0.02,
            "{}: {:?}",
            r.chain,
            region("all")
        );
        assert!(
            region("face").error.mean < 0.05,
            "{}: {:?}",
            r.chain,
            region("face")
        );
        assert!(
            region("UV seams").error.mean < 0.05,
            "{}: {:?}",
            r.chain,
            region("UV seams")
        );
    }
    // The fold term (skin::fold) holds the same bounds and gives a finite
    // value everywhere; whether it helps depends on the resolution and the
    // light (docs/records/2026-11-29-fold-term.md: at 1024² in the default
    // scene it does, in this scene at 512² the upper lip is worse).
    let fold = &rows[2];
    assert!(fold.fold_correction && !rows[1].fold_correction);
    for g in &fold.regions {
        assert!(g.error.mean.is_finite(), "{}: {:?}", g.region, g.error);
    }
}

/// The reference convolves the light that enters the skin: the sky's light
/// through thin skin, which the chain adds to its irradiance as its stand-in
/// for a thin part's far side, is left out of it (the reference's chords
/// through the skin carry that light themselves), so its result is the same
/// with transmission on and off, while the chain's is not.
#[test]
fn the_exact_reference_leaves_out_the_chains_transmitted_light() {
    use dermis::fidelity::diffusion_gap::{run, DiffusionOptions};
    use dermis::scene::file::Chain;
    let read = |transmission: f32| {
        let mut scene = scene_by_name(None).unwrap();
        scene.render.irradiance_resolution = 256;
        (scene.render.width, scene.render.height) = (24, 30);
        scene.skin.transmission = transmission;
        let dir = std::env::temp_dir().join(format!(
            "dermis-entering-{}-{transmission}",
            std::process::id()
        ));
        let opts = DiffusionOptions {
            scene,
            chains: vec![(Chain::Full, false)],
            stride: 8,
            out_dir: Some(dir.clone()),
        };
        common::with_gpu(|ctx| run(ctx, &opts, |_| {}).unwrap());
        let file = |name: &str| std::fs::read(dir.join(name)).unwrap();
        let files = (file("reference.exr"), file("full.exr"));
        std::fs::remove_dir_all(&dir).unwrap();
        files
    };
    let (reference_on, chain_on) = read(1.0);
    let (reference_off, chain_off) = read(0.0);
    assert!(chain_on != chain_off, "transmission changed nothing");
    assert!(
        reference_on == reference_off,
        "the reference read the transmitted light"
    );
}

/// The nose's shadow on the cheek under one directional light (black
/// environment), `--view direct` against the CPU reference's shadow rays: the
/// visibility V = image / image without shadows on both sides, the mean offset
/// of the V = ½ line (positive: dermis's edge lies inside the reference's
/// shadow) and the width of the 10–90 % penumbra, in mm on the cheek, for a
/// hard light and one 3° across, at two shadow-map resolutions (docs/design/lighting.md,
/// "The nose's shadow edge"). Issue 22's target (within 0.25 mm, penumbra within
/// 25 %) is not met at the default 2048²; the assertions hold what a map of the
/// mesh's bounding sphere gives, that a finer map comes closer, and the soft
/// penumbra's width.
#[test]
fn nose_shadow_edge_against_the_reference() {
    use dermis::scene::env::EnvSource;
    use dermis::scene::file::{Light, LightKind, LightsMode};
    let (w, h) = (160, 160);
    let mut file = scene_by_name(None).unwrap();
    (file.render.width, file.render.height) = (w, h);
    file.render.skybox = false;
    // The soft lights' visibility is stored in UV space at half the irradiance
    // resolution (light::visibility): 2048 gives its finest, 1024² (~0.6 mm).
    file.render.irradiance_resolution = 2048;
    file.skin.occlusion = Occlusion::Off;
    file.environment.source = EnvSource::Uniform(glam::Vec3::ZERO);
    file.environment.lights = LightsMode::Count(0);
    // From the subject's left, a little above and in front: the nose shades the
    // right cheek beside it.
    file.lights = vec![Light {
        kind: LightKind::Directional,
        direction: Some([-0.85, -0.25, -0.45]),
        position: None,
        color: [1.0; 3],
        intensity: 1.0,
        shadow: true,
        angular_diameter_deg: 0.0,
    }];
    // 24 mm square on the cheek beside the nose, 300 mm away: 0.15 mm per pixel.
    file.camera.position = Some([-20.0, 45.0, 400.0]);
    file.camera.target = Some([-20.0, 45.0, 100.0]);
    file.camera.orbit = None;
    file.camera.fov_deg = 2.0 * (12.0f32 / 300.0).atan().to_degrees();
    let mm_per_pixel = 24.0 / h as f32;
    let settings = Settings {
        target_rel_err: 0.01,
        ..Settings::default()
    };
    let visibility = |lit: &[f32], unshadowed: &[f32]| -> Vec<Option<f32>> {
        let peak = unshadowed.chunks_exact(4).map(|p| p[0]).fold(0.0, f32::max);
        lit.chunks_exact(4)
            .zip(unshadowed.chunks_exact(4))
            .map(|(a, b)| (b[3] > 0.5 && b[0] > 0.05 * peak).then(|| (a[0] / b[0]).clamp(0.0, 1.0)))
            .collect()
    };
    let with = |diameter: f32, shadow: bool, focus: bool| {
        let mut f = file.clone();
        f.lights[0].angular_diameter_deg = diameter;
        f.lights[0].shadow = shadow;
        f.render.shadow_focus = focus;
        Scene::load(f).unwrap()
    };
    let mut results = Vec::new();
    for diameter in [0.0f32, 3.0] {
        let reference = |shadow| {
            render_view(&with(diameter, shadow, false), w, h, &settings)
                .unwrap()
                .rgba
        };
        let v_ref = visibility(&reference(true), &reference(false));
        let rows: Vec<[f32; 5]> = common::with_gpu(|ctx| {
            [false, true]
                .map(|focus| {
                    let render = |shadow| {
                        let opts = RenderOptions {
                            hdr: true,
                            view: View::named("direct"),
                            ..RenderOptions::default()
                        };
                        let scene = with(diameter, shadow, focus);
                        render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
                    };
                    let v = visibility(&render(true), &render(false));
                    let (offset, penumbra, penumbra_ref) = edge(&v, &v_ref, w as usize);
                    [diameter, f32::from(focus), offset, penumbra, penumbra_ref]
                })
                .map(|[d, f, o, p, q]| [d, f, o * mm_per_pixel, p * mm_per_pixel, q * mm_per_pixel])
                .to_vec()
        });
        results.extend(rows);
    }
    for [diameter, focus, offset, penumbra, penumbra_ref] in &results {
        let map = if *focus > 0.5 {
            "with its focus map"
        } else {
            "whole mesh only"
        };
        println!(
            "light {diameter}°, 2048² shadow map, {map}: edge {offset:+.3} mm into the \
             reference's shadow, penumbra {penumbra:.3} mm (reference {penumbra_ref:.3} mm)"
        );
    }
    for pair in results.chunks(2) {
        let (whole, focus) = (pair[0], pair[1]);
        // Issue 22's target: the edge within 0.25 mm of the reference's
        // (measured: +0.17 mm hard, +0.06 mm for 3°; the whole mesh's map
        // alone: +1.13 and +1.01 mm).
        assert!(focus[2].abs() <= 0.25, "{results:?}");
        assert!(focus[2].abs() < whole[2].abs(), "{results:?}");
    }
    // Issue 22's target for both lights, with the focus map: the penumbra
    // within 25 % of the reference's (measured: 3°, 1.52 mm of 1.60; hard,
    // 0.361 mm of 0.296, a pixel or two and the 3 × 3 mean: the filter follows
    // the pixel's footprint, and was 0.47 mm with its taps a texel apart).
    assert!(results[2][4] > results[0][4] + 0.5, "{results:?}");
    for focus in [results[1], results[3]] {
        assert!((focus[3] / focus[4] - 1.0).abs() <= 0.25, "{results:?}");
    }
}

/// (offset, penumbra, reference penumbra) in pixels per pixel of edge: the
/// signed area between the V = ½ lines (dermis lit where the reference is in
/// shadow counts positive) and the 10–90 % areas of V smoothed 3 × 3, each over
/// the reference edge's length (its V = ½ transitions between neighbouring
/// pixels).
fn edge(v: &[Option<f32>], v_ref: &[Option<f32>], w: usize) -> (f32, f32, f32) {
    let both: Vec<Option<(f32, f32)>> = v.iter().zip(v_ref).map(|(a, b)| a.zip(*b)).collect();
    let mut length = 0.0f32;
    for (i, p) in both.iter().enumerate() {
        let Some((_, r)) = p else { continue };
        let right = (i % w + 1 < w).then_some(i + 1);
        for j in right.into_iter().chain([i + w]) {
            if let Some(Some((_, s))) = both.get(j) {
                length += f32::from((*r > 0.5) != (*s > 0.5));
            }
        }
    }
    assert!(length > 20.0, "no shadow edge in view ({length} pixels)");
    // The penumbrae of both after a 3 × 3 mean, so that the soft shadows'
    // per-pixel noise (12 turned taps) does not count as penumbra.
    let smooth = |pick: fn((f32, f32)) -> f32| -> Vec<Option<f32>> {
        (0..both.len())
            .map(|i| {
                both[i]?;
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                let near: Vec<f32> = (-1..=1)
                    .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
                    .filter(|&(x, y)| x >= 0 && y >= 0 && x < w as i64)
                    .filter_map(|(x, y)| both.get(y as usize * w + x as usize).copied().flatten())
                    .map(pick)
                    .collect();
                Some(near.iter().sum::<f32>() / near.len() as f32)
            })
            .collect()
    };
    let band =
        |v: &[Option<f32>]| v.iter().flatten().filter(|&&v| v > 0.1 && v < 0.9).count() as f32;
    let offset: f32 = both
        .iter()
        .flatten()
        .map(|(a, r)| f32::from(*a > 0.5 && *r <= 0.5) - f32::from(*a <= 0.5 && *r > 0.5))
        .sum();
    (
        offset / length,
        band(&smooth(|p| p.0)) / length,
        band(&smooth(|p| p.1)) / length,
    )
}
