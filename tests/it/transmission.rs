//! Light through thin skin (translucent shadow maps; docs/records/2026-11-26-transmission.md,
//! "Transmission") on an analytic backlit slab: a flat box d mm thick, a light
//! straight behind it, the camera in front. The front face's transmitted
//! radiance must be T(d)·E·albedo/π, with T the CPU profile's transmittance
//! (skin::profile::Profile::transmittance) — within 2 %. And with
//! `skin.transmission = 0`, or with the light in front, the term adds nothing.

use crate::common;

use dermis::render::{render_scene, RenderOptions, View};
use dermis::scene::camera::Camera;
use dermis::scene::env::EnvMap;
use dermis::scene::file::{Occlusion, SceneFile, SpecularRegion};
use dermis::scene::mesh::Mesh;
use dermis::scene::texture::{Encoding, Texture};
use dermis::scene::{Light, LightSource, Scene};
use dermis::skin::profile::Profile;
use dermis::skin::specular::REGION_NAMES;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

const SIZE: u32 = 64;
/// Half the slab's side, mm.
const HALF: f32 = 20.0;
/// Linear value of the sRGB grey 128 the slab is painted with.
const ALBEDO: f32 = 0.215_861;
/// The light's irradiance: large enough that the red, green and most of the
/// blue transmitted radiance stays well inside half-float range at 5 mm.
const E: f32 = 1000.0;
/// Camera distance, mm (the camera looks down −Z at the origin).
const CAMERA_MM: f32 = 200.0;

