//! The library's error type. Every fallible public function returns
//! [`Result`]; messages are one line and name the file, the feature or the
//! parameter at fault.

use std::path::PathBuf;

/// Everything that can go wrong in alpenglow, as one-line messages.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The Vulkan loader (libvulkan.so.1) could not be opened.
    #[error("cannot load the Vulkan loader: {0} (on Debian 12 run tools/install-vulkan-runtime.sh)")]
    Loader(String),
    /// No usable device, or a device lacks a required feature.
    #[error("{0}")]
    Device(String),
    /// A Vulkan call failed.
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan {
        call: &'static str,
        result: ash::vk::Result,
    },
    /// GPU memory allocation failed.
    #[error("GPU memory allocation failed for {what}: {message}")]
    Allocation { what: String, message: String },
    /// A compiled shader module is missing or malformed.
    #[error("shader {path}: {message}")]
    Shader { path: PathBuf, message: String },
    /// An input file could not be read or is malformed.
    #[error("{}: {message}", path.display())]
    Input { path: PathBuf, message: String },
    /// An output file could not be written.
    #[error("cannot write {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    /// A parameter (camera, size, option) is out of range.
    #[error("invalid {what}: {message}")]
    InvalidArgument { what: String, message: String },
    /// The render graph was declared inconsistently.
    #[error("render graph: {0}")]
    Graph(String),
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An input-file error naming the file.
    pub fn input(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        Error::Input {
            path: path.into(),
            message: message.to_string(),
        }
    }

    /// An output-file error naming the file.
    pub fn output(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        Error::Output {
            path: path.into(),
            message: message.to_string(),
        }
    }

    /// An invalid-argument error naming the parameter.
    pub fn invalid(what: impl Into<String>, message: impl std::fmt::Display) -> Self {
        Error::InvalidArgument {
            what: what.into(),
            message: message.to_string(),
        }
    }
}
