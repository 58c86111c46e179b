//! Compiling a graph: pass order, barriers, resource lifetimes and transient pool
//! slots. Everything here is plain data, testable without a GPU.

use super::{Access, Graph, ResourceKind};
use crate::error::{Error, Result};
use crate::gpu::ImageDesc;
use ash::vk;
use std::fmt;

/// One image or buffer barrier (synchronization2), derived from two accesses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Barrier {
    pub resource: usize,
    pub src_stage: vk::PipelineStageFlags2,
    pub src_access: vk::AccessFlags2,
    pub dst_stage: vk::PipelineStageFlags2,
    pub dst_access: vk::AccessFlags2,
    /// `Some((old, new))` for images, `None` for buffers.
    pub layouts: Option<(vk::ImageLayout, vk::ImageLayout)>,
}

#[derive(Clone, Debug)]
pub struct PlannedPass {
    pub name: String,
    /// Issued as one `vkCmdPipelineBarrier2` before the pass.
    pub barriers: Vec<Barrier>,
}

#[derive(Clone, Debug)]
pub struct PlannedResource {
    pub name: String,
    pub image: Option<ImageDesc>,
    pub buffer_size: Option<u64>,
    pub image_usage: vk::ImageUsageFlags,
    pub buffer_usage: vk::BufferUsageFlags,
    pub imported: bool,
    /// First and last pass index using it; `None` if no pass does.
    pub lifetime: Option<(usize, usize)>,
    /// Transient pool slot backing it (aliased when lifetimes do not overlap).
    pub slot: Option<usize>,
}

#[derive(Clone, Debug)]
pub struct Plan {
    pub passes: Vec<PlannedPass>,
    pub resources: Vec<PlannedResource>,
    /// Issued after the last pass (imports' final accesses).
    pub final_barriers: Vec<Barrier>,
}

/// Synchronisation state of one piece of memory (a pool slot or an import).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Track {
    layout: vk::ImageLayout,
    /// Stages and access of the last write (a layout transition counts, with no access).
    write: Option<(vk::PipelineStageFlags2, vk::AccessFlags2)>,
    /// Stages that have read since that write.
    read_stages: vk::PipelineStageFlags2,
    /// Stages/accesses already made to wait for that write.
    synced_stages: vk::PipelineStageFlags2,
    synced_access: vk::AccessFlags2,
}

impl Track {
    fn fresh() -> Self {
        Track {
            layout: vk::ImageLayout::UNDEFINED,
            write: None,
            read_stages: vk::PipelineStageFlags2::NONE,
            synced_stages: vk::PipelineStageFlags2::NONE,
            synced_access: vk::AccessFlags2::NONE,
        }
    }

    fn after(access: Access) -> Self {
        let i = access.info();
        let mut t = Track::fresh();
        t.layout = i.layout;
        if i.writes {
            t.write = Some((i.stages, i.access));
        } else {
            t.read_stages = i.stages;
            t.synced_stages = i.stages;
            t.synced_access = i.access;
        }
        t
    }

    /// The barrier needed before `access`, updating the state. `discard`: the
    /// previous contents are not needed (first use of a transient).
    fn transition(
        &mut self,
        resource: usize,
        access: Access,
        is_image: bool,
        discard: bool,
    ) -> Option<Barrier> {
        let next = access.info();
        let layout_change = is_image && (discard || self.layout != next.layout);
        let old_layout = if discard {
            vk::ImageLayout::UNDEFINED
        } else {
            self.layout
        };
        let (w_stage, w_access) = self
            .write
            .unwrap_or((vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE));
        let barrier = |src_stage, src_access| Barrier {
            resource,
            src_stage,
            src_access,
            dst_stage: next.stages,
            dst_access: next.access,
            layouts: is_image.then_some((old_layout, next.layout)),
        };
        if next.writes || layout_change {
            // WAW / WAR / layout transition: wait for the last write and every read since.
            let src_stage = w_stage | self.read_stages;
            let nothing_before = src_stage.is_empty();
            *self = Track::fresh();
            self.layout = next.layout;
            if next.writes {
                self.write = Some((next.stages, next.access));
            } else {
                // A read that transitioned: later readers chain on its stages.
                self.write = Some((next.stages, vk::AccessFlags2::NONE));
                self.read_stages = next.stages;
                self.synced_stages = next.stages;
                self.synced_access = next.access;
            }
            if nothing_before && !layout_change {
                return None;
            }
            return Some(barrier(src_stage, w_access));
        }
        // A read in the current layout.
        self.read_stages |= next.stages;
        let synced =
            self.synced_stages.contains(next.stages) && self.synced_access.contains(next.access);
        if self.write.is_none() || synced {
            return None;
        }
        self.synced_stages |= next.stages;
        self.synced_access |= next.access;
        Some(barrier(w_stage, w_access))
    }
}

