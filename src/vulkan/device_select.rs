//! Physical-device choice and the features alpenglow requires.
//!
//! Order of preference: discrete GPU, integrated GPU, virtual GPU, CPU
//! (lavapipe), other; overridable by name (case-insensitive substring) or by
//! index in `vkEnumeratePhysicalDevices` order.

use std::ffi::CStr;

use ash::vk;

use crate::error::{Error, Result};

/// Which physical device to use.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DeviceSelector {
    /// The best device: discrete, then integrated, then CPU.
    #[default]
    Best,
    /// The device at this index of `vkEnumeratePhysicalDevices`.
    Index(usize),
    /// The first device whose name contains this text (case-insensitive).
    Name(String),
}

impl std::str::FromStr for DeviceSelector {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim();
        if s.is_empty() || s.eq_ignore_ascii_case("best") || s.eq_ignore_ascii_case("auto") {
            Ok(DeviceSelector::Best)
        } else if let Ok(index) = s.parse::<usize>() {
            Ok(DeviceSelector::Index(index))
        } else {
            Ok(DeviceSelector::Name(s.to_string()))
        }
    }
}

/// Everything about a candidate device that choosing one needs.
#[derive(Debug)]
pub(crate) struct Candidate {
    pub physical: vk::PhysicalDevice,
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    pub properties: vk::PhysicalDeviceProperties,
    pub driver_name: String,
    pub driver_info: String,
    pub driver_id: vk::DriverId,
    pub queue_family: Option<u32>,
    /// The first missing requirement, if any.
    pub missing: Option<String>,
}

fn type_rank(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

/// Human name of a device type.
pub fn device_type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
        vk::PhysicalDeviceType::CPU => "CPU",
        _ => "other",
    }
}

/// The features alpenglow enables, by the name the Vulkan spec gives them.
pub const REQUIRED_FEATURES: &[&str] = &[
    "Vulkan 1.3",
    "dynamicRendering",
    "synchronization2",
    "maintenance4",
    "timelineSemaphore",
    "descriptorIndexing",
    "runtimeDescriptorArray",
    "descriptorBindingPartiallyBound",
    "descriptorBindingSampledImageUpdateAfterBind",
    "descriptorBindingStorageImageUpdateAfterBind",
    "descriptorBindingStorageBufferUpdateAfterBind",
    "shaderSampledImageArrayNonUniformIndexing",
    "shaderStorageImageArrayNonUniformIndexing",
    "shaderStorageBufferArrayNonUniformIndexing",
    "independentBlend",
    "timestamp queries",
];

