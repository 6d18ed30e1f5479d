//! `[outdoor]`: outdoor augmented reality under changing light (Jensen, Andersen & Madsen 2006):
//! the site on Earth (latitude, longitude, elevation, UTC offset, the world direction of north,
//! the air for the refraction correction), when the `[probe]` was taken, the mask of the diffuse
//! real surfaces whose pixels the per-frame sun and sky estimate samples, the number of sample
//! sites, temporal smoothing, an optional irradiance volume, and the video frames
//! (`[outdoor.frames]`: a folder of images or a video file, the local time of the first frame and
//! the interval between frames).
//!
//! An outdoor scene is an ordinary scene plus this table: `[probe]` is the HDR probe taken once
//! (at `probe_time`), `[[local]]` the model of the real buildings and ground, `[camera]` the
//! calibrated video camera, `[[object]]` the virtual objects and `[background]` a photo, a
//! representative frame (the checks that tie these tables together are
//! `SceneDescription::validate`'s).
//!
//! Times are TOML local date-times (`2024-04-20T09:30:00`, no offset): local civil time at
//! `utc_offset_hours` (local = UTC + offset). [`local_civil_time`] splits one into the calendar
//! fields the solar position wants. Paths are relative to the scene file; `ibl-io` resolves them.

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use toml::value::Datetime;

use super::field::{DescriptionError, invalid, positive};

/// Default world direction of geographic north: -Z (so east, `north x up`, is +X).
pub const DEFAULT_NORTH: [f32; 3] = [0.0, 0.0, -1.0];
/// Default air pressure at the site, millibars (hPa): the standard atmosphere at sea level.
pub const DEFAULT_PRESSURE_MBAR: f64 = 1013.25;
/// Default air temperature at the site, degrees Celsius.
pub const DEFAULT_TEMPERATURE_C: f64 = 12.0;
/// Default number of sample sites on the marked surfaces.
pub const DEFAULT_SAMPLES: u32 = 500;
/// Most sample sites a scene may ask for.
pub const MAX_SAMPLES: u32 = 100_000;
/// How far `north` may tilt out of the horizontal plane, degrees.
pub const MAX_NORTH_TILT_DEG: f64 = 1.0;

/// `[outdoor]`: the site, the probe's time, the estimation's settings and the video frames of
/// an outdoor AR scene (Jensen, Andersen & Madsen 2006).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutdoorDescription {
    /// Geodetic latitude of the site, degrees, north positive, in [-90, 90]. Required.
    pub latitude_deg: f64,
    /// Longitude of the site, degrees, **east positive**, in [-180, 180]. Required.
    pub longitude_deg: f64,
    /// Height of the site above sea level, metres, in [-500, 9000]. Default 0.
    #[serde(default)]
    pub elevation_m: f64,
    /// Local civil time minus UTC, hours (local = UTC + offset; e.g. 2 for central European
    /// summer time), in [-14, 14]. Every time in the table is local time at this offset.
    /// Required.
    pub utc_offset_hours: f64,
    /// World direction of geographic north (world frame, +Y up): horizontal to within
    /// [`MAX_NORTH_TILT_DEG`], non-zero, any length ([`OutdoorDescription::north_unit`] gives
    /// it as a horizontal unit vector). Default [`DEFAULT_NORTH`], -Z.
    #[serde(default = "default_north")]
    pub north: [f32; 3],
    /// Air pressure at the site, millibars (hPa), in (0, 2000], for the refraction correction
    /// of the sun's elevation. Default [`DEFAULT_PRESSURE_MBAR`].
    #[serde(default = "default_pressure")]
    pub pressure_mbar: f64,
    /// Air temperature at the site, degrees Celsius, in [-90, 60], for the refraction
    /// correction. Default [`DEFAULT_TEMPERATURE_C`].
    #[serde(default = "default_temperature")]
    pub temperature_c: f64,
    /// When the `[probe]` was taken: a TOML local date-time (`2024-04-20T09:30:00`; local time
    /// at `utc_offset_hours`, no offset of its own). Required.
    pub probe_time: Datetime,
    /// Image marking the diffuse real surfaces the estimate samples (non-black pixels are
    /// marked), relative to the scene file; the same size as the frames. Required.
    pub mask: PathBuf,
    /// Sample sites on the marked surfaces, in 1..=[`MAX_SAMPLES`]. Default
    /// [`DEFAULT_SAMPLES`].
    #[serde(default = "default_samples")]
    pub samples: u32,
    /// Temporal smoothing of the per-frame estimates (a Kalman filter over the frames).
    /// Default false.
    #[serde(default)]
    pub smoothing: bool,
    /// Spacing of the irradiance volume's key points over the objects' surroundings, metres
    /// (world units), positive. Default none: no volume.
    pub volume_spacing_m: Option<f64>,
    /// The video frames. Required.
    pub frames: FramesDescription,
}

