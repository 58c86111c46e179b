//! Post-processing against independent references: the glow of a single bright
//! pixel against d'Eon & Luebke's two-Gaussian profile (post::glow::kernel,
//! evaluated analytically), and the frame's metering of the lit scan against
//! the CPU's log-average (post::meter::exposure) and the key it must meet.

use crate::common;

use dermis::gpu::{ImageDesc, Pipelines, Sampler};
use dermis::graph::upload::{upload_texture, Readback};
use dermis::graph::{Access, Executor, Graph, Imported};
use dermis::post::glow::{kernel, Glow};
use dermis::post::meter::{self, KEY};
use dermis::render::{render_scene, RenderOptions};
use dermis::scene::file::load_scene;
use dermis::scene::texture::LUMINANCE;
use dermis::scene::Scene;
use std::path::Path;
use std::sync::Arc;

#[test]
fn the_glow_of_one_bright_pixel_is_the_two_gaussian_profile() {
    // 160 × 160: the narrow Gaussian is blurred at mip level 1 (σ 7.1 texels),
    // the wide one at level 3 (σ 4.8); the pixel is not on either level's grid.
    let (w, h) = (160u32, 160u32);
    let (cx, cy) = (81usize, 78usize);
    // Exactly representable in f16; the halo's peak is then ≈ 1.7.
    let p = 49152.0f32;
    let mut texels = vec![0.0f32; (w * h * 4) as usize];
    texels[(cy * w as usize + cx) * 4..][..4].copy_from_slice(&[p, p, p, 1.0]);
    let intensity = 1.0;
    let out = common::with_gpu(|ctx| {
        let desc = ImageDesc::new(w, h, dermis::testscene::HALF);
        let src = upload_texture(ctx, "impulse", desc, &common::to_f16_bytes(&texels)).unwrap();
        let glow = Glow::new(
            &Pipelines::new(ctx),
            Arc::new(Sampler::clamped(ctx, false).unwrap()),
            Arc::new(Sampler::clamped(ctx, true).unwrap()),
        )
        .unwrap();
        let readback = Readback::new(ctx, "glowed", (w * h * 8) as u64).unwrap();
        let mut g = Graph::new();
        let hdr = g.import_image(
            "impulse",
            Imported::Image(src),
            Some(Access::ShaderSampled),
            None,
        );
        let glowed = glow.pass(&mut g, &hdr, intensity);
        readback.image_pass(&mut g, &glowed);
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.run(g).unwrap();
        ex.finish().unwrap();
        common::from_f16_bytes(readback.bytes().unwrap())
    });
    // The kernel is per image height²: r in image heights, one pixel 1/h² of area.
    let expected = |r_px: f32| intensity * p * kernel(r_px / h as f32) / (h * h) as f32;
    let peak = expected(0.0);
    // Radial bins of one pixel: mean of the halo against the mean of the
    // profile over the same pixels (the centre pixel holds the impulse).
    let bins = 115;
    let (mut got, mut want, mut n) = (vec![0.0f64; bins], vec![0.0f64; bins], vec![0u32; bins]);
    let mut worst_pixel = 0.0f32;
    for y in 0..h as usize {
        for x in 0..w as usize {
            let r = ((x as f32 - cx as f32).powi(2) + (y as f32 - cy as f32).powi(2)).sqrt();
            let b = r.round() as usize;
            if b == 0 || b >= bins {
                continue;
            }
            let halo = out[(y * w as usize + x) * 4 + 1];
            worst_pixel = worst_pixel.max((halo - expected(r)).abs() / peak);
            got[b] += halo as f64;
            want[b] += expected(r) as f64;
            n[b] += 1;
        }
    }
    let mut worst_bin = (0.0f64, 0);
    for b in 1..bins {
        let e = (got[b] - want[b]).abs() / n[b] as f64 / peak as f64;
        if e > worst_bin.0 {
            worst_bin = (e, b);
        }
    }
    println!(
        "glow of one pixel at {w}×{h}: radial profile within {:.2} % of the peak (worst at r = {} px) \
         over r = 1…{} px (0.006–0.71 image heights); single pixels within {:.2} %",
        100.0 * worst_bin.0,
        worst_bin.1,
        bins - 1,
        100.0 * worst_pixel
    );
    assert!(worst_bin.0 < 0.02, "{worst_bin:?}");
    // Alpha (coverage) is kept: 1 at the pixel, 0 elsewhere.
    assert_eq!(out[(cy * w as usize + cx) * 4 + 3], 1.0);
    assert_eq!(out[3], 0.0);
}

#[test]
fn metering_exposes_the_lit_scan_to_the_key() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes/lee-perry-smith-lights.toml");
    let mut file = load_scene(&path).unwrap();
    file.render.width = 96;
    file.render.height = 120;
    file.render.irradiance_resolution = 256;
    assert_eq!(file.render.exposure, None, "the scene is metered");
    let scene = Scene::load(file).unwrap();
    let out = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    });
    let gpu = out.metered.expect("metered on the GPU");
    let hdr = out.hdr.as_ref().unwrap();
    let cpu = meter::exposure(hdr);
    println!("lit scan: GPU {gpu:?}, CPU {cpu:?}");
    assert_eq!(gpu.pixels, cpu.pixels);
    assert!(gpu.pixels > 96 * 120 / 10, "{gpu:?}");
    assert!((gpu.ev - cpu.ev).abs() < 1e-3, "GPU {gpu:?} vs CPU {cpu:?}");
    assert_eq!(out.exposure, gpu.ev);
    assert_eq!(out.report.setup.exposure_ev, gpu.ev);
    assert!(out.report.setup.exposure_metered);
    // The skin's log-average luminance after exposure is the key.
    let (mut sum, mut count) = (0.0f64, 0);
    let scale = out.exposure.exp2();
    for p in hdr.chunks_exact(4).filter(|p| p[3] > 0.5) {
        let l = glam::Vec3::from_slice(&p[..3]).dot(LUMINANCE);
        sum += f64::from(l * scale).max(1e-9).ln();
        count += 1;
    }
    let exposed = (sum / count as f64).exp() as f32;
    // Well exposed: few of the mesh's pixels clip in the 8-bit image.
    let clipped = out
        .rgba8
        .chunks_exact(4)
        .zip(hdr.chunks_exact(4))
        .filter(|(l, h)| h[3] > 0.5 && l[..3].contains(&255))
        .count();
    println!(
        "exposed log-average {exposed:.4} (key {KEY}), {:.2} % of mesh pixels clipped at {:+.2} EV",
        100.0 * clipped as f32 / count as f32,
        out.exposure
    );
    assert!((exposed / KEY - 1.0).abs() < 0.03, "{exposed}");
    assert!(clipped * 20 < count, "{clipped} of {count}");
}
