//! The Vulkan context: instance, validation, device, queue, allocator,
//! timeline semaphore, deferred destruction and the descriptor heap.
//!
//! [`Context`] is a cheap, cloneable handle; the GPU objects it owns are
//! destroyed when the last handle (and the last resource made from it) drops,
//! after the GPU is idle.

use std::ffi::{c_char, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::clock::GpuClock;
use super::device_select::{self, DeviceSelector, REQUIRED_FEATURES};
use super::features::OptionalFeatures;
use super::heap::DescriptorHeap;
use super::memory::Garbage;
use super::validation::{messenger_info, ValidationReport};
use crate::error::{Error, Result};

pub(super) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How to create a [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable the Khronos validation layer with synchronization validation.
    pub validation: bool,
    /// Which physical device to use.
    pub device: DeviceSelector,
}

/// What the chosen device is and what alpenglow uses of it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    pub name: String,
    pub device_type: String,
    pub vendor_id: u32,
    pub device_id: u32,
    pub driver_name: String,
    pub driver_info: String,
    pub api_version: String,
    pub index: usize,
    pub timestamp_period_ns: f32,
    pub max_image_dimension_2d: u32,
    /// Bytes of the largest device-local heap (its budget where
    /// `VK_EXT_memory_budget` is offered) and of the largest single
    /// allocation ([`Context::memory_limits`]).
    pub memory_heap_bytes: u64,
    pub max_allocation_bytes: u64,
    /// Whether `VK_EXT_memory_budget` is enabled.
    pub memory_budget: bool,
    /// Whether GPU timestamps are calibrated against the CPU clock
    /// (`VK_EXT_calibrated_timestamps` or `VK_KHR_calibrated_timestamps`).
    pub calibrated_timestamps: bool,
    /// Whether frames can be presented to a window (`VK_KHR_swapchain`
    /// and a surface extension of the loader).
    pub presentation: bool,
    pub features: Vec<String>,
    /// Optional features the device offers and alpenglow enabled.
    pub optional_features: Vec<String>,
    /// Largest point primitive side in pixels (1 without `largePoints`).
    pub max_point_size: f32,
    pub validation: bool,
}

pub(crate) struct Shared {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    /// The device's physical device (surface queries).
    pub physical: vk::PhysicalDevice,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    pub debug_device: Option<ash::ext::debug_utils::Device>,
    pub device: ash::Device,
    queue: Mutex<vk::Queue>,
    pub queue_family: u32,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    timeline: vk::Semaphore,
    last_submitted: AtomicU64,
    garbage: Mutex<Vec<(u64, Garbage)>>,
    pub heap: ManuallyDrop<DescriptorHeap>,
    pub info: DeviceInfo,
    pub limits: vk::PhysicalDeviceLimits,
    /// Heap and single-allocation limits ([`Context::memory_limits`]).
    pub(super) memory: super::device_memory::DeviceMemory,
    /// Reads the GPU and CPU clocks together, where the device can.
    pub(super) clock: Option<GpuClock>,
    report: Option<Arc<ValidationReport>>,
    /// SPIR-V that replaces embedded modules (feature `hot-reload`).
    pub(super) shader_overrides: super::shader_overrides::ShaderOverrides,
}

/// A Vulkan instance and device with everything alpenglow renders through.
#[derive(Clone)]
pub struct Context {
    pub(crate) shared: Arc<Shared>,
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Context")
            .field("device", &self.shared.info.name)
            .finish()
    }
}

/// The physical device `options` choose among the instance's.
fn select_device(instance: &ash::Instance, options: &ContextOptions) -> Result<device_select::Candidate> {
    // SAFETY: plain query on a live instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.map_err(vk_err("vkEnumeratePhysicalDevices"))?;
    let candidates = physicals
        .iter()
        .enumerate()
        .map(|(i, &p)| device_select::inspect(instance, p, i))
        .collect();
    device_select::choose(candidates, &options.device)
}

