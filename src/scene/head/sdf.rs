//! The head's signed distance field (mm) and its landmarks; see the parent module
//! for the coordinate frame and the sources of the proportions.

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

// ---------------------------------------------------------------------------------
// Landmarks (mm). Bilateral features are given for the +X (left) side and mirrored.

/// Eyeball centre; interpupillary distance 63 mm (Farkas 1994).
pub(super) const EYE_CENTRE: Vec3 = Vec3::new(31.5, 3.0, 70.0);
/// Adult eyeball diameter ≈ 24 mm.
pub(super) const EYE_RADIUS: f32 = 12.0;
/// Eyelids: a 2 mm shell over the eyeball, cut open by the palpebral fissure.
const LID_RADIUS: f32 = 14.0;
/// Vertex (top of the head): vertex–gnathion ≈ 230 mm (Farkas 1994) with the chin
/// at y ≈ −108.
pub(super) const CROWN_Y: f32 = 122.0;
/// Stomion (the mouth line), 22 mm below subnasale (y ≈ −40).
pub(super) const STOMION_Y: f32 = -62.0;
/// The neck is cut flat here, ≈ 100 mm below the chin.
pub(super) const NECK_BOTTOM_Y: f32 = -210.0;

/// Signed distance (mm, negative inside) to the head surface. An approximation away
/// from the surface (ellipsoids and smooth unions are not exact distances), exact
/// enough near it for meshing and gradients.
pub fn sdf(p: Vec3) -> f32 {
    // Bilateral symmetry: model the +X half.
    let q = Vec3::new(p.x.abs(), p.y, p.z);

    // Cranium: breadth 150, length ≈ 195 with the brow, vertex at y = 122 (Farkas).
    let mut d = sd_ellipsoid(q, Vec3::new(0.0, 30.0, -3.0), Vec3::new(75.0, 92.0, 96.0));
    // Frontal bone: a flatter, broader forehead than the cranial ellipsoid gives.
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(0.0, 45.0, 30.0),
        Vec3::new(62.0, 55.0, 60.0),
        12.0,
    );
    // Mid and lower face mass (maxilla, cheeks); face width ≈ 130 at the cheekbones.
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(0.0, -28.0, 38.0),
        Vec3::new(57.0, 62.0, 50.0),
        18.0,
    );
    // Cheekbones (zygomatic prominences), kept soft.
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(44.0, -12.0, 58.0),
        Vec3::new(15.0, 9.0, 15.0),
        16.0,
    );
    // Masseter and ramus: fill the side of the face between cheekbone and jaw angle.
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(44.0, -50.0, 16.0),
        Vec3::new(13.0, 28.0, 24.0),
        16.0,
    );
    // Mandible: a tapering bar from the jaw angle (gonion, mandible width ≈ 100) to
    // the chin, and the chin itself (pogonion z ≈ 92, gnathion y ≈ −108).
    let (ga, gb) = (Vec3::new(44.0, -72.0, 8.0), Vec3::new(12.0, -98.0, 70.0));
    d = blend(d, q, (ga + gb) * 0.5, 50.0, 20.0, || {
        sd_round_cone(q, ga, gb, 7.0, 10.0)
    });
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(0.0, -94.0, 77.0),
        Vec3::new(19.0, 13.0, 14.0),
        16.0,
    );
    // Dental arch under the lips: mouth corners sit ≈ 10 mm behind the lip centre.
    d = ellipsoid_union(
        d,
        q,
        Vec3::new(0.0, -62.0, 62.0),
        Vec3::new(34.0, 26.0, 30.0),
        10.0,
    );
    // Brow ridge.
    let (ba, bb) = (Vec3::new(0.0, 24.0, 90.0), Vec3::new(40.0, 22.0, 80.0));
    d = blend(d, q, (ba + bb) * 0.5, 30.0, 10.0, || {
        sd_capsule(q, ba, bb, 7.0)
    });
    // Neck: ≈ 110 mm wide, 100 mm deep.
    let neck = sd_ellipse2(Vec2::new(q.x, q.z + 14.0), Vec2::new(55.0, 50.0)).max(q.y + 30.0);
    d = smin(d, neck, 18.0);

    // Eye sockets (orbits), then eyelids and eyeballs inside them.
    if (q - Vec3::new(31.5, 5.0, 80.0)).length() - 27.0 < (8.0 - d).max(d + 2.0) {
        d = smax(
            d,
            -sd_ellipsoid(q, Vec3::new(31.5, 6.0, 88.0), Vec3::new(18.0, 13.0, 12.0)),
            8.0,
        );
        d = smin(d, sd_eyelids(q), 2.0);
        d = smin(d, (q - EYE_CENTRE).length() - EYE_RADIUS, 0.8);
    }
    // Nose: nasion at y ≈ 14, subnasale at y ≈ −40 (height 54), tip at z ≈ 112;
    // nostrils open from below with ≈ 5 mm alar walls.
    if (q - Vec3::new(0.0, -13.0, 98.0)).length() - 36.0 < (d + 6.0).max(1.0 - d) {
        let mut nose = sd_round_cone(
            q,
            Vec3::new(0.0, 14.0, 88.0),
            Vec3::new(0.0, -24.0, 104.0),
            5.5,
            7.5,
        );
        nose = smin(
            nose,
            sd_ellipsoid(q, Vec3::new(0.0, -28.0, 104.0), Vec3::new(9.0, 8.5, 8.5)),
            5.0,
        );
        // Alae (nose wings): alar width ≈ 36 mm.
        nose = smin(
            nose,
            sd_ellipsoid(q, Vec3::new(11.0, -32.5, 94.0), Vec3::new(6.5, 5.5, 8.5)),
            6.0,
        );
        // Columella.
        nose = smin(
            nose,
            sd_capsule(
                q,
                Vec3::new(0.0, -36.0, 103.0),
                Vec3::new(0.0, -40.0, 93.0),
                3.5,
            ),
            3.0,
        );
        d = smin(d, nose, 6.0);
        d = smax(
            d,
            -sd_ellipsoid(q, Vec3::new(8.5, -34.5, 94.0), Vec3::new(4.8, 4.5, 5.0)),
            1.0,
        );
    }
    // Lips: upper and lower vermilion bulges; the mouth line is the crease between.
    if (q - Vec3::new(0.0, STOMION_Y, 88.0)).length() - 31.0 < d + 4.0 {
        d = smin(
            d,
            sd_ellipsoid(q, Vec3::new(0.0, -56.5, 88.0), Vec3::new(24.0, 6.0, 8.0)),
            4.0,
        );
        d = smin(
            d,
            sd_ellipsoid(q, Vec3::new(0.0, -68.0, 86.0), Vec3::new(22.0, 6.5, 8.0)),
            4.0,
        );
    }
    // Ears, fused to the head at the front; the concha digs a bowl toward the canal.
    if (q - ear_frame().centre).length() - 38.0 < (d + 3.0).max(2.0 - d) {
        let l = ear_local(q);
        d = smin(d, sd_ear(l), 3.0);
        d = smax(
            d,
            -sd_ellipsoid(l, Vec3::new(3.5, -4.0, 5.0), Vec3::new(6.0, 10.0, 7.5)),
            2.0,
        );
    }
    // The neck is cut flat at the bottom.
    d.max(NECK_BOTTOM_Y - q.y)
}