/// A box of sides 2·HALF × 2·HALF × `d` mm centred on the origin, its large
/// faces facing ±Z, each face its own UV chart.
fn slab(d: f32) -> Mesh {
    let (a, h) = (HALF, 0.5 * d);
    let mut m = Mesh {
        name: "slab".into(),
        ..Mesh::default()
    };
    // (corner, edge along u, edge along v, UV corner, UV size): e_u × e_v is
    // the outward normal.
    let faces = [
        (
            Vec3::new(-a, -a, h),
            Vec3::new(2.0 * a, 0.0, 0.0),
            Vec3::new(0.0, 2.0 * a, 0.0),
            Vec2::new(0.02, 0.02),
            Vec2::splat(0.45),
        ),
        (
            Vec3::new(a, -a, -h),
            Vec3::new(-2.0 * a, 0.0, 0.0),
            Vec3::new(0.0, 2.0 * a, 0.0),
            Vec2::new(0.53, 0.02),
            Vec2::splat(0.45),
        ),
        (
            Vec3::new(a, -a, h),
            Vec3::new(0.0, 0.0, -d),
            Vec3::new(0.0, 2.0 * a, 0.0),
            Vec2::new(0.02, 0.53),
            Vec2::new(0.2, 0.45),
        ),
        (
            Vec3::new(-a, -a, -h),
            Vec3::new(0.0, 0.0, d),
            Vec3::new(0.0, 2.0 * a, 0.0),
            Vec2::new(0.26, 0.53),
            Vec2::new(0.2, 0.45),
        ),
        (
            Vec3::new(-a, a, h),
            Vec3::new(2.0 * a, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -d),
            Vec2::new(0.52, 0.53),
            Vec2::new(0.2, 0.45),
        ),
        (
            Vec3::new(-a, -a, -h),
            Vec3::new(2.0 * a, 0.0, 0.0),
            Vec3::new(0.0, 0.0, d),
            Vec2::new(0.76, 0.53),
            Vec2::new(0.2, 0.45),
        ),
    ];
    for (corner, eu, ev, uv0, uv_size) in faces {
        let n = eu.cross(ev).normalize();
        let base = m.positions.len() as u32;
        for (s, t) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            m.positions.push(corner + eu * s + ev * t);
            m.normals.push(n);
            m.uvs.push(uv0 + uv_size * Vec2::new(s, t));
            m.tangents.push(eu.normalize().extend(1.0));
        }
        m.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

/// A UV sphere of radius `r` mm about the origin (longitude along u,
/// latitude along v).
fn sphere(r: f32) -> Mesh {
    let (rings, segments) = (96u32, 192u32);
    let mut m = Mesh {
        name: "sphere".into(),
        ..Mesh::default()
    };
    for j in 0..=rings {
        let theta = PI * j as f32 / rings as f32;
        for i in 0..=segments {
            let phi = 2.0 * PI * i as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            m.positions.push(r * n);
            m.normals.push(n);
            m.uvs.push(Vec2::new(
                0.02 + 0.96 * i as f32 / segments as f32,
                0.02 + 0.96 * j as f32 / rings as f32,
            ));
            m.tangents
                .push(Vec3::new(-phi.sin(), 0.0, phi.cos()).extend(1.0));
        }
    }
    let row = segments + 1;
    for j in 0..rings {
        for i in 0..segments {
            let k = j * row + i;
            m.indices
                .extend([k, k + row, k + 1, k + 1, k + row, k + row + 1]);
        }
    }
    m
}

/// The slab lit by `light` alone (black environment), with no specular (ρs = 0
/// in every region), so the front face's radiance is the transmitted term.
fn scene(d: f32, light: LightSource, transmission: f32) -> Scene {
    let mut file = SceneFile::default();
    file.skin.occlusion = Occlusion::Off;
    file.skin.transmission = transmission;
    file.skin.regions = Some(
        REGION_NAMES
            .iter()
            .map(|name| SpecularRegion {
                name: (*name).into(),
                rho_s: 0.0,
                m: 0.3,
            })
            .collect(),
    );
    file.render.width = SIZE;
    file.render.height = SIZE;
    file.render.irradiance_resolution = 256;
    file.render.exposure = Some(0.0);
    let grey = |v: u8| Texture::solid([v, v, v, 255], Encoding::Linear);
    Scene {
        mesh: slab(d),
        albedo: Texture::solid([128, 128, 128, 255], Encoding::Srgb),
        normal: Texture::solid([128, 128, 255, 255], Encoding::Linear),
        specular: grey(255),
        roughness: grey(77),
        regions: grey(0),
        env: EnvMap::uniform(Vec3::ZERO, 64, 32),
        camera: Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, CAMERA_MM, 30.0),
        lights: vec![Light {
            source: light,
            irradiance: Vec3::splat(E),
            shadow: true,
            angular_radius: 0.0,
        }],
        pre_exposure: dermis::scene::range::PreExposure::NONE,
        file,
    }
}

/// Linear RGBA of `view` (radiance, exposure 0).
fn render(ctx: &std::sync::Arc<dermis::gpu::Context>, scene: &Scene, view: &str) -> Vec<f32> {
    let opts = RenderOptions {
        view: View::named(view),
        hdr: true,
        ..RenderOptions::default()
    };
    render_scene(ctx, scene, &opts).unwrap().hdr.unwrap()
}

/// Mean RGB of the 5 × 5 pixels at the image's centre (the slab's centre).
fn centre(img: &[f32]) -> Vec3 {
    let c = SIZE as usize / 2;
    let mut sum = Vec3::ZERO;
    for y in c - 2..=c + 2 {
        for x in c - 2..=c + 2 {
            let i = (y * SIZE as usize + x) * 4;
            sum += Vec3::new(img[i], img[i + 1], img[i + 2]);
        }
    }
    sum / 25.0
}