/// Creates the logical device of `candidate` with one graphics+compute
/// queue, the required features (Vulkan 1.2 descriptor indexing and
/// timeline semaphores, 1.3 dynamic rendering and synchronization2) and
/// the optional ones it offers (and the extensions of memory budgets and
/// calibrated timestamps where offered).
fn open_device(entry: &ash::Entry, instance: &ash::Instance, candidate: device_select::Candidate) -> Result<Opened> {
    let priorities = [1.0f32];
    let queue_infos = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(candidate.queue_family.unwrap_or(0))
        .queue_priorities(&priorities)];
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default()
        .timeline_semaphore(true)
        .descriptor_indexing(true)
        .runtime_descriptor_array(true)
        .descriptor_binding_partially_bound(true)
        .descriptor_binding_sampled_image_update_after_bind(true)
        .descriptor_binding_storage_image_update_after_bind(true)
        .descriptor_binding_storage_buffer_update_after_bind(true)
        .shader_sampled_image_array_non_uniform_indexing(true)
        .shader_storage_image_array_non_uniform_indexing(true)
        .shader_storage_buffer_array_non_uniform_indexing(true);
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default()
        .dynamic_rendering(true)
        .synchronization2(true)
        .maintenance4(true);
    let optional = OptionalFeatures::offered(instance, candidate.physical);
    let base = optional.base();
    v12 = v12.shader_buffer_int64_atomics(optional.shader_buffer_int64_atomics);
    let mut interlock =
        vk::PhysicalDeviceFragmentShaderInterlockFeaturesEXT::default().fragment_shader_pixel_interlock(true);
    let memory_budget = super::device_memory::offers_memory_budget(instance, candidate.physical);
    let mut extensions = Vec::new();
    if optional.fragment_shader_pixel_interlock {
        extensions.push(ash::ext::fragment_shader_interlock::NAME.as_ptr());
    }
    if memory_budget {
        extensions.push(ash::ext::memory_budget::NAME.as_ptr());
    }
    let calibration = super::clock::offered(entry, instance, candidate.physical);
    if let Some(name) = calibration {
        extensions.push(name.as_ptr());
    }
    let presentation = super::present::offers_swapchain(instance, candidate.physical);
    if presentation {
        extensions.push(ash::khr::swapchain::NAME.as_ptr());
    }
    let mut device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_infos)
        .enabled_features(&base)
        .enabled_extension_names(&extensions)
        .push_next(&mut v12)
        .push_next(&mut v13);
    if optional.fragment_shader_pixel_interlock {
        device_info = device_info.push_next(&mut interlock);
    }
    // SAFETY: the features were checked as supported by `inspect`; pointers are to locals.
    let device =
        unsafe { instance.create_device(candidate.physical, &device_info, None) }.map_err(vk_err("vkCreateDevice"))?;
    Ok(Opened {
        candidate,
        device,
        optional,
        memory_budget,
        calibration,
        presentation,
    })
}

/// What [`open_device`] opened.
struct Opened {
    candidate: device_select::Candidate,
    device: ash::Device,
    optional: OptionalFeatures,
    /// Whether `VK_EXT_memory_budget` is enabled.
    memory_budget: bool,
    /// The calibrated-timestamps extension enabled, if any.
    calibration: Option<&'static CStr>,
    /// Whether `VK_KHR_swapchain` is enabled.
    presentation: bool,
}

/// What [`Context::info`] reports of the device opened from `candidate`.
fn describe_device(
    candidate: &device_select::Candidate,
    optional: &OptionalFeatures,
    memory: &super::device_memory::DeviceMemory,
    memory_budget: bool,
    validation: bool,
) -> DeviceInfo {
    let props = &candidate.properties;
    DeviceInfo {
        name: candidate.name.clone(),
        device_type: device_select::device_type_name(candidate.device_type).into(),
        vendor_id: props.vendor_id,
        device_id: props.device_id,
        driver_name: candidate.driver_name.clone(),
        driver_info: candidate.driver_info.clone(),
        api_version: format!(
            "{}.{}.{}",
            vk::api_version_major(props.api_version),
            vk::api_version_minor(props.api_version),
            vk::api_version_patch(props.api_version)
        ),
        index: candidate.index,
        timestamp_period_ns: props.limits.timestamp_period,
        max_image_dimension_2d: props.limits.max_image_dimension2_d,
        memory_heap_bytes: memory.heap,
        max_allocation_bytes: memory.allocation,
        memory_budget,
        calibrated_timestamps: false,
        presentation: false,
        features: REQUIRED_FEATURES.iter().map(|s| s.to_string()).collect(),
        optional_features: optional.names(),
        max_point_size: if optional.large_points {
            props.limits.point_size_range[1]
        } else {
            1.0
        },
        validation,
    }
}

