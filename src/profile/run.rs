//! What `--report FILE.json` writes: what was run, where, and what it cost.

use super::stats::Stats;
use super::{FrameReport, PassTime};
use crate::gpu::DeviceInfo;
use serde::{Deserialize, Serialize};

/// The dermis version the report was made by.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// `git rev-parse --short HEAD` at build time (build.rs), or "unknown".
pub const GIT_COMMIT: &str = env!("DERMIS_GIT_COMMIT");

/// What was rendered, as the caller resolved it: enough to run it again.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RunSetup {
    /// The scene file, or "default".
    pub scene: String,
    /// The glTF mesh, or "builtin".
    pub mesh: String,
    /// The environment source as given (`sky…`, `uniform:…`, a file).
    pub environment: String,
    pub environment_rotation_deg: f32,
    /// Side of the UV-space irradiance texture.
    pub irradiance_resolution: u32,
    /// Blur kernel: `deon7` or `accurate`.
    pub kernel: String,
    /// Resolutions of the diffusion chain: `full` or `adaptive`.
    pub chain: String,
    /// `final` or the intermediate written.
    pub view: String,
    /// Screen size rendered at (the output size is the report's width × height).
    pub render_width: u32,
    pub render_height: u32,
    /// Occlusion method: `raster`, `raytrace` or `off`.
    pub occlusion: String,
    pub shadow_resolution: u32,
    /// The scene's explicit lights.
    pub lights: usize,
    /// `environment.lights`: `auto` or a count.
    pub environment_lights: String,
    /// Bright sources taken out of the environment as lights.
    pub extracted_lights: usize,
    /// The exposure used, EV (post::meter when metered).
    pub exposure_ev: f32,
    /// Whether it was metered from the frame (else given, or 0 for a view of
    /// fractions or data).
    pub exposure_metered: bool,
    /// `linear`, `aces` or `neutral`.
    pub tone_curve: String,
    /// Glow intensity; 0: off.
    pub glow_intensity: f32,
    /// Scale on the profile's variances.
    pub blur_width: f32,
    /// Share of the blurred irradiance in the diffuse term.
    pub blur_amount: f32,
    /// The test texture replaced the albedo.
    pub test_texture: bool,
}

/// Device memory at the end of the run.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct MemoryUse {
    /// Pooled transient images of the render graph.
    pub transient_pool_bytes: u64,
    /// gpu-allocator: bytes of live allocations (the pool included).
    pub allocated_bytes: u64,
    /// gpu-allocator: bytes of device memory blocks it holds.
    pub reserved_bytes: u64,
}

/// The pass whose cost per texel every other pass is compared with (render's
/// `--ruler`: a plain RGBA16F copy at the irradiance resolution).
pub const RULER_COPY: &str = "ruler_copy";

/// One pass (or the frame span) over the measured frames.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct PassStats {
    pub name: String,
    /// Measured frames that timed it.
    pub frames: usize,
    /// `None` when no frame timed it.
    #[serde(flatten)]
    pub time: Option<Stats>,
    /// Texels (invocations, or render-area pixels) the pass computes.
    pub texels: Option<u64>,
    /// Nominal traffic: each graph image and buffer it uses once at full size.
    pub bytes: Option<u64>,
    /// Median time per texel.
    pub ns_per_texel: Option<f64>,
    /// Nominal traffic over the median time (bytes per ns = GB/s).
    pub gb_per_s: Option<f64>,
    /// ns/texel as a multiple of the copy ruler's in the same run.
    pub x_ruler: Option<f64>,
    /// The measured frames' times in frame order, `None` where a frame did not
    /// time it (`dermis compare` resamples these).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples_ns: Vec<Option<f64>>,
}

impl PassStats {
    fn of(name: &str, values: Vec<Option<f64>>) -> Self {
        let finite: Vec<f64> = values.iter().flatten().copied().collect();
        Self {
            name: name.into(),
            frames: finite.iter().filter(|v| v.is_finite()).count(),
            time: Stats::of(&finite),
            samples_ns: values,
            ..Default::default()
        }
    }

