//! The value and structure checks of a sequential point tree, run on every
//! tree read (after the checksum) and before every tree written.

use glam::Vec3;

use super::super::spt::{SequentialPointTree, SptNode, NO_PARENT, ROOT_R_MAX};

/// Largest magnitude of a coordinate (node positions, bounds centre) in an
/// SPT file: 10⁷ m, beyond any terrain the renderer draws. An edited file
/// with a bounds centre of 3·10³⁸ once passed and its object vanished.
pub const MAX_SPT_COORDINATE: f32 = 1e7;

/// Largest length in an SPT file (bounds radius, disk diameters, the errors
/// e_p, e_t, e_g, clip-line offsets): 4·10⁷ m, more than the diagonal of the
/// ±[`MAX_SPT_COORDINATE`] cube.
pub const MAX_SPT_LENGTH: f32 = 4e7;

/// Largest magnitude of a clip-line angle (radians); any angle is one in
/// (−π, π] plus turns, so this only rejects absurd values.
const MAX_CLIP_ANGLE: f32 = 1e3;

/// Relative slack of the "disk inside the bounding sphere" check (the
/// writer enlarges the sphere by 10⁻⁶ and rounds up).
const BOUNDS_SLACK: f64 = 1e-4;

fn check_vec(what: &str, v: Vec3) -> Result<(), String> {
    if !v.is_finite() {
        return Err(format!("non-finite {what} ({}, {}, {})", v.x, v.y, v.z));
    }
    if v.abs().max_element() > MAX_SPT_COORDINATE {
        let s = |x: f32| {
            if x.abs() >= 1e16 {
                format!("{x:e}")
            } else {
                x.to_string()
            }
        };
        return Err(format!(
            "{what} ({}, {}, {}) exceeds ±{MAX_SPT_COORDINATE} m",
            s(v.x),
            s(v.y),
            s(v.z)
        ));
    }
    Ok(())
}

/// Checks one node's own values (not its relation to others).
fn check_node(node: &SptNode, centre: Vec3, radius: f32) -> Result<(), String> {
    check_vec("position", node.position)?;
    if !node.normal.is_finite() {
        return Err("non-finite normal".into());
    }
    if (node.normal.length() - 1.0).abs() > 1e-3 {
        return Err("normal is not unit length".into());
    }
    let scalars = [
        ("diameter", node.diameter),
        ("e_p", node.e_p),
        ("e_t", node.e_t),
        ("e_g", node.e_g),
        ("r_min", node.r_min),
        ("r_max", node.r_max),
    ];
    for (name, v) in scalars {
        if !v.is_finite() {
            return Err(format!("non-finite {name}"));
        }
        if v < 0.0 {
            return Err(format!("negative {name}"));
        }
        let is_length = !name.starts_with("r_");
        if is_length && v > MAX_SPT_LENGTH {
            return Err(format!("{name} {v:e} exceeds {MAX_SPT_LENGTH} m"));
        }
    }
    if node.diameter <= 0.0 {
        return Err("diameter is zero".into());
    }
    if node.r_min > node.r_max {
        return Err("r_min exceeds r_max".into());
    }
    if node.parent != NO_PARENT && node.r_max == ROOT_R_MAX {
        return Err("r_max is the root's but the node has a parent".into());
    }
    let packed = node.clip.packed();
    if !packed.iter().all(|v| v.is_finite()) {
        return Err("non-finite clip line".into());
    }
    for k in 0..2 {
        let (angle, offset) = (packed[2 * k], packed[2 * k + 1]);
        if offset != f32::MAX && (angle.abs() > MAX_CLIP_ANGLE || offset.abs() > MAX_SPT_LENGTH) {
            return Err(format!(
                "clip line {k} (angle {angle}, offset {offset}) is out of range"
            ));
        }
    }
    let reach = f64::from((node.position - centre).length()) + 0.5 * f64::from(node.diameter);
    let allowed = f64::from(radius) * (1.0 + BOUNDS_SLACK) + 1e-3;
    if reach > allowed {
        return Err(format!(
            "the disk reaches {reach:.6} m from the bounds centre, outside the bounds radius {radius}"
        ));
    }
    Ok(())
}

/// Checks the values and structure of a tree; the message is one line
/// without the file name and names the node and field.
pub(super) fn validate(tree: &SequentialPointTree) -> Result<(), String> {
    let n = tree.nodes.len();
    if n == 0 {
        return Err("the tree has no nodes".into());
    }
    if n >= NO_PARENT as usize {
        return Err(format!("{n} nodes exceed the format's limit"));
    }
    if !(tree.epsilon.is_finite() && tree.epsilon > 0.0) {
        return Err(format!("epsilon {} is not positive and finite", tree.epsilon));
    }
    check_vec("bounds centre", tree.bounds_centre)?;
    let radius = tree.bounds_radius;
    if !(radius.is_finite() && (0.0..=MAX_SPT_LENGTH).contains(&radius)) {
        return Err(format!("bounds radius {radius:e} is not in 0..={MAX_SPT_LENGTH} m"));
    }
    let mut roots = 0usize;
    let mut has_child = vec![false; n];
    for (i, node) in tree.nodes.iter().enumerate() {
        let bad = |what: &str| Err(format!("node {i}: {what}"));
        check_node(node, tree.bounds_centre, radius).map_err(|m| format!("node {i}: {m}"))?;
        if i > 0 && tree.nodes[i - 1].r_max < node.r_max {
            return bad("nodes are not sorted by decreasing r_max");
        }
        if node.parent == NO_PARENT {
            roots += 1;
            if node.depth != 0 {
                return bad("the root has a depth other than 0");
            }
            continue;
        }
        let p = node.parent as usize;
        if p >= n || p == i {
            return bad(&format!("parent index {p} is out of range"));
        }
        let parent = &tree.nodes[p];
        if parent.is_leaf {
            return bad(&format!("parent {p} is a leaf"));
        }
        if parent.depth.checked_add(1) != Some(node.depth) {
            return bad(&format!(
                "depth {} does not follow its parent's {}",
                node.depth, parent.depth
            ));
        }
        has_child[p] = true;
    }
    if roots != 1 {
        return Err(format!("{roots} root nodes (expected exactly 1)"));
    }
    if let Some(i) = (0..n).find(|&i| !tree.nodes[i].is_leaf && !has_child[i]) {
        return Err(format!("node {i}: an inner node without children"));
    }
    Ok(())
}
