//! Recording and submitting compiled graphs: frames in flight, the transient
//! image pool, per-pass debug labels, GPU timestamps and, when asked for,
//! pipeline statistics (work counters).

use super::commands::{barriers, begin_rendering};
use super::pass_cx::{PassCx, ResolvedImage};
use super::plan::{Plan, PoolState};
use super::{Graph, Imported, ResourceKind};
use crate::error::{Error, Result, VkResultExt};
use crate::gpu::{Context, Image};
use crate::timing::{CpuSpan, FrameTiming, PassCounters, PassTime, PassWork};
use ash::vk;
use std::ffi::CString;
use std::sync::Arc;
use std::time::Instant;

/// A graph with its plan, ready to submit. The plan may be inspected (and, in
/// tests, deliberately broken) before submission.
pub struct Compiled {
    pub plan: Plan,
    graph: Graph,
}

/// Per frame in flight: command buffer, fence, timestamp queries and pipeline
/// statistics queries (one per pass, with counters on).
struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    queries: vk::QueryPool,
    query_capacity: u32,
    stats: vk::QueryPool,
    stats_capacity: u32,
    in_flight: Option<InFlight>,
}

/// What a submitted frame keeps alive until its fence signals.
struct InFlight {
    frame: u64,
    pass_names: Vec<String>,
    work: Vec<PassWork>,
    counted: bool,
    /// Record and submit, on the host clock from `host_epoch`.
    spans: Vec<CpuSpan>,
    cpu_record_ns: f64,
    cpu_submit_ns: f64,
    _graph: Graph,
}

/// Semaphores a frame's work waits on (with the stage that waits) and signals:
/// a swapchain image's acquire and present.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameSync {
    pub wait: Option<(vk::Semaphore, vk::PipelineStageFlags2)>,
    pub signal: Option<vk::Semaphore>,
}

/// Which clock measures passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Clock {
    /// GPU timestamps around each pass, one submission per frame (real GPUs).
    GpuTimestamp,
    /// One submission per pass, timed on the host from submit to fence. On CPU
    /// devices this is the true cost: lavapipe (Mesa 22.3) resolves timestamp
    /// queries on its rasterizer threads while compute runs on the queue thread,
    /// so its timestamps do not bracket compute passes.
    HostFence,
}

impl Clock {
    /// Timestamps where they measure work, host fences on CPU devices.
    pub fn auto(info: &crate::gpu::DeviceInfo) -> Self {
        if info.timestamps && info.device_type != "CPU" {
            Clock::GpuTimestamp
        } else {
            Clock::HostFence
        }
    }
}

/// The statistics a pass's query counts, in the order their results come
/// ([`PassCounters::from_raw`]). Geometry and tessellation counts are left out:
/// no pass uses those stages.
const STATISTICS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_VERTICES.as_raw()
        | vk::QueryPipelineStatisticFlags::INPUT_ASSEMBLY_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::VERTEX_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::CLIPPING_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::CLIPPING_PRIMITIVES.as_raw()
        | vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);

pub struct Executor {
    ctx: Arc<Context>,
    clock: Clock,
    /// Pipeline statistics per pass ([`Executor::set_counters`]).
    counters: bool,
    slots: Vec<FrameSlot>,
    next: usize,
    frame: u64,
    pool: PoolState,
    pool_images: Vec<Option<Image>>,
    /// The first frame's start, that later frames' starts count from: a raw
    /// timestamp (GPU clock) and an instant (host clock).
    gpu_epoch: Option<u64>,
    host_epoch: Option<Instant>,
    /// A GPU timestamp and the host instant of the same moment
    /// (Context::calibrate), taken with the first frame on GPU timestamps,
    /// and how far apart they may be, ns.
    calibration: Option<(u64, Instant, f64)>,
    /// Submissions wait while another thread holds `Context::foreground`.
    background: bool,
}

impl Executor {
    /// `frames_in_flight` ≥ 1 (2 is the usual choice).
    pub fn new(ctx: &Arc<Context>, frames_in_flight: usize) -> Result<Self> {
        let mut ex = Executor {
            ctx: ctx.clone(),
            clock: Clock::auto(&ctx.info),
            counters: false,
            slots: Vec::new(),
            next: 0,
            frame: 0,
            pool: PoolState::default(),
            pool_images: Vec::new(),
            gpu_epoch: None,
            host_epoch: None,
            calibration: None,
            background: false,
        };
        for _ in 0..frames_in_flight.max(1) {
            let slot = ex.new_slot()?;
            ex.slots.push(slot);
        }
        Ok(ex)
    }