/// Inspects one device: properties, driver, queue family and the first
/// missing requirement.
pub(crate) fn inspect(instance: &ash::Instance, physical: vk::PhysicalDevice, index: usize) -> Candidate {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    // SAFETY: `physical` was returned by this instance; the out-structs live across the call.
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    let properties = props2.properties;
    let name = properties
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "unknown device".into());
    let driver_name = c_text(driver.driver_name_as_c_str());
    let driver_info = c_text(driver.driver_info_as_c_str());
    let driver_id = driver.driver_id;

    // SAFETY: as above.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let queue_family = families
        .iter()
        .position(|f| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                && f.timestamp_valid_bits > 0
        })
        .map(|i| i as u32);

    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut v12)
        .push_next(&mut v13);
    let missing = if properties.api_version < vk::API_VERSION_1_3 {
        Some(format!(
            "Vulkan 1.3 (the driver offers {}.{})",
            vk::api_version_major(properties.api_version),
            vk::api_version_minor(properties.api_version)
        ))
    } else {
        // SAFETY: the device supports Vulkan 1.3, so both feature structs are valid in the chain.
        unsafe { instance.get_physical_device_features2(physical, &mut features2) };
        // The ids AOV is an integer target beside blended float targets.
        let independent_blend = features2.features.independent_blend;
        let checks: [(&str, vk::Bool32); 14] = [
            ("dynamicRendering", v13.dynamic_rendering),
            ("synchronization2", v13.synchronization2),
            ("maintenance4", v13.maintenance4),
            ("timelineSemaphore", v12.timeline_semaphore),
            ("descriptorIndexing", v12.descriptor_indexing),
            ("runtimeDescriptorArray", v12.runtime_descriptor_array),
            (
                "descriptorBindingPartiallyBound",
                v12.descriptor_binding_partially_bound,
            ),
            (
                "descriptorBindingSampledImageUpdateAfterBind",
                v12.descriptor_binding_sampled_image_update_after_bind,
            ),
            (
                "descriptorBindingStorageImageUpdateAfterBind",
                v12.descriptor_binding_storage_image_update_after_bind,
            ),
            (
                "descriptorBindingStorageBufferUpdateAfterBind",
                v12.descriptor_binding_storage_buffer_update_after_bind,
            ),
            (
                "shaderSampledImageArrayNonUniformIndexing",
                v12.shader_sampled_image_array_non_uniform_indexing,
            ),
            (
                "shaderStorageImageArrayNonUniformIndexing",
                v12.shader_storage_image_array_non_uniform_indexing,
            ),
            (
                "shaderStorageBufferArrayNonUniformIndexing",
                v12.shader_storage_buffer_array_non_uniform_indexing,
            ),
            ("independentBlend", independent_blend),
        ];
        checks
            .iter()
            .find(|(_, supported)| *supported == vk::FALSE)
            .map(|(feature, _)| format!("feature {feature}"))
            .or_else(|| {
                queue_family
                    .is_none()
                    .then(|| "timestamp queries on a graphics+compute queue".into())
            })
    };
    Candidate {
        physical,
        index,
        name,
        device_type: properties.device_type,
        properties,
        driver_name,
        driver_info,
        driver_id,
        queue_family,
        missing,
    }
}

