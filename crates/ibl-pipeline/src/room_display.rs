//! Grosch 2005 section 4.1's two displays of virtual objects in the reconstructed room, as a
//! scene a front end draws itself (the GPU viewer, live): the room is the real layer, the edits'
//! objects the virtual one, composited into the edited panorama by the difference rule, with
//! Grosch's lights.
//!
//! - **Real layer**: every patch of the room (walls, floor, boxes, windows) as its own
//!   triangles with its own reflectance (the edit's, per patch: rho = B / E, EQ3, after the
//!   material changes), so a shadow on the room subtracts exactly Grosch's
//!   `dL_i = rho / pi E_i` of the light the objects block.
//! - **Background**: the edited panorama the probe shows (material changes with their colour
//!   bleeding, new lights with their bounces: [`crate::room_render::EditedRoom::panorama`]), without the objects.
//! - **Lights**: each important patch as a point at its centroid (1 cm in front of it) radiating
//!   `L A cos theta` into its front hemisphere (a Lambertian patch seen from afar: its
//!   intensity times `cos theta_e / d^2` is the patch's irradiance, EQ5 with
//!   `I = L A cos theta`), and each new light as itself. All of them are already in the
//!   background, so on the room they only cast the objects' shadows; on the objects they light
//!   in the improved display and not in the fast one ([`RoomDisplay::lights_objects`]).
//! - **Ambient**: the irradiance volume (section 8 of docs/ROOMS.md) at a point, its second
//!   layer (the unimportant light) for the improved display, its first (all light) for the
//!   fast one, with the CPU display's leak control and visibility ([`RoomDisplay::ambient`]).
//!
//! What the CPU display (`ibl_room::ObjectDisplay`) does and this does not: each patch is one
//! point here, not 2 x 2 (harder shadows, a patch's near field), the volume is read at one point
//! for a whole object (the CPU reads it at every shaded point), and the improved display's
//! differential gather (the floor's light that the object now hides from its own underside) is
//! left out. The camera is expected at the probe's centre: the panorama is projected onto the
//! room from there, without the moved camera's fill of what the probe did not see.

use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};
use ibl_core::{Image, Rgb};
use ibl_light::{CandelaTable, GoniometricLight};
use ibl_room::irradiance_volume::KeyPointVisibility;
use ibl_room::{DisplayMode, ImportantLights, Room, RoomVolume};
use ibl_scene::description::{
    CameraDescription, CompositeRule, GeometryDescription, SceneDescription,
};
use ibl_scene::material::Material;
use ibl_scene::mesh::TriangleMesh;
use ibl_scene::{GeometryLayer, PlacedMesh, Scene};
use ibl_sh::{LeakControl, VolumeLayer};

use crate::error::{PipelineError, Result};
use crate::progress::Progress;
use crate::room_estimate::{SamplingOptions, estimate_read_room};
use crate::room_input::read_room;
use crate::room_render::{RoomEdits, edit_room, object_lighting};

/// How far in front of its patch an important patch's point light sits, metres: off the
/// patch's own plane, so that its wall does not shadow it.
pub const PATCH_LIGHT_OFFSET_M: f32 = 0.01;

/// The room and the edits' objects, ready to be drawn (see the module notes).
#[derive(Clone, Debug)]
pub struct RoomDisplay {
    /// The scene: the room file's probe (the edited panorama) and the objects (`description`'s
    /// `object` entries, mesh files resolved), the room as its real layer.
    pub scene: Scene,
    /// The description the scene was made from: the room file's `[probe]`, the edits' objects,
    /// a camera at the probe's centre looking at them (or the edits' `[view]`).
    pub description: SceneDescription,
    /// The room (for the volume's visibility tests).
    pub room: Room,
    /// The important patches.
    pub important: ImportantLights,
    /// The new lights of the edits.
    pub lamps: Vec<GoniometricLight>,
    /// The irradiance volume of the edited room.
    pub volume: RoomVolume,
    /// Fast or improved.
    pub mode: DisplayMode,
    /// Every file read.
    pub inputs: Vec<PathBuf>,
}

