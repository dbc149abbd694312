//! `Lighting`: the sun (by angles or by date, time and place), the sky
//! model, exposure, shadows and sky light of a frame.

use pyo3::prelude::*;

use crate::engine;
use crate::{arg_err, invalid};

/// The lighting of a frame. Keywords mirror the library's `Lighting` and
/// the CLI's lighting options: `sun_elevation`/`sun_azimuth` (degrees;
/// azimuth clockwise from +Y, north), `sky` ("physical", "preetham",
/// "cie-clear" or "cie-overcast"),
/// `turbidity`, `exposure` ("auto" or an EV100 number), `shadows`
/// ("cascaded", "horizon", "off"), `sun_disc` ("hard", or "soft": the
/// penumbra of the sun's disc), `sky_light` ("sh", "ao", "patches",
/// "reference", "off"), `aerial_perspective`. `Lighting.time_of_day(…)`
/// places the sun by date, time and place.
#[pyclass(module = "alpenglow", frozen, from_py_object)]
#[derive(Clone)]
pub struct Lighting {
    pub(crate) inner: engine::Lighting,
}

fn sky(name: &str) -> PyResult<engine::SkyModel> {
    match name {
        "physical" => Ok(engine::SkyModel::Physical),
        "preetham" => Ok(engine::SkyModel::Preetham),
        "cie-clear" => Ok(engine::SkyModel::CieClear),
        "cie-overcast" => Ok(engine::SkyModel::CieOvercast),
        _ => Err(invalid(
            "sky",
            format!("{name:?}; expected \"physical\", \"preetham\", \"cie-clear\" or \"cie-overcast\""),
        )),
    }
}

fn shadows(name: &str) -> PyResult<engine::ShadowMode> {
    match name {
        "cascaded" => Ok(engine::ShadowMode::Cascaded),
        "horizon" => Ok(engine::ShadowMode::Horizon),
        "off" => Ok(engine::ShadowMode::Off),
        _ => Err(invalid(
            "shadows",
            format!("{name:?}; expected \"cascaded\", \"horizon\" or \"off\""),
        )),
    }
}

fn sun_disc(name: &str) -> PyResult<engine::SunDisc> {
    match name {
        "hard" => Ok(engine::SunDisc::Hard),
        "soft" => Ok(engine::SunDisc::Soft),
        _ => Err(invalid("sun_disc", format!("{name:?}; expected \"hard\" or \"soft\""))),
    }
}

fn sky_light(name: &str) -> PyResult<engine::SkyLightMode> {
    match name {
        "sh" => Ok(engine::SkyLightMode::Sh),
        "ao" => Ok(engine::SkyLightMode::Ao),
        "patches" => Ok(engine::SkyLightMode::Patches),
        "reference" => Ok(engine::SkyLightMode::Reference),
        "off" => Ok(engine::SkyLightMode::Off),
        _ => Err(invalid(
            "sky_light",
            format!("{name:?}; expected \"sh\", \"ao\", \"patches\", \"reference\" or \"off\""),
        )),
    }
}

fn exposure(value: &Bound<'_, PyAny>) -> PyResult<engine::Exposure> {
    if let Ok(ev) = value.extract::<f32>() {
        if !ev.is_finite() {
            return Err(invalid("exposure", format!("{ev}; must be finite")));
        }
        return Ok(engine::Exposure::Ev100(ev));
    }
    match value.extract::<String>().as_deref() {
        Ok("auto") => Ok(engine::Exposure::Auto),
        _ => Err(invalid("exposure", "expected \"auto\" or an EV100 number")),
    }
}

#[pymethods]
impl Lighting {
    #[new]
    #[pyo3(signature = (*, sun_elevation = 25.0, sun_azimuth = 231.0, sky = "physical", turbidity = 3.0, exposure = None, shadows = "cascaded", sun_disc = "hard", sky_light = "sh", aerial_perspective = true))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        sun_elevation: f32,
        sun_azimuth: f32,
        sky: &str,
        turbidity: f32,
        exposure: Option<&Bound<'_, PyAny>>,
        shadows: &str,
        sun_disc: &str,
        sky_light: &str,
        aerial_perspective: bool,
    ) -> PyResult<Lighting> {
        let inner = engine::Lighting {
            sun: engine::SunPosition::Angles {
                elevation_deg: sun_elevation,
                azimuth_deg: sun_azimuth,
            },
            sky: self::sky(sky)?,
            turbidity,
            exposure: exposure.map(self::exposure).transpose()?.unwrap_or_default(),
            shadows: self::shadows(shadows)?,
            sun_disc: self::sun_disc(sun_disc)?,
            sky_light: self::sky_light(sky_light)?,
            aerial_perspective,
            ..engine::Lighting::default()
        };
        inner.validate().map_err(arg_err)?;
        Ok(Lighting { inner })
    }

    /// This lighting with the sun at `date` ("YYYY-MM-DD"), `time`
    /// ("HH:MM[:SS]", mean local solar time, or civil time at `utc_offset`
    /// hours east of UTC), `latitude` and `longitude` (degrees, north and
    /// east positive).
    #[pyo3(signature = (date, time, latitude, longitude, utc_offset = None))]
    fn time_of_day(
        &self,
        date: &str,
        time: &str,
        latitude: f32,
        longitude: f32,
        utc_offset: Option<f32>,
    ) -> PyResult<Lighting> {
        let day = engine::parse_date(date).map_err(arg_err)?;
        let minutes = engine::parse_time(time).map_err(arg_err)?;
        let clock = match utc_offset {
            Some(h) if !(h.is_finite() && (-14.0..=14.0).contains(&h)) => {
                return Err(invalid("utc_offset", format!("{h}; must be in -14..=14 hours")))
            }
            Some(h) => engine::Clock::UtcOffset(h),
            None => engine::Clock::MeanSolar,
        };
        let sun = engine::solar_position(day.year, day.day_of_year(), minutes, latitude, longitude, clock)
            .map_err(arg_err)?;
        let inner = engine::Lighting {
            sun: sun.position(),
            ..self.inner
        };
        inner.validate().map_err(arg_err)?;
        Ok(Lighting { inner })
    }

    /// The unit direction towards the sun (+Z up).
    #[getter]
    fn sun_direction(&self) -> (f32, f32, f32) {
        self.inner.sun_direction().into()
    }

    fn __repr__(&self) -> String {
        let d = self.inner.sun_direction();
        format!(
            "Lighting(sun_direction=({:.4}, {:.4}, {:.4}), sky={:?}, exposure={:?})",
            d.x, d.y, d.z, self.inner.sky, self.inner.exposure
        )
    }
}
