//! Texture-space diffusion against analytic Gaussians (d'Eon & Luebke, GPU Gems 3
//! §14.4; the paper's eq. 2-5): the real stretch pass and blur chain on flat
//! planes whose UV scale is known, fed with chosen irradiance.

use crate::common;

use dermis::frame_inputs::MeshBuffers;
use dermis::gpu::{Context, ImageDesc, Pipelines, Sampler};
use dermis::graph::upload::upload_texture;
use dermis::graph::upload::Readback;
use dermis::graph::{Access, Executor, Graph, Imported};
use dermis::scene::file::Chain;
use dermis::scene::mesh::Mesh;
use dermis::scene::texture::LUMINANCE;
use dermis::skin::blur::{BlurChain, BlurKernel};
use dermis::skin::chain::{self, Stencil};
use dermis::skin::profile::{gaussian, Kernel, Profile};
use dermis::skin::stretch::StretchMaps;
use dermis::skin::{mean_stretch, UV_FORMAT};
use glam::{Vec2, Vec3, Vec4};
use std::sync::Arc;

const N: u32 = 512;

/// A plane of `lx` × `ly` mm in the XY plane whose UVs cover `[u0, u1]²`.
fn plane(lx: f32, ly: f32, u0: f32, u1: f32) -> Mesh {
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    Mesh {
        name: "plane".into(),
        positions: corners
            .iter()
            .map(|&(s, t)| Vec3::new(s * lx, t * ly, 0.0))
            .collect(),
        normals: vec![Vec3::Z; 4],
        uvs: corners
            .iter()
            .map(|&(s, t)| Vec2::new(u0 + s * (u1 - u0), u0 + t * (u1 - u0)))
            .collect(),
        tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

fn accurate() -> BlurKernel {
    BlurKernel::Accurate
}

/// Runs the stretch maps + the six-level chain (`full` or `adaptive`) on `input`
/// (N×N RGBA, alpha = coverage); returns each level sampled bilinearly at the N×N
/// texel centres, as the final pass reads it, and normalised by its coverage.
fn chain_with(
    mesh: &Mesh,
    input: &[[f32; 4]],
    kernel: &BlurKernel,
    correction: bool,
    variant: Chain,
) -> Vec<Vec<Vec3>> {
    common::with_gpu(|ctx: &Arc<Context>| {
        let texels: Vec<f32> = input.iter().flatten().copied().collect();
        let bytes = common::to_f16_bytes(&texels);
        let irr = upload_texture(ctx, "input", ImageDesc::new(N, N, UV_FORMAT), &bytes).unwrap();
        let buffers = Arc::new(MeshBuffers::upload(ctx, mesh).unwrap());
        let profile = Profile::skin();
        let constant = (!correction).then(|| mean_stretch(mesh, N));
        let pipelines = Pipelines::new(ctx);
        let stretch = StretchMaps::new(&pipelines, N, &profile, constant, true).unwrap();
        let sampler = Arc::new(Sampler::clamped(ctx, true).unwrap());
        let blur = BlurChain::new(&pipelines, kernel, sampler, true).unwrap();
        let plan = chain::plan(&profile, variant, N, mean_stretch(mesh, N));
        let readbacks: Vec<Readback> = plan
            .iter()
            .map(|l| Readback::new(ctx, "level", (l.resolution.pow(2) * 8) as u64).unwrap())
            .collect();
        let mut g = Graph::new();
        let input = g.import_image(
            "input",
            Imported::Image(irr.clone()),
            Some(Access::ShaderSampled),
            None,
        );
        let st = stretch.pass(&mut g, &buffers, &blur);
        let blurred = blur.chain(&mut g, &input, &st, &plan, None);
        let levels = BlurChain::select(&input, &blurred, &plan);
        for (level, buf) in levels.iter().zip(&readbacks) {
            buf.image_pass(&mut g, level);
        }
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.run(g).unwrap();
        ex.finish().unwrap();
        readbacks
            .iter()
            .zip(&plan)
            .map(|(b, l)| {
                let level = common::from_f16_bytes(b.bytes().unwrap());
                bilinear(&level, l.resolution)
            })
            .collect()
    })
}

fn chain(mesh: &Mesh, input: &[[f32; 4]], kernel: &BlurKernel, correction: bool) -> Vec<Vec<Vec3>> {
    chain_with(mesh, input, kernel, correction, Chain::Full)
}

/// An RGBA level of `side`² sampled bilinearly (clamp to edge) at the centres of
/// N×N texels, then divided by its coverage.
fn bilinear(level: &[f32], side: u32) -> Vec<Vec3> {
    let at = |x: i64, y: i64| {
        let c = |t: i64| t.clamp(0, side as i64 - 1) as usize;
        let i = 4 * (c(y) * side as usize + c(x));
        Vec4::from_slice(&level[i..i + 4])
    };
    (0..N * N)
        .map(|i| {
            let scale = side as f32 / N as f32;
            let fx = ((i % N) as f32 + 0.5) * scale - 0.5;
            let fy = ((i / N) as f32 + 0.5) * scale - 0.5;
            let (x0, y0) = (fx.floor(), fy.floor());
            let (tx, ty) = (fx - x0, fy - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let p = (at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx) * (1.0 - ty)
                + (at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
            if p.w > 1e-4 {
                p.truncate() / p.w
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Σ w_i · level_i with the skin profile's RGB weights (the paper's Fig. 2).
fn combine(levels: &[Vec<Vec3>]) -> Vec<Vec3> {
    let profile = Profile::skin();
    (0..levels[0].len())
        .map(|i| {
            profile
                .gaussians
                .iter()
                .zip(levels)
                .map(|(g, l)| g.weights * l[i])
                .sum()
        })
        .collect()
}

fn impulse(value: f32) -> Vec<[f32; 4]> {
    let mut input = vec![[0.0, 0.0, 0.0, 1.0]; (N * N) as usize];
    input[(N / 2 * N + N / 2) as usize] = [value, value, value, 1.0];
    input
}

/// Max |GPU − analytic| along the row through the impulse, r ∈ [0, 3σ6], as a
/// fraction of the analytic peak, per channel.
fn profile_error(kernel: &BlurKernel, variant: Chain) -> Vec3 {
    let l = 18.0; // mm: 3σ6 = 8.2 mm fits in the half-width, σ1 = 2.3 texels
    let a = l / N as f32; // mm per texel
    let p = 100.0;
    let out = combine(&chain_with(
        &plane(l, l, 0.0, 1.0),
        &impulse(p),
        kernel,
        true,
        variant,
    ));
    let profile = Profile::skin();
    // The texture holds point samples: a unit sample of flux p·a² convolved with
    // the profile is the profile itself, sampled at texel centres.
    let reference = |r: f32| -> Vec3 {
        profile
            .gaussians
            .iter()
            .map(|g| g.weights * gaussian(g.variance_mm2, r))
            .sum::<Vec3>()
            * p
            * a
            * a
    };
    let peak = reference(0.0);
    let sigma6 = profile.gaussians[5].variance_mm2.sqrt();
    let row = (N / 2 * N) as usize;
    let mut worst = Vec3::ZERO;
    for dx in 0..=((3.0 * sigma6 / a) as usize) {
        let got = out[row + (N / 2) as usize + dx];
        let err = (got - reference(dx as f32 * a)).abs() / peak;
        worst = worst.max(err);
    }
    worst
}

#[test]
fn impulse_response_matches_the_sum_of_gaussians() {
    let accurate = profile_error(&accurate(), Chain::Full);
    let deon7 = profile_error(&BlurKernel::Fixed(Kernel::deon7()), Chain::Full);
    let adaptive = profile_error(&BlurKernel::Accurate, Chain::Adaptive);
    println!(
        "max error / peak over r in [0, 3σ6]: accurate kernel {accurate:.4}, d'Eon 7-tap \
         {deon7:.4}, accurate kernel on the adaptive chain {adaptive:.4}"
    );
    assert!(accurate.max_element() < 0.02, "accurate kernel: {accurate}");
    // The adaptive chain (levels down to 64² here) keeps the same bound.
    assert!(adaptive.max_element() < 0.02, "adaptive chain: {adaptive}");
}

/// World-space standard deviation (mm) of `values` along x and y.
fn widths(values: &[f32], mm_per_texel: Vec2) -> Vec2 {
    let (mut w, mut sx, mut sy) = (0.0f64, 0.0f64, 0.0f64);
    for (i, &v) in values.iter().enumerate() {
        let x = ((i as u32 % N) as f32 - (N / 2) as f32) * mm_per_texel.x;
        let y = ((i as u32 / N) as f32 - (N / 2) as f32) * mm_per_texel.y;
        w += v as f64;
        sx += (v * x * x) as f64;
        sy += (v * y * y) as f64;
    }
    Vec2::new((sx / w).sqrt() as f32, (sy / w).sqrt() as f32)
}

#[test]
fn stretch_correction_makes_stretched_uvs_isotropic() {
    // 18 × 36 mm mapped to the square: v texels are twice as long as u texels.
    let mesh = plane(18.0, 36.0, 0.0, 1.0);
    let texel = Vec2::new(18.0, 36.0) / N as f32;
    let green = |levels: Vec<Vec<Vec3>>| combine(&levels).iter().map(|c| c.y).collect::<Vec<f32>>();
    let on = widths(
        &green(chain(&mesh, &impulse(100.0), &accurate(), true)),
        texel,
    );
    let off = widths(
        &green(chain(&mesh, &impulse(100.0), &accurate(), false)),
        texel,
    );
    println!("world-space widths (mm): correction on {on}, off {off}");
    let ratio = |w: Vec2| w.y / w.x;
    assert!((ratio(on) - 1.0).abs() < 0.05, "on: {on}");
    assert!(ratio(off) > 1.3, "off should be anisotropic: {off}");
}

/// A plane whose UVs are an affine shear of its positions: u runs along x and v
/// along (cos φ, sin φ), each `l` mm across the UV square, so the surface
/// directions of u and v meet at φ (cos φ = `cos`). Returns the mesh and the
/// map from UV texels to surface mm, as the two columns ∂P/∂u, ∂P/∂v.
fn sheared_plane(l: f32, cos: f32) -> (Mesh, [Vec2; 2]) {
    let sin = (1.0 - cos * cos).sqrt();
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let at = |u: f32, v: f32| Vec3::new(l * (u + cos * v), l * sin * v, 0.0);
    let mesh = Mesh {
        name: "sheared plane".into(),
        positions: corners.iter().map(|&(u, v)| at(u, v)).collect(),
        normals: vec![Vec3::Z; 4],
        uvs: corners.iter().map(|&(u, v)| Vec2::new(u, v)).collect(),
        tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let texel = l / N as f32;
    (
        mesh,
        [Vec2::new(texel, 0.0), Vec2::new(texel * cos, texel * sin)],
    )
}

/// One Gaussian of σ mm (the accurate kernel, taps spaced by the unblurred
/// stretch map; `one_pass`: the one-pass blur of a narrow Gaussian over that
/// stencil) on `input` into `side`² (N or N/2); the result sampled bilinearly
/// at N² and divided by its coverage.
fn one_gaussian(
    mesh: &Mesh,
    input: &[[f32; 4]],
    sigma_mm: f32,
    shear: bool,
    one_pass: Option<Stencil>,
    side: u32,
) -> Vec<Vec3> {
    common::with_gpu(|ctx: &Arc<Context>| {
        let texels: Vec<f32> = input.iter().flatten().copied().collect();
        let bytes = common::to_f16_bytes(&texels);
        let irr = upload_texture(ctx, "input", ImageDesc::new(N, N, UV_FORMAT), &bytes).unwrap();
        let buffers = Arc::new(MeshBuffers::upload(ctx, mesh).unwrap());
        let pipelines = Pipelines::new(ctx);
        let stretch = StretchMaps::new(&pipelines, N, &Profile::skin(), None, shear).unwrap();
        let sampler = Arc::new(Sampler::clamped(ctx, true).unwrap());
        let blur = BlurChain::new(&pipelines, &accurate(), sampler, shear).unwrap();
        let readback = Readback::new(ctx, "blurred", (side * side * 8) as u64).unwrap();
        let mut g = Graph::new();
        let input = g.import_image(
            "input",
            Imported::Image(irr.clone()),
            Some(Access::ShaderSampled),
            None,
        );
        let st = stretch.pass(&mut g, &buffers, &blur);
        let mut dst = g.create_image("blurred", ImageDesc::new(side, side, UV_FORMAT));
        if let Some(stencil) = one_pass {
            blur.narrow(
                &mut g,
                "blurred",
                (&input, &st[0]),
                sigma_mm,
                stencil,
                &mut dst,
            );
        } else {
            blur.gaussian(&mut g, "blurred", &input, &st[0], sigma_mm, &mut dst);
        }
        readback.image_pass(&mut g, &dst);
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.run(g).unwrap();
        ex.finish().unwrap();
        bilinear(&common::from_f16_bytes(readback.bytes().unwrap()), side)
    })
}

/// Second moments (mm²) of `values` on the surface, about the centre texel:
/// each texel's UV offset mapped by `jacobian`. Returns the covariance's two
/// eigenvalues (major, minor) and its cross term.
fn surface_moments(values: &[f32], jacobian: [Vec2; 2]) -> (f64, f64, f64) {
    surface_moments_less(values, jacobian, 0.0)
}

/// [`surface_moments`] less an isotropic UV-space variance of `uv_variance`
/// texels² (bilinear upsampling's tent), mapped to the surface.
fn surface_moments_less(values: &[f32], jacobian: [Vec2; 2], uv_variance: f64) -> (f64, f64, f64) {
    let (mut w, mut xx, mut xy, mut yy) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (i, &v) in values.iter().enumerate() {
        let du = (i as u32 % N) as f32 - (N / 2) as f32;
        let dv = (i as u32 / N) as f32 - (N / 2) as f32;
        let p = jacobian[0] * du + jacobian[1] * dv;
        let v = v as f64;
        w += v;
        xx += v * (p.x * p.x) as f64;
        xy += v * (p.x * p.y) as f64;
        yy += v * (p.y * p.y) as f64;
    }
    let (a, b) = (jacobian[0].as_dvec2(), jacobian[1].as_dvec2());
    let xx = xx / w - uv_variance * (a.x * a.x + b.x * b.x);
    let xy = xy / w - uv_variance * (a.x * a.y + b.x * b.y);
    let yy = yy / w - uv_variance * (a.y * a.y + b.y * b.y);
    let mean = 0.5 * (xx + yy);
    let d = (0.25 * (xx - yy).powi(2) + xy * xy).sqrt();
    (mean + d, mean - d, xy)
}

#[test]
fn shear_correction_makes_sheared_uvs_isotropic() {
    // u along x, v at 53° to it on the surface (cos 0.6): 24 mm across the UV
    // square, 0.047 mm per texel along each axis. σ = 0.6 mm is 12.8 texels
    // along u; the chart's nearest border is 9.6 mm (16σ) from the impulse.
    let cos = 0.6;
    let (mesh, jacobian) = sheared_plane(24.0, cos);
    let sigma = 0.6f32;
    let variance = (sigma * sigma) as f64;
    let green = |out: Vec<Vec3>| out.iter().map(|c| c.y).collect::<Vec<f32>>();
    let on = surface_moments(
        &green(one_gaussian(&mesh, &impulse(100.0), sigma, true, None, N)),
        jacobian,
    );
    let off = surface_moments(
        &green(one_gaussian(&mesh, &impulse(100.0), sigma, false, None, N)),
        jacobian,
    );
    let report = |(major, minor, cross): (f64, f64, f64)| {
        format!(
            "eigen-variances {:.4} / {:.4} σ², cross {:+.4} σ², width ratio {:.3}",
            major / variance,
            minor / variance,
            cross / variance,
            (major / minor).sqrt()
        )
    };
    println!(
        "sheared UVs (cos {cos}), one Gaussian of σ = {sigma} mm, surface moments: \
         shear correction on: {}; off: {}",
        report(on),
        report(off)
    );
    let (major, minor, cross) = on;
    assert!((major / variance - 1.0).abs() < 0.03, "on: {}", report(on));
    assert!((minor / variance - 1.0).abs() < 0.03, "on: {}", report(on));
    assert!((cross / variance).abs() < 0.02, "on: {}", report(on));
    // Off: the u-then-v blur makes σ²(â âᵀ + b̂ b̂ᵀ), eigen-variances σ²(1 ± cos).
    let (major, minor, _) = off;
    assert!(
        (major / minor).sqrt() > 1.8,
        "off should be anisotropic: {}",
        report(off)
    );
}

#[test]
fn a_narrow_gaussian_in_one_pass_has_its_covariance() {
    // σ of 0.3 and 0.7 texels along u over the 3×3 stencil, 0.7 and 1.0 over
    // the 5×5 (skin::chain::Stencil), on a plain and a sheared plane (cos 0.6:
    // at 0.3 texels its cross moment is beyond what the 3×3's symmetric tap
    // pairs hold, at 1.0 its variance along u is past the 5×5's centre weight):
    // the surface covariance is σ², isotropic, as the separable passes give
    // for wide Gaussians.
    let sigma = 0.6f32;
    let variance = (sigma * sigma) as f64;
    let green = |out: Vec<Vec3>| out.iter().map(|c| c.y).collect::<Vec<f32>>();
    for (stencil, widths) in [(Stencil::Three, [0.3, 0.7]), (Stencil::Five, [0.7, 1.0])] {
        for cos in [0.0, 0.6] {
            for texels in widths {
                let (mesh, jacobian) = sheared_plane(N as f32 * sigma / texels, cos);
                let moments = |one_pass| {
                    let out = one_gaussian(&mesh, &impulse(100.0), sigma, true, one_pass, N);
                    let (major, minor, cross) = surface_moments(&green(out), jacobian);
                    [major / variance, minor / variance, cross / variance]
                };
                let (one, two) = (moments(Some(stencil)), moments(None));
                println!(
                    "{stencil:?}, cos {cos}, σ = {texels} texels: eigen-variances / σ², \
                     cross / σ²: one pass {one:.4?}, separable accurate kernel {two:.4?}"
                );
                assert!((one[0] - 1.0).abs() < 0.02, "{one:?}");
                assert!((one[1] - 1.0).abs() < 0.02, "{one:?}");
                assert!(one[2].abs() < 0.02, "{one:?}");
            }
        }
    }
}

#[test]
fn a_narrow_gaussian_that_halves_the_resolution_in_one_pass_has_its_covariance() {
    // The 5×5 stencil from a source of twice the side (N to N/2), σ of 0.5,
    // 0.97 (the scan's levels 5 and 6 at 1024²) and 1.22 texels of the
    // destination along u, on a plain and a sheared plane (cos 0.6). An
    // impulse's response depends on where it falls in the 2×2 texels of N a
    // destination texel covers, so the four placements are summed (each
    // moved back by its offset): that sum's moments are the stencil's. Less
    // the bilinear upsampling back to N² (a destination texel reaches N's
    // texels at ±½ and ±1½ with ¾ and ¼: ¾ texel² of N), the surface
    // covariance is σ², isotropic.
    let sigma = 0.6f32;
    let variance = (sigma * sigma) as f64;
    let side = N / 2;
    for cos in [0.0, 0.6] {
        for texels in [0.5, 0.97, 1.22] {
            let (mesh, jacobian) = sheared_plane(side as f32 * sigma / texels, cos);
            let moments = |one_pass| {
                let mut sum = vec![0.0f32; (N * N) as usize];
                for (a, b) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let mut input = vec![[0.0, 0.0, 0.0, 1.0]; (N * N) as usize];
                    input[((N / 2 + b) * N + N / 2 + a) as usize] = [100.0, 100.0, 100.0, 1.0];
                    let out = one_gaussian(&mesh, &input, sigma, true, one_pass, side);
                    for y in 0..N - 1 {
                        for x in 0..N - 1 {
                            sum[(y * N + x) as usize] += out[((y + b) * N + x + a) as usize].y;
                        }
                    }
                }
                let (major, minor, cross) = surface_moments_less(&sum, jacobian, 0.75);
                [major / variance, minor / variance, cross / variance]
            };
            let (one, two) = (moments(Some(Stencil::Five)), moments(None));
            println!(
                "halving 5×5, cos {cos}, σ = {texels} texels of N/2: eigen-variances / σ², \
                 cross / σ²: one pass {one:.4?}, separable accurate kernel {two:.4?}"
            );
            assert!((one[0] - 1.0).abs() < 0.02, "{one:?}");
            assert!((one[1] - 1.0).abs() < 0.02, "{one:?}");
            assert!(one[2].abs() < 0.02, "{one:?}");
        }
    }
}

#[test]
fn shear_correction_holds_down_the_adaptive_chain() {
    // The same sheared plane through the adaptive chain, whose levels shrink
    // (512² to 128² at level 2 here) as the V passes step along the sheared
    // direction: each level's surface covariance is its total variance v_k,
    // isotropic, once the bilinear upsampling to N² (a tent of (N/side)²/6
    // texels² along u and v) is taken off. Unsheared (cos 0), the adaptive
    // chain's own coarseness is all there is: 1.4 % with the levels that halve
    // in one pass (4.4 % when they were two passes). Sheared, the worst is
    // level 4, two passes at 64² whose V pass interpolates across columns:
    // 5.2 % (6.7 % before). Without the shear correction the eigen-variances
    // would be σ²(1 ± cos), 60 % off.
    let profile = Profile::skin();
    let mut worst = [0.0f64; 2];
    for (i, cos) in [0.0, 0.6].into_iter().enumerate() {
        let (mesh, jacobian) = sheared_plane(24.0, cos);
        let plan = chain::plan(&profile, Chain::Adaptive, N, mean_stretch(&mesh, N));
        let levels = chain_with(&mesh, &impulse(100.0), &accurate(), true, Chain::Adaptive);
        // Level 1 (σ 1.9 texels) is the impulse itself; level 6's 3σ (8.2 mm)
        // meets the chart's border (9.6 mm away).
        for k in 1..5 {
            let green: Vec<f32> = levels[k].iter().map(|c| c.y).collect();
            let f = (N / plan[k].resolution) as f64;
            let (major, minor, cross) = surface_moments_less(&green, jacobian, f * f / 6.0);
            let v = profile.gaussians[k].variance_mm2 as f64;
            println!(
                "cos {cos}: adaptive level {} at {}²: eigen-variances {:.4} / {:.4} v, cross {:+.4} v",
                k + 1,
                plan[k].resolution,
                major / v,
                minor / v,
                cross / v
            );
            let error = [
                (major / v - 1.0).abs(),
                (minor / v - 1.0).abs(),
                (cross / v).abs(),
            ];
            worst[i] = error.into_iter().fold(worst[i], f64::max);
        }
    }
    println!(
        "worst relative error: unsheared {:.4}, sheared {:.4}",
        worst[0], worst[1]
    );
    assert!(worst[0] < 0.03, "{worst:?}");
    assert!(worst[1] < 0.06, "{worst:?}");
}

/// A chart covering the UV square [0.25, 0.75]², gutter around it; `f(x, y)`
/// gives the irradiance of covered texels.
fn chart_input(f: impl Fn(u32, u32) -> f32) -> Vec<[f32; 4]> {
    (0..N * N)
        .map(|i| {
            let (x, y) = (i % N, i / N);
            let inside =
                |t: u32| (t as f32 + 0.5) / N as f32 > 0.25 && ((t as f32 + 0.5) / N as f32) < 0.75;
            if inside(x) && inside(y) {
                let v = f(x, y);
                [v, 0.5 * v, 0.25 * v, 1.0]
            } else {
                [0.0; 4]
            }
        })
        .collect()
}

#[test]
fn uniform_irradiance_stays_uniform_up_to_the_chart_border() {
    // 40 mm chart: the widest Gaussian reaches well past its border into the gutter.
    let input = chart_input(|_, _| 1.0);
    let out = combine(&chain(
        &plane(40.0, 40.0, 0.25, 0.75),
        &input,
        &accurate(),
        true,
    ));
    let mut worst = 0.0f32;
    for (o, i) in out.iter().zip(&input) {
        if i[3] > 0.0 {
            let want = Vec3::new(i[0], i[1], i[2]);
            worst = worst.max(((*o - want).abs() / want).max_element());
        }
    }
    println!("uniform irradiance: max relative deviation {worst:.5}");
    assert!(worst < 0.005, "{worst}");
}

#[test]
fn flux_is_conserved_on_a_closed_chart() {
    // A bright band away from the border and a dimmer rest.
    let input = chart_input(|x, _| if (200..260).contains(&x) { 4.0 } else { 0.5 });
    let out = combine(&chain(
        &plane(40.0, 40.0, 0.25, 0.75),
        &input,
        &accurate(),
        true,
    ));
    let covered = |i: usize| input[i][3] > 0.0;
    let flux_in: f64 = (0..input.len())
        .filter(|&i| covered(i))
        .map(|i| input[i][0] as f64)
        .sum();
    let flux_out: f64 = (0..input.len())
        .filter(|&i| covered(i))
        .map(|i| out[i].x as f64)
        .sum();
    let change = (flux_out / flux_in - 1.0).abs();
    println!(
        "flux in {flux_in:.1}, out {flux_out:.1}: change {:.4}%",
        change * 100.0
    );
    assert!(change < 0.01, "flux changed by {change}");
}

/// The diffuse term of the built-in head under a shadowed light (sharp edges
/// for the blur to soften), without specular (every region's ρs = 0, so no
/// energy goes to it), occlusion or texture detail (a uniform albedo, a flat
/// normal map: the screen and the UV space would sample them differently),
/// with `skin` changed by `set`; or, `direct`, the screen-space Lambert term
/// albedo/π · E of the same scene (light::direct), which is what the diffuse
/// term is with no blur at all.
fn diffuse_term(set: impl Fn(&mut dermis::scene::file::Skin), direct: bool) -> Vec<f32> {
    use dermis::render::{render_scene, RenderOptions, View};
    use dermis::scene::file::{Light, LightKind, Occlusion, SceneFile, SpecularRegion};
    let mut file = SceneFile::default();
    let dir = std::env::temp_dir().join(format!("dermis-blur-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, rgb) in [
        ("albedo.png", [188, 140, 120]),
        ("normal.png", [128, 128, 255]),
    ] {
        let rgba = [rgb[0], rgb[1], rgb[2], 255];
        image::save_buffer(dir.join(name), &rgba, 1, 1, image::ExtendedColorType::Rgba8).unwrap();
    }
    file.textures.albedo = Some(dir.join("albedo.png"));
    file.textures.normal = Some(dir.join("normal.png"));
    file.environment.source = "uniform:0.05,0.05,0.05".parse().unwrap();
    file.environment.lights = dermis::scene::file::LightsMode::Count(0);
    file.lights = vec![Light {
        kind: LightKind::Directional,
        direction: Some([-0.7, -0.3, -0.6]),
        position: None,
        color: [1.0, 1.0, 1.0],
        intensity: 1.0,
        shadow: true,
        angular_diameter_deg: 0.0,
    }];
    file.skin.occlusion = Occlusion::Off;
    file.skin.regions = Some(
        (0..10)
            .map(|i| SpecularRegion {
                name: format!("r{i}"),
                rho_s: 0.0,
                m: 0.3,
            })
            .collect(),
    );
    set(&mut file.skin);
    file.render.width = 128;
    file.render.height = 160;
    file.render.irradiance_resolution = 1024;
    file.render.exposure = Some(0.0);
    file.render.skybox = false;
    let scene = dermis::scene::Scene::load(file).unwrap();
    common::with_gpu(|ctx| {
        let opts = RenderOptions {
            hdr: true,
            view: if direct {
                View::named("direct")
            } else {
                View::named("diffuse")
            },
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
    })
}

/// Mean |a − b| over the pixels both cover, relative to b's mean (luminance).
fn mean_difference(a: &[f32], b: &[f32]) -> f64 {
    let luma = |p: &[f32]| f64::from(Vec3::from_slice(&p[..3]).dot(LUMINANCE));
    let (mut diff, mut sum) = (0.0, 0.0);
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        if p[3] > 0.5 && q[3] > 0.5 {
            diff += (luma(p) - luma(q)).abs();
            sum += luma(q);
        }
    }
    diff / sum
}

#[test]
fn blur_width_zero_and_blur_amount_zero_give_the_unblurred_irradiance() {
    let direct = diffuse_term(|_| {}, true);
    let blurred = diffuse_term(|_| {}, false);
    let no_width = diffuse_term(|s| s.blur_width = 0.0, false);
    let no_amount = diffuse_term(|s| s.blur_amount = 0.0, false);
    let half = diffuse_term(|s| s.blur_amount = 0.5, false);
    let mid: Vec<f32> = blurred
        .iter()
        .zip(&no_amount)
        .map(|(a, b)| 0.5 * (a + b))
        .collect();
    let e = |a: &[f32], b: &[f32]| 100.0 * mean_difference(a, b);
    println!(
        "mean |Δ| relative to the mean, over the head: width 0 vs direct {:.2} %, amount 0 vs \
         direct {:.2} %, width 0 vs amount 0 {:.3} %, blurred vs direct {:.2} %, amount 0.5 vs \
         the mean of blurred and unblurred {:.3} %",
        e(&no_width, &direct),
        e(&no_amount, &direct),
        e(&no_width, &no_amount),
        e(&blurred, &direct),
        e(&half, &mid),
    );
    // Width 0 leaves every level unblurred, and the final pass evaluates the
    // irradiance per pixel (skin::chain::unblurred_levels): the Lambert term
    // itself up to the profile weights' sums, 1 ± 0.001 (measured 0.03 %).
    // Amount 0 reads the irradiance texture: the same term sampled at 1024²
    // instead of per pixel (0.25 %).
    assert!(mean_difference(&no_width, &direct) < 0.002);
    assert!(mean_difference(&no_amount, &direct) < 0.03);
    // The blur moves light across the shadow edge and around the curvature:
    // measurably further from the Lambert term (0.44 %).
    assert!(mean_difference(&blurred, &direct) > 5.0 * mean_difference(&no_width, &direct));
    // The amount mixes linearly.
    assert!(mean_difference(&half, &mid) < 0.001);
}
