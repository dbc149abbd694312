//! The `--terrain procedural:MODEL[,key=value...]` command-line value.
//!
//! ```text
//! procedural:ridged,seed=7,octaves=8,lacunarity=2,h=1,offset=1,gain=2,wavelength=2500,amplitude=600,size=513,spacing=20
//! ```
//!
//! `MODEL` is one of the [`TerrainModel::name`]s; the keys ([`KEYS`]) are optional, each
//! at most once, and those not given take the values of
//! [`ProceduralTerrain::default`] (whatever the model), a 513×513 grid and
//! 20 m spacing. `size=N` gives an N×N grid (`size=C:R` for C columns and R
//! rows), `spacing=D` square cells (`spacing=DX:DY` for anisotropic ones).
//! [`TerrainSpec`]'s `Display` writes the canonical form, with every key,
//! which parses back to the same spec.

use std::fmt;
use std::str::FromStr;

use glam::DVec2;

use alpenglow::{Error, HeightField, ProceduralTerrain, Result, TerrainModel};

/// The prefix every spec starts with.
pub const PREFIX: &str = "procedural:";

/// Smallest accepted grid side in samples.
pub const MIN_SIZE: u32 = 2;
/// Largest accepted grid side in samples.
pub const MAX_SIZE: u32 = 8193;
/// Grid side when `size` is not given.
pub const DEFAULT_SIZE: u32 = 513;
/// Metres per sample when `spacing` is not given.
pub const DEFAULT_SPACING: f64 = 20.0;

/// The accepted keys, in canonical order.
pub const KEYS: [&str; 10] = [
    "seed",
    "octaves",
    "lacunarity",
    "h",
    "offset",
    "gain",
    "wavelength",
    "amplitude",
    "size",
    "spacing",
];

/// The accepted model names, comma-separated ([`TerrainModel::name`]).
fn model_names() -> String {
    TerrainModel::ALL.map(TerrainModel::name).join(", ")
}

/// A procedural terrain and the grid it is sampled on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TerrainSpec {
    pub terrain: ProceduralTerrain,
    /// Samples along x.
    pub columns: u32,
    /// Samples along y.
    pub rows: u32,
    /// Metres between samples along x and y.
    pub spacing: DVec2,
}

impl Default for TerrainSpec {
    /// `procedural:ridged` with every key at its default.
    fn default() -> Self {
        Self {
            terrain: ProceduralTerrain::default(),
            columns: DEFAULT_SIZE,
            rows: DEFAULT_SIZE,
            spacing: DVec2::splat(DEFAULT_SPACING),
        }
    }
}

impl TerrainSpec {
    /// Checks the terrain parameters ([`ProceduralTerrain::validate`]), the
    /// grid size ([`MIN_SIZE`]..=[`MAX_SIZE`] per side) and the spacing
    /// (the height field's range, [`alpenglow::files::check_spacing`]).
    pub fn validate(&self) -> Result<()> {
        self.terrain.validate()?;
        for (what, v) in [("columns", self.columns), ("rows", self.rows)] {
            if !(MIN_SIZE..=MAX_SIZE).contains(&v) {
                return Err(Error::invalid(
                    format!("terrain {what}"),
                    format!("{v} (must be in {MIN_SIZE}..={MAX_SIZE})"),
                ));
            }
        }
        alpenglow::files::check_spacing(self.spacing).map_err(|m| Error::invalid("spacing= of the terrain", m))?;
        Ok(())
    }

    /// Samples the terrain on the spec's grid.
    pub fn generate(&self) -> Result<HeightField> {
        self.validate()?;
        self.terrain.try_generate(self.columns, self.rows, self.spacing)
    }
}

fn usage() -> String {
    format!(
        "expected {PREFIX}MODEL[,key=value...] with MODEL one of {} and keys {}",
        model_names(),
        KEYS.join(", ")
    )
}

fn number<T: FromStr>(key: &str, value: &str, kind: &str) -> std::result::Result<T, String> {
    value
        .parse()
        .map_err(|_| format!("--terrain: {key}={value}: '{value}' is not {kind}"))
}

/// One number, or two separated by `:`.
fn pair<T: FromStr + Copy>(key: &str, value: &str, kind: &str) -> std::result::Result<(T, T), String> {
    let bad = || format!("--terrain: {key}={value}: '{value}' is not {kind}");
    match value.split_once(':') {
        None => value.parse().map(|v| (v, v)).map_err(|_| bad()),
        Some((a, b)) => match (a.trim().parse(), b.trim().parse()) {
            (Ok(a), Ok(b)) => Ok((a, b)),
            _ => Err(bad()),
        },
    }
}

