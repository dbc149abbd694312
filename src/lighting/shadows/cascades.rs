//! Cascade planning of the sun's shadow maps (dissertation §9.5 compares
//! shadow maps with horizon maps; `ALGORITHMS.md` §6): CPU only, per view and
//! frame.
//!
//! 1. Splits: the practical split scheme, a blend `λ·log + (1−λ)·uniform` of
//!    the logarithmic and uniform splits of `[near, distance]` (distance: the
//!    view's far plane capped at [`ShadowSettings::max_distance`]).
//! 2. Per cascade an orthographic sun-space box around the bounding sphere
//!    of the cascade's frustum slice. The sphere depends only on the field of
//!    view, the aspect and the split depths, so the box does not change size
//!    when the camera turns.
//! 3. Texel snapping: the box's origin, in a sun-space basis that depends
//!    only on the sun, is rounded to whole shadow texels, so a camera that
//!    moves or turns shifts the shadow map by whole texels and the shadows do
//!    not shimmer.
//! 4. Depth: from the back of the sphere to the highest point of the scene
//!    towards the sun ([`SceneBounds`]), so casters outside the view (a ridge
//!    between the slice and the sun) are in the map.
//!
//! Each cascade's matrix maps world space into its quadrant of one 2×2
//! atlas (a single D32 image; quadrant `i` at column `i % 2`, row `i / 2`),
//! depth 0 nearest the sun.

use glam::{DMat4, DVec2, DVec3, DVec4, Vec3};

use crate::error::{Error, Result};
use crate::lighting::constants::{LightingFrame, MAX_CASCADES};
use crate::view::camera::Camera;

/// The widest reach (texels) of the soft sun's blocker search and disc
/// filter (`SOFT_MAX_TEXELS` in `glsl/include/shadows.glsl`): the casters
/// draw that far around the receivers.
pub const SOFT_FILTER_TEXELS: f64 = 24.0;

/// How the shadow maps are laid out and filtered.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Cascades, 1..=4.
    pub cascades: u32,
    /// Side of the square atlas in texels (each cascade gets a quadrant).
    pub atlas_size: u32,
    /// Shadows end at the view's far plane or this view depth (m), whichever is nearer.
    pub max_distance: f64,
    /// Blend of the logarithmic (1) and uniform (0) splits.
    pub lambda: f64,
    /// PCF kernel radius in texels (the tent spans `radius + 1` texels each side).
    pub pcf_radius: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        ShadowSettings {
            cascades: 4,
            atlas_size: 4096,
            max_distance: 30_000.0,
            lambda: 0.75,
            pcf_radius: 2,
        }
    }
}

impl ShadowSettings {
    /// Checks every number; the error names the one out of range.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_CASCADES as u32).contains(&self.cascades) {
            return Err(Error::invalid(
                "shadows.cascades",
                format!("{}; must be 1..={MAX_CASCADES}", self.cascades),
            ));
        }
        if !(64..=16384).contains(&self.atlas_size) || self.atlas_size % 2 != 0 {
            return Err(Error::invalid(
                "shadows.atlas_size",
                format!("{}; must be even and in 64..=16384", self.atlas_size),
            ));
        }
        if !(self.max_distance.is_finite() && self.max_distance > 0.0) {
            return Err(Error::invalid(
                "shadows.max_distance",
                format!("{}; must be a positive number", self.max_distance),
            ));
        }
        if !(0.0..=1.0).contains(&self.lambda) {
            return Err(Error::invalid(
                "shadows.lambda",
                format!("{}; must be in 0..=1", self.lambda),
            ));
        }
        if self.pcf_radius > 4 {
            return Err(Error::invalid(
                "shadows.pcf_radius",
                format!("{}; must be 0..=4", self.pcf_radius),
            ));
        }
        Ok(())
    }

    /// Texels of one cascade's quadrant per side.
    pub fn quadrant(&self) -> u32 {
        self.atlas_size / 2
    }
}

/// An axis-aligned box holding every shadow caster of the scene (terrain
/// height range, point objects).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBounds {
    pub min: DVec3,
    pub max: DVec3,
}

