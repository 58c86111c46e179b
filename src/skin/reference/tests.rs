//! The exact-diffusion integrator against closed forms: a spot of irradiance on
//! a plane gives the profile, and a sphere under a directional light matches a
//! fine numerical integral over the exact sphere.

use super::*;
use crate::skin::profile::Profile;
use std::f64::consts::PI as PI64;

fn skin() -> (Vec<f32>, Vec<Vec3>) {
    let p = Profile::skin();
    (
        p.gaussians.iter().map(|g| g.variance_mm2).collect(),
        p.gaussians.iter().map(|g| g.weights).collect(),
    )
}

/// A `side`-mm square at z = 0 centred on the origin, `cells` × `cells` quads,
/// with UVs spanning [0, 1]².
fn plane(side: f32, cells: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let (mut p, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..=cells {
        for i in 0..=cells {
            let t = Vec2::new(i as f32, j as f32) / cells as f32;
            p.push(((t - 0.5) * side).extend(0.0));
            uv.push(t);
        }
    }
    let at = |i: u32, j: u32| j * (cells + 1) + i;
    for j in 0..cells {
        for i in 0..cells {
            idx.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            idx.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (p, uv, idx)
}

#[test]
fn a_spot_on_a_plane_gives_the_profile() {
    // A "point" of irradiance: a Gaussian spot (σ 0.2 mm) of unit power at the
    // origin, so each M_k is exactly G(v_k + v0, r) (Gaussians convolve by adding
    // variances), and the profile Σ w_k G(v_k + v0, r) at every distance.
    let (variances, weights) = skin();
    let (side, v0) = (60.0, 0.04);
    let (p, uv, idx) = plane(side, 6);
    let diffusion = Diffusion::new(&p, &uv, &idx, &variances)
        .unwrap()
        .with_irradiance_scale(1e-3 * gaussian(v0, 0.0));
    let spot = |uv: Vec2| {
        let y = (uv - 0.5) * side;
        Some(Vec3::splat(gaussian(v0, y.length_squared())))
    };
    for r in [0.0, 0.05, 0.15, 0.4, 1.0, 2.0, 4.0, 7.0] {
        let s = diffusion.at(Vec3::new(r, 0.3 * r, 0.0), Vec3::Z, &spot);
        let r2 = 1.09 * r * r;
        for (k, &v) in variances.iter().enumerate() {
            let want = gaussian(v + v0, r2);
            let got = s.irradiance[k].x;
            // Where the spot lies within the Gaussian's reach (each ends at 4σ).
            if r2.sqrt() + 3.0 * v0.sqrt() <= EXTENT_SIGMA * v.sqrt() {
                assert!(
                    (got / want - 1.0).abs() < 0.005,
                    "r {r} Gaussian {k}: {got} against {want}"
                );
            }
            assert!(
                (s.reach[k] - 1.0).abs() < 0.002,
                "C_{k} = {} on a plane",
                s.reach[k]
            );
        }
        let want: Vec3 = (0..6)
            .map(|k| weights[k] * gaussian(variances[k] + v0, r2))
            .sum();
        let got = s.diffuse(&weights, true, |_| false);
        assert_eq!(
            got,
            s.diffuse(&weights, false, |_| false),
            "no path leaves a plane"
        );
        // Relative to the brightest channel: each Gaussian ends at its own 4σ, so
        // blue's tail (its two narrowest) at 1 mm is a few % short of the
        // untruncated profile, 3e-5 of red's value.
        let err = (got - want).abs().max_element() / want.max_element();
        assert!(err < 0.005, "r {r}: {got} against {want}");
    }
}

/// A sphere of `radius` mm centred on the origin, latitude–longitude
/// tessellated; u = φ/2π, v = θ/π.
fn sphere(radius: f32, rings: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
    let segments = 2 * rings;
    let (mut p, mut uv, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..=rings {
        for i in 0..=segments {
            let t = Vec2::new(i as f32 / segments as f32, j as f32 / rings as f32);
            p.push(radius * direction(t));
            uv.push(t);
        }
    }
    let at = |i: u32, j: u32| j * (segments + 1) + i;
    for j in 0..rings {
        for i in 0..segments {
            idx.extend([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            idx.extend([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (p, uv, idx)
}

fn direction(uv: Vec2) -> Vec3 {
    let (phi, theta) = (2.0 * PI * uv.x, PI * uv.y);
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// M_k at the point of the unit sphere direction `x` of a sphere of `radius`
/// under E(n) = max(0, n·z): a midpoint rule in polar coordinates about x
/// (angle α from x, azimuth β), dense enough to resolve the narrowest Gaussian,
/// out to the chord `extent` as the integrator.
fn sphere_integral(radius: f64, x: [f64; 3], v: f64, extent: f64) -> f64 {
    let (na, nb) = (40_000, 720);
    // An orthonormal frame (x, t1, t2).
    let t1 = if x[2].abs() < 0.9 {
        let c = [x[1], -x[0], 0.0];
        let l = (c[0] * c[0] + c[1] * c[1]).sqrt();
        [c[0] / l, c[1] / l, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let t2 = [
        x[1] * t1[2] - x[2] * t1[1],
        x[2] * t1[0] - x[0] * t1[2],
        x[0] * t1[1] - x[1] * t1[0],
    ];
    // The whole sphere, but the steps in α follow the narrowest scale needed.
    let a_max = PI64;
    let (da, db) = (a_max / na as f64, 2.0 * PI64 / nb as f64);
    let mut sum = 0.0;
    for i in 0..na {
        let a = (i as f64 + 0.5) * da;
        let r2 = 2.0 * radius * radius * (1.0 - a.cos());
        if r2 > extent * extent {
            break;
        }
        let g = (-r2 / (2.0 * v)).exp() / (2.0 * PI64 * v);
        if g < 1e-30 {
            continue;
        }
        let mut ring = 0.0;
        for j in 0..nb {
            let b = (j as f64 + 0.5) * db;
            let n_z = a.cos() * x[2] + a.sin() * (b.cos() * t1[2] + b.sin() * t2[2]);
            ring += n_z.max(0.0);
        }
        sum += g * ring * db * radius * radius * a.sin() * da;
    }
    sum
}

#[test]
fn a_sphere_under_a_directional_light_matches_a_numerical_integral() {
    // 8 mm: smaller than the widest Gaussian's reach (10.9 mm), so curvature and
    // light from the far side count.
    let (variances, _) = skin();
    let radius = 8.0;
    let (p, uv, idx) = sphere(radius, 200);
    let diffusion = Diffusion::new(&p, &uv, &idx, &variances)
        .unwrap()
        .with_irradiance_scale(1.0);
    let lit = |uv: Vec2| Some(Vec3::splat(direction(uv).z.max(0.0)));
    // From the lit pole through the terminator into the dark side.
    for theta_deg in [30.0f32, 80.0, 90.0, 100.0, 130.0] {
        let t = theta_deg.to_radians();
        let n = Vec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos());
        let s = diffusion.at(radius * n, n, &lit);
        assert!(
            s.through_air.iter().all(|a| *a == Vec3::ZERO),
            "a convex body has no air paths"
        );
        for (k, &v) in variances.iter().enumerate() {
            let want = sphere_integral(
                radius as f64,
                n.as_dvec3().to_array(),
                v as f64,
                diffusion.extent() as f64,
            );
            let got = s.irradiance[k].x as f64;
            assert!(
                (got - want).abs() <= 0.004 * want + 2e-5,
                "θ {theta_deg}° Gaussian {k}: {got} against {want}"
            );
        }
    }
}

#[test]
fn a_fold_sends_its_other_side_through_the_air() {
    // An inside corner: the floor z = 0 (x ≥ 0) and the wall x = 0 (z ≥ 0), 30 mm
    // each, facing each other. From a point of the floor 1 mm from the wall, the
    // wall rises at up to 90°: its light crosses the air. The narrowest Gaussian
    // (reach 0.32 mm) does not reach the wall.
    let (variances, weights) = skin();
    let p = [
        Vec3::new(0.0, -15.0, 0.0),
        Vec3::new(30.0, -15.0, 0.0),
        Vec3::new(30.0, 15.0, 0.0),
        Vec3::new(0.0, 15.0, 0.0),
        Vec3::new(0.0, -15.0, 30.0),
        Vec3::new(0.0, 15.0, 30.0),
    ];
    let uv = [Vec2::ZERO; 6];
    let idx = [0, 1, 2, 0, 2, 3, 0, 3, 5, 0, 5, 4];
    let diffusion = Diffusion::new(&p, &uv, &idx, &variances).unwrap();
    let s = diffusion.at(Vec3::new(1.0, 0.0, 0.0), Vec3::Z, &|_| Some(Vec3::ONE));
    assert_eq!(s.through_air[0], Vec3::ZERO);
    assert!(s.through_air[5].x > 0.1 * s.irradiance[5].x, "{s:?}");
    let (all, inside) = (
        s.diffuse(&weights, true, |_| false),
        s.diffuse(&weights, false, |_| false),
    );
    assert!(all.x > inside.x && inside.x > 0.9, "{all} {inside}");
}
