//! The sun (§6.3, §9.5): where it is and what reaches the ground.
//!
//! Position (Fig. 9.3 gives its lighting environments as day of year, time
//! of day and turbidity): solar elevation and azimuth from the date, the
//! time, the latitude and the longitude.
//!
//! Colour ([`transmitted_sun`]): the extraterrestrial disc
//! ([`SUN_LUMINANCE_EXTRATERRESTRIAL`] is its mean luminance: × the disc's
//! solid angle it gives the solar illuminance constant, ≈ 133 klx) times the
//! spectral transmittances of Preetham, Shirley and Smits 1999, appendix
//! A.1, averaged over a few wavelengths per channel.
//!
//! Algorithm: NOAA's solar calculator spreadsheet (Global Monitoring
//! Laboratory), after Meeus, "Astronomical Algorithms" ch. 25: the sun's
//! apparent longitude and the obliquity from the Julian century give the
//! declination and the equation of time; valid 1901–2099, ≈ 0.01° against
//! NREL's SPA (no refraction, no parallax). It needs the year: Spencer's
//! 1971 one-year Fourier series (NOAA's "General Solar Position
//! Calculations") ignores the leap-year cycle and is off by up to ≈ 0.35°
//! in declination near the equinoxes. Where only a day of year is given
//! (the presets), the year is [`DEFAULT_YEAR`].
//!
//! Time convention ([`Clock`]): without a time zone the clock time is *mean
//! local solar time* (12:00 is the sun's mean transit at that longitude; the
//! longitude is then irrelevant and only the equation of time applies).
//! With a UTC offset (hours, east positive) it is civil time in that zone and
//! the longitude (degrees, east positive) matters:
//! `true solar minutes = clock + eqtime + 4·longitude − 60·offset`.
//! Azimuth: degrees clockwise from north (+Y), east = 90° (+X), as
//! [`crate::view::lighting::sun_direction`] takes it.

use glam::Vec3;

use super::constants::{SUN_ANGULAR_RADIUS, SUN_COLOUR_EXTRATERRESTRIAL, SUN_LUMINANCE_EXTRATERRESTRIAL};
use crate::error::{Error, Result};
use crate::view::lighting::{sun_direction, SunPosition};

/// The year of a day-of-year without one (the dissertation's).
pub const DEFAULT_YEAR: i32 = 2005;

/// How the clock time of a [`solar_position`] query is meant.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Clock {
    /// Mean local solar time at the place.
    #[default]
    MeanSolar,
    /// Civil time at this offset from UTC (hours, east positive).
    UtcOffset(f32),
}

/// The sun's position in the sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunAngles {
    /// Degrees above the horizon (negative: below).
    pub elevation_deg: f32,
    /// Degrees clockwise from north (+Y), in 0..360.
    pub azimuth_deg: f32,
}

impl SunAngles {
    /// The unit vector towards the sun (+Z up).
    pub fn direction(&self) -> Vec3 {
        sun_direction(self.elevation_deg, self.azimuth_deg)
    }

    /// As a [`SunPosition`] of the frame's lighting request.
    pub fn position(&self) -> SunPosition {
        SunPosition::Angles {
            elevation_deg: self.elevation_deg,
            azimuth_deg: self.azimuth_deg,
        }
    }
}

/// A calendar date (proleptic Gregorian).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Date {
    pub year: i32,
    pub month: u32,
    pub day: u32,
}

fn is_leap(year: i32) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i32, month: u32) -> u32 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

impl Date {
    /// Day of the year, 1 = 1 January.
    pub fn day_of_year(&self) -> u32 {
        (1..self.month).map(|m| days_in_month(self.year, m)).sum::<u32>() + self.day
    }
}

