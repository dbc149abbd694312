//! The CPU twin of the Monte Carlo reference (§9.2): the estimator of
//! `glsl/lighting/reference.comp` for single texels, with the exact ray
//! caster of [`super::HeightFieldTracer`] and the sky as a closure, for
//! validation (analytic cases and the GPU pass).

use glam::{DVec3, Vec3};

use super::sampling::{bounce_dimension, cosine_direction, disc_direction, hammersley, random, texel_key};
use super::{horizon_clamp, ray_offset, HeightFieldTracer, ReferenceSettings};
use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::lighting::constants::{LightingFrame, LIGHTING_ALBEDO_OVERRIDE, LIGHTING_SUN_IN_ENVIRONMENT};

/// The sun as the reference sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunInput {
    /// Unit vector towards the sun.
    pub direction: Vec3,
    /// Angular radius of the disc (rad).
    pub angular_radius: f32,
    /// Irradiance of the whole disc on a plane facing it.
    pub irradiance: Vec3,
    /// `LIGHTING_SUN_IN_ENVIRONMENT`: the direct sun at `x` is in the map.
    pub in_environment: bool,
}

impl SunInput {
    /// The sun of a frame's lighting constants, and the bounce albedo they
    /// ask for (the override when flagged, else `default_albedo`).
    pub fn from_frame(frame: &LightingFrame, default_albedo: f32) -> (SunInput, f32) {
        let flags = frame.models[3];
        let sun = SunInput {
            direction: Vec3::new(frame.sun[0], frame.sun[1], frame.sun[2]),
            angular_radius: frame.sun[3],
            irradiance: Vec3::new(
                frame.sun_irradiance[0],
                frame.sun_irradiance[1],
                frame.sun_irradiance[2],
            ),
            in_environment: flags & LIGHTING_SUN_IN_ENVIRONMENT != 0,
        };
        let albedo = if flags & LIGHTING_ALBEDO_OVERRIDE != 0 {
            frame.exposure[3]
        } else {
            default_albedo
        };
        (sun, albedo)
    }
}

/// One texel's estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelEstimate {
    /// Sky light per unit albedo (the map's rgb).
    pub sky_light: Vec3,
    /// Fraction of cosine-weighted rays that escape (the map's a).
    pub sky_visibility: f32,
    /// Fraction of shadow rays over the sun's disc that escape.
    pub sun_visibility: f32,
    /// Standard error of `sky_light` (sample standard deviation / √N).
    pub standard_error: Vec3,
}

/// The Monte Carlo reference on the CPU for single texels (§9.2).
#[derive(Clone, Debug)]
pub struct CpuReference<'a> {
    tracer: HeightFieldTracer<'a>,
    settings: ReferenceSettings,
    offset: f64,
}

impl<'a> CpuReference<'a> {
    /// Validates the field and the settings.
    pub fn new(field: &'a HeightField, settings: ReferenceSettings) -> Result<Self> {
        settings.validate()?;
        Ok(CpuReference {
            tracer: HeightFieldTracer::new(field)?,
            settings,
            offset: f64::from(ray_offset(field)),
        })
    }

    /// Whether the ray from `p` (lifted) along `dir` escapes.
    fn escapes(&self, p: DVec3, dir: Vec3) -> bool {
        self.tracer.trace(p + DVec3::Z * self.offset, dir.as_dvec3()).is_none()
    }

    /// The estimate at texel `(c, r)` under `sun` and the sky `sky` (radiance
    /// along a unit direction with z ≥ 0, without the sun's disc), bounce
    /// albedo `albedo` (see [`SunInput::from_frame`]).
    pub fn texel(
        &self,
        c: u32,
        r: u32,
        sun: &SunInput,
        albedo: f32,
        sky: &dyn Fn(Vec3) -> Vec3,
    ) -> Result<TexelEstimate> {
        let field = self.tracer.field();
        if c >= field.columns || r >= field.rows {
            return Err(Error::invalid(
                "lighting.reference.texel",
                format!("({c}, {r}) outside the {}×{} field", field.columns, field.rows),
            ));
        }
        let n = self.settings.samples;
        let key = texel_key(self.settings.seed, c, r);
        let x = self.tracer.sample_position(c, r);
        let normal = self.tracer.vertex_normal(c.into(), r.into()).as_vec3();
        let sun_term = sun.irradiance / std::f32::consts::PI;
        let bounced_sun = sun.in_environment || self.settings.sun_bounces;
        let (mut sum, mut sum_sq) = (Vec3::ZERO, Vec3::ZERO);
        let (mut escaped, mut sun_seen) = (0u32, 0u32);
        for s in 0..n {
            let mut value = Vec3::ZERO;
            // The shadow ray at x: sun visibility, and the direct sun when
            // it is part of the environment.
            let towards = disc_direction(sun.direction, sun.angular_radius, hammersley(key, s, n, 1));
            if self.escapes(x, towards) {
                sun_seen += 1;
                if sun.in_environment {
                    value += sun_term * normal.dot(sun.direction).max(0.0);
                }
            }
            let mut dir = cosine_direction(normal, hammersley(key, s, n, 0));
            let (mut origin, mut throughput) = (x, 1.0f32);
            for vertex in 0..=self.settings.bounces {
                let Some(hit) = self.tracer.trace(origin + DVec3::Z * self.offset, dir.as_dvec3()) else {
                    value += throughput * sky(horizon_clamp(dir));
                    escaped += u32::from(vertex == 0);
                    break;
                };
                if vertex == self.settings.bounces {
                    break;
                }
                throughput *= albedo;
                let n_y = self.tracer.normal_at(hit.grid).as_vec3();
                let dim = bounce_dimension(vertex + 1);
                let cos_sun = n_y.dot(sun.direction);
                if bounced_sun && cos_sun > 0.0 {
                    let u = [random(key, s, dim + 2), random(key, s, dim + 3)];
                    if self.escapes(hit.position, disc_direction(sun.direction, sun.angular_radius, u)) {
                        value += throughput * sun_term * cos_sun;
                    }
                }
                dir = cosine_direction(n_y, [random(key, s, dim), random(key, s, dim + 1)]);
                origin = hit.position;
            }
            sum += value;
            sum_sq += value * value;
        }
        let inv = 1.0 / n as f32;
        let mean = sum * inv;
        let variance = (sum_sq * inv - mean * mean).max(Vec3::ZERO) * (n as f32 / (n.max(2) - 1) as f32);
        Ok(TexelEstimate {
            sky_light: mean,
            sky_visibility: escaped as f32 * inv,
            sun_visibility: sun_seen as f32 * inv,
            standard_error: (variance * inv).powf(0.5),
        })
    }
}
