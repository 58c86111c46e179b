//! Every view of `dermis render --view`, the debug sheet and the occlusion
//! comparison render at a small size under validation (no message) on the
//! built-in head (it has a region map), and none is constant: each shows a
//! quantity that varies over the head.

use crate::common;

use dermis::post::debug::DebugView;
use dermis::render::sheet::{COLUMNS, TILE};
use dermis::render::{
    compare_occlusion, debug_sheet, render_scene, sheet_views, views, RenderOptions, Screen, View,
};
use dermis::scene::file::SceneFile;
use dermis::scene::Scene;
use dermis::skin::shade::ShadeMode;

const SIZE: (u32, u32) = (96, 120);

fn scene() -> Scene {
    let mut file = SceneFile::default();
    file.render.width = SIZE.0;
    file.render.height = SIZE.1;
    file.render.irradiance_resolution = 256;
    Scene::load(file).unwrap()
}

/// The fewest distinct colours a view of the head must show: the region ids
/// are ten colours and the background; the light through thin skin lies on a
/// few pixels only (the far sides of thin parts: docs/records/2026-11-26-transmission.md, "Only from a far
/// side"), so it must only not be blank; the rest vary smoothly.
fn least_colours(view: &View) -> usize {
    match view {
        View::Screen(Screen::Skin(ShadeMode::Transmission)) => 3,
        View::Screen(Screen::Debug(DebugView::Regions)) => 5,
        _ => 32,
    }
}

/// Distinct RGB colours of an RGBA8 image.
fn colours(rgba8: &[u8]) -> usize {
    let mut c: Vec<[u8; 3]> = rgba8.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).collect();
    c.sort_unstable();
    c.dedup();
    c.len()
}

#[test]
fn the_view_list_names_every_screen_view_and_the_papers_intermediates() {
    let scene = scene();
    let names = common::with_gpu(|ctx| views(ctx, &scene).unwrap());
    let wanted = Screen::all()
        .map(|s| s.name().to_string())
        .chain(["irradiance", "prefiltered", "hdr"].map(String::from))
        .chain((0..6).map(dermis::skin::stretch::level_name))
        .chain((1..=6).map(dermis::skin::blur::BlurChain::level_name));
    for name in wanted {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "{names:?}");
}

#[test]
fn every_view_renders_and_shows_something() {
    let scene = scene();
    common::with_gpu(|ctx| {
        // The reference is the CPU's (tests/it/reference_gpu.rs, light::reference).
        let names = views(ctx, &scene).unwrap();
        for view in names.iter().map(|n| View::named(n)) {
            if view == View::Screen(Screen::Reference) {
                continue;
            }
            let opts = RenderOptions {
                view: view.clone(),
                ..RenderOptions::default()
            };
            let out = render_scene(ctx, &scene, &opts).unwrap();
            let n = colours(&out.rgba8);
            println!(
                "{:>12}: {}×{}, {n} colours, exposure {:+.2} EV",
                view.name(),
                out.width,
                out.height,
                out.exposure
            );
            assert_eq!(out.rgba8.len(), (out.width * out.height * 4) as usize);
            if !view.uv_space() {
                assert_eq!((out.width, out.height), SIZE, "{}", view.name());
            }
            assert!(n >= least_colours(&view), "{}: {n} colours", view.name());
        }
    });
}

