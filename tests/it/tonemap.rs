//! The tone-map pass against its CPU reference (post::tonemap::encode8, whose
//! curves are written from the published formulas and checked at published
//! points in its unit tests) on a ramp: every tone curve (linear, Narkowicz's
//! ACES fit, Khronos PBR Neutral) with the sRGB curve and pure powers, given
//! and metered exposures (the GPU meter against post::meter::exposure), and the
//! background where alpha (coverage) is 0.

use crate::common;

use dermis::gpu::{ImageDesc, Pipelines, Sampler};
use dermis::graph::upload::{upload_texture, Readback};
use dermis::graph::{Access, Executor, Graph, Imported};
use dermis::post::meter::{self, Meter, Metered};
use dermis::post::tonemap::{encode8, Tonemap, LDR_FORMAT};
use dermis::post::{Display, Exposure};
use dermis::scene::file::{Gamma, ToneCurve};
use std::sync::Arc;

const W: u32 = 256;

/// The pass's 8-bit output and, when metered, the GPU's metering.
fn tonemap(ramp: &[f32], exposure: Exposure, display: &Display) -> (Vec<u8>, Option<Metered>) {
    common::with_gpu(|ctx| {
        let desc = ImageDesc::new(W, 1, dermis::testscene::HALF);
        let src = upload_texture(ctx, "ramp", desc, &common::to_f16_bytes(ramp)).unwrap();
        let sampler = Arc::new(Sampler::clamped(ctx, false).unwrap());
        let pipelines = Pipelines::new(ctx);
        let tonemap = Tonemap::new(&pipelines, sampler.clone()).unwrap();
        let meter = Meter::new(&pipelines, sampler).unwrap();
        let readback = Readback::new(ctx, "ldr", W as u64 * 4).unwrap();
        let metered = Readback::new(ctx, "exposure", meter::RESULT_BYTES).unwrap();
        let mut g = Graph::new();
        let hdr = g.import_image(
            "ramp",
            Imported::Image(src),
            Some(Access::ShaderSampled),
            None,
        );
        let result = match exposure {
            Exposure::Metered => meter.pass(&mut g, &hdr),
            Exposure::Given(_) => meter.result(&mut g),
        };
        let mut ldr = g.create_image("ldr", ImageDesc::new(W, 1, LDR_FORMAT));
        tonemap.pass(&mut g, &hdr, &result, &mut ldr, exposure, display);
        readback.image_pass(&mut g, &ldr);
        metered.buffer_pass(&mut g, &result);
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.run(g).unwrap();
        ex.finish().unwrap();
        let m =
            (exposure == Exposure::Metered).then(|| Metered::from_bytes(metered.bytes().unwrap()));
        (readback.bytes().unwrap().to_vec(), m)
    })
}

#[test]
fn the_pass_encodes_a_ramp_as_the_cpu_reference_does() {
    // 0 … 4 in 256 steps (past 1 to check clipping and the curves' shoulders),
    // rounded to f16 as stored; every fourth pixel uncovered (alpha 0).
    let ramp: Vec<f32> = (0..W)
        .flat_map(|i| {
            let v = common::round_f16(4.0 * i as f32 / (W - 1) as f32);
            let a = if i % 4 == 3 { 0.0 } else { 1.0 };
            [
                v,
                common::round_f16(v * 0.5),
                common::round_f16(v * 0.25),
                a,
            ]
        })
        .collect();
    let cpu_metered = meter::exposure(&ramp);
    let mut worst_overall = 0;
    for curve in [ToneCurve::Linear, ToneCurve::Aces, ToneCurve::Neutral] {
        for (gamma, exposure) in [
            (Gamma::Srgb, Exposure::Given(0.0)),
            (Gamma::Power(1.0), Exposure::Given(-1.0)),
            (Gamma::Power(2.2), Exposure::Given(-0.5)),
            (Gamma::Srgb, Exposure::Metered),
        ] {
            let display = Display {
                curve,
                gamma,
                background: [0.2, 0.1, 0.0],
            };
            let (got, metered) = tonemap(&ramp, exposure, &display);
            let ev = match (exposure, metered) {
                (Exposure::Given(ev), _) => ev,
                (Exposure::Metered, m) => {
                    let m = m.unwrap();
                    // The GPU meter (f32 sums in another order) against the CPU's (f64).
                    assert_eq!(m.pixels, cpu_metered.pixels);
                    assert!(
                        (m.ev - cpu_metered.ev).abs() < 1e-4,
                        "{m:?} {cpu_metered:?}"
                    );
                    m.ev
                }
            };
            let want = encode8(&ramp, ev, &display);
            let worst = got
                .iter()
                .zip(&want)
                .map(|(&a, &b)| (a as i32 - b as i32).abs())
                .max()
                .unwrap();
            println!("{curve:?}, {gamma:?}, {exposure:?} ({ev:+.3} EV): worst {worst} step(s)");
            // One 8-bit step: the GPU's pow, exp and rounding are not the CPU's.
            assert!(
                worst <= 1,
                "{curve:?} {gamma:?}: worst difference {worst} steps"
            );
            worst_overall = worst_overall.max(worst);
            // Not constant: dark at the start, bright at the end (red, covered).
            let last = (W as usize - 2) * 4;
            assert!(
                got[0] < 20 && got[last] > 150,
                "{curve:?} {gamma:?}: {} {}",
                got[0],
                got[last]
            );
        }
    }
    println!("worst difference over all cases: {worst_overall} step(s)");
    println!("CPU metering of the ramp: {cpu_metered:?}");
}
