//! The scene pass (`scene_pass.wgsl`): virtual objects and local geometry lit by the lights with
//! their shadows, composited into the background by differential rendering, 4x multisampled and
//! deferred: a geometry pass writes each sample's surface, then one full-screen pass shades each
//! pixel's surfaces once. See the shader's notes for the composite and `shadow_atlas.rs` for
//! the shadows.
//!
//! The scene's fixed choices (hard or soft shadows, composite rule, background kind, glossy
//! source, ambient, background rays) are pipeline-overridable constants, one shading pipeline
//! per [`ShaderVariant`], built the first time a frame needs it: a shader that branches on a
//! uniform keeps every branch, which on lavapipe made the hard-shadow frame 4 to 5 times slower
//! than the same shader with the soft branch compiled away (BENCHMARKS.md, "Viewer"). The
//! geometry pass is the same for every variant.

use std::collections::HashMap;

use crate::environment_maps::EnvironmentMaps;
use crate::frame_targets::{COVERAGE_FORMAT, FrameTargets, MSAA_SAMPLES};
use crate::gpu::GBUFFER_FORMATS;
use crate::gpu::{DEPTH_FORMAT, GpuContext, HDR_FORMAT};
use crate::gpu_scene::GpuScene;
use crate::light_tiles::LightTiles;
use crate::scene_geometry::{VERTEX_ATTRIBUTES, Vertex};
use crate::shadow_atlas::ShadowAtlases;
use crate::textures::HdrTexture;

/// The per-scene choices compiled into a scene pass pipeline (the shader's `override`s).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShaderVariant {
    /// PCSS soft shadows (else one hard tap).
    pub soft_shadows: bool,
    /// The ratio composite rule (else the difference rule).
    pub ratio_rule: bool,
    /// A background photograph (else the panorama).
    pub photo_background: bool,
    /// Glossy lobes from the prefiltered probe (else from the lights).
    pub glossy_from_probe: bool,
    /// The hybrid ambient map is bound.
    pub has_ambient: bool,
    /// Background rays per pixel axis, 1 to 8.
    pub background_rays: u32,
    /// The real geometry lies in one plane (`FrameUniform::real_plane`).
    pub flat_real_layer: bool,
    /// Real surfaces loop over their screen tile's lights (`light_tiles.rs`; else over every
    /// light, and the culling pass does not run).
    pub tiled_lights: bool,
    /// The scene has goniometric point lights (`point_lights.rs`).
    pub point_lights: bool,
    /// Real surfaces lose the ambient light the objects' occluding sphere hides
    /// (`FrameUniform::occluder`).
    pub occlusion_gather: bool,
}

impl ShaderVariant {
    fn constants(&self) -> [(&'static str, f64); 10] {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        [
            ("SOFT_SHADOWS", flag(self.soft_shadows)),
            ("RATIO_RULE", flag(self.ratio_rule)),
            ("PHOTO_BACKGROUND", flag(self.photo_background)),
            ("GLOSSY_FROM_PROBE", flag(self.glossy_from_probe)),
            ("HAS_AMBIENT", flag(self.has_ambient)),
            (
                "BACKGROUND_RAYS",
                f64::from(self.background_rays.clamp(1, 8)),
            ),
            ("FLAT_REAL_LAYER", flag(self.flat_real_layer)),
            ("TILED_LIGHTS", flag(self.tiled_lights)),
            ("POINT_LIGHTS", flag(self.point_lights)),
            ("OCCLUSION_GATHER", flag(self.occlusion_gather)),
        ]
    }
}

/// The scene's vertices as `vs_geometry` reads them.
fn vertex_buffer_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    }
}

/// Pipelines and samplers of the scene pass.
#[derive(Debug)]
pub struct ScenePass {
    module: wgpu::ShaderModule,
    /// The geometry pass (group 0 only).
    geometry: wgpu::RenderPipeline,
    /// Groups 0 and 1 (the geometry pass's samples).
    shading_layout: wgpu::PipelineLayout,
    /// The shading pipeline of each variant built so far.
    shading: HashMap<ShaderVariant, wgpu::RenderPipeline>,
    layout: wgpu::BindGroupLayout,
    gbuffer_layout: wgpu::BindGroupLayout,
    light_tiles: LightTiles,
    probe_sampler: wgpu::Sampler,
    shadow_sampler: wgpu::Sampler,
}

