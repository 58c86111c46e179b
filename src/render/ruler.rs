//! The rulers (`render --ruler`, the bench, `dermis sweep`): three passes timed
//! in the same frame as the rest, at the irradiance resolution and format, that
//! every other pass is compared with — `ruler_copy` reads and writes one RGBA16F
//! texel per invocation, `ruler_read` only reads, `ruler_empty` is one
//! invocation of the read (what any pass costs before its work). A pass's
//! ns/texel over the copy's (`x_ruler` in reports) survives a noisy machine
//! better than milliseconds; the copy's bandwidth and the empty pass's time
//! are what timing::bound judges passes by.

use crate::error::Result;
use crate::gpu::{ImageDesc, Pipelines, Sampler};
use crate::graph::{Graph, ImageHandle};
use crate::timing::{RULER_COPY, RULER_EMPTY, RULER_READ};
use std::sync::Arc;

/// The tag of the ruler passes.
pub const TAG: &str = "ruler";

/// Both rulers over `src` (read-only, sampled with `sampler`), its size and
/// format; their pipelines from the render's cache.
pub fn passes(
    g: &mut Graph,
    pipelines: &Pipelines,
    sampler: &Arc<Sampler>,
    src: &ImageHandle,
) -> Result<()> {
    let desc = src.desc;
    let mut copy = g.create_image("ruler copy", desc);
    g.simple_pass(RULER_COPY, &pipelines.compute("ruler_copy.comp", &[])?)
        .tag(TAG)
        .sample(src, sampler)
        .store(&mut copy)
        .dispatch([desc.width, desc.height, 1]);
    let mut sink = g.create_image("ruler sink", ImageDesc::new(1, 1, desc.format));
    let read = pipelines.compute("ruler_read.comp", &[])?;
    g.simple_pass(RULER_READ, &read)
        .tag(TAG)
        .sample(src, sampler)
        .store(&mut sink)
        .dispatch([desc.width, desc.height, 1]);
    let mut empty_sink = g.create_image("ruler empty sink", ImageDesc::new(1, 1, desc.format));
    g.simple_pass(RULER_EMPTY, &read)
        .tag(TAG)
        .sample(src, sampler)
        .store(&mut empty_sink)
        .dispatch([1, 1, 1]);
    // Timed, not read: requested, so that the graph keeps them.
    g.output(&copy);
    g.output(&sink);
    g.output(&empty_sink);
    Ok(())
}
