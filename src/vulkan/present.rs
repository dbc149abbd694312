//! Presentation to a window: a surface and its swapchain, whose images the
//! render graph imports one frame at a time (the viewer, `alpenglow view`).
//! The window is the caller's (any `raw-window-handle` window: winit's, a
//! simulator's); the surface comes from `ash-window`, the Vulkan project's
//! own crate for it.

use std::ffi::{c_char, CStr};
use std::sync::Arc;

use ash::vk;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};

use super::context::{vk_err, Context};
use super::frames::FRAMES_IN_FLIGHT;
use super::image::{Image, ImageDesc};
use crate::error::{Error, Result};

/// The window-system extensions of the instance: `VK_KHR_surface` and
/// every platform's surface extension among `offered` (none without
/// `VK_KHR_surface`).
pub(crate) fn surface_extensions(offered: &[vk::ExtensionProperties]) -> Vec<*const c_char> {
    let has = |name: &CStr| offered.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
    if !has(ash::khr::surface::NAME) {
        return Vec::new();
    }
    let platforms = [
        ash::khr::xlib_surface::NAME,
        ash::khr::xcb_surface::NAME,
        ash::khr::wayland_surface::NAME,
        ash::khr::win32_surface::NAME,
        ash::ext::metal_surface::NAME,
    ];
    std::iter::once(ash::khr::surface::NAME)
        .chain(platforms.into_iter().filter(|p| has(p)))
        .map(CStr::as_ptr)
        .collect()
}

/// Whether `physical` offers `VK_KHR_swapchain`.
pub(crate) fn offers_swapchain(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    // SAFETY: plain query on a physical device of this instance.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    (extensions.iter()).any(|e| e.extension_name_as_c_str() == Ok(ash::khr::swapchain::NAME))
}

/// The binary semaphores of a frame drawn into a swapchain image: the
/// frame waits for `acquired` and signals `rendered`, which the
/// presentation waits for.
#[derive(Clone, Copy, Debug)]
pub struct PresentSync {
    pub(crate) acquired: vk::Semaphore,
    pub(crate) rendered: vk::Semaphore,
}

/// A swapchain image acquired for a frame.
pub struct AcquiredImage {
    index: u32,
    /// The image (its layout is undefined: the frame overwrites it).
    pub image: Arc<Image>,
    pub sync: PresentSync,
}

/// A window's surface and swapchain. FIFO presentation (vsync) unless
/// asked otherwise and offered; the image size follows
/// [`Swapchain::resize`]; a minimised (0×0) window presents nothing.
pub struct Swapchain {
    ctx: Context,
    surface_fn: ash::khr::surface::Instance,
    swapchain_fn: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    raw: vk::SwapchainKHR,
    images: Vec<Arc<Image>>,
    /// Signalled by each frame's submission, waited by its presentation:
    /// one per image (an image is re-acquired only after its presentation).
    rendered: Vec<vk::Semaphore>,
    /// Signalled by acquisition, one per frame slot (the slot's previous
    /// frame, which waited on it, has completed when the slot is reused).
    acquired: Vec<vk::Semaphore>,
    format: vk::SurfaceFormatKHR,
    extent: (u32, u32),
    /// The window's size in pixels.
    wanted: (u32, u32),
    vsync: bool,
    /// Out of date or suboptimal: recreate before the next acquisition.
    stale: bool,
}

impl Swapchain {
    /// A surface on `window` and a swapchain of `width`×`height` images
    /// (the window's size in pixels). Errors name what the device lacks.
    pub fn new(
        ctx: &Context,
        window: &(impl HasDisplayHandle + HasWindowHandle),
        (width, height): (u32, u32),
        vsync: bool,
    ) -> Result<Swapchain> {
        if !ctx.info().presentation {
            return Err(Error::Device(
                "the device cannot present to a window (VK_KHR_swapchain or VK_KHR_surface missing)".into(),
            ));
        }
        let handle_error = |e: raw_window_handle::HandleError| Error::Device(format!("window handle: {e}"));
        let display = window.display_handle().map_err(handle_error)?.as_raw();
        let window = window.window_handle().map_err(handle_error)?.as_raw();
        let shared = &ctx.shared;
        // SAFETY: the handles are of a live window (borrowed for this call);
        // the instance enabled every surface extension the loader offers.
        let surface = unsafe { ash_window::create_surface(&shared.entry, &shared.instance, display, window, None) }
            .map_err(|e| match e {
                vk::Result::ERROR_EXTENSION_NOT_PRESENT => {
                    Error::Device("the Vulkan loader offers no surface extension for this window system".into())
                }
                e => vk_err("vkCreate*SurfaceKHR")(e),
            })?;
        let surface_fn = ash::khr::surface::Instance::new(&shared.entry, &shared.instance);
        // SAFETY: plain query; the queue family exists.
        let supported =
            unsafe { surface_fn.get_physical_device_surface_support(shared.physical, shared.queue_family, surface) };
        if !supported.unwrap_or(false) {
            // SAFETY: the surface was just created and is unused.
            unsafe { surface_fn.destroy_surface(surface, None) };
            return Err(Error::Device(format!(
                "{}'s queue cannot present to this window",
                ctx.info().name
            )));
        }
        let mut swapchain = Swapchain {
            ctx: ctx.clone(),
            swapchain_fn: ash::khr::swapchain::Device::new(&shared.instance, &shared.device),
            surface_fn,
            surface,
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            rendered: Vec::new(),
            acquired: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            extent: (0, 0),
            wanted: (width, height),
            vsync,
            stale: true,
        };
        for _ in 0..FRAMES_IN_FLIGHT {
            let semaphore = swapchain.semaphore()?;
            swapchain.acquired.push(semaphore);
        }
        swapchain.recreate()?;
        Ok(swapchain)
    }

