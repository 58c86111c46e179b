//! The render graph on a real device: upload → clear → compute blur (two passes)
//! → graphics pass → readback, checked texel by texel against a CPU computation;
//! and the foreground gate background executors wait for.

use crate::common;

use ash::vk;
use dermis::gpu::{Buffer, Context, ImageDesc, MemoryLocation};
use dermis::graph::upload::Readback;
use dermis::graph::{Access, Clock, Compiled, Executor, Graph, Imported, LoadOp};
use dermis::testscene::{CompositePush, TestScene, HALF};
use std::sync::Arc;

const W: usize = 45;
const H: usize = 38;
const RADIUS: i32 = 4;
const SIGMA: f32 = 2.0;
const SPLIT: usize = 29;
const CLEAR: [f32; 4] = [0.125, 0.25, 0.5, 1.0];
const SCALE: f32 = 0.5;
const BIAS: f32 = 0.25;

/// CPU reference of one blur direction, clamp-to-edge, the shader's weights,
/// rounded to f16 as the RGBA16F target stores it.
fn blur_cpu(src: &[f32], dir: (i32, i32)) -> Vec<f32> {
    let mut out = vec![0.0; src.len()];
    let weights: Vec<f32> = (-RADIUS..=RADIUS)
        .map(|i| (-((i * i) as f32) / (2.0 * SIGMA * SIGMA)).exp())
        .collect();
    let total: f32 = weights.iter().sum();
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            for c in 0..4 {
                let mut sum = 0.0;
                for (k, w) in weights.iter().enumerate() {
                    let i = k as i32 - RADIUS;
                    let qx = (x + i * dir.0).clamp(0, W as i32 - 1) as usize;
                    let qy = (y + i * dir.1).clamp(0, H as i32 - 1) as usize;
                    sum += w * src[(qy * W + qx) * 4 + c];
                }
                out[(y as usize * W + x as usize) * 4 + c] = common::round_f16(sum / total);
            }
        }
    }
    out
}

fn expected(input: &[f32]) -> Vec<f32> {
    let blurred = blur_cpu(&blur_cpu(input, (1, 0)), (0, 1));
    let mut out = vec![0.0; W * H * 4];
    for y in 0..H {
        for x in 0..W {
            for (c, clear) in CLEAR.iter().enumerate() {
                let i = (y * W + x) * 4 + c;
                out[i] = if x < SPLIT {
                    common::round_f16(blurred[i] * SCALE + BIAS)
                } else {
                    *clear
                };
            }
        }
    }
    out
}

struct Chain {
    scene: TestScene,
    staging: Arc<Buffer>,
    readback: Readback,
}

fn chain(ctx: &Arc<Context>, input: &[f32]) -> Chain {
    let bytes = (W * H * 8) as u64;
    let mut staging = Buffer::new(
        ctx,
        "staging",
        bytes,
        vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )
    .unwrap();
    staging
        .mapped_mut()
        .unwrap()
        .copy_from_slice(&common::to_f16_bytes(input));
    let readback = Readback::new(ctx, "readback", bytes).unwrap();
    Chain {
        scene: TestScene::new(ctx).unwrap(),
        staging: Arc::new(staging),
        readback,
    }
}

fn build(ex: &mut Executor, c: &Chain) -> Compiled {
    let desc = ImageDesc::new(W as u32, H as u32, HALF);
    let mut g = Graph::new();
    // Host writes before vkQueueSubmit are visible to the device: nothing to wait for.
    let staging = g.import_buffer("staging", Imported::Buffer(c.staging.clone()), None, None);
    let mut input = g.create_image("input", desc);
    let mut p = g.add_pass("upload");
    let src = p.read_buffer(&staging, Access::TransferSrc);
    let dst = p.write(&mut input, Access::TransferDst);
    p.record(move |cx| cx.copy_buffer_to_image(src, dst));

    let mut target = g.create_image("target", desc);
    let mut p = g.add_pass("clear");
    let t = p.write(&mut target, Access::TransferDst);
    p.record(move |cx| cx.clear_image(t, CLEAR));

    let blurred = c.scene.blur(&mut g, &input, RADIUS, SIGMA);
    let push = CompositePush {
        scale: SCALE,
        bias: BIAS,
        split_x: SPLIT as f32,
        encode_srgb: 0,
    };
    c.scene
        .composite(&mut g, &blurred, &mut target, LoadOp::Load, push);
    c.readback.image_pass(&mut g, &target);
    ex.compile(g).unwrap()
}

