//! What `--report FILE.json` writes: what was run, where, and what it cost.

use super::bound::{bound_by, BoundBy, PassFigures, DRAW_TAG, WORK_SKIPPED_TAG};
use super::fingerprint::{run_id, timestamp, Fingerprint};
use super::stats::Stats;
use super::{FrameTiming, PassCounters, PassTime};
use crate::gpu::DeviceInfo;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The dermis version the report was made by.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// `git rev-parse --short HEAD` at build time (build.rs), or "unknown".
pub const GIT_COMMIT: &str = env!("DERMIS_GIT_COMMIT");
/// Whether the built sources differed from that commit (build.rs).
pub const GIT_DIRTY: bool = matches!(env!("DERMIS_GIT_DIRTY").as_bytes(), b"true");

/// The version of the report's JSON layout (`docs/report.schema.json`): 2 added
/// the fingerprint, runs, samples, mean and standard deviation.
pub const SCHEMA_VERSION: u32 = 2;

/// The camera as rendered, in millimetres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct CameraSetup {
    pub position_mm: [f32; 3],
    pub target_mm: [f32; 3],
    pub up: [f32; 3],
    pub fov_y_deg: f32,
    pub near_mm: f32,
    pub far_mm: f32,
}

/// What was rendered, as the caller resolved it: enough to run it again.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(default)]
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
    /// A second shadow map per shadowed light, fitted to what the camera sees
    /// (`render.shadow_focus`; false in reports written before it existed).
    pub shadow_focus: bool,
    /// How the irradiance pass reached the texels (`render.irradiance_shading`
    /// as run): `compute`, or absent for `raster` (as in reports written
    /// before the compute pass existed).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub irradiance_shading: String,
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
    /// Scale on the light transmitted through thin skin (`skin.transmission`;
    /// 0: off, and in reports written before the term existed).
    pub transmission: f32,
    /// The test texture replaced the albedo.
    pub test_texture: bool,
    /// Output transfer: `srgb` or a power (`2.2`).
    pub gamma: String,
    /// The environment drawn behind the head.
    pub skybox: bool,
    /// Linear display colour where nothing covers (skybox off).
    pub background: [f32; 3],
    /// The maps' UV origin: `top-left` or `bottom-left`.
    pub uv_origin: String,
    /// Millimetres per mesh unit (`None`: the mesh's own, or the built-in head's).
    pub mm_per_unit: Option<f32>,
    pub camera: CameraSetup,
}

/// Device memory at the end of the run.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, JsonSchema)]
pub struct MemoryUse {
    /// Pooled transient images of the render graph.
    pub transient_pool_bytes: u64,
    /// gpu-allocator: bytes of live allocations (the pool included).
    pub allocated_bytes: u64,
    /// gpu-allocator: bytes of device memory blocks it holds.
    pub reserved_bytes: u64,
}

/// How long the driver took to create one of the render's pipelines
/// (pipeline creation feedback).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct PipelineTime {
    /// Its shaders (`vertex+fragment` for graphics pipelines).
    pub name: String,
    pub creation_ns: f64,
}

/// The pass whose cost per texel every other pass is compared with (render's
/// `--ruler`: a plain RGBA16F copy at the irradiance resolution).
pub const RULER_COPY: &str = "ruler_copy";
/// The read ruler's pass name (render::ruler).
pub const RULER_READ: &str = "ruler_read";
/// The empty ruler's pass name: one invocation, the cost of a pass itself.
pub const RULER_EMPTY: &str = "ruler_empty";

/// Whether a pass is a ruler: by name, so that reports written before passes
/// carried tags are read the same way.
pub fn is_ruler(name: &str) -> bool {
    name == RULER_COPY || name == RULER_READ || name == RULER_EMPTY
}

