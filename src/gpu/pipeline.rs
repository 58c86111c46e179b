//! Compute and graphics pipelines built from embedded SPIR-V. Descriptors are
//! push descriptors (VK_KHR_push_descriptor): one set per pipeline, written at
//! record time, so there are no descriptor pools to manage.

use super::{shaders, Context, ShaderLayout};
use crate::error::{Result, VkResultExt};
use ash::vk;
use std::sync::Arc;

/// Fixed-function state of a graphics pipeline (dynamic rendering, dynamic viewport).
#[derive(Debug)]
pub struct GraphicsDesc<'a> {
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub color_formats: &'a [vk::Format],
    pub depth_format: Option<vk::Format>,
    /// Write depth (test LESS); false: test LESS_OR_EQUAL against a depth
    /// pre-pass of the same vertex shader, without writing.
    pub depth_write: bool,
    /// Vertex buffer stride and (format, offset) per location; `None`: no vertex input.
    pub vertex_layout: Option<(u32, &'a [(vk::Format, u32)])>,
    pub cull_mode: vk::CullModeFlags,
    /// Specialization constants of both stages: `constant_id = i` takes `[i]`.
    pub specialization: &'a [u32],
    /// Blend premultiplied-alpha colour over the target (ONE, ONE_MINUS_SRC_ALPHA);
    /// false: overwrite.
    pub alpha_blend: bool,
}

impl<'a> GraphicsDesc<'a> {
    /// A full-screen triangle (shaders-glsl/fullscreen.vert, no vertex input)
    /// shading `fragment` into one colour target of each of `color_formats`.
    pub fn fullscreen(fragment: &'a str, color_formats: &'a [vk::Format]) -> Self {
        Self {
            vertex: "fullscreen.vert",
            fragment,
            color_formats,
            depth_format: None,
            depth_write: false,
            vertex_layout: None,
            cull_mode: vk::CullModeFlags::NONE,
            specialization: &[],
            alpha_blend: false,
        }
    }
}

/// Map entries for specialization constants 0..n, one 32-bit word each.
fn specialization_entries(values: &[u32]) -> Vec<vk::SpecializationMapEntry> {
    (0..values.len() as u32)
        .map(|i| vk::SpecializationMapEntry {
            constant_id: i,
            offset: 4 * i,
            size: 4,
        })
        .collect()
}

/// The shader a pipeline made now uses for `name`: its variant with the work
/// skipped (shaders::skip_work_name) while [`Context::set_skip_work`] is on
/// and it has one, else itself.
fn shader_for(ctx: &Context, name: &str) -> String {
    if ctx.skip_work() && shaders::has_skip_work(name) {
        shaders::skip_work_name(name)
    } else {
        name.to_string()
    }
}

pub struct Pipeline {
    ctx: Arc<Context>,
    pub name: String,
    pub raw: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pub bind_point: vk::PipelineBindPoint,
    pub stages: vk::ShaderStageFlags,
    /// Bindings, push-constant size and workgroup size, reflected from the SPIR-V.
    pub interface: ShaderLayout,
    /// How long the driver took to create it (pipeline creation feedback,
    /// core in Vulkan 1.3), where it said.
    pub creation_ns: Option<f64>,
    /// Made with its shaders' variants that skip their work
    /// ([`Context::set_skip_work`]).
    pub work_skipped: bool,
}

/// The feedback's duration, where the driver marked it valid.
fn feedback_ns(f: &vk::PipelineCreationFeedback) -> Option<f64> {
    f.flags
        .contains(vk::PipelineCreationFeedbackFlags::VALID)
        .then_some(f.duration as f64)
}

