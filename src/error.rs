//! The library's error type. Every fallible public function returns
//! [`Result`]; messages are one line and name the file, the feature or the
//! parameter at fault.

use std::path::PathBuf;

/// Everything that can go wrong in alpenglow, as one-line messages.
///
/// Non-exhaustive: later versions may add variants.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
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
    #[error("invalid {parameter}: {message}")]
    InvalidArgument {
        /// The library's name of the parameter: a field path of the
        /// settings it belongs to where there is one, e.g. `width`,
        /// `camera.fov_y_deg`, `terrain.grid_side`, `points.epsilon`;
        /// otherwise a short description ("texture atlas", a file name).
        /// Front ends map these names to their own (the CLI to its flags).
        parameter: String,
        /// What is wrong with it, one line.
        message: String,
    },
    /// The render graph was declared inconsistently.
    #[error("render graph: {0}")]
    Graph(String),
}

/// `text` with line breaks and other control characters escaped (`\n`), so
/// that a message quoting user input (a rig's view name, a file's value)
/// stays on one line.
fn single_line(text: String) -> String {
    if !text.chars().any(char::is_control) {
        return text;
    }
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// `text` as it may be printed or logged: control characters (line
/// breaks, escape sequences that would drive the terminal) escaped as
/// `\n`, `\u{1b}`. For user-supplied names (layers, views) in anything
/// that reaches a terminal; [`Error`]'s constructors do the same.
pub fn printable(text: &str) -> String {
    single_line(text.to_string())
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An input-file error naming the file.
    pub fn input(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        Error::Input {
            path: path.into(),
            message: single_line(message.to_string()),
        }
    }

    /// An output-file error naming the file.
    pub fn output(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        Error::Output {
            path: path.into(),
            message: single_line(message.to_string()),
        }
    }

    /// An invalid-argument error naming the parameter (see
    /// [`Error::InvalidArgument`] for how parameters are named).
    pub fn invalid(parameter: impl Into<String>, message: impl std::fmt::Display) -> Self {
        Error::InvalidArgument {
            parameter: parameter.into(),
            message: single_line(message.to_string()),
        }
    }

    /// The parameter an [`Error::InvalidArgument`] names; None for every
    /// other error.
    pub fn parameter(&self) -> Option<&str> {
        match self {
            Error::InvalidArgument { parameter, .. } => Some(parameter),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_names_its_parameter() {
        let e = Error::invalid("camera.fov_y_deg", "0 degrees; must be in (0, 180)");
        assert_eq!(e.parameter(), Some("camera.fov_y_deg"));
        assert_eq!(
            e.to_string(),
            "invalid camera.fov_y_deg: 0 degrees; must be in (0, 180)"
        );
        assert_eq!(Error::input("a.png", "truncated").parameter(), None);
    }

    /// Quoted user input cannot break a message onto two lines (the fuzz
    /// suite found a rig view named "fr\nt").
    #[test]
    fn messages_stay_on_one_line() {
        let e = Error::invalid("view.name", "'fr\nt'; use letters");
        assert_eq!(e.to_string(), "invalid view.name: 'fr\\nt'; use letters");
        assert!(!Error::input("a.toml", "x\r\ny\u{1b}")
            .to_string()
            .contains(['\n', '\r', '\u{1b}']));
        assert!(!Error::output("a.png", "two\nlines").to_string().contains('\n'));
    }
}
