//! Helpers shared by the point-rendering benchmarks (`examples/splat_bench.rs`,
//! `examples/splat_modes_bench.rs`), included with `#[path]`.

use alpenglow::bench::ROOT_R_MAX;
use alpenglow::tools::spt::SequentialPointTree;
use alpenglow::Camera;
use glam::DVec3;

/// The leaves of `tree` as a flat list drawn at every distance.
pub fn all_leaves(tree: &SequentialPointTree) -> SequentialPointTree {
    let mut flat = tree.clone();
    flat.nodes.retain(|n| n.is_leaf);
    for n in &mut flat.nodes {
        n.r_min = 0.0;
        n.r_max = ROOT_R_MAX;
    }
    flat
}

/// Looking at the standing bunny from `distance` metres, slightly from above.
pub fn camera_at(distance: f64) -> Camera {
    Camera {
        eye: DVec3::new(0.0, -distance, 0.1 + 0.2 * distance),
        target: DVec3::new(-0.02, 0.0, 0.09),
        up: DVec3::Z,
        fov_y_deg: 40.0,
        near: 0.01,
        far: 1000.0,
    }
}
