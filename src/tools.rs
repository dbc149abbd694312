//! The offline tools behind the CLI's `spt`, `synth` and `layers`
//! subcommands, with the helpers they share: memory and time budgets,
//! profile summaries, and the solar calendar.
//!
//! Each submodule is a curated list of re-exports: what a program needs to
//! do what the matching subcommand does, and nothing of the implementation.
//!
//! ```no_run
//! use alpenglow::tools::budget::{format_bytes, MemoryLimits};
//! let limits = MemoryLimits::host_only();
//! println!("host memory limit: {}", format_bytes(limits.host));
//! ```

/// Point trees (`.spt`): sample a mesh or read a point cloud, estimate the
/// build's cost, build the tree (`alpenglow spt build`).
pub mod spt {
    pub use crate::points::build::estimate::complete_cloud;
    pub use crate::points::build::mesh_out::write_obj;
    pub use crate::points::build::plan::{plan_build, BuildCost};
    pub use crate::points::build::rocks::{generate_rock, RockParams, MAX_SUBDIVISIONS};
    pub use crate::points::build::sampling::{
        sample_mesh_reporting, sampling_footprint, SamplingMethod, SamplingOptions,
    };
    pub use crate::points::build::spt::{build_spt, epsilon_from_pixels, SequentialPointTree, SptOptions};
}

/// Terrain synthesis by example: fill the holes of a DEM, grow a new field
/// from an exemplar or a transition between two (`alpenglow synth
/// fill|grow|transition`).
pub mod synth {
    pub use crate::synthesis::cost::{GrowthCost, SearchDevice};
    pub use crate::synthesis::fill::{check_hole_fill, fill_holes, fill_holes_cpu, plan_hole_fill, FillParams, Growth};
    pub use crate::synthesis::free::{check_free_growth, grow_free_cpu, plan_free_growth, FREE_GROWTH, MAX_SIDE};
    pub use crate::synthesis::gpu::GpuSearch;
    pub use crate::synthesis::search::CpuSearch;
    pub use crate::synthesis::search::NeighbourhoodSearch;
    pub use crate::synthesis::transition::{
        band_of, check_fields, grow_transition, grow_transition_cpu, plan_transition, Axis, TransitionParams,
    };
}

/// A layer tree from a classified image (`alpenglow layers from-image`),
/// and the names of the layer tree's input maps.
pub mod layers {
    pub use crate::surface::layers::INPUT_NAMES;
    /// The layer tree's limits (what a loaded tree is guaranteed to respect).
    pub use crate::surface::layers::{
        vegetation::{MAX_DENSITY as MAX_VEGETATION_DENSITY, MAX_SCALE as MAX_VEGETATION_SCALE},
        Constraint, MAX_BLUR_RADII, MAX_HEIGHT_BLUR, MAX_SAMPLES,
    };
    pub use crate::texturing::from_image::{
        build_layers, load_mask, load_rgb_image,
        plot::{plot_distributions, plot_hue_saturation},
        ClassCount, FromImageOptions, PixelStatus, MAX_CLASSES,
    };
    pub use crate::texturing::reference::srgb8;
}

/// The sun's position from a place, a date and a time of day, and the sky
/// presets (`--lat`, `--date`, `--time`, `--sky`).
pub mod solar {
    pub use crate::lighting::solar::{parse_date, parse_time, solar_position, Clock, SkyPreset};
}

/// The memory model (host and device limits, footprints) and the time
/// budget every long computation checks before it starts.
pub mod budget {
    pub use crate::budget::{
        check_duration, format_bytes, format_duration, Footprint, MemoryLimits, DEFAULT_MAX_HOURS,
    };
}

/// Summaries and exports of [`FrameProfile`](crate::FrameProfile)s, and the
/// median and quantiles of timings.
pub mod profile {
    pub use crate::profile::{
        chrome_trace, gpu_spans_outside_frames, median, profile_json, quantile, summarize, write_chrome_trace,
        write_profile_json, DeviceMemoryUse, FrameSummary, PassSummary, PassTiming, PipelineStats, StageTiming,
    };
}

/// RenderDoc frame captures through its in-application API: of a frame of
/// a headless run (`render`/`bench`/`fly --renderdoc-capture N`) or of the
/// next presented frame (`trigger_capture`). docs/PROFILING.md.
pub mod renderdoc {
    pub use crate::vulkan::renderdoc::RenderDocCapture;
}

/// Hot reload of `glsl/` (feature `hot-reload`): shaders recompiled when
/// their files change, installed for the pipelines built afterwards
/// (`alpenglow view` rebuilds its renderer). docs/PROFILING.md.
#[cfg(feature = "hot-reload")]
pub mod hot_reload {
    pub use crate::hot_reload::ShaderWatcher;
}