fn max_error(got: &[f32], want: &[f32]) -> f32 {
    got.iter()
        .zip(want)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max)
}

#[test]
fn chain_matches_cpu_reference_over_frames() {
    let input = common::pattern(W * H * 4, 7);
    let want = expected(&input);
    common::with_gpu(|ctx| {
        let c = chain(ctx, &input);
        let mut ex = Executor::new(ctx, 2).unwrap();
        // Three frames through two frames in flight: pooled images are reused and
        // the first barrier of each frame must wait for the previous frame.
        let mut reports = Vec::new();
        for _ in 0..3 {
            let compiled = build(&mut ex, &c);
            reports.extend(ex.submit(compiled).unwrap());
        }
        reports.extend(ex.finish().unwrap());
        assert_eq!(reports.len(), 3, "one report per frame");
        let got = common::from_f16_bytes(c.readback.bytes().unwrap());
        let err = max_error(&got, &want);
        println!("max |GPU - CPU| = {err:e}");
        // Values lie in [0.25, 0.75] where an f16 ulp is 2^-11 ≈ 4.9e-4; two rounding
        // stages with a different summation order allow a few ulps, a wrong tap many.
        assert!(err <= 2e-3, "max error {err}");
        // The right part kept the clear colour (clear → LoadOp::Load worked).
        let right = &got[(W - 1) * 4..W * 4];
        assert_eq!(right, &CLEAR);
    });
}

#[test]
fn the_check_can_fail_a_wrong_blur_is_detected() {
    // Guards the reference itself: a blur of a different width must not match.
    let input = common::pattern(W * H * 4, 7);
    let want = expected(&input);
    let identity: Vec<f32> = (0..W * H * 4)
        .map(|i| {
            if (i / 4) % W < SPLIT {
                common::round_f16(input[i] * SCALE + BIAS)
            } else {
                CLEAR[i % 4]
            }
        })
        .collect();
    assert!(max_error(&identity, &want) > 0.05);
}

#[test]
fn sync_validation_catches_a_missing_barrier() {
    let input = common::pattern(W * H * 4, 3);
    let (_, log) = common::with_gpu_log(|ctx| {
        let c = chain(ctx, &input);
        let mut ex = Executor::new(ctx, 2).unwrap();
        // One command buffer per frame, so the hazard lies within one submission.
        ex.set_clock(Clock::GpuTimestamp).unwrap();
        // First a correct frame, so the only fault is the one we make.
        let ok = build(&mut ex, &c);
        ex.submit(ok).unwrap();
        ex.finish().unwrap();
        assert_eq!(ctx.validation().unwrap().count(), 0);
        let mut broken = build(&mut ex, &c);
        // Keep blur_v's layout transition of the horizontal blur's output but drop
        // its first synchronisation scope: the transition now races the write.
        let tmp = broken
            .plan
            .resources
            .iter()
            .position(|r| r.name == "blur_tmp")
            .unwrap();
        let blur_v = broken
            .plan
            .passes
            .iter_mut()
            .find(|p| p.name == "blur_v")
            .unwrap();
        let barrier = blur_v
            .barriers
            .iter_mut()
            .find(|b| b.resource == tmp)
            .unwrap();
        barrier.src_stage = vk::PipelineStageFlags2::NONE;
        barrier.src_access = vk::AccessFlags2::NONE;
        ex.submit(broken).unwrap();
        ex.finish().unwrap();
    });
    let messages = log.messages();
    assert!(
        messages.iter().any(|m| m.contains("SYNC-HAZARD")),
        "expected a synchronization hazard, got: {messages:#?}"
    );
}

