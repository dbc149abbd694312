//! SPIR-V that replaces embedded modules by name when pipelines are
//! created: what hot reload (`crate::hot_reload`, feature `hot-reload`)
//! installs. Without the feature the table is empty and costs nothing.

use std::borrow::Cow;

use super::context::Context;
use super::pipeline::SpirV;

#[cfg(not(feature = "hot-reload"))]
pub(crate) use none::ShaderOverrides;
#[cfg(feature = "hot-reload")]
pub(crate) use table::ShaderOverrides;

impl Context {
    /// The bytes a pipeline is built from: the module installed for its
    /// name, else the embedded one.
    pub(super) fn shader_bytes(&self, spirv: &SpirV) -> Cow<'static, [u8]> {
        self.shared.shader_overrides.bytes(spirv)
    }
}

#[cfg(not(feature = "hot-reload"))]
mod none {
    use std::borrow::Cow;

    use super::SpirV;

    /// Nothing to hold without the feature.
    #[derive(Default)]
    pub(crate) struct ShaderOverrides;

    impl ShaderOverrides {
        pub(super) fn bytes(&self, spirv: &SpirV) -> Cow<'static, [u8]> {
            Cow::Borrowed(spirv.bytes)
        }
    }
}

#[cfg(feature = "hot-reload")]
mod table {
    use std::borrow::Cow;
    use std::collections::HashMap;
    use std::sync::RwLock;

    use super::{Context, SpirV};

    /// Module name (a [`SpirV::name`], `post/tonemap.comp`) → its SPIR-V.
    #[derive(Default)]
    pub(crate) struct ShaderOverrides(RwLock<HashMap<String, Vec<u8>>>);

    impl ShaderOverrides {
        pub(super) fn bytes(&self, spirv: &SpirV) -> Cow<'static, [u8]> {
            let table = self.0.read().unwrap_or_else(|e| e.into_inner());
            match table.get(spirv.name) {
                Some(bytes) => Cow::Owned(bytes.clone()),
                None => Cow::Borrowed(spirv.bytes),
            }
        }
    }

    impl Context {
        /// Pipelines created from now on of each module named (a
        /// [`SpirV::name`]: its path under `glsl/`) use the SPIR-V given
        /// instead of the embedded one; pipelines already built keep theirs.
        pub(crate) fn override_shaders(&self, modules: impl IntoIterator<Item = (String, Vec<u8>)>) {
            let mut table = self
                .shared
                .shader_overrides
                .0
                .write()
                .unwrap_or_else(|e| e.into_inner());
            table.extend(modules);
        }
    }
}
