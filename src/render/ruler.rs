//! The rulers (`render --ruler`, the bench, `dermis sweep`): two passes timed in
//! the same frame as the rest, at the irradiance resolution and format, that every
//! other pass is compared with — `ruler_copy` reads and writes one RGBA16F texel
//! per invocation, `ruler_read` only reads. A pass's ns/texel over the copy's
//! (`x_ruler` in reports) survives a noisy machine better than milliseconds.

use crate::error::Result;
use crate::gpu::{Context, ImageDesc, Pipeline, Sampler};
use crate::graph::{Graph, ImageHandle};
use crate::profile::RULER_COPY;
use std::sync::Arc;

/// The tag of the ruler passes.
pub const TAG: &str = "ruler";

pub struct Ruler {
    copy: Arc<Pipeline>,
    read: Arc<Pipeline>,
    sampler: Arc<Sampler>,
}

impl Ruler {
    pub fn new(ctx: &Arc<Context>, sampler: Arc<Sampler>) -> Result<Self> {
        Ok(Self {
            copy: Pipeline::compute(ctx, "ruler_copy.comp")?,
            read: Pipeline::compute(ctx, "ruler_read.comp")?,
            sampler,
        })
    }

    /// Both rulers over `src` (read-only), its size and format.
    pub fn passes(&self, g: &mut Graph, src: &ImageHandle) {
        let desc = src.desc;
        let mut copy = g.create_image("ruler copy", desc);
        g.simple_pass(RULER_COPY, &self.copy)
            .tag(TAG)
            .sample(src, &self.sampler)
            .store(&mut copy)
            .dispatch([desc.width, desc.height, 1]);
        let mut sink = g.create_image("ruler sink", ImageDesc::new(1, 1, desc.format));
        g.simple_pass("ruler_read", &self.read)
            .tag(TAG)
            .sample(src, &self.sampler)
            .store(&mut sink)
            .dispatch([desc.width, desc.height, 1]);
        // Timed, not read: requested, so that the graph keeps them.
        g.output(&copy);
        g.output(&sink);
    }
}
