//! The tone-mapping pass against its CPU reference (post::tonemap::encode8, itself
//! checked against IEC 61966-2-1 points in its unit test) on a ramp, for the sRGB
//! curve and pure powers, with exposure.

mod common;

use dermis::gpu::{ImageDesc, Sampler};
use dermis::graph::upload::{upload_texture, Readback};
use dermis::graph::{Access, Executor, Graph, Imported};
use dermis::post::tonemap::{encode8, Tonemap, LDR_FORMAT};
use dermis::scene::file::Gamma;
use std::sync::Arc;

const W: u32 = 256;

#[test]
fn the_pass_encodes_a_ramp_as_the_cpu_reference_does() {
    // 0 … 1.5 in 256 steps (past 1 to check clipping), rounded to f16 as stored.
    let ramp: Vec<f32> = (0..W)
        .flat_map(|i| {
            let v = common::round_f16(1.5 * i as f32 / (W - 1) as f32);
            [v, v * 0.5, v * 0.25, 1.0]
        })
        .collect();
    for (gamma, exposure) in [
        (Gamma::Srgb, 0.0),
        (Gamma::Power(1.0), 0.0),
        (Gamma::Power(2.2), -0.5),
    ] {
        let got = common::with_gpu(|ctx| {
            let desc = ImageDesc::new(W, 1, dermis::testscene::HALF);
            let src = upload_texture(ctx, "ramp", desc, &common::to_f16_bytes(&ramp)).unwrap();
            let tonemap =
                Tonemap::new(ctx, Arc::new(Sampler::clamped(ctx, false).unwrap())).unwrap();
            let readback = Readback::new(ctx, "ldr", W as u64 * 4).unwrap();
            let mut g = Graph::new();
            let hdr = g.import_image(
                "ramp",
                Imported::Image(src),
                Some(Access::ShaderSampled),
                None,
            );
            let mut ldr = g.create_image("ldr", ImageDesc::new(W, 1, LDR_FORMAT));
            tonemap.pass(&mut g, &hdr, &mut ldr, exposure, gamma);
            readback.image_pass(&mut g, &ldr);
            let mut ex = Executor::new(ctx, 1).unwrap();
            ex.run(g).unwrap();
            ex.finish().unwrap();
            readback.bytes().unwrap().to_vec()
        });
        let want = encode8(&ramp, exposure, gamma);
        let worst = got
            .iter()
            .zip(&want)
            .map(|(&a, &b)| (a as i32 - b as i32).abs())
            .max()
            .unwrap();
        // One 8-bit step: the GPU's pow and rounding are not the CPU's.
        assert!(worst <= 1, "{gamma:?}: worst difference {worst} steps");
        // Not constant: the ramp reaches both ends.
        assert_eq!((got[0], got[(W as usize - 1) * 4]), (0, 255), "{gamma:?}");
    }
}