impl SceneBounds {
    /// The smallest box holding both.
    pub fn union(self, other: SceneBounds) -> SceneBounds {
        SceneBounds {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        let (a, b) = (self.min, self.max);
        [0, 1, 2, 3, 4, 5, 6, 7].map(|i| {
            DVec3::new(
                if i & 1 == 0 { a.x } else { b.x },
                if i & 2 == 0 { a.y } else { b.y },
                if i & 4 == 0 { a.z } else { b.z },
            )
        })
    }
}

/// One cascade of a [`CascadePlan`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cascade {
    /// World → atlas clip space (xy in this cascade's quadrant, depth 0..1 from the sun).
    pub view_proj: DMat4,
    /// View depths (m) where the cascade's slice starts and ends.
    pub near: f64,
    pub far: f64,
    /// World size (m) of one shadow texel.
    pub texel: f64,
    /// Snapped box centre in sun space (x, y) and half side (m).
    pub centre: [f64; 2],
    pub half: f64,
    /// Sun-space depth range (m along the sun direction): [back, front].
    pub depth: [f64; 2],
    /// The atlas texels its receivers can sample (first x, first y, last
    /// x, last y, inclusive): the view's frustum slice, with the previous
    /// cascade's blend band, projected into the quadrant and grown by the
    /// PCF and normal-offset margin. The casters draw only there (the rest
    /// of the quadrant keeps depth 1 and is never read).
    pub receivers: [u32; 4],
}

/// The cascades of one view this frame.
#[derive(Clone, Debug, PartialEq)]
pub struct CascadePlan {
    pub cascades: Vec<Cascade>,
    /// Unit vector towards the sun.
    pub sun: DVec3,
    /// Sun-space basis: x, y across the sun, z = `sun`.
    pub basis: [DVec3; 3],
    pub atlas_size: u32,
    pub pcf_radius: u32,
}

impl CascadePlan {
    /// Cascades to draw and sample: none when the sun is below the horizon.
    pub fn count(&self) -> u32 {
        if self.sun.z > 0.0 {
            self.cascades.len() as u32
        } else {
            0
        }
    }

    /// Writes the shadow fields of `frame` (`shadows.yzw`, `cascade_view_proj`,
    /// `cascade_far`, `cascade_texel`); the atlas's heap handle, `shadows.x`,
    /// is written by the pass that declares the atlas
    /// ([`crate::view::LightingMap::ShadowAtlas`]).
    pub fn fill(&self, frame: &mut LightingFrame) {
        frame.shadows = [frame.shadows[0], self.count(), self.atlas_size, self.pcf_radius];
        frame.cascade_view_proj = [[0.0; 16]; MAX_CASCADES];
        frame.cascade_far = [0.0; 4];
        frame.cascade_texel = [0.0; 4];
        for (i, c) in self.cascades.iter().take(MAX_CASCADES).enumerate() {
            frame.cascade_view_proj[i] = c.view_proj.as_mat4().to_cols_array();
            frame.cascade_far[i] = c.far as f32;
            frame.cascade_texel[i] = c.texel as f32;
        }
    }

    /// Whether a caster inside the sphere (`centre`, `radius`) can shadow a
    /// receiver of some cascade (a conservative test in sun space).
    pub fn may_cast(&self, centre: DVec3, radius: f64) -> bool {
        let [bx, by, bz] = self.basis;
        let (x, y, z) = (centre.dot(bx), centre.dot(by), centre.dot(bz));
        self.cascades.iter().any(|c| {
            (x - c.centre[0]).abs() <= c.half + radius
                && (y - c.centre[1]).abs() <= c.half + radius
                && z + radius >= c.depth[0]
        })
    }
}

/// Fraction of a cascade's depth range over which it blends into the next
/// (`SHADOW_BLEND_BAND` in `glsl/include/shadows.glsl`).
const BLEND_BAND: f64 = 0.1;

/// The view frustum whose slices the cascades cover.
struct SliceFrustum<'a> {
    camera: &'a Camera,
    /// Tangents of the half angles across and up.
    tan: (f64, f64),
}

impl SliceFrustum<'_> {
    /// The texel box of cascade `index`'s quadrant of an `atlas`² atlas
    /// (through `view_proj`) holding the slice between view depths
    /// `range`, grown by `margin` texels.
    fn texels(&self, view_proj: DMat4, range: (f64, f64), (index, atlas): (usize, u32), margin: f64) -> [u32; 4] {
        let (eye, forward) = (self.camera.eye, self.camera.forward());
        let (right, up) = (self.camera.right() * self.tan.0, self.camera.image_up() * self.tan.1);
        let size = f64::from(atlas);
        let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
        for d in [range.0, range.1] {
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                let p = eye + d * (forward + sx * right + sy * up);
                let clip = view_proj * p.extend(1.0);
                let texel = (clip.truncate().truncate() * 0.5 + 0.5) * size;
                lo = lo.min(texel);
                hi = hi.max(texel);
            }
        }
        let side = atlas / 2;
        let q0 = glam::UVec2::new((index % 2) as u32, (index / 2) as u32) * side;
        let q1 = q0 + (side - 1);
        let clamp = |v: f64, lo: u32, hi: u32| (v.max(f64::from(lo)).min(f64::from(hi))) as u32;
        [
            clamp((lo.x - margin).floor(), q0.x, q1.x),
            clamp((lo.y - margin).floor(), q0.y, q1.y),
            clamp((hi.x + margin).ceil(), q0.x, q1.x),
            clamp((hi.y + margin).ceil(), q0.y, q1.y),
        ]
    }
}

