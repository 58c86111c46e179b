//! The simple pass (after kajiya-rg's `SimpleRenderPass`): one pipeline, the
//! resources its shader binds declared in binding order, typed push constants, and
//! one dispatch or draw. Accesses follow from the pipeline (compute or fragment)
//! and the declaration; the declaration is checked against the layout reflected
//! from the SPIR-V when the graph compiles, so binding order is written in GLSL and
//! in exactly one Rust call chain. A binding the shader leaves unused (a gap in its
//! layout, e.g. one declaration shared by two fragment shaders) is tracked by the
//! graph but not written.
//!
//! ```text
//! g.simple_pass("blur1_u", &pipeline)
//!     .sample(&src, &sampler)          // binding 0
//!     .store(&mut dst)                 // binding 1
//!     .buffer(&taps)                   // binding 2
//!     .constants(&push)
//!     .dispatch([w, h, 1]);
//! ```

use super::pass_cx::{Descriptor, PassCx};
use super::{Access, BufferHandle, BufferRef, Graph, ImageHandle, ImageRef, LoadOp, PassBuilder};
use crate::gpu::{Buffer, Image, Pipeline, Sampler};
use crate::timing::{DRAW_TAG, WORK_SKIPPED_TAG};
use ash::vk;
use std::sync::Arc;

/// One bound resource, in binding order.
enum Bound {
    /// Graph image, `imageStore`d (storage image).
    Storage(ImageRef),
    /// Graph image, sampled.
    Sampled(ImageRef, Arc<Sampler>),
    /// Static texture outside the graph (uploaded, SHADER_READ_ONLY_OPTIMAL).
    Texture(Arc<Image>, Arc<Sampler>),
    /// Graph storage buffer.
    Buffer(BufferRef),
    /// Graph buffer read as a uniform buffer.
    GraphUniform(BufferRef),
    /// Static uniform buffer outside the graph.
    Uniform(Arc<Buffer>),
    /// Static storage buffer outside the graph.
    StaticBuffer(Arc<Buffer>),
}

impl Bound {
    fn descriptor_type(&self) -> vk::DescriptorType {
        match self {
            Bound::Storage(_) => vk::DescriptorType::STORAGE_IMAGE,
            Bound::Sampled(..) | Bound::Texture(..) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            Bound::Buffer(_) | Bound::StaticBuffer(_) => vk::DescriptorType::STORAGE_BUFFER,
            Bound::Uniform(_) | Bound::GraphUniform(_) => vk::DescriptorType::UNIFORM_BUFFER,
        }
    }

    fn descriptor(&self) -> Descriptor<'_> {
        match self {
            Bound::Storage(r) => Descriptor::StorageImage(*r),
            Bound::Sampled(r, s) => Descriptor::Sampled(*r, s),
            Bound::Texture(i, s) => Descriptor::StaticSampled(i, s),
            Bound::Buffer(r) => Descriptor::Storage(*r),
            Bound::Uniform(b) => Descriptor::StaticUniform(b),
            Bound::GraphUniform(r) => Descriptor::Uniform(*r),
            Bound::StaticBuffer(b) => Descriptor::StaticStorage(b),
        }
    }
}

/// A pass under construction; see the module documentation.
#[must_use = "a simple pass is added by dispatch, draw, draw_indexed or record"]
pub struct SimplePass<'g> {
    pass: PassBuilder<'g>,
    pipeline: Arc<Pipeline>,
    bindings: Vec<Bound>,
    constants: Vec<u8>,
    errors: Vec<String>,
}

impl Graph {
    /// A pass that runs `pipeline` once; declare its bindings in order.
    ///
    /// A pipeline made with its work skipped tags the pass
    /// [`WORK_SKIPPED_TAG`] (and a draw [`DRAW_TAG`]) for the timing report.
    pub fn simple_pass(&mut self, name: &str, pipeline: &Arc<Pipeline>) -> SimplePass<'_> {
        let mut pass = self.add_pass(name);
        if pipeline.work_skipped {
            pass.tag(WORK_SKIPPED_TAG);
            if pipeline.bind_point == vk::PipelineBindPoint::GRAPHICS {
                pass.tag(DRAW_TAG);
            }
        }
        SimplePass {
            pass,
            pipeline: pipeline.clone(),
            bindings: Vec::new(),
            constants: Vec::new(),
            errors: Vec::new(),
        }
    }
}

