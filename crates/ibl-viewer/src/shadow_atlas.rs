//! A shadow map for every light, packed into two depth atlases (`shadow_atlas.wgsl` draws them,
//! `shadow_lookup.wgsl` reads them), designed around what moves:
//!
//! - the **real atlas** holds the real (local) geometry as each light sees it. That geometry
//!   never moves, so the atlas is drawn only when the lights change or the virtual objects leave
//!   the region it covers: a sphere of [`REGION_FACTOR`] times the objects' bounding radius about
//!   them (the receivers that need real casters are the objects themselves and the real surfaces
//!   their shadows fall on). Its depth slab spans the whole real geometry along each light.
//! - the **virtual atlas** holds only the virtual objects, each tile fitted tightly around their
//!   bounding sphere (so a 512-texel tile resolves a 0.5 m object to about a millimetre). It is
//!   drawn only when an object moved or the lights changed, in one instanced draw per object for
//!   all lights at once.
//!
//! A receiver's visibility of light `i` is the product of its visibility in both atlases
//! (ibl-render's shadow rays test both layers: blocked by either is blocked). Real surfaces whose
//! projection falls outside every virtual tile skip the virtual look-ups entirely, and lights
//! behind a surface are skipped before any look-up (the shader's loops): with sixteen lights
//! most real pixels cost sixteen dot products and tile tests, not thirty-two texture reads.
//!
//! Soft shadows widen each virtual tile by `1 + 2 tan a` (at most 3x) so a penumbra of cone
//! half-angle `a` fits in it.
//!
//! A closed virtual object (`scene_geometry::Closure`) is drawn into the virtual atlas with its
//! triangles that face away from the light culled: a ray from the light meets a closed surface
//! first where it enters it, through a triangle facing the light, so every texel keeps the
//! depth it had (the same triangles rasterised the same way), for half the triangles
//! ([`away_facing`]; `tests/shadow_culling.rs` compares the atlases texel for texel). An open
//! object, and any object a point light stands inside, draws every triangle.
//!
//! Goniometric point lights take six tiles each after the directional lights' (their cube
//! faces, `point_lights.rs`), drawn with the same rules: the real faces when the lights change,
//! the virtual ones when an object moves, and only the faces that see casters.
//!
//! Depth formats: the real atlas is `Depth32Float` (its slab spans the whole real geometry, and a
//! point light's perspective faces need a float's resolution near their far plane). Without
//! point lights the virtual atlas is `Depth16Unorm`: its orthographic slab spans only the
//! objects' bounding sphere, so 16 bits resolve 2^-16 of the objects' diameter, 64 times finer
//! than the look-up's smallest depth bias at the default 1024-texel tiles (a texel's width over
//! the slab, at least 1.05 / 1024 of it; 16 times at 4096-texel tiles). Half the bytes make the
//! shading pass's PCSS taps cheaper on a CPU rasterizer (lavapipe: 5 % of bunny-sky's frame,
//! BENCHMARKS.md "Round 6"). With point lights it is `Depth32Float`, as their faces share its
//! texture.

use glam::Vec3;
use ibl_render::lighting::DirectionalLight;
use ibl_scene::ShadowKind;

use crate::gpu::{DEPTH_FORMAT, GpuContext};
use crate::gpu_scene::{
    FACES, GpuLight, GpuPointLight, GpuScene, MAX_POINT_LIGHTS, MeshBuffer, vec4,
};
use crate::light_space::{AtlasLayout, ShadowProjection, bounding_sphere, box_corners, box_depths};
use crate::point_lights::{FaceCasters, PointLightInputs, face_coords, gpu_point_lights};
use crate::scene_geometry::{VERTEX_ATTRIBUTES, Vertex};

/// The virtual atlas's depth format in a scene without point lights (module notes).
pub const VIRTUAL_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth16Unorm;

/// The real atlas covers this many times the virtual objects' bounding radius about them.
pub const REGION_FACTOR: f32 = 4.0;

/// One atlas texture.
#[derive(Debug)]
pub struct Atlas {
    /// Its tiles.
    pub layout: AtlasLayout,
    /// The depth texture.
    pub texture: wgpu::Texture,
    /// Its format.
    pub format: wgpu::TextureFormat,
    /// A view of it.
    pub view: wgpu::TextureView,
}

