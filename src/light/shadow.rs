//! Shadow maps for the explicit lights (GPU Gems 3 §14.4.1 shadows the irradiance
//! pass with them): the mesh's depth seen from each shadowed light, one square tile
//! per light in a grid in one D32 atlas, read by shaders-glsl/common/lights.glsl
//! with 3×3 bilinear PCF, or for a source of angular size with soft shadows.

use crate::error::Result;
use crate::frame_inputs::{MeshBuffers, Vertex, SHADOW_FORMAT};
use crate::gpu::{GraphicsDesc, Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, Imported, LoadOp};
use crate::scene::LightSource;
use ash::vk;
use glam::camera::rh::{proj::vulkan as proj, view::look_at_mat4};
use glam::{Mat4, Vec2, Vec3, Vec4};
use std::sync::Arc;

/// Each light's frustum holds the mesh's bounding sphere grown by this factor, so
/// PCF taps at the rim stay inside the light's tile.
const FIT_MARGIN: f32 = 1.05;

/// A focus map is drawn only when it is at least this much finer than the
/// whole map: a second tile that gains less is not worth its draw.
const MIN_FOCUS_ZOOM: f32 = 1.5;

/// A shadowed light's two maps, in two neighbouring tiles of the atlas.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowMaps {
    /// Holds the mesh's bounding sphere, so every texel of the irradiance
    /// texture finds its shadow.
    pub whole: ShadowView,
    /// The window of `whole` that holds what the camera sees, at the same
    /// resolution: finer where the face is (`None`: it would not be
    /// [`MIN_FOCUS_ZOOM`]× finer). The shaders use it wherever a lookup and its
    /// filter fit inside it (common/lights.glsl, `shadow_map`).
    pub focus: Option<Focus>,
}

/// A square window of a whole map, in its normalised device coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Focus {
    pub view: ShadowView,
    /// Half the side (1: the whole map).
    pub half: f32,
    /// The depth of the nearest vertex in the window: no blocker of its soft
    /// shadows lies nearer the light, which bounds their blocker search.
    pub nearest: f32,
}

impl Focus {
    /// The window of `whole` (a `resolution`² map) around the `seen` points
    /// the camera sees, each grown by `margin_mm` (the diffusion's reach: light
    /// from just outside the view scatters into it), over the mesh of
    /// `vertices`; `None` when nothing is seen or the window would not be
    /// [`MIN_FOCUS_ZOOM`]× finer.
    pub fn fit(
        whole: &ShadowView,
        seen: &[Vec3],
        vertices: &[Vec3],
        margin_mm: f32,
        resolution: u32,
    ) -> Option<Self> {
        let ndc = |p: &Vec3| whole.view_proj.project_point3(*p);
        let lo = seen.iter().map(|p| ndc(p).truncate()).reduce(Vec2::min)?;
        let hi = seen.iter().map(|p| ndc(p).truncate()).reduce(Vec2::max)?;
        // Normalised coordinates per mm: a point light's at its nearest, where
        // a mm spans the most.
        let span_mm = resolution as f32 * whole.texel_mm * whole.near_mm.unwrap_or(1.0);
        let margin = Vec2::splat(2.0 * margin_mm / span_mm);
        let (lo, hi) = (
            (lo - margin).max(Vec2::NEG_ONE),
            (hi + margin).min(Vec2::ONE),
        );
        // Snapped, so that a small camera move gives the same window (the maps
        // are not drawn again) while one camera always gives one window: the
        // side up to a step of 2^(1/8), the centre to 1/16 of it, which moves
        // it by at most 1/32 of the side, within the 1/16 added first.
        let half = 0.5 * (hi - lo).max_element() * 17.0 / 16.0;
        let half = (8.0 * half.log2()).ceil().exp2().powf(1.0 / 8.0);
        if half * MIN_FOCUS_ZOOM > 1.0 {
            return None;
        }
        let step = half / 16.0;
        let centre = (0.5 * (lo + hi) / step).round() * step;
        // The square inside the map.
        let centre = centre.clamp(Vec2::splat(half - 1.0), Vec2::splat(1.0 - half));
        // Vertices a margin beyond the window too, for triangles that cross
        // its border.
        let reach = Vec2::splat(half) + margin;
        let nearest = vertices
            .iter()
            .map(ndc)
            .filter(|p| (p.truncate() - centre).abs().cmple(reach).all())
            .map(|p| p.z)
            .fold(1.0, f32::min)
            .max(0.0);
        Some(Self::window(whole, centre, half, nearest))
    }