/// `smin(d, f(), k)` for a primitive inside the sphere (`c`, `r`), skipping `f` where
/// the primitive is too far away to change the result.
fn blend(d: f32, q: Vec3, c: Vec3, r: f32, k: f32, f: impl FnOnce() -> f32) -> f32 {
    if (q - c).length() - r >= d + k {
        d
    } else {
        smin(d, f(), k)
    }
}

fn ellipsoid_union(d: f32, q: Vec3, c: Vec3, r: Vec3, k: f32) -> f32 {
    blend(d, q, c, r.max_element(), k, || sd_ellipsoid(q, c, r))
}

// ---------------------------------------------------------------------------------
// SDF pieces.

fn sd_ellipsoid(p: Vec3, c: Vec3, r: Vec3) -> f32 {
    // Quílez's first-order ellipsoid distance: exact on the surface, bounded near it.
    let q = p - c;
    let k0 = (q / r).length();
    let k1 = (q / (r * r)).length();
    if k1 < 1e-12 {
        return -r.min_element();
    }
    k0 * (k0 - 1.0) / k1
}

fn sd_ellipse2(p: Vec2, r: Vec2) -> f32 {
    let k0 = (p / r).length();
    let k1 = (p / (r * r)).length();
    if k1 < 1e-12 {
        return -r.min_element();
    }
    k0 * (k0 - 1.0) / k1
}

