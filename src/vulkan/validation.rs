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
    set_aside: AtomicU64,
    /// Set aside synchronization-validation reports on descriptors of runtime
    /// descriptor arrays (see [`ValidationReport::for_layer`]).
    set_aside_bindless_hazards: bool,
    messages: Mutex<Vec<String>>,
}

/// The first Khronos validation layer release (SDK 1.3.268) that no longer
/// reports hazards for every element of a runtime descriptor array a shader
/// could index (KhronosGroup/Vulkan-ValidationLayers#3450, fixed by #6605).
pub const BINDLESS_SYNCVAL_FIX: u32 = ash::vk::make_api_version(0, 1, 3, 268);

impl ValidationReport {
    /// A report for a validation layer whose spec version is `layer_version`.
    ///
    /// Layers before `BINDLESS_SYNCVAL_FIX` treat every descriptor of a bound
    /// runtime array as accessed by every draw and dispatch, so a bindless heap
    /// produces hazards on resources the shader never touches. Those reports
    /// (and only those: they name a descriptor binding and index) are counted
    /// in [`ValidationReport::set_aside`] instead of as errors, which is what
    /// newer layers do by not reporting them. Attachment, vertex, index, copy
    /// and layout-transition hazards are still errors; the graph's barrier
    /// derivation is unit-tested independently (src/graph/access.rs).
    pub fn for_layer(layer_version: u32) -> Self {
        ValidationReport {
            set_aside_bindless_hazards: layer_version < BINDLESS_SYNCVAL_FIX,
            ..Default::default()
        }
    }

    /// Synchronization reports on bindless descriptor-array elements that were
    /// set aside as known false positives of old layers.
    pub fn set_aside(&self) -> u64 {
        self.set_aside.load(Ordering::SeqCst)
    }

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

    /// Counts a message (allocating only for those kept: errors and warnings).
    fn record(&self, severity: vk::DebugUtilsMessageSeverityFlagsEXT, text: &str) {
        if self.set_aside_bindless_hazards && is_descriptor_array_hazard(text) {
            self.set_aside.fetch_add(1, Ordering::SeqCst);
            log::debug!("validation (set aside, layer bug #3450): {text}");
            return;
        }
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
            messages.push(text.to_string());
        }
    }
}

/// Whether `text` is a synchronization hazard reported on an element of a
/// descriptor array (the layer names the descriptor type, binding and index).
fn is_descriptor_array_hazard(text: &str) -> bool {
    text.contains("SYNC-HAZARD")
        && text.contains("VkDescriptorSet")
        && text.contains(", type: VK_DESCRIPTOR_TYPE_")
        && text.contains("binding #")
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
        // Borrowed unless the message is not UTF-8: the layers' per-draw
        // messages (INFO, the set-aside hazards) allocate nothing.
        let text = (*data)
            .message_as_c_str()
            .map(|s| s.to_string_lossy())
            .unwrap_or_default();
        // Loader chatter ("Inserted device layer", ICD search) is INFO and not counted.
        report.record(severity, &text);
    }
    vk::FALSE
}

/// The layer search paths the user set (`VK_LAYER_PATH`,
/// `VK_ADD_LAYER_PATH`), as `NAME=VALUE`.
pub(super) fn layer_paths() -> Vec<String> {
    ["VK_LAYER_PATH", "VK_ADD_LAYER_PATH"]
        .iter()
        .filter_map(|v| std::env::var_os(v).map(|p| format!("{v}={}", p.to_string_lossy())))
        .collect()
}

/// The validation layer could not be loaded: `call` failed with `result`.
/// Names the layer search path the user set, where a broken manifest or
/// library usually is.
pub(super) fn layer_error(call: &str, result: vk::Result) -> crate::error::Error {
    let set = layer_paths();
    let hint = match set.is_empty() {
        true => "check the installed layer manifests (tools/install-vulkan-runtime.sh)".to_string(),
        false => format!(
            "check the layer manifests (.json) and libraries under {}",
            set.join(" and ")
        ),
    };
    crate::error::Error::Device(crate::error::printable(&format!(
        "validation requested but the validation layer {} could not be loaded ({call}: {result}); {hint}",
        super::context::VALIDATION_LAYER.to_string_lossy()
    )))
}

/// The error of a failed `vkCreateInstance` (`validation`: the validation
/// layer was asked for): a missing driver, a layer that could not be loaded,
/// a malformed manifest under the layer path the user set (the loader
/// reports it as a host allocation failure), or the plain Vulkan error.
pub(super) fn instance_error(result: vk::Result, validation: bool) -> crate::error::Error {
    use crate::error::Error;
    match result {
        vk::Result::ERROR_INCOMPATIBLE_DRIVER => {
            Error::Device("no Vulkan 1.3 driver found (run tools/install-vulkan-runtime.sh)".into())
        }
        vk::Result::ERROR_OUT_OF_HOST_MEMORY if !layer_paths().is_empty() => {
            Error::Device(crate::error::printable(&format!(
                "vkCreateInstance failed ({result}) while the loader read the layer manifests under {}; \
                 one is probably malformed",
                layer_paths().join(" and ")
            )))
        }
        vk::Result::ERROR_LAYER_NOT_PRESENT
        | vk::Result::ERROR_EXTENSION_NOT_PRESENT
        | vk::Result::ERROR_INITIALIZATION_FAILED
            if validation =>
        {
            layer_error("vkCreateInstance", result)
        }
        other => Error::Vulkan {
            call: "vkCreateInstance",
            result: other,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BINDLESS: &str = "Validation Error: [ SYNC-HAZARD-WRITE-AFTER-WRITE ] Object 0: handle = 0x26, \
        name = hdr radiance, type = VK_OBJECT_TYPE_IMAGE_VIEW; | vkCmdDispatch: Hazard WRITE_AFTER_WRITE for \
        VkImageView 0x26[hdr radiance], in VkCommandBuffer 0x5[frame slot 0], and VkPipeline 0x1d[post/tonemap.comp], \
        VkDescriptorSet 0x5[], type: VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, imageLayout: VK_IMAGE_LAYOUT_GENERAL, binding #1, index 0.";
    const ATTACHMENT: &str = "Validation Error: [ SYNC-HAZARD-WRITE-AFTER-WRITE ] vkCmdBeginRendering: Hazard \
        WRITE_AFTER_WRITE vs. layout transition in subpass 0 for attachment 0 color aspect";

    #[test]
    fn old_layers_set_aside_only_descriptor_array_hazards() {
        let report = ValidationReport::for_layer(vk::make_api_version(0, 1, 3, 239));
        report.record(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR, BINDLESS);
        assert_eq!((report.errors(), report.set_aside()), (0, 1));
        report.record(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR, ATTACHMENT);
        assert_eq!((report.errors(), report.set_aside()), (1, 1));
    }

    #[test]
    fn fixed_layers_count_everything() {
        let report = ValidationReport::for_layer(BINDLESS_SYNCVAL_FIX);
        report.record(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR, BINDLESS);
        report.record(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING, "a warning");
        assert_eq!((report.errors(), report.warnings(), report.set_aside()), (1, 1, 0));
    }
}