    /// The window (`centre`, `half`) of `whole`: its clip space scaled by
    /// 1/half about the centre, depth and w unchanged (so depth range, near
    /// plane and what the shaders derive from them stay the whole map's).
    fn window(whole: &ShadowView, centre: Vec2, half: f32, nearest: f32) -> Self {
        let k = 1.0 / half;
        let zoom = Mat4::from_cols(
            Vec4::new(k, 0.0, 0.0, 0.0),
            Vec4::new(0.0, k, 0.0, 0.0),
            Vec4::Z,
            Vec4::new(-k * centre.x, -k * centre.y, 0.0, 1.0),
        );
        Self {
            view: ShadowView {
                view_proj: zoom * whole.view_proj,
                texel_mm: whole.texel_mm * half,
                ..*whole
            },
            half,
            nearest,
        }
    }
}

/// One light's shadow projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowView {
    /// World (mm) to the light's clip space (Vulkan: depth in [0, 1]).
    pub view_proj: Mat4,
    /// World size of one texel, mm: constant for a directional light; for a point
    /// light, per mm of distance from it. The shaders' acne offsets scale with it.
    pub texel_mm: f32,
    /// Depth range of the map, mm (far − near; depth is linear for a directional
    /// light), which the soft shadows turn blocker depths into distances with.
    pub depth_range_mm: f32,
    /// A point light's near plane, mm from it (its depth is perspective:
    /// [`ShadowView::thickness_mm`]); `None` for a directional light.
    pub near_mm: Option<f32>,
}

/// Columns and rows of the atlas's grid of `tiles` square tiles: ⌊√n⌋ rows,
/// as many columns as they need (8 lights: 4 × 2, no tile wasted).
pub fn atlas_grid(tiles: usize) -> (u32, u32) {
    let n = tiles.max(1);
    let rows = (n as f64).sqrt().floor() as usize;
    (n.div_ceil(rows) as u32, rows as u32)
}

/// What a source of angular radius `r` (radians) adds to the Beckmann lobe's
/// m² when its light is treated as a direction: the reflected direction spreads
/// over a disc of radius r, the half vector over r/2, a disc of slopes tan(r/2)
/// whose mean squared slope, tan²(r/2)/2, adds to m² (the variance of a
/// convolution is the sum). D stays normalised, so the energy does not change.
pub fn lobe_widening(r: f32) -> f32 {
    let t = (0.5 * r).tan();
    0.5 * t * t
}

impl ShadowView {
    /// The frustum of `light` that holds the sphere (`centre`, `radius`) in a
    /// `resolution`² map: orthographic for a directional light, a perspective
    /// cone for a point light. `None` for a point light inside the sphere, which
    /// no single map can hold (that needs a cube map).
    pub fn fit(light: LightSource, centre: Vec3, radius: f32, resolution: u32) -> Option<Self> {
        let r = radius.max(1e-3) * FIT_MARGIN;
        let res = resolution as f32;
        let up = |dir: Vec3| {
            if dir.y.abs() > 0.9 {
                Vec3::Z
            } else {
                Vec3::Y
            }
        };
        match light {
            LightSource::Directional(towards) => {
                let eye = centre + towards * 2.0 * r;
                let view = look_at_mat4(eye, centre, up(towards));
                let proj = proj::orthographic(-r, r, -r, r, r, 3.0 * r);
                Some(Self {
                    view_proj: proj * view,
                    texel_mm: 2.0 * r / res,
                    depth_range_mm: 2.0 * r,
                    near_mm: None,
                })
            }
            LightSource::Point(p) => {
                let d = p.distance(centre);
                if d <= r {
                    return None;
                }
                let half = (r / d).asin();
                let view = look_at_mat4(p, centre, up((p - centre) / d));
                let proj = proj::perspective(2.0 * half, 1.0, d - r, d + r);
                Some(Self {
                    view_proj: proj * view,
                    texel_mm: 2.0 * half.tan() / res,
                    depth_range_mm: 2.0 * r,
                    near_mm: Some(d - r),
                })
            }
        }
    }

    /// The distance, mm, a ray from the light travels from the surface stored
    /// at depth `stored` to a point at depth `depth` on the same ray, `dist` mm
    /// from a point light (unused for a directional one); 0 where the stored
    /// surface is not in front. The CPU copy of common/lights.glsl's
    /// `shadow_thickness` for one texel: a directional light's depth is linear
    /// over the range; a point light's perspective depth z is made the distance
    /// along the axis, n·f/(f − z(f − n)), and distances along one ray are in
    /// the ratio of the axial distances.
    pub fn thickness_mm(&self, stored: f32, depth: f32, dist: f32) -> f32 {
        let range = self.depth_range_mm;
        let t = match self.near_mm {
            None => (depth - stored) * range,
            Some(near) => {
                let far = near + range;
                let axial = |z: f32| near * far / (far - z * range);
                dist * (1.0 - axial(stored) / axial(depth))
            }
        };
        t.max(0.0)
    }