impl Atlas {
    fn new(
        gpu: &GpuContext,
        label: &str,
        layout: AtlasLayout,
        format: wgpu::TextureFormat,
    ) -> Atlas {
        let (w, h) = layout.size();
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            // Copied out only by checks (`SceneRenderer::virtual_atlas_texels`).
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Atlas {
            layout,
            texture,
            format,
            view,
        }
    }

    /// Width and height, texels.
    pub fn size(&self) -> (u32, u32) {
        self.layout.size()
    }
}

/// Tan of a light's cone half-angle (0 for a point-like light), capped at 10 (84 degrees).
pub fn cone_tangent(light: &DirectionalLight) -> f32 {
    light.cone.map_or(0.0, |cone| {
        let c = cone.cos_half_angle().clamp(-1.0, 1.0);
        if c <= 0.1 {
            10.0
        } else {
            ((1.0 - c * c).sqrt() / c).min(10.0)
        }
    })
}

/// What the atlases were last fitted to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// Centre of the real atlas's region.
    pub centre: Vec3,
    /// Its radius.
    pub radius: f32,
}

impl Region {
    /// Whether a sphere (the virtual objects now) is still well inside the region, and not much
    /// smaller or larger than the one it was fitted for.
    pub fn holds(&self, centre: Vec3, radius: f32) -> bool {
        let fitted = self.radius / REGION_FACTOR;
        (centre - self.centre).length() + radius <= 0.5 * self.radius
            && radius <= 1.25 * fitted
            && radius >= 0.5 * fitted
    }
}

/// Both atlases and their pipelines.
#[derive(Debug)]
pub struct ShadowAtlases {
    /// Real geometry.
    pub real: Atlas,
    /// Virtual objects.
    pub virtual_objects: Atlas,
    real_pipeline: wgpu::RenderPipeline,
    /// The virtual objects for the directional lights, by [`Culling`].
    virtual_pipelines: [wgpu::RenderPipeline; 3],
    /// Point lights' cube faces, both atlases (`vs_point_face`), by [`Culling`].
    face_pipelines: [wgpu::RenderPipeline; 3],
    bind_layout: wgpu::BindGroupLayout,
    /// The point lights as last fitted (their faces' tiles say which faces to draw).
    points: Vec<GpuPointLight>,
    /// The region the real atlas covers now (`None`: never drawn).
    pub region: Option<Region>,
}

