//! Compiling a graph: pass order, barriers, resource lifetimes and transient pool
//! slots. Everything here is plain data, testable without a GPU.

use super::{Access, Graph, ResourceKind};
use crate::error::{Error, Result};
use crate::gpu::ImageDesc;
use crate::timing::PassWork;
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
    /// What the pass is measured against, and its tags (timing::PassWork).
    pub work: PassWork,
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
    /// What the owner keeps after the frame (graph::Kept).
    pub kept: super::Kept,
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

/// The pass's texels (declared, else the render area of its first attachment) and
/// nominal traffic: every graph resource it uses counted once at full size (an
/// image's first mip level); and the traffic it can touch, each image capped at
/// one texel per invocation.
fn work(pass: &super::PassDecl, resources: &[PlannedResource]) -> PassWork {
    let texels = pass.texels.or_else(|| {
        let a = pass.attachments.first()?;
        let d = resources[a.resource].image?;
        Some(d.width as u64 * d.height as u64)
    });
    let mut seen: Vec<usize> = Vec::new();
    let (mut bytes, mut touched_bytes) = (0, 0);
    for &(r, _) in &pass.uses {
        if seen.contains(&r) {
            continue;
        }
        seen.push(r);
        let res = &resources[r];
        let (full, touched) = match (res.image, res.buffer_size) {
            (Some(d), _) => {
                let texel = crate::gpu::texel_bytes(d.format).unwrap_or(0) as u64;
                let full = d.width as u64 * d.height as u64 * texel;
                (full, texels.map_or(full, |t| full.min(t * texel)))
            }
            (None, Some(size)) => (size, size),
            (None, None) => (0, 0),
        };
        bytes += full;
        touched_bytes += touched;
    }
    PassWork {
        texels,
        bytes,
        touched_bytes,
        tags: pass.tags.clone(),
    }
}

