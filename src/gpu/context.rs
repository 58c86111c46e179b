//! Instance, device, queue, memory allocator and validation: the root every GPU
//! object holds an `Arc` of, so that it is destroyed last.

use super::pipeline_cache::{DeviceKey, PipelineCache};
use super::validation::{messenger_info, ValidationLog, TEST_MESSAGE_VAR};
use crate::error::{Error, Result, VkResultExt};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use serde::Serialize;
use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable VK_LAYER_KHRONOS_validation with synchronization validation.
    pub validation: bool,
    /// Pick the first device whose name contains this (case-insensitive).
    pub device: Option<String>,
    /// Present to windows of this display (the viewer): the instance gets the
    /// display's surface extensions and the device VK_KHR_swapchain.
    pub display: Option<raw_window_handle::RawDisplayHandle>,
    /// The folder of the on-disk pipeline cache (`pipeline_cache.rs`), read
    /// when the context is made and written when it ends; `None`: pipelines
    /// are compiled afresh and nothing is kept.
    pub pipeline_cache: Option<PathBuf>,
}

impl ContextOptions {
    /// Options from the environment: `DERMIS_VALIDATION=1`, `DERMIS_DEVICE=<substring>`;
    /// the pipeline cache in the cache folder (`cache::default_cache_dir`).
    pub fn from_env() -> Self {
        Self {
            validation: std::env::var("DERMIS_VALIDATION").is_ok_and(|v| v == "1"),
            device: std::env::var("DERMIS_DEVICE")
                .ok()
                .filter(|s| !s.is_empty()),
            display: None,
            pipeline_cache: Some(crate::cache::default_cache_dir()),
        }
    }
}

/// What `dermis info` reports, and what frame reports are stamped with.
#[derive(Clone, Debug, Serialize)]
pub struct DeviceInfo {
    pub name: String,
    pub device_type: String,
    pub driver_name: String,
    pub driver_info: String,
    pub api_version: String,
    pub vendor_id: u32,
    pub device_id: u32,
    pub timestamps: bool,
    pub timestamp_period_ns: f32,
    pub timestamp_valid_bits: u32,
    /// Pipeline statistics queries (the `pipelineStatisticsQuery` feature,
    /// enabled on the device when offered): per-pass work counters.
    pub pipeline_statistics: bool,
    /// Calibrated timestamps (`VK_EXT_calibrated_timestamps` with the device
    /// and CLOCK_MONOTONIC domains, enabled when offered): GPU timestamps on the
    /// host's clock.
    pub calibrated_timestamps: bool,
    pub max_image_dimension_2d: u32,
    pub memory_heaps: Vec<MemoryHeap>,
    pub validation: bool,
}

