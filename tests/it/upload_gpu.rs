//! Static uploads: buffers round-trip, textures get GPU-generated mip levels that
//! equal the CPU box filter of the level above.

use crate::common;

use ash::vk;
use dermis::gpu::{Buffer, ImageDesc, MemoryLocation};
use dermis::graph::upload::{full_mip_count, upload_buffer, upload_texture};
use dermis::graph::{Access, Executor, Graph, Imported};
use std::sync::Arc;

#[test]
fn mip_count() {
    assert_eq!(full_mip_count(1, 1), 1);
    assert_eq!(full_mip_count(1024, 1024), 11);
    assert_eq!(full_mip_count(64, 32), 7);
    assert_eq!(full_mip_count(1000, 3), 10);
}

#[test]
fn texture_mips_are_box_filtered_on_the_gpu() {
    let (w, h) = (64u32, 32u32);
    let texels: Vec<u8> = (0..w * h * 4)
        .map(|i| ((i * 37 + i / 7) % 251) as u8)
        .collect();
    let levels = full_mip_count(w, h);
    let read = common::with_gpu(|ctx| {
        let desc = ImageDesc {
            mip_levels: levels,
            ..ImageDesc::new(w, h, vk::Format::R8G8B8A8_UNORM)
        };
        let tex = upload_texture(ctx, "tex", desc, &texels).unwrap();
        // Read level 0 and level 1 back through a graph that imports the texture
        // in the state uploads leave it in.
        let mut out = Vec::new();
        for level in [0u32, 1] {
            let bytes = ((w >> level) * (h >> level) * 4) as u64;
            let rb = Arc::new(
                Buffer::new(
                    ctx,
                    "rb",
                    bytes,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )
                .unwrap(),
            );
            let mut g = Graph::new();
            let t = g.import_image(
                "tex",
                Imported::Image(tex.clone()),
                Some(Access::ShaderSampled),
                Some(Access::ShaderSampled),
            );
            let mut b = g.import_buffer(
                "rb",
                Imported::Buffer(rb.clone()),
                None,
                Some(Access::HostRead),
            );
            let mut p = g.add_pass("read");
            let src = p.read(&t, Access::TransferSrc);
            let dst = p.write_buffer(&mut b, Access::TransferDst);
            p.record(move |cx| cx.copy_level_to_buffer(src, level, dst));
            let mut ex = Executor::new(ctx, 1).unwrap();
            ex.run(g).unwrap();
            ex.finish().unwrap();
            out.push(rb.mapped().unwrap().to_vec());
        }
        out
    });
    assert_eq!(read[0], texels, "level 0 round-trips");
    let (w1, h1) = (w as usize / 2, h as usize / 2);
    let mut worst = 0i32;
    for y in 0..h1 {
        for x in 0..w1 {
            for c in 0..4 {
                let at = |xx: usize, yy: usize| texels[(yy * w as usize + xx) * 4 + c] as f32;
                let avg = (at(2 * x, 2 * y)
                    + at(2 * x + 1, 2 * y)
                    + at(2 * x, 2 * y + 1)
                    + at(2 * x + 1, 2 * y + 1))
                    / 4.0;
                let got = read[1][(y * w1 + x) * 4 + c] as i32;
                worst = worst.max((got - avg.round() as i32).abs());
            }
        }
    }
    assert!(
        worst <= 1,
        "level 1 differs from the 2x2 box average by {worst} LSB"
    );
}

#[test]
fn buffers_round_trip() {
    let data: Vec<u8> = (0..4096u32)
        .flat_map(|i| (i * 2_654_435_761).to_le_bytes())
        .collect();
    let got = common::with_gpu(|ctx| {
        let buf = upload_buffer(ctx, "data", &data, Access::TransferSrc).unwrap();
        let rb = Arc::new(
            Buffer::new(
                ctx,
                "rb",
                data.len() as u64,
                vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )
            .unwrap(),
        );
        let mut g = Graph::new();
        let s = g.import_buffer(
            "data",
            Imported::Buffer(buf.clone()),
            Some(Access::TransferSrc),
            None,
        );
        let mut d = g.import_buffer(
            "rb",
            Imported::Buffer(rb.clone()),
            None,
            Some(Access::HostRead),
        );
        let mut p = g.add_pass("copy");
        let (sr, dr) = (
            p.read_buffer(&s, Access::TransferSrc),
            p.write_buffer(&mut d, Access::TransferDst),
        );
        let size = data.len() as u64;
        p.record(move |cx| unsafe {
            cx.ctx.device.cmd_copy_buffer(
                cx.cmd,
                cx.buffer(sr),
                cx.buffer(dr),
                &[vk::BufferCopy {
                    src_offset: 0,
                    dst_offset: 0,
                    size,
                }],
            )
        });
        let mut ex = Executor::new(ctx, 1).unwrap();
        ex.run(g).unwrap();
        ex.finish().unwrap();
        rb.mapped().unwrap().to_vec()
    });
    assert_eq!(got, data);
}
