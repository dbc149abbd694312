//! The lighting flags (§6.3, §9): sun position by angles, by date and place
//! or by a preset, sky model, turbidity, exposure, shadows, sky light.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use alpenglow::tools::solar::{parse_date, parse_time, solar_position, Clock, SkyPreset};
use alpenglow::{Exposure, Lighting, ShadowMode, SkyLightMode, SkyModel, SunDisc, SunPosition};

#[derive(Args, Debug, Clone, Default)]
#[command(next_help_heading = "Lighting")]
pub struct LightingArgs {
    /// Sun elevation above the horizon, degrees (-90..90).
    #[arg(long = "sun-elevation", allow_hyphen_values = true, value_name = "DEGREES")]
    pub sun_elevation: Option<f32>,
    /// Sun azimuth, degrees clockwise from +Y (north of the height field).
    #[arg(long = "sun-azimuth", allow_hyphen_values = true, value_name = "DEGREES")]
    pub sun_azimuth: Option<f32>,
    /// Date YYYY-MM-DD for the solar position (with --time, --latitude, --longitude).
    #[arg(long, value_name = "YYYY-MM-DD")]
    pub date: Option<String>,
    /// Local mean solar time HH:MM (with --date).
    #[arg(long, value_name = "HH:MM")]
    pub time: Option<String>,
    /// Latitude, degrees north (with --date).
    #[arg(long, allow_hyphen_values = true, value_name = "DEGREES")]
    pub latitude: Option<f32>,
    /// Longitude, degrees east (with --date).
    #[arg(long, allow_hyphen_values = true, value_name = "DEGREES")]
    pub longitude: Option<f32>,
    /// The text's environments of Fig. 9.3: morning (day 298 07:30) or noon (day 180 12:00), 49.6° N, T = 2.1.
    #[arg(long = "sky-preset", value_name = "morning|noon")]
    pub sky_preset: Option<String>,
    /// Atmospheric turbidity T (1.7..10; default 3, or the preset's).
    #[arg(long, value_name = "T")]
    pub turbidity: Option<f32>,
    /// Sky model.
    #[arg(long, value_enum, default_value_t = SkyArg::Physical, value_name = "MODEL")]
    pub sky: SkyArg,
    /// Exposure: EV100, or "auto" (metered from the frame).
    #[arg(long, default_value = "auto", allow_hyphen_values = true, value_name = "EV100|auto")]
    pub exposure: String,
    /// Sun shadows.
    #[arg(long, value_enum, default_value_t = ShadowArg::Cascaded, value_name = "METHOD")]
    pub shadows: ShadowArg,
    /// Sun shadow edges: the penumbra of the sun's 0.53° disc, or hard (the shadow filter only).
    #[arg(long = "sun-disc", value_enum, default_value_t = SunDiscArg::Hard, value_name = "EDGES")]
    pub sun_disc: SunDiscArg,
    /// Sky light on the terrain (§9.3–9.5).
    #[arg(long, value_enum, default_value_t = LightingArg::Sh, value_name = "METHOD")]
    pub lighting: LightingArg,
    /// Spherical-harmonic bands of --lighting sh: 3 or 5.
    #[arg(long = "sh-bands", default_value_t = 5, value_name = "BANDS", value_parser = clap::value_parser!(u32).range(0..))]
    pub sh_bands: u32,
    /// Interreflection bounces of the sky-light transfer: 0, 1 or 2.
    #[arg(long, default_value_t = 1, value_name = "COUNT", value_parser = clap::value_parser!(u32).range(0..))]
    pub bounces: u32,
    /// Sky patches per side of --lighting patches: 4 (16 patches) or 8 (64).
    #[arg(long = "sky-patches", default_value_t = 8, value_name = "SIDE", value_parser = clap::value_parser!(u32).range(0..))]
    pub sky_patches: u32,
    /// Render every surface with this albedo (1: white diffuse).
    #[arg(long = "albedo-override", value_name = "ALBEDO")]
    pub albedo_override: Option<f32>,
    /// Where the sky-light bake is cached (default: $XDG_CACHE_HOME/alpenglow
    /// or ~/.cache/alpenglow; "none": bake every time). Optional: a cache
    /// that cannot be read or written is a warning, and the render goes on.
    #[arg(long = "cache-dir", value_name = "DIR|none")]
    pub cache_dir: Option<PathBuf>,
}

