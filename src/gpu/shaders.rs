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

/// The name under which build.rs keeps a shader's variant with its work
/// skipped (its `#ifdef SKIP_WORK` block compiled in).
pub fn skip_work_name(name: &str) -> String {
    format!("{name}:skip-work")
}

/// Whether `name` has a variant with its work skipped.
pub fn has_skip_work(name: &str) -> bool {
    let variant = skip_work_name(name);
    SHADERS.iter().any(|(n, _)| *n == variant)
}
