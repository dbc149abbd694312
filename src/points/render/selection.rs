//! The CPU half of sequential point tree rendering (dissertation §10.1.7):
//! per frame and instance, a lower bound r_lo of the eye distance over the
//! object's bounding sphere, and the prefix of the splat list with
//! `r_max ≥ r_lo` found by binary search. Instances whose bounding sphere is
//! outside the view frustum are not drawn. The exact interval test runs in
//! the vertex stage (`glsl/points/splat.vert`).
//!
//! Objects marked for thinning (vegetation, `PointObject::thinning`): an
//! instance whose bounding sphere spans `s` < [`THINNING_SIZE`] pixels in
//! the image is drawn with probability
//! `(s/THINNING_SIZE)²`, decided by a fixed hash of its index
//! ([`keeps_instance`]). A splat never covers less than the EWA
//! resampling filter (about three pixels across), so sub-pixel plants
//! would paint a distant hillside with blobs; thinning keeps their
//! expected coverage near their true projected area, and their draws few.
//! Kept instances are a nested set as the camera approaches (each plant
//! appears at its own distance and stays).
//!
//! With normal clusters (§10.1.10) an object's list is cut into 128 sorted
//! lists by normal direction; clusters whose every splat faces away from the
//! eye are skipped and the others get their own prefix and draw.

use std::sync::Arc;

use glam::{DMat4, DVec3};

use super::gpu_layout::GpuInstance;
use crate::points::build::clusters::ClusteredTree;
use crate::points::scene::{PointObject, PointScene};
use crate::random::SplitMix64;
use crate::view::camera::frustum_planes;

/// Image size in pixels below which instances of thinned objects are drawn
/// with falling probability (module docs).
pub const THINNING_SIZE: f64 = 3.0;

/// Whether instance `index` of `object`, its bounding sphere's centre
/// `distance` away from the eye (in object units), is drawn (module docs)
/// in a view whose pixels are `pixel` wide at unit distance (1/f_y);
/// always true for objects without thinning.
pub fn keeps_instance(object: &PointObject, index: usize, distance: f64, pixel: f64) -> bool {
    if !object.thinning {
        return true;
    }
    let size = 2.0 * f64::from(object.tree.bounds_radius) / (distance.max(1e-9) * pixel.max(1e-12));
    if size >= THINNING_SIZE {
        return true;
    }
    let u = SplitMix64(index as u64 ^ 0x7468_696e_6e69_6e67).next_f64();
    u < (size / THINNING_SIZE).powi(2)
}

/// Where an object's splats are in the splat buffer.
#[derive(Clone, Debug)]
pub struct ObjectLayout {
    /// Index of its first splat.
    pub first: u32,
    /// Its normal clusters, when the list is clustered (the buffer then holds `clusters.nodes`).
    pub clusters: Option<Arc<ClusteredTree>>,
    /// Index of its first triangle in the hybrid triangle buffer (hybrid objects, §10.1.8).
    pub first_triangle: u32,
}

/// One instance to draw this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InstanceDraw {
    /// Index into this frame's instance records.
    pub record: u32,
    /// Splats of the prefix.
    pub count: u32,
}

/// What the CPU decided for one frame.
#[derive(Clone, Debug, Default)]
pub struct FramePlan {
    pub records: Vec<GpuInstance>,
    pub draws: Vec<InstanceDraw>,
    /// Instances of the scene.
    pub instances: usize,
    /// Splats in the drawn prefixes.
    pub prefix_splats: u64,
    /// Splats of the drawn instances' whole lists.
    pub list_splats: u64,
    /// Instances with at least one draw.
    pub instances_drawn: usize,
    /// Triangle draws of hybrid objects (§10.1.8): record and triangles of the prefix.
    pub triangle_draws: Vec<InstanceDraw>,
    /// Triangles in the drawn prefixes.
    pub prefix_triangles: u64,
}