pub(crate) fn vk_err(call: &'static str) -> impl Fn(vk::Result) -> Error {
    move |result| Error::Vulkan { call, result }
}

impl Context {
    /// Creates the instance (with validation when asked) and the device.
    pub fn new(options: &ContextOptions) -> Result<Self> {
        // SAFETY: loading libvulkan.so.1 runs its initialisers; the loader is a
        // well-behaved shared library.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        // SAFETY: plain queries with no external state.
        // The loader fails to list the layers when a manifest it finds is
        // malformed (reported as a host allocation failure). Layers are only
        // needed for validation: without it go on with none; with it, say
        // that the validation layer could not be loaded, and where from.
        let layers = match unsafe { entry.enumerate_instance_layer_properties() } {
            Ok(layers) => layers,
            Err(_) if !options.validation => Vec::new(),
            Err(result) => {
                return Err(super::validation::layer_error(
                    "vkEnumerateInstanceLayerProperties",
                    result,
                ))
            }
        };
        let layer_version = layers
            .iter()
            .find(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER))
            .map(|l| l.spec_version)
            .unwrap_or(0);
        let report = options
            .validation
            .then(|| Arc::new(ValidationReport::for_layer(layer_version)));
        let has_layer = |name: &CStr| layers.iter().any(|l| l.layer_name_as_c_str().ok() == Some(name));
        // SAFETY: as above.
        let extensions = unsafe { entry.enumerate_instance_extension_properties(None) }
            .map_err(vk_err("vkEnumerateInstanceExtensionProperties"))?;
        let has_debug_utils = extensions
            .iter()
            .any(|e| e.extension_name_as_c_str().ok() == Some(ash::ext::debug_utils::NAME));

        let mut layer_names: Vec<*const c_char> = Vec::new();
        let mut extension_names: Vec<*const c_char> = Vec::new();
        if options.validation {
            if !has_layer(VALIDATION_LAYER) {
                return Err(Error::Device(
                    "validation requested but VK_LAYER_KHRONOS_validation is not installed \
                     (apt install vulkan-validationlayers, or run tools/install-vulkan-runtime.sh)"
                        .into(),
                ));
            }
            layer_names.push(VALIDATION_LAYER.as_ptr());
            extension_names.push(ash::ext::validation_features::NAME.as_ptr());
        }
        // Windows (the viewer, `alpenglow view`): every surface extension the
        // loader offers, so a swapchain can be made on any window later
        // (harmless headless: nothing is created until a window asks).
        extension_names.extend(super::present::surface_extensions(&extensions));
        let debug_utils = has_debug_utils || options.validation;
        if debug_utils {
            extension_names.push(ash::ext::debug_utils::NAME.as_ptr());
        }

