//! A lasting render (the viewer's `render::session`): what a session computes once
//! and keeps (SH, stretch maps, the prefiltered environment, the shadow atlas and
//! soft visibility) is computed by the first frame that needs it, whatever view
//! came first, and frames that reuse it are the frames that computed it.

use crate::common;

use dermis::gpu::{Context, Image};
use dermis::graph::upload::Readback;
use dermis::graph::{Access, Executor, Graph, Imported};
use dermis::render::session::Session;
use dermis::render::View;
use dermis::scene::file::load_scene;
use dermis::scene::Scene;
use std::sync::Arc;

/// The RGBA8 pixels of a session's displayable image.
fn pixels(ctx: &Arc<Context>, image: &Arc<Image>) -> Vec<u8> {
    let (w, h) = (image.desc.width as u64, image.desc.height as u64);
    let readback = Readback::new(ctx, "readback", w * h * 4).unwrap();
    let mut g = Graph::new();
    let handle = g.import_image(
        "session image",
        Imported::Image(image.clone()),
        Some(Access::FragmentSampled),
        Some(Access::FragmentSampled),
    );
    readback.image_pass(&mut g, &handle);
    let mut executor = Executor::new(ctx, 1).unwrap();
    let compiled = executor.compile(g).unwrap();
    executor.submit(compiled).unwrap();
    executor.finish().unwrap();
    readback.bytes().unwrap().to_vec()
}

/// The default scene (the scan under royal_esplanade, two extracted lamps) at
/// `size`, irradiance 256².
fn scan((width, height): (u32, u32)) -> Scene {
    let mut file = load_scene(std::path::Path::new("assets/default.toml")).unwrap();
    (file.render.width, file.render.height) = (width, height);
    file.render.irradiance_resolution = 256;
    Scene::load(file).unwrap()
}

/// Bytes that differ between two images of one size.
fn differing(a: &[u8], b: &[u8]) -> usize {
    assert_eq!(a.len(), b.len());
    a.iter().zip(b).filter(|(x, y)| x != y).count()
}

#[test]
fn a_session_computes_what_it_keeps_when_a_view_first_needs_it() {
    let scene = scan((64, 80));
    common::with_gpu(|ctx| {
        let mut fresh = Session::new(ctx, scene.clone()).unwrap();
        assert!(fresh.extracted_lights() > 0);
        let (first, _) = fresh.render(&View::FINAL).unwrap();
        let expected = pixels(ctx, &first);
        // The next frame reuses all that is kept: the same image.
        let (again, _) = fresh.render(&View::FINAL).unwrap();
        assert_eq!(
            differing(&pixels(ctx, &again), &expected),
            0,
            "a frame on what was kept"
        );
        // Views that skip the chain, the prefilter, or the shadows and the
        // chain; then the full frame computes what they skipped.
        for view in [
            View::named("depth"),
            View::named("direct"),
            View::named("irradiance"),
            View::named("prefiltered"),
        ] {
            let mut session = Session::new(ctx, scene.clone()).unwrap();
            session.render(&view).unwrap();
            let (image, _) = session.render(&View::FINAL).unwrap();
            let n = differing(&pixels(ctx, &image), &expected);
            assert_eq!(n, 0, "final after {}: bytes differing", view.name());
        }
    });
}

#[test]
fn turning_the_environment_in_a_session_is_a_fresh_session_at_that_angle() {
    let scene = scan((64, 80));
    let mut turned = scene.clone();
    turned.file.environment.rotation_deg = 120.0;
    common::with_gpu(|ctx| {
        let mut fresh = Session::new(ctx, turned.clone()).unwrap();
        let (image, _) = fresh.render(&View::FINAL).unwrap();
        let expected = pixels(ctx, &image);
        let mut session = Session::new(ctx, scene.clone()).unwrap();
        let (image, _) = session.render(&View::FINAL).unwrap();
        let before = pixels(ctx, &image);
        session.set_rotation(120.0).unwrap();
        let (image, _) = session.render(&View::FINAL).unwrap();
        let after = pixels(ctx, &image);
        assert_eq!(differing(&after, &expected), 0, "turned in the session");
        // The lamps moved: the image changed.
        let changed = differing(&before, &after);
        assert!(
            changed > before.len() / 4,
            "{changed} of {} bytes",
            before.len()
        );
    });
}

