//! The probe the probe viewer shows: read through `ibl-io` in any format, in any mapping
//! `ibl-mapping` knows (guessed from the image's shape unless given), resampled to lat-long
//! once at load (energy-conserving, as `ibl convert --to latlong`); what the viewer shows of it
//! and where the cursor points.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat3, Vec2, Vec3};
use ibl_core::tonemap::Display;
use ibl_core::{Image, LatLong, Rgb};
use ibl_extract::ModelSpec;
use ibl_light::{LightSource, Method};
use ibl_mapping::Mapping;

use crate::ViewerError;
use crate::lighting::ProbeOverlay;
use crate::markers_pass::{Marker, MarkerStyle};
use crate::probe_pass::{ProbeLayer, ProbeProjection};
use crate::view_camera::{OrbitControl, OutputCamera};

/// A probe read for viewing.
#[derive(Clone, Debug)]
pub struct ProbeModel {
    /// The file.
    pub path: PathBuf,
    /// Lat-long radiance (resampled from `mapping` when that is not lat-long).
    pub latlong: Arc<Image<Rgb>>,
    /// The file's own mapping.
    pub mapping: Mapping,
    /// Encoding details from the reader, and how many values were clamped.
    pub details: String,
}

impl ProbeModel {
    /// Reads `path`; `mapping` overrides the guess from the image's shape.
    pub fn open(path: &Path, mapping: Option<Mapping>) -> Result<ProbeModel, ViewerError> {
        let loaded = ibl_io::read_image(path)?;
        let (w, h) = (loaded.image.width(), loaded.image.height());
        let mapping = match mapping.or_else(|| Mapping::detect_from_shape(w, h)) {
            Some(mapping) => mapping,
            None => {
                return Err(ViewerError::Input {
                    path: path.to_path_buf(),
                    problem: format!(
                        "a {w} x {h} image has no mapping its shape tells (2:1 lat-long, 1:1 \
                         angular or mirror ball, 4:3 / 3:4 cross, 6:1 / 1:6 strip): give --mapping"
                    ),
                });
            }
        };
        mapping.check_shape(w, h).map_err(|e| ViewerError::Input {
            path: path.to_path_buf(),
            problem: e.to_string(),
        })?;
        let latlong = if mapping == Mapping::LatLong {
            loaded.image
        } else {
            let (lw, lh) = Mapping::LatLong.default_size_for(mapping, w, h);
            ibl_mapping::resample(
                &loaded.image,
                mapping,
                Mapping::LatLong,
                lw,
                lh,
                Mat3::IDENTITY,
                &|_, _| {},
            )
            .map_err(|e| ViewerError::Input {
                path: path.to_path_buf(),
                problem: e.to_string(),
            })?
        };
        let clamped = loaded.report.clamped_values();
        let details = if clamped > 0 {
            format!("{}; {clamped} invalid values clamped to 0", loaded.details)
        } else {
            loaded.details
        };
        Ok(ProbeModel {
            path: path.to_path_buf(),
            latlong: Arc::new(latlong),
            mapping,
            details,
        })
    }

    /// The radiance of the texel holding world direction `d` (nearest texel, as the renderer
    /// reads a probe).
    pub fn radiance_towards(&self, d: Vec3) -> Rgb {
        let image = &*self.latlong;
        let grid = LatLong::new(image.width(), image.height());
        let (i, j) = grid.dir_to_pixel(d.normalize_or(Vec3::NEG_Z).as_dvec3());
        *image.get(i, j)
    }
}

/// The overlays a user switched on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Overlays {
    /// Rings at the extracted lights.
    pub lights: bool,
    /// Borders of the lights' regions (region methods).
    pub regions: bool,
    /// The dominant light's cross-hair.
    pub dominant: bool,
}

/// What the probe viewer shows and how.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeViewSettings {
    /// Look around or flat.
    pub projection: ProbeProjection,
    /// Radiance or SH irradiance.
    pub layer: ProbeLayer,
    /// The look-around camera (distance 0: turning about the eye).
    pub orbit: OrbitControl,
    /// Exposure and tone curve.
    pub display: Display,
    /// Laplacian sharpening strength, 0 to 2.
    pub sharpen: f32,
    /// Overlays.
    pub overlays: Overlays,
    /// Lights of the overlay: method or `sun`.
    pub spec: ModelSpec,
    /// How many lights.
    pub lights: usize,
    /// SH bands of the irradiance layer.
    pub bands: usize,
}