/// The sky-light bake's cache folder of the arguments: `--cache-dir`, else
/// the default of [`default_cache_dir`] from the environment (its warning
/// logged). The cache is optional: None bakes every time.
pub fn cache_dir(args: &LightingArgs) -> Option<PathBuf> {
    match &args.cache_dir {
        Some(p) if p.as_os_str() == "none" => None,
        Some(p) => Some(p.clone()),
        None => {
            let (dir, warning) = default_cache_dir(std::env::var_os("XDG_CACHE_HOME"), std::env::var_os("HOME"));
            if let Some(w) = warning {
                log::warn!("{w}");
            }
            dir
        }
    }
}

/// The default cache folder as the XDG Base Directory specification has it:
/// `$XDG_CACHE_HOME/alpenglow` when that is an absolute path, else
/// `$HOME/.cache/alpenglow`; an empty variable counts as unset, and a
/// relative `XDG_CACHE_HOME` is ignored ("all paths set in these
/// environment variables must be absolute"), with a warning. Without a
/// usable `HOME` either there is no cache (and a warning: every run bakes).
pub fn default_cache_dir(
    xdg_cache_home: Option<std::ffi::OsString>,
    home: Option<std::ffi::OsString>,
) -> (Option<PathBuf>, Option<String>) {
    let set = |v: Option<std::ffi::OsString>| v.filter(|v| !v.is_empty()).map(PathBuf::from);
    let mut warning = None;
    if let Some(xdg) = set(xdg_cache_home) {
        if xdg.is_absolute() {
            return (Some(xdg.join("alpenglow")), None);
        }
        warning = Some(format!(
            "XDG_CACHE_HOME={} is not an absolute path; ignored, as the XDG Base Directory specification says",
            xdg.display()
        ));
    }
    match set(home) {
        Some(home) if home.is_absolute() => (Some(home.join(".cache").join("alpenglow")), warning),
        home => {
            let why = match home {
                Some(h) => format!("HOME={} is not an absolute path", h.display()),
                None => "HOME is not set".to_string(),
            };
            let w = match warning {
                Some(w) => format!("{w}, and {why}: no sky-light cache (--cache-dir DIR chooses one); every run bakes"),
                None => format!("no sky-light cache: {why} and XDG_CACHE_HOME is not set (--cache-dir DIR chooses one); every run bakes"),
            };
            (None, Some(w))
        }
    }
}

