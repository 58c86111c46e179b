//! Post-processing after shading: exposure and tone mapping (glow and debug
//! views join here).

pub mod tonemap;