    /// Fills the per-texel figures from the pass's work and median.
    fn with_work(mut self, texels: Option<u64>, bytes: Option<u64>) -> Self {
        let median = self.time.map(|t| t.median_ns).filter(|&t| t > 0.0);
        self.texels = texels;
        self.bytes = bytes;
        self.ns_per_texel = median
            .zip(texels.filter(|&t| t > 0))
            .map(|(t, n)| t / n as f64);
        self.gb_per_s = median
            .zip(bytes.filter(|&b| b > 0))
            .map(|(t, b)| b as f64 / t);
        self
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    pub dermis_version: String,
    pub git_commit: String,
    pub setup: RunSetup,
    pub device: String,
    pub device_type: String,
    pub driver: String,
    pub api_version: String,
    /// `LP_NUM_THREADS` (lavapipe's rasterizer thread count), when set.
    pub lp_num_threads: Option<String>,
    /// What measured the passes: "gpu-timestamp" or "host-fence".
    pub clock: String,
    /// Output image size.
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub warmup_frames: usize,
    /// Same as `memory.transient_pool_bytes` (kept for older readers).
    pub transient_bytes: u64,
    pub memory: MemoryUse,
    /// Per pass over the measured (post-warm-up) frames, in first-seen order.
    pub passes: Vec<PassStats>,
    /// The frame's GPU span over the measured frames.
    pub frame_span: PassStats,
    /// Per-pass medians over the measured frames.
    pub median: Option<FrameReport>,
    /// Passes only the warm-up frame ran: what a render computes once and keeps
    /// (SH projection, prefiltered environment, stretch maps, shadows).
    pub warmup_only: Vec<PassTime>,
    pub per_frame: Vec<FrameReport>,
}

impl RunReport {
    /// With more than one frame the first is warm-up, outside the statistics.
    pub fn new(
        device: &DeviceInfo,
        setup: RunSetup,
        width: u32,
        height: u32,
        per_frame: Vec<FrameReport>,
        memory: MemoryUse,
    ) -> Self {
        let warmup = usize::from(per_frame.len() > 1);
        let measured = &per_frame[warmup.min(per_frame.len())..];
        let mut names: Vec<&str> = Vec::new();
        for p in measured.iter().flat_map(|f| &f.passes) {
            if !names.contains(&p.name.as_str()) {
                names.push(&p.name);
            }
        }
        let mut passes: Vec<PassStats> = names
            .iter()
            .map(|n| {
                let v = measured.iter().map(|f| f.pass_ns(n)).collect();
                let work = measured.iter().rev().find_map(|f| f.pass(n));
                PassStats::of(n, v)
                    .with_work(work.and_then(|p| p.texels), work.and_then(|p| p.bytes))
            })
            .collect();
        let ruler = passes
            .iter()
            .find(|p| p.name == RULER_COPY)
            .and_then(|p| p.ns_per_texel);
        for p in &mut passes {
            p.x_ruler = p.ns_per_texel.zip(ruler).map(|(a, r)| a / r);
        }
        let spans = measured.iter().map(|f| f.gpu_frame_ns).collect();
        let warmup_only = per_frame[..warmup]
            .iter()
            .flat_map(|f| &f.passes)
            .filter(|p| !names.contains(&p.name.as_str()))
            .cloned()
            .collect();
        Self {
            dermis_version: VERSION.into(),
            git_commit: GIT_COMMIT.into(),
            setup,
            device: device.name.clone(),
            device_type: device.device_type.clone(),
            driver: format!("{} {}", device.driver_name, device.driver_info),
            api_version: device.api_version.clone(),
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
            clock: per_frame
                .first()
                .map_or_else(|| "none".into(), |f| f.clock.clone()),
            width,
            height,
            frames: per_frame.len(),
            warmup_frames: warmup,
            transient_bytes: memory.transient_pool_bytes,
            memory,
            passes,
            frame_span: PassStats::of("frame (GPU span)", spans),
            median: FrameReport::median(measured),
            warmup_only,
            per_frame,
        }
    }

    /// Three lines: the device, the setup and the post-processing.
    pub fn header(&self) -> String {
        let s = &self.setup;
        format!(
            "{} ({}), API {}, LP_NUM_THREADS={}, dermis {} ({})\n\
             {} {}x{} (render {}x{}), irradiance {}², kernel {}, chain {}, occlusion {}, \
             mesh {}, env {} @ {}° ({} light(s) extracted, lights = {}), {} frame(s), {} warm-up\n\
             exposure {:+.2} EV ({}), tone curve {}, glow {}, blur width {}, blur amount {}{}\n",
            self.device,
            self.driver.trim(),
            self.api_version,
            self.lp_num_threads.as_deref().unwrap_or("unset"),
            self.dermis_version,
            self.git_commit,
            s.view,
            self.width,
            self.height,
            s.render_width,
            s.render_height,
            s.irradiance_resolution,
            s.kernel,
            s.chain,
            s.occlusion,
            s.mesh,
            s.environment,
            s.environment_rotation_deg,
            s.extracted_lights,
            s.environment_lights,
            self.frames,
            self.warmup_frames,
            s.exposure_ev,
            if s.exposure_metered {
                "metered"
            } else {
                "given"
            },
            s.tone_curve,
            if s.glow_intensity > 0.0 {
                s.glow_intensity.to_string()
            } else {
                "off".into()
            },
            s.blur_width,
            s.blur_amount,
            if s.test_texture { ", test texture" } else { "" },
        )
    }

