//! What a graph runs: the passes its outputs depend on (after Granite's
//! `RenderGraph::bake`, which walks back from the requested output), and the
//! resources its owner keeps across frames, looked up by key (after kajiya-rg's
//! temporal resources): a kept resource is computed when its key is new and
//! reused while it stays the same.

use super::{Access, BufferHandle, Graph, ImageHandle, Imported};
use crate::gpu::Image;
use std::collections::HashMap;
use std::sync::Arc;

/// The key each kept resource was last computed for, by name: what a graph's
/// owner carries from one frame to the next (`Graph::with_kept`, `Plan::kept`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Kept(HashMap<String, u64>);

impl Kept {
    /// Whether `name` holds what `key`'s inputs give.
    pub fn holds(&self, name: &str, key: u64) -> bool {
        self.0.get(name) == Some(&key)
    }
}

impl Graph {
    /// A resource kept across frames (an image the owner made): valid if the
    /// owner's [`Kept`] says it was computed for `key`. Returns the handle and
    /// whether it is to be computed; then declare the passes that compute it,
    /// and the graph runs them only if a requested output needs it. `access`:
    /// how its readers use it, and how every frame leaves it.
    pub fn import_kept_image(
        &mut self,
        name: &str,
        image: Imported,
        access: Access,
        key: u64,
    ) -> (ImageHandle, bool) {
        let valid = self.kept.holds(name, key);
        let handle = self.import_image(name, image, valid.then_some(access), Some(access));
        let compute = self.keep(handle.id, key, valid);
        (handle, compute)
    }

    /// [`Graph::import_kept_image`] for images one pass computes together:
    /// their handles, and whether any of them is to be computed (then the
    /// pass writes them all).
    pub fn import_kept_images<const N: usize>(
        &mut self,
        images: [(&str, &Arc<Image>); N],
        access: Access,
        key: u64,
    ) -> ([ImageHandle; N], bool) {
        let mut compute = false;
        let handles = images.map(|(name, image)| {
            let imported = Imported::Image(image.clone());
            let (handle, stale) = self.import_kept_image(name, imported, access, key);
            compute |= stale;
            handle
        });
        (handles, compute)
    }

    /// [`Graph::import_kept_image`] for a buffer.
    pub fn import_kept_buffer(
        &mut self,
        name: &str,
        buffer: Imported,
        access: Access,
        key: u64,
    ) -> (BufferHandle, bool) {
        let valid = self.kept.holds(name, key);
        let handle = self.import_buffer(name, buffer, valid.then_some(access), Some(access));
        let compute = self.keep(handle.id, key, valid);
        (handle, compute)
    }

    /// Marks resource `id` kept for `key`; whether it is to be computed.
    fn keep(&mut self, id: usize, key: u64, valid: bool) -> bool {
        self.resources[id].kept_key = Some(key);
        !valid
    }

    /// Drops the passes no output depends on, and returns what the owner keeps
    /// after the frame. The outputs are the requested resources and the imports
    /// left for a use after the graph (a final access: readbacks, swapchain
    /// images), kept resources aside. A graph without any output runs whole.
    pub(super) fn cull(&mut self) -> Kept {
        let mut needed = vec![false; self.resources.len()];
        for &r in &self.outputs {
            needed[r] = true;
        }
        for (r, decl) in self.resources.iter().enumerate() {
            let after = decl
                .import
                .as_ref()
                .is_some_and(|i| i.final_access.is_some());
            needed[r] |= after && decl.kept_key.is_none();
        }
        if needed.iter().any(|&n| n) {
            let mut keep = vec![false; self.passes.len()];
            for (p, pass) in self.passes.iter().enumerate().rev() {
                keep[p] = pass.uses.iter().any(|&(r, a)| needed[r] && a.info().writes);
                if keep[p] {
                    for &(r, _) in &pass.uses {
                        needed[r] = true;
                    }
                }
            }
            let mut keep = keep.into_iter();
            self.passes.retain(|_| keep.next().unwrap_or(true));
        }
        self.kept_after()
    }

    /// The owner's kept keys after the surviving passes ran: a kept resource
    /// they write holds its new key; one they leave holds what it held.
    fn kept_after(&self) -> Kept {
        let mut kept = self.kept.clone();
        for (r, decl) in self.resources.iter().enumerate() {
            let Some(key) = decl.kept_key else { continue };
            let written = self
                .passes
                .iter()
                .any(|p| p.uses.iter().any(|&(u, a)| u == r && a.info().writes));
            if written {
                kept.0.insert(decl.name.clone(), key);
            } else if !kept.holds(&decl.name, key) {
                kept.0.remove(&decl.name);
            }
        }
        kept
    }
}

#[cfg(test)]
mod tests {
    use crate::gpu::ImageDesc;
    use crate::graph::plan::PoolState;
    use crate::graph::{Access, Graph, ImageHandle, Imported, Kept};
    use ash::vk;

    const F: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

    fn described() -> Imported {
        Imported::Described {
            image: Some(ImageDesc::new(8, 8, F)),
            buffer_size: 0,
            image_usage: vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED,
            buffer_usage: vk::BufferUsageFlags::empty(),
        }
    }

    /// A compute pass `name` sampling `reads` and storing `write`.
    fn pass(g: &mut Graph, name: &str, reads: &[&ImageHandle], write: &mut ImageHandle) {
        let mut p = g.add_pass(name);
        for r in reads {
            p.read(r, Access::ComputeSampled);
        }
        p.write(write, Access::ComputeStorageWrite);
        p.record(|_| {});
    }

