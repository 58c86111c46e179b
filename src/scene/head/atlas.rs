//! The UV atlas: triangles labelled by projection axis, connected components as
//! charts (split where they overlap themselves), orthographic projection at one
//! common texel density, shelf packing with a gutter, seams by duplicating border
//! vertices, and tangents from the resulting UVs.

use glam::{Vec2, Vec3, Vec4};

use super::raster::raster_triangle;
use super::regions::{region_at, REGION_EARS};
use crate::scene::mesh::Mesh;

/// Projection axes: +X, −X, +Y, −Y, +Z, −Z.
const AXES: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];
/// Index of +Z in [`AXES`]: the face chart's axis.
const AXIS_PZ: usize = 4;
/// The face chart takes front triangles down to this cosine: up to 2.5× UV stretch.
const FACE_MIN_COS: f32 = 0.4;
/// A small chart may join a neighbour whose axis its triangles face at least this much.
const MERGE_MIN_COS: f32 = 0.25;
/// Components of fewer triangles than this try to merge into a neighbour.
const SMALL_CHART: usize = 80;
/// Resolution (mm) of the self-overlap check of charts.
const OVERLAP_CHECK_MM: f32 = 0.2;

/// Triangles (mesh ids) projected along one of [`AXES`].
pub(super) struct Chart {
    axis: usize,
    tris: Vec<u32>,
}

/// Orthographic projection onto the plane of `axis`, as (u right, v down) in mm.
/// The in-plane frame (r, up) satisfies r × up = axis, so every triangle facing the
/// axis keeps one winding (negative signed area with v down).
fn project(axis: usize, p: Vec3) -> Vec2 {
    let (r, up) = match axis {
        0 => (Vec3::NEG_Z, Vec3::Y),
        1 => (Vec3::Z, Vec3::Y),
        2 => (Vec3::X, Vec3::NEG_Z),
        3 => (Vec3::X, Vec3::Z),
        4 => (Vec3::X, Vec3::Y),
        _ => (Vec3::NEG_X, Vec3::Y),
    };
    Vec2::new(p.dot(r), -p.dot(up))
}

fn tri_normal(pos: &[Vec3], t: &[u32; 3]) -> Vec3 {
    let [a, b, c] = t.map(|i| pos[i as usize]);
    (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::ZERO)
}

/// Edge neighbours of every triangle (u32::MAX across boundary or non-manifold edges).
fn triangle_adjacency(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut edges: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(tris.len() * 3);
    for (t, tri) in tris.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (tri[e], tri[(e + 1) % 3]);
            edges.push((a.min(b), a.max(b), t as u32, e as u8));
        }
    }
    edges.sort_unstable();
    let mut adj = vec![[u32::MAX; 3]; tris.len()];
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 && edges[j].1 == edges[i].1 {
            j += 1;
        }
        if j - i == 2 {
            let (x, y) = (edges[i], edges[i + 1]);
            adj[x.2 as usize][x.3 as usize] = y.2;
            adj[y.2 as usize][y.3 as usize] = x.2;
        }
        i = j;
    }
    adj
}

/// Connected components of `members` (triangle ids) under edge adjacency, where two
/// triangles connect only if `key` agrees. Deterministic order.
fn components(members: &[u32], adj: &[[u32; 3]], key: &[u32]) -> Vec<Vec<u32>> {
    let mut seen = vec![false; adj.len()];
    let mut in_set = vec![false; adj.len()];
    for &t in members {
        in_set[t as usize] = true;
    }
    let mut out = Vec::new();
    for &start in members {
        if seen[start as usize] {
            continue;
        }
        seen[start as usize] = true;
        let mut comp = vec![start];
        let mut head = 0;
        while head < comp.len() {
            let t = comp[head] as usize;
            head += 1;
            for &nb in &adj[t] {
                let n = nb as usize;
                if nb != u32::MAX && in_set[n] && !seen[n] && key[n] == key[t] {
                    seen[n] = true;
                    comp.push(nb);
                }
            }
        }
        out.push(comp);
    }
    out
}