#[derive(Clone, Debug)]
struct Slot {
    desc: ImageDesc,
    usage: vk::ImageUsageFlags,
    track: Track,
}

/// Transient pool bookkeeping carried from frame to frame: which slots exist and
/// how each was last accessed (so the first barrier of a frame waits for the last
/// use in the previous one).
#[derive(Clone, Debug, Default)]
pub struct PoolState {
    slots: Vec<Slot>,
}

impl PoolState {
    pub fn slot_count(&self) -> usize {
        self.slots.len()
    }

    pub fn slot(&self, i: usize) -> Option<(ImageDesc, vk::ImageUsageFlags)> {
        self.slots.get(i).map(|s| (s.desc, s.usage))
    }
}

impl Graph {
    /// Derives the plan. `pool` is updated only when compilation succeeds.
    pub fn compile(&self, pool: &mut PoolState) -> Result<Plan> {
        let mut resources = self.plan_resources()?;
        let mut next_pool = pool.clone();
        assign_slots(&mut resources, &mut next_pool);

        let mut tracks: Vec<Track> = self
            .resources
            .iter()
            .map(|r| {
                r.import
                    .as_ref()
                    .and_then(|i| i.initial)
                    .map_or_else(Track::fresh, Track::after)
            })
            .collect();
        let mut passes = Vec::with_capacity(self.passes.len());
        for (p, pass) in self.passes.iter().enumerate() {
            let mut barriers = Vec::new();
            for &(r, access) in &pass.uses {
                let res = &resources[r];
                let is_image = res.image.is_some();
                let discard = !res.imported && res.lifetime.is_some_and(|(first, _)| first == p);
                let track = match res.slot {
                    Some(s) => &mut next_pool.slots[s].track,
                    None => &mut tracks[r],
                };
                barriers.extend(track.transition(r, access, is_image, discard));
            }
            passes.push(PlannedPass {
                name: pass.name.clone(),
                barriers,
            });
        }
        let mut final_barriers = Vec::new();
        for (r, decl) in self.resources.iter().enumerate() {
            let Some(access) = decl.import.as_ref().and_then(|i| i.final_access) else {
                continue;
            };
            let is_image = resources[r].image.is_some();
            final_barriers.extend(tracks[r].transition(r, access, is_image, false));
        }
        *pool = next_pool;
        Ok(Plan {
            passes,
            resources,
            final_barriers,
        })
    }

    /// Lifetimes and usage of every resource, with the declaration checks.
    fn plan_resources(&self) -> Result<Vec<PlannedResource>> {
        let mut out: Vec<PlannedResource> = self
            .resources
            .iter()
            .map(|r| PlannedResource {
                name: r.name.clone(),
                image: match r.kind {
                    ResourceKind::Image(d) => Some(d),
                    ResourceKind::Buffer(_) => None,
                },
                buffer_size: match r.kind {
                    ResourceKind::Buffer(s) => Some(s),
                    ResourceKind::Image(_) => None,
                },
                image_usage: vk::ImageUsageFlags::empty(),
                buffer_usage: vk::BufferUsageFlags::empty(),
                imported: r.import.is_some(),
                lifetime: None,
                slot: None,
            })
            .collect();
        for (p, pass) in self.passes.iter().enumerate() {
            for (k, &(r, access)) in pass.uses.iter().enumerate() {
                let res = &mut out[r];
                if pass.uses[..k].iter().any(|&(other, _)| other == r) {
                    return Err(Error::Graph(format!(
                        "pass {:?} declares {:?} twice; use one combined access",
                        pass.name, res.name
                    )));
                }
                let fits = if res.image.is_some() {
                    access.for_images()
                } else {
                    access.for_buffers()
                };
                if !fits {
                    return Err(Error::Graph(format!(
                        "pass {:?}: {access:?} does not apply to {:?}",
                        pass.name, res.name
                    )));
                }
                if res.lifetime.is_none() && !res.imported && !access.info().writes {
                    return Err(Error::Graph(format!(
                        "pass {:?} reads {:?} before any pass writes it",
                        pass.name, res.name
                    )));
                }
                res.lifetime = Some(res.lifetime.map_or((p, p), |(first, _)| (first, p)));
                if res.image.is_some() {
                    res.image_usage |= access.image_usage();
                } else {
                    res.buffer_usage |= access.buffer_usage();
                }
            }
        }
        for (decl, res) in self.resources.iter().zip(&out) {
            let Some(import) = &decl.import else {
                if res.image.is_none() {
                    return Err(Error::Graph(format!(
                        "buffer {:?} must be imported",
                        res.name
                    )));
                }
                continue;
            };
            let (have_image, have_buffer) = match &import.source {
                super::Imported::Image(i) => (i.usage, vk::BufferUsageFlags::empty()),
                super::Imported::Buffer(b) => (vk::ImageUsageFlags::empty(), b.usage),
                super::Imported::Described {
                    image_usage,
                    buffer_usage,
                    ..
                } => (*image_usage, *buffer_usage),
            };
            if !have_image.contains(res.image_usage) || !have_buffer.contains(res.buffer_usage) {
                return Err(Error::Graph(format!(
                    "imported {:?} lacks usage flags its passes need ({:?} / {:?})",
                    res.name, res.image_usage, res.buffer_usage
                )));
            }
        }
        Ok(out)
    }
}

