//! Post-processing after shading (the paper's §IV; docs/design/post.md): metering,
//! glow, exposure and tone mapping, and the debug views drawn for it.

pub mod debug;
pub mod glow;
pub mod meter;
pub mod tonemap;

use crate::scene::file::{Gamma, Render, ToneCurve};

/// The tag of the post-processing passes (meter, glow, tone map).
pub const TAG: &str = "post";

/// How a view's image becomes display values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// Radiance: glow, the exposure (given or metered), the scene's tone curve
    /// and transfer function.
    Exposed,
    /// A fraction in [0, 1] (occlusion, albedo): exposure 0, no curve, the
    /// scene's transfer function.
    Fraction,
    /// Data (depth, normals, region colours): the values as they are.
    Data,
}

/// Where the exposure comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// `render.exposure`, EV.
    Given(f32),
    /// The frame's own log-average luminance (post::meter).
    Metered,
}

/// How exposed radiance becomes display values: the tone-map pass's settings
/// and those of its CPU twin ([`tonemap::encode8`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Display {
    pub curve: ToneCurve,
    pub gamma: Gamma,
    /// Display colour (linear, before `gamma`) added where the image's alpha
    /// (the mesh's coverage) is below 1.
    pub background: [f32; 3],
}

impl Display {
    /// Values shown as they are: no curve, no transfer function (normals,
    /// depth, region ids).
    pub fn data(background: [f32; 3]) -> Display {
        Display {
            curve: ToneCurve::Linear,
            gamma: Gamma::Power(1.0),
            background,
        }
    }
}

/// The post-processing settings of a render, resolved once from `[render]`;
/// plain values, so a viewer can change them between frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PostSettings {
    /// Glow intensity; `None`: off.
    pub glow: Option<f32>,
    pub exposure: Exposure,
    pub display: Display,
    /// `render.skybox`: the environment drawn behind the head.
    pub skybox: bool,
}

impl PostSettings {
    /// `render` without what post-processing reads (those keys at their
    /// defaults): what a change of post settings leaves alone. The keys
    /// [`PostSettings::resolve`] reads are cleared here, and nowhere else.
    pub fn clear(render: &Render) -> Render {
        let d = Render::default();
        Render {
            exposure: d.exposure,
            gamma: d.gamma,
            tone_curve: d.tone_curve,
            skybox: d.skybox,
            background: d.background,
            glow: d.glow,
            glow_intensity: d.glow_intensity,
            ..render.clone()
        }
    }

    pub fn resolve(render: &Render) -> PostSettings {
        PostSettings {
            skybox: render.skybox,
            glow: render.glow.then_some(render.glow_intensity),
            exposure: render.exposure.map_or(Exposure::Metered, Exposure::Given),
            display: Display {
                curve: render.tone_curve,
                gamma: render.gamma,
                // The skybox leaves alpha at 0 too: the background is for
                // images without one.
                background: if render.skybox {
                    [0.0; 3]
                } else {
                    render.background
                },
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::IrradianceShading;

    #[test]
    fn clear_takes_out_exactly_what_resolve_reads() {
        // Every key off its default (no `..`: a new key must be placed here).
        let r = Render {
            width: 7,
            height: 9,
            irradiance_resolution: 512,
            shadow_resolution: 256,
            shadow_focus: false,
            irradiance_shading: IrradianceShading::Compute,
            exposure: Some(1.5),
            gamma: Gamma::Power(1.8),
            tone_curve: ToneCurve::Aces,
            skybox: false,
            background: [0.2, 0.3, 0.4],
            glow: true,
            glow_intensity: 2.0,
        };
        let d = Render::default();
        assert_ne!(PostSettings::resolve(&r), PostSettings::resolve(&d));
        let cleared = PostSettings::clear(&r);
        assert_eq!(PostSettings::resolve(&cleared), PostSettings::resolve(&d));
        // What it keeps: the rest, as it was.
        assert_eq!(
            (cleared.width, cleared.height),
            (r.width, r.height),
            "the size is not post-processing"
        );
        assert_eq!(
            (cleared.irradiance_resolution, cleared.shadow_resolution),
            (r.irradiance_resolution, r.shadow_resolution)
        );
        assert_eq!(cleared.shadow_focus, r.shadow_focus);
        assert_eq!(cleared.irradiance_shading, r.irradiance_shading);
        assert_ne!(
            (d.width, d.irradiance_resolution, d.shadow_resolution),
            (r.width, r.irradiance_resolution, r.shadow_resolution)
        );
    }
}