/// `[outdoor.frames]`: the video frames of an outdoor scene, at a fixed interval.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FramesDescription {
    /// A folder of images (the frames in order of file name) or a video file (decoded by
    /// ffmpeg), relative to the scene file. Required.
    pub source: PathBuf,
    /// Local time of the first frame: a TOML local date-time at `outdoor.utc_offset_hours`, no
    /// offset of its own. Required.
    pub start: Datetime,
    /// Seconds between consecutive frames, finite and > 0: frame `i` is at
    /// `start + i * interval_s`. Required.
    pub interval_s: f64,
}

fn default_north() -> [f32; 3] {
    DEFAULT_NORTH
}
fn default_pressure() -> f64 {
    DEFAULT_PRESSURE_MBAR
}
fn default_temperature() -> f64 {
    DEFAULT_TEMPERATURE_C
}
fn default_samples() -> u32 {
    DEFAULT_SAMPLES
}

/// A local civil time split into its calendar fields: `(year, month, day, hour, minute,
/// second)`, month 1..=12, day 1..=31, hour 0..=23, minute 0..=59, second in [0, 61) with its
/// fraction.
pub type CivilTime = (i32, u32, u32, u32, u32, f64);

/// The calendar fields of `time`, a local date-time, or an error at `field` when it lacks a
/// date or a time, carries a UTC offset (local times in `[outdoor]` take
/// `outdoor.utc_offset_hours`), or holds an impossible date or time. Seconds default to 0 and
/// keep their fraction (`09:30:00.25` gives 0.25).
pub fn local_civil_time(field: &str, time: &Datetime) -> Result<CivilTime, DescriptionError> {
    if time.offset.is_some() {
        return Err(invalid(
            field,
            format!(
                "{time} carries a UTC offset; give the local time without one \
                 (e.g. 2024-04-20T09:30:00): outdoor.utc_offset_hours sets the offset"
            ),
        ));
    }
    let (Some(date), Some(clock)) = (time.date, time.time) else {
        return Err(invalid(
            field,
            format!("{time} is not a date and a time (e.g. 2024-04-20T09:30:00)"),
        ));
    };
    let y = date.year;
    let leap = y.is_multiple_of(4) && (!y.is_multiple_of(100) || y.is_multiple_of(400));
    let days = match date.month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => 0,
    };
    let second = clock.second.unwrap_or(0);
    let nanosecond = clock.nanosecond.unwrap_or(0);
    if !(1..=days).contains(&date.day)
        || clock.hour > 23
        || clock.minute > 59
        || second > 60
        || nanosecond >= 1_000_000_000
    {
        return Err(invalid(
            field,
            format!("{time} is not a valid date and time"),
        ));
    }
    Ok((
        i32::from(date.year),
        u32::from(date.month),
        u32::from(date.day),
        u32::from(clock.hour),
        u32::from(clock.minute),
        f64::from(second) + f64::from(nanosecond) / 1e9,
    ))
}

/// `v` in `[lo, hi]` (a NaN or infinity is not), or an error at `field` with `unit`.
fn within(field: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Result<(), DescriptionError> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(invalid(field, format!("{v} is not in [{lo}, {hi}] {unit}")))
    }
}

fn nonempty(field: &str, path: &Path) -> Result<(), DescriptionError> {
    if path.as_os_str().is_empty() {
        Err(invalid(field, "is an empty path"))
    } else {
        Ok(())
    }
}

impl OutdoorDescription {
    /// Checks every value, naming the field at fault (`outdoor.north`,
    /// `outdoor.frames.interval_s`, ...). The mask's size against the frames' is checked when
    /// the files are read.
    pub(crate) fn validate(&self) -> Result<(), DescriptionError> {
        within(
            "outdoor.latitude_deg",
            self.latitude_deg,
            -90.0,
            90.0,
            "degrees (north positive)",
        )?;
        within(
            "outdoor.longitude_deg",
            self.longitude_deg,
            -180.0,
            180.0,
            "degrees (east positive)",
        )?;
        within(
            "outdoor.elevation_m",
            self.elevation_m,
            -500.0,
            9000.0,
            "metres",
        )?;
        within(
            "outdoor.utc_offset_hours",
            self.utc_offset_hours,
            -14.0,
            14.0,
            "hours",
        )?;
        self.validate_north()?;
        let p = self.pressure_mbar;
        let pressure_ok = p > 0.0 && p <= 2000.0;
        if !pressure_ok {
            return Err(invalid(
                "outdoor.pressure_mbar",
                format!("{} is not in (0, 2000] millibars", self.pressure_mbar),
            ));
        }
        within(
            "outdoor.temperature_c",
            self.temperature_c,
            -90.0,
            60.0,
            "degrees Celsius",
        )?;
        local_civil_time("outdoor.probe_time", &self.probe_time)?;
        nonempty("outdoor.mask", &self.mask)?;
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(invalid(
                "outdoor.samples",
                format!("{} is not in 1..={MAX_SAMPLES}", self.samples),
            ));
        }
        if let Some(spacing) = self.volume_spacing_m {
            positive("outdoor.volume_spacing_m", spacing)?;
        }
        self.frames.validate()
    }

    fn validate_north(&self) -> Result<(), DescriptionError> {
        let field = "outdoor.north";
        let v = self.north;
        if !v.iter().all(|x| x.is_finite()) {
            return Err(invalid(field, format!("{v:?} is not finite")));
        }
        let n = Vec3::from(v).as_dvec3();
        let length = n.length();
        if length <= 0.0 {
            return Err(invalid(
                field,
                format!("{v:?} is zero: give the world direction of geographic north"),
            ));
        }
        let tilt_deg = (n.y.abs() / length).min(1.0).asin().to_degrees();
        if tilt_deg > MAX_NORTH_TILT_DEG {
            return Err(invalid(
                field,
                format!(
                    "{v:?} is {tilt_deg:.2} degrees off the horizontal (world up is +y); \
                     north must be horizontal to within {MAX_NORTH_TILT_DEG} degree"
                ),
            ));
        }
        Ok(())
    }

    /// `north` as a horizontal unit vector, world frame: projected onto the plane `y = 0` and
    /// normalised (for a validated description; [`Vec3::ZERO`] where the projection is zero).
    pub fn north_unit(&self) -> Vec3 {
        let n = Vec3::from(self.north).as_dvec3();
        DVec3::new(n.x, 0.0, n.z).normalize_or_zero().as_vec3()
    }

    /// When the probe was taken, as local civil time at `utc_offset_hours`.
    pub fn probe_local_time(&self) -> Result<CivilTime, DescriptionError> {
        local_civil_time("outdoor.probe_time", &self.probe_time)
    }
}