/// Gives every used transient image a pool slot with the same description and
/// usage; a slot is reused once its previous holder's last pass is over.
fn assign_slots(resources: &mut [PlannedResource], pool: &mut PoolState) {
    let mut order: Vec<usize> = (0..resources.len())
        .filter(|&r| !resources[r].imported && resources[r].lifetime.is_some())
        .collect();
    order.sort_by_key(|&r| resources[r].lifetime.map(|l| l.0));
    // Last pass of this frame's current holder of each slot.
    let mut busy_until: Vec<Option<usize>> = vec![None; pool.slots.len()];
    for r in order {
        let (Some(desc), Some((first, last))) = (resources[r].image, resources[r].lifetime) else {
            continue;
        };
        let usage = resources[r].image_usage;
        let free = (0..pool.slots.len()).find(|&s| {
            pool.slots[s].desc == desc
                && pool.slots[s].usage == usage
                && busy_until[s].is_none_or(|end| end < first)
        });
        let slot = free.unwrap_or_else(|| {
            pool.slots.push(Slot {
                desc,
                usage,
                track: Track::fresh(),
            });
            busy_until.push(None);
            pool.slots.len() - 1
        });
        busy_until[slot] = Some(last);
        resources[r].slot = Some(slot);
    }
}

impl fmt::Display for Plan {
    /// The plan as `dermis render --dump-graph` prints it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "resources:")?;
        for (i, r) in self.resources.iter().enumerate() {
            let what = match (r.image, r.buffer_size) {
                (Some(d), _) => format!("image {}x{} {:?}", d.width, d.height, d.format),
                (None, Some(s)) => format!("buffer {s} bytes"),
                _ => String::new(),
            };
            let origin = match (r.imported, r.slot) {
                (true, _) => "imported".to_string(),
                (false, Some(s)) => format!("pool slot {s}"),
                (false, None) => "unused".to_string(),
            };
            let life = r
                .lifetime
                .map_or(String::from("-"), |(a, b)| format!("passes {a}..={b}"));
            writeln!(f, "  #{i} {:<18} {what}, {origin}, {life}", r.name)?;
        }
        writeln!(f, "passes:")?;
        for (i, p) in self.passes.iter().enumerate() {
            writeln!(f, "  {i}: {}", p.name)?;
            for b in &p.barriers {
                writeln!(f, "      {}", BarrierDisplay(b, &self.resources))?;
            }
        }
        if !self.final_barriers.is_empty() {
            writeln!(f, "  end:")?;
            for b in &self.final_barriers {
                writeln!(f, "      {}", BarrierDisplay(b, &self.resources))?;
            }
        }
        Ok(())
    }
}

struct BarrierDisplay<'a>(&'a Barrier, &'a [PlannedResource]);

impl fmt::Display for BarrierDisplay<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = self.0;
        let name = self.1.get(b.resource).map_or("?", |r| r.name.as_str());
        write!(
            f,
            "barrier {name}: {:?}/{:?} -> {:?}/{:?}",
            b.src_stage, b.src_access, b.dst_stage, b.dst_access
        )?;
        if let Some((old, new)) = b.layouts {
            write!(f, ", {old:?} -> {new:?}")?;
        }
        Ok(())
    }
}
