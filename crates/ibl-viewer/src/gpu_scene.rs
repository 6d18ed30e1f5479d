//! The scene's data on the GPU: vertex buffers, materials, object transforms, lights and the
//! per-frame uniform. The structs here are the byte-for-byte twins of `gpu_scene.wgsl` (every
//! field a 16-byte column, so neither side pads).

use bytemuck::{Pod, Zeroable};
use glam::{Affine3A, Mat3, Mat4, Vec4};
use ibl_scene::Material;
use wgpu::util::DeviceExt;

use crate::gpu::GpuContext;
use crate::scene_geometry::SceneGeometry;

/// `Frame` of `gpu_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    /// Clip space from world.
    pub clip_from_world: [[f32; 4]; 4],
    /// Camera right, up, back (columns).
    pub world_from_camera: [[f32; 4]; 4],
    /// The eye.
    pub camera_position: [f32; 4],
    /// fx, fy, cx, cy (output pixels).
    pub intrinsics: [f32; 4],
    /// World to probe frame.
    pub probe_from_world: [[f32; 4]; 4],
    /// Probe centre and the probe texture's radiance scale.
    pub probe_position: [f32; 4],
    /// width, height, 1 / width, 1 / height.
    pub viewport: [f32; 4],
    /// x: the light count; y, z, w: 0 (the scene's other choices are pipeline constants,
    /// `scene_pass.rs`'s `ShaderVariant`).
    pub counts: [u32; 4],
    /// glossy level-1 exponent, glossy levels, photo scale, ambient scale.
    pub environment: [f32; 4],
    /// real atlas size, virtual atlas size (texels).
    pub atlas: [f32; 4],
    /// The flat real layer's plane `(n, d)`, `n . p + d = 0` (zero when it is not flat).
    pub real_plane: [f32; 4],
    /// The objects' occluding sphere (centre, radius), zero without the gather.
    pub occluder: [f32; 4],
    /// Their mean diffuse albedo.
    pub occluder_albedo: [f32; 4],
}

/// `Light` of `gpu_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuLight {
    /// Direction towards the light; w: tan of the cone's half-angle.
    pub direction: [f32; 4],
    /// `I = L A`.
    pub irradiance: [f32; 4],
    /// Real atlas projection.
    pub real_map: [[f32; 4]; 4],
    /// Real atlas tile (uv rect).
    pub real_tile: [f32; 4],
    /// Real tile half extent, depth range, texel size (world units).
    pub real_extent: [f32; 4],
    /// Virtual atlas projection.
    pub virtual_map: [[f32; 4]; 4],
    /// Virtual atlas tile.
    pub virtual_tile: [f32; 4],
    /// Virtual tile extents.
    pub virtual_extent: [f32; 4],
}

/// Most point lights a frame draws (a scene's `[[luminaire]]` entries are bounded by
/// `ibl_scene::description::MAX_LUMINAIRES`, the same number).
pub const MAX_POINT_LIGHTS: usize = 64;

/// Cube faces per point light (`point_lights.rs`).
pub const FACES: usize = 6;

/// One point light as the shaders read it (`gpu_scene.wgsl`'s `PointLight`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuPointLight {
    /// xyz: world position; w: the faces' near plane (world units).
    pub position: [f32; 4],
    /// x: the faces' far plane; y: a face tile's side, texels; z: 1 when the light is already
    /// in the background (else a new light); w: 1 when it lights the virtual objects.
    pub shadow: [f32; 4],
    /// Rotation from world to the photometric frame (columns).
    pub light_from_world: [[f32; 4]; 4],
    /// Rows of its map in the strip (v0, dv, texture coordinates), the strip's scale and the
    /// least squared distance counted (m^2, 0 for a point lamp).
    pub map: [f32; 4],
    /// Face tiles in the real atlas (u0, v0, du, dv), zero where the face sees no caster.
    pub real_faces: [[f32; 4]; FACES],
    /// Face tiles in the virtual atlas.
    pub virtual_faces: [[f32; 4]; FACES],
    /// The cone from the light holding the virtual objects' vertices
    /// (`point_lights::shadow_cone`).
    pub shadow_cone: [f32; 4],
}