fn sd_capsule(p: Vec3, a: Vec3, b: Vec3, r: f32) -> f32 {
    let pa = p - a;
    let ba = b - a;
    let h = (pa.dot(ba) / ba.dot(ba)).clamp(0.0, 1.0);
    (pa - ba * h).length() - r
}

/// Capsule whose radius goes linearly from `ra` at `a` to `rb` at `b` (approximate).
fn sd_round_cone(p: Vec3, a: Vec3, b: Vec3, ra: f32, rb: f32) -> f32 {
    let pa = p - a;
    let ba = b - a;
    let h = (pa.dot(ba) / ba.dot(ba)).clamp(0.0, 1.0);
    (pa - ba * h).length() - (ra + (rb - ra) * h)
}

/// Polynomial smooth minimum with blend width `k` (mm).
fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

fn smax(a: f32, b: f32, k: f32) -> f32 {
    -smin(-a, -b, k)
}

/// Eyelids: a shell over the eyeball, minus the palpebral fissure (≈ 30 × 10 mm,
/// lateral canthus ≈ 2 mm higher than the medial one; Farkas 1994).
fn sd_eyelids(q: Vec3) -> f32 {
    let d = q - EYE_CENTRE;
    let shell = d.length() - LID_RADIUS;
    // Rounded lid margins: a smooth cut is resolved better by the mesh than a crease.
    smax(shell, -fissure(d), 1.2)
}

/// Palpebral fissure as an implicit in the eye's frame (`d` = point − eye centre),
/// extruded along z: negative inside the opening (≈ mm near its border).
pub(super) fn fissure(d: Vec3) -> f32 {
    let x = d.x;
    let t = (1.0 - (x / 15.0).powi(2)).max(0.0).sqrt();
    let tilt = 0.07 * x;
    let upper = tilt + 5.0 * t * (1.0 - 0.15 * x / 15.0);
    let lower = tilt - 4.0 * t;
    (d.y - upper).max(lower - d.y)
}

/// Frame of the left ear: `out` lateral (normal of the auricle), `up` along the ear's
/// long axis, `fwd` toward the face.
struct EarFrame {
    centre: Vec3,
    out: Vec3,
    up: Vec3,
    fwd: Vec3,
}

fn ear_frame() -> &'static EarFrame {
    static FRAME: OnceLock<EarFrame> = OnceLock::new();
    FRAME.get_or_init(|| {
        // The long axis leans back ≈ 15°; the auricle faces ≈ 30° forward
        // (artistic values within the usual ranges).
        let tilt = 15f32.to_radians();
        let flare = 30f32.to_radians();
        let up = Vec3::new(0.0, tilt.cos(), -tilt.sin());
        let out0 = Vec3::new(flare.cos(), 0.0, flare.sin());
        let out = (out0 - up * out0.dot(up)).normalize();
        EarFrame {
            // Ear centre ≈ 8 mm below the origin and behind the tragion.
            centre: Vec3::new(69.0, -8.0, -12.0),
            out,
            up,
            fwd: out.cross(up),
        }
    })
}

/// Point in the left ear's local frame: x lateral, y up, z forward.
pub(super) fn ear_local(q: Vec3) -> Vec3 {
    let f = ear_frame();
    let d = q - f.centre;
    Vec3::new(d.dot(f.out), d.dot(f.up), d.dot(f.fwd))
}