impl ShadowAtlases {
    /// Atlases of `tiles` tiles (a directional light takes one, a point light [`FACES`]) of
    /// `tile` texels each (shrunk to fit the device), for a scene with or without
    /// `point_lights` (the virtual atlas's format: [`ShadowAtlases::virtual_format`]).
    pub fn new(gpu: &GpuContext, tiles: u32, tile: u32, point_lights: bool) -> ShadowAtlases {
        let layout = AtlasLayout::new(tiles, tile, gpu.max_texture_side());
        let device = &gpu.device;
        let source = format!(
            "{}\n{}",
            include_str!("gpu_scene.wgsl"),
            include_str!("shadow_atlas.wgsl")
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow_atlas.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX,
            ty,
            count: None,
        };
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let bind_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow atlas"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(
                    1,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                entry(2, storage),
                entry(
                    3,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow atlas"),
            bind_group_layouts: &[Some(&bind_layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str, format: wgpu::TextureFormat, culling: Culling| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: std::mem::size_of::<Vertex>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &VERTEX_ATTRIBUTES,
                    })],
                },
                primitive: wgpu::PrimitiveState {
                    // Counter-clockwise in normalised device coordinates is the front.
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: culling.face(),
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::Less),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState::default(),
                fragment: None,
                multiview_mask: None,
                cache: None,
            })
        };
        let virtual_format = ShadowAtlases::virtual_format(point_lights);
        ShadowAtlases {
            real: Atlas::new(gpu, "real shadow atlas", layout, DEPTH_FORMAT),
            virtual_objects: Atlas::new(gpu, "virtual shadow atlas", layout, virtual_format),
            real_pipeline: pipeline("vs_real_tile", DEPTH_FORMAT, Culling::None),
            virtual_pipelines: Culling::ALL
                .map(|culling| pipeline("vs_virtual_atlas", virtual_format, culling)),
            // Drawn into both atlases, which with point lights share the format.
            face_pipelines: Culling::ALL
                .map(|culling| pipeline("vs_point_face", DEPTH_FORMAT, culling)),
            bind_layout,
            points: Vec::new(),
            region: None,
        }
    }

    /// The tile side of both atlases, texels.
    pub fn tile(&self) -> u32 {
        self.real.layout.tile
    }

    /// How many tiles the atlases hold.
    pub fn capacity(&self) -> u32 {
        self.real.layout.tiles
    }

    /// The virtual atlas's depth format for a scene with or without point lights (module notes).
    pub fn virtual_format(point_lights: bool) -> wgpu::TextureFormat {
        if point_lights {
            DEPTH_FORMAT
        } else {
            VIRTUAL_DEPTH_FORMAT
        }
    }

    /// Tiles for `lights` directional and `points` point lights.
    pub fn tiles_for(lights: usize, points: usize) -> u32 {
        (lights + FACES * points.min(MAX_POINT_LIGHTS)).max(1) as u32
    }

    /// The point lights as last fitted.
    pub fn point_lights(&self) -> &[GpuPointLight] {
        &self.points
    }

    /// The GPU lights: each light's tiles fitted to the scene (see the module notes). `objects`
    /// is the bounding sphere of the virtual objects now, `caster_points` their distinct
    /// vertices (the point lights' shadow cones), `real_bounds` the real geometry's box.
    /// The point lights' faces are fitted too (kept for drawing, [`Self::point_lights`]).
    /// Returns the directional lights and whether the real region moved (the real atlas must
    /// be redrawn).
    pub fn fit(
        &mut self,
        lights: &[DirectionalLight],
        points: &PointLightInputs<'_>,
        shadows: ShadowKind,
        objects: (Vec3, f32),
        caster_points: &[Vec3],
        real_bounds: Option<(Vec3, Vec3)>,
    ) -> (Vec<GpuLight>, bool) {
        let casters = FaceCasters {
            objects,
            points: caster_points,
            real: real_bounds.map(|(lo, hi)| bounding_sphere(lo, hi)),
        };
        self.points = gpu_point_lights(points, &self.real.layout, lights.len() as u32, casters);
        let (centre, radius) = objects;
        let region = match self.region {
            Some(r) if r.holds(centre, radius) => r,
            _ => Region {
                centre,
                radius: radius * REGION_FACTOR,
            },
        };
        let moved = self.region != Some(region);
        self.region = Some(region);
        let tile = self.tile() as f32;
        let gpu_lights = lights
            .iter()
            .enumerate()
            .map(|(i, light)| {
                let w = light.direction;
                let tan_half = cone_tangent(light);
                let soft = shadows == ShadowKind::Soft && tan_half > 0.0;
                let across = if soft {
                    (1.0 + 2.0 * tan_half).min(3.0)
                } else {
                    1.05
                };
                let virtual_map = ShadowProjection::around_sphere(w, centre, radius, across);
                let (mut toward, mut away) = real_bounds
                    .map(|(lo, hi)| box_depths(w, region.centre, lo, hi))
                    .unwrap_or((0.0, 0.0));
                toward = toward.max(region.radius);
                away = away.max(region.radius);
                let real_map = ShadowProjection::new(w, region.centre, region.radius, toward, away);
                let index = i as u32;
                let irradiance = light.irradiance;
                GpuLight {
                    direction: vec4(w, if soft { tan_half } else { 0.0 }),
                    irradiance: [irradiance.r, irradiance.g, irradiance.b, 0.0],
                    real_map: real_map.map_from_world.to_cols_array_2d(),
                    real_tile: self.real.layout.uv_rect(index).to_array(),
                    real_extent: [
                        real_map.half_extent,
                        real_map.depth_range,
                        2.0 * real_map.half_extent / tile,
                        0.0,
                    ],
                    virtual_map: virtual_map.map_from_world.to_cols_array_2d(),
                    virtual_tile: self.virtual_objects.layout.uv_rect(index).to_array(),
                    virtual_extent: [
                        virtual_map.half_extent,
                        virtual_map.depth_range,
                        2.0 * virtual_map.half_extent / tile,
                        0.0,
                    ],
                }
            })
            .collect();
        (gpu_lights, moved)
    }

    fn bind_group(&self, gpu: &GpuContext, scene: &GpuScene) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow atlas"),
            layout: &self.bind_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: scene.frame.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: scene.lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: scene.transforms.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: scene.point_lights.as_entire_binding(),
                },
            ],
        })
    }

    fn pass<'a>(
        encoder: &'a mut wgpu::CommandEncoder,
        atlas: &'a Atlas,
        label: &str,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'a>>,
    ) -> wgpu::RenderPass<'a> {
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &atlas.view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// Draws the real geometry into the real atlas, one tile per directional light, then the
    /// point lights' faces.
    pub fn draw_real(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        lights: u32,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let bind_group = self.bind_group(gpu, scene);
        let mut pass = Self::pass(encoder, &self.real, "real shadows", timestamps);
        if scene.real.is_empty() {
            return;
        }
        pass.set_pipeline(&self.real_pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        scene.real.bind(&mut pass);
        let tile = self.real.layout.tile as f32;
        for i in 0..lights.min(self.capacity()) {
            let (x, y) = self.real.layout.origin(i);
            pass.set_viewport(x as f32, y as f32, tile, tile, 0.0, 1.0);
            scene.real.draw(&mut pass, i..i + 1);
        }
        self.draw_faces(&mut pass, &self.real, 0, &scene.real, None, |p| {
            p.real_faces
        });
    }

    /// Draws one caster (`object` 0 the real geometry, `k + 1` virtual object k, its `mesh`
    /// bound) into every point-light face of `atlas` that `faces` gives a tile, the viewport set
    /// to the tile. A virtual object (`placed`) is drawn at the level its distance from the
    /// light allows and, when that level is closed, without its triangles facing away from the
    /// light; every triangle of the full mesh where the light stands inside its bounding sphere.
    fn draw_faces(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        atlas: &Atlas,
        object: u32,
        mesh: &MeshBuffer,
        placed: Option<(&CasterPlacement, ShadowDrawing)>,
        faces: impl Fn(&GpuPointLight) -> [[f32; 4]; FACES],
    ) {
        let (w, h) = atlas.size();
        let mut bound = None;
        // The object's corners and bounding sphere now.
        let placed = placed.map(|(p, drawing)| {
            let (lo, hi) = p.bounds;
            (p, drawing, box_corners(lo, hi), bounding_sphere(lo, hi))
        });
        for (k, light) in self.points.iter().enumerate() {
            let position = Vec3::new(light.position[0], light.position[1], light.position[2]);
            // The object drawn whole where the light is inside it.
            let outside =
                placed.filter(|&(_, _, _, (centre, radius))| position.distance(centre) > radius);
            for (f, tile) in faces(light).iter().enumerate() {
                if tile[2] == 0.0 {
                    continue;
                }
                let (level, culling) =
                    outside.map_or((0, Culling::None), |(p, drawing, corners, _)| {
                        // A face's texel at depth z along its axis is 2 z / texels wide, and the
                        // object lies no nearer along it than its box's nearest corner.
                        let depth = corners
                            .iter()
                            .map(|&c| face_coords(c - position, f).z)
                            .fold(f32::INFINITY, f32::min);
                        let texel = 2.0 * depth.max(0.0) / light.shadow[1].max(1.0);
                        drawn_as(mesh, p, drawing, texel, face_handedness(f))
                    });
                if bound != Some(culling) {
                    pass.set_pipeline(&self.face_pipelines[culling.index()]);
                    bound = Some(culling);
                }
                pass.set_viewport(
                    tile[0] * w as f32,
                    tile[1] * h as f32,
                    tile[2] * w as f32,
                    tile[3] * h as f32,
                    0.0,
                    1.0,
                );
                let instance =
                    (object * MAX_POINT_LIGHTS as u32 + k as u32) * FACES as u32 + f as u32;
                mesh.draw_level(pass, level, instance..instance + 1);
            }
        }
    }

    /// Draws the virtual objects into the virtual atlas, all directional lights in one
    /// instanced draw each, then the point lights' faces. `placements` has one entry per
    /// object; `directional_texel` is the directional tiles' finest texel, world units (the
    /// lights' `virtual_extent.z`).
    #[allow(clippy::too_many_arguments)]
    pub fn draw_virtual(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        lights: u32,
        placements: &[CasterPlacement],
        drawing: ShadowDrawing,
        directional_texel: f32,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let bind_group = self.bind_group(gpu, scene);
        let mut pass = Self::pass(
            encoder,
            &self.virtual_objects,
            "virtual shadows",
            timestamps,
        );
        let (w, h) = self.virtual_objects.size();
        let lights = lights.min(self.capacity());
        pass.set_bind_group(0, &bind_group, &[]);
        for ((k, mesh), placement) in scene.objects.iter().enumerate().zip(placements) {
            if mesh.is_empty() {
                continue;
            }
            let object = k as u32 + 1;
            mesh.bind(&mut pass);
            if lights > 0 {
                let (level, culling) = drawn_as(
                    mesh,
                    placement,
                    drawing,
                    directional_texel,
                    DIRECTIONAL_HANDEDNESS,
                );
                pass.set_pipeline(&self.virtual_pipelines[culling.index()]);
                pass.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
                mesh.draw_level(&mut pass, level, object * lights..(object + 1) * lights);
            }
            self.draw_faces(
                &mut pass,
                &self.virtual_objects,
                object,
                mesh,
                Some((placement, drawing)),
                |p| p.virtual_faces,
            );
        }
    }
}