    /// World to (atlas u, v, depth) after the divide by w, for tile `tile` of
    /// `tiles` laid out row by row in the [`atlas_grid`].
    pub fn atlas_matrix(&self, tile: usize, tiles: usize) -> Mat4 {
        let (cols, rows) = atlas_grid(tiles);
        let (c, r) = (cols as f32, rows as f32);
        let (col, row) = ((tile as u32 % cols) as f32, (tile as u32 / cols) as f32);
        let bias = Mat4::from_cols(
            Vec4::new(0.5 / c, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 0.5 / r, 0.0, 0.0),
            Vec4::new(0.0, 0.0, 1.0, 0.0),
            Vec4::new((0.5 + col) / c, (0.5 + row) / r, 0.0, 1.0),
        );
        bias * self.view_proj
    }
}

/// The projections of the atlas's tiles, in order (`None`: a tile left empty).
fn tile_matrices(tiles: &[Option<ShadowView>]) -> Vec<Option<[f32; 16]>> {
    tiles
        .iter()
        .map(|v| v.map(|v| v.view_proj.to_cols_array()))
        .collect()
}

/// Renders the atlas: depth only, no culling (scanned meshes are not closed).
/// The mesh and the lights do not move within a render, so the atlas is drawn by
/// the first frame that needs it and kept.
pub struct ShadowPass {
    pipeline: Arc<Pipeline>,
    atlas: Arc<Image>,
    /// The shadowed lights' projections, in tile order (`None`: not drawn).
    matrices: Vec<Option<[f32; 16]>>,
    resolution: u32,
}

impl ShadowPass {
    /// The pass and atlas of `tiles` (light::lighting::Lighting::tiles;
    /// `None`: left empty), `resolution` texels a side; a 1×1 atlas when there
    /// are none, so the lighting shaders always have one to bind.
    pub fn new(
        pipelines: &Pipelines,
        tiles: &[Option<ShadowView>],
        resolution: u32,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        let pipeline = pipelines.graphics(&GraphicsDesc {
            vertex: "shadow.vert",
            fragment: "shadow.frag",
            color_formats: &[],
            depth_format: Some(SHADOW_FORMAT),
            depth_write: true,
            // Positions only.
            vertex_layout: Some(Vertex::position_layout()),
            cull_mode: vk::CullModeFlags::NONE,
            specialization: &[],
            alpha_blend: false,
        })?;
        let matrices = tile_matrices(tiles);
        let (cols, rows) = atlas_grid(matrices.len());
        let (w, h) = match matrices.len() {
            0 => (1, 1),
            _ => (cols * resolution, rows * resolution),
        };
        let atlas = Image::new(
            ctx,
            "shadow atlas",
            ImageDesc::new(w, h, SHADOW_FORMAT),
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        )?;
        Ok(Self {
            pipeline,
            atlas: Arc::new(atlas),
            matrices,
            resolution,
        })
    }

    /// The same lights turned (the environment's sources) or seen from
    /// elsewhere (the focus): new projections, as many tiles.
    pub fn set_tiles(&mut self, tiles: &[Option<ShadowView>]) {
        let matrices = tile_matrices(tiles);
        debug_assert_eq!(matrices.len(), self.matrices.len(), "the atlas's tiles");
        self.matrices = matrices;
    }

