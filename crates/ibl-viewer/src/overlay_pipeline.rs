//! The pipeline both overlay passes share ([`crate::markers_pass`], [`crate::lines_pass`]): a
//! WGSL module drawing one quad (6 vertices) per instance over the display target, reading a
//! uniform `vec4` of screen data (binding 0) and a storage array of instances (binding 1),
//! blended with premultiplied alpha onto what the frame already holds. Each pass keeps its own
//! shader and its own instance layout; this module holds the pipeline, the buffers and the
//! render pass they have in common.

use bytemuck::Pod;
use wgpu::util::DeviceExt;

use crate::frame_targets::FrameTargets;
use crate::gpu::{DISPLAY_FORMAT, GpuContext};

/// One overlay's pipeline and bind-group layout.
#[derive(Debug)]
pub struct OverlayPipeline {
    label: &'static str,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl OverlayPipeline {
    /// Builds the pipeline of the WGSL `source` (named `file` in messages) with entry points
    /// `vertex` and `fragment`.
    pub fn new(
        gpu: &GpuContext,
        label: &'static str,
        file: &'static str,
        source: &'static str,
        vertex: &'static str,
        fragment: &'static str,
    ) -> OverlayPipeline {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(file),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform),
                buffer(1, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vertex),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: DISPLAY_FORMAT,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        OverlayPipeline {
            label,
            pipeline,
            layout,
        }
    }

    /// Draws one quad per element of `instances` over `targets.display`, with `screen` as the
    /// uniform; nothing when `instances` is empty.
    pub fn record<T: Pod>(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        screen: [f32; 4],
        instances: &[T],
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        if instances.is_empty() {
            return;
        }
        let init = |label, contents: &[u8], usage| {
            gpu.device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(label),
                    contents,
                    usage,
                })
        };
        let screen = init(
            "screen",
            bytemuck::cast_slice(&screen),
            wgpu::BufferUsages::UNIFORM,
        );
        let instances_buffer = init(
            self.label,
            bytemuck::cast_slice(instances),
            wgpu::BufferUsages::STORAGE,
        );
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(self.label),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: screen.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: instances_buffer.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(self.label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &targets.display_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Load,
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..6, 0..instances.len() as u32);
    }
}