/// How a virtual object is drawn into a shadow map whose texels are `texel` world units wide at
/// it, through a projection of handedness `handedness`: the level (the coarsest within half a
/// texel, `shadow_lod.rs`) and, when that level is closed, its triangles facing away from the
/// light culled ([`away_facing`]; the level's winding turned over by a mirroring placement).
fn drawn_as(
    mesh: &MeshBuffer,
    placement: &CasterPlacement,
    drawing: ShadowDrawing,
    texel: f32,
    handedness: f32,
) -> (usize, Culling) {
    let level = if drawing.levels {
        mesh.level_for(texel, placement.scale)
    } else {
        0
    };
    let culling = mesh.shadow_levels[level]
        .closure
        .sign()
        .filter(|_| drawing.culling)
        .map_or(Culling::None, |s| {
            Culling::Face(away_facing(s * placement.mirror, handedness))
        });
    (level, culling)
}

/// Which triangles a shadow pass leaves out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Culling {
    /// None: an open caster.
    None,
    /// Those wgpu calls this side (the side facing away from the light).
    Face(wgpu::Face),
}

impl Culling {
    const ALL: [Culling; 3] = [
        Culling::None,
        Culling::Face(wgpu::Face::Front),
        Culling::Face(wgpu::Face::Back),
    ];