impl FromStr for TerrainSpec {
    type Err = String;

    /// Parses `procedural:MODEL[,key=value...]` (see the module
    /// documentation); the error is one line naming the bad part.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let s = s.trim();
        let body = s
            .strip_prefix(PREFIX)
            .ok_or_else(|| format!("--terrain '{s}': missing '{PREFIX}' prefix; {}", usage()))?;
        let mut parts = body.split(',').map(str::trim);
        let model_part = parts.next().unwrap_or_default();
        let model = TerrainModel::from_name(model_part)
            .ok_or_else(|| format!("--terrain: unknown model '{model_part}' (models: {})", model_names()))?;
        let mut spec = TerrainSpec {
            terrain: ProceduralTerrain {
                model,
                ..ProceduralTerrain::default()
            },
            ..TerrainSpec::default()
        };
        let mut seen = [false; KEYS.len()];
        for part in parts {
            let (key, value) = part
                .split_once('=')
                .map(|(k, v)| (k.trim(), v.trim()))
                .ok_or_else(|| format!("--terrain: '{part}' is not key=value (keys: {})", KEYS.join(", ")))?;
            let index = KEYS
                .iter()
                .position(|&k| k == key)
                .ok_or_else(|| format!("--terrain: unknown key '{key}' (keys: {})", KEYS.join(", ")))?;
            if std::mem::replace(&mut seen[index], true) {
                return Err(format!("--terrain: key '{key}' given more than once"));
            }
            let t = &mut spec.terrain;
            let real = "a number";
            match key {
                "seed" => t.seed = number(key, value, "an unsigned 64-bit integer")?,
                "octaves" => t.octaves = number(key, value, "an unsigned integer")?,
                "lacunarity" => t.lacunarity = number(key, value, real)?,
                "h" => t.h = number(key, value, real)?,
                "offset" => t.offset = number(key, value, real)?,
                "gain" => t.gain = number(key, value, real)?,
                "wavelength" => t.base_wavelength = number(key, value, real)?,
                "amplitude" => t.amplitude = number(key, value, real)?,
                "size" => {
                    (spec.columns, spec.rows) = pair(key, value, "N or COLUMNS:ROWS (unsigned integers)")?;
                }
                "spacing" => {
                    let (dx, dy) = pair(key, value, "D or DX:DY (numbers)")?;
                    spec.spacing = DVec2::new(dx, dy);
                }
                _ => return Err(format!("--terrain: unknown key '{key}' (keys: {})", KEYS.join(", "))),
            }
        }
        spec.validate().map_err(|e| format!("--terrain '{s}': {e}"))?;
        Ok(spec)
    }
}