/// Parses `YYYY-MM-DD` (`--date`); the error names `lighting.date`.
pub fn parse_date(text: &str) -> Result<Date> {
    let bad = |why: &str| Error::invalid("lighting.date", format!("{text:?}: {why}"));
    let parts: Vec<&str> = text.trim().split('-').collect();
    let [y, m, d] = parts[..] else {
        return Err(bad("expected YYYY-MM-DD"));
    };
    if y.len() != 4 || m.len() != 2 || d.len() != 2 {
        return Err(bad("expected YYYY-MM-DD"));
    }
    let num = |s: &str| s.parse::<u32>().map_err(|_| bad("expected YYYY-MM-DD"));
    let (year, month, day) = (num(y)? as i32, num(m)?, num(d)?);
    if !(1..=12).contains(&month) {
        return Err(bad("month must be 01..12"));
    }
    let last = days_in_month(year, month);
    if !(1..=last).contains(&day) {
        return Err(bad(&format!("day must be 01..{last} in that month")));
    }
    Ok(Date { year, month, day })
}

/// Parses `HH:MM` (`--time`, 00:00..23:59) into minutes after midnight; the
/// error names `lighting.time`.
pub fn parse_time(text: &str) -> Result<f32> {
    let bad = |why: &str| Error::invalid("lighting.time", format!("{text:?}: {why}"));
    let Some((h, m)) = text.trim().split_once(':') else {
        return Err(bad("expected HH:MM"));
    };
    let num = |s: &str| {
        if s.is_empty() || s.len() > 2 {
            return Err(bad("expected HH:MM"));
        }
        s.parse::<u32>().map_err(|_| bad("expected HH:MM"))
    };
    let (h, m) = (num(h)?, num(m)?);
    if h > 23 {
        return Err(bad("hour must be 00..23"));
    }
    if m > 59 {
        return Err(bad("minute must be 00..59"));
    }
    Ok((h * 60 + m) as f32)
}

/// Years the algorithm is valid for.
pub const YEARS: std::ops::RangeInclusive<i32> = 1901..=2099;

/// Julian day of 0 h UTC on 1 January of `year` (Gregorian).
fn julian_day_jan1(year: i32) -> f64 {
    let y = (year + 4799) as i64;
    let jdn = 1 + (153 * 10 + 2) / 5 + 365 * y + y / 4 - y / 100 + y / 400 - 32045;
    jdn as f64 - 0.5
}

/// (declination rad, equation of time min) at Julian day `jd` (UTC):
/// NOAA's spreadsheet, after Meeus, "Astronomical Algorithms" ch. 25.
fn declination_and_eqtime(jd: f64) -> (f64, f64) {
    let t = (jd - 2_451_545.0) / 36_525.0;
    let l0 = (280.46646 + t * (36000.76983 + t * 0.0003032))
        .rem_euclid(360.0)
        .to_radians();
    let m = (357.52911 + t * (35999.05029 - 0.0001537 * t)).to_radians();
    let e = 0.016708634 - t * (0.000042037 + 0.0000001267 * t);
    let c = m.sin() * (1.914602 - t * (0.004817 + 0.000014 * t))
        + (2.0 * m).sin() * (0.019993 - 0.000101 * t)
        + (3.0 * m).sin() * 0.000289;
    let omega = (125.04 - 1934.136 * t).to_radians();
    let lambda = (l0.to_degrees() + c - 0.00569 - 0.00478 * omega.sin()).to_radians();
    let eps0 = 23.0 + (26.0 + (21.448 - t * (46.815 + t * (0.00059 - t * 0.001813))) / 60.0) / 60.0;
    let eps = (eps0 + 0.00256 * omega.cos()).to_radians();
    let decl = (eps.sin() * lambda.sin()).asin();
    let y = (eps / 2.0).tan().powi(2);
    let eqtime = 4.0
        * (y * (2.0 * l0).sin() - 2.0 * e * m.sin() + 4.0 * e * y * m.sin() * (2.0 * l0).cos()
            - 0.5 * y * y * (4.0 * l0).sin()
            - 1.25 * e * e * (2.0 * m).sin())
        .to_degrees();
    (decl, eqtime)
}