impl Graph {
    /// Drops the passes no output needs (`Graph::cull`), then derives the
    /// plan. `pool` is updated only when compilation succeeds.
    pub fn compile(&mut self, pool: &mut PoolState) -> Result<Plan> {
        if !self.errors.is_empty() {
            return Err(Error::Graph(self.errors.join("; ")));
        }
        let kept = self.cull();
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
                work: work(pass, &resources),
            });
        }
        let mut final_barriers = Vec::new();
        for (r, decl) in self.resources.iter().enumerate() {
            let Some(access) = decl.import.as_ref().and_then(|i| i.final_access) else {
                continue;
            };
            // An import no pass used is left as it was.
            if resources[r].lifetime.is_none() {
                continue;
            }
            let is_image = resources[r].image.is_some();
            final_barriers.extend(tracks[r].transition(r, access, is_image, false));
        }
        *pool = next_pool;
        Ok(Plan {
            passes,
            resources,
            final_barriers,
            kept,
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
                // The same read twice (one image sampled by two bindings) is one use.
                if pass.uses[..k]
                    .iter()
                    .any(|&(other, a)| other == r && (a != access || access.info().writes))
                {
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
                // Kept imports not yet computed hold nothing to read either.
                let defined = self.resources[r]
                    .import
                    .as_ref()
                    .is_some_and(|i| i.initial.is_some() || self.resources[r].kept_key.is_none());
                if res.lifetime.is_none() && !defined && !access.info().writes {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::{Graph, ImageHandle, Imported};
    use vk::AccessFlags2 as A;
    use vk::ImageLayout as L;
    use vk::PipelineStageFlags2 as S;

    const F: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

    fn image(g: &mut Graph, name: &str) -> ImageHandle {
        g.create_image(name, ImageDesc::new(64, 64, F))
    }

    fn pass(
        g: &mut Graph,
        name: &str,
        reads: &[(&ImageHandle, Access)],
        writes: &mut [(&mut ImageHandle, Access)],
    ) {
        let mut p = g.add_pass(name);
        for (h, a) in reads {
            p.read(h, *a);
        }
        for (h, a) in writes.iter_mut() {
            p.write(h, *a);
        }
        p.record(|_| {});
    }

    fn barriers_for(plan: &Plan, pass: usize, resource: usize) -> Vec<Barrier> {
        plan.passes[pass]
            .barriers
            .iter()
            .filter(|b| b.resource == resource)
            .copied()
            .collect()
    }

    #[test]
    fn read_after_write_waits_for_the_write_and_transitions() {
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let mut b = image(&mut g, "b");
        pass(
            &mut g,
            "write",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "read",
            &[(&a, Access::ComputeSampled)],
            &mut [(&mut b, Access::ComputeStorageWrite)],
        );
        let plan = g.compile(&mut PoolState::default()).unwrap();
        let first = barriers_for(&plan, 0, 0);
        assert_eq!(first.len(), 1);
        assert_eq!(first[0].layouts, Some((L::UNDEFINED, L::GENERAL)));
        assert_eq!(first[0].src_stage, S::NONE, "fresh slot waits for nothing");
        let raw = barriers_for(&plan, 1, 0);
        assert_eq!(raw.len(), 1);
        let b0 = raw[0];
        assert_eq!(
            (b0.src_stage, b0.src_access),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE)
        );
        assert_eq!(
            (b0.dst_stage, b0.dst_access),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ)
        );
        assert_eq!(b0.layouts, Some((L::GENERAL, L::SHADER_READ_ONLY_OPTIMAL)));
    }

    #[test]
    fn second_reader_in_same_stage_needs_no_barrier_other_stage_does() {
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let (mut b, mut c, mut d) = (image(&mut g, "b"), image(&mut g, "c"), image(&mut g, "d"));
        pass(
            &mut g,
            "w",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "r1",
            &[(&a, Access::ComputeSampled)],
            &mut [(&mut b, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "r2",
            &[(&a, Access::ComputeSampled)],
            &mut [(&mut c, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "r3",
            &[(&a, Access::FragmentSampled)],
            &mut [(&mut d, Access::ColorAttachment)],
        );
        let plan = g.compile(&mut PoolState::default()).unwrap();
        assert!(
            barriers_for(&plan, 2, 0).is_empty(),
            "read-after-read in the same stage"
        );
        let r3 = barriers_for(&plan, 3, 0);
        assert_eq!(r3.len(), 1, "a new stage must wait too");
        assert_eq!(r3[0].dst_stage, S::FRAGMENT_SHADER);
        assert_eq!(
            r3[0].layouts,
            Some((L::SHADER_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL))
        );
        // Chains on the stage that performed the layout transition.
        assert!(r3[0].src_stage.contains(S::COMPUTE_SHADER));
    }

    #[test]
    fn write_after_read_waits_for_readers_without_access() {
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let mut b = image(&mut g, "b");
        pass(
            &mut g,
            "w",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "r",
            &[(&a, Access::FragmentSampled)],
            &mut [(&mut b, Access::ColorAttachment)],
        );
        pass(&mut g, "w2", &[], &mut [(&mut a, Access::TransferDst)]);
        let plan = g.compile(&mut PoolState::default()).unwrap();
        let war = barriers_for(&plan, 2, 0);
        assert_eq!(war.len(), 1);
        assert!(war[0].src_stage.contains(S::FRAGMENT_SHADER));
        assert_eq!(war[0].dst_access, A::TRANSFER_WRITE);
        assert_eq!(
            war[0].layouts,
            Some((L::SHADER_READ_ONLY_OPTIMAL, L::TRANSFER_DST_OPTIMAL))
        );
    }

    #[test]
    fn write_after_write_in_same_layout_carries_the_write_access() {
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        pass(
            &mut g,
            "w1",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        pass(
            &mut g,
            "w2",
            &[],
            &mut [(&mut a, Access::ComputeStorageReadWrite)],
        );
        let plan = g.compile(&mut PoolState::default()).unwrap();
        let waw = barriers_for(&plan, 1, 0);
        assert_eq!(waw.len(), 1);
        assert_eq!(waw[0].src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(waw[0].layouts, Some((L::GENERAL, L::GENERAL)));
    }

    #[test]
    fn transients_with_disjoint_lifetimes_share_a_slot() {
        // a → b → c → d, each written then sampled: same description and usage.
        let mut g = Graph::new();
        let mut imgs: Vec<ImageHandle> = ["a", "b", "c", "d"]
            .iter()
            .map(|n| image(&mut g, n))
            .collect();
        let mut last = image(&mut g, "last");
        pass(
            &mut g,
            "wa",
            &[],
            &mut [(&mut imgs[0], Access::ComputeStorageWrite)],
        );
        for i in 1..4 {
            let (src, dst) = imgs.split_at_mut(i);
            pass(
                &mut g,
                "blur",
                &[(&src[i - 1], Access::ComputeSampled)],
                &mut [(&mut dst[0], Access::ComputeStorageWrite)],
            );
        }
        pass(
            &mut g,
            "final",
            &[(&imgs[3], Access::ComputeSampled)],
            &mut [(&mut last, Access::ComputeStorageWrite)],
        );
        let mut pool = PoolState::default();
        let plan = g.compile(&mut pool).unwrap();
        let slots: Vec<_> = plan.resources.iter().map(|r| r.slot.unwrap()).collect();
        assert_eq!(
            &slots[..4],
            &[0, 1, 0, 1],
            "a chain needs only two live targets"
        );
        assert_ne!(slots[4], 0, "different usage, different slot");
        // c's first barrier discards, but waits for a's last reader (a WAR on the memory).
        let alias = barriers_for(&plan, 2, 2);
        assert_eq!(alias[0].layouts, Some((L::UNDEFINED, L::GENERAL)));
        assert!(alias[0].src_stage.contains(S::COMPUTE_SHADER));
    }

    #[test]
    fn reuse_across_frames_waits_for_the_previous_frame() {
        let build = || {
            let mut g = Graph::new();
            let mut a = image(&mut g, "a");
            let mut out = g.import_image(
                "out",
                Imported::Described {
                    image: Some(ImageDesc::new(64, 64, F)),
                    buffer_size: 0,
                    image_usage: vk::ImageUsageFlags::COLOR_ATTACHMENT,
                    buffer_usage: vk::BufferUsageFlags::empty(),
                },
                None,
                None,
            );
            pass(
                &mut g,
                "wa",
                &[],
                &mut [(&mut a, Access::ComputeStorageWrite)],
            );
            pass(
                &mut g,
                "draw",
                &[(&a, Access::FragmentSampled)],
                &mut [(&mut out, Access::ColorAttachment)],
            );
            g
        };
        let mut pool = PoolState::default();
        let first = build().compile(&mut pool).unwrap();
        let second = build().compile(&mut pool).unwrap();
        assert_eq!(
            pool.slot_count(),
            1,
            "the second frame reuses the pooled image"
        );
        assert_eq!(first.passes[0].barriers[0].src_stage, S::NONE);
        let b = second.passes[0].barriers[0];
        assert_eq!(b.layouts, Some((L::UNDEFINED, L::GENERAL)));
        assert!(
            b.src_stage.contains(S::FRAGMENT_SHADER),
            "frame 2's write must wait for frame 1's sampling: {b:?}"
        );
    }

    #[test]
    fn imports_start_from_their_initial_access_and_end_in_their_final_one() {
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let mut buf = g.import_buffer(
            "readback",
            Imported::Described {
                image: None,
                buffer_size: 64 * 64 * 8,
                image_usage: vk::ImageUsageFlags::empty(),
                buffer_usage: vk::BufferUsageFlags::TRANSFER_DST,
            },
            Some(Access::HostRead),
            Some(Access::HostRead),
        );
        pass(
            &mut g,
            "wa",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        let mut p = g.add_pass("copy");
        p.read(&a, Access::TransferSrc);
        p.write_buffer(&mut buf, Access::TransferDst);
        p.record(|_| {});
        let plan = g.compile(&mut PoolState::default()).unwrap();
        let copy = barriers_for(&plan, 1, 1);
        assert_eq!(copy[0].src_stage, S::HOST, "waits for the host's last read");
        assert_eq!(copy[0].layouts, None);
        let end = plan.final_barriers[0];
        assert_eq!(
            (end.src_access, end.dst_stage, end.dst_access),
            (A::TRANSFER_WRITE, S::HOST, A::HOST_READ)
        );
    }

    #[test]
    fn a_swapchain_image_is_drawn_after_its_acquire_and_left_for_present() {
        let mut g = Graph::new();
        let mut target = g.import_image(
            "swapchain",
            Imported::Described {
                image: Some(ImageDesc::new(64, 64, vk::Format::B8G8R8A8_UNORM)),
                buffer_size: 0,
                image_usage: vk::ImageUsageFlags::COLOR_ATTACHMENT,
                buffer_usage: vk::BufferUsageFlags::empty(),
            },
            Some(Access::Acquired),
            Some(Access::Present),
        );
        let mut p = g.add_pass("ui");
        p.color_attachment(&mut target, crate::graph::LoadOp::Clear([0.0; 4]));
        p.record(|_| {});
        let plan = g.compile(&mut PoolState::default()).unwrap();
        let first = barriers_for(&plan, 0, 0)[0];
        // Chains with the acquire semaphore's wait at the attachment stage.
        assert_eq!(
            (first.src_stage, first.src_access),
            (S::COLOR_ATTACHMENT_OUTPUT, A::NONE)
        );
        assert_eq!(
            first.layouts,
            Some((L::UNDEFINED, L::COLOR_ATTACHMENT_OPTIMAL))
        );
        let end = plan.final_barriers[0];
        assert_eq!(end.src_stage, S::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(
            end.layouts,
            Some((L::COLOR_ATTACHMENT_OPTIMAL, L::PRESENT_SRC_KHR))
        );
    }

    #[test]
    fn declaration_errors_are_reported() {
        let mut g = Graph::new();
        let a = image(&mut g, "a");
        let mut b = image(&mut g, "b");
        pass(
            &mut g,
            "early read",
            &[(&a, Access::ComputeSampled)],
            &mut [(&mut b, Access::ComputeStorageWrite)],
        );
        let e = g
            .compile(&mut PoolState::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("reads \"a\" before any pass writes it"), "{e}");

        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let mut p = g.add_pass("twice");
        p.write(&mut a, Access::ComputeStorageWrite);
        p.write(&mut a, Access::TransferDst);
        p.record(|_| {});
        assert!(g.compile(&mut PoolState::default()).is_err());

        // One image read twice with one access (two sampled bindings) is fine;
        // read with two different accesses it is not.
        for (second, ok) in [(Access::ComputeSampled, true), (Access::TransferSrc, false)] {
            let mut g = Graph::new();
            let mut a = image(&mut g, "a");
            let mut b = image(&mut g, "b");
            pass(
                &mut g,
                "fill",
                &[],
                &mut [(&mut a, Access::ComputeStorageWrite)],
            );
            pass(
                &mut g,
                "read twice",
                &[(&a, Access::ComputeSampled), (&a, second)],
                &mut [(&mut b, Access::ComputeStorageWrite)],
            );
            pass(&mut g, "sink", &[(&b, Access::TransferSrc)], &mut []);
            assert_eq!(
                g.compile(&mut PoolState::default()).is_ok(),
                ok,
                "{second:?}"
            );
        }

        let mut g = Graph::new();
        let mut out = g.import_image(
            "out",
            Imported::Described {
                image: Some(ImageDesc::new(8, 8, F)),
                buffer_size: 0,
                image_usage: vk::ImageUsageFlags::SAMPLED,
                buffer_usage: vk::BufferUsageFlags::empty(),
            },
            None,
            None,
        );
        pass(
            &mut g,
            "w",
            &[],
            &mut [(&mut out, Access::ComputeStorageWrite)],
        );
        let e = g
            .compile(&mut PoolState::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("lacks usage flags"), "{e}");
    }

    #[test]
    fn failed_compile_leaves_the_pool_untouched() {
        let mut pool = PoolState::default();
        let mut g = Graph::new();
        let mut a = image(&mut g, "a");
        let b = image(&mut g, "b");
        pass(
            &mut g,
            "w",
            &[],
            &mut [(&mut a, Access::ComputeStorageWrite)],
        );
        pass(&mut g, "bad", &[(&b, Access::ComputeSampled)], &mut []);
        assert!(g.compile(&mut pool).is_err());
        assert_eq!(pool.slot_count(), 0);
    }
}
