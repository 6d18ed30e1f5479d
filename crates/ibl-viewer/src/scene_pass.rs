//! The scene pass (`scene_pass.wgsl`): virtual objects and local geometry lit by the lights with
//! their shadows, composited into the background by differential rendering, 4x multisampled.
//! See the shader's notes for the composite and `shadow_atlas.rs` for the shadows.

use crate::environment_maps::EnvironmentMaps;
use crate::frame_targets::{COVERAGE_FORMAT, FrameTargets, MSAA_SAMPLES};
use crate::gpu::{DEPTH_FORMAT, GpuContext, HDR_FORMAT};
use crate::gpu_scene::GpuScene;
use crate::scene_geometry::{VERTEX_ATTRIBUTES, Vertex};
use crate::shadow_atlas::ShadowAtlases;
use crate::textures::HdrTexture;

/// Pipelines and samplers of the scene pass.
#[derive(Debug)]
pub struct ScenePass {
    geometry: wgpu::RenderPipeline,
    sky: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    probe_sampler: wgpu::Sampler,
    shadow_sampler: wgpu::Sampler,
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
}

impl ScenePass {
    /// Builds the pipelines.
    pub fn new(gpu: &GpuContext) -> ScenePass {
        let device = &gpu.device;
        let source = format!(
            "{}\n{}\n{}",
            include_str!("gpu_scene.wgsl"),
            include_str!("shadow_lookup.wgsl"),
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
                buffer(1, storage),
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
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("scene pass"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let targets = [
            Some(wgpu::ColorTargetState::from(HDR_FORMAT)),
            Some(wgpu::ColorTargetState::from(COVERAGE_FORMAT)),
        ];
        let multisample = wgpu::MultisampleState {
            count: MSAA_SAMPLES,
            ..Default::default()
        };
        let vertex_layout = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX_ATTRIBUTES,
        })];
        let geometry = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene geometry"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
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
            multisample,
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_geometry"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        let sky = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene sky"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_sky"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample,
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_sky"),
                compilation_options: Default::default(),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        ScenePass {
            geometry,
            sky,
            layout,
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
            ],
        })
    }

    /// Records the pass into `targets` (MSAA targets resolved into `radiance` and `coverage`).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        scene: &GpuScene,
        bind_group: &wgpu::BindGroup,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let clear = wgpu::Operations {
            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
            // The samples are resolved into the single-sample targets; they need not be kept.
            store: wgpu::StoreOp::Discard,
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[
                Some(wgpu::RenderPassColorAttachment {
                    view: &targets.msaa_radiance,
                    depth_slice: None,
                    resolve_target: Some(&targets.radiance_view),
                    ops: clear,
                }),
                Some(wgpu::RenderPassColorAttachment {
                    view: &targets.msaa_coverage,
                    depth_slice: None,
                    resolve_target: Some(&targets.coverage_view),
                    ops: clear,
                }),
            ],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.msaa_depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_pipeline(&self.geometry);
        if scene.real.vertices > 0 {
            pass.set_vertex_buffer(0, scene.real.buffer.slice(..));
            pass.draw(0..scene.real.vertices, 0..1);
        }
        for (k, mesh) in scene.objects.iter().enumerate() {
            if mesh.vertices == 0 {
                continue;
            }
            let object = k as u32 + 1;
            pass.set_vertex_buffer(0, mesh.buffer.slice(..));
            pass.draw(0..mesh.vertices, object..object + 1);
        }
        pass.set_pipeline(&self.sky);
        pass.draw(0..3, 0..1);
    }
}
