//! The scene the viewer edits: the scene file's description (the edits live in it, so saving
//! writes exactly what the user changed), the scene assembled by `ibl-io` from it at load (for
//! the lights and the geometry), and what the mouse does to objects.
//!
//! An object's placement is its entry's `world_from_model = T R S` (`docs/SCENES.md`); the
//! geometry was placed once at load, so the GPU draws it through
//! `world_from_load = world_from_model(now) world_from_model(load)^-1`.
//!
//! Interaction (Blender-like, in the window's terms): a click picks the nearest virtual object
//! under the cursor (ray against each object's BVH, in its load frame); dragging it moves it
//! along the horizontal plane through the point that was grabbed (so it slides over the ground
//! and keeps its height); with Shift it turns about +Y (yaw); with Ctrl it scales about its own
//! origin. Lights do not depend on the objects and are not recomputed.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Affine3A, Vec3};
use ibl_light::LightSet;
use ibl_pipeline::LightingPlan;
use ibl_scene::description::{
    GeometryDescription, MaterialDescription, MaterialKind, RenderMode, Scale,
};
use ibl_scene::{Material, Ray, Scene, SceneDescription};

use crate::ViewerError;
use crate::scene_geometry::SceneGeometry;

/// A scene file opened for viewing and editing.
#[derive(Clone, Debug)]
pub struct SceneModel {
    /// The scene file.
    pub path: PathBuf,
    /// Its text as read (saving keeps its comments and layout).
    pub text: String,
    /// The description as read.
    pub original: SceneDescription,
    /// The description with the user's edits.
    pub description: SceneDescription,
    /// The scene as assembled at load.
    pub scene: Arc<Scene>,
    /// Its triangles.
    pub geometry: SceneGeometry,
    /// `world_from_model` of every virtual object at load.
    load_placements: Vec<Affine3A>,
    /// Every file the scene read.
    pub inputs: Vec<PathBuf>,
    /// The lights of the scene's `[lighting] lights_file` (a light set, or an area-light file's
    /// patches seen from the probe's centre), probe frame, with the probe's
    /// `radiance_scale` applied (the rule of `ibl_pipeline::lighting_plan`); read once at load.
    given_lights: Option<LightSet>,
}

/// What the mouse does to the selected object while dragging.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DragAction {
    /// Slide along the horizontal plane through the grabbed point.
    Move,
    /// Turn about +Y.
    Rotate,
    /// Scale about the object's origin.
    Scale,
}

/// Degrees of yaw per pixel of horizontal drag.
pub const ROTATE_DEG_PER_PIXEL: f32 = 0.5;
/// Relative scale change per pixel of vertical drag (up grows).
pub const SCALE_PER_PIXEL: f32 = 0.005;

impl SceneModel {
    /// Reads a scene file and everything it names (`ibl_io::read_scene`).
    pub fn open(path: &Path) -> Result<SceneModel, ViewerError> {
        let loaded = ibl_io::read_scene(path)?;
        let text = ibl_io::read_text(path, ibl_io::scene_file::MAX_SCENE_BYTES)?;
        let geometry = SceneGeometry::from_scene(&loaded.scene);
        let given_lights = match &loaded.lights_path {
            Some(file) => Some(
                ibl_io::area_light_file::read_scene_lights(file)?
                    .scaled(f64::from(loaded.description.probe.radiance_scale)),
            ),
            None => None,
        };
        let load_placements = loaded
            .description
            .object
            .iter()
            .map(GeometryDescription::world_from_model)
            .collect();
        Ok(SceneModel {
            path: path.to_path_buf(),
            text,
            original: loaded.description.clone(),
            description: loaded.description,
            scene: Arc::new(loaded.scene),
            geometry,
            load_placements,
            inputs: loaded.inputs,
            given_lights,
        })
    }

    /// A scene made in memory rather than read from a file (a room's live display,
    /// `ibl_pipeline::room_display`): `description` and `scene` as the scene reader would give
    /// them, `path` the file it stands for (messages; saving is the front end's to refuse).
    pub fn from_parts(
        path: &Path,
        description: SceneDescription,
        scene: Scene,
        inputs: Vec<PathBuf>,
    ) -> SceneModel {
        let geometry = SceneGeometry::from_scene(&scene);
        let load_placements = description
            .object
            .iter()
            .map(GeometryDescription::world_from_model)
            .collect();
        SceneModel {
            path: path.to_path_buf(),
            text: String::new(),
            original: description.clone(),
            description,
            scene: Arc::new(scene),
            geometry,
            load_placements,
            inputs,
            given_lights: None,
        }
    }