/// Plans a frame into `plan`: `view` world → camera, `view_proj` world →
/// clip, `pixel` the width of a pixel at unit distance (1/f_y, for
/// thinning), `objects[o]` where object o's list is; reusing its memory (no allocation once its
/// vectors have grown to a frame's size).
pub fn plan_frame_into(
    plan: &mut FramePlan,
    scene: &PointScene,
    objects: &[ObjectLayout],
    (eye, view, view_proj): (DVec3, DMat4, DMat4),
    pixel: f64,
) {
    let planes = frustum_planes(view_proj);
    let (mut records, mut draws, mut triangle_draws) = (
        std::mem::take(&mut plan.records),
        std::mem::take(&mut plan.draws),
        std::mem::take(&mut plan.triangle_draws),
    );
    records.clear();
    draws.clear();
    triangle_draws.clear();
    *plan = FramePlan {
        instances: scene.instances.len(),
        records,
        draws,
        triangle_draws,
        ..FramePlan::default()
    };
    for (index, inst) in scene.instances.iter().enumerate() {
        let object = &scene.objects[inst.object];
        let tree = &object.tree;
        let layout = &objects[inst.object];
        let model = inst.transform.matrix();
        let scale = inst.transform.scale;
        let centre = model.transform_point3(tree.bounds_centre.as_dvec3());
        let radius = f64::from(tree.bounds_radius) * scale;
        if planes.iter().any(|p| p.truncate().dot(centre) + p.w < -radius) {
            continue;
        }
        if !keeps_instance(object, index, (eye - centre).length() / scale, pixel) {
            continue;
        }
        // r_lo in object units: the tree's intervals are in object units.
        let r_lo = ((((eye - centre).length() - radius) / scale).max(0.0)) as f32;
        let model_view = (view * model).as_mat4().to_cols_array();
        let record = |first: u32, count: usize| GpuInstance {
            model_view,
            params: [
                scale as f32,
                f32::from_bits(first),
                f32::from_bits(count as u32),
                f32::from_bits(layout.first_triangle),
            ],
            ids: [object.class.id(), index as u32 + 1, u32::from(object.two_sided), 0],
        };
        let first_record = plan.records.len() as u32;
        let mut drawn = false;
        let mut push = |plan: &mut FramePlan, first: u32, count: usize| {
            if count == 0 {
                return;
            }
            plan.draws.push(InstanceDraw {
                record: plan.records.len() as u32,
                count: count as u32,
            });
            plan.records.push(record(first, count));
            plan.prefix_splats += count as u64;
            drawn = true;
        };
        match &layout.clusters {
            None => push(plan, layout.first, tree.prefix_len(r_lo)),
            Some(clustered) => {
                let eye_object = model.inverse().transform_point3(eye).as_vec3();
                let visible = (clustered.clusters.iter().enumerate())
                    .filter(|(_, c)| object.two_sided || !c.is_back_facing(eye_object, c.centre, c.radius));
                for (k, c) in visible {
                    push(plan, layout.first + c.first, clustered.cluster_prefix_len(k, r_lo));
                }
            }
        }
        let triangles = object.hybrid.as_ref().map_or(0, |h| h.prefix_len(r_lo, tree.epsilon));
        if triangles > 0 {
            if !drawn {
                plan.records.push(record(layout.first, 0));
            }
            plan.triangle_draws.push(InstanceDraw {
                record: first_record,
                count: triangles as u32,
            });
            plan.prefix_triangles += triangles as u64;
            drawn = true;
        }
        if drawn {
            plan.instances_drawn += 1;
            plan.list_splats += tree.nodes.len() as u64;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::plants::build_plant_tree;
    use crate::points::build::spt::SptOptions;
    use crate::surface::plants::PlantModel;

    #[test]
    fn thinning_keeps_large_instances_and_a_nested_share_of_small_ones() {
        let built = build_plant_tree(PlantModel::GrassTuft, 1, 300, false, &SptOptions::default()).unwrap();
        let mut object = PointObject::new("tuft", built.tree);
        let pixel = 1e-3;
        let diameter = 2.0 * f64::from(object.tree.bounds_radius);
        // At distance d the object spans diameter/(d·pixel) pixels.
        let distance_for = |pixels: f64| diameter / (pixels * pixel);
        let n = 20_000;
        let kept = |object: &PointObject, pixels: f64| -> Vec<usize> {
            (0..n)
                .filter(|&i| keeps_instance(object, i, distance_for(pixels), pixel))
                .collect()
        };
        assert_eq!(kept(&object, 0.1).len(), n, "objects without thinning are all drawn");
        object.thinning = true;
        assert_eq!(kept(&object, THINNING_SIZE).len(), n);
        assert_eq!(kept(&object, 10.0).len(), n);
        let (half, tenth) = (kept(&object, 1.5), kept(&object, 0.3));
        for (set, pixels) in [(&half, 1.5), (&tenth, 0.3)] {
            let p = (pixels / THINNING_SIZE).powi(2);
            let sigma = (n as f64 * p * (1.0 - p)).sqrt();
            assert!(
                (set.len() as f64 - n as f64 * p).abs() < 4.5 * sigma,
                "{pixels} px: {}",
                set.len()
            );
        }
        // Nested: what is drawn far away stays drawn nearer.
        assert!(tenth.iter().all(|i| half.binary_search(i).is_ok()));
    }
}
