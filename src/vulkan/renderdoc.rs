//! RenderDoc's in-application API (the `renderdoc` crate): frame captures
//! of a headless run, delimited by the application, or of the next
//! presented frame. Front door: `alpenglow::tools::renderdoc`.
//!
//! The library is never loaded behind the caller's back:
//! [`RenderDocCapture::attach`] finds it only when the process already runs
//! under RenderDoc (`renderdoccmd capture`, qrenderdoc's launcher), and
//! [`RenderDocCapture::load`] opens it on request (`--renderdoc [PATH]`).
//! Its only `unsafe` is that load: opening a shared library runs its
//! initialisers.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// The option a caller names in errors about a fresh load.
const FEATURE: &str = "RenderDoc";

/// Where [`RenderDocCapture::load`] looks without a path: the dynamic
/// linker's search path first (the file name alone), then the usual
/// install places (Debian's `renderdoc` package puts it in /usr/lib).
#[cfg(not(windows))]
const CANDIDATES: &[&str] = &[
    "librenderdoc.so",
    "/usr/lib/librenderdoc.so",
    "/usr/lib/x86_64-linux-gnu/librenderdoc.so",
    "/usr/lib/renderdoc/librenderdoc.so",
    "/usr/local/lib/librenderdoc.so",
    "/opt/renderdoc/lib/librenderdoc.so",
];
#[cfg(windows)]
const CANDIDATES: &[&str] = &["renderdoc.dll", "C:\\Program Files\\RenderDoc\\renderdoc.dll"];

/// RenderDoc's in-application API, attached to the RenderDoc library of
/// this process.
///
/// Headless runs delimit their frames themselves: [`start_frame`] before a
/// frame's first submission, [`end_frame`] after its last, and the capture
/// is written when the frame ends. Windowed programs can instead
/// [`trigger_capture`]: RenderDoc captures the next presented frame.
///
/// [`start_frame`]: RenderDocCapture::start_frame
/// [`end_frame`]: RenderDocCapture::end_frame
/// [`trigger_capture`]: RenderDocCapture::trigger_capture
///
/// ```no_run
/// use alpenglow::tools::renderdoc::RenderDocCapture;
/// // Before the first Context: a freshly loaded RenderDoc hooks Vulkan
/// // instances created after it.
/// let mut rdoc = match RenderDocCapture::attach() {
///     Some(rdoc) => rdoc,
///     None => RenderDocCapture::load(None)?,
/// };
/// rdoc.set_capture_path_template("captures/terrain".as_ref())?;
/// let ctx = alpenglow::Context::new(&alpenglow::ContextOptions::default())?;
/// // … create a renderer, then around one frame:
/// rdoc.start_frame();
/// // renderer.render(&camera)?;
/// let capture = rdoc.end_frame()?;
/// println!("RenderDoc capture: {}", capture.display());
/// # Ok::<(), alpenglow::Error>(())
/// ```
pub struct RenderDocCapture {
    api: backend::Api,
    /// The library file when this process loaded it ([`RenderDocCapture::load`]).
    library: Option<PathBuf>,
}

impl std::fmt::Debug for RenderDocCapture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderDocCapture")
            .field("library", &self.library)
            .field("api_version", &self.api_version())
            .finish()
    }
}

impl RenderDocCapture {
    /// The API of the RenderDoc library already loaded in this process
    /// (running under `renderdoccmd capture` or qrenderdoc); None when
    /// there is none. Never loads the library.
    pub fn attach() -> Option<RenderDocCapture> {
        let api = backend::attach().ok()?;
        Some(RenderDocCapture { api, library: None })
    }

    /// Loads RenderDoc's library, from `path` or (None) from the dynamic
    /// linker's search path and the usual install places, unless it is
    /// already loaded. Call it before the first [`Context`](crate::Context):
    /// RenderDoc hooks the Vulkan instances created after it (through its
    /// Vulkan layer, which its package registers). Errors name the file or
    /// say where RenderDoc was looked for.
    pub fn load(path: Option<&Path>) -> Result<RenderDocCapture> {
        if let Some(found) = RenderDocCapture::attach() {
            return Ok(found);
        }
        let library = match path {
            Some(path) => {
                if !path.is_file() {
                    return Err(Error::input(path, "no such RenderDoc library (librenderdoc.so)"));
                }
                backend::open_library(path).map_err(|e| Error::input(path, e))?;
                path.to_path_buf()
            }
            None => CANDIDATES
                .iter()
                .map(Path::new)
                .find(|p| backend::open_library(p).is_ok())
                .ok_or_else(|| {
                    Error::Device(format!(
                        "{FEATURE}: its library was not found (looked for {}); install RenderDoc \
                         (Debian: apt-get install renderdoc) or give its path",
                        CANDIDATES.join(", ")
                    ))
                })?
                .to_path_buf(),
        };
        let api = backend::attach().map_err(|e| Error::input(&library, format!("not RenderDoc's library: {e}")))?;
        Ok(RenderDocCapture {
            api,
            library: Some(library),
        })
    }