/// One pass (or the frame span) over the measured frames.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
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
    /// Traffic it can touch: each image it uses capped at one texel per
    /// invocation (a screen pass sampling a 4096² level at its pixels touches
    /// those, not the level).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub touched_bytes: Option<u64>,
    /// Touched bytes per ns as a fraction of the copy ruler's in the same run:
    /// how close the pass comes to what a plain copy achieves (> 1: caches
    /// serve some of it, or it touches less than it declares).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub of_ruler_bandwidth: Option<f64>,
    /// Its median with its shader's work skipped (one read and the output
    /// kept) over its median, where `render --variants` ran that variant.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub work_skipped_share: Option<f64>,
    /// What bounds the pass (timing::bound), where the rulers ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound_by: Option<BoundBy>,
    /// What the pass belongs to (e.g. `diffusion`, `ruler`), as it declared.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tags: Vec<String>,
    /// Pipeline statistics (`render --counters`), each the median over the
    /// measured frames; absent when not counted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counters: Option<PassCounters>,
    /// Fragment invocations per pixel of the render area (covered share ×
    /// over-shading), from the counters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fragments_per_pixel: Option<f64>,
    /// Compute invocations per texel, from the counters (> 1: workgroups
    /// overhang the image).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub invocations_per_texel: Option<f64>,
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

    /// Fills the tags and per-texel figures from the pass's work and median.
    fn with_work(mut self, work: Option<&PassTime>) -> Self {
        let median = self.time.map(|t| t.median_ns).filter(|&t| t > 0.0);
        let (texels, bytes) = (work.and_then(|p| p.texels), work.and_then(|p| p.bytes));
        self.tags = work.map(|p| p.tags.clone()).unwrap_or_default();
        self.texels = texels;
        self.bytes = bytes;
        self.touched_bytes = work.and_then(|p| p.touched_bytes);
        self.ns_per_texel = median
            .zip(texels.filter(|&t| t > 0))
            .map(|(t, n)| t / n as f64);
        self.gb_per_s = median
            .zip(bytes.filter(|&b| b > 0))
            .map(|(t, b)| b as f64 / t);
        self
    }

    /// Fills the counters (their per-frame median) and what they say per texel.
    fn with_counters(mut self, counters: Option<PassCounters>) -> Self {
        self.counters = counters;
        self.fragments_per_pixel = counters.and_then(|c| c.fragments_per_pixel(self.texels));
        self.invocations_per_texel = counters.and_then(|c| c.invocations_per_texel(self.texels));
        self
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
pub struct RunReport {
    /// [`SCHEMA_VERSION`] of the writer.
    pub schema_version: u32,
    pub dermis_version: String,
    pub git_commit: String,
    /// The binary was built from sources that differ from `git_commit`.
    pub git_dirty: bool,
    /// Unique per run (fingerprint::run_id): keeps concatenated CSVs apart.
    pub run_id: String,
    /// When the report was made, RFC 3339 UTC.
    pub timestamp: String,
    /// The process's arguments, the program first.
    pub command_line: Vec<String>,
    pub setup: RunSetup,
    /// Device, driver, CPU, threads, clock, validation.
    pub fingerprint: Fingerprint,
    /// Output image size.
    pub width: u32,
    pub height: u32,
    /// Independent repetitions (`--runs`), each with its own pipelines and warm-up.
    pub runs: usize,
    /// Frames of all runs, warm-up included.
    pub frames: usize,
    /// Warm-up frames at the start of each run, outside the statistics.
    pub warmup_frames: usize,
    /// The pre-roll after each run's first frame: frames rendered for this
    /// long and not reported (render::RenderOptions::warmup_ms); 0 in reports
    /// written before it existed.
    #[serde(default)]
    pub preroll_ms: u64,
    /// Same as `memory.transient_pool_bytes` (kept for older readers).
    pub transient_bytes: u64,
    pub memory: MemoryUse,
    /// Per pass over the measured (post-warm-up) frames of every run, in
    /// first-seen order.
    pub passes: Vec<PassStats>,
    /// The frame's GPU span over the measured frames.
    pub frame_span: PassStats,
    /// Per-pass medians over the measured frames.
    pub median: Option<FrameTiming>,
    /// Passes only warm-up frames ran: what a render computes once and keeps
    /// (SH projection, prefiltered environment, stretch maps, shadows), from the
    /// first run.
    pub warmup_only: Vec<PassTime>,
    pub per_frame: Vec<FrameTiming>,
    /// With validation on: the validation layer's messages (warnings and errors)
    /// up to the report, which make the run fail (exit status 4); absent with
    /// validation off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_messages: Option<u32>,
    /// The last run's cached pipelines, once per render: how long the driver
    /// took to create each (creation feedback), slowest first.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pipelines: Vec<PipelineTime>,
}

impl RunReport {
    /// `per_frame` holds every run's frames in order (`FrameTiming::run`); the
    /// first `warmup` frames of each run are warm-up, outside the statistics.
    pub fn new(
        device: &DeviceInfo,
        setup: RunSetup,
        (width, height): (u32, u32),
        mut per_frame: Vec<FrameTiming>,
        warmup: usize,
        memory: MemoryUse,
    ) -> Self {
        let mut seen = 0;
        for i in 0..per_frame.len() {
            seen = if i > 0 && per_frame[i].run == per_frame[i - 1].run {
                seen + 1
            } else {
                0
            };
            per_frame[i].warmup = seen < warmup;
        }
        let measured: Vec<&FrameTiming> = per_frame.iter().filter(|f| !f.warmup).collect();
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
                let counted: Vec<PassCounters> = measured
                    .iter()
                    .filter_map(|f| f.pass(n)?.counters)
                    .collect();
                PassStats::of(n, v)
                    .with_work(work)
                    .with_counters(PassCounters::median(&counted))
            })
            .collect();
        let ruler = passes.iter().find(|p| p.name == RULER_COPY);
        // Touched bytes per ns.
        let touched = |p: &PassStats| {
            let (t, b) = (p.time?.median_ns, p.touched_bytes?);
            (t > 0.0).then(|| b as f64 / t)
        };
        let (ruler_ns, ruler_gb) = (ruler.and_then(|p| p.ns_per_texel), ruler.and_then(touched));
        for p in &mut passes {
            p.x_ruler = p.ns_per_texel.zip(ruler_ns).map(|(a, r)| a / r);
            p.of_ruler_bandwidth = touched(p).zip(ruler_gb).map(|(a, r)| a / r);
        }
        let spans = measured.iter().map(|f| f.gpu_frame_ns).collect();
        let first_run = per_frame.first().map_or(0, |f| f.run);
        let warmup_only = per_frame
            .iter()
            .filter(|f| f.warmup && f.run == first_run)
            .flat_map(|f| &f.passes)
            .filter(|p| !names.contains(&p.name.as_str()))
            .cloned()
            .collect();
        let measured_owned: Vec<FrameTiming> = measured.into_iter().cloned().collect();
        let mut fingerprint = Fingerprint::of(device);
        fingerprint.clock = per_frame
            .first()
            .map_or_else(|| "none".into(), |f| f.clock.clone());
        fingerprint.counters = per_frame
            .iter()
            .any(|f| f.passes.iter().any(|p| p.counters.is_some()));
        let mut runs: Vec<u32> = per_frame.iter().map(|f| f.run).collect();
        runs.dedup();
        let mut report = Self {
            schema_version: SCHEMA_VERSION,
            dermis_version: VERSION.into(),
            git_commit: GIT_COMMIT.into(),
            git_dirty: GIT_DIRTY,
            run_id: run_id(),
            timestamp: timestamp(),
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            setup,
            fingerprint,
            width,
            height,
            runs: runs.len().max(1),
            frames: per_frame.len(),
            warmup_frames: warmup,
            preroll_ms: 0,
            transient_bytes: memory.transient_pool_bytes,
            memory,
            passes,
            frame_span: PassStats::of("frame (GPU span)", spans),
            median: FrameTiming::median(&measured_owned),
            warmup_only,
            per_frame,
            validation_messages: device.validation.then(crate::gpu::validation_messages),
            pipelines: Vec::new(),
        };
        report.judge(&[]);
        report
    }

    /// Each pass's verdict (timing::bound), `draws` naming the passes that draw.
    fn judge(&mut self, draws: &[String]) {
        let empty_ns = self
            .passes
            .iter()
            .find(|p| p.name == RULER_EMPTY)
            .and_then(|p| p.time)
            .map(|t| t.median_ns);
        for p in &mut self.passes {
            p.bound_by = p.time.and_then(|t| {
                bound_by(&PassFigures {
                    median_ns: t.median_ns,
                    empty_ns,
                    of_ruler_bandwidth: p.of_ruler_bandwidth,
                    counters: p.counters,
                    work_skipped_share: p.work_skipped_share,
                    draw: draws.contains(&p.name),
                })
            });
        }
    }

    /// The work-skipped variant's figures from `skipped`, a run of the same
    /// frame whose pipelines skipped their shaders' work
    /// (gpu::Context::set_skip_work): each pass it tagged [`WORK_SKIPPED_TAG`]
    /// gets its median there over its median here, and the verdicts follow.
    pub fn with_work_skipped(mut self, skipped: &RunReport) -> Self {
        let tagged = |p: &&PassStats, tag: &str| p.tags.iter().any(|t| t == tag);
        let varied: Vec<&PassStats> = skipped
            .passes
            .iter()
            .filter(|p| tagged(p, WORK_SKIPPED_TAG))
            .collect();
        for p in &mut self.passes {
            let full = p.time.map(|t| t.median_ns).filter(|&t| t > 0.0);
            let kept = varied
                .iter()
                .find(|v| v.name == p.name)
                .and_then(|v| v.time);
            p.work_skipped_share = full.zip(kept).map(|(f, k)| k.median_ns / f);
        }
        let draws: Vec<String> = varied
            .iter()
            .filter(|p| tagged(p, DRAW_TAG))
            .map(|p| p.name.clone())
            .collect();
        self.judge(&draws);
        self
    }

    /// The measured frames, every run's warm-up left out.
    pub fn measured(&self) -> impl Iterator<Item = &FrameTiming> {
        self.per_frame.iter().filter(|f| !f.warmup)
    }

    /// Statistics that came from cold frames alone (one frame per run, no
    /// warm-up: lavapipe compiled every shader inside it): say so.
    pub fn cold_warning(&self) -> Option<String> {
        (self.warmup_frames == 0 && !self.per_frame.is_empty()).then(|| {
            "warning: no warm-up frame: the timings include shader compilation and first \
             use; render with --frames 2 or more (the first is warm-up)"
                .to_string()
        })
    }

    /// Three lines: the device, the setup and the post-processing.
    pub fn header(&self) -> String {
        let (s, f) = (&self.setup, &self.fingerprint);
        format!(
            "{} ({}), API {}, CPU {} × {}, LP_NUM_THREADS={}, validation {}, dermis {} ({}{})\n\
             {} {}x{} (render {}x{}), irradiance {}², kernel {}, chain {}, occlusion {}, \
             mesh {}, env {} @ {}° ({} light(s) extracted, lights = {}), {} run(s), \
             {} frame(s), {} warm-up per run{}\n\
             exposure {:+.2} EV ({}), tone curve {}, glow {}, blur width {}, blur amount {}{}\n",
            f.device,
            f.driver,
            f.api_version,
            f.cpu_model,
            f.cpu_cores,
            f.lp_num_threads.as_deref().unwrap_or("unset"),
            if f.validation { "on" } else { "off" },
            self.dermis_version,
            self.git_commit,
            if self.git_dirty { ", dirty" } else { "" },
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
            self.runs,
            self.frames,
            self.warmup_frames,
            match self.preroll_ms {
                0 => String::new(),
                ms => format!(" (a {ms} ms pre-roll after the first)"),
            },
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
    /// texels, ns per texel, GB/s of nominal traffic, × the copy ruler (time
    /// per texel) and the fraction of the copy's bandwidth (BW/r).
    pub fn table(&self) -> String {
        let ms = |ns: Option<f64>| ns.map_or("n/a".to_string(), |v| format!("{:.3}", v / 1e6));
        let row = |name: &str, frames: usize, t: Option<Stats>| {
            format!(
                "{:<24} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>6}",
                name,
                ms(t.map(|t| t.median_ns)),
                ms(t.map(|t| t.min_ns)),
                ms(t.map(|t| t.max_ns)),
                ms(t.map(|t| t.p90_ns)),
                ms(t.map(|t| t.mean_ns)),
                ms(t.map(|t| t.std_ns)),
                frames
            )
        };
        let opt =
            |v: Option<f64>, digits: usize| v.map_or(String::new(), |v| format!("{v:.digits$}"));
        let mut s =
            format!(
            "{:<24} {:>10} {:>10} {:>10} {:>10} {:>10} {:>9} {:>6} {:>10} {:>9} {:>7} {:>7} {:>6}   (ms; clock: {})\n",
            "pass", "median", "min", "max", "p90", "mean", "std", "frames", "texels", "ns/texel",
            "GB/s", "×ruler", "BW/r", self.fingerprint.clock
        );
        for p in &self.passes {
            s += &format!(
                "{} {:>10} {:>9} {:>7} {:>7} {:>6}\n",
                row(&p.name, p.frames, p.time),
                p.texels.map_or(String::new(), |t| t.to_string()),
                opt(p.ns_per_texel, 2),
                opt(p.gb_per_s, 2),
                opt(p.x_ruler, 2),
                opt(p.of_ruler_bandwidth, 2),
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
        let measured: Vec<&FrameTiming> = self.measured().collect();
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
        if !self.pipelines.is_empty() {
            let total: f64 = self.pipelines.iter().map(|p| p.creation_ns).sum();
            let slowest: Vec<String> = self
                .pipelines
                .iter()
                .take(3)
                .map(|p| format!("{} {:.1}", p.name, p.creation_ns / 1e6))
                .collect();
            s += &format!(
                "pipelines (once per render): {} created in {:.1} ms; slowest (ms): {}\n",
                self.pipelines.len(),
                total / 1e6,
                slowest.join(", ")
            );
        }
        let dropped: u32 = measured.iter().map(|f| f.dropped_deltas).sum();
        if dropped > 0 {
            s += &format!("({dropped} non-positive timestamp deltas dropped)\n");
        }
        s += &self.counters_table();
        let bound: Vec<String> = self
            .passes
            .iter()
            .filter_map(|p| {
                let b = p.bound_by.as_ref()?;
                Some(format!(
                    "  {:<22} {:<15} {}\n",
                    p.name,
                    b.bound.name(),
                    b.why
                ))
            })
            .collect();
        if !bound.is_empty() {
            s += &format!(
                "bound by (docs/design/pass-analysis.md):\n{}",
                bound.concat()
            );
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

impl RunReport {
    /// The passes' work counters (per frame, medians), when counted: empty
    /// otherwise.
    pub fn counters_table(&self) -> String {
        if self.passes.iter().all(|p| p.counters.is_none()) {
            return String::new();
        }
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.3}"));
        let mut s = format!(
            "{:<24} {:>10} {:>10} {:>10} {:>10} {:>12} {:>8} {:>12} {:>9}   (work counters per frame)\n",
            "pass", "vertices", "VS inv", "prims in", "prims out", "fragments", "frag/px",
            "compute inv", "inv/texel"
        );
        for p in &self.passes {
            let Some(c) = p.counters else {
                continue;
            };
            s += &format!(
                "{:<24} {:>10} {:>10} {:>10} {:>10} {:>12} {:>8} {:>12} {:>9}\n",
                p.name,
                c.input_vertices,
                c.vertex_invocations,
                c.clipping_invocations,
                c.clipping_primitives,
                c.fragment_invocations,
                opt(p.fragments_per_pixel),
                c.compute_invocations,
                opt(p.invocations_per_texel),
            );
        }
        s
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Frames of passes "a" (at 10 ns, lasting `a`) and "b" (right after),
    /// on the host-fence clock, 1000 ns apart.
    pub fn frames(a: &[f64]) -> Vec<FrameTiming> {
        a.iter()
            .enumerate()
            .map(|(i, &a)| FrameTiming {
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
            pipeline_statistics: true,
            calibrated_timestamps: false,
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
        let warmup = usize::from(a.len() > 1);
        RunReport::new(
            &device(),
            setup(),
            (64, 48),
            frames(a),
            warmup,
            MemoryUse::default(),
        )
    }

    /// A pass's work: `texels`, `bytes`, tagged `t`.
    fn work(texels: Option<u64>, bytes: Option<u64>) -> PassTime {
        PassTime {
            texels,
            bytes,
            tags: vec!["t".into()],
            ..PassTime::default()
        }
    }

    #[test]
    fn per_texel_figures_follow_from_work_and_median() {
        let mut s = PassStats::of("p", vec![Some(2000.0), Some(4000.0), Some(3000.0)])
            .with_work(Some(&work(Some(1000), Some(6000))));
        assert_eq!(s.ns_per_texel, Some(3.0));
        assert_eq!(s.gb_per_s, Some(2.0));
        assert_eq!(s.tags, ["t"]);
        s = s.with_work(Some(&work(None, Some(0))));
        assert_eq!((s.ns_per_texel, s.gb_per_s), (None, None));
        // No time: no figures, never NaN.
        let s = PassStats::of("q", vec![]).with_work(Some(&work(Some(10), Some(10))));
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
        assert_eq!(r.fingerprint.clock, "host-fence");
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
        let r = RunReport::new(&device(), setup(), (64, 48), f, 1, MemoryUse::default());
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
        assert_eq!(v["schema_version"], SCHEMA_VERSION);
        assert_eq!(v["fingerprint"]["clock"], "host-fence");
        assert_eq!(v["passes"][0]["samples_ns"], serde_json::json!([3.0, 5.0]));
        // What is written reads back.
        let back: RunReport = serde_json::from_value(v).unwrap();
        assert_eq!(back.passes[0].time, report(&[7.0, 3.0, 5.0]).passes[0].time);
    }

    #[test]
    fn runs_each_have_their_warm_up() {
        // Two runs of three frames, warm-up 1 each: measured 10 20 | 30 40.
        let mut f = frames(&[1000.0, 10.0, 20.0]);
        let mut second = frames(&[2000.0, 30.0, 40.0]);
        for x in &mut second {
            x.run = 1;
        }
        f.extend(second);
        let r = RunReport::new(&device(), setup(), (1, 1), f, 1, MemoryUse::default());
        assert_eq!((r.runs, r.frames, r.warmup_frames), (2, 6, 1));
        let warm: Vec<bool> = r.per_frame.iter().map(|f| f.warmup).collect();
        assert_eq!(warm, [true, false, false, true, false, false]);
        let a = r.passes[0].time.unwrap();
        assert_eq!((a.median_ns, a.mean_ns), (25.0, 25.0));
        assert_eq!(r.passes[0].frames, 4);
        assert!(r.cold_warning().is_none());
    }

    #[test]
    fn a_pass_no_frame_timed_has_a_count_of_zero() {
        let mut f = frames(&[1.0]);
        f[0].passes[0].gpu_ns = None;
        let r = RunReport::new(&device(), setup(), (1, 1), f, 0, MemoryUse::default());
        assert!(r.cold_warning().is_some());
        let v = serde_json::to_value(&r.passes[0]).unwrap();
        assert_eq!(v["frames"], 0);
        assert!(v.get("median_ns").is_none(), "{v}");
    }
}
