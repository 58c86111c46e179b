//! Khronos validation layer messages: logged, counted, kept for tests.

use ash::vk;
use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

/// Validation messages of warning or error severity in this process, every
/// context together: `main` fails the run when it is not zero (README, exit status).
static PROCESS_MESSAGES: AtomicU32 = AtomicU32::new(0);

/// How many validation messages of warning or error severity this process has had.
pub fn validation_messages() -> u32 {
    PROCESS_MESSAGES.load(Ordering::SeqCst)
}

/// Test-only: with validation on, `DERMIS_TEST_VALIDATION_MESSAGE=TEXT` makes the
/// context submit TEXT as an error message through the layer's messenger, so that
/// the tests can check a message fails the run.
pub(crate) const TEST_MESSAGE_VAR: &str = "DERMIS_TEST_VALIDATION_MESSAGE";

/// Everything the validation layer said of warning or error severity.
#[derive(Default, Debug)]
pub struct ValidationLog {
    errors: AtomicU32,
    warnings: AtomicU32,
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn errors(&self) -> u32 {
        self.errors.load(Ordering::SeqCst)
    }
    pub fn warnings(&self) -> u32 {
        self.warnings.load(Ordering::SeqCst)
    }
    /// Warnings plus errors: what tests require to be zero.
    pub fn count(&self) -> u32 {
        self.errors() + self.warnings()
    }
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        PROCESS_MESSAGES.fetch_add(1, Ordering::SeqCst);
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            self.errors.fetch_add(1, Ordering::SeqCst);
            log::error!("[validation] {text}");
        } else {
            self.warnings.fetch_add(1, Ordering::SeqCst);
            log::warn!("[validation] {text}");
        }
        if let Ok(mut m) = self.messages.lock() {
            m.push(text);
        }
    }
}

/// Messenger settings: warnings and errors of every type go to [`callback`].
pub(crate) fn messenger_info(log: &ValidationLog) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(callback))
        .user_data(log as *const ValidationLog as *mut c_void)
}

unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the `ValidationLog` owned by the context, which outlives the
    // messenger; `data` is valid for the duration of the call (Vulkan spec).
    let (log, data) = unsafe { (&*(user as *const ValidationLog), &*data) };
    let text = if data.p_message.is_null() {
        String::from("(no message)")
    } else {
        unsafe { CStr::from_ptr(data.p_message) }
            .to_string_lossy()
            .into_owned()
    };
    log.record(severity, text);
    vk::FALSE
}