/// The bind groups a scene pass records with.
#[derive(Debug)]
pub struct SceneBindGroups {
    /// [`ScenePass::bind_group`].
    pub scene: wgpu::BindGroup,
    /// The shading pass's group 1 ([`ScenePass::target_bind_groups`]).
    pub shading_targets: wgpu::BindGroup,
    /// The light culling's group ([`ScenePass::target_bind_groups`]).
    pub light_tiles: wgpu::BindGroup,
}

/// The textures a scene pass reads besides the scene buffers.
pub struct ScenePassInputs<'a> {
    /// The probe's chains.
    pub environment: &'a EnvironmentMaps,
    /// The hybrid ambient's irradiance map (or a black texel).
    pub ambient: &'a HdrTexture,
    /// The background photograph at the output size (or a black texel).
    pub photo: &'a HdrTexture,
    /// The shadow atlases.
    pub shadows: &'a ShadowAtlases,
    /// The point lights' intensity maps (`point_lights::intensity_strip`).
    pub intensity: &'a HdrTexture,
}

impl ScenePass {
    /// Builds the pipelines.
    pub fn new(gpu: &GpuContext) -> ScenePass {
        let device = &gpu.device;
        let source = format!(
            "{}\n{}\n{}\n{}",
            include_str!("gpu_scene.wgsl"),
            include_str!("shadow_lookup.wgsl"),
            include_str!("point_lights.wgsl"),
            include_str!("scene_pass.wgsl")
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scene_pass.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let fragment = wgpu::ShaderStages::FRAGMENT;
        let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: both,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let storage = wgpu::BufferBindingType::Storage { read_only: true };
        let texture = |binding, sample_type| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type,
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let filterable = wgpu::TextureSampleType::Float { filterable: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene pass"),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform),
                buffer(1, wgpu::BufferBindingType::Uniform),
                buffer(2, storage),
                buffer(3, storage),
                texture(4, filterable),
                texture(5, filterable),
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    visibility: fragment,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                texture(7, filterable),
                texture(8, filterable),
                texture(9, wgpu::TextureSampleType::Depth),
                texture(10, wgpu::TextureSampleType::Depth),
                wgpu::BindGroupLayoutEntry {
                    binding: 11,
                    visibility: fragment,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
                buffer(12, wgpu::BufferBindingType::Uniform),
                texture(13, filterable),
            ],
        });
        let samples = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: true,
            },
            count: None,
        };
        let gbuffer_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene gbuffer"),
            entries: &[
                samples(0),
                samples(1),
                samples(2),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: fragment,
                    ty: wgpu::BindingType::Buffer {
                        ty: storage,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let geometry_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene geometry"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let shading_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene shading"),
            bind_group_layouts: &[Some(&layout), Some(&gbuffer_layout)],
            immediate_size: 0,
        });
        let geometry = geometry_pipeline(device, &module, &geometry_layout);
        ScenePass {
            module,
            geometry,
            shading_layout,
            shading: HashMap::new(),
            layout,
            gbuffer_layout,
            light_tiles: LightTiles::new(gpu),
            probe_sampler: device.create_sampler(&crate::textures::probe_sampler_descriptor()),
            shadow_sampler: device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow comparison"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                compare: Some(wgpu::CompareFunction::LessEqual),
                ..Default::default()
            }),
        }
    }

    /// Builds the shading pipeline of `variant` unless it exists (the first frame of a scene,
    /// or after a setting changed; lavapipe compiles the shader then).
    pub fn prepare(&mut self, gpu: &GpuContext, variant: ShaderVariant) {
        if self.shading.contains_key(&variant) {
            return;
        }
        let constants = variant.constants();
        let options = wgpu::PipelineCompilationOptions {
            constants: &constants,
            ..Default::default()
        };
        let targets = [
            Some(wgpu::ColorTargetState::from(HDR_FORMAT)),
            Some(wgpu::ColorTargetState::from(COVERAGE_FORMAT)),
        ];
        let shading = gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("scene shading"),
                layout: Some(&self.shading_layout),
                vertex: wgpu::VertexState {
                    module: &self.module,
                    entry_point: Some("vs_fullscreen"),
                    compilation_options: options.clone(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &self.module,
                    entry_point: Some("fs_shade"),
                    compilation_options: options,
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            });
        self.shading.insert(variant, shading);
    }

    /// The bind groups of a frame size: the shading pass's view of `targets` (the geometry
    /// pass's samples and the light masks) and the light culling's (rebuild when the targets
    /// are).
    pub fn target_bind_groups(
        &self,
        gpu: &GpuContext,
        scene: &GpuScene,
        targets: &FrameTargets,
    ) -> (wgpu::BindGroup, wgpu::BindGroup) {
        let view = wgpu::BindingResource::TextureView;
        let shading = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene gbuffer"),
            layout: &self.gbuffer_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: view(&targets.gbuffer[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: view(&targets.gbuffer[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: view(&targets.gbuffer[2]),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: targets.light_masks.as_entire_binding(),
                },
            ],
        });
        let culling =
            self.light_tiles
                .bind_group(gpu, scene, &targets.gbuffer, &targets.light_masks);
        (shading, culling)
    }

    /// The bind group of a scene and its inputs (rebuild when a buffer or texture is replaced).
    pub fn bind_group(
        &self,
        gpu: &GpuContext,
        scene: &GpuScene,
        inputs: &ScenePassInputs<'_>,
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene pass"),
            layout: &self.layout,
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
                    resource: scene.materials.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: view(&inputs.environment.probe),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: view(&inputs.environment.glossy),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::Sampler(&self.probe_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: view(&inputs.ambient.view),
                },
                wgpu::BindGroupEntry {
                    binding: 8,
                    resource: view(&inputs.photo.view),
                },
                wgpu::BindGroupEntry {
                    binding: 9,
                    resource: view(&inputs.shadows.real.view),
                },
                wgpu::BindGroupEntry {
                    binding: 10,
                    resource: view(&inputs.shadows.virtual_objects.view),
                },
                wgpu::BindGroupEntry {
                    binding: 11,
                    resource: wgpu::BindingResource::Sampler(&self.shadow_sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 12,
                    resource: scene.point_lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 13,
                    resource: view(&inputs.intensity.view),
                },
            ],
        })
    }

    /// Records the geometry pass into `targets`'s samples, the light culling, then the shading
    /// pass into its `radiance` and `coverage`, with the shading pipeline of `variant`
    /// ([`ScenePass::prepare`]d; nothing is drawn otherwise). `timestamps` are written at the
    /// start of the first pass and the end of the last.
    pub fn record(
        &self,
        variant: ShaderVariant,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        scene: &GpuScene,
        bind_groups: &SceneBindGroups,
        timestamps: Option<(
            wgpu::RenderPassTimestampWrites<'_>,
            wgpu::RenderPassTimestampWrites<'_>,
        )>,
    ) {
        let Some(shading) = self.shading.get(&variant) else {
            return;
        };
        let (start, end) = timestamps.unzip();
        let clear = wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            store: wgpu::StoreOp::Store,
        };
        let gbuffer: Vec<Option<wgpu::RenderPassColorAttachment<'_>>> = targets
            .gbuffer
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: clear,
                })
            })
            .collect();
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene geometry"),
                color_attachments: &gbuffer,
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.msaa_depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: start,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &bind_groups.scene, &[]);
            pass.set_pipeline(&self.geometry);
            draw_geometry(&mut pass, scene);
        }
        if variant.tiled_lights {
            self.light_tiles
                .record(encoder, &bind_groups.light_tiles, targets.size);
        }
        let output = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: clear,
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene shading"),
            color_attachments: &[
                output(&targets.radiance_view),
                output(&targets.coverage_view),
            ],
            depth_stencil_attachment: None,
            timestamp_writes: end,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &bind_groups.scene, &[]);
        pass.set_bind_group(1, &bind_groups.shading_targets, &[]);
        pass.set_pipeline(shading);
        pass.draw(0..3, 0..1);
    }
}

/// The geometry pass's pipeline (`fs_gbuffer`; the same for every variant).
fn geometry_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
) -> wgpu::RenderPipeline {
    let targets = GBUFFER_FORMATS.map(|format| Some(wgpu::ColorTargetState::from(format)));
    let vertex_layout = [Some(vertex_buffer_layout())];
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("scene geometry"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_geometry"),
            compilation_options: Default::default(),
            buffers: &vertex_layout,
        },
        primitive: wgpu::PrimitiveState {
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Greater),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: MSAA_SAMPLES,
            ..Default::default()
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_gbuffer"),
            compilation_options: Default::default(),
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Draws the real geometry (instance 0) and each virtual object (instance k + 1).
fn draw_geometry(pass: &mut wgpu::RenderPass<'_>, scene: &GpuScene) {
    if !scene.real.is_empty() {
        scene.real.bind(pass);
        scene.real.draw(pass, 0..1);
    }
    for (k, mesh) in scene.objects.iter().enumerate() {
        if mesh.is_empty() {
            continue;
        }
        let object = k as u32 + 1;
        mesh.bind(pass);
        mesh.draw(pass, object..object + 1);
    }
}
