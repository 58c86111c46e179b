//! SPIR-V compiled from `shaders-glsl/` by build.rs, embedded in the binary.

use crate::error::{Error, Result};

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// SPIR-V words of a shader by file name, e.g. `"blur.comp"`.
pub fn spirv(name: &str) -> Result<&'static [u32]> {
    SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, words)| *words)
        .ok_or_else(|| Error::Graph(format!("no embedded shader named {name:?}")))
}