/// The auricle (≈ 62 × 34 mm, ≈ 6 mm thick), at a point `l` in the ear frame.
fn sd_ear(l: Vec3) -> f32 {
    // Cartilage plate.
    let plate = sd_ellipsoid(l, Vec3::new(-1.0, 0.0, 0.0), Vec3::new(3.0, 30.0, 16.0));
    // Helix: a rim tube round the top and back, ending above the lobule.
    let e = sd_ellipse2(Vec2::new(l.y, l.z), Vec2::new(28.5, 15.0));
    let mut helix = Vec2::new(e, l.x - 1.5).length() - 3.3;
    let front_low = (4.0 - l.z).max(l.y - 12.0);
    let bottom = l.y + 20.0;
    helix = smax(helix, -front_low.min(bottom), 2.0);
    // Antihelix: an inner ridge on the back half.
    let e2 = sd_ellipse2(Vec2::new(l.y - 4.0, l.z + 2.0), Vec2::new(18.0, 8.5));
    let mut anti = Vec2::new(e2, l.x - 1.0).length() - 2.2;
    anti = smax(anti, l.z - 2.0, 2.0);
    // Lobule and tragus.
    let lobule = sd_ellipsoid(l, Vec3::new(-0.5, -23.0, 2.0), Vec3::new(3.5, 9.0, 8.5));
    let tragus = sd_ellipsoid(l, Vec3::new(0.5, -6.0, 14.0), Vec3::new(3.0, 5.0, 3.0));
    let mut ear = smin(plate, helix, 2.0);
    ear = smin(ear, anti, 1.5);
    ear = smin(ear, lobule, 3.0);
    smin(ear, tragus, 2.0)
}

