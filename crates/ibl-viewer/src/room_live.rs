//! Grosch 2005's two displays live on the GPU (issue 17, part 6): the objects an edits file
//! inserts, drawn by the scene pass in the reconstructed room, which is the real layer
//! (`ibl_pipeline::room_display`, the library's account of what is drawn and what is left out).
//! The important patches are point lights already in the background, each with its cube shadow
//! map (`point_lights.rs`): in both displays the objects' shadows of them are subtracted from
//! the room as `rho E_i / pi`; in the improved display they also light the objects, over the
//! irradiance volume's unimportant light; in the fast display the objects take the volume's
//! total irradiance alone. The volume is read by normal at the objects' centre into the
//! scene pass's ambient map.

use std::path::Path;

use ibl_pipeline::progress::Progress;
use ibl_pipeline::room_display::RoomDisplay;
use ibl_room::DisplayMode;

use crate::ViewerError;
use crate::gpu_scene::MAX_POINT_LIGHTS;
use crate::lighting::{IRRADIANCE_MAP_WIDTH, SceneLighting};
use crate::point_lights::PointLightRole;
use crate::scene_model::SceneModel;

/// A room's live display: the scene to draw and its lights.
#[derive(Clone, Debug)]
pub struct RoomLive {
    /// The room as the real layer, the objects, the edited panorama.
    pub model: SceneModel,
    /// The patches and new lights as point lights, the volume as the ambient.
    pub lighting: SceneLighting,
}

/// Estimates the room `room`, applies the edits file `edits` (which must insert objects) and
/// makes its live display.
pub fn room_live(
    room: &Path,
    edits: &Path,
    progress: &dyn Progress,
) -> Result<RoomLive, ViewerError> {
    let display = RoomDisplay::open(room, edits, progress)?;
    let lights = display.point_lights();
    if lights.len() > MAX_POINT_LIGHTS {
        return Err(ViewerError::Input {
            path: edits.to_path_buf(),
            problem: format!(
                "{} important patches and new lights: the live display draws at most {MAX_POINT_LIGHTS} \
                 shadowed point lights (lower important_patches)",
                lights.len()
            ),
        });
    }
    let model = SceneModel::from_parts(
        edits,
        display.description.clone(),
        display.scene.clone(),
        display.inputs.clone(),
    );
    let centre = model
        .objects_sphere()
        .map_or(display.room.probe_position, |(c, _)| c);
    let ambient = display.ambient_map(centre, IRRADIANCE_MAP_WIDTH);
    let patches = display.important.important.len();
    let summary = match display.mode {
        DisplayMode::Improved => format!(
            "Grosch's improved display: {patches} important patches and {} new lights as shadowed \
             point lights + the volume's unimportant light",
            display.lamps.len()
        ),
        DisplayMode::Fast => format!(
            "Grosch's fast display: the volume's total light, the shadows of {patches} important \
             patches and {} new lights subtracted from the room",
            display.lamps.len()
        ),
    };
    let lighting = SceneLighting {
        lights: Vec::new(),
        luminaires: lights,
        luminaire_role: PointLightRole {
            in_background: true,
            light_objects: display.lights_objects(),
        },
        luminaire_near_field_m2: display.near_field_m2(),
        occlusion_gather: display.lights_objects(),
        ambient: Some(ambient),
        summary,
    };
    Ok(RoomLive { model, lighting })
}