impl DeviceInfo {
    /// A CPU implementation (lavapipe): work runs on the host's cores.
    pub fn is_cpu(&self) -> bool {
        self.device_type == "CPU"
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct MemoryHeap {
    pub size_bytes: u64,
    pub device_local: bool,
}

pub struct Context {
    pub(crate) entry: ash::Entry,
    pub instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub(crate) push_descriptor: ash::khr::push_descriptor::Device,
    pipeline_cache: PipelineCache,
    /// Whether a pipeline was made through the cache (else it is not saved).
    pipelines_made: AtomicBool,
    /// Pipelines made from now on skip their shaders' work
    /// ([`Context::set_skip_work`]).
    skip_work: AtomicBool,
    calibrated: Option<ash::ext::calibrated_timestamps::Device>,
    queue: Mutex<vk::Queue>,
    /// Held by work that must not wait behind another thread's (see [`Context::foreground`]).
    foreground: Mutex<()>,
    pub queue_family: u32,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    pub info: DeviceInfo,
    validation: Option<Arc<ValidationLog>>,
}

fn cstr(chars: &[c_char]) -> String {
    // Vulkan strings are NUL-terminated within fixed arrays.
    let bytes: Vec<u8> = chars
        .iter()
        .take_while(|&&c| c != 0)
        .map(|&c| c as u8)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

fn version_string(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

/// Preference order when no device is named: discrete > integrated > virtual > CPU.
fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

fn type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
        vk::PhysicalDeviceType::CPU => "CPU",
        _ => "other",
    }
}

/// Held while a context is created or destroyed: the loader, layers and
/// drivers are not all safe against instances and devices made and destroyed
/// on several threads at once (one of the GPU tests, which each make their own
/// context in parallel, died of SIGSEGV at start-up in CI; Vulkan-Loader#220 and
/// kvark/blade#336 are the same race elsewhere). Rendering is not serialised.
static LIFECYCLE: Mutex<()> = Mutex::new(());

fn lifecycle() -> MutexGuard<'static, ()> {
    LIFECYCLE
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl Context {
    pub fn new(options: &ContextOptions) -> Result<Arc<Self>> {
        let _lifecycle = lifecycle();
        // SAFETY: loading libvulkan runs its initialisers; nothing else is in flight.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::NoLoader(e.to_string()))?;
        let validation = options
            .validation
            .then(|| Arc::new(ValidationLog::default()));
        let surface_extensions = match options.display {
            Some(display) => ash_window::enumerate_required_extensions(display)
                .map_err(|e| {
                    Error::Window(format!("no Vulkan surface extension for this display: {e}"))
                })?
                .to_vec(),
            None => Vec::new(),
        };
        let (instance, messenger) =
            create_instance(&entry, validation.as_deref(), &surface_extensions)?;
        // From here on, `partial` destroys what exists if a later step fails.
        let partial = Partial {
            instance: &instance,
            messenger: messenger.as_ref(),
        };
        let swapchain = options.display.is_some();
        let (physical, queue_family, mut info) = choose_device(
            &instance,
            options.device.as_deref(),
            validation.is_some(),
            swapchain,
        )?;
        info.calibrated_timestamps = calibration_offered(&entry, &instance, physical);
        let device = create_device(&instance, physical, queue_family, swapchain, &info)?;
        let key = DeviceKey::of(&unsafe { instance.get_physical_device_properties(physical) });
        let pipeline_cache = PipelineCache::new(&device, &key, options.pipeline_cache.as_deref())
            .inspect_err(|_| unsafe { device.destroy_device(None) })?;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|source| {
            unsafe {
                device.destroy_pipeline_cache(pipeline_cache.raw, None);
                device.destroy_device(None);
            }
            Error::Alloc {
                name: "allocator".into(),
                source,
            }
        })?;
        std::mem::forget(partial);
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let debug_utils = messenger
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device))
            .or_else(|| {
                has_instance_extension(&entry, ash::ext::debug_utils::NAME)
                    .then(|| ash::ext::debug_utils::Device::new(&instance, &device))
            });
        let push_descriptor = ash::khr::push_descriptor::Device::new(&instance, &device);
        let calibrated = info
            .calibrated_timestamps
            .then(|| ash::ext::calibrated_timestamps::Device::new(&instance, &device));
        log::info!(
            "device: {} ({}), driver {} {}, Vulkan {}",
            info.name,
            info.device_type,
            info.driver_name,
            info.driver_info,
            info.api_version
        );
        Ok(Arc::new(Self {
            entry,
            instance,
            messenger,
            debug_utils,
            physical,
            device,
            push_descriptor,
            pipeline_cache,
            pipelines_made: AtomicBool::new(false),
            skip_work: AtomicBool::new(false),
            calibrated,
            queue: Mutex::new(queue),
            foreground: Mutex::new(()),
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            info,
            validation,
        }))
    }

    /// The device's timestamp and the host's instant at one moment, with the
    /// uncertainty in ns (the driver's maximum deviation plus the call's
    /// length, the instant being the call's midpoint): what puts GPU
    /// timestamps on the host's clock. `None` without calibrated timestamps.
    pub fn calibrate(&self) -> Option<(u64, std::time::Instant, f64)> {
        let ext = self.calibrated.as_ref()?;
        let info = [
            vk::CalibratedTimestampInfoEXT::default().time_domain(vk::TimeDomainEXT::DEVICE),
            vk::CalibratedTimestampInfoEXT::default()
                .time_domain(vk::TimeDomainEXT::CLOCK_MONOTONIC),
        ];
        let before = std::time::Instant::now();
        let (stamps, deviation) = unsafe { ext.get_calibrated_timestamps(&info) }.ok()?;
        let after = std::time::Instant::now();
        let call = after - before;
        Some((
            stamps[0],
            before + call / 2,
            deviation as f64 + call.as_nanos() as f64,
        ))
    }

    /// The validation log, when validation is on. Keep the `Arc` to read it after
    /// the context is dropped (leaks are reported at device destruction).
    pub fn validation(&self) -> Option<Arc<ValidationLog>> {
        self.validation.clone()
    }

    /// The cache every pipeline is made through.
    pub(crate) fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipelines_made.store(true, Ordering::Relaxed);
        self.pipeline_cache.raw
    }

    /// Pipelines made from now on, while `skip`, use the variant of each shader
    /// that has one with its work skipped (build.rs, `#ifdef SKIP_WORK`): the
    /// timing variant of docs/design/pass-analysis.md. Pipelines made before
    /// keep theirs.
    pub fn set_skip_work(&self, skip: bool) {
        self.skip_work.store(skip, Ordering::Relaxed);
    }

    pub(crate) fn skip_work(&self) -> bool {
        self.skip_work.load(Ordering::Relaxed)
    }

    pub(crate) fn allocator(&self) -> MutexGuard<'_, Allocator> {
        self.allocator.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// gpu-allocator's totals now: (bytes in live allocations, bytes of device
    /// memory blocks it holds).
    pub fn allocator_bytes(&self) -> (u64, u64) {
        let report = self.allocator().generate_report();
        (report.total_allocated_bytes, report.total_capacity_bytes)
    }

    pub(crate) fn queue(&self) -> MutexGuard<'_, vk::Queue> {
        self.queue.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Held by a thread while its submissions must not queue behind another
    /// thread's (the viewer's window frames, from submit to present): background
    /// executors (`graph::Executor::set_background`) wait for it before each
    /// submission. The device has one queue, and on a CPU device a submission
    /// runs after everything submitted before it.
    pub fn foreground(&self) -> MutexGuard<'_, ()> {
        self.foreground.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Names a Vulkan object for debuggers and validation messages.
    pub(crate) fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(du) = &self.debug_utils else { return };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // Naming is best effort: a failure only loses a label.
        let _ = unsafe { du.set_debug_utils_object_name(&info) };
    }

    /// Whether sampled images of `format` support linear filtering (optional for
    /// 32-bit float formats in Vulkan).
    pub fn supports_linear_filter(&self, format: vk::Format) -> bool {
        let props = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical, format)
        };
        props
            .optimal_tiling_features
            .contains(vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR)
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        let _lifecycle = lifecycle();
        unsafe {
            let _ = self.device.device_wait_idle();
            self.pipeline_cache
                .save_and_destroy(&self.device, self.pipelines_made.load(Ordering::Relaxed));
            // Device memory goes back before the device itself.
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some((du, messenger)) = &self.messenger {
                du.destroy_debug_utils_messenger(*messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// Destroys the instance (and messenger) if device creation fails half way.
struct Partial<'a> {
    instance: &'a ash::Instance,
    messenger: Option<&'a (ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

impl Drop for Partial<'_> {
    fn drop(&mut self) {
        unsafe {
            if let Some((du, m)) = self.messenger {
                du.destroy_debug_utils_messenger(*m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

fn has_instance_extension(entry: &ash::Entry, name: &CStr) -> bool {
    unsafe { entry.enumerate_instance_extension_properties(None) }
        .unwrap_or_default()
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(name))
}

type Messenger = (ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT);

fn create_instance(
    entry: &ash::Entry,
    validation: Option<&ValidationLog>,
    surface_extensions: &[*const c_char],
) -> Result<(ash::Instance, Option<Messenger>)> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"dermis")
        .engine_name(c"dermis")
        .api_version(vk::API_VERSION_1_3);
    let mut layers: Vec<*const c_char> = Vec::new();
    let mut extensions: Vec<*const c_char> = surface_extensions.to_vec();
    if has_instance_extension(entry, ash::ext::debug_utils::NAME) || validation.is_some() {
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    if validation.is_some() {
        let available = unsafe { entry.enumerate_instance_layer_properties() }
            .vk("vkEnumerateInstanceLayerProperties")?;
        if !available
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER))
        {
            return Err(Error::NoValidationLayer);
        }
        layers.push(VALIDATION_LAYER.as_ptr());
    }
    // Synchronization validation is switched on through VkValidationFeaturesEXT
    // (the Debian 12 layer, 1.3.239, predates VK_EXT_layer_settings).
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    let mut messenger_ci = validation.map(messenger_info);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if let Some(ci) = messenger_ci.as_mut() {
        // Chained so that instance creation and destruction are validated too.
        info = info.push_next(ci).push_next(&mut features);
    }
    let instance = unsafe { entry.create_instance(&info, None) }.map_err(|e| match e {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER | vk::Result::ERROR_INITIALIZATION_FAILED => {
            Error::NoDevice
        }
        result => Error::Vk {
            call: "vkCreateInstance",
            result,
        },
    })?;
    let messenger = match validation {
        Some(log) => {
            let du = ash::ext::debug_utils::Instance::new(entry, &instance);
            match unsafe { du.create_debug_utils_messenger(&messenger_info(log), None) } {
                Ok(m) => {
                    submit_test_message(&du);
                    Some((du, m))
                }
                Err(result) => {
                    unsafe { instance.destroy_instance(None) };
                    return Err(Error::Vk {
                        call: "vkCreateDebugUtilsMessengerEXT",
                        result,
                    });
                }
            }
        }
        None => None,
    };
    Ok((instance, messenger))
}

/// [`TEST_MESSAGE_VAR`]'s message, when set, as an error of the layer.
fn submit_test_message(du: &ash::ext::debug_utils::Instance) {
    let Some(text) = std::env::var(TEST_MESSAGE_VAR)
        .ok()
        .and_then(|t| std::ffi::CString::new(t).ok())
    else {
        return;
    };
    let data = vk::DebugUtilsMessengerCallbackDataEXT::default().message(&text);
    // SAFETY: the instance and its messenger exist; `data` outlives the call.
    unsafe {
        du.submit_debug_utils_message(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
            &data,
        )
    };
}

fn choose_device(
    instance: &ash::Instance,
    wanted: Option<&str>,
    validation: bool,
    swapchain: bool,
) -> Result<(vk::PhysicalDevice, u32, DeviceInfo)> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    if devices.is_empty() {
        return Err(Error::NoDevice);
    }
    let mut candidates = Vec::new();
    for &pd in &devices {
        let props = unsafe { instance.get_physical_device_properties(pd) };
        let name = cstr(&props.device_name);
        if let Some(w) = wanted {
            if !name.to_lowercase().contains(&w.to_lowercase()) {
                continue;
            }
        }
        candidates.push((type_rank(props.device_type), pd, name));
    }
    if candidates.is_empty() {
        let available = devices
            .iter()
            .map(|&pd| cstr(&unsafe { instance.get_physical_device_properties(pd) }.device_name))
            .collect::<Vec<_>>()
            .join(", ");
        return Err(Error::DeviceNotFound {
            wanted: wanted.unwrap_or_default().to_string(),
            available,
        });
    }
    candidates.sort_by_key(|c| c.0);
    let mut reasons = Vec::new();
    for (_, pd, name) in candidates {
        match check_device(instance, pd, swapchain) {
            Ok(family) => return Ok((pd, family, device_info(instance, pd, family, validation))),
            Err(why) => reasons.push(format!("{name}: {why}")),
        }
    }
    Err(Error::Unsupported {
        device: "every device".into(),
        what: reasons.join("; "),
    })
}

/// Returns the queue family to use, or why the device does not qualify.
fn check_device(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    swapchain: bool,
) -> Result<u32, String> {
    let props = unsafe { instance.get_physical_device_properties(pd) };
    if props.api_version < vk::API_VERSION_1_3 {
        return Err(format!(
            "Vulkan {} < 1.3",
            version_string(props.api_version)
        ));
    }
    let exts =
        unsafe { instance.enumerate_device_extension_properties(pd) }.map_err(|e| e.to_string())?;
    if !exts
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::push_descriptor::NAME))
    {
        return Err("no VK_KHR_push_descriptor".into());
    }
    if swapchain
        && !exts
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::swapchain::NAME))
    {
        return Err("no VK_KHR_swapchain".into());
    }
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f12)
        .push_next(&mut f13);
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    if f13.synchronization2 == 0 || f13.dynamic_rendering == 0 || f12.host_query_reset == 0 {
        return Err("needs synchronization2, dynamicRendering and hostQueryReset".into());
    }
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let wanted = vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE;
    families
        .iter()
        .enumerate()
        .filter(|(_, f)| f.queue_flags.contains(wanted))
        .max_by_key(|(_, f)| f.timestamp_valid_bits)
        .map(|(i, _)| i as u32)
        .ok_or_else(|| "no graphics+compute queue".into())
}