/// Field value and gradient from four samples on a tetrahedron (step 0.1 mm).
pub(super) fn sdf_and_gradient(p: Vec3) -> (f32, Vec3) {
    const E: f32 = 0.1;
    const K: [Vec3; 4] = [
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let (mut v, mut g) = (0.0, Vec3::ZERO);
    for k in K {
        let f = sdf(p + k * E);
        v += f;
        g += k * f;
    }
    (v * 0.25, g / (4.0 * E))
}

#[cfg(test)]
mod tests {
    use super::super::regions::REGION_EARS;
    use super::super::tests::head;
    use super::*;

    /// Distance along `dir` from `from` to the first point inside the surface.
    fn march_in(from: Vec3, dir: Vec3, max: f32) -> Option<f32> {
        let mut t = 0.0;
        while t < max {
            if sdf(from + dir * t) < 0.0 {
                return Some(t);
            }
            t += 0.02;
        }
        None
    }

    /// Thickness of the solid along its inward normal at the surface point hit by the
    /// ray (`from`, `dir`).
    fn thickness_along_normal(from: Vec3, dir: Vec3) -> f32 {
        let hit = from + dir * march_in(from, dir, 100.0).expect("ray misses the head");
        let n = sdf_and_gradient(hit).1.normalize();
        let mut t = 0.0;
        while t < 60.0 && sdf(hit - n * t) < 0.0 {
            t += 0.02;
        }
        t
    }

    #[test]
    fn dimensions_are_realistic() {
        let (lo, hi) = head().mesh.bounds().unwrap();
        let within = |v: f32, target: f32| (v - target).abs() <= 0.1 * target;
        // Crown to chin ≈ 230 (chin: lowest point of the face at z = 80).
        let chin = -150.0 + march_in(Vec3::new(0.0, -150.0, 80.0), Vec3::Y, 100.0).unwrap();
        assert!(within(hi.y - chin, 230.0), "crown {} chin {chin}", hi.y);
        // Head breadth ≈ 150 without the ears; ears stick out ≈ 5–15 mm further.
        let h = head();
        let breadth = h
            .mesh
            .positions
            .iter()
            .zip(&h.region_of_vertex)
            .filter(|(_, &r)| r != REGION_EARS)
            .fold(0.0f32, |m, (p, _)| m.max(p.x.abs()))
            * 2.0;
        assert!(within(breadth, 150.0), "breadth {breadth}");
        assert!(hi.x - lo.x > breadth + 5.0 && hi.x - lo.x < 190.0);
        // Length (nose tip to occiput) ≈ 195 … 215.
        assert!(within(hi.z - lo.z, 195.0), "depth {}", hi.z - lo.z);
        // Neck ≈ 110 wide, cut flat ≈ 100 mm below the chin.
        let neck =
            2.0 * (100.0 - march_in(Vec3::new(100.0, -170.0, -14.0), -Vec3::X, 100.0).unwrap());
        assert!(within(neck, 110.0), "neck {neck}");
        assert!(within(chin - lo.y, 100.0), "neck length {}", chin - lo.y);
    }

    #[test]
    fn eye_sockets_are_recessed() {
        let z = |x: f32, y: f32| 150.0 - march_in(Vec3::new(x, y, 150.0), -Vec3::Z, 200.0).unwrap();
        let (brow, brow_lateral, cheekbone) = (z(31.5, 24.0), z(44.0, 22.0), z(44.0, -14.0));
        let (lid_crease, lateral_canthus) = (z(31.5, 13.0), z(46.0, 4.0));
        assert!(lid_crease < brow - 5.0, "lid {lid_crease} brow {brow}");
        assert!(lateral_canthus < brow_lateral - 5.0);
        assert!(
            lateral_canthus < cheekbone - 3.0,
            "canthus {lateral_canthus} cheek {cheekbone}"
        );
        // The eyeballs are in the sockets: the cornea stays behind the brow.
        assert!(z(31.5, 3.0) < brow - 4.0);
        assert!(sdf(EYE_CENTRE) < 0.0 && sdf(EYE_CENTRE * Vec3::new(-1.0, 1.0, 1.0)) < 0.0);
    }

    #[test]
    fn nostrils_are_open_cavities() {
        for s in [1.0, -1.0] {
            let inside = Vec3::new(8.5 * s, -34.5, 95.0);
            assert!(sdf(inside) > 0.0, "no nostril cavity");
            // Surrounded by tissue above, laterally (ala) and medially (columella)…
            assert!(sdf(Vec3::new(7.5 * s, -29.0, 96.0)) < 0.0);
            assert!(sdf(Vec3::new(14.0 * s, -35.0, 95.0)) < 0.0);
            assert!(sdf(Vec3::new(0.0, -35.0, 98.0)) < 0.0);
            // …and open to the outside below.
            let mut y = -35.0;
            while y > -45.0 {
                assert!(sdf(Vec3::new(7.5 * s, y, 96.0)) > 0.0, "closed at y = {y}");
                y -= 0.25;
            }
        }
    }

    #[test]
    fn ears_have_folds_and_a_gap_behind() {
        let f = ear_frame();
        let world = |l: Vec3| f.centre + f.out * l.x + f.up * l.y + f.fwd * l.z;
        let depth = |ly: f32, lz: f32| {
            30.0 - march_in(world(Vec3::new(30.0, ly, lz)), -f.out, 60.0).unwrap()
        };
        // The concha is a bowl: deeper than the helix rim and the antihelix.
        let (concha, helix, antihelix) = (depth(-4.0, 5.0), depth(0.0, -15.0), depth(4.0, -10.5));
        assert!(concha < helix - 4.0, "concha {concha} helix {helix}");
        assert!(
            concha < antihelix - 2.0,
            "concha {concha} antihelix {antihelix}"
        );
        // Behind the back of the auricle there is air, then the head.
        let start = world(Vec3::new(30.0, 0.0, -13.0));
        let enter = march_in(start, -f.out, 60.0).unwrap();
        let mut t = enter;
        while sdf(start - f.out * t) < 0.0 {
            t += 0.02;
        }
        let exit = t;
        let reenter = exit + march_in(start - f.out * exit, -f.out, 60.0).unwrap();
        assert!(
            reenter - exit > 2.0,
            "no gap behind the ear ({})",
            reenter - exit
        );
        // Mirror image on the right.
        assert!((sdf(start) - sdf(start * Vec3::new(-1.0, 1.0, 1.0))).abs() < 1e-4);
    }

    #[test]
    fn ears_and_nose_wings_are_thin() {
        let f = ear_frame();
        let world = |l: Vec3| f.centre + f.out * l.x + f.up * l.y + f.fwd * l.z;
        for (ly, lz) in [(14.0, -8.0), (20.0, -10.7), (0.0, -15.0)] {
            let t = thickness_along_normal(world(Vec3::new(30.0, ly, lz)), -f.out);
            assert!(t > 2.5 && t < 8.0, "ear thickness {t} mm at ({ly}, {lz})");
        }
        let ala = thickness_along_normal(Vec3::new(40.0, -34.5, 94.0), -Vec3::X);
        assert!(ala > 1.5 && ala < 8.0, "alar wall {ala} mm");
    }
}
