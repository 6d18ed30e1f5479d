//! The one probe loader of every job that takes a light probe (`lights`, `sh`, `irradiance`,
//! `eval`, the demo): the file's mapping is the one the caller names or the one its shape
//! shows ([`ibl_mapping::Mapping::detect_from_shape`]), an image whose shape names no mapping is
//! refused (issue 13: a 2:3 photo is not four lights), and anything but a lat-long is resampled
//! to lat-long before the job sees it, because every algorithm downstream integrates over
//! lat-long texels (`ibl_core::LatLong`).
//!
//! The conversion is `ibl convert`'s exactly: energy-conserving resampling (solid-angle-weighted
//! supersampling, `ibl-mapping`), identity rotation, the lat-long size that keeps the source's
//! angular resolution ([`Mapping::default_size_for`]). So `ibl sh angular.hdr` and
//! `ibl convert angular.hdr ll.pfm --to latlong && ibl sh ll.pfm` give the same coefficients
//! (tested in `tests/cli_probe_input.rs`). What was detected and done is returned as a
//! [`ProbeDetection`] (for `--json`) and told through [`Progress::note`] when the probe was
//! converted.

use std::path::Path;

use ibl_core::glam::Mat3;
use ibl_mapping::Mapping;
use serde::Serialize;

use crate::envmap_files::{self, EnvMapping, LoadedEnv};
use crate::error::{Context, Result};
use crate::progress::{Progress, rows};

/// Where the mapping of a probe came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MappingSource {
    /// The caller named it (`--mapping`).
    Given,
    /// Detected from the image's shape.
    Shape,
}

/// What the loader found and did, for messages and `--json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ProbeDetection {
    /// The file (or the `{face}` pattern), as given.
    pub file: String,
    /// Size of the image as stored (of the joined strip for six face files).
    pub stored_size: [usize; 2],
    /// The stored image's mapping.
    pub mapping: String,
    /// Where that mapping came from.
    pub mapping_source: MappingSource,
    /// The lat-long size it was resampled to; `None` when it was lat-long already.
    pub converted_to: Option<[usize; 2]>,
}

impl ProbeDetection {
    /// One sentence for the user: `sky.hdr: angular (from the 1:1 shape), converted to a
    /// 512 x 256 lat-long`.
    pub fn sentence(&self) -> String {
        let [w, h] = self.stored_size;
        let source = match self.mapping_source {
            MappingSource::Given => "as given".to_string(),
            MappingSource::Shape if self.mapping == Mapping::Angular.name() => format!(
                "from the {w} x {h} square shape; a mirror ball needs --mapping mirror-ball"
            ),
            MappingSource::Shape => format!("from the {w} x {h} shape"),
        };
        match self.converted_to {
            Some([cw, ch]) => format!(
                "{}: {} ({source}), converted to a {cw} x {ch} lat-long (energy-conserving)",
                self.file, self.mapping
            ),
            None => format!("{}: {} ({source})", self.file, self.mapping),
        }
    }
}

/// A probe as every job uses it: a lat-long radiance map, with what loading found.
pub struct LoadedProbe {
    /// The lat-long map (`env.mapping` is always [`Mapping::LatLong`]); `env.files` are the files
    /// read.
    pub env: LoadedEnv,
    /// What was detected and done.
    pub detection: ProbeDetection,
}

/// Reads a probe in `mapping` (`None`: detected from its shape, refused when the shape names
/// none), converts it to lat-long when needed and notes clamped values and the conversion on
/// `progress`. Cost: the read, plus O(W_out H_out k^2) for a conversion (`ibl_mapping::resample`).
pub fn load_probe(
    path: &Path,
    mapping: Option<EnvMapping>,
    progress: &dyn Progress,
) -> Result<LoadedProbe> {
    let env = envmap_files::load(path, mapping)?;
    envmap_files::note_clamped(&env, progress);
    let (w, h) = (env.image.width(), env.image.height());
    let mut detection = ProbeDetection {
        file: path.display().to_string(),
        stored_size: [w, h],
        mapping: mapping.map_or_else(|| env.mapping.name(), EnvMapping::name),
        mapping_source: if mapping.is_some() {
            MappingSource::Given
        } else {
            MappingSource::Shape
        },
        converted_to: None,
    };
    if env.mapping == Mapping::LatLong {
        return Ok(LoadedProbe { env, detection });
    }
    let (lw, lh) = Mapping::LatLong.default_size_for(env.mapping, w, h);
    progress.begin("converting to lat-long", lh as u64);
    let latlong = ibl_mapping::resample(
        &env.image,
        env.mapping,
        Mapping::LatLong,
        lw,
        lh,
        Mat3::IDENTITY,
        &rows(progress),
    );
    progress.end();
    let latlong = latlong.context(path.display().to_string())?;
    detection.converted_to = Some([lw, lh]);
    progress.note(&format!("note: {}", detection.sentence()));
    Ok(LoadedProbe {
        env: LoadedEnv {
            image: latlong,
            mapping: Mapping::LatLong,
            ..env
        },
        detection,
    })
}
