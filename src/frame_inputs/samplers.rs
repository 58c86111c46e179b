//! The samplers every pass shares.

use super::SHADOW_FORMAT;
use crate::error::Result;
use crate::gpu::{Context, Sampler};
use std::sync::Arc;

pub struct Samplers {
    pub linear: Arc<Sampler>,
    pub nearest: Arc<Sampler>,
    /// Depth comparison for the shadow atlas, bilinear where the device filters D32.
    pub shadow: Arc<Sampler>,
}

impl Samplers {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let linear_depth = ctx.supports_linear_filter(SHADOW_FORMAT);
        Ok(Self {
            linear: Arc::new(Sampler::clamped(ctx, true)?),
            nearest: Arc::new(Sampler::clamped(ctx, false)?),
            shadow: Arc::new(Sampler::shadow(ctx, linear_depth)?),
        })
    }
}
