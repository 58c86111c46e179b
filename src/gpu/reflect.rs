//! What a pipeline's layout is, read from its SPIR-V (rspirv-reflect, as kajiya
//! does): the descriptor type of every binding of set 0, the push-constant size and
//! a compute shader's workgroup size. The GLSL is the one place a layout is written.

use super::shaders;
use crate::error::{Error, Result};
use ash::vk;

/// The reflected interface of one or more shader stages.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ShaderLayout {
    /// Descriptor type of bindings 0, 1, … of set 0 (`None`: a gap, unused).
    pub bindings: Vec<Option<vk::DescriptorType>>,
    pub push_constant_bytes: u32,
    /// `local_size_{x,y,z}` of a compute shader; [1, 1, 1] otherwise.
    pub local_size: [u32; 3],
}

impl ShaderLayout {
    /// Reflects an embedded shader by file name, e.g. `"blur.comp"`.
    pub fn of(name: &str) -> Result<Self> {
        let words = shaders::spirv(name)?;
        let bad = |what: String| Error::Graph(format!("reflecting {name}: {what}"));
        let r = rspirv_reflect::Reflection::new_from_spirv(bytemuck::cast_slice(words))
            .map_err(|e| bad(format!("{e:?}")))?;
        let sets = r.get_descriptor_sets().map_err(|e| bad(format!("{e:?}")))?;
        if let Some(set) = sets.keys().find(|&&s| s != 0) {
            return Err(bad(format!("descriptor set {set}: only set 0 is pushed")));
        }
        let mut layout = ShaderLayout {
            local_size: r
                .get_compute_group_size()
                .map_or([1, 1, 1], |(x, y, z)| [x, y, z]),
            push_constant_bytes: r
                .get_push_constant_range()
                .map_err(|e| bad(format!("{e:?}")))?
                .map_or(0, |p| p.offset + p.size),
            bindings: Vec::new(),
        };
        for (&binding, info) in sets.get(&0).into_iter().flatten() {
            if !matches!(info.binding_count, rspirv_reflect::BindingCount::One) {
                return Err(bad(format!("binding {binding} is an array")));
            }
            layout.set(binding, vk::DescriptorType::from_raw(info.ty.0 as i32))?;
        }
        Ok(layout)
    }

    fn set(&mut self, binding: u32, ty: vk::DescriptorType) -> Result<()> {
        let i = binding as usize;
        if self.bindings.len() <= i {
            self.bindings.resize(i + 1, None);
        }
        match self.bindings[i] {
            Some(t) if t != ty => Err(Error::Graph(format!(
                "binding {binding} is {t:?} in one stage and {ty:?} in another"
            ))),
            _ => {
                self.bindings[i] = Some(ty);
                Ok(())
            }
        }
    }

    /// The union of two stages' interfaces (vertex + fragment).
    pub fn merge(mut self, other: &ShaderLayout) -> Result<Self> {
        for (i, ty) in other.bindings.iter().enumerate() {
            if let Some(ty) = ty {
                self.set(i as u32, *ty)?;
            }
        }
        self.push_constant_bytes = self.push_constant_bytes.max(other.push_constant_bytes);
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_layout_is_read_from_its_spirv() {
        // shaders-glsl/blur.comp: source and stretch samplers, an rgba16f storage
        // image, the taps' uniform block.
        let l = ShaderLayout::of("blur.comp").unwrap();
        use vk::DescriptorType as D;
        assert_eq!(
            l.bindings,
            [
                D::COMBINED_IMAGE_SAMPLER,
                D::COMBINED_IMAGE_SAMPLER,
                D::STORAGE_IMAGE,
                D::UNIFORM_BUFFER
            ]
            .map(Some)
        );
        assert_eq!(l.push_constant_bytes, 12);
        assert_eq!(l.local_size, [8, 8, 1]);
    }

    #[test]
    fn vertex_and_fragment_stages_merge() {
        // mesh_lit.vert reads the transfer (binding 4) that skin.frag only declares in
        // a comment; the union has it.
        let v = ShaderLayout::of("mesh_lit.vert").unwrap();
        let f = ShaderLayout::of("skin.frag").unwrap();
        let m = v.merge(&f).unwrap();
        assert_eq!(m.bindings[4], Some(vk::DescriptorType::STORAGE_BUFFER));
        assert_eq!(m.bindings[6], None, "{m:?}");
        // skin.vert reads it too, and the RGB transfer (binding 6) that neither
        // of the others does: its union with skin.frag, the skin pass's
        // layout, has every binding.
        let s = ShaderLayout::of("skin.vert").unwrap().merge(&f).unwrap();
        assert_eq!(s.bindings[4], Some(vk::DescriptorType::STORAGE_BUFFER));
        assert_eq!(s.bindings[6], Some(vk::DescriptorType::STORAGE_BUFFER));
        assert!(s.bindings.iter().all(Option::is_some), "{s:?}");
        assert!(ShaderLayout::of("no such shader").is_err());
    }
}