    /// The atlas as a graph image, kept for `key` (light::lighting's
    /// shadow key): drawn (pass `shadow maps`) by the first frame that needs it.
    pub fn pass(&self, g: &mut Graph, mesh: &Arc<MeshBuffers>, key: u64) -> ImageHandle {
        let (mut atlas, draw) = g.import_kept_image(
            "shadow atlas",
            Imported::Image(self.atlas.clone()),
            Access::ShaderSampled,
            key,
        );
        if draw {
            let (pipe, mesh) = (self.pipeline.clone(), mesh.clone());
            let (matrices, resolution) = (self.matrices.clone(), self.resolution);
            let (cols, _) = atlas_grid(matrices.len());
            g.simple_pass("shadow maps", &self.pipeline)
                .tag(super::TAG)
                .depth(&mut atlas, LoadOp::Clear([1.0; 4]))
                .record(move |cx| {
                    for (i, m) in matrices.iter().enumerate() {
                        let Some(m) = m else { continue };
                        let (col, row) = (i as u32 % cols, i as u32 / cols);
                        cx.set_viewport(col * resolution, row * resolution, resolution, resolution);
                        cx.push_constants(&pipe, m);
                        mesh.record_draw(cx);
                    }
                });
        }
        atlas
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project(m: Mat4, p: Vec3) -> Vec3 {
        m.project_point3(p)
    }

    #[test]
    fn the_bounding_sphere_fits_inside_each_tile() {
        let (c, r) = (Vec3::new(10.0, 20.0, -5.0), 100.0);
        let lights = [
            LightSource::Directional(Vec3::new(0.3, 0.8, 0.5).normalize()),
            LightSource::Directional(Vec3::Y),
            LightSource::Point(c + Vec3::new(300.0, 100.0, 400.0)),
        ];
        for (k, light) in lights.into_iter().enumerate() {
            let v = ShadowView::fit(light, c, r, 1024).unwrap();
            // Tiles 0, 2 and 4 of five: a 3 × 2 grid, tile 4 on the second row.
            let tile = 2 * k;
            let m = v.atlas_matrix(tile, 5);
            let (col, row) = ((tile % 3) as f32, (tile / 3) as f32);
            // Points on the sphere land in this tile with depth in (0, 1).
            for dir in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                let s = project(m, c + dir * r);
                let (u, w) = (s.x * 3.0 - col, s.y * 2.0 - row);
                assert!(
                    u > 0.0 && u < 1.0 && w > 0.0 && w < 1.0,
                    "{light:?} {dir} {s}"
                );
                assert!(s.z > 0.0 && s.z < 1.0, "{light:?} {dir} {s}");
            }
            // Depth grows away from the light.
            let towards = match light {
                LightSource::Directional(d) => d,
                LightSource::Point(p) => (p - c).normalize(),
            };
            assert!(project(m, c + towards * r).z < project(m, c).z);
            assert!(project(m, c).z < project(m, c - towards * r).z);
        }
        assert!(ShadowView::fit(LightSource::Point(c), c, r, 1024).is_none());
    }

    /// What the transmission reads: the distance between two points on one
    /// ray from the light, from their depths alone, for both kinds of light.
    #[test]
    fn thickness_from_depths_is_the_distance_along_the_ray() {
        let (c, r) = (Vec3::new(10.0, 20.0, -5.0), 100.0);
        let point = c + Vec3::new(300.0, 100.0, 400.0);
        for light in [
            LightSource::Directional(Vec3::new(0.3, 0.8, 0.5).normalize()),
            LightSource::Point(point),
        ] {
            let v = ShadowView::fit(light, c, r, 1024).unwrap();
            let m = v.atlas_matrix(0, 1);
            // A ray through the sphere, off the map's axis.
            let entry = c + Vec3::new(20.0, -30.0, 10.0);
            let dir = match light {
                LightSource::Directional(d) => -d,
                LightSource::Point(p) => (entry - p).normalize(),
            };
            for d in [0.5f32, 1.0, 2.0, 5.0, 40.0] {
                let x = entry + dir * d;
                let (front, back) = (project(m, entry), project(m, x));
                assert!((front.truncate() - back.truncate()).length() < 1e-5);
                let dist = match light {
                    LightSource::Point(p) => p.distance(x),
                    LightSource::Directional(_) => 1.0,
                };
                let t = v.thickness_mm(front.z, back.z, dist);
                assert!((t - d).abs() < 2e-3 * d.max(1.0), "{light:?}: {t} for {d}");
                assert_eq!(v.thickness_mm(back.z, front.z, dist), 0.0);
            }
        }
    }

    #[test]
    fn atlas_grids_are_nearly_square() {
        let grids: Vec<_> = (0..=8).map(atlas_grid).collect();
        assert_eq!(
            grids,
            [
                (1, 1),
                (1, 1),
                (2, 1),
                (3, 1),
                (2, 2),
                (3, 2),
                (3, 2),
                (4, 2),
                (4, 2)
            ]
        );
    }

    #[test]
    fn a_source_widens_the_lobe_by_its_slope_variance() {
        // The sun (0.53° across) adds nothing visible to m = 0.3; a 20° softbox
        // adds tan²(5°)/2.
        assert!(lobe_widening(0.265f32.to_radians()) < 1e-5);
        let t = 5f32.to_radians().tan();
        assert!((lobe_widening(10f32.to_radians()) - 0.5 * t * t).abs() < 1e-7);
        assert_eq!(lobe_widening(0.0), 0.0);
    }

