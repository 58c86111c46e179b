//! The integration tests, one crate: each former `tests/<name>.rs` is a module
//! here, so the suite links dermis and its dependencies once instead of once per
//! file. `cargo test --release --test it <module>::` runs one of them.
//!
//! In-process GPU tests take turns at the device across every module
//! (`common::with_gpu`); tests that run the `dermis` binary run beside them.

mod common;

mod bound;
mod cli;
mod compare;
mod counters;
mod docs;
mod graph_gpu;
mod layers;
mod pipeline_cache;
mod post;
mod reference_gpu;
mod scene_render;
mod session;
mod sh_gpu;
mod skin_diffusion;
mod specular;
mod sweep;
mod sweep_shards;
mod timeline;
mod timestamps;
mod tonemap;
mod transmission;
mod upload_gpu;
mod viewer;
mod views;