/// `Object` of `gpu_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuObject {
    /// World from the load frame.
    pub world_from_load: [[f32; 4]; 4],
    /// Its normal matrix.
    pub normal_from_load: [[f32; 4]; 4],
    /// layer (0 real, 1 virtual), selected, 0, 0.
    pub flags: [u32; 4],
}

/// `Material` of `gpu_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    /// Diffuse albedo and kind (0 diffuse, 1 glossy, 2 mirror).
    pub albedo_kind: [f32; 4],
    /// Specular or mirror reflectance and Phong exponent.
    pub specular_exponent: [f32; 4],
}

impl GpuMaterial {
    /// The GPU form of a material.
    pub fn of(material: &Material) -> GpuMaterial {
        match *material {
            Material::Diffuse { albedo } => GpuMaterial {
                albedo_kind: [albedo.r, albedo.g, albedo.b, 0.0],
                specular_exponent: [0.0; 4],
            },
            Material::Glossy {
                albedo,
                specular,
                exponent,
            } => GpuMaterial {
                albedo_kind: [albedo.r, albedo.g, albedo.b, 1.0],
                specular_exponent: [specular.r, specular.g, specular.b, exponent],
            },
            Material::Mirror { reflectance } => GpuMaterial {
                albedo_kind: [0.0, 0.0, 0.0, 2.0],
                specular_exponent: [reflectance.r, reflectance.g, reflectance.b, 0.0],
            },
        }
    }
}

impl GpuObject {
    /// An object drawn through `world_from_load`.
    pub fn new(world_from_load: Affine3A, is_virtual: bool, selected: bool) -> GpuObject {
        let m = Mat4::from(world_from_load);
        let normal = Mat3::from(world_from_load.matrix3).inverse().transpose();
        GpuObject {
            world_from_load: m.to_cols_array_2d(),
            normal_from_load: Mat4::from_mat3(normal).to_cols_array_2d(),
            flags: [u32::from(is_virtual), u32::from(selected), 0, 0],
        }
    }
}

/// A column-major 4 x 4 from a 3 x 3 rotation.
pub fn mat3_columns(m: Mat3) -> [[f32; 4]; 4] {
    Mat4::from_mat3(m).to_cols_array_2d()
}

/// A vector with a fourth component.
pub fn vec4(v: glam::Vec3, w: f32) -> [f32; 4] {
    Vec4::new(v.x, v.y, v.z, w).to_array()
}

/// One mesh's vertex and index buffers ([`crate::scene_geometry::shared_vertices`]).
#[derive(Debug)]
pub struct MeshBuffer {
    /// The distinct vertices.
    pub buffer: wgpu::Buffer,
    /// Three indices per triangle (u32).
    pub index_buffer: wgpu::Buffer,
    /// How many indices.
    pub indices: u32,
    /// Its levels for the shadow passes, finest first (`shadow_lod.rs`); level 0 is the mesh
    /// itself and draws from `index_buffer`. Only the virtual objects have more than one.
    pub shadow_levels: Vec<ShadowLevel>,
}

/// One level of a mesh for the shadow passes on the GPU.
#[derive(Debug)]
pub struct ShadowLevel {
    /// Its indices (`None` for level 0: the mesh's own).
    pub index_buffer: Option<wgpu::Buffer>,
    /// How many indices.
    pub indices: u32,
    /// How far its surface lies from the mesh's, load-frame units (meshoptimizer's estimate).
    pub deviation: f32,
    /// Whether it closes a volume.
    pub closure: crate::scene_geometry::Closure,
}

