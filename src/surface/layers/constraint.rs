//! The constraint functions F of a layer (dissertation §8.2 hat functions,
//! §8.3 sampled functions; `ALGORITHMS.md` §4–§5) and their file format.
//!
//! A constraint is either a hat `{ min, max, fuzz }` or a sampled function
//! `{ samples = [s_0, …, s_{n−1}], min, max }`: n values (1 ≤ n ≤
//! [`MAX_SAMPLES`], each finite in [0, 1]) at the centres of n equal bins
//! over [min, max] (min < max):
//!
//! ```text
//! x_i  = min + (i + ½)·(max − min)/n
//! t(a) = clamp((a − min)/(max − min)·n − ½, 0, n − 1),  i = ⌊t⌋,  u = t − i
//! F(a) = s_i·(1 − u) + s_min(i+1, n−1)·u      for a in [min, max]
//! F(a) = 0                                   outside [min, max] and for NaN
//! ```
//!
//! so F interpolates linearly between neighbouring centres and holds the end
//! sample's value in the outer half-bins. The domain defaults to [0, 90]
//! degrees for `slope` and [0, 1] for `elevation`; `altitude` and the input
//! maps need `min` and `max`. The GPU evaluates the same f32 formula
//! (`constraint` in `glsl/include/surface_layers.glsl`).

use serde::Deserialize;

/// Most samples of a sampled function.
pub const MAX_SAMPLES: usize = 64;
/// Largest magnitude of a constraint's min, max and fuzz (metres for
/// altitude, degrees for slope, the maps' own units).
pub const MAX_HAT_VALUE: f32 = 1e7;

/// A hat function over an attribute (§8.2): 1 inside [min, max], ramps of
/// half-width `fuzz` around the ends.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hat {
    pub min: f32,
    pub max: f32,
    #[serde(default)]
    pub fuzz: f32,
}

impl Hat {
    /// F(a) (`layers` module docs); 0 for NaN (an absent input).
    pub fn eval(&self, a: f32) -> f32 {
        if a.is_nan() {
            return 0.0;
        }
        if self.fuzz <= 0.0 {
            return if a >= self.min && a <= self.max { 1.0 } else { 0.0 };
        }
        let f1 = (a - (self.min - self.fuzz)) / (2.0 * self.fuzz);
        let f2 = ((self.max + self.fuzz) - a) / (2.0 * self.fuzz);
        f1.min(f2).clamp(0.0, 1.0)
    }

    fn validate(&self) -> Result<(), String> {
        if !(self.min.is_finite() && self.max.is_finite() && self.fuzz.is_finite()) {
            return Err("range and fuzz must be finite".into());
        }
        if [self.min, self.max, self.fuzz].iter().any(|v| v.abs() > MAX_HAT_VALUE) {
            return Err(format!("range and fuzz must lie within ±{MAX_HAT_VALUE}"));
        }
        if self.min > self.max {
            return Err(format!("min {} is above max {}", self.min, self.max));
        }
        if self.fuzz < 0.0 {
            return Err(format!("fuzz {} is negative", self.fuzz));
        }
        Ok(())
    }
}

/// A function sampled at the centres of equal bins over [min, max] (§8.3:
/// the scaled histogram of where a class occurs), interpolated linearly
/// (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct SampledFunction {
    pub min: f32,
    pub max: f32,
    /// 1 to [`MAX_SAMPLES`] values in [0, 1].
    pub samples: Vec<f32>,
}

impl SampledFunction {
    /// F(a) (module docs); 0 outside [min, max] and for NaN.
    pub fn eval(&self, a: f32) -> f32 {
        let n = self.samples.len();
        if n == 0 || !(a >= self.min && a <= self.max) {
            return 0.0;
        }
        let last = (n - 1) as f32;
        let t = ((a - self.min) / (self.max - self.min) * n as f32 - 0.5).clamp(0.0, last);
        let i = t.floor();
        let u = t - i;
        let k = (i as usize).min(n - 1);
        let lo = self.samples[k];
        let hi = self.samples[(k + 1).min(n - 1)];
        lo * (1.0 - u) + hi * u
    }
}

/// One constraint of a layer: F_i of the product Π F_i.
#[derive(Clone, Debug, PartialEq)]
pub enum Constraint {
    Hat(Hat),
    Sampled(SampledFunction),
}

impl Constraint {
    /// F(a); 0 for NaN (an absent input).
    pub fn eval(&self, a: f32) -> f32 {
        match self {
            Constraint::Hat(h) => h.eval(a),
            Constraint::Sampled(s) => s.eval(a),
        }
    }
}

impl From<Hat> for Constraint {
    fn from(h: Hat) -> Constraint {
        Constraint::Hat(h)
    }
}

/// A constraint as written in the file: a hat (min, max, fuzz) or a sampled
/// function (samples, min, max).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ConstraintFile {
    min: Option<f32>,
    max: Option<f32>,
    fuzz: Option<f32>,
    samples: Option<Vec<f32>>,
}

/// The domain of a sampled function on `key` when the file gives none.
fn default_domain(key: &str) -> Option<(f32, f32)> {
    match key {
        "slope" => Some((0.0, 90.0)),
        "elevation" => Some((0.0, 1.0)),
        _ => None,
    }
}

impl ConstraintFile {
    /// The validated constraint on attribute `key`; the error says why (one line).
    pub(super) fn into_constraint(self, key: &str) -> Result<Constraint, String> {
        let Some(samples) = self.samples else {
            let (Some(min), Some(max)) = (self.min, self.max) else {
                return Err("a hat needs min and max (or give samples)".into());
            };
            let hat = Hat {
                min,
                max,
                fuzz: self.fuzz.unwrap_or(0.0),
            };
            hat.validate()?;
            return Ok(Constraint::Hat(hat));
        };
        if self.fuzz.is_some() {
            return Err("fuzz belongs to hats, not to sampled functions".into());
        }
        if samples.is_empty() || samples.len() > MAX_SAMPLES {
            return Err(format!(
                "{} samples; a sampled function has 1 to {MAX_SAMPLES}",
                samples.len()
            ));
        }
        if let Some((i, v)) = samples.iter().enumerate().find(|(_, v)| !(0.0..=1.0).contains(*v)) {
            return Err(format!("sample {i} is {v}, not in [0, 1]"));
        }
        let (min, max) = match (self.min, self.max, default_domain(key)) {
            (Some(min), Some(max), _) => (min, max),
            (None, None, Some(domain)) => domain,
            (Some(min), None, Some((_, max))) => (min, max),
            (None, Some(max), Some((min, _))) => (min, max),
            _ => return Err("a sampled function needs min and max here".into()),
        };
        if !(min.is_finite() && max.is_finite() && min.abs() <= MAX_HAT_VALUE && max.abs() <= MAX_HAT_VALUE) {
            return Err(format!("min and max must be finite within ±{MAX_HAT_VALUE}"));
        }
        if min >= max {
            return Err(format!("min {min} is not below max {max}"));
        }
        Ok(Constraint::Sampled(SampledFunction { min, max, samples }))
    }
}
