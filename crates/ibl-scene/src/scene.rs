//! A scene ready to render: the real and the virtual geometry each in its own BVH, with
//! per-triangle shading data, the probe placed in the world, the background and the camera.
//!
//! Real and virtual geometry live in separate layers so that differential rendering can trace
//! the scene "without the objects" by skipping one layer: the real layer's hits are then bit for
//! bit the same in both passes, which is what makes an empty scene composite to the background
//! exactly (Debevec 1998; Grosch 2005 section 4.1).

use glam::{Mat3, Vec2, Vec3};
use ibl_core::{EulerDegrees, Image, Rgb};
use ibl_light::GoniometricLight;

use crate::description::{
    BackgroundKind, DescriptionError, GeometryDescription, LightingDescription, RenderDescription,
    SceneDescription, ShapeKind,
};
use crate::patch::PatchAttributes;
use crate::ray::gamma;
use crate::{Bvh, Camera, Hit, Material, TriangleMesh, primitives};

pub use crate::description::SPHERE_SUBDIVISIONS;

/// Shading data of one triangle of a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceTriangle {
    /// Unit vertex normals (the geometric normal three times for flat meshes).
    pub normals: [Vec3; 3],
    /// Unit geometric normal `(b - a) x (c - a)`, normalised: the front side.
    pub geometric_normal: Vec3,
    /// Index into the layer's materials.
    pub material: u32,
    /// Index into the layer's object names.
    pub object: u32,
}

/// The shading frame at a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// Hit position, world frame: the barycentric interpolation of the triangle's corners.
    pub position: Vec3,
    /// Per axis, a bound on the rounding error of `position` (world units): the computed point
    /// lies within this box of the exact point on the triangle (see
    /// [`GeometryLayer::surface_point`]).
    pub position_error: Vec3,
    /// Unit shading normal (interpolated), on the same side as `geometric_normal`.
    pub shading_normal: Vec3,
    /// Unit geometric normal, facing the incoming ray's origin.
    pub geometric_normal: Vec3,
    /// The material there.
    pub material: Material,
}

/// Triangles with a BVH and what each looks like. The geometry (`triangles`) is kept beside the
/// accelerator built over it, so that it can be subdivided into patches
/// ([`GeometryLayer::from_parts`] rebuilds the BVH); `triangles`, `surfaces` and `patches` are
/// parallel (one entry per triangle, the BVH's triangle indices).
#[derive(Clone, Debug)]
pub struct GeometryLayer {
    /// Corners of every triangle, world frame.
    pub triangles: Vec<[Vec3; 3]>,
    /// Accelerator over `triangles`.
    pub bvh: Bvh,
    /// Per-triangle shading data.
    pub surfaces: Vec<SurfaceTriangle>,
    /// Per-triangle radiosity data (reflectance, outgoing radiance).
    pub patches: Vec<PatchAttributes>,
    /// Materials referred to by `surfaces`: one per material group.
    pub materials: Vec<Material>,
    /// Name of each material group (`object/group`), parallel to `materials`.
    pub group_names: Vec<String>,
    /// Names of the objects, referred to by `surfaces`.
    pub object_names: Vec<String>,
}

/// Parts of a layer that do not fit together.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayerError {
    /// The per-triangle lists differ in length.
    #[error("{triangles} triangles but {surfaces} surfaces and {patches} patches")]
    Lengths {
        /// Triangles.
        triangles: usize,
        /// Shading entries.
        surfaces: usize,
        /// Radiosity entries.
        patches: usize,
    },
    /// A surface refers to a material or object that is not there.
    #[error("triangle {triangle} refers to a missing material or object")]
    Index {
        /// The triangle.
        triangle: usize,
    },
    /// The group names do not match the materials.
    #[error("{names} group names for {materials} materials")]
    Groups {
        /// Names.
        names: usize,
        /// Materials.
        materials: usize,
    },
}