/// View depths of the `n + 1` split planes over `[near, far]`.
#[cfg(test)]
pub fn split_depths(near: f64, far: f64, n: u32, lambda: f64) -> Vec<f64> {
    (0..=n).map(|i| split_depth(near, far, (i, n), lambda)).collect()
}

/// Split `i` of `n` of [`split_depths`].
fn split_depth(near: f64, far: f64, (i, n): (u32, u32), lambda: f64) -> f64 {
    let f = f64::from(i) / f64::from(n);
    let log = near * (far / near).powf(f);
    let uniform = near + (far - near) * f;
    lambda * log + (1.0 - lambda) * uniform
}

/// Sun-space basis: x, y across the sun, z towards it; depends only on the sun.
pub fn sun_basis(sun: DVec3) -> [DVec3; 3] {
    let z = sun.normalize();
    let reference = if z.z.abs() < 0.99 { DVec3::Z } else { DVec3::Y };
    let x = reference.cross(z).normalize();
    [x, z.cross(x), z]
}

/// Bounding sphere of the frustum slice between view depths `near` and
/// `far`, as (depth of its centre on the view axis, radius); `k` is the
/// tangent of the half-angle to a frustum corner.
pub fn slice_sphere(near: f64, far: f64, k: f64) -> (f64, f64) {
    let k2 = k * k;
    let c = (0.5 * (near + far) * (1.0 + k2)).min(far);
    let r = ((c - near).powi(2) + near * near * k2)
        .max((far - c).powi(2) + far * far * k2)
        .sqrt();
    (c, r)
}

/// Plans the cascades of `camera` (image aspect `aspect`) for a sun in
/// direction `sun` over a scene inside `bounds`.
pub fn plan_cascades(
    camera: &Camera,
    aspect: f64,
    sun: Vec3,
    bounds: SceneBounds,
    settings: &ShadowSettings,
) -> Result<CascadePlan> {
    let mut plan = CascadePlan {
        cascades: Vec::new(),
        sun: DVec3::Z,
        basis: [DVec3::X, DVec3::Y, DVec3::Z],
        atlas_size: settings.atlas_size,
        pcf_radius: settings.pcf_radius,
    };
    plan_cascades_into(&mut plan, (camera, aspect), sun, bounds, settings)?;
    Ok(plan)
}

