//! The `--mapping` and `--fov` options of every command that reads a probe (`lights`, `sh`,
//! `irradiance`, `eval`), parsed into the pipeline's [`EnvMapping`]; without `--mapping` the
//! pipeline's probe loader detects the mapping from the image's shape.

use clap::Args;
use ibl_pipeline::EnvMapping;

/// How the probe file is mapped.
#[derive(Args, Clone, Debug)]
pub struct ProbeMappingArgs {
    /// Mapping of the probe: latlong, angular, mirror-ball, cube-hcross, cube-vcross,
    /// cube-strip, cube-vstrip, cube-faces, fisheye, dual-fisheye (default: detected from its
    /// shape: 2:1 lat-long, 1:1 angular, 4:3 / 3:4 cross, 6:1 / 1:6 strip; other shapes are
    /// refused). Anything but lat-long is converted to lat-long first, energy-conserving, as
    /// `ibl convert` does.
    #[arg(long, value_name = "MAPPING")]
    pub mapping: Option<String>,
    /// Field of view in degrees for the fisheye mappings.
    #[arg(long = "fov", default_value_t = 180.0, value_name = "DEG")]
    pub fov: f32,
}

impl ProbeMappingArgs {
    /// The mapping named, if any.
    pub fn mapping(&self) -> anyhow::Result<Option<EnvMapping>> {
        Ok(self
            .mapping
            .as_deref()
            .map(|m| EnvMapping::parse(m, self.fov))
            .transpose()?)
    }
}
