//! Reversed depth (issue 28): every view's depth buffer holds 1 at the near
//! plane and 0 at the far plane (or at infinity, for a camera whose far
//! plane is `f64::INFINITY`), in a 32-bit float buffer. The projected depth
//! `near / d` (infinite far) falls off like the float's own spacing, so the
//! relative precision is the same at every distance: a driver's eye 0.1 m
//! above the road still orders ridges 100 km away (a forward buffer, 1 − near
//! / d, keeps about 2⁻²⁴ of absolute precision near 1 and loses them). The
//! shadow atlas keeps forward depth (orthographic, linear).
//!
//! Passes that depth-test against a view's depth buffer clear it to
//! [`FAR_DEPTH`] and compare with [`NEARER`] or [`NEARER_OR_EQUAL`].

use glam::DMat4;

use crate::vulkan::CompareOp;

/// The depth buffer's value at the far plane (and its clear value).
pub const FAR_DEPTH: f32 = 0.0;
/// Depth test: the fragment is nearer than what the buffer holds.
pub const NEARER: CompareOp = CompareOp::GREATER;
/// Depth test: the fragment is nearer than or as near as the buffer.
pub const NEARER_OR_EQUAL: CompareOp = CompareOp::GREATER_OR_EQUAL;

/// The projection's depth row: with view-space `z` (−d in front of the
/// camera) clip `z = a·z + b` and clip `w = −z`, so the depth is
/// `−a + b / d`: 1 at `near`, 0 at `far` (`f64::INFINITY`: `a = 0`,
/// `b = near`).
pub fn depth_row(near: f64, far: f64) -> (f64, f64) {
    if far.is_infinite() {
        return (0.0, near);
    }
    let range = far - near;
    (near / range, near * far / range)
}

/// Sets the depth row of the perspective projection `proj` (a matrix whose
/// clip `w` is `−z`) to reversed depth ([`depth_row`]).
pub fn set_reversed_depth(proj: &mut DMat4, near: f64, far: f64) {
    let (a, b) = depth_row(near, far);
    proj.z_axis.z = a;
    proj.w_axis.z = b;
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    fn depth(near: f64, far: f64, d: f64) -> f64 {
        let mut proj = DMat4::perspective_rh(1.0, 1.5, 1.0, 2.0);
        set_reversed_depth(&mut proj, near, far);
        let clip = proj * DVec4::new(0.0, 0.0, -d, 1.0);
        clip.z / clip.w
    }

    #[test]
    fn near_is_one_and_far_is_zero() {
        assert!((depth(0.1, 1e5, 0.1) - 1.0).abs() < 1e-12);
        assert!(depth(0.1, 1e5, 1e5).abs() < 1e-12);
        assert!((depth(0.1, f64::INFINITY, 0.1) - 1.0).abs() < 1e-12);
        assert!((depth(0.1, f64::INFINITY, 1e9) - 1e-10).abs() < 1e-20);
        // Nearer is greater.
        assert!(depth(0.1, 1e5, 50_000.0) > depth(0.1, 1e5, 50_001.0));
    }

    /// In f32, two ridges 1 % apart at 50 km keep their order with a
    /// near plane of 0.1 m (a forward buffer rounds both to one value at
    /// 0.01 m).
    #[test]
    fn float_depth_orders_distant_surfaces() {
        let (a, b) = (depth(0.01, 1e5, 50_000.0) as f32, depth(0.01, 1e5, 50_500.0) as f32);
        assert!(a > b, "{a} {b}");
        let forward = |d: f64| (1e5 / (1e5 - 0.01) * (1.0 - 0.01 / d)) as f32;
        assert_eq!(
            forward(50_000.0),
            forward(50_500.0),
            "the forward buffer cannot tell them apart"
        );
    }
}
