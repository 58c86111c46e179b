//! The render graph: passes declare what they read and write; the graph derives
//! barriers, layouts, usage flags, transient lifetimes and pooling, then records.
//! It knows nothing about skin.
//!
//! Building (`Graph`, `PassBuilder`) → compiling (`Graph::compile` → [`Plan`],
//! plain data) → executing (`Executor::submit`). Writes take `&mut` handles and
//! reads `&` handles (kajiya-rg), so the code shows who mutates what.

mod access;
mod commands;
mod cull;
mod execute;
mod pass_cx;
mod plan;
mod simple;
pub mod upload;

pub use access::{Access, AccessInfo};
pub use cull::Kept;
pub use execute::{Clock, Compiled, Executor, FrameSync};
pub use pass_cx::{Descriptor, PassCx, ResolvedImage};
pub use plan::{Barrier, Plan, PlannedPass, PlannedResource, PoolState};
pub use simple::SimplePass;

use crate::gpu::{Buffer, Image, ImageDesc};
use ash::vk;
use std::sync::Arc;

/// A graph image. Not `Copy`: writing needs `&mut`.
#[derive(Debug)]
pub struct ImageHandle {
    id: usize,
    pub desc: ImageDesc,
}

/// A graph buffer. Not `Copy`: writing needs `&mut`.
#[derive(Debug)]
pub struct BufferHandle {
    id: usize,
    pub size: u64,
}

/// What a pass's recording closure uses to name an image it declared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageRef(pub(crate) usize);

/// What a pass's recording closure uses to name a buffer it declared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferRef(pub(crate) usize);

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadOp {
    Clear([f32; 4]),
    Load,
    DontCare,
}

/// A resource owned outside the graph.
pub enum Imported {
    Image(Arc<Image>),
    Buffer(Arc<Buffer>),
    /// Only described: enough to plan (tests, `--dump-graph`), not to execute.
    Described {
        image: Option<ImageDesc>,
        buffer_size: u64,
        image_usage: vk::ImageUsageFlags,
        buffer_usage: vk::BufferUsageFlags,
    },
}

pub(crate) enum ResourceKind {
    Image(ImageDesc),
    Buffer(u64),
}

pub(crate) struct ResourceDecl {
    pub name: String,
    pub kind: ResourceKind,
    pub import: Option<ImportDecl>,
    /// Kept across frames (`Graph::import_kept_image`): the key of the inputs
    /// its contents are to be computed from.
    pub kept_key: Option<u64>,
}

pub(crate) struct ImportDecl {
    pub source: Imported,
    /// The access the resource was last used with before this graph (`None`: nothing
    /// to wait for, contents undefined).
    pub initial: Option<Access>,
    /// The access to leave it ready for after the graph (e.g. `HostRead`).
    pub final_access: Option<Access>,
}

pub(crate) struct Attachment {
    pub resource: usize,
    pub load: LoadOp,
    pub depth: bool,
}

pub(crate) type RecordFn = Box<dyn Fn(&PassCx) + Send>;

pub(crate) struct PassDecl {
    pub name: String,
    /// Texels (invocations) the pass computes; `None`: its render area, if any.
    pub texels: Option<u64>,
    pub uses: Vec<(usize, Access)>,
    pub attachments: Vec<Attachment>,
    pub record: Option<RecordFn>,
    /// What the pass belongs to (e.g. the diffusion chain), for reports.
    pub tags: Vec<&'static str>,
}

#[derive(Default)]
pub struct Graph {
    pub(crate) resources: Vec<ResourceDecl>,
    pub(crate) passes: Vec<PassDecl>,
    /// Declarations that contradict a shader's reflected layout; compiling fails.
    pub(crate) errors: Vec<String>,
    /// Resources requested by the graph's owner (`Graph::output`).
    pub(crate) outputs: Vec<usize>,
    /// Other names of resources (`Graph::alias`).
    pub(crate) aliases: Vec<(String, usize)>,
    /// The keys the owner's kept resources were last computed for.
    pub(crate) kept: Kept,
}

impl Graph {
    pub fn new() -> Self {
        Self::default()
    }

    /// A graph whose owner keeps resources across frames: `kept` says which
    /// were computed, and for what (see [`Graph::import_kept_image`]).
    pub fn with_kept(kept: Kept) -> Self {
        Self {
            kept,
            ..Self::default()
        }
    }

    /// Requests `image` as an output: the passes it depends on are kept when
    /// the graph compiles (see [`Graph::compile`]).
    pub fn output(&mut self, image: &ImageHandle) {
        self.outputs.push(image.id);
    }

    /// Requests `buffer` as an output.
    pub fn output_buffer(&mut self, buffer: &BufferHandle) {
        self.outputs.push(buffer.id);
    }

    /// Gives `image` another name, by which [`Graph::find_image`] finds it
    /// (e.g. a level that is its predecessor's image).
    pub fn alias(&mut self, name: &str, image: &ImageHandle) {
        self.aliases.push((name.into(), image.id));
    }