impl fmt::Display for TerrainSpec {
    /// The canonical spec with every key; parses back to `self`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = &self.terrain;
        write!(
            f,
            "{PREFIX}{},seed={},octaves={},lacunarity={},h={},offset={},gain={},wavelength={},amplitude={}",
            t.model.name(),
            t.seed,
            t.octaves,
            t.lacunarity,
            t.h,
            t.offset,
            t.gain,
            t.base_wavelength,
            t.amplitude
        )?;
        if self.columns == self.rows {
            write!(f, ",size={}", self.columns)?;
        } else {
            write!(f, ",size={}:{}", self.columns, self.rows)?;
        }
        if self.spacing.x == self.spacing.y {
            write!(f, ",spacing={}", self.spacing.x)
        } else {
            write!(f, ",spacing={}:{}", self.spacing.x, self.spacing.y)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> std::result::Result<TerrainSpec, String> {
        s.parse()
    }

    #[test]
    fn full_example_parses() {
        let spec = parse(
            "procedural:ridged,seed=7,octaves=8,lacunarity=2,h=1,offset=1,gain=2,wavelength=2500,\
             amplitude=600,size=513,spacing=20",
        )
        .unwrap();
        let expect = TerrainSpec {
            terrain: ProceduralTerrain {
                seed: 7,
                ..ProceduralTerrain::default()
            },
            ..TerrainSpec::default()
        };
        assert_eq!(spec, expect);
    }

    #[test]
    fn defaults_and_models() {
        assert_eq!(parse("procedural:ridged").unwrap(), TerrainSpec::default());
        for (name, model) in TerrainModel::ALL.map(|m| m.name()).iter().zip(TerrainModel::ALL) {
            let spec = parse(&format!("procedural:{name}")).unwrap();
            let expect = ProceduralTerrain {
                model,
                ..ProceduralTerrain::default()
            };
            assert_eq!(spec.terrain, expect);
            assert_eq!(model.name(), *name);
        }
        let spec = parse(" procedural:fbm, h = 0.5 ,size=65:33,spacing=10:12.5 ").unwrap();
        assert_eq!(spec.terrain.model, TerrainModel::Fbm);
        assert_eq!(spec.terrain.h, 0.5);
        assert_eq!((spec.columns, spec.rows), (65, 33));
        assert_eq!(spec.spacing, DVec2::new(10.0, 12.5));
    }

    #[test]
    fn round_trip() {
        let spec = TerrainSpec {
            terrain: ProceduralTerrain {
                model: TerrainModel::Hybrid,
                seed: u64::MAX,
                octaves: 11,
                lacunarity: 2.137,
                h: 0.1 + 0.2,
                offset: 0.7,
                gain: -1.5,
                base_wavelength: 1234.5678,
                amplitude: 1e-3,
            },
            columns: 8193,
            rows: 2,
            spacing: DVec2::new(0.3, 1e5),
        };
        let text = spec.to_string();
        assert_eq!(parse(&text).unwrap(), spec, "{text}");
        let square = TerrainSpec::default();
        assert_eq!(parse(&square.to_string()).unwrap(), square);
        assert!(square.to_string().ends_with(",size=513,spacing=20"));
    }

    #[test]
    fn bad_specs_are_rejected_with_a_useful_message() {
        let err = |s: &str| parse(s).unwrap_err();
        let e = err("ridged,seed=1");
        assert!(
            e.contains("missing 'procedural:' prefix") && e.contains("fbm, multifractal"),
            "{e}"
        );
        let e = err("procedural:perlin");
        assert!(
            e.contains("unknown model 'perlin'") && e.contains("heterogeneous"),
            "{e}"
        );
        assert!(err("procedural:").contains("unknown model ''"));
        let e = err("procedural:fbm,colour=red");
        assert!(e.contains("unknown key 'colour'") && e.contains("wavelength"), "{e}");
        let e = err("procedural:fbm,seed=1,seed=2");
        assert!(e.contains("key 'seed' given more than once"), "{e}");
        let e = err("procedural:fbm,seed");
        assert!(e.contains("'seed' is not key=value"), "{e}");
        let e = err("procedural:fbm,octaves=-3");
        assert!(e.contains("octaves=-3") && e.contains("unsigned integer"), "{e}");
        assert!(err("procedural:fbm,seed=1.5").contains("seed=1.5"));
        assert!(err("procedural:fbm,h=abc").contains("h=abc"));
        assert!(err("procedural:fbm,spacing=1:x").contains("spacing=1:x"));
        assert!(err("procedural:fbm,,seed=1").contains("is not key=value"));
        for e in [err("procedural:fbm,octaves=0"), err("procedural:fbm,octaves=33")] {
            assert!(e.contains("octaves"), "{e}");
        }
        assert!(err("procedural:fbm,lacunarity=1").contains("lacunarity"));
        assert!(err("procedural:fbm,wavelength=0").contains("wavelength"));
        assert!(err("procedural:fbm,gain=nan").contains("gain"));
        assert!(err("procedural:fbm,amplitude=inf").contains("amplitude"));
        assert!(err("procedural:fbm,size=1").contains("columns"));
        assert!(err("procedural:fbm,size=8194").contains("8193"));
        assert!(err("procedural:fbm,size=9:8194").contains("rows"));
        assert!(err("procedural:fbm,spacing=0").contains("spacing"));
        assert!(err("procedural:fbm,spacing=1:inf").contains("spacing"));
        for s in ["x", "procedural:fbm,seed=1,seed=2", "procedural:fbm,octaves=0"] {
            assert!(!err(s).contains('\n'));
        }
    }

    #[test]
    fn generate_uses_the_grid() {
        let spec = parse("procedural:fbm,octaves=3,size=9:5,spacing=30:40").unwrap();
        let field = spec.generate().unwrap();
        assert_eq!(
            (field.columns, field.rows, field.spacing),
            (9, 5, DVec2::new(30.0, 40.0))
        );
        assert_eq!(field, spec.terrain.generate(9, 5, spec.spacing));
        let bad = TerrainSpec { columns: 1, ..spec };
        assert!(bad.generate().is_err());
    }
}