    /// Number of virtual objects.
    pub fn object_count(&self) -> usize {
        self.description.object.len()
    }

    /// The name of virtual object `i`.
    pub fn object_name(&self, i: usize) -> String {
        self.description.object[i]
            .name
            .clone()
            .unwrap_or_else(|| format!("object[{i}]"))
    }

    /// `world_from_load` of virtual object `i` (see the module notes).
    pub fn world_from_load(&self, i: usize) -> Affine3A {
        self.description.object[i].world_from_model() * self.load_placements[i].inverse()
    }

    /// The world box of virtual object `i` as placed now, `(min, max)` (`None` when it has no
    /// triangles): its load bounds' corners moved by `world_from_load`.
    pub fn object_box(&self, i: usize) -> Option<(Vec3, Vec3)> {
        let g = &self.geometry.objects[i];
        if g.vertices.is_empty() {
            return None;
        }
        let m = self.world_from_load(i);
        let (a, b) = g.bounds;
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for corner in crate::light_space::box_corners(a, b) {
            let p = m.transform_point3(corner);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Some((lo, hi))
    }

    /// Every distinct vertex of every virtual object as placed now, world frame (the point
    /// lights' shadow cones: `point_lights::shadow_cone`).
    pub fn caster_points(&self) -> Vec<Vec3> {
        (0..self.geometry.objects.len())
            .flat_map(|i| {
                let m = self.world_from_load(i);
                self.geometry.objects[i]
                    .points
                    .iter()
                    .map(move |&p| m.transform_point3(p))
            })
            .collect()
    }

    /// The bounding sphere of every virtual object as placed now (`None` without objects).
    pub fn objects_sphere(&self) -> Option<(Vec3, f32)> {
        let (lo, hi) = (0..self.geometry.objects.len())
            .filter_map(|i| self.object_box(i))
            .reduce(|(lo, hi), (a, b)| (lo.min(a), hi.max(b)))?;
        Some(crate::light_space::bounding_sphere(lo, hi))
    }

    /// The materials of every triangle slot as edited (real first, then each object's).
    pub fn materials(&self) -> Vec<Material> {
        let mut materials = self.geometry.materials.clone();
        for (i, g) in self.geometry.objects.iter().enumerate() {
            if let Some(m) = self.edited_material(i) {
                for slot in g.materials.clone() {
                    materials[slot as usize] = m;
                }
            }
        }
        materials
    }

    /// Whether a virtual object reflects the environment (a mirror, or a glossy lobe that may be
    /// drawn from the prefiltered probe): a changing environment must then be uploaded again.
    pub fn reflects_environment(&self) -> bool {
        let materials = self.materials();
        self.geometry.objects.iter().any(|g| {
            g.materials
                .clone()
                .any(|slot| !matches!(materials[slot as usize], Material::Diffuse { .. }))
        })
    }

    /// The material of object `i` if the user set one (`None`: the file's own materials).
    fn edited_material(&self, i: usize) -> Option<Material> {
        let now = &self.description.object[i];
        let then = &self.original.object[i];
        (now.material != then.material || now.albedo != then.albedo).then(|| {
            match (&now.material, now.albedo) {
                (Some(m), _) => m.material(),
                (None, Some(a)) => Material::Diffuse {
                    albedo: ibl_core::Rgb::new(a[0], a[1], a[2]),
                },
                (None, None) => Material::Diffuse {
                    albedo: ibl_core::Rgb::splat(0.8),
                },
            }
        })
    }

    /// Sets the material of object `i` (the scene file's `material` table).
    pub fn set_material(&mut self, i: usize, material: MaterialDescription) {
        self.description.object[i].material = Some(material);
    }

    /// The material of object `i` as a description the UI can edit.
    pub fn material_description(&self, i: usize) -> MaterialDescription {
        let entry = &self.description.object[i];
        if let Some(m) = &entry.material {
            return m.clone();
        }
        let slot = self.geometry.objects[i].materials.start as usize;
        let albedo = match self.geometry.materials.get(slot) {
            Some(m) => m.diffuse_albedo(),
            None => ibl_core::Rgb::splat(0.5),
        };
        MaterialDescription {
            kind: MaterialKind::Diffuse,
            albedo: Some([albedo.r, albedo.g, albedo.b]),
            specular: None,
            exponent: None,
        }
    }

    /// The nearest virtual object hit by a world ray, and the hit distance.
    pub fn pick(&self, origin: Vec3, direction: Vec3) -> Option<(usize, f32)> {
        let mut best: Option<(usize, f32)> = None;
        for (i, g) in self.geometry.objects.iter().enumerate() {
            let load_from_world = self.world_from_load(i).inverse();
            let o = load_from_world.transform_point3(origin);
            let d = load_from_world.transform_vector3(direction);
            let Some(hit) = g.bvh.closest_hit(&Ray::new(o, d), 0.0, f32::INFINITY) else {
                continue;
            };
            let p = self
                .world_from_load(i)
                .transform_point3(o + Ray::new(o, d).direction * hit.t);
            let t = (p - origin).dot(direction.normalize());
            if best.is_none_or(|(_, bt)| t < bt) {
                best = Some((i, t));
            }
        }
        best
    }

    /// Object `i`'s translation (world frame).
    pub fn translation(&self, i: usize) -> Vec3 {
        Vec3::from(self.description.object[i].translate.unwrap_or_default())
    }

    /// Moves object `i` by `delta` (world frame).
    pub fn translate(&mut self, i: usize, delta: Vec3) {
        let entry = &mut self.description.object[i];
        let t = Vec3::from(entry.translate.unwrap_or_default()) + delta;
        entry.translate = Some(t.to_array());
    }

    /// Turns object `i` by `degrees` about +Y (its yaw).
    pub fn rotate(&mut self, i: usize, degrees: f32) {
        let entry = &mut self.description.object[i];
        let [yaw, pitch, roll] = entry.rotate_deg.unwrap_or_default();
        entry.rotate_deg = Some([
            (yaw + degrees + 180.0).rem_euclid(360.0) - 180.0,
            pitch,
            roll,
        ]);
    }

    /// Scales object `i` by `factor` (> 0) about its origin.
    pub fn scale(&mut self, i: usize, factor: f32) {
        if !(factor.is_finite() && factor > 0.0) {
            return;
        }
        let entry = &mut self.description.object[i];
        entry.scale = Some(match entry.scale {
            None => Scale::Uniform(factor),
            Some(Scale::Uniform(s)) => Scale::Uniform(s * factor),
            Some(Scale::PerAxis(s)) => Scale::PerAxis(s.map(|v| v * factor)),
        });
    }

    /// Applies a drag of `(dx, dy)` pixels to object `i` (rotate and scale); moving is done with
    /// [`SceneModel::drag_to`], which needs the rays.
    pub fn drag_pixels(&mut self, i: usize, action: DragAction, dx: f32, dy: f32) {
        match action {
            DragAction::Move => {}
            DragAction::Rotate => self.rotate(i, dx * ROTATE_DEG_PER_PIXEL),
            DragAction::Scale => self.scale(i, (-dy * SCALE_PER_PIXEL).exp()),
        }
    }

    /// Moves object `i` along the horizontal plane `y = plane_y` from where ray `from` meets it to
    /// where ray `to` does (`(origin, direction)` pairs); nothing when a ray misses the plane or
    /// meets it more than `max_distance` away (a ray grazing the horizon).
    pub fn drag_to(
        &mut self,
        i: usize,
        plane_y: f32,
        from: (Vec3, Vec3),
        to: (Vec3, Vec3),
        max_distance: f32,
    ) {
        let meet = |(o, d): (Vec3, Vec3)| {
            let t = (plane_y - o.y) / d.y;
            (d.y.abs() > 1e-6 && t > 0.0 && t * d.length() < max_distance).then(|| o + d * t)
        };
        if let (Some(a), Some(b)) = (meet(from), meet(to)) {
            let delta = b - a;
            self.translate(i, Vec3::new(delta.x, 0.0, delta.z));
        }
    }

    /// The lighting plan of the scene as edited (the viewer's `lights` or `hybrid` mode: a
    /// reference render cannot be drawn in real time, so `reference` draws as `lights`).
    pub fn lighting_plan(&self) -> LightingPlan {
        let l = &self.description.lighting;
        LightingPlan {
            mode: self.mode(),
            source: l.method,
            lights: l.lights as usize,
            given: self.given_lights.clone(),
            shadows: l.shadows,
            ambient_bands: l.ambient_bands,
            occlusion_rays: l.ao_samples,
            seed: self.description.render.seed,
        }
    }

    /// The mode the viewer draws: the file's `lights` or `hybrid`; `reference` draws as `lights`.
    pub fn mode(&self) -> RenderMode {
        match self.description.render.mode {
            RenderMode::Hybrid => RenderMode::Hybrid,
            RenderMode::Lights | RenderMode::Reference => RenderMode::Lights,
        }
    }

    /// Whether the description differs from the file.
    pub fn is_edited(&self) -> bool {
        self.description != self.original
    }
}