impl RoomDisplay {
    /// Reads the room file `room` and the edits file `edits` (which must insert objects),
    /// estimates the room and applies the edits. Errors name the file.
    pub fn open(room: &Path, edits: &Path, progress: &dyn Progress) -> Result<RoomDisplay> {
        let read = RoomEdits::read(edits)?;
        if read.objects.is_empty() {
            return Err(PipelineError::parameter(format!(
                "{}: inserts no [[object]]: the live display draws the objects an edits file \
                 inserts",
                edits.display()
            )));
        }
        let assets = read.load()?;
        let objects = assets
            .objects
            .clone()
            .ok_or_else(|| PipelineError::parameter(format!("{}: no objects", edits.display())))?;
        let input = read_room(room)?;
        let room_file = input.file.clone();
        let mut inputs = vec![
            room.to_path_buf(),
            edits.to_path_buf(),
            input.probe_path.clone(),
        ];
        inputs.extend(read.lights.iter().map(|l| l.file.clone()));
        let estimated = estimate_read_room(room, input, &SamplingOptions::default(), progress)?;
        let edited = edit_room(&estimated, &read, &assets, room)?;
        let field = edited.radiance(&estimated)?;
        let (important, volume) =
            object_lighting(&field, &edited.estimate, read.important_patches)?;
        let panorama = edited.panorama(&estimated)?;
        let the_room = estimated.input.room.clone();

        let folder = edits.parent().unwrap_or(Path::new("."));
        let mut described: Vec<GeometryDescription> = read.objects.clone();
        for o in &mut described {
            if let Some(file) = &mut o.file {
                *file = folder.join(&*file);
                inputs.push(file.clone());
            }
        }
        let camera = match &read.view {
            Some(v) => CameraDescription {
                position: v.position.to_array(),
                look_at: v.look_at.to_array(),
                up: [0.0, 1.0, 0.0],
                vertical_fov_deg: Some(v.vertical_fov_deg),
                focal_length_px: None,
                principal_point_px: None,
                image_size_px: Some([v.width, v.height]),
            },
            None => {
                let (lo, hi) = objects.bvh.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
                CameraDescription {
                    position: the_room.probe_position.to_array(),
                    look_at: ((lo + hi) * 0.5).to_array(),
                    up: [0.0, 1.0, 0.0],
                    vertical_fov_deg: Some(50.0),
                    focal_length_px: None,
                    principal_point_px: None,
                    image_size_px: Some([640, 480]),
                }
            }
        };
        let mut description = SceneDescription {
            version: room_file.version,
            probe: room_file.probe.clone(),
            background: Default::default(),
            camera: Some(camera),
            local: Vec::new(),
            object: Vec::new(),
            render: Default::default(),
            lighting: Default::default(),
            luminaire: Vec::new(),
            outdoor: None,
            room: None,
        };
        description.probe.radiance_scale = 1.0;
        description.render.composite = CompositeRule::Difference;
        // The scene without objects is assembled from the description (probe, camera), then
        // given the room and the objects already read.
        let mut scene = Scene::assemble(&description, panorama, None, Vec::new(), Vec::new())
            .map_err(|e| PipelineError::parameter(format!("{}: {e}", room.display())))?;
        scene.real = room_layer(&the_room, &edited.edit.reflectance);
        scene.virtual_objects = objects;
        description.object = described;
        Ok(RoomDisplay {
            scene,
            description,
            room: the_room,
            important,
            lamps: assets.lights.iter().map(|l| l.light.clone()).collect(),
            volume,
            mode: read.display,
            inputs,
        })
    }

    /// Whether the display's point lights light the objects (the improved display) or only
    /// cast their shadows on the room (the fast one, whose objects take all their light from
    /// the volume).
    pub fn lights_objects(&self) -> bool {
        self.mode == DisplayMode::Improved
    }

    /// The point lights: the important patches as Lambertian points, then the new lights.
    pub fn point_lights(&self) -> Vec<GoniometricLight> {
        let mut lights: Vec<GoniometricLight> = self
            .important
            .important
            .iter()
            .map(|p| {
                patch_light(
                    Vec3::from_array(p.position),
                    Vec3::from_array(p.normal),
                    Rgb::from_array(p.radiance) * p.area_m2,
                )
            })
            .collect();
        lights.extend(self.lamps.iter().cloned());
        lights
    }

    /// Per point light of [`RoomDisplay::point_lights`], the least squared distance its
    /// `1 / d^2` counts, m^2: a patch's area (the CPU display's rule for a patch's points,
    /// `cell_m2`, with one point per patch), 0 for a new light.
    pub fn near_field_m2(&self) -> Vec<f32> {
        let mut d2: Vec<f32> = self.important.important.iter().map(|p| p.area_m2).collect();
        d2.extend(self.lamps.iter().map(|_| 0.0));
        d2
    }