    /// The library this process loaded through [`RenderDocCapture::load`];
    /// None when RenderDoc was already there (injected by its launcher).
    pub fn loaded_library(&self) -> Option<&Path> {
        self.library.as_deref()
    }

    /// RenderDoc's in-application API version (major, minor, patch).
    pub fn api_version(&self) -> (u32, u32, u32) {
        backend::api_version(&self.api)
    }

    /// Where captures go: RenderDoc names them `TEMPLATE_frameN.rdc`.
    /// Relative templates are relative to the working directory. An error
    /// for a template that is not UTF-8 or holds a NUL (RenderDoc takes a
    /// C string).
    pub fn set_capture_path_template(&mut self, template: &Path) -> Result<()> {
        match template.to_str() {
            Some(t) if !t.is_empty() && !t.contains('\0') => {
                backend::set_template(&mut self.api, t);
                Ok(())
            }
            _ => Err(Error::invalid(
                "RenderDoc capture path template",
                format!("{} is empty, not UTF-8 or holds a NUL", template.display()),
            )),
        }
    }

    /// The capture path template in use (`renderdoccmd capture -c` sets it).
    pub fn capture_path_template(&self) -> Option<PathBuf> {
        backend::template(&self.api)
    }

    /// Starts capturing: every Vulkan call until [`RenderDocCapture::end_frame`]
    /// goes into the capture (the device of the process: one device and no
    /// window, as in a headless run).
    pub fn start_frame(&mut self) {
        backend::start(&mut self.api);
    }

    /// Whether a capture is under way.
    pub fn is_capturing(&self) -> bool {
        backend::is_capturing(&self.api)
    }

    /// Ends the capture [`RenderDocCapture::start_frame`] started and
    /// returns the file RenderDoc wrote. An error when RenderDoc wrote
    /// none (no capture under way, or no Vulkan device RenderDoc hooks: a
    /// library loaded after the Vulkan instance was created).
    pub fn end_frame(&mut self) -> Result<PathBuf> {
        let before = backend::captures(&self.api);
        let capturing = backend::is_capturing(&self.api);
        backend::end(&mut self.api);
        if backend::captures(&self.api) > before {
            if let Some(path) = self.latest_capture() {
                return Ok(path);
            }
        }
        Err(Error::Device(format!(
            "{FEATURE}: no capture was written ({}); was RenderDoc loaded before the Vulkan instance was created?",
            if capturing {
                "RenderDoc saw no device to capture"
            } else {
                "no capture was under way"
            }
        )))
    }

    /// Ends the capture under way without writing it; false when there was none.
    pub fn discard_frame(&mut self) -> bool {
        backend::discard(&mut self.api)
    }

    /// Captures the next presented frame (windowed programs: a key such as
    /// F11); [`RenderDocCapture::latest_capture`] names the file once the
    /// frame was presented.
    ///
    /// ```no_run
    /// # let mut rdoc = alpenglow::tools::renderdoc::RenderDocCapture::attach().unwrap();
    /// // On the capture key:
    /// let before = rdoc.captures();
    /// rdoc.trigger_capture();
    /// // … render and present a frame, then:
    /// if rdoc.captures() > before {
    ///     println!("RenderDoc capture: {:?}", rdoc.latest_capture());
    /// }
    /// ```
    pub fn trigger_capture(&mut self) {
        backend::trigger(&mut self.api);
    }

    /// Turns RenderDoc's own capture keys (F12 and Print Screen by
    /// default) off, for a program whose keys they would shadow; captures
    /// then come from [`RenderDocCapture::trigger_capture`] only.
    pub fn disable_capture_keys(&mut self) {
        backend::disable_keys(&mut self.api);
    }

    /// How many captures RenderDoc wrote in this process.
    pub fn captures(&self) -> u32 {
        backend::captures(&self.api)
    }

    /// The last capture RenderDoc wrote in this process.
    pub fn latest_capture(&self) -> Option<PathBuf> {
        let n = backend::captures(&self.api);
        n.checked_sub(1).and_then(|i| backend::capture(&self.api, i))
    }
}

/// The `renderdoc` crate where it builds (not on Apple platforms).
#[cfg(not(any(target_os = "macos", target_os = "ios")))]
mod backend {
    use std::path::{Path, PathBuf};

