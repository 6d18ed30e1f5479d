//! `[background]`: what the render is composited into: the probe itself seen from its centre (a
//! panorama), or a photograph taken with the scene's pinhole `[camera]`. The checks that tie the
//! background to the camera are the whole description's (`SceneDescription::validate`).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// `[background]`: what the render is composited into.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BackgroundDescription {
    /// `panorama` (the probe seen from its centre; the default) or `photo`.
    #[serde(default)]
    pub kind: BackgroundKind,
    /// The photograph (linear HDR or 8-bit sRGB), relative to the scene file; `photo` only.
    pub file: Option<PathBuf>,
}

/// The two kinds of background.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BackgroundKind {
    /// The probe itself, seen from its centre, as a lat-long panorama.
    #[default]
    Panorama,
    /// A photograph taken with the pinhole `[camera]`.
    Photo,
}