/// A renderer, with a progress bar while the sky-light transfer bakes.
pub fn renderer(
    ctx: &alpenglow::Context,
    scene: &alpenglow::Scene,
    settings: alpenglow::Settings,
) -> alpenglow::Result<alpenglow::Renderer> {
    let bar = indicatif::ProgressBar::new(1000);
    bar.set_style(
        indicatif::ProgressStyle::with_template("sky-light bake {bar:40} {percent:>3}% {elapsed}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let renderer = alpenglow::Renderer::with_progress(ctx, scene, settings, &mut |f| {
        bar.set_position((f.clamp(0.0, 1.0) * 1000.0) as u64)
    });
    bar.finish_and_clear();
    renderer
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SkyArg {
    /// Preetham/Perez analytic sky (§6.3).
    Preetham,
    /// Rayleigh + Mie + ozone lookup tables (Hillaire 2020).
    #[default]
    Physical,
    /// CIE clear sky (§6.3 eq. 6.18; Preetham's zenith and colours).
    CieClear,
    /// CIE overcast sky (§6.3 eq. 6.19): no direct sun, white sky light.
    CieOvercast,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ShadowArg {
    /// Cascaded shadow maps (terrain and points).
    #[default]
    Cascaded,
    /// Horizon maps of the height field.
    Horizon,
    Off,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SunDiscArg {
    /// Penumbrae of the disc (horizon map: disc fraction; cascades: blocker-distance filter).
    Soft,
    /// Edges as sharp as the shadow filter.
    #[default]
    Hard,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightingArg {
    /// Monte Carlo ray tracing of the height field (slow; still frames).
    Reference,
    /// Precomputed radiance transfer in spherical harmonics.
    #[default]
    Sh,
    /// Ambient occlusion with bent normals.
    Ao,
    /// Sky as constant patches with per-patch visibility.
    Patches,
    /// Unoccluded sky light.
    Off,
}

/// A one-line error naming `flag`.
fn bad(flag: &str, message: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("invalid {flag}: {message}")
}

/// The lighting of the arguments, on top of `base` (the scene's sun and
/// snow line).
pub fn lighting(args: &LightingArgs, base: Lighting) -> anyhow::Result<Lighting> {
    let mut l = Lighting {
        sky: match args.sky {
            SkyArg::Preetham => SkyModel::Preetham,
            SkyArg::Physical => SkyModel::Physical,
            SkyArg::CieClear => SkyModel::CieClear,
            SkyArg::CieOvercast => SkyModel::CieOvercast,
        },
        shadows: match args.shadows {
            ShadowArg::Cascaded => ShadowMode::Cascaded,
            ShadowArg::Horizon => ShadowMode::Horizon,
            ShadowArg::Off => ShadowMode::Off,
        },
        sun_disc: match args.sun_disc {
            SunDiscArg::Soft => SunDisc::Soft,
            SunDiscArg::Hard => SunDisc::Hard,
        },
        sky_light: match args.lighting {
            LightingArg::Reference => SkyLightMode::Reference,
            LightingArg::Sh => SkyLightMode::Sh,
            LightingArg::Ao => SkyLightMode::Ao,
            LightingArg::Patches => SkyLightMode::Patches,
            LightingArg::Off => SkyLightMode::Off,
        },
        sh_bands: args.sh_bands,
        bounces: args.bounces,
        sky_patches: args.sky_patches,
        albedo_override: args.albedo_override,
        ..base
    };
    l.exposure = match args.exposure.as_str() {
        "auto" => Exposure::Auto,
        ev => Exposure::Ev100(
            ev.parse::<f32>()
                .map_err(|_| bad("--exposure", format!("{ev:?}: expected an EV100 number or \"auto\"")))?,
        ),
    };
    sun_position(args, &mut l)?;
    if let Some(t) = args.turbidity {
        l.turbidity = t;
    }
    Ok(l)
}

/// The sun (and a preset's turbidity) of the arguments.
fn sun_position(args: &LightingArgs, l: &mut Lighting) -> anyhow::Result<()> {
    let angles = args.sun_elevation.is_some() || args.sun_azimuth.is_some();
    let place = args.date.is_some() || args.time.is_some() || args.latitude.is_some() || args.longitude.is_some();
    let preset = args.sky_preset.is_some();
    if (angles as u8 + place as u8 + preset as u8) > 1 {
        return Err(bad(
            "--sun-elevation/--date/--sky-preset",
            "give the sun by angles, by date and place, or by a preset, not several",
        ));
    }
    if angles {
        l.sun = SunPosition::Angles {
            elevation_deg: args.sun_elevation.unwrap_or(30.0),
            azimuth_deg: args.sun_azimuth.unwrap_or(180.0),
        };
    }
    if let Some(name) = &args.sky_preset {
        let preset = SkyPreset::parse(name)?;
        l.sun = preset.sun()?.position();
        l.turbidity = preset.turbidity();
    }
    if place {
        let (Some(date), Some(time), Some(latitude), Some(longitude)) =
            (&args.date, &args.time, args.latitude, args.longitude)
        else {
            return Err(bad(
                "--date/--time/--latitude/--longitude",
                "the sun by date and place needs all four",
            ));
        };
        let date = parse_date(date)?;
        let minutes = parse_time(time)?;
        let sun = solar_position(
            date.year,
            date.day_of_year(),
            minutes,
            latitude,
            longitude,
            Clock::MeanSolar,
        )?;
        l.sun = sun.position();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_cache_dir_follows_the_xdg_specification() {
        let v = |s: &str| Some(std::ffi::OsString::from(s));
        let dir = |d: &str| Some(PathBuf::from(d));
        assert_eq!(default_cache_dir(v("/c"), v("/h")), (dir("/c/alpenglow"), None));
        assert_eq!(default_cache_dir(None, v("/h")), (dir("/h/.cache/alpenglow"), None));
        assert_eq!(default_cache_dir(v(""), v("/h")), (dir("/h/.cache/alpenglow"), None));
        let (d, w) = default_cache_dir(v("rel/cache"), v("/h"));
        assert_eq!(d, dir("/h/.cache/alpenglow"));
        assert!(w.unwrap().contains("XDG_CACHE_HOME=rel/cache is not an absolute path"));
        for (xdg, home, needles) in [
            (None, None, ["HOME is not set", "XDG_CACHE_HOME is not set"]),
            (v(""), v(""), ["HOME is not set", "no sky-light cache"]),
            (v("rel"), None, ["XDG_CACHE_HOME=rel", "HOME is not set"]),
            (None, v("h"), ["HOME=h is not an absolute path", "no sky-light cache"]),
        ] {
            let (d, w) = default_cache_dir(xdg, home);
            let w = w.unwrap();
            assert_eq!(d, None);
            assert!(needles.iter().all(|n| w.contains(n)) && !w.contains('\n'), "{w}");
        }
    }
}