impl<'g> SimplePass<'g> {
    fn compute(&self) -> bool {
        self.pipeline.bind_point == vk::PipelineBindPoint::COMPUTE
    }

    fn bind(mut self, b: Bound) -> Self {
        self.bindings.push(b);
        self
    }

    /// The next binding: a graph image, sampled.
    pub fn sample(mut self, image: &ImageHandle, sampler: &Arc<Sampler>) -> Self {
        let access = if self.compute() {
            Access::ComputeSampled
        } else {
            Access::FragmentSampled
        };
        let r = self.pass.read(image, access);
        self.bind(Bound::Sampled(r, sampler.clone()))
    }

    /// The next binding: a graph image written with `imageStore` (compute only).
    pub fn store(mut self, image: &mut ImageHandle) -> Self {
        if !self.compute() {
            self.errors
                .push("storage-image writes are declared for compute passes only".into());
        }
        let r = self.pass.write(image, Access::ComputeStorageWrite);
        self.bind(Bound::Storage(r))
    }

    /// The next binding: a graph image read with `imageLoad` and written with
    /// `imageStore` in place (compute only).
    pub fn load_store(mut self, image: &mut ImageHandle) -> Self {
        if !self.compute() {
            self.errors
                .push("storage-image writes are declared for compute passes only".into());
        }
        let r = self.pass.write(image, Access::ComputeStorageReadWrite);
        self.bind(Bound::Storage(r))
    }

    /// The next binding: a graph storage buffer, read.
    pub fn read_buffer(mut self, buffer: &BufferHandle) -> Self {
        let access = if self.compute() {
            Access::ComputeBufferRead
        } else {
            Access::FragmentBufferRead
        };
        let r = self.pass.read_buffer(buffer, access);
        self.bind(Bound::Buffer(r))
    }

    /// The next binding: a graph buffer read as a uniform buffer (it needs
    /// UNIFORM_BUFFER usage). Uniform loads are much cheaper than storage loads on
    /// CPU drivers (lavapipe: docs/records/2026-11-24-frame-speed.md).
    pub fn read_uniform(mut self, buffer: &BufferHandle) -> Self {
        let r = self.pass.read_buffer(buffer, Access::UniformRead);
        self.bind(Bound::GraphUniform(r))
    }

    /// The next binding: a graph storage buffer, written (compute only).
    pub fn write_buffer(mut self, buffer: &mut BufferHandle) -> Self {
        if !self.compute() {
            self.errors
                .push("storage-buffer writes are declared for compute passes only".into());
        }
        let r = self.pass.write_buffer(buffer, Access::ComputeBufferWrite);
        self.bind(Bound::Buffer(r))
    }

    /// The next binding: a static texture (uploaded outside the graph).
    pub fn texture(self, image: &Arc<Image>, sampler: &Arc<Sampler>) -> Self {
        self.bind(Bound::Texture(image.clone(), sampler.clone()))
    }

    /// The next binding: a static uniform buffer.
    pub fn uniform(self, buffer: &Arc<Buffer>) -> Self {
        self.bind(Bound::Uniform(buffer.clone()))
    }

    /// The next binding: a static storage buffer.
    pub fn buffer(self, buffer: &Arc<Buffer>) -> Self {
        self.bind(Bound::StaticBuffer(buffer.clone()))
    }

    /// A colour attachment (not a binding); the pass renders at its size.
    pub fn color(mut self, image: &mut ImageHandle, load: LoadOp) -> Self {
        self.pass.color_attachment(image, load);
        self
    }

    /// The depth attachment (not a binding).
    pub fn depth(mut self, image: &mut ImageHandle, load: LoadOp) -> Self {
        self.pass.depth_attachment(image, load);
        self
    }

    /// The push constants (the shader's `push_constant` block, byte for byte).
    pub fn constants<T: bytemuck::NoUninit>(mut self, value: &T) -> Self {
        self.constants = bytemuck::bytes_of(value).to_vec();
        self
    }

    /// Tags the pass (`PassBuilder::tag`).
    pub fn tag(mut self, tag: &'static str) -> Self {
        self.pass.tag(tag);
        self
    }