fn c_text(text: std::result::Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    text.map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The fix to suggest when `candidate` lacks a feature.
fn remedy(candidate: &Candidate) -> String {
    let lavapipe = candidate.driver_id == vk::DriverId::MESA_LLVMPIPE || candidate.name.contains("llvmpipe");
    if lavapipe {
        " — lavapipe needs Mesa >= 23 for it (on Debian 12: add bookworm-backports and \
         `apt install -t bookworm-backports mesa-vulkan-drivers`, or run tools/install-vulkan-runtime.sh)"
            .into()
    } else {
        " — update the GPU driver".into()
    }
}

/// Chooses a device according to `selector`; the error names the device and
/// the first feature it lacks.
pub(crate) fn choose(candidates: Vec<Candidate>, selector: &DeviceSelector) -> Result<Candidate> {
    if candidates.is_empty() {
        return Err(Error::Device(
            "no Vulkan device found (install a GPU driver, or lavapipe: tools/install-vulkan-runtime.sh)".into(),
        ));
    }
    let listing = || {
        candidates
            .iter()
            .map(|c| format!("{}: {}", c.index, c.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let chosen = match selector {
        DeviceSelector::Index(i) => match candidates.iter().position(|c| c.index == *i) {
            Some(pos) => pos,
            None => {
                return Err(Error::Device(format!(
                    "no Vulkan device with index {i} (devices: {})",
                    listing()
                )))
            }
        },
        DeviceSelector::Name(name) => {
            let needle = name.to_lowercase();
            match candidates.iter().position(|c| c.name.to_lowercase().contains(&needle)) {
                Some(pos) => pos,
                None => {
                    return Err(Error::Device(format!(
                        "no Vulkan device named like '{name}' (devices: {})",
                        listing()
                    )))
                }
            }
        }
        DeviceSelector::Best => {
            let mut order: Vec<usize> = (0..candidates.len()).collect();
            order.sort_by_key(|&i| (candidates[i].missing.is_some(), type_rank(candidates[i].device_type), i));
            order[0]
        }
    };
    let mut candidates = candidates;
    let candidate = candidates.swap_remove(chosen);
    if let Some(missing) = &candidate.missing {
        return Err(Error::Device(format!(
            "Vulkan device '{}' ({}) lacks {missing}{}",
            candidate.name,
            candidate.driver_info,
            remedy(&candidate)
        )));
    }
    Ok(candidate)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(index: usize, name: &str, device_type: vk::PhysicalDeviceType, missing: Option<&str>) -> Candidate {
        Candidate {
            physical: vk::PhysicalDevice::null(),
            index,
            name: name.into(),
            device_type,
            properties: vk::PhysicalDeviceProperties::default(),
            driver_name: "driver".into(),
            driver_info: "1.0".into(),
            driver_id: if name.contains("llvmpipe") {
                vk::DriverId::MESA_LLVMPIPE
            } else {
                vk::DriverId::NVIDIA_PROPRIETARY
            },
            queue_family: Some(0),
            missing: missing.map(String::from),
        }
    }

    #[test]
    fn prefers_discrete_then_integrated_then_cpu() {
        let pick = |list: Vec<Candidate>| choose(list, &DeviceSelector::Best).map(|c| c.name);
        let cpu = || candidate(0, "llvmpipe", vk::PhysicalDeviceType::CPU, None);
        let igpu = || candidate(1, "iGPU", vk::PhysicalDeviceType::INTEGRATED_GPU, None);
        let dgpu = || candidate(2, "dGPU", vk::PhysicalDeviceType::DISCRETE_GPU, None);
        assert_eq!(pick(vec![cpu(), igpu(), dgpu()]).unwrap(), "dGPU");
        assert_eq!(pick(vec![cpu(), igpu()]).unwrap(), "iGPU");
        assert_eq!(pick(vec![cpu()]).unwrap(), "llvmpipe");
        // A capable CPU device beats a discrete GPU that lacks a feature.
        let broken = candidate(
            2,
            "old dGPU",
            vk::PhysicalDeviceType::DISCRETE_GPU,
            Some("feature maintenance4"),
        );
        assert_eq!(pick(vec![broken, cpu()]).unwrap(), "llvmpipe");
    }

    #[test]
    fn selection_by_name_and_index() {
        let list = || {
            vec![
                candidate(0, "llvmpipe (LLVM 15)", vk::PhysicalDeviceType::CPU, None),
                candidate(1, "NVIDIA H100", vk::PhysicalDeviceType::DISCRETE_GPU, None),
            ]
        };
        let by_name = choose(list(), &"llvm".parse().unwrap()).unwrap();
        assert_eq!(by_name.index, 0);
        let by_index = choose(list(), &"1".parse().unwrap()).unwrap();
        assert_eq!(by_index.name, "NVIDIA H100");
        let err = choose(list(), &DeviceSelector::Index(5)).unwrap_err().to_string();
        assert!(
            err.contains("no Vulkan device with index 5") && err.contains("1: NVIDIA H100"),
            "{err}"
        );
    }

    #[test]
    fn a_missing_feature_is_named_with_the_lavapipe_fix() {
        let old_lavapipe = candidate(
            0,
            "llvmpipe (LLVM 15.0.6, 256 bits)",
            vk::PhysicalDeviceType::CPU,
            Some("feature descriptorBindingSampledImageUpdateAfterBind"),
        );
        let err = choose(vec![old_lavapipe], &DeviceSelector::Best)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("lacks feature descriptorBindingSampledImageUpdateAfterBind"),
            "{err}"
        );
        assert!(
            err.contains("Mesa >= 23") && err.contains("bookworm-backports"),
            "{err}"
        );
        assert_eq!(err.lines().count(), 1);
        let gpu = candidate(
            0,
            "GPU",
            vk::PhysicalDeviceType::DISCRETE_GPU,
            Some("Vulkan 1.3 (the driver offers 1.2)"),
        );
        let err = choose(vec![gpu], &DeviceSelector::Best).unwrap_err().to_string();
        assert!(
            err.contains("lacks Vulkan 1.3") && err.contains("update the GPU driver"),
            "{err}"
        );
    }
}