    /// Makes every submission wait while another thread holds
    /// [`Context::foreground`](crate::gpu::Context::foreground) (with one
    /// submission per pass on CPU devices, between passes).
    pub fn set_background(&mut self) {
        self.background = true;
    }

    /// How far GPU times put on the host clock may be off, ns: the
    /// calibration's uncertainty (Context::calibrate); `None` before the first
    /// frame or without calibrated timestamps.
    pub fn calibration_uncertainty_ns(&self) -> Option<f64> {
        self.calibration.map(|(_, _, u)| u)
    }

    /// Overrides the automatic choice; `GpuTimestamp` needs device timestamps.
    pub fn set_clock(&mut self, clock: Clock) -> Result<()> {
        if clock == Clock::GpuTimestamp && !self.ctx.info.timestamps {
            return Err(Error::Input(format!(
                "{} has no timestamp queries",
                self.ctx.info.name
            )));
        }
        self.clock = clock;
        Ok(())
    }

    /// Counts each pass's work with a pipeline statistics query (vertices,
    /// primitives, vertex, fragment and compute invocations) around it, outside
    /// its timestamps. Off by default: then no query is recorded. An error on a
    /// device without the `pipelineStatisticsQuery` feature.
    pub fn set_counters(&mut self, on: bool) -> Result<()> {
        if on && !self.ctx.info.pipeline_statistics {
            return Err(Error::Input(format!(
                "{} has no pipeline statistics queries (the pipelineStatisticsQuery \
                 feature): it cannot count a pass's work",
                self.ctx.info.name
            )));
        }
        self.counters = on;
        Ok(())
    }