fn device_info(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    family: u32,
    validation: bool,
) -> DeviceInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut p2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    unsafe { instance.get_physical_device_properties2(pd, &mut p2) };
    let props = p2.properties;
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let valid_bits = families
        .get(family as usize)
        .map_or(0, |f| f.timestamp_valid_bits);
    let mem = unsafe { instance.get_physical_device_memory_properties(pd) };
    let features = unsafe { instance.get_physical_device_features(pd) };
    let heaps = mem.memory_heaps[..mem.memory_heap_count as usize]
        .iter()
        .map(|h| MemoryHeap {
            size_bytes: h.size,
            device_local: h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL),
        })
        .collect();
    DeviceInfo {
        name: cstr(&props.device_name),
        device_type: type_name(props.device_type).into(),
        driver_name: cstr(&driver.driver_name),
        driver_info: cstr(&driver.driver_info),
        api_version: version_string(props.api_version),
        vendor_id: props.vendor_id,
        device_id: props.device_id,
        timestamps: valid_bits > 0 && props.limits.timestamp_compute_and_graphics != 0,
        timestamp_period_ns: props.limits.timestamp_period,
        timestamp_valid_bits: valid_bits,
        pipeline_statistics: features.pipeline_statistics_query != 0,
        calibrated_timestamps: false,
        max_image_dimension_2d: props.limits.max_image_dimension2_d,
        memory_heaps: heaps,
        validation,
    }
}