impl ProbeViewSettings {
    /// Defaults for a probe: looking forward with a 75-degree field of view, automatic exposure,
    /// 16 median-cut lights, SH of 3 bands.
    pub fn for_probe(probe: &Image<Rgb>) -> ProbeViewSettings {
        ProbeViewSettings {
            projection: ProbeProjection::LookAround,
            layer: ProbeLayer::Radiance,
            orbit: OrbitControl {
                target: Vec3::ZERO,
                distance: 0.0,
                yaw: 0.0,
                pitch: 0.0,
                vertical_fov: 75f32.to_radians(),
            },
            display: Display {
                exposure_stops: ibl_core::tonemap::auto_exposure_stops(probe),
                ..Display::default()
            },
            sharpen: 0.0,
            overlays: Overlays {
                lights: true,
                regions: false,
                dominant: true,
            },
            spec: ModelSpec::Lights(LightSource::Method(Method::MedianCut)),
            lights: 16,
            bands: 3,
        }
    }

    /// The look-around camera at `width x height`.
    pub fn camera(&self, width: u32, height: u32) -> OutputCamera {
        self.orbit.camera(width, height)
    }

    /// Output pixel coordinates of world direction `d` in this view (`None` when not visible).
    pub fn pixel_of(&self, d: Vec3, width: u32, height: u32) -> Option<Vec2> {
        match self.projection {
            ProbeProjection::LookAround => self.camera(width, height).project(d),
            ProbeProjection::LatLong => {
                let (u, v) = LatLong::dir_to_uv(d.as_dvec3());
                Some(Vec2::new(u as f32 * width as f32, v as f32 * height as f32))
            }
        }
    }

    /// The world direction under output pixel `(x, y)`.
    pub fn direction_at(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        match self.projection {
            ProbeProjection::LookAround => self.camera(width, height).ray(x, y),
            ProbeProjection::LatLong => LatLong::uv_to_dir(
                f64::from(x / width as f32).clamp(0.0, 1.0),
                f64::from(y / height as f32).clamp(0.0, 1.0),
            ),
        }
    }

    /// The markers of the overlay in this view; `scale` multiplies sizes (high-DPI screens).
    pub fn markers(
        &self,
        overlay: &ProbeOverlay,
        width: u32,
        height: u32,
        scale: f32,
    ) -> Vec<Marker> {
        let mut markers = Vec::new();
        if self.overlays.lights {
            let lum = |l: &ibl_light::Light| {
                0.2126 * l.irradiance[0] + 0.7152 * l.irradiance[1] + 0.0722 * l.irradiance[2]
            };
            let brightest = overlay.set.lights.iter().map(lum).fold(0.0f64, f64::max);
            for light in &overlay.set.lights {
                let d = Vec3::new(
                    light.direction[0] as f32,
                    light.direction[1] as f32,
                    light.direction[2] as f32,
                );
                if let Some(p) = self.pixel_of(d, width, height) {
                    let share = if brightest > 0.0 {
                        (lum(light) / brightest).sqrt()
                    } else {
                        0.0
                    };
                    markers.push(Marker {
                        centre: p.to_array(),
                        radius: scale * (4.0 + 12.0 * share as f32),
                        style: MarkerStyle::Ring,
                        colour: [1.0, 0.85, 0.1, 0.95],
                    });
                }
            }
        }
        if self.overlays.dominant
            && let Some(sun) = &overlay.dominant
        {
            let d = Vec3::new(
                sun.direction[0] as f32,
                sun.direction[1] as f32,
                sun.direction[2] as f32,
            );
            if let Some(p) = self.pixel_of(d, width, height) {
                markers.push(Marker {
                    centre: p.to_array(),
                    radius: scale * 18.0,
                    style: MarkerStyle::Crosshair,
                    colour: [1.0, 0.25, 0.2, 0.95],
                });
            }
        }
        markers
    }
}