    /// Dispatches enough workgroups (of the shader's reflected local size) to
    /// cover `threads` (x, y, z); 1-D and 2-D dispatches pass 1 for the rest.
    pub fn dispatch(mut self, threads: [u32; 3]) {
        self.pass
            .texels(threads.iter().map(|&t| t as u64).product());
        let local = self.pipeline.interface.local_size;
        let groups = std::array::from_fn(|i| threads[i].div_ceil(local[i].max(1)));
        self.finish(false, move |cx| cx.dispatch(groups))
    }

    /// Dispatches exactly `groups` workgroups (e.g. one per row or per vertex).
    pub fn dispatch_groups(mut self, groups: [u32; 3]) {
        let local = self.pipeline.interface.local_size;
        self.pass
            .texels((0..3).map(|i| groups[i] as u64 * local[i] as u64).product());
        self.finish(false, move |cx| cx.dispatch(groups))
    }

    /// Draws `vertices` vertices without a vertex buffer (full-screen triangle).
    pub fn draw(self, vertices: u32) {
        self.finish(false, move |cx| cx.draw(vertices, 1))
    }

    /// Draws `count` u32 indices from static vertex and index buffers.
    pub fn draw_indexed(self, vertices: &Arc<Buffer>, indices: &Arc<Buffer>, count: u32) {
        let (v, i) = (vertices.clone(), indices.clone());
        self.finish(false, move |cx| {
            cx.bind_vertex_buffer(&v);
            cx.bind_index_buffer(&i);
            cx.draw_indexed(count, 1);
        })
    }

    /// Finishes with a custom body, recorded after the pipeline, descriptors and
    /// constants (if any were given) are bound: several viewports, several draws,
    /// constants pushed per draw by the body.
    pub fn record(self, body: impl Fn(&PassCx) + Send + 'static) {
        self.finish(true, body)
    }

    fn finish(self, custom: bool, body: impl Fn(&PassCx) + Send + 'static) {
        let SimplePass {
            pass,
            pipeline,
            bindings,
            constants,
            mut errors,
        } = self;
        // A custom body may push its own constants.
        let constant_bytes = (!custom || !constants.is_empty()).then_some(constants.len());
        errors.extend(check(&pipeline, &bindings, constant_bytes));
        for e in errors {
            let message = format!("pass {:?} ({}): {e}", pass.pass.name, pipeline.name);
            pass.graph.errors.push(message);
        }
        pass.record(move |cx| {
            cx.bind(&pipeline);
            // Bindings the shader leaves unused (gaps in its layout) are not written.
            let d: Vec<(u32, Descriptor)> = bindings
                .iter()
                .zip(&pipeline.interface.bindings)
                .enumerate()
                .filter(|(_, (_, ty))| ty.is_some())
                .map(|(i, (b, _))| (i as u32, b.descriptor()))
                .collect();
            if !d.is_empty() {
                cx.push_descriptors(&pipeline, &d);
            }
            if !constants.is_empty() {
                cx.push_constant_bytes(&pipeline, &constants);
            }
            body(cx);
        });
    }
}

/// The declared bindings and constants against the reflected layout.
fn check(pipeline: &Pipeline, bindings: &[Bound], constant_bytes: Option<usize>) -> Vec<String> {
    let layout = &pipeline.interface;
    let mut errors = Vec::new();
    // The declaration may name bindings past the shader's last, or in its gaps,
    // that the shader does not use (one declaration for several shaders).
    if bindings.len() < layout.bindings.len() {
        errors.push(format!(
            "declares {} bindings; the shader has {}",
            bindings.len(),
            layout.bindings.len()
        ));
    }
    for (i, (b, ty)) in bindings.iter().zip(&layout.bindings).enumerate() {
        if ty.is_some_and(|t| t != b.descriptor_type()) {
            errors.push(format!(
                "binding {i} is declared {:?}; the shader has {ty:?}",
                b.descriptor_type()
            ));
        }
    }
    if let Some(n) = constant_bytes.filter(|&n| n != layout.push_constant_bytes as usize) {
        errors.push(format!(
            "pushes {n} bytes of constants; the shader's block has {}",
            layout.push_constant_bytes
        ));
    }
    errors
}