    /// The window is now `width`×`height` pixels (0 when minimised): the
    /// swapchain is recreated before the next frame.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) != self.wanted {
            self.wanted = (width, height);
            self.stale = true;
        }
    }

    /// Whether the window is minimised (0 pixels wide or high): nothing
    /// is presented until it is restored.
    pub fn is_minimised(&self) -> bool {
        self.wanted.0 == 0 || self.wanted.1 == 0
    }

    /// The images' size in pixels.
    pub fn extent(&self) -> (u32, u32) {
        self.extent
    }

    /// The images' format (B8G8R8A8 or R8G8B8A8, UNORM where offered: the
    /// frame's display image is already sRGB-encoded).
    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    fn semaphore(&self) -> Result<vk::Semaphore> {
        // SAFETY: valid create info on a live device.
        unsafe { (self.ctx.shared.device).create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
            .map_err(vk_err("vkCreateSemaphore"))
    }

    /// Acquires the next image for frame `frame` (call after the frame's
    /// slot was waited for); None while the window is minimised.
    pub fn acquire(&mut self, frame: u64) -> Result<Option<AcquiredImage>> {
        for _ in 0..3 {
            if self.stale && !self.recreate()? {
                return Ok(None);
            }
            let acquired = self.acquired[frame as usize % self.acquired.len()];
            // SAFETY: the swapchain is live; the semaphore is unsignalled (its
            // last wait, by this slot's previous frame, has completed).
            let result =
                unsafe { (self.swapchain_fn).acquire_next_image(self.raw, u64::MAX, acquired, vk::Fence::null()) };
            match result {
                Ok((index, suboptimal)) => {
                    self.stale |= suboptimal;
                    return Ok(Some(AcquiredImage {
                        index,
                        image: self.images[index as usize].clone(),
                        sync: PresentSync {
                            acquired,
                            rendered: self.rendered[index as usize],
                        },
                    }));
                }
                Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.stale = true,
                Err(e) => return Err(vk_err("vkAcquireNextImageKHR")(e)),
            }
        }
        Err(Error::Device("the swapchain stays out of date after recreation".into()))
    }

    /// Presents `image` once its frame (submitted before) is done.
    pub fn present(&mut self, image: AcquiredImage) -> Result<()> {
        let waits = [image.sync.rendered];
        let swapchains = [self.raw];
        let indices = [image.index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        let swapchain_fn = &self.swapchain_fn;
        // SAFETY: the queue is locked; the image was acquired from this
        // swapchain and its frame, which signals `rendered`, was submitted.
        let result = self
            .ctx
            .with_queue(|queue| unsafe { swapchain_fn.queue_present(queue, &info) })?;
        match result {
            Ok(suboptimal) => self.stale |= suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.stale = true,
            Err(e) => return Err(vk_err("vkQueuePresentKHR")(e)),
        }
        Ok(())
    }

    /// Recreates the swapchain at the window's size; false while it is
    /// 0×0 (minimised).
    fn recreate(&mut self) -> Result<bool> {
        let shared = &self.ctx.shared;
        // SAFETY: plain queries on a live surface.
        let caps = unsafe { (self.surface_fn).get_physical_device_surface_capabilities(shared.physical, self.surface) }
            .map_err(vk_err("vkGetPhysicalDeviceSurfaceCapabilitiesKHR"))?;
        let extent = match caps.current_extent.width {
            u32::MAX => vk::Extent2D {
                width: self
                    .wanted
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: self
                    .wanted
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            },
            _ => caps.current_extent,
        };
        if extent.width == 0 || extent.height == 0 || self.wanted.0 == 0 || self.wanted.1 == 0 {
            return Ok(false);
        }
        // SAFETY: as above.
        let formats = unsafe { (self.surface_fn).get_physical_device_surface_formats(shared.physical, self.surface) }
            .map_err(vk_err("vkGetPhysicalDeviceSurfaceFormatsKHR"))?;
        // SAFETY: as above.
        let modes =
            unsafe { (self.surface_fn).get_physical_device_surface_present_modes(shared.physical, self.surface) }
                .map_err(vk_err("vkGetPhysicalDeviceSurfacePresentModesKHR"))?;
        self.format = choose_format(&formats)?;
        let mode = match self.vsync {
            false if modes.contains(&vk::PresentModeKHR::MAILBOX) => vk::PresentModeKHR::MAILBOX,
            false if modes.contains(&vk::PresentModeKHR::IMMEDIATE) => vk::PresentModeKHR::IMMEDIATE,
            _ => vk::PresentModeKHR::FIFO,
        };
        let usage = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(Error::Device(
                "the window's swapchain images cannot be transfer destinations and colour attachments".into(),
            ));
        }
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        // The old swapchain's images may still be in flight or presented.
        self.wait_queue_idle()?;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(mode)
            .clipped(true)
            .old_swapchain(self.raw);
        // SAFETY: valid create info; the old swapchain (if any) is retired by it.
        let raw = unsafe { self.swapchain_fn.create_swapchain(&info, None) }.map_err(vk_err("vkCreateSwapchainKHR"))?;
        self.destroy_swapchain();
        self.raw = raw;
        // SAFETY: the swapchain was just created.
        let images =
            unsafe { self.swapchain_fn.get_swapchain_images(raw) }.map_err(vk_err("vkGetSwapchainImagesKHR"))?;
        for (k, image) in images.into_iter().enumerate() {
            let desc = ImageDesc {
                name: format!("swapchain image {k}"),
                width: extent.width,
                height: extent.height,
                format: self.format.format,
                usage,
            };
            self.images
                .push(Arc::new(Image::from_swapchain(&self.ctx, image, desc)?));
            let semaphore = self.semaphore()?;
            self.rendered.push(semaphore);
        }
        self.extent = (extent.width, extent.height);
        self.stale = false;
        log::debug!(
            "swapchain: {}×{} {:?}, {:?}, {} images",
            extent.width,
            extent.height,
            self.format.format,
            mode,
            self.images.len()
        );
        Ok(true)
    }

    /// Waits for every frame and presentation (the timeline does not track
    /// presentation).
    fn wait_queue_idle(&self) -> Result<()> {
        self.ctx.wait_idle()?;
        let device = &self.ctx.shared.device;
        // SAFETY: the queue is locked while waited for.
        (self.ctx)
            .with_queue(|q| unsafe { device.queue_wait_idle(q) })?
            .map_err(vk_err("vkQueueWaitIdle"))
    }

    /// Destroys the swapchain, its image views and per-image semaphores
    /// (the device is idle: [`Swapchain::recreate`] and drop wait for it).
    fn destroy_swapchain(&mut self) {
        self.images.clear();
        let _ = self.ctx.collect_garbage();
        let device = &self.ctx.shared.device;
        for semaphore in self.rendered.drain(..) {
            // SAFETY: the device is idle: no submission or presentation uses it.
            unsafe { device.destroy_semaphore(semaphore, None) };
        }
        if self.raw != vk::SwapchainKHR::null() {
            // SAFETY: the device is idle and the views of its images are gone.
            unsafe { self.swapchain_fn.destroy_swapchain(self.raw, None) };
            self.raw = vk::SwapchainKHR::null();
        }
    }
}

/// An 8-bit UNORM format with the sRGB colour space (the display image is
/// sRGB-encoded already), else the first offered.
fn choose_format(formats: &[vk::SurfaceFormatKHR]) -> Result<vk::SurfaceFormatKHR> {
    let wanted = [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM];
    (formats.iter())
        .find(|f| wanted.contains(&f.format) && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        .or_else(|| formats.first())
        .copied()
        .ok_or_else(|| Error::Device("the window's surface offers no format".into()))
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        let _ = self.wait_queue_idle();
        self.destroy_swapchain();
        let device = &self.ctx.shared.device;
        for semaphore in self.acquired.drain(..) {
            // SAFETY: the queue is idle.
            unsafe { device.destroy_semaphore(semaphore, None) };
        }
        // SAFETY: the swapchain made on it is destroyed.
        unsafe { self.surface_fn.destroy_surface(self.surface, None) };
    }
}