/// Whether the device offers `VK_EXT_calibrated_timestamps` with both the
/// device's and CLOCK_MONOTONIC's domains (std's `Instant` on Linux).
fn calibration_offered(
    entry: &ash::Entry,
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
) -> bool {
    let name = ash::ext::calibrated_timestamps::NAME;
    let offered = unsafe { instance.enumerate_device_extension_properties(pd) }
        .is_ok_and(|exts| exts.iter().any(|e| e.extension_name_as_c_str() == Ok(name)));
    if !offered {
        return false;
    }
    let ext = ash::ext::calibrated_timestamps::Instance::new(entry, instance);
    unsafe { ext.get_physical_device_calibrateable_time_domains(pd) }.is_ok_and(|d| {
        d.contains(&vk::TimeDomainEXT::DEVICE) && d.contains(&vk::TimeDomainEXT::CLOCK_MONOTONIC)
    })
}

fn create_device(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    family: u32,
    swapchain: bool,
    info: &DeviceInfo,
) -> Result<ash::Device> {
    let pipeline_statistics = info.pipeline_statistics;
    let priorities = [1.0];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(family)
        .queue_priorities(&priorities)];
    let mut extensions = vec![ash::khr::push_descriptor::NAME.as_ptr()];
    if swapchain {
        extensions.push(ash::khr::swapchain::NAME.as_ptr());
    }
    if info.calibrated_timestamps {
        extensions.push(ash::ext::calibrated_timestamps::NAME.as_ptr());
    }
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default().host_query_reset(true);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .dynamic_rendering(true);
    // Enabling the feature costs nothing until a query is begun.
    let features =
        vk::PhysicalDeviceFeatures::default().pipeline_statistics_query(pipeline_statistics);
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_features(&features)
        .enabled_extension_names(&extensions)
        .push_next(&mut f12)
        .push_next(&mut f13);
    unsafe { instance.create_device(pd, &info, None) }.vk("vkCreateDevice")
}
