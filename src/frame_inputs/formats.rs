//! Formats of the targets that several passes share.

use ash::vk;

/// Screen-space radiance (the background, skin and direct passes, tone mapping's input).
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Screen-space depth of the mesh passes.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// The lights' shadow atlas (light::shadow), sampled with depth comparison.
pub const SHADOW_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