impl MeshBuffer {
    /// Whether the mesh has no triangles (its buffers then hold a stand-in, never drawn).
    pub fn is_empty(&self) -> bool {
        self.indices == 0
    }

    /// Binds the vertex buffer (slot 0) and the index buffer.
    pub fn bind(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.buffer.slice(..));
        pass.set_index_buffer(self.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
    }

    /// Draws every triangle as `instances` (after [`MeshBuffer::bind`]).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, instances: std::ops::Range<u32>) {
        pass.draw_indexed(0..self.indices, 0, instances);
    }

    /// Draws shadow level `level` as `instances`, binding its indices (after
    /// [`MeshBuffer::bind`], whose vertex buffer every level shares).
    pub fn draw_level(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        level: usize,
        instances: std::ops::Range<u32>,
    ) {
        let level = &self.shadow_levels[level.min(self.shadow_levels.len() - 1)];
        let buffer = level.index_buffer.as_ref().unwrap_or(&self.index_buffer);
        pass.set_index_buffer(buffer.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..level.indices, 0, instances);
    }

    /// The level to draw into a shadow map whose texels are `texel` world units wide at the
    /// mesh, placed with its largest stretch `scale` (`shadow_lod::level_for`).
    pub fn level_for(&self, texel: f32, scale: f32) -> usize {
        crate::shadow_lod::level_for(self.shadow_levels.iter().map(|l| l.deviation), texel, scale)
    }
}

/// Buffers of a scene.
#[derive(Debug)]
pub struct GpuScene {
    /// Real geometry (object 0).
    pub real: MeshBuffer,
    /// Virtual objects (objects 1..).
    pub objects: Vec<MeshBuffer>,
    /// Materials (storage).
    pub materials: wgpu::Buffer,
    /// Object transforms (storage), real first.
    pub transforms: wgpu::Buffer,
    /// Lights (uniform), [`MAX_SHADOWED_LIGHTS`] entries.
    pub lights: wgpu::Buffer,
    /// The goniometric point lights (`point_lights.rs`), a uniform array of
    /// `MAX_POINT_LIGHTS`.
    pub point_lights: wgpu::Buffer,
    /// The frame uniform.
    pub frame: wgpu::Buffer,
    /// Each virtual object's cluster spheres, load frame (`caster_cells::cluster_spheres`).
    pub clusters: Vec<Vec<(glam::Vec3, f32)>>,
    /// The lights' caster cells (storage, `caster_cells.rs`), [`MAX_SHADOWED_LIGHTS`] lights'
    /// worth; zero (a caster anywhere: conservative) until written.
    pub caster_cells: wgpu::Buffer,
}

/// The buffers of a mesh given as three vertices per triangle; with its simplified copies for
/// the shadow passes when `shadow_copies` (the virtual objects).
fn mesh(
    gpu: &GpuContext,
    label: &str,
    vertices: &[crate::scene_geometry::Vertex],
    shadow_copies: bool,
) -> MeshBuffer {
    let (kept, indices) = crate::scene_geometry::shared_vertices(vertices);
    let count = indices.len() as u32;
    let levels = if shadow_copies {
        crate::shadow_lod::shadow_lods(&kept, &indices)
    } else {
        Vec::new()
    };
    // wgpu refuses empty buffers: one degenerate vertex and triangle stand in (never drawn).
    let (kept, indices) = if kept.is_empty() {
        (vec![crate::scene_geometry::Vertex::zeroed()], vec![0; 3])
    } else {
        (kept, indices)
    };
    let init = |contents: &[u8], usage, suffix: &str| {
        gpu.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(&format!("{label} {suffix}")),
                contents,
                usage,
            })
    };
    let mut shadow_levels = vec![ShadowLevel {
        index_buffer: None,
        indices: count,
        deviation: 0.0,
        closure: levels
            .first()
            .map_or(crate::scene_geometry::Closure::Open, |l| l.closure),
    }];
    shadow_levels.extend(levels.iter().skip(1).map(|l| ShadowLevel {
        index_buffer: Some(init(
            bytemuck::cast_slice(&l.indices),
            wgpu::BufferUsages::INDEX,
            "shadow level",
        )),
        indices: l.indices.len() as u32,
        deviation: l.deviation,
        closure: l.closure,
    }));
    MeshBuffer {
        buffer: init(
            bytemuck::cast_slice(&kept),
            wgpu::BufferUsages::VERTEX,
            "vertices",
        ),
        index_buffer: init(
            bytemuck::cast_slice(&indices),
            wgpu::BufferUsages::INDEX,
            "indices",
        ),
        indices: count,
        shadow_levels,
    }
}