pub(super) fn build_charts(pos: &[Vec3], tris: &[[u32; 3]]) -> Vec<Chart> {
    let adj = triangle_adjacency(tris);
    let normals: Vec<Vec3> = tris.iter().map(|t| tri_normal(pos, t)).collect();
    // Labels: group (0 head, 1 ears) × 6 + axis.
    let mut label: Vec<u32> = tris
        .iter()
        .zip(&normals)
        .map(|(t, &n)| {
            let c = (pos[t[0] as usize] + pos[t[1] as usize] + pos[t[2] as usize]) / 3.0;
            let ear = region_at(c) == REGION_EARS;
            if !ear && c.z > 20.0 && n.z > FACE_MIN_COS {
                return AXIS_PZ as u32;
            }
            let axis = (0..6)
                .max_by(|&a, &b| n.dot(AXES[a]).total_cmp(&n.dot(AXES[b])))
                .unwrap_or(0);
            u32::from(ear) * 6 + axis as u32
        })
        .collect();
    let all: Vec<u32> = (0..tris.len() as u32).collect();

    // Merge small components into a neighbour of the same group that they face.
    for _ in 0..6 {
        let mut changed = false;
        for comp in components(&all, &adj, &label) {
            if comp.len() >= SMALL_CHART {
                continue;
            }
            let own = label[comp[0] as usize];
            let mut cands: Vec<(u32, u32)> = Vec::new(); // (shared edges, label)
            for &t in &comp {
                for &nb in &adj[t as usize] {
                    if nb == u32::MAX {
                        continue;
                    }
                    let l = label[nb as usize];
                    if l == own || l / 6 != own / 6 {
                        continue;
                    }
                    match cands.iter_mut().find(|c| c.1 == l) {
                        Some(c) => c.0 += 1,
                        None => cands.push((1, l)),
                    }
                }
            }
            cands.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
            for &(_, l) in &cands {
                let axis = AXES[(l % 6) as usize];
                if comp
                    .iter()
                    .all(|&t| normals[t as usize].dot(axis) > MERGE_MIN_COS)
                {
                    for &t in &comp {
                        label[t as usize] = l;
                    }
                    changed = true;
                    break;
                }
            }
        }
        if !changed {
            break;
        }
    }

    // Charts; repair those whose projection overlaps itself. Where the overlap comes
    // from slanted triangles (an overhang), those move to their next-best axis; where
    // whole layers overlap (e.g. an ear's rim over its own plate), the chart is split
    // by depth along its axis. Repeat until every chart is one-to-one.
    let mut pending: Vec<Chart> = components(&all, &adj, &label)
        .into_iter()
        .map(|tris| Chart {
            axis: (label[tris[0] as usize] % 6) as usize,
            tris,
        })
        .collect();
    pending.reverse();
    let mut charts = Vec::new();
    let mut part = vec![0u32; tris.len()];
    let mut budget = 400;
    while let Some(chart) = pending.pop() {
        let Some(pairs) = self_overlaps(pos, tris, &chart) else {
            charts.push(chart);
            continue;
        };
        if budget == 0 || chart.tris.len() < 2 {
            log::warn!("built-in head: a UV chart still overlaps itself");
            charts.push(chart);
            continue;
        }
        budget -= 1;
        let axis = AXES[chart.axis];
        let facing = |t: u32| normals[t as usize].dot(axis);
        let losers: Vec<u32> = pairs
            .iter()
            .map(|&(a, b)| if facing(a) <= facing(b) { a } else { b })
            .collect();
        let pieces = if losers.iter().all(|&t| facing(t) < 0.7) {
            for &t in &losers {
                let n = normals[t as usize];
                let next = (0..6)
                    .filter(|&a| a != chart.axis)
                    .max_by(|&a, &b| n.dot(AXES[a]).total_cmp(&n.dot(AXES[b])))
                    .unwrap_or(chart.axis);
                label[t as usize] = (label[t as usize] / 6) * 6 + next as u32;
            }
            components(&chart.tris, &adj, &label)
        } else {
            let depth = |t: u32| {
                tris[t as usize]
                    .iter()
                    .map(|&i| pos[i as usize].dot(axis))
                    .sum::<f32>()
                    / 3.0
            };
            let mut mids: Vec<f32> = pairs
                .iter()
                .map(|&(a, b)| 0.5 * (depth(a) + depth(b)))
                .collect();
            mids.sort_by(f32::total_cmp);
            let split = mids[mids.len() / 2];
            for &t in &chart.tris {
                part[t as usize] = u32::from(depth(t) >= split);
            }
            components(&chart.tris, &adj, &part)
        };
        let pieces = if pieces.len() < 2 {
            // Cannot happen (the overlapping triangles end up apart); halve anyway.
            let half = chart.tris.len() / 2;
            vec![chart.tris[..half].to_vec(), chart.tris[half..].to_vec()]
        } else {
            pieces
        };
        for tris in pieces.into_iter().rev() {
            let axis = (label[tris[0] as usize] % 6) as usize;
            pending.push(Chart { axis, tris });
        }
    }
    charts
}