    /// The volume's irradiance at `point` for a surface facing `normal` (fast: all light;
    /// improved: the unimportant light), as `ibl_room::ObjectDisplay` reads it: leak control
    /// facing the normal, key points the room hides from the point left out (all of them when
    /// that leaves none); black where no key point is valid.
    pub fn ambient(&self, point: Vec3, normal: Vec3) -> Rgb {
        let layer = match self.mode {
            DisplayMode::Fast => VolumeLayer::AllLight,
            DisplayMode::Improved => VolumeLayer::UnimportantLight,
        };
        let leak = LeakControl::Facing(normal);
        let sample = |visibility| {
            self.volume
                .sample(&self.room, point, layer, leak, visibility)
        };
        sample(KeyPointVisibility::Unoccluded)
            .or_else(|| sample(KeyPointVisibility::Any))
            .map_or(Rgb::ZERO, |p| {
                Rgb::from_array(p.irradiance(normal)).map(|v| v.max(0.0))
            })
    }

    /// [`RoomDisplay::ambient`] at `point` for every direction of a `width x width / 2`
    /// lat-long grid (world frame): the ambient map of a small object there.
    pub fn ambient_map(&self, point: Vec3, width: usize) -> Image<Rgb> {
        let grid = ibl_core::LatLong::new(width, width / 2);
        Image::from_fn_par(width, width / 2, |i, j| {
            self.ambient(point, grid.pixel_dir64(i, j).as_vec3())
        })
    }
}

/// A Lambertian patch of power `L A` (radiance times area, per channel) at `centroid` facing
/// `normal`, as a goniometric point light [`PATCH_LIGHT_OFFSET_M`] in front of it: intensity
/// `L A cos theta` in its front hemisphere (the light's nadir, gamma = 0, along the normal).
pub fn patch_light(centroid: Vec3, normal: Vec3, power: Rgb) -> GoniometricLight {
    let steps = 90;
    let vertical: Vec<f32> = (0..=steps).map(|k| k as f32).collect();
    let candela: Vec<f32> = vertical
        .iter()
        .map(|g| g.to_radians().cos().max(0.0))
        .collect();
    let table = CandelaTable::new(vertical, vec![0.0], candela)
        .expect("a cosine over 0 to 90 degrees is a valid table");
    let n = normal.normalize_or(Vec3::Y);
    GoniometricLight {
        position: centroid + n * PATCH_LIGHT_OFFSET_M,
        world_from_light: Mat3::from_quat(glam::Quat::from_rotation_arc(Vec3::NEG_Y, n)),
        table,
        intensity_per_candela: power,
    }
}

/// The room's patches as one mesh, each patch its own material of its reflectance.
fn room_layer(room: &Room, reflectance: &[Rgb]) -> GeometryLayer {
    let mut mesh = TriangleMesh::default();
    let mut materials = Vec::new();
    for (k, p) in room.patches.iter().enumerate() {
        let slot = materials.len() as u32;
        mesh.material_names.push(format!("patch {k}"));
        materials.push(Material::Diffuse {
            albedo: reflectance.get(k).copied().unwrap_or(Rgb::ZERO),
        });
        for t in p.shape.triangles() {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(t);
            mesh.triangles.push([base, base + 1, base + 2]);
            mesh.material_slots.push(slot);
        }
    }
    GeometryLayer::new(vec![PlacedMesh {
        name: "room".into(),
        mesh,
        materials,
    }])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_patch_light_gives_a_patchs_far_field_irradiance() {
        // A 0.1 m^2 patch of radiance 2 on the ceiling (facing down) over a floor point 2 m
        // below and 1 m aside: E = L A cos theta_p cos theta_e / d^2.
        let light = patch_light(Vec3::new(0.0, 3.0, 0.0), Vec3::NEG_Y, Rgb::splat(2.0 * 0.1));
        let point = Vec3::new(1.0, 3.0 - 2.0 - PATCH_LIGHT_OFFSET_M, 0.0);
        let d2 = 5.0f32;
        let cos = 2.0 / d2.sqrt();
        let want = 0.2 * cos * cos / d2;
        let got = light.irradiance_at(point, Vec3::Y).g;
        // The table steps by 1 degree: cos is linear between steps, 1e-4 relative at most.
        assert!((got - want).abs() < 1e-3 * want, "{got} against {want}");
        // Nothing behind the patch.
        assert_eq!(
            light.irradiance_at(Vec3::new(0.0, 4.0, 0.0), Vec3::NEG_Y),
            Rgb::ZERO
        );
    }
}