    /// The image named `name` (its own name or an alias; the last declared
    /// of that name), readable by a pass added later.
    pub fn find_image(&self, name: &str) -> Option<ImageHandle> {
        let own = self
            .resources
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name.as_str(), i));
        let aliases = self.aliases.iter().map(|(n, i)| (n.as_str(), *i));
        let id = own.chain(aliases).rfind(|(n, _)| *n == name)?.1;
        match self.resources[id].kind {
            ResourceKind::Image(desc) => Some(ImageHandle { id, desc }),
            ResourceKind::Buffer(_) => None,
        }
    }

    /// The names of the graph's images and their aliases, in declaration order.
    pub fn image_names(&self) -> Vec<String> {
        let own = self
            .resources
            .iter()
            .filter(|r| matches!(r.kind, ResourceKind::Image(_)))
            .map(|r| r.name.clone());
        let mut names: Vec<String> = Vec::new();
        for n in own.chain(self.aliases.iter().map(|(n, _)| n.clone())) {
            if !names.contains(&n) {
                names.push(n);
            }
        }
        names
    }

    /// An image that lives only within the frame; backed by the executor's pool.
    pub fn create_image(&mut self, name: &str, desc: ImageDesc) -> ImageHandle {
        self.resources.push(ResourceDecl {
            name: name.into(),
            kind: ResourceKind::Image(desc),
            import: None,
            kept_key: None,
        });
        ImageHandle {
            id: self.resources.len() - 1,
            desc,
        }
    }

    pub fn import_image(
        &mut self,
        name: &str,
        image: Imported,
        initial: Option<Access>,
        final_access: Option<Access>,
    ) -> ImageHandle {
        let desc = match &image {
            Imported::Image(i) => i.desc,
            Imported::Described { image: Some(d), .. } => *d,
            _ => ImageDesc::new(0, 0, vk::Format::UNDEFINED),
        };
        self.resources.push(ResourceDecl {
            name: name.into(),
            kind: ResourceKind::Image(desc),
            import: Some(ImportDecl {
                source: image,
                initial,
                final_access,
            }),
            kept_key: None,
        });
        ImageHandle {
            id: self.resources.len() - 1,
            desc,
        }
    }

    pub fn import_buffer(
        &mut self,
        name: &str,
        buffer: Imported,
        initial: Option<Access>,
        final_access: Option<Access>,
    ) -> BufferHandle {
        let size = match &buffer {
            Imported::Buffer(b) => b.size,
            Imported::Described { buffer_size, .. } => *buffer_size,
            Imported::Image(_) => 0,
        };
        self.resources.push(ResourceDecl {
            name: name.into(),
            kind: ResourceKind::Buffer(size),
            import: Some(ImportDecl {
                source: buffer,
                initial,
                final_access,
            }),
            kept_key: None,
        });
        BufferHandle {
            id: self.resources.len() - 1,
            size,
        }
    }

    pub fn add_pass(&mut self, name: &str) -> PassBuilder<'_> {
        PassBuilder {
            graph: self,
            pass: PassDecl {
                name: name.into(),
                texels: None,
                uses: Vec::new(),
                attachments: Vec::new(),
                record: None,
                tags: Vec::new(),
            },
        }
    }
}

pub struct PassBuilder<'g> {
    graph: &'g mut Graph,
    pass: PassDecl,
}

impl PassBuilder<'_> {
    pub fn read(&mut self, image: &ImageHandle, access: Access) -> ImageRef {
        self.pass.uses.push((image.id, access));
        ImageRef(image.id)
    }

    pub fn write(&mut self, image: &mut ImageHandle, access: Access) -> ImageRef {
        self.pass.uses.push((image.id, access));
        ImageRef(image.id)
    }

    pub fn read_buffer(&mut self, buffer: &BufferHandle, access: Access) -> BufferRef {
        self.pass.uses.push((buffer.id, access));
        BufferRef(buffer.id)
    }

    pub fn write_buffer(&mut self, buffer: &mut BufferHandle, access: Access) -> BufferRef {
        self.pass.uses.push((buffer.id, access));
        BufferRef(buffer.id)
    }

    /// A colour attachment; the executor begins and ends dynamic rendering around
    /// the pass and sets the viewport and scissor to the attachment's extent.
    pub fn color_attachment(&mut self, image: &mut ImageHandle, load: LoadOp) -> ImageRef {
        self.pass.attachments.push(Attachment {
            resource: image.id,
            load,
            depth: false,
        });
        self.write(image, Access::ColorAttachment)
    }

    pub fn depth_attachment(&mut self, image: &mut ImageHandle, load: LoadOp) -> ImageRef {
        self.pass.attachments.push(Attachment {
            resource: image.id,
            load,
            depth: true,
        });
        self.write(image, Access::DepthAttachment)
    }

    /// Tags the pass (e.g. as part of the diffusion chain): reports carry it.
    pub fn tag(&mut self, tag: &'static str) {
        self.pass.tags.push(tag);
    }

    /// How many texels (invocations) the pass computes, for per-texel costs
    /// (a graphics pass defaults to its render area).
    pub fn texels(&mut self, texels: u64) {
        self.pass.texels = Some(texels);
    }

    /// Finishes the pass with the closure that records its commands.
    pub fn record(mut self, f: impl Fn(&PassCx) + Send + 'static) {
        self.pass.record = Some(Box::new(f));
        self.graph.passes.push(self.pass);
    }
}
