//! dermis: realistic real-time face rendering under environment lighting
//! (Yang, Wang & Zuo 2012; d'Eon & Luebke, GPU Gems 3 ch. 14) on raw Vulkan,
//! measured pass by pass.

pub mod assets;
pub mod atomic;
pub mod cache;
pub mod error;
pub mod fidelity;
pub mod frame_inputs;
pub mod gpu;
pub mod graph;
pub mod light;
pub mod post;
pub mod render;
pub mod scene;
pub mod skin;
pub mod sweep;
pub mod testscene;
pub mod text;
pub mod timing;
pub mod viewer;

pub use error::{Error, Result};