impl FramesDescription {
    /// Checks the source, the start time and the interval.
    fn validate(&self) -> Result<(), DescriptionError> {
        nonempty("outdoor.frames.source", &self.source)?;
        local_civil_time("outdoor.frames.start", &self.start)?;
        positive("outdoor.frames.interval_s", self.interval_s)
    }

    /// The local civil time of the first frame, at `outdoor.utc_offset_hours`.
    pub fn start_local_time(&self) -> Result<CivilTime, DescriptionError> {
        local_civil_time("outdoor.frames.start", &self.start)
    }

    /// Seconds from the first frame to frame `index`: `index * interval_s`.
    pub fn seconds_after_start(&self, index: usize) -> f64 {
        index as f64 * self.interval_s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn datetime(text: &str) -> Datetime {
        text.parse().unwrap()
    }

    #[test]
    fn a_local_date_time_splits_into_its_fields() {
        let t = local_civil_time("t", &datetime("2024-04-20T09:30:00")).unwrap();
        assert_eq!(t, (2024, 4, 20, 9, 30, 0.0));
        let t = local_civil_time("t", &datetime("2024-02-29T23:59:07.25")).unwrap();
        assert_eq!((t.0, t.1, t.2, t.3, t.4), (2024, 2, 29, 23, 59));
        assert!((t.5 - 7.25).abs() < 1e-12, "{}", t.5);
    }

    #[test]
    fn offsets_dates_alone_and_times_alone_are_refused() {
        for (text, phrase) in [
            ("2024-04-20T09:30:00+02:00", "UTC offset"),
            ("2024-04-20T09:30:00Z", "UTC offset"),
            ("2024-04-20", "not a date and a time"),
            ("09:30:00", "not a date and a time"),
        ] {
            let e = local_civil_time("outdoor.probe_time", &datetime(text)).unwrap_err();
            assert_eq!(e.field, "outdoor.probe_time");
            assert!(e.problem.contains(phrase), "{text}: {}", e.problem);
        }
        // Built in code: an impossible date.
        let mut t = datetime("2023-02-28T12:00:00");
        if let Some(d) = &mut t.date {
            d.day = 29;
        }
        let e = local_civil_time("f", &t).unwrap_err();
        assert!(e.problem.contains("not a valid"), "{}", e.problem);
    }

    #[test]
    fn north_is_made_horizontal_and_unit() {
        let frames = FramesDescription {
            source: "frames".into(),
            start: datetime("2024-04-20T11:00:00"),
            interval_s: 1800.0,
        };
        let mut d = OutdoorDescription {
            latitude_deg: 57.0,
            longitude_deg: 9.9,
            elevation_m: 0.0,
            utc_offset_hours: 2.0,
            north: [3.0, 0.02, 4.0],
            pressure_mbar: DEFAULT_PRESSURE_MBAR,
            temperature_c: DEFAULT_TEMPERATURE_C,
            probe_time: datetime("2024-04-20T09:30:00"),
            mask: "mask.png".into(),
            samples: DEFAULT_SAMPLES,
            smoothing: false,
            volume_spacing_m: None,
            frames,
        };
        d.validate().unwrap();
        let n = d.north_unit();
        assert_eq!(n.y, 0.0);
        assert!((n - Vec3::new(0.6, 0.0, 0.8)).length() < 1e-6, "{n}");
        // 1 degree is the limit: tan(1.01 degrees) above the horizontal is refused.
        let t = 1.01_f32.to_radians().tan();
        d.north = [0.0, t, -1.0];
        assert_eq!(d.validate().unwrap_err().field, "outdoor.north");
        d.north = [0.0, 0.99_f32.to_radians().tan(), -1.0];
        d.validate().unwrap();
        assert_eq!(d.frames.seconds_after_start(3), 5400.0);
    }
}