    fn face(self) -> Option<wgpu::Face> {
        match self {
            Culling::None => None,
            Culling::Face(face) => Some(face),
        }
    }

    fn index(self) -> usize {
        match self {
            Culling::None => 0,
            Culling::Face(wgpu::Face::Front) => 1,
            Culling::Face(wgpu::Face::Back) => 2,
        }
    }
}

/// A virtual object as the shadow passes see it now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CasterPlacement {
    /// -1 when its placement mirrors it (its determinant is negative: a winding counter-clockwise
    /// from outside at load is clockwise now), else +1.
    pub mirror: f32,
    /// Its placement's largest stretch: a load-frame length times at most this in the world.
    pub scale: f32,
    /// Its world box now, `(min, max)`: how near a light's face it comes; a point light inside
    /// its bounding sphere sees its inside, and draws every triangle of the full mesh.
    pub bounds: (Vec3, Vec3),
}

/// What the virtual shadow passes may leave out (both by default; off to check them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowDrawing {
    /// A closed level's triangles facing away from the light ([`away_facing`]).
    pub culling: bool,
    /// The full mesh where a coarser copy is within half a texel (`shadow_lod.rs`).
    pub levels: bool,
}

/// The sign of the determinant of every directional light's map from world to (x, y, depth)
/// (`ShadowProjection`): its rows are the light frame's u and v and minus its w (towards the
/// light; depth grows away from it), all scaled by positive factors, and u x v = w.
pub const DIRECTIONAL_HANDEDNESS: f32 = -1.0;