#[test]
fn the_debug_sheet_and_the_occlusion_comparison_are_labelled_images_of_their_views() {
    let scene = scene();
    let (sheet, comparison) = common::with_gpu(|ctx| {
        let opts = RenderOptions::default();
        (
            debug_sheet(ctx, &scene, &opts).unwrap(),
            compare_occlusion(ctx, &scene, &opts).unwrap(),
        )
    });
    let sheet_views = sheet_views();
    let rows = sheet_views.len().div_ceil(COLUMNS) as u32;
    assert_eq!(sheet.width, COLUMNS as u32 * TILE.0);
    assert!(sheet.height > rows * TILE.1 && sheet.height < rows * (TILE.1 + 40));
    // Every tile shows its view: many colours inside each tile.
    let cell_h = sheet.height / rows;
    for (i, view) in sheet_views.iter().enumerate() {
        let (x0, y0) = ((i % COLUMNS) as u32 * TILE.0, (i / COLUMNS) as u32 * cell_h);
        let tile: Vec<u8> = (y0..y0 + TILE.1)
            .flat_map(|y| {
                let start = ((y * sheet.width + x0) * 4) as usize;
                sheet.rgba8[start..start + (TILE.0 * 4) as usize].to_vec()
            })
            .collect();
        let n = colours(&tile);
        assert!(n >= least_colours(view), "{}: {n} colours", view.name());
    }
    // Side by side at the view's size, labels below; occlusion darkens the
    // concavities, so the halves differ.
    assert_eq!(comparison.width, 2 * SIZE.0);
    assert!(comparison.height > SIZE.1);
    let half = |left: bool| -> Vec<u8> {
        (0..SIZE.1)
            .flat_map(|y| {
                let x = if left { 0 } else { SIZE.0 };
                let start = ((y * comparison.width + x) * 4) as usize;
                comparison.rgba8[start..start + (SIZE.0 * 4) as usize].to_vec()
            })
            .collect()
    };
    let (on, off) = (half(true), half(false));
    let differ = on
        .chunks_exact(4)
        .zip(off.chunks_exact(4))
        .filter(|(a, b)| a != b)
        .count();
    println!(
        "sheet {}×{}, comparison {}×{}: {differ} pixels differ",
        sheet.width, sheet.height, comparison.width, comparison.height
    );
    assert!(differ > (SIZE.0 * SIZE.1 / 20) as usize, "{differ}");
    // The labels are drawn: light text in the strip under the first tile.
    let strip = (TILE.1..cell_h).flat_map(|y| {
        let start = ((y * sheet.width) * 4) as usize;
        sheet.rgba8[start..start + (TILE.0 * 4) as usize].to_vec()
    });
    assert!(strip
        .collect::<Vec<u8>>()
        .chunks_exact(4)
        .any(|p| p[0] > 200));
}

/// The sky is drawn behind the shaded images only: a term's view (diffuse,
/// specular, the light through thin skin) or a fraction (occlusion) shows the
/// term alone, so its exposure, metered on the term, cannot blow the sky out.
#[test]
fn the_sky_is_behind_the_shaded_views_only() {
    let scene = scene();
    assert!(
        scene.file.render.skybox,
        "the test needs a scene with its sky on"
    );
    let outs = common::with_gpu(|ctx| {
        [
            "final",
            "direct",
            "diffuse",
            "specular",
            "transmission",
            "occlusion",
        ]
        .map(|name| {
            let opts = RenderOptions {
                view: View::named(name),
                hdr: true,
                ..RenderOptions::default()
            };
            (name, render_scene(ctx, &scene, &opts).unwrap())
        })
    });
    for (name, out) in outs {
        let hdr = out.hdr.as_ref().unwrap();
        // Uncovered pixels (alpha 0) and the brightest of them.
        let sky = hdr
            .chunks_exact(4)
            .filter(|p| p[3] == 0.0)
            .map(|p| p[0].max(p[1]).max(p[2]))
            .collect::<Vec<f32>>();
        let brightest = sky.iter().fold(0.0f32, |a, &b| a.max(b));
        println!(
            "{name:>12}: {} uncovered pixels, brightest {brightest}",
            sky.len()
        );
        assert!(
            sky.len() > (SIZE.0 * SIZE.1 / 10) as usize,
            "{name}: {}",
            sky.len()
        );
        if matches!(name, "final" | "direct") {
            assert!(brightest > 0.0, "{name}: no sky");
        } else {
            assert_eq!(brightest, 0.0, "{name}: the sky is drawn behind a term");
        }
    }
}

/// Texels of an `n`² grid whose centre lies in a UV triangle of `mesh`, with
/// row 0 at v = 1 (`authored`: the orientation of a bottom-left map's image)
/// or at v = 0.
fn uv_coverage(mesh: &dermis::scene::mesh::Mesh, n: usize, authored: bool) -> Vec<bool> {
    let mut covered = vec![false; n * n];
    for t in mesh.indices.chunks_exact(3) {
        let p: Vec<glam::Vec2> = t
            .iter()
            .map(|&i| {
                let uv = mesh.uvs[i as usize];
                let v = if authored { 1.0 - uv.y } else { uv.y };
                glam::Vec2::new(uv.x, v) * n as f32
            })
            .collect();
        let edge = |a: glam::Vec2, b: glam::Vec2, q: glam::Vec2| (b - a).perp_dot(q - a);
        let area = edge(p[0], p[1], p[2]);
        if area == 0.0 {
            continue;
        }
        let lo = p[0].min(p[1]).min(p[2]).floor().max(glam::Vec2::ZERO);
        let hi = p[0]
            .max(p[1])
            .max(p[2])
            .ceil()
            .min(glam::Vec2::splat(n as f32));
        for y in lo.y as usize..hi.y as usize {
            for x in lo.x as usize..hi.x as usize {
                let q = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = [
                    edge(p[1], p[2], q),
                    edge(p[2], p[0], q),
                    edge(p[0], p[1], q),
                ];
                if w.iter().all(|&w| w * area >= 0.0) {
                    covered[y * n + x] = true;
                }
            }
        }
    }
    covered
}