/// Solar position on `day_of_year` (1..=366) of `year` (1901..=2099) at
/// `minutes` after midnight (0..1440) of `clock`, at `latitude_deg` (north
/// positive) and `longitude_deg` (east positive). See the module
/// documentation.
pub fn solar_position(
    year: i32,
    day_of_year: u32,
    minutes: f32,
    latitude_deg: f32,
    longitude_deg: f32,
    clock: Clock,
) -> Result<SunAngles> {
    if !YEARS.contains(&year) {
        return Err(Error::invalid(
            "lighting.date",
            format!("year {year}; must be in 1901..=2099"),
        ));
    }
    let days = if is_leap(year) { 366 } else { 365 };
    if !(1..=days).contains(&day_of_year) {
        return Err(Error::invalid(
            "lighting.day_of_year",
            format!("{day_of_year}; must be in 1..={days}"),
        ));
    }
    if !(0.0..1440.0).contains(&minutes) {
        return Err(Error::invalid(
            "lighting.time",
            format!("{minutes} minutes; must be in 0..1440"),
        ));
    }
    if !(-90.0..=90.0).contains(&latitude_deg) {
        return Err(Error::invalid(
            "lighting.latitude",
            format!("{latitude_deg}; must be in -90..=90 degrees"),
        ));
    }
    if !(-180.0..=180.0).contains(&longitude_deg) {
        return Err(Error::invalid(
            "lighting.longitude",
            format!("{longitude_deg}; must be in -180..=180 degrees"),
        ));
    }
    let (minutes, longitude) = (minutes as f64, longitude_deg as f64);
    // UTC minutes of the instant, and the longitude term of the true solar time.
    let (utc, longitude_term) = match clock {
        Clock::MeanSolar => (minutes - 4.0 * longitude, 0.0),
        Clock::UtcOffset(h) if (-14.0..=14.0).contains(&h) => {
            (minutes - 60.0 * h as f64, 4.0 * longitude - 60.0 * h as f64)
        }
        Clock::UtcOffset(h) => {
            return Err(Error::invalid(
                "lighting.utc_offset",
                format!("{h}; must be in -14..=14 hours"),
            ));
        }
    };
    let jd = julian_day_jan1(year) + (day_of_year - 1) as f64 + utc / 1440.0;
    let (decl, eqtime) = declination_and_eqtime(jd);
    let true_solar = minutes + eqtime + longitude_term;
    let hour_angle = (true_solar / 4.0 - 180.0).to_radians();
    let lat = (latitude_deg as f64).to_radians();
    let sin_elevation = lat.sin() * decl.sin() + lat.cos() * decl.cos() * hour_angle.cos();
    let elevation = sin_elevation.clamp(-1.0, 1.0).asin();
    // sin A cos e = −cos δ sin H; cos A cos e = sin δ cos φ − cos δ sin φ cos H.
    let azimuth = (-decl.cos() * hour_angle.sin())
        .atan2(decl.sin() * lat.cos() - decl.cos() * lat.sin() * hour_angle.cos())
        .to_degrees()
        .rem_euclid(360.0);
    Ok(SunAngles {
        elevation_deg: elevation.to_degrees() as f32,
        azimuth_deg: azimuth as f32,
    })
}

/// The lighting environments of the text's Fig. 9.3 (§9.5), latitude 49.6°
/// (Erlangen), turbidity 2.1, mean local solar time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyPreset {
    /// Autumn morning: day 298, 07:30 (sun ≈ 7° up, in the east-south-east).
    Morning,
    /// Summer noon: day 180, 12:00.
    Noon,
}

impl SkyPreset {
    pub const LATITUDE_DEG: f32 = 49.6;
    pub const TURBIDITY: f32 = 2.1;

    /// `morning` or `noon`; the error names `lighting.sky_preset`.
    pub fn parse(name: &str) -> Result<SkyPreset> {
        match name.trim().to_ascii_lowercase().as_str() {
            "morning" => Ok(SkyPreset::Morning),
            "noon" => Ok(SkyPreset::Noon),
            _ => Err(Error::invalid(
                "lighting.sky_preset",
                format!("{name:?}; must be morning or noon"),
            )),
        }
    }

    /// (day of year, minutes after midnight, mean local solar time).
    pub fn day_and_time(self) -> (u32, f32) {
        match self {
            SkyPreset::Morning => (298, 7.0 * 60.0 + 30.0),
            SkyPreset::Noon => (180, 12.0 * 60.0),
        }
    }

    pub fn turbidity(self) -> f32 {
        SkyPreset::TURBIDITY
    }

