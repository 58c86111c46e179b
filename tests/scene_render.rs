//! Scenes render as users run them: the built-in head and the Lee Perry-Smith
//! scan produce a sane image (the head covers the middle of the frame, nothing is
//! NaN or black), and EXR output is the linear image behind the PNG.

mod common;

use dermis::render::{render_scene, RenderOptions, RenderOutput};
use dermis::scene::file::{load_scene, SceneFile};
use dermis::scene::Scene;
use std::path::{Path, PathBuf};

const SIZE: u32 = 128;

fn assets() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/assets");
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("skipped: {} is absent", dir.display());
        None
    }
}

/// Renders `file` under a uniform grey environment, so that every pixel that
/// differs from the background belongs to the mesh.
fn render(mut file: SceneFile) -> RenderOutput {
    file.environment.source = "uniform:0.5,0.5,0.5".into();
    file.render.width = SIZE;
    file.render.height = SIZE;
    file.render.exposure = Some(0.0);
    file.render.irradiance_resolution = 512;
    common::with_gpu(|ctx| {
        let scene = Scene::load(file).unwrap();
        let opts = RenderOptions {
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    })
}

struct Coverage {
    fraction: f32,
    centroid: (f32, f32),
    mean_mesh_luma: f32,
}

fn coverage(out: &RenderOutput) -> Coverage {
    let hdr = out.hdr.as_ref().unwrap();
    assert!(hdr.iter().all(|v| v.is_finite()), "NaN or Inf in the image");
    let (w, h) = (out.width as usize, out.height as usize);
    let (mut n, mut sx, mut sy, mut luma) = (0usize, 0.0, 0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let p = &hdr[(y * w + x) * 4..][..3];
            // The background is exactly the environment radiance, 0.5.
            if p.iter().any(|c| (c - 0.5).abs() > 1e-3) {
                n += 1;
                sx += x as f32;
                sy += y as f32;
                luma += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            }
        }
    }
    let n = n.max(1);
    Coverage {
        fraction: n as f32 / (w * h) as f32,
        centroid: (sx / n as f32 / w as f32, sy / n as f32 / h as f32),
        mean_mesh_luma: luma / n as f32,
    }
}

fn assert_sane(c: &Coverage, what: &str) {
    println!(
        "{what}: coverage {:.2}, centroid ({:.2}, {:.2}), mean luminance {:.3}",
        c.fraction, c.centroid.0, c.centroid.1, c.mean_mesh_luma
    );
    assert!(
        (0.15..0.85).contains(&c.fraction),
        "{what}: coverage {}",
        c.fraction
    );
    assert!(
        (c.centroid.0 - 0.5).abs() < 0.15,
        "{what}: centroid {:?}",
        c.centroid
    );
    assert!(
        (c.centroid.1 - 0.5).abs() < 0.2,
        "{what}: centroid {:?}",
        c.centroid
    );
    // Albedo ~0.3-0.6 under a uniform radiance of 0.5: the mesh is lit, not black.
    assert!(
        c.mean_mesh_luma > 0.05,
        "{what}: too dark: {}",
        c.mean_mesh_luma
    );
}

#[test]
fn builtin_head_renders_in_the_middle_of_the_frame() {
    let out = render(SceneFile::default());
    assert_sane(&coverage(&out), "built-in head");
}

#[test]
fn lee_perry_smith_scan_renders() {
    let Some(_) = assets() else { return };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes/lee-perry-smith.toml");
    let out = render(load_scene(&path).unwrap());
    assert_sane(&coverage(&out), "Lee Perry-Smith");
}

#[test]
fn exr_is_the_linear_image_behind_the_png() {
    let out = render(SceneFile::default());
    let hdr = out.hdr.as_ref().unwrap();
    let srgb = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        if c <= 0.0031308 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let worst = hdr
        .chunks_exact(4)
        .zip(out.rgba8.chunks_exact(4))
        .flat_map(|(h, l)| (0..3).map(move |c| (srgb(h[c]) * 255.0 - l[c] as f32).abs()))
        .fold(0.0f32, f32::max);
    // One 8-bit step of rounding plus f16 storage of the HDR target.
    assert!(worst <= 1.5, "PNG and EXR disagree by {worst} / 255");
    let path = std::env::temp_dir().join(format!("dermis-{}.exr", std::process::id()));
    dermis::output::write(&path, &out).unwrap();
    let read = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |res, _| vec![0.0f32; res.width() * res.height() * 4],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            let i = (pos.y() * SIZE as usize + pos.x()) * 4;
            px[i..i + 4].copy_from_slice(&[r, g, b, a]);
        },
    )
    .unwrap();
    assert_eq!(read.layer_data.channel_data.pixels, *hdr);
}