/// [`plan_cascades`] into `plan`, reusing its memory (no allocation).
pub fn plan_cascades_into(
    plan: &mut CascadePlan,
    (camera, aspect): (&Camera, f64),
    sun: Vec3,
    bounds: SceneBounds,
    settings: &ShadowSettings,
) -> Result<()> {
    settings.validate()?;
    camera.validate()?;
    let sun = sun.as_dvec3();
    if !(sun.is_finite() && sun.length() > 1e-6) {
        return Err(Error::invalid("lighting.sun", format!("{sun}; must be non-zero")));
    }
    let sun = sun.normalize();
    let basis = sun_basis(sun);
    let far = camera.far.min(settings.max_distance).max(camera.near * 1.001);
    let n = settings.cascades.clamp(1, MAX_CASCADES as u32);
    let mut split_array = [0.0; MAX_CASCADES + 1];
    for (i, s) in split_array.iter_mut().enumerate().take(n as usize + 1) {
        *s = split_depth(camera.near, far, (i as u32, n), settings.lambda);
    }
    let splits = &split_array[..n as usize + 1];
    let tan_y = (0.5 * camera.fov_y_deg.to_radians()).tan();
    let k = tan_y * (1.0 + aspect * aspect).sqrt();
    let quadrant = f64::from(settings.quadrant());
    // Margin in texels: half a texel of snapping, the PCF tent and the normal
    // offset, or the soft sun's disc filter (at most SOFT_MAX_TEXELS = 24
    // texels and a bilinear tap; glsl/include/shadows.glsl), whichever is wider.
    let margin = (2.0 * f64::from(settings.pcf_radius) + 8.0).max(SOFT_FILTER_TEXELS + 2.0);
    let forward = camera.forward();
    let top = bounds.corners().iter().map(|p| p.dot(sun)).fold(f64::MIN, f64::max);
    let mut cascades = std::mem::take(&mut plan.cascades);
    cascades.clear();
    let slice = SliceFrustum {
        camera,
        tan: (tan_y * aspect, tan_y),
    };
    for (i, w) in splits.windows(2).enumerate() {
        let (c, r) = slice_sphere(w[0], w[1], k);
        // Quantised so the size does not flicker with rounding.
        let r = (r * 16.0).ceil() / 16.0;
        let texel = 2.0 * r / (quadrant - margin);
        let half = 0.5 * quadrant * texel;
        let centre = camera.eye + forward * c;
        let [bx, by, bz] = basis;
        let snap = |v: f64| (v / texel).round() * texel;
        let (sx, sy, sz) = (snap(centre.dot(bx)), snap(centre.dot(by)), centre.dot(bz));
        let back = (sz - r - texel).floor();
        let front = (sz + r).max(top).ceil() + 1.0;
        // Sun space: x' = (p·bx − sx)/half, y' likewise, depth = (front − p·bz)/(front − back).
        let depth_scale = 1.0 / (front - back);
        let ortho = DMat4::from_cols(
            DVec4::new(bx.x / half, by.x / half, -bz.x * depth_scale, 0.0),
            DVec4::new(bx.y / half, by.y / half, -bz.y * depth_scale, 0.0),
            DVec4::new(bx.z / half, by.z / half, -bz.z * depth_scale, 0.0),
            DVec4::new(-sx / half, -sy / half, front * depth_scale, 1.0),
        );
        // NDC of the atlas: x_a = 0.5·x + q_x − 0.5 (q the quadrant's column, row).
        let (qx, qy) = ((i % 2) as f64, (i / 2) as f64);
        let to_quadrant = DMat4::from_cols(
            DVec4::new(0.5, 0.0, 0.0, 0.0),
            DVec4::new(0.0, 0.5, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 1.0, 0.0),
            DVec4::new(qx - 0.5, qy - 0.5, 0.0, 1.0),
        );
        let view_proj = to_quadrant * ortho;
        // Receivers in the previous cascade's blend band sample this one too.
        let first = match i {
            0 => w[0],
            _ => w[0] - BLEND_BAND * (w[0] - splits[i - 1]),
        };
        let receivers = slice.texels(view_proj, (first, w[1]), (i, settings.atlas_size), margin);
        cascades.push(Cascade {
            view_proj,
            near: w[0],
            far: w[1],
            texel,
            centre: [sx, sy],
            half,
            depth: [back, front],
            receivers,
        });
    }
    *plan = CascadePlan {
        cascades,
        sun,
        basis,
        atlas_size: settings.atlas_size,
        pcf_radius: settings.pcf_radius,
    };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: DVec3, target: DVec3) -> Camera {
        Camera {
            eye,
            target,
            up: DVec3::Z,
            fov_y_deg: 55.0,
            near: 1.0,
            far: 80_000.0,
        }
    }

    fn bounds() -> SceneBounds {
        SceneBounds {
            min: DVec3::new(-20_000.0, -20_000.0, 0.0),
            max: DVec3::new(60_000.0, 60_000.0, 3_000.0),
        }
    }

    fn sun() -> Vec3 {
        crate::view::lighting::sun_direction(25.0, 231.0)
    }

    /// Atlas texel coordinates and depth of `p` in cascade `c`.
    fn atlas_texel(c: &Cascade, p: DVec3, size: f64) -> DVec3 {
        let q = c.view_proj * p.extend(1.0);
        DVec3::new((q.x * 0.5 + 0.5) * size, (q.y * 0.5 + 0.5) * size, q.z)
    }

    /// A point of the view frustum at view depth `d` and NDC `(u, v)`.
    fn frustum_point(cam: &Camera, aspect: f64, d: f64, u: f64, v: f64) -> DVec3 {
        let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
        cam.eye + cam.forward() * d + cam.right() * (u * t * aspect * d) + cam.image_up() * (v * t * d)
    }

    fn inside_receivers(c: &Cascade, t: DVec3, margin: f64) -> bool {
        let [x0, y0, x1, y1] = c.receivers.map(f64::from);
        t.x >= x0 + margin && t.x <= x1 + 1.0 - margin && t.y >= y0 + margin && t.y <= y1 + 1.0 - margin
    }

    /// The receivers' box is smaller than the quadrant: the casters skip
    /// the texels no receiver reads.
    #[test]
    fn receivers_cover_less_than_the_quadrant() {
        let settings = ShadowSettings::default();
        let cam = camera(DVec3::new(100.0, 200.0, 900.0), DVec3::new(5000.0, 9000.0, 400.0));
        let plan = plan_cascades(&cam, 16.0 / 9.0, sun(), bounds(), &settings).unwrap();
        let quadrant = f64::from(settings.quadrant()).powi(2);
        let share: Vec<f64> = (plan.cascades.iter())
            .map(|c| {
                f64::from((c.receivers[2] + 1 - c.receivers[0]) * (c.receivers[3] + 1 - c.receivers[1])) / quadrant
            })
            .collect();
        assert!(share.iter().all(|&s| s > 0.0 && s <= 1.0), "{share:?}");
        assert!(share.iter().sum::<f64>() < 0.8 * share.len() as f64, "{share:?}");
    }

    fn inside_quadrant(i: usize, t: DVec3, size: f64, margin: f64) -> bool {
        let q = size / 2.0;
        let (x0, y0) = ((i % 2) as f64 * q, (i / 2) as f64 * q);
        t.x >= x0 + margin && t.x <= x0 + q - margin && t.y >= y0 + margin && t.y <= y0 + q - margin
    }

    #[test]
    fn splits_cover_near_to_distance_contiguously() {
        let s = split_depths(1.0, 30_000.0, 4, 0.75);
        assert_eq!(s.len(), 5);
        assert!((s[0] - 1.0).abs() < 1e-9 && (s[4] - 30_000.0).abs() < 1e-6);
        assert!(s.windows(2).all(|w| w[1] > w[0]));
        let cam = camera(DVec3::new(100.0, 200.0, 900.0), DVec3::new(5000.0, 9000.0, 400.0));
        let plan = plan_cascades(&cam, 16.0 / 9.0, sun(), bounds(), &ShadowSettings::default()).unwrap();
        assert_eq!(plan.cascades.len(), 4);
        assert_eq!(plan.cascades[0].near, cam.near);
        assert!(
            (plan.cascades[3].far - 30_000.0).abs() < 1e-6,
            "capped at the shadow distance"
        );
        for w in plan.cascades.windows(2) {
            assert_eq!(w[0].far, w[1].near, "no gap between cascades");
        }
    }

    #[test]
    fn every_frustum_point_is_inside_its_cascade() {
        let settings = ShadowSettings::default();
        let size = f64::from(settings.atlas_size);
        let aspect = 16.0 / 9.0;
        for (eye, target) in [
            (DVec3::new(100.0, 200.0, 900.0), DVec3::new(5000.0, 9000.0, 400.0)),
            (
                DVec3::new(-3000.0, 7.0, 50.0),
                DVec3::new(-3000.0, 7.0, -1000.0) + DVec3::X,
            ),
        ] {
            let cam = camera(eye, target);
            let plan = plan_cascades(&cam, aspect, sun(), bounds(), &settings).unwrap();
            let mut rng = crate::random::SplitMix64(3);
            for _ in 0..20_000 {
                let d = cam.near + (30_000.0 - cam.near) * rng.next_f64().powi(3);
                let (u, v) = (2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0);
                let p = frustum_point(&cam, aspect, d, u, v);
                let i = plan
                    .cascades
                    .iter()
                    .position(|c| d <= c.far)
                    .expect("within the distance");
                let c = &plan.cascades[i];
                let t = atlas_texel(c, p, size);
                let margin = f64::from(settings.pcf_radius) + 1.5;
                assert!(inside_quadrant(i, t, size, margin), "cascade {i}: {p} → {t}");
                assert!(t.z > 0.0 && t.z < 1.0, "depth {}", t.z);
                // The casters draw every texel its PCF tent reads; in the
                // blend band the next cascade's too.
                assert!(
                    inside_receivers(c, t, margin),
                    "cascade {i}: {p} → {t}, {:?}",
                    c.receivers
                );
                if let Some(next) = plan.cascades.get(i + 1).filter(|_| d > c.far - 0.1 * (c.far - c.near)) {
                    let t = atlas_texel(next, p, size);
                    assert!(inside_receivers(next, t, margin), "blend into {}: {t}", i + 1);
                }
            }
            // Every corner of every slice.
            for (i, c) in plan.cascades.iter().enumerate() {
                for d in [c.near, c.far] {
                    for (u, v) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                        let t = atlas_texel(c, frustum_point(&cam, aspect, d, u, v), size);
                        assert!(inside_quadrant(i, t, size, 0.0), "corner of slice {i}: {t}");
                    }
                }
            }
        }
    }

    #[test]
    fn casters_between_the_slice_and_the_sun_are_in_depth_range() {
        let cam = camera(DVec3::new(100.0, 200.0, 900.0), DVec3::new(5000.0, 9000.0, 400.0));
        let settings = ShadowSettings::default();
        let plan = plan_cascades(&cam, 1.5, sun(), bounds(), &settings).unwrap();
        let s = plan.sun;
        for c in &plan.cascades {
            // A point of the slice moved towards the sun until it reaches the top of the scene.
            let p = frustum_point(&cam, 1.5, 0.5 * (c.near + c.far), 0.3, -0.2);
            let high = p + s * ((3000.0 - p.z) / s.z);
            let t = atlas_texel(c, high, f64::from(settings.atlas_size));
            assert!(t.z >= 0.0 && t.z < 1.0, "{}", t.z);
        }
    }

    #[test]
    fn snapped_cascades_move_by_whole_texels() {
        let settings = ShadowSettings::default();
        let size = f64::from(settings.atlas_size);
        let base = camera(DVec3::new(100.0, 200.0, 900.0), DVec3::new(5000.0, 9000.0, 400.0));
        let a = plan_cascades(&base, 1.5, sun(), bounds(), &settings).unwrap();
        let probe = DVec3::new(1234.5, 2345.25, 812.0);
        for (dx, turn) in [
            (DVec3::new(3.3, -7.1, 0.4), 0.0),
            (DVec3::new(-211.7, 95.03, 12.0), 0.4),
        ] {
            let mut moved = base;
            moved.eye += dx;
            let dir = base.target - base.eye;
            let (s, c) = f64::sin_cos(turn);
            moved.target = moved.eye + DVec3::new(c * dir.x - s * dir.y, s * dir.x + c * dir.y, dir.z);
            let b = plan_cascades(&moved, 1.5, sun(), bounds(), &settings).unwrap();
            for (ca, cb) in a.cascades.iter().zip(&b.cascades) {
                assert_eq!(ca.texel, cb.texel, "rotation- and translation-invariant size");
                let (ta, tb) = (atlas_texel(ca, probe, size), atlas_texel(cb, probe, size));
                for d in [tb.x - ta.x, tb.y - ta.y] {
                    assert!((d - d.round()).abs() < 1e-3, "moved by {d} texels");
                }
            }
        }
    }

    #[test]
    fn fill_writes_the_lighting_frame() {
        let cam = camera(DVec3::new(0.0, 0.0, 500.0), DVec3::new(1000.0, 0.0, 400.0));
        let settings = ShadowSettings {
            cascades: 3,
            ..ShadowSettings::default()
        };
        let plan = plan_cascades(&cam, 1.0, sun(), bounds(), &settings).unwrap();
        let mut frame = bytemuck::Zeroable::zeroed();
        plan.fill(&mut frame);
        let f: LightingFrame = frame;
        assert_eq!(f.shadows, [0, 3, 4096, 2]);
        assert_eq!(f.cascade_far[2], 30_000.0);
        assert_eq!(f.cascade_far[3], 0.0);
        assert!(f.cascade_texel[0] > 0.0 && f.cascade_texel[0] < f.cascade_texel[1]);
        let below = plan_cascades(&cam, 1.0, Vec3::new(0.3, 0.2, -0.1), bounds(), &settings).unwrap();
        assert_eq!(below.count(), 0, "no cascade when the sun is down");
    }

    #[test]
    fn bad_settings_are_named() {
        let bad = |s: ShadowSettings| s.validate().unwrap_err().parameter().map(str::to_string);
        let s = ShadowSettings::default();
        assert!(s.validate().is_ok());
        assert_eq!(
            bad(ShadowSettings { cascades: 5, ..s }).as_deref(),
            Some("shadows.cascades")
        );
        assert_eq!(
            bad(ShadowSettings { atlas_size: 1001, ..s }).as_deref(),
            Some("shadows.atlas_size")
        );
        assert_eq!(
            bad(ShadowSettings { lambda: 1.5, ..s }).as_deref(),
            Some("shadows.lambda")
        );
    }
}