    /// Where the sun is.
    pub fn sun(self) -> Result<SunAngles> {
        let (day, minutes) = self.day_and_time();
        solar_position(
            DEFAULT_YEAR,
            day,
            minutes,
            SkyPreset::LATITUDE_DEG,
            0.0,
            Clock::MeanSolar,
        )
    }
}

/// Precipitable water (cm) for the water-vapour transmittance.
pub const WATER_VAPOUR_CM: f32 = 2.0;
/// Total ozone column (cm) of Preetham's appendix A.1.
pub const OZONE_CM: f32 = 0.35;
/// Relative optical air mass at sun zenith angle `zenith_deg` (clamped to
/// 0..=90°): Kasten and Young 1989, `1 / (cos z + 0.50572·(96.07995° −
/// z)^−1.6364)`; ≈ 38 at the horizon.
pub fn relative_air_mass(zenith_deg: f32) -> f32 {
    let z = zenith_deg.clamp(0.0, 90.0);
    1.0 / (z.to_radians().cos() + 0.50572 * (96.07995 - z).powf(-1.6364))
}

/// Linear interpolation in a table of (wavelength nm, value), clamped.
fn table(t: &[(f32, f32)], lambda: f32) -> f32 {
    let i = t.partition_point(|&(l, _)| l < lambda);
    if i == 0 {
        return t[0].1;
    }
    if i == t.len() {
        return t[t.len() - 1].1;
    }
    let ((l0, v0), (l1, v1)) = (t[i - 1], t[i]);
    v0 + (v1 - v0) * (lambda - l0) / (l1 - l0)
}

/// Ozone absorption k_o (1/cm), appendix A.1 (from Iqbal 1983), 355–790 nm.
const K_OZONE: [(f32, f32); 44] = [
    (355.0, 0.0),
    (445.0, 0.003),
    (450.0, 0.003),
    (455.0, 0.004),
    (460.0, 0.006),
    (465.0, 0.008),
    (470.0, 0.009),
    (475.0, 0.012),
    (480.0, 0.014),
    (485.0, 0.017),
    (490.0, 0.021),
    (495.0, 0.025),
    (500.0, 0.03),
    (505.0, 0.035),
    (510.0, 0.04),
    (515.0, 0.045),
    (520.0, 0.048),
    (525.0, 0.057),
    (530.0, 0.063),
    (535.0, 0.07),
    (540.0, 0.075),
    (545.0, 0.08),
    (550.0, 0.085),
    (555.0, 0.095),
    (560.0, 0.103),
    (565.0, 0.11),
    (570.0, 0.12),
    (575.0, 0.122),
    (580.0, 0.12),
    (585.0, 0.118),
    (590.0, 0.115),
    (595.0, 0.12),
    (600.0, 0.125),
    (605.0, 0.13),
    (610.0, 0.12),
    (620.0, 0.105),
    (630.0, 0.09),
    (640.0, 0.079),
    (650.0, 0.067),
    (660.0, 0.057),
    (670.0, 0.048),
    (680.0, 0.036),
    (690.0, 0.028),
    (700.0, 0.023),
];
/// Mixed-gas (O₂) absorption k_g (1/km), appendix A.1.
const K_GAS: [(f32, f32); 4] = [(759.0, 0.0), (760.0, 3.0), (770.0, 0.21), (771.0, 0.0)];
/// Water-vapour absorption k_wa (1/cm), appendix A.1.
const K_WATER: [(f32, f32); 5] = [
    (689.0, 0.0),
    (690.0, 0.016),
    (700.0, 0.024),
    (710.0, 0.0125),
    (720.0, 1.0),
];