    use renderdoc::{RenderDoc, V141};

    pub type Api = RenderDoc<V141>;

    /// Opens the shared library `path` for good (RenderDoc hooks the
    /// process: it is never unloaded); [`attach`] then finds it.
    pub fn open_library(path: &Path) -> Result<(), String> {
        // SAFETY: opening a library runs its initialisers; the callers open
        // only RenderDoc's library (the file the user named, or its usual
        // places), whose initialisers install its hooks and nothing else.
        let library = unsafe { libloading::Library::new(path) }.map_err(|e| e.to_string())?;
        std::mem::forget(library);
        Ok(())
    }

    /// RenderDoc's API from the library loaded in this process (the crate
    /// opens it with `RTLD_NOLOAD`: never a fresh load).
    pub fn attach() -> Result<Api, renderdoc::Error> {
        RenderDoc::new()
    }

    pub fn api_version(api: &Api) -> (u32, u32, u32) {
        api.get_api_version()
    }

    pub fn set_template(api: &mut Api, template: &str) {
        api.set_capture_file_path_template(template);
    }

    pub fn template(api: &Api) -> Option<PathBuf> {
        // The crate panics on a template that is not UTF-8.
        std::panic::catch_unwind(|| api.get_capture_file_path_template().to_path_buf()).ok()
    }

    /// Null device and window: RenderDoc's wildcard (the one device).
    pub fn start(api: &mut Api) {
        api.start_frame_capture(std::ptr::null(), std::ptr::null());
    }

    pub fn end(api: &mut Api) {
        api.end_frame_capture(std::ptr::null(), std::ptr::null());
    }

    pub fn discard(api: &mut Api) -> bool {
        api.discard_frame_capture(std::ptr::null(), std::ptr::null())
    }

    pub fn is_capturing(api: &Api) -> bool {
        api.is_frame_capturing()
    }

    pub fn trigger(api: &mut Api) {
        api.trigger_capture();
    }

    pub fn disable_keys(api: &mut Api) {
        api.set_capture_keys::<renderdoc::InputButton>(&[]);
    }

    pub fn captures(api: &Api) -> u32 {
        api.get_num_captures()
    }

    pub fn capture(api: &Api, index: u32) -> Option<PathBuf> {
        // The crate panics on a capture path that is not UTF-8.
        std::panic::catch_unwind(|| api.get_capture(index).map(|(path, _)| path))
            .ok()
            .flatten()
    }
}

/// No RenderDoc on Apple platforms: never attached.
#[cfg(any(target_os = "macos", target_os = "ios"))]
mod backend {
    use std::path::{Path, PathBuf};

    pub enum Api {}

    pub fn open_library(_: &Path) -> Result<(), String> {
        Err("RenderDoc does not run on Apple platforms".into())
    }

    pub fn attach() -> Result<Api, &'static str> {
        Err("RenderDoc does not run on Apple platforms")
    }
    pub fn api_version(api: &Api) -> (u32, u32, u32) {
        match *api {}
    }
    pub fn set_template(api: &mut Api, _: &str) {
        match *api {}
    }
    pub fn template(api: &Api) -> Option<PathBuf> {
        match *api {}
    }
    pub fn start(api: &mut Api) {
        match *api {}
    }
    pub fn end(api: &mut Api) {
        match *api {}
    }
    pub fn discard(api: &mut Api) -> bool {
        match *api {}
    }
    pub fn is_capturing(api: &Api) -> bool {
        match *api {}
    }
    pub fn trigger(api: &mut Api) {
        match *api {}
    }
    pub fn disable_keys(api: &mut Api) {
        match *api {}
    }
    pub fn captures(api: &Api) -> u32 {
        match *api {}
    }
    pub fn capture(api: &Api, _: u32) -> Option<PathBuf> {
        match *api {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_library_file_is_an_error_naming_it() {
        if RenderDocCapture::attach().is_some() {
            return; // under RenderDoc: load() returns the attached library
        }
        let e = RenderDocCapture::load(Some(Path::new("/nonexistent/librenderdoc.so"))).unwrap_err();
        let line = e.to_string();
        assert!(line.contains("/nonexistent/librenderdoc.so"), "{line}");
        assert!(!line.contains('\n'), "{line}");
    }

    #[test]
    fn a_file_that_is_not_a_library_is_an_error_naming_it() {
        if RenderDocCapture::attach().is_some() {
            return;
        }
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
        let line = RenderDocCapture::load(Some(&path)).unwrap_err().to_string();
        assert!(line.contains("Cargo.toml"), "{line}");
        assert!(!line.contains('\n'), "{line}");
    }
}
