//! Khronos validation: the debug-utils messenger and its per-instance counts.
//!
//! The messenger's `p_user_data` points at the [`ValidationReport`] of the
//! instance that created it, so several instances in one process (as
//! `cargo test` runs them, one per thread) never mix their counts.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use ash::vk;

/// Counts and keeps the validation messages reported to one instance.
#[derive(Debug, Default)]
pub struct ValidationReport {
    errors: AtomicU64,
    warnings: AtomicU64,
    messages: Mutex<Vec<String>>,
}

impl ValidationReport {
    /// Validation errors reported so far.
    pub fn errors(&self) -> u64 {
        self.errors.load(Ordering::SeqCst)
    }

    /// Validation warnings (including performance warnings) reported so far.
    pub fn warnings(&self) -> u64 {
        self.warnings.load(Ordering::SeqCst)
    }

    /// Errors plus warnings.
    pub fn total(&self) -> u64 {
        self.errors() + self.warnings()
    }

    /// The text of every error and warning, in the order reported.
    pub fn messages(&self) -> Vec<String> {
        self.messages.lock().map(|m| m.clone()).unwrap_or_default()
    }

    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: String) {
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            self.errors.fetch_add(1, Ordering::SeqCst);
            log::error!("validation: {text}");
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            self.warnings.fetch_add(1, Ordering::SeqCst);
            log::warn!("validation: {text}");
        } else {
            log::debug!("vulkan: {text}");
            return;
        }
        if let Ok(mut messages) = self.messages.lock() {
            messages.push(text);
        }
    }
}

/// The messenger create-info that reports into `report`. The report must
/// outlive the messenger (the context keeps an `Arc` to it).
pub(crate) fn messenger_info(report: &ValidationReport) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(report as *const ValidationReport as *mut std::ffi::c_void)
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut std::ffi::c_void,
) -> vk::Bool32 {
    // SAFETY: the loader passes valid callback data for the duration of the call,
    // and `user_data` is the `ValidationReport` the context keeps alive for as long
    // as the messenger exists.
    unsafe {
        if data.is_null() || user_data.is_null() {
            return vk::FALSE;
        }
        let report = &*(user_data as *const ValidationReport);
        let text = (*data)
            .message_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        // Loader chatter ("Inserted device layer", ICD search) is INFO and not counted.
        report.record(severity, text);
    }
    vk::FALSE
}
