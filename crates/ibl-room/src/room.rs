//! A room ready for radiosity: its material groups, faces and patches, the BVH over the patches'
//! triangles, and the probe placed in it (world position and `world_from_probe`).
//!
//! Everything is in the world frame of `docs/CONVENTIONS.md` (+Y up, -Z forward), metres. Ray
//! queries return the patch hit and whether its front was hit: a patch radiates and receives on
//! its front only (Grosch's patches are one-sided), so a ray reaching a back side has found a
//! gap in the model, not light. The BVH is `ibl-scene`'s (two-sided, watertight), built over the
//! patches' triangles (two per rectangular patch), with a map from triangle to patch.

use glam::{Mat3, Vec3};
use ibl_core::{EulerDegrees, Rgb};
use ibl_scene::{Bvh, Material, PlacedMesh, Ray, TriangleMesh};

use crate::RoomError;
use crate::description::{GroupKind, RoomDescription, RoomFile};
use crate::geometry::{Face, faces};
use crate::patches::{Patch, subdivide};

/// A material group of a room.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    /// Name.
    pub name: String,
    /// Surface (estimated reflectance) or light (radiosity from the probe).
    pub kind: GroupKind,
    /// Reflectance measured by other means, if given (Table 1's "Real" column).
    pub measured_reflectance: Option<Rgb>,
}

/// What a ray met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchHit {
    /// The patch.
    pub patch: u32,
    /// Distance along the (unit) ray, metres.
    pub distance_m: f32,
    /// Whether the patch's front side was hit.
    pub front: bool,
}

/// A room: groups, faces, patches and the probe, with a BVH over the patches.
#[derive(Clone, Debug)]
pub struct Room {
    /// Material groups, in description order.
    pub groups: Vec<Group>,
    /// Planar faces.
    pub faces: Vec<Face>,
    /// Patches (Grosch section 3.3).
    pub patches: Vec<Patch>,
    /// Largest patch area the room was cut with, m^2.
    pub patch_area_m2: f32,
    /// The probe centre, world frame, metres.
    pub probe_position: Vec3,
    /// Rotation from probe directions to world directions.
    pub world_from_probe: Mat3,
    bvh: Bvh,
    triangle_patch: Vec<u32>,
}

/// Largest deviation of `M^T M` from the identity accepted for `world_from_probe`.
const ORTHOGONALITY_TOLERANCE: f32 = 1e-4;

impl Room {
    /// The room of `description` with the probe at `probe_position` (world, metres) and
    /// rotation `world_from_probe` (orthogonal, determinant +1). Cost: O(P log P) for P patches.
    pub fn new(
        description: &RoomDescription,
        probe_position: Vec3,
        world_from_probe: Mat3,
    ) -> Result<Room, RoomError> {
        if !probe_position.is_finite() {
            return Err(RoomError::invalid("probe.position", "is not finite"));
        }
        let gram = world_from_probe.transpose() * world_from_probe;
        if !(gram.abs_diff_eq(Mat3::IDENTITY, ORTHOGONALITY_TOLERANCE)
            && world_from_probe.determinant() > 0.0)
        {
            return Err(RoomError::Parameter(
                "world_from_probe is not a rotation (orthogonal with determinant +1)".into(),
            ));
        }
        let faces = faces(description)?;
        let patches = subdivide(&faces, description.patch_area_m2)?;
        let mut corners = Vec::with_capacity(patches.len() * 2);
        let mut triangle_patch = Vec::with_capacity(patches.len() * 2);
        for (i, p) in patches.iter().enumerate() {
            for t in p.shape.triangles() {
                corners.push(t);
                triangle_patch.push(i as u32);
            }
        }
        let groups = description
            .groups
            .iter()
            .map(|g| Group {
                name: g.name.clone(),
                kind: g.kind,
                measured_reflectance: g.measured_reflectance.map(Rgb::from_array),
            })
            .collect();
        Ok(Room {
            groups,
            faces,
            patches,
            patch_area_m2: description.patch_area_m2,
            probe_position,
            world_from_probe,
            bvh: Bvh::new(&corners),
            triangle_patch,
        })
    }

    /// The room of a room file: the probe's `position` and `rotation_deg` place it.
    pub fn from_file(file: &RoomFile) -> Result<Room, RoomError> {
        file.validate()?;
        let [yaw_deg, pitch_deg, roll_deg] = file.probe.rotation_deg;
        let world_from_probe = EulerDegrees {
            yaw_deg,
            pitch_deg,
            roll_deg,
        }
        .world_from_probe();
        Room::new(
            &file.room,
            Vec3::from(file.probe.position),
            world_from_probe,
        )
    }

    /// The closest patch along the unit ray `origin + t direction`, `t_min < t < t_max` metres.
    pub fn hit(&self, origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> Option<PatchHit> {
        let hit = self
            .bvh
            .closest_hit(&Ray::new(origin, direction), t_min, t_max)?;
        let patch = self.triangle_patch[hit.triangle as usize];
        Some(PatchHit {
            patch,
            distance_m: hit.t,
            front: self.patches[patch as usize].normal.dot(direction) < 0.0,
        })
    }

    /// Whether anything lies on the segment `origin + t direction`, `t_min < t < t_max`.
    pub fn occluded(&self, origin: Vec3, direction: Vec3, t_min: f32, t_max: f32) -> bool {
        self.bvh
            .occluded(&Ray::new(origin, direction), t_min, t_max)
    }

    /// The index of the group named `name`.
    pub fn group_index(&self, name: &str) -> Option<usize> {
        self.groups.iter().position(|g| g.name == name)
    }

    /// Axis-aligned bounds of the room, world frame, metres.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bvh.bounds()
    }

    /// The room's surfaces as meshes for `ibl-render`: one mesh per group for which `material`
    /// gives a material (groups it skips, such as windows that must stay open to the
    /// environment, are left out), made of the patches' triangles.
    pub fn placed_meshes(&self, material: impl Fn(&Group) -> Option<Material>) -> Vec<PlacedMesh> {
        let mut meshes = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            let Some(m) = material(group) else { continue };
            let mut mesh = TriangleMesh {
                material_names: vec![group.name.clone()],
                ..TriangleMesh::default()
            };
            for p in self.patches.iter().filter(|p| p.group as usize == g) {
                for t in p.shape.triangles() {
                    let base = mesh.positions.len() as u32;
                    mesh.positions.extend(t);
                    mesh.triangles.push([base, base + 1, base + 2]);
                    mesh.material_slots.push(0);
                }
            }
            if mesh.triangles.is_empty() {
                continue;
            }
            meshes.push(PlacedMesh {
                name: group.name.clone(),
                mesh,
                materials: vec![m],
            });
        }
        meshes
    }
}