    /// Per pass: median, min, max, p90 over the measured frames, and their count;
    /// texels, ns per texel, GB/s of nominal traffic and × the copy ruler.
    pub fn table(&self) -> String {
        let ms = |ns: Option<f64>| ns.map_or("n/a".to_string(), |v| format!("{:.3}", v / 1e6));
        let row = |name: &str, frames: usize, t: Option<Stats>| {
            format!(
                "{:<24} {:>10} {:>10} {:>10} {:>10} {:>6}",
                name,
                ms(t.map(|t| t.median_ns)),
                ms(t.map(|t| t.min_ns)),
                ms(t.map(|t| t.max_ns)),
                ms(t.map(|t| t.p90_ns)),
                frames
            )
        };
        let opt =
            |v: Option<f64>, digits: usize| v.map_or(String::new(), |v| format!("{v:.digits$}"));
        let mut s =
            format!(
            "{:<24} {:>10} {:>10} {:>10} {:>10} {:>6} {:>10} {:>9} {:>7} {:>7}   (ms; clock: {})\n",
            "pass", "median", "min", "max", "p90", "frames", "texels", "ns/texel", "GB/s", "×ruler",
            self.clock
        );
        for p in &self.passes {
            s += &format!(
                "{} {:>10} {:>9} {:>7} {:>7}\n",
                row(&p.name, p.frames, p.time),
                p.texels.map_or(String::new(), |t| t.to_string()),
                opt(p.ns_per_texel, 2),
                opt(p.gb_per_s, 2),
                opt(p.x_ruler, 2),
            );
        }
        let sum: f64 = self
            .passes
            .iter()
            .filter_map(|p| p.time.map(|t| t.median_ns))
            .sum();
        s += &format!("{:<24} {:>10}\n", "sum of pass medians", ms(Some(sum)));
        s += &row(
            &self.frame_span.name,
            self.frame_span.frames,
            self.frame_span.time,
        );
        s.push('\n');
        let measured = &self.per_frame[self.warmup_frames.min(self.per_frame.len())..];
        for (name, v) in [
            (
                "CPU record",
                measured.iter().map(|f| f.cpu_record_ns).collect::<Vec<_>>(),
            ),
            (
                "CPU submit",
                measured.iter().map(|f| f.cpu_submit_ns).collect(),
            ),
        ] {
            s += &row(name, v.len(), Stats::of(&v));
            s.push('\n');
        }
        if !self.warmup_only.is_empty() {
            let once: Vec<String> = self
                .warmup_only
                .iter()
                .map(|p| format!("{} {}", p.name, ms(p.gpu_ns)))
                .collect();
            s += &format!(
                "once per render (warm-up frame only, ms): {}\n",
                once.join(", ")
            );
        }
        let dropped: u32 = measured.iter().map(|f| f.dropped_deltas).sum();
        if dropped > 0 {
            s += &format!("({dropped} non-positive timestamp deltas dropped)\n");
        }
        let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
        s += &format!(
            "memory: transient pool {:.1} MiB, allocated {:.1} MiB, reserved {:.1} MiB\n",
            mib(self.memory.transient_pool_bytes),
            mib(self.memory.allocated_bytes),
            mib(self.memory.reserved_bytes)
        );
        s
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Frames of passes "a" (at 10 ns, lasting `a`) and "b" (right after),
    /// on the host-fence clock, 1000 ns apart.
    pub fn frames(a: &[f64]) -> Vec<FrameReport> {
        a.iter()
            .enumerate()
            .map(|(i, &a)| FrameReport {
                frame: i as u64,
                start_ns: Some(1000.0 * i as f64),
                passes: vec![
                    PassTime {
                        name: "a".into(),
                        gpu_ns: Some(a),
                        start_ns: Some(10.0),
                        ..Default::default()
                    },
                    PassTime {
                        name: "b".into(),
                        gpu_ns: Some(5.0),
                        start_ns: Some(10.0 + a),
                        ..Default::default()
                    },
                ],
                gpu_frame_ns: Some(a + 20.0),
                cpu_record_ns: 1.0,
                clock: "host-fence".into(),
                ..Default::default()
            })
            .collect()
    }

    pub fn device() -> DeviceInfo {
        DeviceInfo {
            name: "test device, 2 cores".into(),
            device_type: "CPU".into(),
            driver_name: "drv".into(),
            driver_info: "1.0".into(),
            api_version: "1.3.0".into(),
            vendor_id: 0,
            device_id: 0,
            timestamps: true,
            timestamp_period_ns: 1.0,
            timestamp_valid_bits: 64,
            max_image_dimension_2d: 8192,
            memory_heaps: Vec::new(),
            validation: false,
        }
    }

    pub fn setup() -> RunSetup {
        RunSetup {
            scene: "default".into(),
            mesh: "builtin".into(),
            environment: "sky".into(),
            irradiance_resolution: 256,
            kernel: "deon7".into(),
            chain: "full".into(),
            view: "final".into(),
            occlusion: "raytrace".into(),
            ..Default::default()
        }
    }

    pub fn report(a: &[f64]) -> RunReport {
        RunReport::new(&device(), setup(), 64, 48, frames(a), MemoryUse::default())
    }

    #[test]
    fn per_texel_figures_follow_from_work_and_median() {
        let mut s =
            PassStats::of("p", vec![Some(2000.0), Some(4000.0), Some(3000.0)]).with_work(Some(1000), Some(6000));
        assert_eq!(s.ns_per_texel, Some(3.0));
        assert_eq!(s.gb_per_s, Some(2.0));
        s = s.with_work(None, Some(0));
        assert_eq!((s.ns_per_texel, s.gb_per_s), (None, None));
        // No time: no figures, never NaN.
        let s = PassStats::of("q", vec![]).with_work(Some(10), Some(10));
        assert_eq!((s.ns_per_texel, s.gb_per_s), (None, None));
    }

    #[test]
    fn statistics_leave_the_warm_up_out() {
        // Warm-up 1000, then 40 10 30 20 50: median 30, p90 rank ⌈4.5⌉ = 5 → 50.
        let r = report(&[1000.0, 40.0, 10.0, 30.0, 20.0, 50.0]);
        assert_eq!((r.frames, r.warmup_frames), (6, 1));
        let a = &r.passes[0];
        assert_eq!((a.name.as_str(), a.frames), ("a", 5));
        let t = a.time.unwrap();
        assert_eq!(
            [t.median_ns, t.min_ns, t.max_ns, t.p90_ns],
            [30.0, 10.0, 50.0, 50.0]
        );
        assert_eq!(r.frame_span.time.unwrap().median_ns, 50.0);
        assert_eq!(r.median.as_ref().unwrap().pass_ns("a"), Some(30.0));
        assert_eq!(r.clock, "host-fence");
        let table = r.table();
        assert!(
            table.contains("p90") && table.contains("frame (GPU span)"),
            "{table}"
        );
        assert!(r.warmup_only.is_empty() && !table.contains("once per render"));
    }

    #[test]
    fn passes_only_the_warm_up_ran_are_listed_apart() {
        let mut f = frames(&[1000.0, 40.0, 10.0]);
        f[0].passes.push(PassTime {
            name: "shadow maps".into(),
            gpu_ns: Some(2.5e6),
            ..Default::default()
        });
        let r = RunReport::new(&device(), setup(), 64, 48, f, MemoryUse::default());
        assert_eq!(r.passes.len(), 2);
        assert_eq!(r.warmup_only.len(), 1);
        let table = r.table();
        assert!(
            table.contains("once per render (warm-up frame only, ms): shadow maps 2.500"),
            "{table}"
        );
    }

    #[test]
    fn json_holds_the_setup_and_flat_statistics() {
        let v = serde_json::to_value(report(&[7.0, 3.0, 5.0])).unwrap();
        assert_eq!(v["setup"]["irradiance_resolution"], 256);
        assert_eq!(v["setup"]["kernel"], "deon7");
        assert_eq!(v["dermis_version"], VERSION);
        assert!(v["git_commit"].as_str().is_some_and(|c| !c.is_empty()));
        assert_eq!(v["passes"][0]["frames"], 2);
        assert_eq!(v["passes"][0]["median_ns"], 4.0);
        assert_eq!(v["passes"][1]["p90_ns"], 5.0);
        assert_eq!(v["per_frame"][1]["passes"][1]["start_ns"], 13.0);
    }

    #[test]
    fn a_pass_no_frame_timed_has_a_count_of_zero() {
        let mut f = frames(&[1.0]);
        f[0].passes[0].gpu_ns = None;
        let r = RunReport::new(&device(), setup(), 1, 1, f, MemoryUse::default());
        let v = serde_json::to_value(&r.passes[0]).unwrap();
        assert_eq!(v["frames"], 0);
        assert!(v.get("median_ns").is_none(), "{v}");
    }
}