    /// A patch the camera sees, 40 mm across, in a mesh 200 mm in radius: its
    /// window lands it inside the focus tile at a finer texel, with the whole
    /// map's depths, and its nearest vertex bounds every depth in the window.
    #[test]
    fn the_focus_window_holds_what_the_camera_sees_finer() {
        let (c, r) = (Vec3::ZERO, 200.0);
        let patch: Vec<Vec3> = (0..25)
            .map(|k| Vec3::new((k % 5) as f32 * 10.0 - 20.0, (k / 5) as f32 * 10.0, 60.0))
            .collect();
        let blocker = Vec3::new(0.0, 20.0, 120.0);
        let far = Vec3::new(150.0, -100.0, 100.0);
        let vertices: Vec<Vec3> = patch.iter().copied().chain([blocker, far]).collect();
        for light in [
            LightSource::Directional(Vec3::new(0.2, 0.3, 1.0).normalize()),
            LightSource::Point(Vec3::new(100.0, 200.0, 900.0)),
        ] {
            let whole = ShadowView::fit(light, c, r, 1024).unwrap();
            let f = Focus::fit(&whole, &patch, &vertices, 5.0, 1024).unwrap();
            assert!(f.half < 0.25, "{light:?}: {}", f.half);
            assert!((f.view.texel_mm - whole.texel_mm * f.half).abs() < 1e-6);
            let (m, m_whole) = (f.view.atlas_matrix(1, 2), whole.atlas_matrix(0, 2));
            for p in &patch {
                let (s, s_whole) = (m.project_point3(*p), m_whole.project_point3(*p));
                assert!(
                    s.x > 0.5 && s.x < 1.0 && s.y > 0.0 && s.y < 1.0,
                    "{light:?}: {s}"
                );
                assert!((s.z - s_whole.z).abs() < 1e-6, "{light:?}: depth");
                assert!(f.nearest <= s.z);
            }
            // The blocker between the patch and the light is the nearest; the
            // far vertex outside the window does not count.
            let blocker_depth = m.project_point3(blocker).z;
            assert!(
                (f.nearest - blocker_depth).abs() < 1e-6,
                "{light:?}: {}",
                f.nearest
            );
            assert!(m.project_point3(far).x > 1.0 || m.project_point3(far).y < 0.0);
        }
    }

    #[test]
    fn no_focus_where_the_camera_sees_nearly_everything_or_nothing() {
        let (c, r) = (Vec3::ZERO, 100.0);
        let whole = ShadowView::fit(LightSource::Directional(Vec3::Z), c, r, 512).unwrap();
        let rim = [Vec3::new(-90.0, -90.0, 0.0), Vec3::new(90.0, 90.0, 0.0)];
        assert!(Focus::fit(&whole, &rim, &rim, 0.0, 512).is_none());
        assert!(Focus::fit(&whole, &[], &rim, 0.0, 512).is_none());
        // A patch a third of the map across is 1.5× finer or more.
        let third = [Vec3::new(-30.0, -30.0, 0.0), Vec3::new(30.0, 30.0, 0.0)];
        assert!(Focus::fit(&whole, &third, &third, 0.0, 512).is_some());
    }

    /// Small camera moves keep the window (no new maps); leaving it or
    /// zooming in does not.
    #[test]
    fn a_window_stays_while_the_view_moves_a_little() {
        let whole =
            ShadowView::fit(LightSource::Directional(Vec3::Z), Vec3::ZERO, 100.0, 512).unwrap();
        let at = |x: f32, size: f32| {
            let patch = [Vec3::new(x, 0.0, 0.0), Vec3::new(x + size, size, 0.0)];
            Focus::fit(&whole, &patch, &patch, 0.0, 512).unwrap()
        };
        let f = at(0.0, 30.0);
        assert_eq!(f, at(0.2, 30.0));
        assert_eq!(f, at(0.0, 30.3));
        assert_ne!(f, at(5.0, 30.0), "moved off");
        assert_ne!(f, at(0.0, 20.0), "zoomed in");
        // Snapping only grows the window, by 1/16 and at most a step of
        // 2^(1/8): 15 mm of the map's 100 · FIT_MARGIN mm, half a side each.
        let half_mm = f.half * 100.0 * FIT_MARGIN;
        let least = 15.0 * 17.0 / 16.0;
        assert!(
            half_mm >= least && half_mm <= least * 2f32.powf(0.125),
            "{half_mm}"
        );
    }
}