#[test]
fn a_session_shows_uv_views_as_render_writes_them() {
    // The scan's maps have their UV origin at the bottom left: both paths flip
    // its UV-space views (tests/it/views.rs checks render's against the UVs).
    let scene = scan((64, 80));
    let (shown, written) = common::with_gpu(|ctx| {
        let mut session = Session::new(ctx, scene.clone()).unwrap();
        let (image, _) = session.render(&View::named("irradiance")).unwrap();
        let opts = dermis::render::RenderOptions {
            view: View::named("irradiance"),
            ..Default::default()
        };
        let out = dermis::render::render_scene(ctx, &scene, &opts).unwrap();
        (pixels(ctx, &image), out.rgba8)
    });
    let mut upside_down = written.clone();
    dermis::scene::texture::flip_rows(&mut upside_down, 256 * 4);
    let mean = |a: &[u8], b: &[u8]| {
        let rgb = |i: usize| i % 4 != 3;
        let (sum, n) = a
            .iter()
            .zip(b)
            .enumerate()
            .filter(|(i, _)| rgb(*i))
            .fold((0.0, 0.0), |(s, n), (_, (&x, &y))| {
                (s + (x as f64 - y as f64).abs(), n + 1.0)
            });
        sum / n
    };
    let (same, flipped) = (mean(&shown, &written), mean(&shown, &upside_down));
    println!(
        "mean |session - render|: {same:.3} 8-bit steps; against render flipped: {flipped:.3}"
    );
    // The session meters and encodes on the GPU, render on the CPU: the same
    // functions (tests/it/tonemap.rs), at most rounding apart.
    assert!(same < 0.5 && flipped > 20.0, "{same} {flipped}");
}

#[test]
fn a_session_after_set_camera_is_a_fresh_session_with_that_camera() {
    // The window grew and the camera moved in: the frame is metered over all of
    // its pixels, and the depth view spans the mesh as seen from there.
    let small = scan((48, 60));
    let mut moved = small.clone();
    (moved.file.render.width, moved.file.render.height) = (96, 120);
    let c = &mut moved.camera;
    c.position = c.target + 0.7 * (c.position - c.target);
    common::with_gpu(|ctx| {
        for view in [View::FINAL, View::named("depth")] {
            let mut fresh = Session::new(ctx, moved.clone()).unwrap();
            let (image, _) = fresh.render(&view).unwrap();
            let expected = pixels(ctx, &image);
            let mut session = Session::new(ctx, small.clone()).unwrap();
            session.render(&view).unwrap();
            session.set_camera(moved.camera, (96, 120)).unwrap();
            let (image, _) = session.render(&view).unwrap();
            let n = differing(&pixels(ctx, &image), &expected);
            assert_eq!(n, 0, "{}: bytes differing", view.name());
        }
    });
}

#[test]
fn a_session_takes_post_and_rotation_changes_and_needs_a_new_one_for_the_rest() {
    use dermis::scene::file::{Gamma, ToneCurve};
    let scene = scan((48, 60));
    let mut live = scene.clone();
    let r = &mut live.file.render;
    (r.gamma, r.tone_curve, r.exposure) = (Gamma::Power(1.8), ToneCurve::Aces, Some(0.5));
    (r.glow, r.skybox) = (true, false);
    live.file.environment.rotation_deg = 40.0;
    common::with_gpu(|ctx| {
        let mut fresh = Session::new(ctx, live.clone()).unwrap();
        let (image, _) = fresh.render(&View::FINAL).unwrap();
        let expected = pixels(ctx, &image);
        let mut session = Session::new(ctx, scene.clone()).unwrap();
        session.render(&View::FINAL).unwrap();
        assert!(
            session.update(&live.file).unwrap(),
            "post and rotation are live"
        );
        let (image, _) = session.render(&View::FINAL).unwrap();
        let n = differing(&pixels(ctx, &image), &expected);
        assert_eq!(n, 0, "bytes differing from a fresh session");
        // The irradiance resolution is not.
        let mut other = live.file.clone();
        other.render.irradiance_resolution = 512;
        assert!(!session.update(&other).unwrap());
    });
}