#[test]
fn simple_pass_declarations_are_checked_against_the_shader() {
    common::with_gpu(|ctx| {
        let scene = TestScene::new(ctx).unwrap();
        let desc = ImageDesc::new(16, 16, HALF);
        let compile = |build: &dyn Fn(&mut Graph)| {
            let mut g = Graph::new();
            build(&mut g);
            let mut ex = Executor::new(ctx, 1).unwrap();
            ex.compile(g).err().map(|e| e.to_string())
        };
        // test_blur.comp: binding 0 sampled, binding 1 storage, 16 bytes of constants.
        let push = dermis::testscene::BlurPush {
            dir: [1, 0],
            radius: 1,
            sigma: 1.0,
        };
        let right = compile(&|g| {
            let mut src = g.create_image("src", desc);
            g.simple_pass("fill", &scene.pattern)
                .store(&mut src)
                .constants(&[16u32, 16])
                .dispatch([16, 16, 1]);
            let mut dst = g.create_image("dst", desc);
            g.simple_pass("blur", &scene.blur)
                .sample(&src, &scene.sampler)
                .store(&mut dst)
                .constants(&push)
                .dispatch([16, 16, 1]);
        });
        assert_eq!(right, None);
        let swapped = compile(&|g| {
            let mut src = g.create_image("src", desc);
            g.simple_pass("fill", &scene.pattern)
                .store(&mut src)
                .constants(&[16u32, 16])
                .dispatch([16, 16, 1]);
            let mut dst = g.create_image("dst", desc);
            g.simple_pass("swapped", &scene.blur)
                .store(&mut dst)
                .sample(&src, &scene.sampler)
                .constants(&push)
                .dispatch([16, 16, 1]);
        })
        .expect("binding types are checked");
        assert!(swapped.contains("\"swapped\""), "{swapped}");
        assert!(
            swapped.contains("binding 0 is declared STORAGE_IMAGE"),
            "{swapped}"
        );
        let short = compile(&|g| {
            let mut src = g.create_image("src", desc);
            g.simple_pass("fill", &scene.pattern)
                .store(&mut src)
                .constants(&[16u32])
                .dispatch([16, 16, 1]);
        })
        .expect("constant sizes are checked");
        assert!(short.contains("pushes 4 bytes"), "{short}");
        let missing = compile(&|g| {
            g.simple_pass("empty", &scene.pattern)
                .constants(&[16u32, 16])
                .dispatch([16, 16, 1]);
        })
        .expect("missing bindings are checked");
        assert!(missing.contains("declares 0 bindings"), "{missing}");
    });
}

#[test]
fn a_background_executor_does_not_submit_while_the_foreground_is_held() {
    let input = common::pattern(W * H * 4, 3);
    common::with_gpu(|ctx| {
        let c = chain(ctx, &input);
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.set_background();
        let compiled = build(&mut ex, &c);
        let submitted = std::sync::atomic::AtomicBool::new(false);
        std::thread::scope(|s| {
            let foreground = ctx.foreground();
            let worker = s.spawn(|| {
                ex.submit(compiled).unwrap();
                ex.finish().unwrap();
                submitted.store(true, std::sync::atomic::Ordering::SeqCst);
            });
            // Ample time for an unblocked submission of this tiny graph.
            std::thread::sleep(std::time::Duration::from_millis(300));
            assert!(
                !submitted.load(std::sync::atomic::Ordering::SeqCst),
                "submitted while the foreground was held"
            );
            drop(foreground);
            worker.join().unwrap();
        });
        assert!(submitted.into_inner());
    });
}

#[test]
fn a_pipeline_is_built_once_per_shader_and_constants() {
    use dermis::gpu::{GraphicsDesc, Pipelines};
    common::with_gpu(|ctx| {
        let p = Pipelines::new(ctx);
        let a = p.compute("blur.comp", &[7]).unwrap();
        let again = p.compute("blur.comp", &[7]).unwrap();
        assert!(Arc::ptr_eq(&a, &again));
        let other = p.compute("blur.comp", &[0]).unwrap();
        assert!(
            !Arc::ptr_eq(&a, &other),
            "other constants, another pipeline"
        );
        let desc = GraphicsDesc::fullscreen("background.frag", &[HALF]);
        let g = p.graphics(&desc).unwrap();
        assert!(Arc::ptr_eq(&g, &p.graphics(&desc).unwrap()));
        assert_eq!(p.len(), 3);
        // Another cache (another render) builds its own.
        let fresh = Pipelines::new(ctx);
        assert!(!Arc::ptr_eq(&a, &fresh.compute("blur.comp", &[7]).unwrap()));
    });
}