impl LayerError {
    /// Always true: the parts come from the caller.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

/// A mesh with one material per material slot, to be placed in a layer.
#[derive(Clone, Debug)]
pub struct PlacedMesh {
    /// Name for messages.
    pub name: String,
    /// The mesh in the world frame.
    pub mesh: TriangleMesh,
    /// One material per entry of `mesh.material_names`.
    pub materials: Vec<Material>,
}

impl GeometryLayer {
    /// A layer holding `meshes`; every triangle is one patch of its material's diffuse albedo.
    /// Cost: O(T log T) for T triangles (the BVH build).
    pub fn new(meshes: Vec<PlacedMesh>) -> GeometryLayer {
        let mut corners = Vec::new();
        let mut surfaces = Vec::new();
        let mut patches = Vec::new();
        let mut materials = Vec::new();
        let mut group_names = Vec::new();
        let mut object_names = Vec::new();
        for (object, placed) in meshes.into_iter().enumerate() {
            let first_material = materials.len() as u32;
            materials.extend(placed.materials);
            let mesh = placed.mesh;
            group_names.extend(
                mesh.material_names
                    .iter()
                    .map(|group| format!("{}/{group}", placed.name)),
            );
            object_names.push(placed.name);
            for (i, tri) in mesh.triangles.iter().enumerate() {
                let c = mesh.corners(i);
                let geometric_normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero();
                let normals = if mesh.normals.is_empty() {
                    [geometric_normal; 3]
                } else {
                    tri.map(|v| mesh.normals[v as usize])
                };
                corners.push(c);
                let material = first_material + mesh.material_slots[i];
                surfaces.push(SurfaceTriangle {
                    normals,
                    geometric_normal,
                    material,
                    object: object as u32,
                });
                patches.push(PatchAttributes::unlit(
                    materials[material as usize].diffuse_albedo(),
                ));
            }
        }
        GeometryLayer {
            bvh: Bvh::new(&corners),
            triangles: corners,
            surfaces,
            patches,
            materials,
            group_names,
            object_names,
        }
    }

    /// A layer from its parts (for instance after subdividing `triangles` into patches), the BVH
    /// built anew. Cost: O(T log T).
    pub fn from_parts(
        triangles: Vec<[Vec3; 3]>,
        surfaces: Vec<SurfaceTriangle>,
        patches: Vec<PatchAttributes>,
        materials: Vec<Material>,
        group_names: Vec<String>,
        object_names: Vec<String>,
    ) -> Result<GeometryLayer, LayerError> {
        if surfaces.len() != triangles.len() || patches.len() != triangles.len() {
            return Err(LayerError::Lengths {
                triangles: triangles.len(),
                surfaces: surfaces.len(),
                patches: patches.len(),
            });
        }
        if group_names.len() != materials.len() {
            return Err(LayerError::Groups {
                names: group_names.len(),
                materials: materials.len(),
            });
        }
        if let Some(triangle) = surfaces.iter().position(|s| {
            s.material as usize >= materials.len() || s.object as usize >= object_names.len()
        }) {
            return Err(LayerError::Index { triangle });
        }
        Ok(GeometryLayer {
            bvh: Bvh::new(&triangles),
            triangles,
            surfaces,
            patches,
            materials,
            group_names,
            object_names,
        })
    }

    /// An empty layer.
    pub fn empty() -> GeometryLayer {
        GeometryLayer::new(Vec::new())
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.surfaces.len()
    }

