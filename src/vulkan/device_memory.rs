//! What the device can take, for the memory model ([`crate::budget`]): the
//! size (and, with `VK_EXT_memory_budget`, the budget) of its largest
//! device-local heap, and the largest single allocation
//! (`maxMemoryAllocationSize`, `maxBufferSize`, and that heap).

use ash::vk;

use super::Context;
use crate::profile::DeviceMemoryUse;

/// The device's memory limits as Vulkan reports them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct DeviceMemory {
    /// Bytes of the largest device-local heap: its budget where
    /// `VK_EXT_memory_budget` is enabled (what this process may use now),
    /// else its size.
    pub heap: u64,
    /// Largest single allocation: the smaller of `maxMemoryAllocationSize`
    /// (Vulkan 1.1), `maxBufferSize` (Vulkan 1.3) and the heap.
    pub allocation: u64,
    /// The device, and whether `VK_EXT_memory_budget` is enabled (for
    /// [`Context::memory_use`]).
    pub physical: vk::PhysicalDevice,
    pub budget: bool,
}

/// Whether `physical` offers `VK_EXT_memory_budget` (then enabled with the device).
pub(crate) fn offers_memory_budget(instance: &ash::Instance, physical: vk::PhysicalDevice) -> bool {
    // SAFETY: plain query on a physical device of this instance.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    extensions
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::memory_budget::NAME))
}

/// The limits of `physical`; `budget`: `VK_EXT_memory_budget` is enabled.
pub(crate) fn query(instance: &ash::Instance, physical: vk::PhysicalDevice, budget: bool) -> DeviceMemory {
    let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
    let mut maintenance4 = vk::PhysicalDeviceMaintenance4Properties::default();
    let mut properties = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut maintenance3)
        .push_next(&mut maintenance4);
    // SAFETY: the device supports Vulkan 1.3 (checked by `inspect`), so both
    // maintenance structs are core.
    unsafe { instance.get_physical_device_properties2(physical, &mut properties) };
    let mut budgets = vk::PhysicalDeviceMemoryBudgetPropertiesEXT::default();
    let mut memory = vk::PhysicalDeviceMemoryProperties2::default();
    if budget {
        memory = memory.push_next(&mut budgets);
    }
    // SAFETY: as above; the budget struct is chained only when its
    // extension is enabled.
    unsafe { instance.get_physical_device_memory_properties2(physical, &mut memory) };
    let props = memory.memory_properties;
    let heaps = &props.memory_heaps[..(props.memory_heap_count as usize).min(vk::MAX_MEMORY_HEAPS)];
    let local = |h: &vk::MemoryHeap| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL);
    let usable = |(i, h): (usize, &vk::MemoryHeap)| match budget && budgets.heap_budget[i] > 0 {
        true => budgets.heap_budget[i].min(h.size),
        false => h.size,
    };
    let heap = (heaps.iter().enumerate())
        .filter(|(_, h)| local(h))
        .map(usable)
        .max()
        .or_else(|| heaps.iter().enumerate().map(usable).max())
        .unwrap_or(0);
    let largest_heap = heaps.iter().map(|h| h.size).max().unwrap_or(0);
    let limit = |v: u64| if v == 0 { u64::MAX } else { v };
    DeviceMemory {
        heap,
        allocation: limit(maintenance3.max_memory_allocation_size)
            .min(limit(maintenance4.max_buffer_size))
            .min(limit(largest_heap)),
        physical,
        budget,
    }
}

impl Context {
    /// Device memory in use now: what the allocator handed out and
    /// reserved, and with `VK_EXT_memory_budget` this process's use of the
    /// device-local heaps and their budget.
    pub fn memory_use(&self) -> DeviceMemoryUse {
        let (allocated_bytes, reserved_bytes) = match self.shared.allocator.lock() {
            Ok(allocator) => {
                let report = allocator.generate_report();
                (report.total_allocated_bytes, report.total_reserved_bytes)
            }
            Err(_) => (0, 0),
        };
        let mut use_ = DeviceMemoryUse {
            allocated_bytes,
            reserved_bytes,
            ..DeviceMemoryUse::default()
        };
        if self.shared.memory.budget {
            let mut budgets = vk::PhysicalDeviceMemoryBudgetPropertiesEXT::default();
            let mut memory = vk::PhysicalDeviceMemoryProperties2::default().push_next(&mut budgets);
            // SAFETY: plain query on this context's physical device; the
            // budget struct is chained only when its extension is enabled.
            unsafe {
                (self.shared.instance).get_physical_device_memory_properties2(self.shared.memory.physical, &mut memory)
            };
            let props = memory.memory_properties;
            let heaps = &props.memory_heaps[..(props.memory_heap_count as usize).min(vk::MAX_MEMORY_HEAPS)];
            let local = (0..heaps.len()).filter(|&i| heaps[i].flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL));
            let (usage, budget) = local.fold((0, 0), |(u, b), i| {
                (u + budgets.heap_usage[i], b + budgets.heap_budget[i])
            });
            use_.heap_usage_bytes = Some(usage);
            use_.heap_budget_bytes = Some(budget);
        }
        use_
    }

    /// What this machine and device can take (`crate::budget`): the
    /// host's available memory, the largest device-local heap (its
    /// `VK_EXT_memory_budget` budget where offered) and the largest single
    /// allocation, capped by `ALPENGLOW_DEVICE_MEMORY_MB` when set.
    pub fn memory_limits(&self) -> crate::budget::MemoryLimits {
        crate::budget::MemoryLimits {
            device: self.shared.memory.heap,
            device_allocation: self.shared.memory.allocation,
            ..crate::budget::MemoryLimits::host_only()
        }
        .with_device_override()
    }
}