/// Rasterises a chart's projection at `OVERLAP_CHECK_MM`; returns the pairs of
/// triangles (mesh ids) that cover the same sample, if any.
fn self_overlaps(pos: &[Vec3], tris: &[[u32; 3]], chart: &Chart) -> Option<Vec<(u32, u32)>> {
    let uv: Vec<[Vec2; 3]> = chart
        .tris
        .iter()
        .map(|&t| tris[t as usize].map(|i| project(chart.axis, pos[i as usize]) / OVERLAP_CHECK_MM))
        .collect();
    let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    for t in &uv {
        for p in t {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
    }
    let w = (hi.x - lo.x).ceil() as usize + 2;
    let h = (hi.y - lo.y).ceil() as usize + 2;
    let mut owner = vec![u32::MAX; w * h];
    let mut pairs = Vec::new();
    for (k, t) in uv.iter().enumerate() {
        let t = t.map(|p| p - lo);
        let id = chart.tris[k];
        raster_triangle(&t, w, h, 1e-3, |x, y, _| {
            let o = &mut owner[y * w + x];
            if *o != u32::MAX && *o != id && pairs.len() < 4096 {
                pairs.push((*o, id));
            }
            *o = id;
        });
    }
    pairs.sort_unstable();
    pairs.dedup();
    (!pairs.is_empty()).then_some(pairs)
}

pub(super) struct Packing {
    pub(super) texels_per_mm: f32,
    /// Per chart: projected-mm minimum and texel offset of that minimum.
    min_mm: Vec<Vec2>,
    offset: Vec<Vec2>,
}

/// Shelf-packs the charts (tallest first) at the largest common scale that fits,
/// keeping `pad` texels free round each chart: ≥ 2·pad + 1 texel centres between
/// the texels of two charts.
pub(super) fn pack_charts(
    pos: &[Vec3],
    tris: &[[u32; 3]],
    charts: &[Chart],
    size: u32,
    pad: u32,
) -> Packing {
    let mut min_mm = Vec::with_capacity(charts.len());
    let mut ext = Vec::with_capacity(charts.len());
    for c in charts {
        let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
        for &t in &c.tris {
            for &i in &tris[t as usize] {
                let p = project(c.axis, pos[i as usize]);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        min_mm.push(lo);
        ext.push(hi - lo);
    }
    let mut order: Vec<usize> = (0..charts.len()).collect();
    order.sort_by(|&a, &b| ext[b].y.total_cmp(&ext[a].y).then(a.cmp(&b)));
    let n = size as f32;
    let padf = pad as f32;
    let place = |s: f32| -> Option<Vec<Vec2>> {
        let mut offset = vec![Vec2::ZERO; charts.len()];
        let (mut x, mut y, mut shelf) = (0.0f32, 0.0f32, 0.0f32);
        for &c in &order {
            let w = (ext[c].x * s).ceil() + 1.0 + 2.0 * padf;
            let h = (ext[c].y * s).ceil() + 1.0 + 2.0 * padf;
            if x + w > n {
                x = 0.0;
                y += shelf;
                shelf = 0.0;
            }
            if x + w > n || y + h > n {
                return None;
            }
            offset[c] = Vec2::new(x + padf + 0.5, y + padf + 0.5);
            x += w;
            shelf = shelf.max(h);
        }
        Some(offset)
    };
    let (mut lo, mut hi) = (1e-4f32, n);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if place(mid).is_some() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let offset = place(lo).unwrap_or_else(|| vec![Vec2::ZERO; charts.len()]);
    Packing {
        texels_per_mm: lo,
        min_mm,
        offset,
    }
}

/// Duplicates vertices per chart (seams) and assigns atlas UVs.
pub(super) fn split_mesh(
    pos: &[Vec3],
    nrm: &[Vec3],
    tris: &[[u32; 3]],
    charts: &[Chart],
    packing: &Packing,
    size: u32,
) -> Mesh {
    let mut mesh = Mesh {
        name: "builtin-head".into(),
        ..Mesh::default()
    };
    let mut stamp = vec![u32::MAX; pos.len()];
    let mut local = vec![0u32; pos.len()];
    let n = size as f32;
    for (ci, c) in charts.iter().enumerate() {
        for &t in &c.tris {
            for &v in &tris[t as usize] {
                let vi = v as usize;
                if stamp[vi] != ci as u32 {
                    stamp[vi] = ci as u32;
                    local[vi] = mesh.positions.len() as u32;
                    let texel = packing.offset[ci]
                        + (project(c.axis, pos[vi]) - packing.min_mm[ci]) * packing.texels_per_mm;
                    mesh.positions.push(pos[vi]);
                    mesh.normals.push(nrm[vi]);
                    mesh.uvs.push((texel / n).clamp(Vec2::ZERO, Vec2::ONE));
                }
                mesh.indices.push(local[vi]);
            }
        }
    }
    mesh
}

/// Per-vertex tangents from the UV parameterisation: per-triangle ∂p/∂u and ∂p/∂v
/// accumulated, then Gram–Schmidt against the normal; w = handedness of (T, B, N).
pub(super) fn compute_tangents(mesh: &Mesh) -> Vec<Vec4> {
    let n = mesh.positions.len();
    let mut tan = vec![Vec3::ZERO; n];
    let mut bit = vec![Vec3::ZERO; n];
    let mut face_n = vec![Vec3::ZERO; n];
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let (e1, e2) = (
            mesh.positions[b] - mesh.positions[a],
            mesh.positions[c] - mesh.positions[a],
        );
        let (d1, d2) = (mesh.uvs[b] - mesh.uvs[a], mesh.uvs[c] - mesh.uvs[a]);
        let r = d1.perp_dot(d2);
        if r.abs() < 1e-20 {
            continue;
        }
        let tu = (e1 * d2.y - e2 * d1.y) / r;
        let tv = (e2 * d1.x - e1 * d2.x) / r;
        // Weight by the UV area so each triangle counts by its size.
        let w = r.abs();
        for v in [a, b, c] {
            tan[v] += tu * w;
            bit[v] += tv * w;
            face_n[v] += e1.cross(e2);
        }
    }
    (0..n)
        .map(|i| {
            let nn = mesh.normals[i];
            let t = (tan[i] - nn * nn.dot(tan[i]))
                .try_normalize()
                .unwrap_or_else(|| nn.any_orthonormal_vector());
            // Handedness from the faces' own orientation (robust where the shading
            // normal of a sub-cell feature disagrees with its faces).
            let gn = face_n[i].try_normalize().unwrap_or(nn);
            let w = if gn.dot(tan[i].cross(bit[i])) < 0.0 {
                -1.0
            } else {
                1.0
            };
            t.extend(w)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::tests::{head, uv_texels};
    use super::*;

    /// Chart id of every triangle: connected components through shared vertex ids
    /// (vertices are duplicated per chart, so charts never share one).
    fn chart_of_triangle(mesh: &Mesh) -> Vec<u32> {
        let mut parent: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        fn find(p: &mut [u32], mut x: u32) -> u32 {
            while p[x as usize] != x {
                p[x as usize] = p[p[x as usize] as usize];
                x = p[x as usize];
            }
            x
        }
        for t in mesh.indices.chunks_exact(3) {
            for k in 1..3 {
                let (a, b) = (find(&mut parent, t[0]), find(&mut parent, t[k]));
                parent[a as usize] = b;
            }
        }
        mesh.indices
            .chunks_exact(3)
            .map(|t| find(&mut parent, t[0]))
            .collect()
    }

    #[test]
    fn uvs_are_in_range_and_never_flipped_or_degenerate() {
        let h = head();
        let n = h.texture_size as f32;
        assert!(h
            .mesh
            .uvs
            .iter()
            .all(|uv| uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all()));
        let mut min_area = f32::MAX;
        for t in h.mesh.indices.chunks_exact(3) {
            let uv = uv_texels(&h.mesh, t, n);
            // All charts keep one winding: negative signed area with v down.
            let area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
            assert!(area < 0.0, "flipped UV triangle");
            min_area = min_area.min(-area);
        }
        assert!(min_area > 1e-5, "degenerate UV triangle: {min_area} texel²");
    }

    #[test]
    fn charts_do_not_overlap_and_keep_a_gutter() {
        let h = head();
        let n = h.texture_size as usize;
        let chart = chart_of_triangle(&h.mesh);
        let mut owner = vec![u32::MAX; n * n];
        let mut overlaps = 0;
        for (t, c) in h.mesh.indices.chunks_exact(3).zip(&chart) {
            raster_triangle(&uv_texels(&h.mesh, t, n as f32), n, n, 1e-3, |x, y, _| {
                let o = &mut owner[y * n + x];
                if *o != u32::MAX {
                    overlaps += 1; // two triangles (same or other chart) on one texel
                }
                *o = *c;
            });
        }
        assert_eq!(overlaps, 0);
        // At least 8 empty texels between texels of different charts.
        for y in 0..n {
            for x in 0..n {
                let c = owner[y * n + x];
                if c == u32::MAX {
                    continue;
                }
                for yy in y.saturating_sub(8)..(y + 9).min(n) {
                    for xx in x.saturating_sub(8)..(x + 9).min(n) {
                        let o = owner[yy * n + xx];
                        assert!(o == u32::MAX || o == c, "gutter < 8 texels at ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn atlas_has_seams_and_real_stretch() {
        let h = head();
        let m = &h.mesh;
        // Seams: the same position appears with different UVs.
        let mut by_pos = std::collections::HashMap::<[u32; 3], Vec2>::new();
        let mut seams = 0;
        for (p, uv) in m.positions.iter().zip(&m.uvs) {
            let key = p.to_array().map(f32::to_bits);
            match by_pos.get(&key) {
                Some(prev) if *prev != *uv => seams += 1,
                Some(_) => {}
                None => {
                    by_pos.insert(key, *uv);
                }
            }
        }
        assert!(seams > 200, "{seams} seam vertices");
        assert!(h.chart_count >= 6);
        // Stretch over the face chart (the chart of the mid-forehead): mm per texel
        // varies with the slant of the surface.
        let chart = chart_of_triangle(m);
        let n = h.texture_size as f32;
        let forehead = Vec3::new(0.0, 50.0, 88.0);
        let tip = m
            .indices
            .chunks_exact(3)
            .map(|t| (m.positions[t[0] as usize] - forehead).length())
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap()
            .0;
        let mut ratio: Vec<f32> = m
            .indices
            .chunks_exact(3)
            .zip(&chart)
            .filter(|(_, &c)| c == chart[tip])
            .map(|(t, _)| {
                let p = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
                let uv = uv_texels(m, t, n);
                let a3 = (p[1] - p[0]).cross(p[2] - p[0]).length();
                let a2 = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
                (a3 / a2).sqrt()
            })
            .collect();
        assert!(
            ratio.len() > 5000,
            "face chart has {} triangles",
            ratio.len()
        );
        ratio.sort_by(f32::total_cmp);
        let (p2, p98) = (ratio[ratio.len() / 50], ratio[ratio.len() * 49 / 50]);
        assert!(p98 / p2 > 1.3, "stretch range {p2}..{p98} mm/texel");
        assert!((p2 - h.mm_per_texel).abs() < 0.1 * h.mm_per_texel);
    }

    #[test]
    fn tangents_are_orthonormal_and_consistently_handed() {
        let m = &head().mesh;
        let w0 = m.tangents[0].w;
        for (t, n) in m.tangents.iter().zip(&m.normals) {
            assert!((t.truncate().length() - 1.0).abs() < 1e-3);
            assert!(t.truncate().dot(*n).abs() < 1e-3);
            assert_eq!(t.w, w0);
        }
    }
}