    /// The shading frame of `hit` for a ray travelling along `direction`: normals flipped to face
    /// the ray's origin (surfaces are two-sided), the shading normal bent back to the geometric
    /// side if interpolation pushed it over.
    ///
    /// The position is interpolated from the corners, `p = b0 p0 + b1 p1 + b2 p2`, not taken
    /// along the ray (`o + t d` carries the error of `t`, which grows with the distance travelled).
    /// Its rounding error is bounded per axis by `gamma_7 (|b0 p0| + |b1 p1| + |b2 p2|)` with
    /// `gamma_n = n u / (1 - n u)`, `u = 2^-24` (Pharr, Jakob and Humphreys, *Physically Based
    /// Rendering*, 4th ed., section 6.8.5): it depends on where the triangle is, never on the
    /// size of the rest of the scene.
    pub fn surface_point(&self, hit: &Hit, direction: Vec3) -> SurfacePoint {
        let s = &self.surfaces[hit.triangle as usize];
        let w = 1.0 - hit.u - hit.v;
        let [p0, p1, p2] = self.triangles[hit.triangle as usize];
        let (a, b, c) = (p0 * w, p1 * hit.u, p2 * hit.v);
        let position = a + b + c;
        let position_error = (a.abs() + b.abs() + c.abs()) * gamma(7);
        let mut shading = (s.normals[0] * w + s.normals[1] * hit.u + s.normals[2] * hit.v)
            .normalize_or(s.geometric_normal);
        let mut geometric = s.geometric_normal;
        if geometric.dot(direction) > 0.0 {
            geometric = -geometric;
            shading = -shading;
        }
        if shading.dot(geometric) <= 0.0 {
            shading = geometric;
        }
        SurfacePoint {
            position,
            position_error,
            shading_normal: shading,
            geometric_normal: geometric,
            material: self.materials[s.material as usize],
        }
    }
}

/// The light probe placed in the world.
#[derive(Clone, Debug)]
pub struct Probe {
    /// Lat-long radiance, already multiplied by the scene's `radiance_scale`.
    pub radiance: Image<Rgb>,
    /// Rotation from the probe frame to the world.
    pub world_from_probe: Mat3,
    /// The probe centre, world frame.
    pub position: Vec3,
}

/// What the render is composited into.
#[derive(Clone, Debug)]
pub enum Background {
    /// The probe itself, seen from its centre.
    Panorama,
    /// A photograph (linear radiance, row 0 at the top), taken with the scene's pinhole camera.
    Photo(Image<Rgb>),
}

/// A mesh read from a file: the mesh in its model frame and a diffuse albedo per material name.
#[derive(Clone, Debug)]
pub struct MeshAsset {
    /// The mesh, model frame.
    pub mesh: TriangleMesh,
    /// Diffuse albedo per entry of `mesh.material_names` (the file's base colours).
    pub base_albedo: Vec<Rgb>,
}

/// A scene ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Real geometry (the local scene).
    pub real: GeometryLayer,
    /// Virtual objects.
    pub virtual_objects: GeometryLayer,
    /// The probe.
    pub probe: Probe,
    /// The background.
    pub background: Background,
    /// The camera.
    pub camera: Camera,
    /// Renderer settings from the file.
    pub render: RenderDescription,
    /// Lighting settings from the file.
    pub lighting: LightingDescription,
    /// The file's `[[luminaire]]` entries as lights (world frame, the probe's radiance unit per
    /// sr): `ibl-io`'s scene reader reads their files; [`Scene::assemble`] leaves this empty.
    pub luminaires: Vec<GoniometricLight>,
}

fn rgb(v: [f32; 3]) -> Rgb {
    Rgb::new(v[0], v[1], v[2])
}

impl Scene {
    /// Builds a scene from a validated description, the probe image, the photograph (photo
    /// backgrounds) and the meshes of the `mesh` entries, in file order (`local` then `object`;
    /// `None` for the other shapes).
    pub fn assemble(
        description: &SceneDescription,
        probe_radiance: Image<Rgb>,
        photo: Option<Image<Rgb>>,
        local_meshes: Vec<Option<MeshAsset>>,
        object_meshes: Vec<Option<MeshAsset>>,
    ) -> Result<Scene, DescriptionError> {
        description.validate()?;
        let p = &description.probe;
        let world_from_probe = EulerDegrees {
            yaw_deg: p.rotation_deg[0],
            pitch_deg: p.rotation_deg[1],
            roll_deg: p.rotation_deg[2],
        }
        .world_from_probe();
        let scale = p.radiance_scale;
        let probe = Probe {
            radiance: probe_radiance.map(|&l| l * scale),
            world_from_probe,
            position: Vec3::from(p.position),
        };
        let (background, size) = match description.background.kind {
            BackgroundKind::Panorama => (Background::Panorama, None),
            BackgroundKind::Photo => {
                let photo = photo.ok_or_else(|| DescriptionError {
                    field: "background.file".into(),
                    problem: "the photograph was not loaded".into(),
                })?;
                let size = (photo.width() as u32, photo.height() as u32);
                (Background::Photo(photo), Some(size))
            }
        };
        let camera = match &description.camera {
            None => Camera::Panorama {
                position: probe.position,
                world_from_probe,
            },
            Some(camera) => {
                // `validate` made sure a size is known and exactly one focal length is given.
                let size = size
                    .or(camera.image_size_px.map(|[w, h]| (w, h)))
                    .unwrap_or((640, 480));
                let focal = match camera.focal_length_px {
                    Some(f) => Vec2::from(f),
                    None => Vec2::splat(Camera::focal_from_vertical_fov(
                        camera.vertical_fov_deg.unwrap_or(50.0),
                        size.1,
                    )),
                };
                let principal = camera
                    .principal_point_px
                    .map(Vec2::from)
                    .unwrap_or(Vec2::new(size.0 as f32, size.1 as f32) * 0.5);
                Camera::look_at(
                    Vec3::from(camera.position),
                    Vec3::from(camera.look_at),
                    Vec3::from(camera.up),
                    focal,
                    principal,
                    size,
                )
            }
        };
        let real = layer("local", &description.local, local_meshes, LayerKind::Real)?;
        let virtual_objects = layer(
            "object",
            &description.object,
            object_meshes,
            LayerKind::Virtual,
        )?;
        Ok(Scene {
            real,
            virtual_objects,
            probe,
            background,
            camera,
            render: description.render.clone(),
            lighting: description.lighting.clone(),
            luminaires: Vec::new(),
        })
    }
}