    fn new_slot(&self) -> Result<FrameSlot> {
        let d = &self.ctx.device;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(self.ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        let pool = unsafe { d.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")?;
        let mut slot = FrameSlot {
            pool,
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
            queries: vk::QueryPool::null(),
            query_capacity: 0,
            stats: vk::QueryPool::null(),
            stats_capacity: 0,
            in_flight: None,
        };
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let made = unsafe { d.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")
            .and_then(|cmds| {
                slot.cmd = cmds[0];
                unsafe { d.create_fence(&vk::FenceCreateInfo::default(), None) }.vk("vkCreateFence")
            });
        match made {
            Ok(fence) => {
                slot.fence = fence;
                Ok(slot)
            }
            Err(e) => {
                self.destroy_slot(&slot);
                Err(e)
            }
        }
    }

    fn destroy_slot(&self, slot: &FrameSlot) {
        let d = &self.ctx.device;
        unsafe {
            if slot.queries != vk::QueryPool::null() {
                d.destroy_query_pool(slot.queries, None);
            }
            if slot.stats != vk::QueryPool::null() {
                d.destroy_query_pool(slot.stats, None);
            }
            if slot.fence != vk::Fence::null() {
                d.destroy_fence(slot.fence, None);
            }
            d.destroy_command_pool(slot.pool, None);
        }
    }

    /// Plans a graph against the executor's transient pool. Submit the result
    /// next: the pool's state assumes it runs.
    pub fn compile(&mut self, mut graph: Graph) -> Result<Compiled> {
        let plan = graph.compile(&mut self.pool)?;
        Ok(Compiled { plan, graph })
    }

    /// Compiles and submits; returns the report of the frame that last used this
    /// frame slot, if any (it has completed).
    pub fn run(&mut self, graph: Graph) -> Result<Option<FrameTiming>> {
        let compiled = self.compile(graph)?;
        self.submit(compiled)
    }

    pub fn submit(&mut self, compiled: Compiled) -> Result<Option<FrameTiming>> {
        self.submit_synced(compiled, FrameSync::default())
    }

    /// [`Executor::submit`] for a frame that draws a swapchain image: its work
    /// waits on `sync.wait` and signals `sync.signal` (in host-fence mode the
    /// first pass's submission waits and the last one's signals).
    pub fn submit_synced(
        &mut self,
        compiled: Compiled,
        sync: FrameSync,
    ) -> Result<Option<FrameTiming>> {
        let index = self.next;
        let previous = self.retire(index)?;
        self.realize_pool()?;
        let started = Instant::now();
        let (images, buffers) = self.resolve(&compiled)?;
        let names: Vec<String> = compiled
            .plan
            .passes
            .iter()
            .map(|p| p.name.clone())
            .collect();
        let n = names.len();
        let work: Vec<PassWork> = compiled
            .plan
            .passes
            .iter()
            .map(|p| p.work.clone())
            .collect();
        if self.counters {
            self.ensure_stats(index, n as u32)?;
        }
        if self.clock == Clock::HostFence {
            let mut report = self.run_isolated(index, &compiled, &images, &buffers, names, sync)?;
            report.set_work(&work);
            if self.counters {
                report.set_counters(&self.read_counters(index, n)?);
            }
            self.frame += 1;
            return Ok(previous.or(Some(report)));
        }
        self.ensure_queries(index, 2 + 2 * n as u32)?;
        if self.host_epoch.is_none() {
            self.host_epoch = Some(started);
            self.calibration = self.ctx.calibrate();
        }
        self.record(index, &compiled, &images, &buffers, 0..n)?;
        let recorded = Instant::now();
        self.submit_slot(index, sync)?;
        let submitted = Instant::now();
        let spans = vec![
            self.span("record", None, started, recorded),
            self.span("submit", None, recorded, submitted),
        ];
        self.slots[index].in_flight = Some(InFlight {
            frame: self.frame,
            pass_names: names,
            work,
            counted: self.counters,
            spans,
            cpu_record_ns: (recorded - started).as_nanos() as f64,
            cpu_submit_ns: (submitted - recorded).as_nanos() as f64,
            _graph: compiled.graph,
        });
        self.frame += 1;
        self.next = (index + 1) % self.slots.len();
        Ok(previous)
    }

    /// A CPU span from `a` to `b` on the host clock from the epoch.
    fn span(&self, what: &str, pass: Option<&str>, a: Instant, b: Instant) -> CpuSpan {
        let epoch = self.host_epoch.unwrap_or(a);
        CpuSpan {
            what: what.into(),
            pass: pass.map(str::to_string),
            start_ns: a.saturating_duration_since(epoch).as_nanos() as f64,
            dur_ns: b.saturating_duration_since(a).as_nanos() as f64,
        }
    }

    fn submit_slot(&self, index: usize, sync: FrameSync) -> Result<()> {
        let slot = &self.slots[index];
        let cmd_info = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
        let waits: Vec<_> = sync
            .wait
            .iter()
            .map(|&(s, stage)| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(stage)
            })
            .collect();
        let signals: Vec<_> = sync
            .signal
            .iter()
            .map(|&s| {
                vk::SemaphoreSubmitInfo::default()
                    .semaphore(s)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
            })
            .collect();
        let submit = [vk::SubmitInfo2::default()
            .command_buffer_infos(&cmd_info)
            .wait_semaphore_infos(&waits)
            .signal_semaphore_infos(&signals)];
        if self.background {
            drop(self.ctx.foreground());
        }
        let queue = self.ctx.queue();
        unsafe { self.ctx.device.queue_submit2(*queue, &submit, slot.fence) }.vk("vkQueueSubmit2")
    }

    /// [`Clock::HostFence`]: each pass is its own submission, waited for and timed
    /// from submit to fence; its start is the submit's offset from the frame's.
    fn run_isolated(
        &mut self,
        index: usize,
        c: &Compiled,
        images: &[Option<ResolvedImage>],
        buffers: &[Option<vk::Buffer>],
        names: Vec<String>,
        sync: FrameSync,
    ) -> Result<FrameTiming> {
        let fence = self.slots[index].fence;
        let d = &self.ctx.device;
        let frame_start = Instant::now();
        let epoch = *self.host_epoch.get_or_insert(frame_start);
        let (mut record_ns, mut submit_ns) = (0.0, 0.0);
        let mut passes = Vec::with_capacity(names.len());
        let mut spans = Vec::with_capacity(3 * names.len());
        let count = names.len().max(1);
        for i in 0..count {
            let t0 = Instant::now();
            self.record(index, c, images, buffers, i..(i + 1).min(names.len()))?;
            let t1 = Instant::now();
            let this = FrameSync {
                wait: sync.wait.filter(|_| i == 0),
                signal: sync.signal.filter(|_| i + 1 == count),
            };
            self.submit_slot(index, this)?;
            let t2 = Instant::now();
            unsafe { d.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")?;
            unsafe { d.reset_fences(&[fence]) }.vk("vkResetFences")?;
            let t3 = Instant::now();
            record_ns += (t1 - t0).as_nanos() as f64;
            submit_ns += (t2 - t1).as_nanos() as f64;
            let pass = names.get(i).map(String::as_str);
            spans.push(self.span("record", pass, t0, t1));
            spans.push(self.span("submit", pass, t1, t2));
            spans.push(self.span("wait", pass, t2, t3));
            if let Some(name) = names.get(i) {
                passes.push(PassTime {
                    name: name.clone(),
                    gpu_ns: Some((t3 - t1).as_nanos() as f64),
                    start_ns: Some((t1 - frame_start).as_nanos() as f64),
                    ..Default::default()
                });
            }
        }
        Ok(FrameTiming {
            frame: self.frame,
            start_ns: Some((frame_start - epoch).as_nanos() as f64),
            passes,
            gpu_frame_ns: Some(frame_start.elapsed().as_nanos() as f64),
            cpu_record_ns: record_ns,
            cpu_submit_ns: submit_ns,
            dropped_deltas: 0,
            clock: "host-fence".into(),
            host_start_ns: Some((frame_start - epoch).as_nanos() as f64),
            cpu_spans: spans,
            ..Default::default()
        })
    }

    /// Frames submitted so far: the number the next one's report will carry.
    pub fn frames_submitted(&self) -> u64 {
        self.frame
    }

    /// Waits for every frame in flight; returns their reports in submission order.
    pub fn finish(&mut self) -> Result<Vec<FrameTiming>> {
        let mut reports = Vec::new();
        for k in 0..self.slots.len() {
            let index = (self.next + k) % self.slots.len();
            reports.extend(self.retire(index)?);
        }
        Ok(reports)
    }

    /// Device memory held by pooled transient images, in bytes.
    pub fn pool_bytes(&self) -> u64 {
        self.pool_images
            .iter()
            .flatten()
            .map(|i| {
                let texel = crate::gpu::texel_bytes(i.desc.format).unwrap_or(0) as u64;
                i.desc.width as u64 * i.desc.height as u64 * texel
            })
            .sum()
    }

    /// Waits for the frame in `index` (if any) and turns its timestamps into a report.
    fn retire(&mut self, index: usize) -> Result<Option<FrameTiming>> {
        let Some(done) = self.slots[index].in_flight.take() else {
            return Ok(None);
        };
        let slot = &self.slots[index];
        let d = &self.ctx.device;
        let wait_start = Instant::now();
        unsafe { d.wait_for_fences(&[slot.fence], true, u64::MAX) }.vk("vkWaitForFences")?;
        let wait = self.span("wait", None, wait_start, Instant::now());
        unsafe { d.reset_fences(&[slot.fence]) }.vk("vkResetFences")?;
        let mut report = if slot.queries != vk::QueryPool::null() {
            let mut raw = vec![0u64; 2 + 2 * done.pass_names.len()];
            unsafe {
                d.get_query_pool_results(
                    slot.queries,
                    0,
                    &mut raw,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .vk("vkGetQueryPoolResults")?;
            let info = &self.ctx.info;
            let mut report = FrameTiming::from_timestamps(
                done.frame,
                &done.pass_names,
                &raw,
                info.timestamp_valid_bits,
                info.timestamp_period_ns,
            );
            // Frames retire in order: the first one retired sets the epoch.
            let epoch = *self.gpu_epoch.get_or_insert(raw[0]);
            let mask = match info.timestamp_valid_bits {
                64.. => u64::MAX,
                bits => (1u64 << bits) - 1,
            };
            let ticks = raw[0].wrapping_sub(epoch) & mask;
            let period = info.timestamp_period_ns as f64;
            report.start_ns = Some(ticks as f64 * period);
            // On the host clock: the calibration's instant, plus the ticks since.
            if let (Some((at_ticks, at, _)), Some(host)) = (self.calibration, self.host_epoch) {
                let since = (raw[0].wrapping_sub(at_ticks) & mask) as f64 * period;
                report.host_start_ns =
                    Some(at.saturating_duration_since(host).as_nanos() as f64 + since);
            }
            report
        } else {
            // No timestamps on this device: passes are listed without GPU times.
            FrameTiming::from_timestamps(done.frame, &done.pass_names, &[], 64, 1.0)
        };
        report.set_work(&done.work);
        report.cpu_spans = done.spans;
        report.cpu_spans.push(wait);
        if done.counted {
            report.set_counters(&self.read_counters(index, done.pass_names.len())?);
        }
        report.cpu_record_ns = done.cpu_record_ns;
        report.cpu_submit_ns = done.cpu_submit_ns;
        Ok(Some(report))
    }

    fn ensure_queries(&mut self, index: usize, needed: u32) -> Result<()> {
        if !self.ctx.info.timestamps {
            return Ok(());
        }
        let d = &self.ctx.device;
        let slot = &mut self.slots[index];
        if slot.query_capacity < needed {
            if slot.queries != vk::QueryPool::null() {
                unsafe { d.destroy_query_pool(slot.queries, None) };
                slot.queries = vk::QueryPool::null();
            }
            let capacity = needed.next_power_of_two().max(64);
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::TIMESTAMP)
                .query_count(capacity);
            slot.queries = unsafe { d.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
            slot.query_capacity = capacity;
        }
        // Host reset (Vulkan 1.2 hostQueryReset): the slot's previous frame is retired.
        unsafe { d.reset_query_pool(slot.queries, 0, slot.query_capacity) };
        Ok(())
    }

    /// A pipeline statistics query per pass in the slot, host-reset.
    fn ensure_stats(&mut self, index: usize, needed: u32) -> Result<()> {
        let d = &self.ctx.device;
        let slot = &mut self.slots[index];
        if slot.stats_capacity < needed.max(1) {
            if slot.stats != vk::QueryPool::null() {
                unsafe { d.destroy_query_pool(slot.stats, None) };
                slot.stats = vk::QueryPool::null();
            }
            let capacity = needed.next_power_of_two().max(32);
            let info = vk::QueryPoolCreateInfo::default()
                .query_type(vk::QueryType::PIPELINE_STATISTICS)
                .pipeline_statistics(STATISTICS)
                .query_count(capacity);
            slot.stats = unsafe { d.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
            slot.stats_capacity = capacity;
        }
        unsafe { d.reset_query_pool(slot.stats, 0, slot.stats_capacity) };
        Ok(())
    }

    /// The counters of the slot's `n` passes (their work has completed).
    fn read_counters(&self, index: usize, n: usize) -> Result<Vec<PassCounters>> {
        let mut raw = vec![[0u64; 7]; n];
        if n > 0 {
            unsafe {
                self.ctx.device.get_query_pool_results(
                    self.slots[index].stats,
                    0,
                    &mut raw,
                    vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
                )
            }
            .vk("vkGetQueryPoolResults")?;
        }
        Ok(raw.into_iter().map(PassCounters::from_raw).collect())
    }

    /// Creates images for pool slots that have none yet.
    fn realize_pool(&mut self) -> Result<()> {
        for s in self.pool_images.len()..self.pool.slot_count() {
            let Some((desc, usage)) = self.pool.slot(s) else {
                continue;
            };
            let image = Image::new(&self.ctx, &format!("transient#{s}"), desc, usage)?;
            self.pool_images.push(Some(image));
        }
        Ok(())
    }

    #[allow(clippy::type_complexity)]
    fn resolve(
        &self,
        c: &Compiled,
    ) -> Result<(Vec<Option<ResolvedImage>>, Vec<Option<vk::Buffer>>)> {
        let mut images = Vec::with_capacity(c.graph.resources.len());
        let mut buffers = Vec::with_capacity(c.graph.resources.len());
        for (decl, planned) in c.graph.resources.iter().zip(&c.plan.resources) {
            let (mut img, mut buf) = (None, None);
            match (&decl.import, &decl.kind) {
                (Some(import), _) => match &import.source {
                    Imported::Image(i) => {
                        img = Some(ResolvedImage {
                            raw: i.raw,
                            view: i.view,
                            desc: i.desc,
                        })
                    }
                    Imported::Buffer(b) => buf = Some(b.raw),
                    Imported::Described { .. } => {
                        return Err(Error::Graph(format!(
                            "{:?} is only described and cannot be executed",
                            decl.name
                        )))
                    }
                },
                (None, ResourceKind::Image(_)) => {
                    if let Some(i) = planned
                        .slot
                        .and_then(|s| self.pool_images.get(s))
                        .and_then(Option::as_ref)
                    {
                        img = Some(ResolvedImage {
                            raw: i.raw,
                            view: i.view,
                            desc: i.desc,
                        });
                    }
                }
                (None, ResourceKind::Buffer(_)) => {}
            }
            images.push(img);
            buffers.push(buf);
        }
        Ok((images, buffers))
    }

    /// Records passes `range` into the slot's command buffer; the first range of a
    /// frame opens it (frame timestamp), the one reaching the end closes it
    /// (final barriers, frame timestamp).
    fn record(
        &self,
        index: usize,
        c: &Compiled,
        images: &[Option<ResolvedImage>],
        buffers: &[Option<vk::Buffer>],
        range: std::ops::Range<usize>,
    ) -> Result<()> {
        let first = range.start == 0;
        let last = range.end == c.plan.passes.len();
        let d = &self.ctx.device;
        let slot = &self.slots[index];
        let cmd = slot.cmd;
        unsafe { d.reset_command_pool(slot.pool, vk::CommandPoolResetFlags::empty()) }
            .vk("vkResetCommandPool")?;
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        unsafe { d.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
        let timestamp = |q: u32| {
            if self.clock == Clock::GpuTimestamp && slot.queries != vk::QueryPool::null() {
                unsafe {
                    d.cmd_write_timestamp2(
                        cmd,
                        vk::PipelineStageFlags2::ALL_COMMANDS,
                        slot.queries,
                        q,
                    )
                };
            }
        };
        if first {
            timestamp(0);
        }
        // Around the pass and its timestamps, after its barriers.
        let counting = self.counters && slot.stats != vk::QueryPool::null();
        let cx = PassCx::new(&self.ctx, cmd, images, buffers);
        for i in range {
            let (planned, pass) = (&c.plan.passes[i], &c.graph.passes[i]);
            self.label_begin(cmd, &planned.name);
            barriers(&self.ctx.device, cmd, &planned.barriers, images, buffers);
            if counting {
                unsafe {
                    d.cmd_begin_query(cmd, slot.stats, i as u32, vk::QueryControlFlags::empty())
                };
            }
            timestamp(2 + 2 * i as u32);
            let rendering = !pass.attachments.is_empty();
            if rendering {
                begin_rendering(&self.ctx.device, cmd, pass, images);
            }
            if let Some(record) = &pass.record {
                record(&cx);
            }
            if rendering {
                unsafe { d.cmd_end_rendering(cmd) };
            }
            timestamp(3 + 2 * i as u32);
            if counting {
                unsafe { d.cmd_end_query(cmd, slot.stats, i as u32) };
            }
            self.label_end(cmd);
        }
        if last {
            barriers(
                &self.ctx.device,
                cmd,
                &c.plan.final_barriers,
                images,
                buffers,
            );
            timestamp(1);
        }
        unsafe { d.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")
    }

    fn label_begin(&self, cmd: vk::CommandBuffer, name: &str) {
        let (Some(du), Ok(name)) = (&self.ctx.debug_utils, CString::new(name)) else {
            return;
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        unsafe { du.cmd_begin_debug_utils_label(cmd, &label) };
    }

    fn label_end(&self, cmd: vk::CommandBuffer) {
        if let Some(du) = &self.ctx.debug_utils {
            unsafe { du.cmd_end_debug_utils_label(cmd) };
        }
    }
}

impl Drop for Executor {
    fn drop(&mut self) {
        for slot in &self.slots {
            if slot.in_flight.is_some() {
                let _ = unsafe {
                    self.ctx
                        .device
                        .wait_for_fences(&[slot.fence], true, u64::MAX)
                };
            }
        }
        for slot in &self.slots {
            self.destroy_slot(slot);
        }
    }
}