/// The sign of the determinant of point-light cube face `face`'s map from world offsets to (x,
/// y, z) (`face_coords`: an even permutation of the axes, times the face's sign on its axis, +1
/// on the even faces and -1 on the odd ones); the perspective division by z > 0 keeps it.
pub fn face_handedness(face: usize) -> f32 {
    if face.is_multiple_of(2) { 1.0 } else { -1.0 }
}

/// The side of a caster's triangles to cull so that those facing the light are drawn, for a
/// caster of `orientation` (+1: counter-clockwise seen from outside) and a projection whose
/// map from world to (x, y, depth), depth growing away from the light, has a determinant of
/// sign `handedness`. A triangle facing the light has its outward normal towards decreasing
/// depth; through a map of positive determinant its corners, seen with x right and y up, run
/// clockwise when it winds counter-clockwise from outside, and counter-clockwise through a
/// negative one. wgpu (`FrontFace::Ccw`) calls counter-clockwise in normalised device
/// coordinates the front, so the light-facing triangles are the front, and the back is culled,
/// when `orientation x handedness < 0`; otherwise they are the back and the front is culled.
pub fn away_facing(orientation: f32, handedness: f32) -> wgpu::Face {
    if orientation * handedness < 0.0 {
        wgpu::Face::Back
    } else {
        wgpu::Face::Front
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_handedness_of_each_projection_is_its_determinants_sign() {
        // Directional: the light frame about many directions, any centre and extents.
        for k in 0..64 {
            let t = k as f32 * 0.7;
            let w = Vec3::new(t.cos() * (0.3 * t).sin(), (0.3 * t).cos(), t.sin()).normalize();
            let p = ShadowProjection::new(w, Vec3::new(1.0, -2.0, 3.0), 0.5 + t, 2.0, 0.1 * t);
            let det = glam::Mat3::from_mat4(p.map_from_world).determinant();
            assert_eq!(det.signum(), DIRECTIONAL_HANDEDNESS, "light towards {w}");
        }
        // Cube faces: face_coords of the three axes.
        for face in 0..FACES {
            let m = glam::Mat3::from_cols(
                crate::point_lights::face_coords(Vec3::X, face),
                crate::point_lights::face_coords(Vec3::Y, face),
                crate::point_lights::face_coords(Vec3::Z, face),
            );
            assert_eq!(m.determinant(), face_handedness(face), "face {face}");
        }
        // A counter-clockwise (from outside) caster keeps its front through a map that turns
        // it over, its back through one that does not; a clockwise one the other way.
        assert_eq!(away_facing(1.0, -1.0), wgpu::Face::Back);
        assert_eq!(away_facing(1.0, 1.0), wgpu::Face::Front);
        assert_eq!(away_facing(-1.0, -1.0), wgpu::Face::Front);
    }

    #[test]
    fn the_region_holds_small_moves_only() {
        let r = Region {
            centre: Vec3::ZERO,
            radius: 4.0,
        };
        assert!(r.holds(Vec3::new(0.5, 0.0, 0.0), 1.0));
        assert!(!r.holds(Vec3::new(1.5, 0.0, 0.0), 1.0));
        assert!(
            !r.holds(Vec3::ZERO, 2.0),
            "scaled up: the tiles would be too coarse"
        );
        assert!(
            !r.holds(Vec3::ZERO, 0.3),
            "scaled down: refit for resolution"
        );
    }

    #[test]
    fn cone_tangents_follow_the_solid_angle() {
        let light = |solid_angle: f32| DirectionalLight {
            direction: Vec3::Y,
            irradiance: ibl_core::Rgb::ONE,
            cone: ibl_render::sampling::UniformCone::from_solid_angle(solid_angle),
            halo: None,
            frame: ibl_render::sampling::OrthonormalBasis::from_normal(Vec3::Y),
            fold: None,
        };
        assert_eq!(cone_tangent(&light(0.0)), 0.0);
        // A cone of half-angle a has solid angle 2 pi (1 - cos a); a = 30 degrees.
        let a = 30f32.to_radians();
        let t = cone_tangent(&light(std::f32::consts::TAU * (1.0 - a.cos())));
        assert!((t - a.tan()).abs() < 1e-4, "{t}");
        assert_eq!(cone_tangent(&light(12.0)), 10.0);
    }
}