/// Spectral transmittance of the atmosphere along relative air mass `m` at
/// `lambda_nm` and turbidity `t` (Preetham 1999, appendix A.1): Rayleigh
/// `e^(−0.008735 λ^−4.08 m)`, aerosols (Ångström) `e^(−β λ^−α m)` with
/// `β = 0.04608T − 0.04586`, `α = 1.3`, ozone `e^(−k_o l m)` with l = 0.35
/// cm, mixed gases `e^(−1.41 k_g m / (1 + 118.93 k_g m)^0.45)` and water
/// vapour `e^(−0.2385 k_wa w m / (1 + 20.07 k_wa w m)^0.45)`, w = 2 cm
/// (λ in µm). The last two absorb only above 689 nm, beyond the sampled
/// channels; the water table stops at 720 nm.
pub fn spectral_transmittance(lambda_nm: f32, m: f32, t: f32) -> f32 {
    let l = lambda_nm / 1000.0;
    let rayleigh = -0.008735 * l.powf(-4.08) * m;
    let aerosol = -(0.04608 * t - 0.04586).max(0.0) * l.powf(-1.3) * m;
    let ozone = -table(&K_OZONE, lambda_nm) * OZONE_CM * m;
    let kg = table(&K_GAS, lambda_nm) * m;
    let gas = -1.41 * kg / (1.0 + 118.93 * kg).powf(0.45);
    let kw = if lambda_nm <= 720.0 {
        table(&K_WATER, lambda_nm)
    } else {
        0.0
    } * WATER_VAPOUR_CM
        * m;
    let water = -0.2385 * kw / (1.0 + 20.07 * kw).powf(0.45);
    (rayleigh + aerosol + ozone + gas + water).exp()
}

/// Wavelengths (nm) averaged for each of R, G, B: equal-weight samples
/// across the band where each sRGB channel is most sensitive (a coarse
/// stand-in for integrating with colour-matching functions).
pub const CHANNEL_SAMPLES_NM: [[f32; 4]; 3] = [
    [600.0, 620.0, 640.0, 660.0],
    [520.0, 540.0, 560.0, 580.0],
    [440.0, 455.0, 470.0, 485.0],
];

/// Atmospheric transmittance of R, G, B for a sun at `zenith_deg`.
pub fn sun_transmittance(zenith_deg: f32, t: f32) -> Vec3 {
    let m = relative_air_mass(zenith_deg);
    Vec3::from_array(
        CHANNEL_SAMPLES_NM
            .map(|band| band.iter().map(|&l| spectral_transmittance(l, m, t)).sum::<f32>() / band.len() as f32),
    )
}