impl Pipeline {
    fn with_layout(
        ctx: &Arc<Context>,
        name: &str,
        bind_point: vk::PipelineBindPoint,
        stages: vk::ShaderStageFlags,
        interface: ShaderLayout,
    ) -> Result<Self> {
        let device = &ctx.device;
        let vk_bindings: Vec<_> = interface
            .bindings
            .iter()
            .enumerate()
            .filter_map(|(i, ty)| {
                ty.map(|ty| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(i as u32)
                        .descriptor_type(ty)
                        .descriptor_count(1)
                        .stage_flags(stages)
                })
            })
            .collect();
        let push_constant_bytes = interface.push_constant_bytes;
        let set_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&vk_bindings);
        let set_layout = unsafe { device.create_descriptor_set_layout(&set_info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        let mut p = Pipeline {
            ctx: ctx.clone(),
            name: name.into(),
            raw: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout,
            bind_point,
            stages,
            interface,
            creation_ns: None,
            work_skipped: false,
        };
        let ranges = [vk::PushConstantRange {
            stage_flags: stages,
            offset: 0,
            size: push_constant_bytes,
        }];
        let set_layouts = [set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_constant_bytes > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        p.layout = unsafe { device.create_pipeline_layout(&layout_info, None) }
            .vk("vkCreatePipelineLayout")?;
        Ok(p)
    }

    /// A compute pipeline; its layout is reflected from the shader.
    pub fn compute(ctx: &Arc<Context>, shader: &str) -> Result<Arc<Self>> {
        Self::compute_specialized(ctx, shader, &[])
    }

    /// A compute pipeline whose `constant_id = i` takes `specialization[i]`
    /// (fixed loop bounds and dead branches let the driver unroll and prune).
    pub fn compute_specialized(
        ctx: &Arc<Context>,
        shader: &str,
        specialization: &[u32],
    ) -> Result<Arc<Self>> {
        let mut p = Self::with_layout(
            ctx,
            shader,
            vk::PipelineBindPoint::COMPUTE,
            vk::ShaderStageFlags::COMPUTE,
            ShaderLayout::of(shader)?,
        )?;
        let used = shader_for(ctx, shader);
        p.work_skipped = used != shader;
        let module = ShaderModule::new(ctx, &used)?;
        let entries = specialization_entries(specialization);
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(specialization));
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(c"main")
            .specialization_info(&spec);
        let mut feedback = vk::PipelineCreationFeedback::default();
        let mut feedback_info = vk::PipelineCreationFeedbackCreateInfo::default()
            .pipeline_creation_feedback(&mut feedback);
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(p.layout)
            .push_next(&mut feedback_info);
        p.raw = unsafe {
            ctx.device
                .create_compute_pipelines(ctx.pipeline_cache(), &[info], None)
        }
        .map_err(|(_, e)| e)
        .vk("vkCreateComputePipelines")?[0];
        p.creation_ns = feedback_ns(&feedback);
        ctx.name(p.raw, shader);
        Ok(Arc::new(p))
    }

    /// A graphics pipeline; its layout is the union of both stages' reflection.
    pub fn graphics(ctx: &Arc<Context>, desc: &GraphicsDesc) -> Result<Arc<Self>> {
        let name = format!("{}+{}", desc.vertex, desc.fragment);
        let mut p = Self::with_layout(
            ctx,
            &name,
            vk::PipelineBindPoint::GRAPHICS,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            ShaderLayout::of(desc.vertex)?.merge(&ShaderLayout::of(desc.fragment)?)?,
        )?;
        let (vertex, fragment) = (shader_for(ctx, desc.vertex), shader_for(ctx, desc.fragment));
        p.work_skipped = vertex != desc.vertex || fragment != desc.fragment;
        let vs = ShaderModule::new(ctx, &vertex)?;
        let fs = ShaderModule::new(ctx, &fragment)?;
        let entries = specialization_entries(desc.specialization);
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(desc.specialization));
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vs.raw)
                .name(c"main")
                .specialization_info(&spec),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(fs.raw)
                .name(c"main")
                .specialization_info(&spec),
        ];
        let mut vertex_bindings = Vec::new();
        let mut vertex_attributes = Vec::new();
        if let Some((stride, attrs)) = desc.vertex_layout {
            vertex_bindings.push(vk::VertexInputBindingDescription {
                binding: 0,
                stride,
                input_rate: vk::VertexInputRate::VERTEX,
            });
            for (location, &(format, offset)) in attrs.iter().enumerate() {
                vertex_attributes.push(vk::VertexInputAttributeDescription {
                    location: location as u32,
                    binding: 0,
                    format,
                    offset,
                });
            }
        }
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&vertex_bindings)
            .vertex_attribute_descriptions(&vertex_attributes);
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull_mode)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_format.is_some())
            .depth_write_enable(desc.depth_format.is_some() && desc.depth_write)
            .depth_compare_op(if desc.depth_write {
                vk::CompareOp::LESS
            } else {
                vk::CompareOp::LESS_OR_EQUAL
            });
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| {
                let state = vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA);
                if desc.alpha_blend {
                    use vk::BlendFactor as F;
                    state
                        .blend_enable(true)
                        .src_color_blend_factor(F::ONE)
                        .dst_color_blend_factor(F::ONE_MINUS_SRC_ALPHA)
                        .color_blend_op(vk::BlendOp::ADD)
                        .src_alpha_blend_factor(F::ONE)
                        .dst_alpha_blend_factor(F::ONE_MINUS_SRC_ALPHA)
                        .alpha_blend_op(vk::BlendOp::ADD)
                } else {
                    state
                }
            })
            .collect();
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut feedback = vk::PipelineCreationFeedback::default();
        let mut feedback_info = vk::PipelineCreationFeedbackCreateInfo::default()
            .pipeline_creation_feedback(&mut feedback);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format.unwrap_or(vk::Format::UNDEFINED));
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(p.layout)
            .push_next(&mut rendering)
            .push_next(&mut feedback_info);
        p.raw = unsafe {
            ctx.device
                .create_graphics_pipelines(ctx.pipeline_cache(), &[info], None)
        }
        .map_err(|(_, e)| e)
        .vk("vkCreateGraphicsPipelines")?[0];
        p.creation_ns = feedback_ns(&feedback);
        ctx.name(p.raw, &name);
        Ok(Arc::new(p))
    }
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        let d = &self.ctx.device;
        unsafe {
            if self.raw != vk::Pipeline::null() {
                d.destroy_pipeline(self.raw, None);
            }
            if self.layout != vk::PipelineLayout::null() {
                d.destroy_pipeline_layout(self.layout, None);
            }
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A shader module, alive only while its pipeline is created.
struct ShaderModule<'a> {
    ctx: &'a Context,
    raw: vk::ShaderModule,
}

impl<'a> ShaderModule<'a> {
    fn new(ctx: &'a Context, name: &str) -> Result<Self> {
        let words = shaders::spirv(name)?;
        let info = vk::ShaderModuleCreateInfo::default().code(words);
        let raw =
            unsafe { ctx.device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")?;
        Ok(Self { ctx, raw })
    }
}

impl Drop for ShaderModule<'_> {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_shader_module(self.raw, None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shaders_with_a_work_skipped_variant_have_it_embedded() {
        for name in [
            "alu_heavy.comp",
            "blur.comp",
            "blur_narrow.comp",
            "irradiance.comp",
            "irradiance.frag",
            "skin.frag",
        ] {
            assert!(shaders::has_skip_work(name), "{name}");
            let (a, b) = (
                shaders::spirv(name).unwrap(),
                shaders::spirv(&shaders::skip_work_name(name)).unwrap(),
            );
            assert_ne!(a, b, "{name}");
        }
        for name in ["ruler_copy.comp", "skin.vert", "tonemap.frag"] {
            assert!(!shaders::has_skip_work(name), "{name}");
        }
    }
}
