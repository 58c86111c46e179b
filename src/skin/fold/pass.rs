//! The fold term on the GPU (shaders-glsl/fold.comp).

use super::{FoldTerm, Source};
use crate::error::Result;
use crate::gpu::{Buffer, Pipeline, Pipelines, Sampler};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, Graph, ImageHandle};
use crate::skin::TAG;
use std::sync::Arc;

/// The term on the GPU: per level, its lists, and the pass that applies them
/// to the level's image in place (shaders-glsl/fold.comp).
pub struct FoldPass {
    pipeline: Arc<Pipeline>,
    sampler: Arc<Sampler>,
    /// (level index, targets, their buffer, the sources' buffer)
    levels: Vec<(usize, u32, Arc<Buffer>, Arc<Buffer>)>,
}

impl FoldPass {
    pub fn new(pipelines: &Pipelines, term: &FoldTerm, sampler: Arc<Sampler>) -> Result<Self> {
        let ctx = pipelines.ctx();
        let mut levels = Vec::new();
        for l in term.levels.iter().filter(|l| !l.targets.is_empty()) {
            let name = |what: &str| format!("fold {what} of blur{}", l.level + 1);
            let upload = |what: &str, bytes: &[u8]| {
                upload_buffer(ctx, &name(what), bytes, Access::ShaderBufferRead)
            };
            // A source list may be empty (a texel only rescaled): keep one entry.
            let sources = if l.sources.is_empty() {
                vec![Source {
                    texel: 0,
                    weight: 0.0,
                }]
            } else {
                l.sources.clone()
            };
            levels.push((
                l.level,
                l.targets.len() as u32,
                upload("targets", bytemuck::cast_slice(&l.targets))?,
                upload("sources", bytemuck::cast_slice(&sources))?,
            ));
        }
        Ok(FoldPass {
            pipeline: pipelines.compute("fold.comp", &[])?,
            sampler,
            levels,
        })
    }

    /// Applies level `k`'s term (0: blur1) to `level`, blurred from `src`.
    pub fn pass(&self, g: &mut Graph, k: usize, src: &ImageHandle, level: &mut ImageHandle) {
        let Some((_, count, targets, sources)) = self.levels.iter().find(|l| l.0 == k) else {
            return;
        };
        // blurK_fold, after blurK (skin::blur::BlurChain::level_name).
        g.simple_pass(&format!("blur{}_fold", k + 1), &self.pipeline)
            .tag(TAG)
            .sample(src, &self.sampler)
            .load_store(level)
            .buffer(targets)
            .buffer(sources)
            .constants(count)
            .dispatch([*count, 1, 1]);
    }
}