    fn names(g: &mut Graph) -> Vec<String> {
        let plan = g.compile(&mut PoolState::default()).unwrap();
        plan.passes.into_iter().map(|p| p.name).collect()
    }

    /// a → b → c, and a → d: two branches from one source.
    fn branches(g: &mut Graph) -> (ImageHandle, ImageHandle) {
        let desc = ImageDesc::new(8, 8, F);
        let [mut a, mut b, mut c, mut d] = ["a", "b", "c", "d"].map(|n| g.create_image(n, desc));
        pass(g, "make_a", &[], &mut a);
        pass(g, "make_b", &[&a], &mut b);
        pass(g, "make_d", &[&a], &mut d);
        pass(g, "make_c", &[&b], &mut c);
        (c, d)
    }

    #[test]
    fn culling_keeps_only_what_an_output_needs() {
        let mut g = Graph::new();
        let (_, d) = branches(&mut g);
        g.output(&d);
        assert_eq!(names(&mut g), ["make_a", "make_d"]);

        let mut g = Graph::new();
        let (c, _) = branches(&mut g);
        g.output(&c);
        assert_eq!(names(&mut g), ["make_a", "make_b", "make_c"]);
    }

    #[test]
    fn two_outputs_keep_the_union() {
        let mut g = Graph::new();
        let (c, d) = branches(&mut g);
        g.output(&c);
        g.output(&d);
        assert_eq!(names(&mut g), ["make_a", "make_b", "make_d", "make_c"]);
    }

    #[test]
    fn an_import_left_for_later_is_an_output_and_no_output_keeps_all() {
        let mut g = Graph::new();
        let (c, _) = branches(&mut g);
        let mut out = g.import_image("out", described(), None, Some(Access::ShaderSampled));
        pass(&mut g, "copy_c", &[&c], &mut out);
        assert_eq!(names(&mut g), ["make_a", "make_b", "make_c", "copy_c"]);

        let mut g = Graph::new();
        branches(&mut g);
        assert_eq!(names(&mut g).len(), 4, "a graph without outputs runs whole");
    }

    /// One frame: a kept image computed from "a" by `compute` when its key is
    /// new, read by `show` when `needed`. Returns the passes run and the keys kept.
    fn frame(kept: &Kept, key: u64, needed: bool) -> (Vec<String>, Kept) {
        let mut g = Graph::with_kept(kept.clone());
        let desc = ImageDesc::new(8, 8, F);
        let (mut lut, compute) =
            g.import_kept_image("lut", described(), Access::ComputeSampled, key);
        if compute {
            pass(&mut g, "compute_lut", &[], &mut lut);
        }
        let mut shown = g.create_image("shown", desc);
        let mut other = g.create_image("other", desc);
        pass(&mut g, "show", &[&lut], &mut shown);
        pass(&mut g, "other", &[], &mut other);
        g.output(if needed { &shown } else { &other });
        let plan = g.compile(&mut PoolState::default()).unwrap();
        (plan.passes.into_iter().map(|p| p.name).collect(), plan.kept)
    }

    #[test]
    fn a_kept_resource_is_computed_once_reused_and_recomputed_when_its_key_changes() {
        // Not needed: not computed, and still to compute.
        let (run, kept) = frame(&Kept::default(), 1, false);
        assert_eq!(run, ["other"]);
        assert_eq!(kept, Kept::default());
        let (run, kept) = frame(&kept, 1, true);
        assert_eq!(run, ["compute_lut", "show"]);
        let (run, kept) = frame(&kept, 1, true);
        assert_eq!(run, ["show"], "reused");
        let (run, kept) = frame(&kept, 1, false);
        assert_eq!(run, ["other"]);
        assert!(kept.holds("lut", 1), "kept while unused");
        let (run, kept) = frame(&kept, 2, true);
        assert_eq!(run, ["compute_lut", "show"], "new inputs, computed again");
        assert!(kept.holds("lut", 2) && !kept.holds("lut", 1));
        // A key that changes while unneeded: stale, computed when next needed.
        let (_, kept) = frame(&kept, 3, false);
        assert!(!kept.holds("lut", 2) && !kept.holds("lut", 3));
        assert_eq!(frame(&kept, 3, true).0, ["compute_lut", "show"]);
    }

    #[test]
    fn a_kept_resource_read_before_it_is_computed_is_an_error() {
        let mut g = Graph::new();
        let (lut, compute) = g.import_kept_image("lut", described(), Access::ComputeSampled, 1);
        assert!(compute);
        let mut shown = g.create_image("shown", ImageDesc::new(8, 8, F));
        pass(&mut g, "show", &[&lut], &mut shown);
        g.output(&shown);
        let e = g
            .compile(&mut PoolState::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("reads \"lut\" before any pass writes it"), "{e}");
    }

    #[test]
    fn aliases_and_names_find_images() {
        let mut g = Graph::new();
        let (c, _) = branches(&mut g);
        g.alias("level3", &c);
        assert_eq!(g.find_image("level3").unwrap().desc, c.desc);
        assert!(g.find_image("c").is_some() && g.find_image("e").is_none());
        assert_eq!(g.image_names(), ["a", "b", "c", "d", "level3"]);
    }
}