        let app = vk::ApplicationInfo::default()
            .application_name(c"alpenglow")
            .engine_name(c"alpenglow")
            .api_version(vk::API_VERSION_1_3);
        let enabled_validation = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_validation);
        let mut messenger_create = report.as_deref().map(messenger_info);
        let mut instance_info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layer_names)
            .enabled_extension_names(&extension_names);
        if let Some(messenger_create) = messenger_create.as_mut() {
            instance_info = instance_info
                .push_next(messenger_create)
                .push_next(&mut validation_features);
        }
        // SAFETY: every pointer in the create info refers to locals that outlive the call.
        let instance = unsafe { entry.create_instance(&instance_info, None) }
            .map_err(|e| super::validation::instance_error(e, options.validation))?;

        let debug_instance = debug_utils.then(|| ash::ext::debug_utils::Instance::new(&entry, &instance));
        let messenger = match (&debug_instance, report.as_deref()) {
            (Some(debug), Some(report)) => {
                // SAFETY: the report outlives the messenger (Shared keeps the Arc).
                unsafe { debug.create_debug_utils_messenger(&messenger_info(report), None) }
                    .map_err(vk_err("vkCreateDebugUtilsMessengerEXT"))?
            }
            _ => vk::DebugUtilsMessengerEXT::null(),
        };

        Self::create_device(entry, instance, debug_instance, messenger, report, options)
    }

    fn create_device(
        entry: ash::Entry,
        instance: ash::Instance,
        debug_instance: Option<ash::ext::debug_utils::Instance>,
        messenger: vk::DebugUtilsMessengerEXT,
        report: Option<Arc<ValidationReport>>,
        options: &ContextOptions,
    ) -> Result<Self> {
        let destroy_instance = |instance: &ash::Instance| {
            // SAFETY: nothing else was created from the instance yet but the messenger.
            unsafe {
                if let Some(debug) = &debug_instance {
                    if messenger != vk::DebugUtilsMessengerEXT::null() {
                        debug.destroy_debug_utils_messenger(messenger, None);
                    }
                }
                instance.destroy_instance(None);
            }
        };
        let opened = select_device(&instance, options).and_then(|c| open_device(&entry, &instance, c));
        let Opened {
            candidate,
            device,
            optional,
            memory_budget,
            calibration,
            presentation,
        } = match opened {
            Ok(opened) => opened,
            Err(e) => {
                destroy_instance(&instance);
                return Err(e);
            }
        };
        let queue_family = candidate.queue_family.unwrap_or(0);
        // SAFETY: the queue family and index were requested at device creation.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let debug_device = debug_instance
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: candidate.physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| Error::Allocation {
            what: "allocator".into(),
            message: e.to_string(),
        })?;

        let mut timeline_type = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let semaphore_info = vk::SemaphoreCreateInfo::default().push_next(&mut timeline_type);
        // SAFETY: valid device; timeline semaphores were enabled.
        let timeline =
            unsafe { device.create_semaphore(&semaphore_info, None) }.map_err(vk_err("vkCreateSemaphore"))?;
        let heap = DescriptorHeap::new(&device)?;

        let memory = super::device_memory::query(&instance, candidate.physical, memory_budget);
        let clock = calibration
            .and_then(|name| GpuClock::new(&instance, &device, name, candidate.properties.limits.timestamp_period));
        let mut info = describe_device(&candidate, &optional, &memory, memory_budget, report.is_some());
        info.calibrated_timestamps = clock.is_some();
        info.presentation = presentation;
        let shared = Shared {
            entry,
            instance,
            physical: candidate.physical,
            debug_instance,
            messenger,
            debug_device,
            device,
            queue: Mutex::new(queue),
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            timeline,
            last_submitted: AtomicU64::new(0),
            garbage: Mutex::new(Vec::new()),
            heap: ManuallyDrop::new(heap),
            info,
            limits: candidate.properties.limits,
            memory,
            clock,
            report,
            shader_overrides: Default::default(),
        };
        log::info!("device: {} ({})", shared.info.name, shared.info.driver_info);
        Ok(Context {
            shared: Arc::new(shared),
        })
    }

    /// The chosen device and the features in use.
    pub fn info(&self) -> &DeviceInfo {
        &self.shared.info
    }

    /// Whether the device is a CPU (`VK_PHYSICAL_DEVICE_TYPE_CPU`: lavapipe,
    /// llvmpipe, SwiftShader), for techniques whose fastest form differs on one.
    pub(crate) fn is_cpu(&self) -> bool {
        self.shared.info.device_type == device_select::device_type_name(vk::PhysicalDeviceType::CPU)
    }

    /// Alignment of a storage-buffer range's offset
    /// (`minStorageBufferOffsetAlignment`).
    pub fn storage_buffer_alignment(&self) -> u64 {
        self.shared.limits.min_storage_buffer_offset_alignment.max(1)
    }

    /// The validation report of this instance (None without validation).
    pub fn validation_report(&self) -> Option<Arc<ValidationReport>> {
        self.shared.report.clone()
    }

    /// Whether the optional feature `name` (as in [`DeviceInfo::optional_features`]) is enabled.
    pub fn has_feature(&self, name: &str) -> bool {
        self.shared.info.optional_features.iter().any(|f| f == name)
    }

    /// Device memory in use by this context's allocations, in bytes (what
    /// the allocator handed out, not the blocks it reserved).
    pub fn allocated_bytes(&self) -> u64 {
        match self.shared.allocator.lock() {
            Ok(allocator) => allocator.generate_report().total_allocated_bytes,
            Err(_) => 0,
        }
    }

    /// The largest 2-D image side the device accepts.
    pub fn max_image_dimension(&self) -> u32 {
        self.shared.limits.max_image_dimension2_d
    }

    /// The most bytes one storage-buffer binding may span
    /// (`maxStorageBufferRange`; 128 MiB on lavapipe).
    pub fn max_storage_buffer_range(&self) -> u64 {
        u64::from(self.shared.limits.max_storage_buffer_range)
    }

    /// Submits `command_buffer`, signalling the timeline; returns the value
    /// that marks its completion.
    pub(crate) fn submit(&self, command_buffer: vk::CommandBuffer) -> Result<u64> {
        self.submit_presenting(command_buffer, None)
    }

    /// [`Context::submit`] of a frame that draws into a swapchain image:
    /// it waits for the image's acquisition and signals that it may be
    /// presented (`present`).
    pub(crate) fn submit_presenting(
        &self,
        command_buffer: vk::CommandBuffer,
        present: Option<&super::present::PresentSync>,
    ) -> Result<u64> {
        let queue = self
            .shared
            .queue
            .lock()
            .map_err(|_| Error::Device("queue lock poisoned".into()))?;
        let value = self.shared.last_submitted.load(Ordering::SeqCst) + 1;
        let timeline = vk::SemaphoreSubmitInfo::default()
            .semaphore(self.shared.timeline)
            .value(value)
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS);
        // On the stack: a frame's submission allocates nothing.
        let (mut signal, mut wait) = ([timeline; 2], [vk::SemaphoreSubmitInfo::default()]);
        let (signals, waits) = match present {
            Some(p) => {
                // The swapchain image is first written by a transfer or an attachment.
                wait[0] = vk::SemaphoreSubmitInfo::default().semaphore(p.acquired).stage_mask(
                    vk::PipelineStageFlags2::ALL_TRANSFER | vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                );
                signal[1] = vk::SemaphoreSubmitInfo::default()
                    .semaphore(p.rendered)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS);
                (2, 1)
            }
            None => (1, 0),
        };
        let buffers = [vk::CommandBufferSubmitInfo::default().command_buffer(command_buffer)];
        let submit = vk::SubmitInfo2::default()
            .wait_semaphore_infos(&wait[..waits])
            .command_buffer_infos(&buffers)
            .signal_semaphore_infos(&signal[..signals]);
        // SAFETY: the queue is externally synchronised by the mutex; the command
        // buffer is fully recorded and not in use by another submission; the
        // binary semaphores are unsignalled (acquire signals, present waits).
        unsafe { self.shared.device.queue_submit2(*queue, &[submit], vk::Fence::null()) }
            .map_err(vk_err("vkQueueSubmit2"))?;
        self.shared.last_submitted.store(value, Ordering::SeqCst);
        Ok(value)
    }

    /// Runs `f` with the queue, locked (presentation).
    pub(crate) fn with_queue<T>(&self, f: impl FnOnce(vk::Queue) -> T) -> Result<T> {
        let queue = self
            .shared
            .queue
            .lock()
            .map_err(|_| Error::Device("queue lock poisoned".into()))?;
        Ok(f(*queue))
    }

    /// The timeline value of the last submission.
    pub(crate) fn last_submitted(&self) -> u64 {
        self.shared.last_submitted.load(Ordering::SeqCst)
    }

    /// The timeline value the GPU has completed.
    pub(crate) fn completed(&self) -> Result<u64> {
        // SAFETY: the semaphore is a live timeline semaphore of this device.
        unsafe { self.shared.device.get_semaphore_counter_value(self.shared.timeline) }
            .map_err(vk_err("vkGetSemaphoreCounterValue"))
    }

    /// Blocks until the GPU has completed timeline value `value`, then frees
    /// what was waiting on it.
    pub fn wait(&self, value: u64) -> Result<()> {
        if value > 0 {
            let semaphores = [self.shared.timeline];
            let values = [value];
            let info = vk::SemaphoreWaitInfo::default().semaphores(&semaphores).values(&values);
            // SAFETY: waiting on a live timeline semaphore with a value that was submitted.
            unsafe { self.shared.device.wait_semaphores(&info, u64::MAX) }.map_err(vk_err("vkWaitSemaphores"))?;
        }
        self.collect_garbage()
    }

    /// Blocks until every submission so far has completed.
    pub fn wait_idle(&self) -> Result<()> {
        self.wait(self.last_submitted())
    }

    /// Queues an object for destruction once the GPU has finished every
    /// submission made so far.
    pub(crate) fn defer_destroy(&self, garbage: Garbage) {
        let value = self.last_submitted();
        if let Ok(mut list) = self.shared.garbage.lock() {
            list.push((value, garbage));
        }
    }

    /// Destroys deferred objects whose last possible use has completed, and
    /// releases descriptor handles likewise.
    pub(crate) fn collect_garbage(&self) -> Result<()> {
        let done = self.completed()?;
        let ready: Vec<Garbage> = {
            let mut list = self
                .shared
                .garbage
                .lock()
                .map_err(|_| Error::Device("garbage lock poisoned".into()))?;
            if !list.iter().any(|(v, _)| *v <= done) {
                // Nothing to destroy: leave the list (and its memory) alone.
                drop(list);
                self.shared.heap.recycle(done);
                return Ok(());
            }
            let (ready, waiting): (Vec<_>, Vec<_>) = list.drain(..).partition(|(v, _)| *v <= done);
            *list = waiting;
            ready.into_iter().map(|(_, g)| g).collect()
        };
        for garbage in ready {
            garbage.destroy(&self.shared);
        }
        self.shared.heap.recycle(done);
        Ok(())
    }

    /// Names a Vulkan object for RenderDoc, Nsight and validation messages.
    pub(crate) fn name_object<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(debug) = &self.shared.debug_device {
            if let Ok(name) = std::ffi::CString::new(name) {
                let info = vk::DebugUtilsObjectNameInfoEXT::default()
                    .object_handle(handle)
                    .object_name(&name);
                // SAFETY: the handle belongs to this device; the name outlives the call.
                let _ = unsafe { debug.set_debug_utils_object_name(&info) };
            }
        }
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        // SAFETY: this is the last reference to the device: every resource made
        // from it has been dropped (they hold the Arc). We wait for the GPU, then
        // destroy children before parents: garbage, heap, allocator, semaphore,
        // device, messenger, instance.
        unsafe {
            let _ = self.device.device_wait_idle();
            let garbage: Vec<_> = self.garbage.get_mut().map(std::mem::take).unwrap_or_default();
            for (_, g) in garbage {
                g.destroy(self);
            }
            ManuallyDrop::take(&mut self.heap).destroy(&self.device);
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_semaphore(self.timeline, None);
            self.device.destroy_device(None);
            if let Some(debug) = &self.debug_instance {
                if self.messenger != vk::DebugUtilsMessengerEXT::null() {
                    debug.destroy_debug_utils_messenger(self.messenger, None);
                }
            }
            self.instance.destroy_instance(None);
        }
    }
}