#[test]
fn uv_views_are_written_as_the_scans_maps_are_authored() {
    // The scan's maps have their UV origin at the bottom left: its irradiance
    // texture is written with v = 1 in the top row, as its painted maps are.
    let mut file =
        dermis::scene::file::load_scene(std::path::Path::new("assets/default.toml")).unwrap();
    file.render.irradiance_resolution = 256;
    (file.render.width, file.render.height) = SIZE;
    let scene = Scene::load(file).unwrap();
    let out = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            view: View::named("irradiance"),
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    });
    assert_eq!((out.width, out.height), (256, 256));
    let alpha: Vec<bool> = out
        .hdr
        .unwrap()
        .chunks_exact(4)
        .map(|p| p[3] > 0.5)
        .collect();
    let agree = |authored: bool| {
        let cpu = uv_coverage(&scene.mesh, 256, authored);
        cpu.iter().zip(&alpha).filter(|(a, b)| a == b).count() as f64 / alpha.len() as f64
    };
    let (authored, stored) = (agree(true), agree(false));
    println!("coverage agrees with the UVs at v = 1 on top: {authored:.4}, at v = 0: {stored:.4}");
    // The layout is near symmetric top to bottom: upside down, 9 % of texels differ.
    assert!(authored > 0.995 && stored < 0.95, "{authored} {stored}");
}

/// The passes a view's frame ran (its first frame: what it keeps included).
fn passes(ctx: &std::sync::Arc<dermis::gpu::Context>, scene: &Scene, view: &str) -> Vec<String> {
    let opts = RenderOptions {
        view: View::named(view),
        ..RenderOptions::default()
    };
    let out = render_scene(ctx, scene, &opts).unwrap();
    let frame = &out.report.per_frame[0];
    frame.passes.iter().map(|p| p.name.clone()).collect()
}

#[test]
fn each_view_runs_only_the_passes_it_depends_on() {
    let scene = scene();
    common::with_gpu(|ctx| {
        let has = |passes: &[String], name: &str| passes.iter().any(|p| p == name);
        let chain = |passes: &[String]| {
            passes
                .iter()
                .filter(|p| p.starts_with("blur") || p.starts_with("stretch"))
                .count()
        };
        let all = passes(ctx, &scene, "final");
        for name in [
            "sh_project",
            "shadow maps",
            "stretch",
            "irradiance",
            "env_prefilter",
        ] {
            assert!(has(&all, name), "final lacks {name}: {all:?}");
        }
        for name in ["skin", "tonemap", "readback"] {
            assert!(has(&all, name), "final lacks {name}: {all:?}");
        }
        assert!(chain(&all) >= 12, "{all:?}");

        let irradiance = passes(ctx, &scene, "irradiance");
        assert_eq!(chain(&irradiance), 0, "{irradiance:?}");
        assert!(has(&irradiance, "irradiance") && has(&irradiance, "sh_project"));
        for name in ["env_prefilter", "skin", "tonemap", "background"] {
            assert!(
                !has(&irradiance, name),
                "irradiance ran {name}: {irradiance:?}"
            );
        }

        let stretch = passes(ctx, &scene, "stretch3");
        assert!(
            has(&stretch, "stretch") && has(&stretch, "stretch3_v"),
            "{stretch:?}"
        );
        for name in ["stretch4_u", "irradiance", "sh_project", "shadow maps"] {
            assert!(!has(&stretch, name), "stretch3 ran {name}: {stretch:?}");
        }

        let depth = passes(ctx, &scene, "depth");
        assert!(has(&depth, "debug_view"), "{depth:?}");
        for name in [
            "sh_project",
            "shadow maps",
            "light_visibility",
            "irradiance",
        ] {
            assert!(!has(&depth, name), "depth ran {name}: {depth:?}");
        }
        assert_eq!(chain(&depth), 0);

        let prefiltered = passes(ctx, &scene, "prefiltered");
        assert_eq!(prefiltered, ["env_prefilter", "readback"]);
    });
}

#[test]
fn the_chain_passes_carry_the_diffusion_tag() {
    let scene = scene();
    let out = common::with_gpu(|ctx| render_scene(ctx, &scene, &RenderOptions::default()).unwrap());
    for p in &out.report.per_frame[0].passes {
        let chain = p.name.starts_with("blur") || p.name.starts_with("stretch");
        let tagged = p.tags.iter().any(|t| t == dermis::skin::TAG);
        assert_eq!(chain, tagged, "{}: {:?}", p.name, p.tags);
    }
}