#[test]
fn a_backlit_slab_transmits_the_profile_through_its_thickness() {
    let profile = Profile::skin();
    // Straight behind: a directional light towards −Z, and a point light on
    // the axis 300 mm behind the slab's centre.
    let behind = [
        ("directional", LightSource::Directional(-Vec3::Z)),
        ("point", LightSource::Point(Vec3::new(0.0, 0.0, -300.0))),
    ];
    let mut worst = 0.0f32;
    common::with_gpu(|ctx| {
        for (kind, light) in behind {
            for d in [0.5f32, 1.0, 2.0, 5.0] {
                let got = centre(&render(ctx, &scene(d, light, 1.0), "transmission"));
                // The irradiance at the shaded point (the front face's centre),
                // facing the light: a point light's falls off with its distance.
                let e = match light {
                    LightSource::Directional(_) => E,
                    LightSource::Point(p) => {
                        let dist = p.distance(Vec3::new(0.0, 0.0, 0.5 * d));
                        E * (1000.0 / dist).powi(2)
                    }
                };
                let expected = profile.transmittance(d) * e * ALBEDO / PI;
                let mut rel = Vec3::ZERO;
                for c in 0..3 {
                    // Half-float resolution: values under its smallest normal
                    // (6.1e-5) are stored in steps of 6e-8.
                    let err = (got[c] - expected[c]).abs();
                    assert!(
                        err <= 0.02 * expected[c] + 1e-7,
                        "{kind}, d = {d} mm, channel {c}: got {got}, expected {expected}"
                    );
                    if expected[c] > 1e-4 {
                        rel[c] = err / expected[c];
                    }
                }
                worst = worst.max(rel.max_element());
                println!(
                    "{kind:>11} d = {d} mm: T = ({:.5}, {:.3e}, {:.3e}); radiance {:.5e} {:.5e} {:.5e} \
                     expected {:.5e} {:.5e} {:.5e}; relative error {:.3} % {:.3} % {:.3} %",
                    profile.transmittance(d).x,
                    profile.transmittance(d).y,
                    profile.transmittance(d).z,
                    got.x,
                    got.y,
                    got.z,
                    expected.x,
                    expected.y,
                    expected.z,
                    100.0 * rel.x,
                    100.0 * rel.y,
                    100.0 * rel.z,
                );
            }
        }
    });
    println!(
        "largest relative error (channels above 1e-4): {:.3} %",
        100.0 * worst
    );
}

