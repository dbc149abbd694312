//! The optional device features alpenglow enables when they are offered.

use ash::vk;

/// Features alpenglow uses when the device has them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OptionalFeatures {
    /// `largePoints`: point primitives wider than one pixel (splat point primitives, §10.3).
    pub large_points: bool,
    /// `vertexPipelineStoresAndAtomics`: the vertex stage counts the splats it draws.
    pub vertex_pipeline_stores_and_atomics: bool,
    /// `shaderInt64` and `shaderBufferInt64Atomics`: the compute path's
    /// visibility buffer (`terrain::visibility`) packs depth and id in one 64-bit word.
    pub shader_buffer_int64_atomics: bool,
    /// `fragmentShaderPixelInterlock` (VK_EXT_fragment_shader_interlock):
    /// the interlock backend of single-pass splatting (§10.4).
    pub fragment_shader_pixel_interlock: bool,
    /// `fragmentStoresAndAtomics`: fragment shaders write storage buffers
    /// (the interlock backend's pixel state).
    pub fragment_stores_and_atomics: bool,
    /// `pipelineStatisticsQuery`: per-pass pipeline statistics (`--pipeline-stats`).
    pub pipeline_statistics_query: bool,
    /// Subgroup vote, arithmetic and ballot operations in compute shaders
    /// (`VkPhysicalDeviceSubgroupProperties`; a property, nothing to
    /// enable): the compute backend of single-pass splatting (§10.4).
    pub subgroup_compute: bool,
}

/// The name [`OptionalFeatures::subgroup_compute`] has in
/// [`super::DeviceInfo::optional_features`].
pub const SUBGROUP_COMPUTE: &str = "subgroupVoteArithmeticBallot";

impl OptionalFeatures {
    /// The optional features `physical` offers.
    pub(super) fn offered(instance: &ash::Instance, physical: vk::PhysicalDevice) -> OptionalFeatures {
        // SAFETY: plain query on a physical device of this instance.
        let offered = unsafe { instance.get_physical_device_features(physical) };
        let (int64_atomics, pixel_interlock) = offered_single_pass_features(instance, physical);
        OptionalFeatures {
            large_points: offered.large_points == vk::TRUE,
            vertex_pipeline_stores_and_atomics: offered.vertex_pipeline_stores_and_atomics == vk::TRUE,
            shader_buffer_int64_atomics: offered.shader_int64 == vk::TRUE && int64_atomics,
            fragment_shader_pixel_interlock: pixel_interlock,
            fragment_stores_and_atomics: offered.fragment_stores_and_atomics == vk::TRUE,
            pipeline_statistics_query: offered.pipeline_statistics_query == vk::TRUE,
            subgroup_compute: offered_subgroup_compute(instance, physical),
        }
    }

    /// The core features to enable: the required `independentBlend` and these.
    pub(super) fn base(self) -> vk::PhysicalDeviceFeatures {
        vk::PhysicalDeviceFeatures::default()
            .independent_blend(true)
            .large_points(self.large_points)
            .vertex_pipeline_stores_and_atomics(self.vertex_pipeline_stores_and_atomics)
            .shader_int64(self.shader_buffer_int64_atomics)
            .fragment_stores_and_atomics(self.fragment_stores_and_atomics)
            .pipeline_statistics_query(self.pipeline_statistics_query)
    }

    pub(super) fn names(self) -> Vec<String> {
        [
            ("largePoints", self.large_points),
            (
                "vertexPipelineStoresAndAtomics",
                self.vertex_pipeline_stores_and_atomics,
            ),
            ("shaderBufferInt64Atomics", self.shader_buffer_int64_atomics),
            ("fragmentShaderPixelInterlock", self.fragment_shader_pixel_interlock),
            ("fragmentStoresAndAtomics", self.fragment_stores_and_atomics),
            ("pipelineStatisticsQuery", self.pipeline_statistics_query),
            (SUBGROUP_COMPUTE, self.subgroup_compute),
        ]
        .iter()
        .filter(|(_, on)| *on)
        .map(|(n, _)| n.to_string())
        .collect()
    }
}

/// What the device offers of `shaderBufferInt64Atomics` (the compute
/// path's visibility buffer) and of `fragmentShaderPixelInterlock` with its
/// extension VK_EXT_fragment_shader_interlock (single-pass splatting's
/// interlock backend, §10.4).
/// Whether compute shaders have subgroup vote, arithmetic and ballot
/// operations (Vulkan 1.1 guarantees only the basic ones).
fn offered_subgroup_compute(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
    // SAFETY: plain query on a physical device of this instance (Vulkan ≥ 1.1,
    // checked by `inspect`); the out-structs live across the call.
    unsafe { instance.get_physical_device_properties2(physical, &mut properties) };
    let needed = vk::SubgroupFeatureFlags::BASIC
        | vk::SubgroupFeatureFlags::VOTE
        | vk::SubgroupFeatureFlags::ARITHMETIC
        | vk::SubgroupFeatureFlags::BALLOT;
    subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE) && subgroup.supported_operations.contains(needed)
}

fn offered_single_pass_features(instance: &ash::Instance, physical: vk::PhysicalDevice) -> (bool, bool) {
    // SAFETY: plain query on a physical device of this instance.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    let has_interlock = extensions
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::fragment_shader_interlock::NAME));
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut interlock = vk::PhysicalDeviceFragmentShaderInterlockFeaturesEXT::default();
    let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut v12);
    if has_interlock {
        features2 = features2.push_next(&mut interlock);
    }
    // SAFETY: the device supports Vulkan 1.3 (checked by `inspect`); the
    // interlock struct is chained only when its extension is offered.
    unsafe { instance.get_physical_device_features2(physical, &mut features2) };
    (
        v12.shader_buffer_int64_atomics == vk::TRUE,
        has_interlock && interlock.fragment_shader_pixel_interlock == vk::TRUE,
    )
}
