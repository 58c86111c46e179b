//! One error type for the library; `main` maps [`Error::exit_code`] to the process status.

use ash::vk;

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Hint printed whenever no Vulkan implementation can be found.
pub const DRIVER_HINT: &str = "install a Vulkan driver; on a machine without a GPU use Mesa's \
     lavapipe (Debian/Ubuntu: apt-get install mesa-vulkan-drivers)";

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("no Vulkan loader (libvulkan.so.1) could be opened: {0}; install libvulkan1 and {DRIVER_HINT}", DRIVER_HINT = DRIVER_HINT)]
    NoLoader(String),
    #[error("no Vulkan device found; {DRIVER_HINT}", DRIVER_HINT = DRIVER_HINT)]
    NoDevice,
    #[error("no Vulkan device name contains {wanted:?}; available: {available}")]
    DeviceNotFound { wanted: String, available: String },
    #[error("validation was requested but VK_LAYER_KHRONOS_validation is not installed (Debian/Ubuntu: apt-get install vulkan-validationlayers)")]
    NoValidationLayer,
    #[error("device {device} cannot run dermis: {what}")]
    Unsupported { device: String, what: String },
    #[error("{call} failed: {result}")]
    Vk {
        call: &'static str,
        result: vk::Result,
    },
    #[error("GPU memory allocation for {name} failed: {source}")]
    Alloc {
        name: String,
        source: gpu_allocator::AllocationError,
    },
    #[error("render graph: {0}")]
    Graph(String),
    /// No display, no window, no surface the device can present to.
    #[error("window system: {0}")]
    Window(String),
    /// Bad user input (files, sizes, options): exit status 2.
    #[error("{0}")]
    Input(String),
    /// Bad input found by a higher layer's loader (scene file, mesh, texture,
    /// environment map), as its own typed error; those layers convert into it.
    #[error(transparent)]
    BadInput(Box<dyn std::error::Error + Send + Sync>),
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}

impl Error {
    /// Process exit status: 2 for bad input, 1 for everything else.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input(_)
            | Error::Io { .. }
            | Error::DeviceNotFound { .. }
            | Error::BadInput(_) => 2,
            _ => 1,
        }
    }
}

/// Attaches the name of the Vulkan call to a raw `vk::Result`.
pub trait VkResultExt<T> {
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkResultExt<T> for std::result::Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| Error::Vk { call, result })
    }
}