/// Every pixel's RGBA bits.
fn bits(img: &[f32]) -> Vec<u32> {
    img.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn transmission_zero_or_a_light_in_front_adds_nothing() {
    common::with_gpu(|ctx| {
        let behind = LightSource::Directional(-Vec3::Z);
        // Backlit: the term is there at 1 and gone at 0 (the pass is then built
        // without it, so its final image is the one without the term).
        let on = render(ctx, &scene(1.0, behind, 1.0), "final");
        let off = render(ctx, &scene(1.0, behind, 0.0), "final");
        assert!(centre(&on).x > 1.0, "{}", centre(&on));
        assert_eq!(centre(&off), Vec3::ZERO);
        let term_off = render(ctx, &scene(1.0, behind, 0.0), "transmission");
        assert!(term_off.chunks_exact(4).all(|p| p[..3] == [0.0; 3]));
        // Lit from the front (the camera's side), the pass with the term gives
        // the same bits as the pass without it: a lit face is not lit twice.
        let front = LightSource::Directional(Vec3::new(0.2, 0.1, 1.0).normalize());
        let with = render(ctx, &scene(1.0, front, 1.0), "final");
        let without = render(ctx, &scene(1.0, front, 0.0), "final");
        // The lit face's own radiance, E·cos θ·albedo/π: what the same albedo
        // and readback give without the transmission (printed for docs/records/2026-11-26-transmission.md).
        let lit = E * Vec3::new(0.2, 0.1, 1.0).normalize().z * ALBEDO / PI;
        println!(
            "front-lit radiance / E·cos θ·albedo/π = {}",
            centre(&with) / lit
        );
        assert!(centre(&with).x > 1.0, "{}", centre(&with));
        assert!(
            bits(&with) == bits(&without),
            "the term changed a front-lit image"
        );
        // Half the scale, half the term.
        let half = render(ctx, &scene(1.0, behind, 0.5), "transmission");
        let full = render(ctx, &scene(1.0, behind, 1.0), "transmission");
        let (h, f) = (centre(&half), centre(&full));
        assert!((2.0 * h - f).abs().max_element() < 2e-3 * f.x, "{h} {f}");
    });
}

/// Just past a convex body's terminator the light's ray leaves the skin close
/// by, so its shadow map gives a small thickness; but that light entered on the
/// same side of the surface, which the chain already carries along it. Only
/// light entering a surface that faces away (a thin part's far side) is
/// transmitted (translucent.frag, `entry_normal`): a 25 mm sphere lit from the
/// side, seen across its terminator, transmits nothing, where a band of up to
/// ~1 % of E·albedo/π was drawn before.
#[test]
fn a_convex_terminator_transmits_nothing() {
    let mut scene = scene(1.0, LightSource::Directional(Vec3::X), 1.0);
    scene.mesh = sphere(25.0);
    scene.file.render.width = 256;
    scene.file.render.height = 256;
    let scale = E * ALBEDO / PI;
    let (lit, through) = common::with_gpu(|ctx| {
        (
            render(ctx, &scene, "final"),
            render(ctx, &scene, "transmission"),
        )
    });
    // The sphere is in view and lit on one side.
    let brightest = lit.chunks_exact(4).map(|p| p[0]).fold(0.0f32, f32::max);
    assert!(
        brightest > 0.1 * scale,
        "the sphere is not lit: {brightest}"
    );
    let worst = through
        .chunks_exact(4)
        .map(|p| p[0].max(p[1]).max(p[2]))
        .fold(0.0f32, f32::max);
    println!(
        "most transmitted radiance: {:.3e} of E·albedo/π",
        worst / scale
    );
    assert!(worst <= 1e-4 * scale, "a band at the terminator: {worst}");
}

/// With a medium (Jensen et al. 2001's skin1) the slab transmits the medium's
/// own T(d), walked on the CPU (skin::walk) at exactly d — the GPU reads it
/// from a table by thickness (skin::medium_tables): within 5 % in every
/// channel from 0.5 to 5 mm. The regions' specular at ρs = 0 keeps the light
/// entering whole, as in the test above.
#[test]
fn a_backlit_slab_of_a_medium_transmits_its_walked_transmittance() {
    use dermis::scene::file::{MediumPreset, SpecularRule};
    use dermis::skin::{medium::Medium, medium_tables::MediumTables, walk};
    let with_medium = |d: f32| {
        let mut s = scene(d, LightSource::Directional(-Vec3::Z), 1.0);
        s.file.skin.medium.preset = Some(MediumPreset::JensenSkin1);
        s.file.skin.medium.specular = Some(SpecularRule::Regions);
        s
    };
    let medium = Medium::from_spec(&with_medium(1.0).file.skin.medium).unwrap();
    let tables = MediumTables::load_or_compute(&medium, &dermis::cache::default_cache_dir());
    common::with_gpu(|ctx| {
        for d in [0.5f32, 1.0, 2.0, 5.0] {
            let got = centre(&render(ctx, &with_medium(d), "transmission"));
            let walked = Vec3::from_array([0, 1, 2].map(|c| {
                walk::slab_to_count(&medium, c, f64::from(d), 16_000, 1 << 24).scattered as f32
            }));
            // The table holds T/albedo; the final pass multiplies by the map's albedo.
            let expected = walked / Vec3::from(tables.albedo) * E * ALBEDO / PI;
            let rel = (got - expected).abs() / expected;
            println!("d = {d} mm: T walked {walked:.4?}, radiance {got:.4?} expected {expected:.4?}, error {rel:.4?}");
            assert!(
                rel.max_element() < 0.05,
                "d = {d} mm: {got} against {expected}"
            );
        }
    });
}