/// Virtual objects described as a scene file's `[[object]]` entries (an edits file's too), each
/// checked as a scene's are (`object[i]` in messages), with their meshes as loaded (`None` for
/// shapes; one entry per description).
pub fn virtual_layer(
    entries: &[GeometryDescription],
    meshes: Vec<Option<MeshAsset>>,
) -> Result<GeometryLayer, DescriptionError> {
    for (i, entry) in entries.iter().enumerate() {
        entry.validate(&format!("object[{i}]"), crate::description::Layer::Virtual)?;
    }
    layer("object", entries, meshes, LayerKind::Virtual)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum LayerKind {
    Real,
    Virtual,
}

fn layer(
    table: &str,
    entries: &[GeometryDescription],
    meshes: Vec<Option<MeshAsset>>,
    kind: LayerKind,
) -> Result<GeometryLayer, DescriptionError> {
    let mut placed = Vec::with_capacity(entries.len());
    let mut meshes = meshes.into_iter();
    for (i, entry) in entries.iter().enumerate() {
        let path = format!("{table}[{i}]");
        let asset = meshes.next().flatten();
        let (model, base_albedo) = match entry.shape {
            ShapeKind::Mesh => {
                let asset = asset.ok_or_else(|| DescriptionError {
                    field: format!("{path}.file"),
                    problem: "the mesh was not loaded".into(),
                })?;
                (asset.mesh, asset.base_albedo)
            }
            ShapeKind::Plane => (
                primitives::plane(
                    Vec3::from(entry.center.unwrap_or_default()),
                    Vec3::from(entry.normal.unwrap_or([0.0, 1.0, 0.0])),
                    entry.size.unwrap_or([1.0, 1.0]),
                ),
                Vec::new(),
            ),
            ShapeKind::Box => (
                primitives::cuboid(
                    Vec3::from(entry.min.unwrap_or([-0.5; 3])),
                    Vec3::from(entry.max.unwrap_or([0.5; 3])),
                ),
                Vec::new(),
            ),
            ShapeKind::Sphere => (
                primitives::sphere(
                    Vec3::from(entry.center.unwrap_or_default()),
                    entry.radius.unwrap_or(1.0),
                    SPHERE_SUBDIVISIONS,
                ),
                Vec::new(),
            ),
        };
        let mut mesh = model.transformed(entry.world_from_model());
        mesh.validate().map_err(|e| DescriptionError {
            field: path.clone(),
            problem: e.to_string(),
        })?;
        if let Some(groups) = &entry.albedo_by_group
            && let Some(unknown) = groups.keys().find(|g| !mesh.material_names.contains(g))
        {
            return Err(DescriptionError {
                field: format!("{path}.albedo_by_group.{unknown}"),
                problem: format!(
                    "no material group of that name (the mesh has: {})",
                    mesh.material_names.join(", ")
                ),
            });
        }
        let materials = mesh
            .material_names
            .iter()
            .enumerate()
            .map(|(slot, name)| {
                let file_albedo = base_albedo.get(slot).copied().unwrap_or(Rgb::splat(0.8));
                match kind {
                    LayerKind::Real => Material::Diffuse {
                        albedo: entry
                            .albedo_by_group
                            .as_ref()
                            .and_then(|g| g.get(name))
                            .or(entry.albedo.as_ref())
                            .map(|&a| rgb(a))
                            .unwrap_or(file_albedo),
                    },
                    LayerKind::Virtual => match (&entry.material, entry.albedo) {
                        (Some(m), _) => m.material(),
                        (None, Some(a)) => Material::Diffuse { albedo: rgb(a) },
                        (None, None) => Material::Diffuse {
                            albedo: file_albedo,
                        },
                    },
                }
            })
            .collect();
        placed.push(PlacedMesh {
            name: entry.name.clone().unwrap_or(path),
            mesh,
            materials,
        });
    }
    Ok(GeometryLayer::new(placed))
}