/// Mean radiance of the sun's disc at the ground towards unit `sun`:
/// extraterrestrial luminance × colour × [`sun_transmittance`], times the
/// fraction of the disc above the horizon (linear in elevation across the
/// disc), so it reaches 0 when the disc has set.
pub fn transmitted_sun(sun: Vec3, t: f32) -> Vec3 {
    let elevation = sun.z.clamp(-1.0, 1.0).asin();
    let visible = ((elevation + SUN_ANGULAR_RADIUS) / (2.0 * SUN_ANGULAR_RADIUS)).clamp(0.0, 1.0);
    if visible <= 0.0 {
        return Vec3::ZERO;
    }
    let zenith_deg = 90.0 - elevation.to_degrees();
    Vec3::from_array(SUN_COLOUR_EXTRATERRESTRIAL)
        * (SUN_LUMINANCE_EXTRATERRESTRIAL * visible)
        * sun_transmittance(zenith_deg, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equinox_noon_elevation_is_the_colatitude() {
        // 2005-03-20 (equinox 12:33 UTC): the day's highest sun.
        for lat in [0.0f32, 30.0, 49.6, -35.0] {
            let noon = (600..840)
                .map(|m| {
                    solar_position(2005, 79, m as f32, lat, 0.0, Clock::MeanSolar)
                        .unwrap()
                        .elevation_deg
                })
                .fold(f32::MIN, f32::max);
            assert!((noon - (90.0 - lat.abs())).abs() < 0.5, "{lat}: {noon}");
        }
    }

    #[test]
    fn published_reference_values() {
        // NREL SPA report (Reda & Andreas 2004), example: 2003-10-17
        // 12:30:30 at UTC−7, 39.742476° N 105.1786° W: zenith 50.11162°
        // (refracted; ≈ +0.02° geometric), azimuth 194.34024°.
        let day = parse_date("2003-10-17").unwrap().day_of_year();
        assert_eq!(day, 290);
        let s = solar_position(2003, day, 750.5, 39.742476, -105.1786, Clock::UtcOffset(-7.0)).unwrap();
        assert!((90.0 - s.elevation_deg - 50.13).abs() < 0.05, "{s:?}");
        assert!((s.azimuth_deg - 194.34).abs() < 0.05, "{s:?}");
        // June solstice, solar noon on the Tropic of Cancer: overhead.
        let s = solar_position(2005, 172, 720.0, 23.44, 0.0, Clock::MeanSolar).unwrap();
        assert!(s.elevation_deg > 89.0, "{s:?}");
    }

    #[test]
    fn morning_sun_is_in_the_east() {
        let s = solar_position(2005, 172, 6.0 * 60.0, 49.6, 11.0, Clock::MeanSolar).unwrap();
        assert!((0.0..180.0).contains(&s.azimuth_deg) && s.elevation_deg > 0.0, "{s:?}");
        let s = solar_position(2005, 172, 18.0 * 60.0, 49.6, 11.0, Clock::MeanSolar).unwrap();
        assert!((180.0..360.0).contains(&s.azimuth_deg), "{s:?}");
        let d = s.direction();
        assert!(d.x < 0.0, "west is −X: {d}");
        // Longitude only matters with a time zone: 11° east is 44 minutes
        // ahead of the zone meridian.
        let civil = solar_position(2005, 172, 12.0 * 60.0 - 44.0, 49.6, 11.0, Clock::UtcOffset(0.0)).unwrap();
        let solar = solar_position(2005, 172, 12.0 * 60.0, 49.6, 11.0, Clock::MeanSolar).unwrap();
        assert!((civil.azimuth_deg - solar.azimuth_deg).abs() < 0.1);
    }

    #[test]
    fn presets() {
        let m = SkyPreset::parse("morning").unwrap().sun().unwrap();
        assert!((3.0..12.0).contains(&m.elevation_deg), "{m:?}");
        assert!((100.0..140.0).contains(&m.azimuth_deg), "{m:?}");
        let n = SkyPreset::parse("Noon").unwrap().sun().unwrap();
        // 90° − 49.6° + 23.2° (declination on 29 June).
        assert!((n.elevation_deg - 63.6).abs() < 0.6, "{n:?}");
        assert!((n.azimuth_deg - 180.0).abs() < 5.0, "{n:?}");
        assert_eq!(SkyPreset::Noon.turbidity(), 2.1);
        let err = SkyPreset::parse("dusk").unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.sky_preset"));
        assert!(!err.to_string().contains('\n'));
    }

    #[test]
    fn parsers_reject_bad_dates_and_times() {
        assert_eq!(parse_date("2024-12-31").unwrap().day_of_year(), 366);
        assert_eq!(parse_date("2024-02-29").unwrap().day_of_year(), 60);
        for bad in [
            "2026-02-30",
            "2023-02-29",
            "2026-13-01",
            "2026-1-01",
            "20260101",
            "2026-04-31",
            "x",
        ] {
            assert_eq!(parse_date(bad).unwrap_err().parameter(), Some("lighting.date"), "{bad}");
        }
        assert_eq!(parse_time("07:30").unwrap(), 450.0);
        assert_eq!(parse_time("23:59").unwrap(), 1439.0);
        for bad in ["25:00", "24:00", "12:60", "12", "1230", ":30", "ab:cd", "-1:00"] {
            assert_eq!(parse_time(bad).unwrap_err().parameter(), Some("lighting.time"), "{bad}");
        }
        let err = solar_position(2005, 0, 0.0, 0.0, 0.0, Clock::MeanSolar).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.day_of_year"));
        let err = solar_position(2005, 1, 0.0, 91.0, 0.0, Clock::MeanSolar).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.latitude"));
        let err = solar_position(2005, 1, 0.0, 0.0, 0.0, Clock::UtcOffset(20.0)).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.utc_offset"));
        let err = solar_position(2005, 366, 0.0, 0.0, 0.0, Clock::MeanSolar).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.day_of_year"));
        let err = solar_position(1800, 1, 0.0, 0.0, 0.0, Clock::MeanSolar).unwrap_err();
        assert_eq!(err.parameter(), Some("lighting.date"));
    }
}
