//! The room file (Grosch 2005, sections 3.1 to 3.3): a scene file (`docs/SCENES.md`) with a
//! `[probe]` and a `[room]` table, what the room commands read and write. Documented for users in
//! `docs/SCENES.md` (section `[room]`) and `docs/ROOMS.md`.
//!
//! The `[room]` table's types and their checks are the scene format's
//! (`ibl_scene::description`'s `room` module), re-exported here: groups, rectangles with holes,
//! boxes with openings, polygons. [`RoomFile::from_toml`] parses the text as a
//! `SceneDescription`, so every error is the scene parser's and names the field by its path
//! (`room.box[1].openings[0].min`), and keeps its `[probe]` and `[room]`; the probe's `position`
//! and `rotation_deg` (`world_from_probe`) place the probe in the room. Other tables of a scene
//! are accepted and left to the renderer; the room commands do not use them.

use ibl_scene::description::{FORMAT_VERSION, ProbeDescription, SceneDescription};
use serde::{Deserialize, Serialize};

pub use ibl_scene::description::{
    BoxDescription, BoxFace, Facing, GroupDescription, GroupKind, HoleDescription,
    MAX_COORDINATE_M, MAX_PATCH_AREA_M2, MAX_POLYGON_VERTICES, MAX_SURFACES, MIN_PATCH_AREA_M2,
    OpeningDescription, PolygonDescription, RectangleDescription, RoomDescription,
};

use crate::RoomError;

/// The only room format version this build reads (the scene format's version).
pub const ROOM_FORMAT_VERSION: u32 = FORMAT_VERSION;

/// A room file: a scene file holding the probe and the room.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoomFile {
    /// Format version; must be [`ROOM_FORMAT_VERSION`].
    pub version: u32,
    /// The probe: its image, `world_from_probe` rotation and world position (metres).
    pub probe: ProbeDescription,
    /// The room.
    pub room: RoomDescription,
}

impl RoomFile {
    /// Parses a room file's TOML text as a scene and validates it; errors name the field by its
    /// path (the scene parser's), and a scene without a `[room]` is refused naming `room`.
    pub fn from_toml(text: &str) -> Result<RoomFile, RoomError> {
        let scene = SceneDescription::from_toml(text)?;
        let room = scene.room.ok_or_else(|| {
            RoomError::invalid("room", "a room file needs a [room] table (docs/SCENES.md)")
        })?;
        let file = RoomFile {
            version: scene.version,
            probe: scene.probe,
            room,
        };
        file.validate()?;
        Ok(file)
    }

    /// The file as TOML text (what [`RoomFile::from_toml`] reads back).
    pub fn to_toml(&self) -> Result<String, RoomError> {
        toml::to_string(self).map_err(|e| RoomError::Numerical(format!("writing TOML: {e}")))
    }

    /// Checks every value, naming the field at fault.
    pub fn validate(&self) -> Result<(), RoomError> {
        if self.version != ROOM_FORMAT_VERSION {
            return Err(RoomError::invalid(
                "version",
                format!(
                    "format version {} is not supported (this build reads {ROOM_FORMAT_VERSION})",
                    self.version
                ),
            ));
        }
        finite3("probe.position", self.probe.position)?;
        finite3("probe.rotation_deg", self.probe.rotation_deg)?;
        if !(self.probe.radiance_scale.is_finite() && self.probe.radiance_scale > 0.0) {
            return Err(RoomError::invalid(
                "probe.radiance_scale",
                format!(
                    "{} is not a positive finite number",
                    self.probe.radiance_scale
                ),
            ));
        }
        Ok(self.room.validate()?)
    }
}

fn finite3(field: &str, v: [f32; 3]) -> Result<(), RoomError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(RoomError::invalid(field, format!("{v:?} is not finite")))
    }
}