/// Most lights a scene frame draws, each with its shadow: the lights are a uniform array of this
/// many (`gpu_scene.wgsl`, 48 KiB, under the 64 KiB every backend allows). On lavapipe a uniform
/// array is read at half the cost of a storage buffer (BENCHMARKS.md, "Viewer").
pub const MAX_SHADOWED_LIGHTS: usize = 256;

/// The lights' uniform buffer, zeroed.
fn lights_buffer(gpu: &GpuContext) -> wgpu::Buffer {
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lights"),
            contents: bytemuck::cast_slice(&[GpuLight::zeroed(); MAX_SHADOWED_LIGHTS]),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        })
}

fn storage(gpu: &GpuContext, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    gpu.device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(label),
            contents: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        })
}

impl GpuScene {
    /// Uploads the geometry and materials; transforms at load, no lights yet.
    pub fn new(gpu: &GpuContext, geometry: &SceneGeometry) -> GpuScene {
        let materials: Vec<GpuMaterial> = geometry.materials.iter().map(GpuMaterial::of).collect();
        let materials = if materials.is_empty() {
            vec![GpuMaterial::zeroed()]
        } else {
            materials
        };
        let mut transforms = vec![GpuObject::new(Affine3A::IDENTITY, false, false)];
        transforms.extend(
            geometry
                .objects
                .iter()
                .map(|_| GpuObject::new(Affine3A::IDENTITY, true, false)),
        );
        GpuScene {
            real: mesh(gpu, "real geometry", &geometry.real.vertices, false),
            objects: geometry
                .objects
                .iter()
                .map(|o| mesh(gpu, &o.name, &o.vertices, true))
                .collect(),
            materials: storage(gpu, "materials", bytemuck::cast_slice(&materials)),
            transforms: storage(gpu, "objects", bytemuck::cast_slice(&transforms)),
            lights: lights_buffer(gpu),
            point_lights: gpu
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("point lights"),
                    contents: bytemuck::cast_slice(&[GpuPointLight::zeroed(); MAX_POINT_LIGHTS]),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                }),
            frame: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame"),
                size: std::mem::size_of::<FrameUniform>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            clusters: geometry
                .objects
                .iter()
                .map(|o| crate::caster_cells::cluster_spheres(&o.vertices))
                .collect(),
            caster_cells: gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("caster cells"),
                size: (MAX_SHADOWED_LIGHTS * crate::caster_cells::CELLS_PER_LIGHT as usize * 4)
                    as u64,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
        }
    }

    /// Writes the caster cells of `lights` (the first [`MAX_SHADOWED_LIGHTS`]) with the virtual
    /// objects at `placements` (world from load, in object order).
    pub fn write_caster_cells(
        &self,
        gpu: &GpuContext,
        lights: &[GpuLight],
        placements: &[Affine3A],
    ) {
        let lights = &lights[..lights.len().min(MAX_SHADOWED_LIGHTS)];
        if lights.is_empty() {
            return;
        }
        let tiles: Vec<crate::light_space::ShadowProjection> = lights
            .iter()
            .map(|l| crate::light_space::ShadowProjection {
                map_from_world: glam::Mat4::from_cols_array_2d(&l.virtual_map),
                half_extent: l.virtual_extent[0],
                depth_range: l.virtual_extent[1],
            })
            .collect();
        let objects: Vec<(Affine3A, &[(glam::Vec3, f32)])> = placements
            .iter()
            .zip(&self.clusters)
            .map(|(&m, c)| (m, &c[..]))
            .collect();
        let cells = crate::caster_cells::caster_cells(&tiles, &objects);
        gpu.queue
            .write_buffer(&self.caster_cells, 0, bytemuck::cast_slice(&cells));
    }

    /// Writes the lights (the first [`MAX_SHADOWED_LIGHTS`]; `lighting.rs` refuses more).
    pub fn write_lights(&self, gpu: &GpuContext, lights: &[GpuLight]) {
        let lights = &lights[..lights.len().min(MAX_SHADOWED_LIGHTS)];
        if !lights.is_empty() {
            gpu.queue
                .write_buffer(&self.lights, 0, bytemuck::cast_slice(lights));
        }
    }

    /// Writes the object transforms (real first).
    pub fn write_transforms(&self, gpu: &GpuContext, objects: &[GpuObject]) {
        gpu.queue
            .write_buffer(&self.transforms, 0, bytemuck::cast_slice(objects));
    }

    /// Writes the materials.
    pub fn write_materials(&self, gpu: &GpuContext, materials: &[Material]) {
        let data: Vec<GpuMaterial> = materials.iter().map(GpuMaterial::of).collect();
        if !data.is_empty() {
            gpu.queue
                .write_buffer(&self.materials, 0, bytemuck::cast_slice(&data));
        }
    }

    /// Writes the point lights (at most `MAX_POINT_LIGHTS`).
    pub fn write_point_lights(&self, gpu: &GpuContext, lights: &[GpuPointLight]) {
        let lights = &lights[..lights.len().min(MAX_POINT_LIGHTS)];
        if !lights.is_empty() {
            gpu.queue
                .write_buffer(&self.point_lights, 0, bytemuck::cast_slice(lights));
        }
    }

    /// Writes the frame uniform.
    pub fn write_frame(&self, gpu: &GpuContext, frame: &FrameUniform) {
        gpu.queue
            .write_buffer(&self.frame, 0, bytemuck::bytes_of(frame));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structs_match_their_wgsl_sizes() {
        // Sums of the WGSL members (all 16-byte columns): no padding on either side.
        assert_eq!(std::mem::size_of::<FrameUniform>(), 3 * 64 + 10 * 16);
        assert_eq!(std::mem::size_of::<GpuLight>(), 2 * 64 + 6 * 16);
        assert_eq!(std::mem::size_of::<GpuObject>(), 2 * 64 + 16);
        assert_eq!(std::mem::size_of::<GpuMaterial>(), 32);
        assert_eq!(std::mem::size_of::<GpuPointLight>(), 64 + 16 * 16);
        assert_eq!(std::mem::size_of::<crate::scene_geometry::Vertex>(), 28);
    }

    #[test]
    fn the_shaders_light_array_has_the_rust_length_and_fits_a_uniform_binding() {
        let declared = format!("const MAX_SHADOWED_LIGHTS: u32 = {MAX_SHADOWED_LIGHTS}u;");
        assert!(include_str!("gpu_scene.wgsl").contains(&declared));
        // 64 KiB: the uniform binding size every wgpu backend allows (WebGPU's default limit).
        assert!(std::mem::size_of::<GpuLight>() * MAX_SHADOWED_LIGHTS <= 1 << 16);
        let points = MAX_POINT_LIGHTS;
        let declared = format!("const MAX_POINT_LIGHTS: u32 = {points}u;");
        assert!(include_str!("gpu_scene.wgsl").contains(&declared));
        assert!(std::mem::size_of::<GpuPointLight>() * points <= 1 << 16);
        assert_eq!(points, ibl_scene::description::MAX_LUMINAIRES);
    }
}
