//! Work counters of a pass (`render --counters`): the pipeline statistics
//! Vulkan counts between a query's begin and end (VkQueryPipelineStatisticFlagBits),
//! and what they say per texel.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// What one pass did, as the device counted it. Vertex and fragment counts are
/// the implementation's: the specification lets it count helper invocations
/// and skip or repeat vertex shader invocations (Vulkan 1.3, "Pipeline
/// Statistics Queries").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct PassCounters {
    /// Vertices the input assembler fetched.
    pub input_vertices: u64,
    /// Primitives the input assembler made.
    pub input_primitives: u64,
    pub vertex_invocations: u64,
    /// Primitives that reached the clipping stage.
    pub clipping_invocations: u64,
    /// Primitives that left it (after clipping and culling by the view volume).
    pub clipping_primitives: u64,
    pub fragment_invocations: u64,
    pub compute_invocations: u64,
}

impl PassCounters {
    /// The statistics in the order of their flag bits, which is the order a
    /// query writes them in (Vulkan 1.3, "Pipeline Statistics Queries"): input
    /// vertices, input primitives, vertex invocations, clipping invocations,
    /// clipping primitives, fragment invocations, compute invocations.
    pub fn from_raw(raw: [u64; 7]) -> Self {
        let [input_vertices, input_primitives, vertex_invocations, clipping_invocations, clipping_primitives, fragment_invocations, compute_invocations] =
            raw;
        Self {
            input_vertices,
            input_primitives,
            vertex_invocations,
            clipping_invocations,
            clipping_primitives,
            fragment_invocations,
            compute_invocations,
        }
    }

    fn fields(&self) -> [u64; 7] {
        [
            self.input_vertices,
            self.input_primitives,
            self.vertex_invocations,
            self.clipping_invocations,
            self.clipping_primitives,
            self.fragment_invocations,
            self.compute_invocations,
        ]
    }

    /// Per counter, the median over `frames` (the lower middle of an even
    /// count, so that the result is a count one frame had).
    pub fn median(frames: &[PassCounters]) -> Option<PassCounters> {
        if frames.is_empty() {
            return None;
        }
        let mut out = [0u64; 7];
        for (k, o) in out.iter_mut().enumerate() {
            let mut v: Vec<u64> = frames.iter().map(|c| c.fields()[k]).collect();
            v.sort_unstable();
            *o = v[(v.len() - 1) / 2];
        }
        Some(Self::from_raw(out))
    }

    /// Fragment invocations per pixel of the render area (`texels` of a
    /// graphics pass): the share of it covered times the over-shading (overlap,
    /// helper lanes, where counted). `None` for a pass that shaded no fragment.
    pub fn fragments_per_pixel(&self, texels: Option<u64>) -> Option<f64> {
        let t = texels.filter(|&t| t > 0)?;
        (self.fragment_invocations > 0).then(|| self.fragment_invocations as f64 / t as f64)
    }

    /// Compute invocations per texel the pass declared: 1 when its dispatch
    /// fits its workgroups exactly, more when they overhang the image.
    pub fn invocations_per_texel(&self, texels: Option<u64>) -> Option<f64> {
        let t = texels.filter(|&t| t > 0)?;
        (self.compute_invocations > 0).then(|| self.compute_invocations as f64 / t as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_order_is_the_flag_order() {
        let c = PassCounters::from_raw([1, 2, 3, 4, 5, 6, 7]);
        assert_eq!((c.input_vertices, c.input_primitives), (1, 2));
        assert_eq!(c.vertex_invocations, 3);
        assert_eq!((c.clipping_invocations, c.clipping_primitives), (4, 5));
        assert_eq!((c.fragment_invocations, c.compute_invocations), (6, 7));
        assert_eq!(c.fields(), [1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn median_per_counter_and_per_texel_figures() {
        let c = |f, k| PassCounters {
            fragment_invocations: f,
            compute_invocations: k,
            ..Default::default()
        };
        let m = PassCounters::median(&[c(10, 3), c(30, 1), c(20, 2), c(40, 9)]).unwrap();
        assert_eq!((m.fragment_invocations, m.compute_invocations), (20, 2));
        assert!(PassCounters::median(&[]).is_none());
        assert_eq!(c(300, 0).fragments_per_pixel(Some(200)), Some(1.5));
        assert_eq!(c(300, 0).invocations_per_texel(Some(200)), None);
        assert_eq!(c(0, 64).invocations_per_texel(Some(60)), Some(64.0 / 60.0));
        assert_eq!(c(0, 64).fragments_per_pixel(Some(60)), None);
        assert_eq!(c(5, 5).fragments_per_pixel(None), None);
        assert_eq!(c(5, 5).invocations_per_texel(Some(0)), None);
    }
}
