//! Light markers drawn over the tone-mapped picture (`markers_pass.wgsl`), so they keep their
//! colour whatever the exposure. Marker positions are computed on the CPU with the same camera
//! the frame used ([`crate::view_camera::OutputCamera::project`]) or the lat-long layout.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::frame_targets::FrameTargets;
use crate::gpu::{DISPLAY_FORMAT, GpuContext};

/// The look of a marker.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MarkerStyle {
    /// A ring (an extracted light).
    Ring,
    /// A ring with a cross (the dominant light).
    Crosshair,
}

/// One marker, in output pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// Centre, pixels.
    pub centre: [f32; 2],
    /// Ring radius, pixels.
    pub radius: f32,
    /// Ring or cross-hair.
    pub style: MarkerStyle,
    /// Display colour (sRGB-encoded, straight alpha).
    pub colour: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuMarker {
    shape: [f32; 4],
    colour: [f32; 4],
}

/// The pipeline.
#[derive(Debug)]
pub struct MarkersPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl MarkersPass {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> MarkersPass {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("markers_pass.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("markers_pass.wgsl").into()),
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
            label: Some("markers"),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform),
                buffer(1, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("markers"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("markers"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_marker"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_marker"),
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
        MarkersPass { pipeline, layout }
    }

    /// Draws `markers` over `targets.display` with lines `line_width` pixels wide.
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        markers: &[Marker],
        line_width: f32,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        if markers.is_empty() {
            return;
        }
        let data: Vec<GpuMarker> = markers
            .iter()
            .map(|m| {
                let a = m.colour[3];
                GpuMarker {
                    shape: [
                        m.centre[0],
                        m.centre[1],
                        m.radius,
                        match m.style {
                            MarkerStyle::Ring => 0.0,
                            MarkerStyle::Crosshair => 1.0,
                        },
                    ],
                    colour: [m.colour[0] * a, m.colour[1] * a, m.colour[2] * a, a],
                }
            })
            .collect();
        let (w, h) = targets.size;
        let screen = [w as f32, h as f32, 0.5 * line_width.max(1.0), 0.0];
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
        let markers_buffer = init(
            "markers",
            bytemuck::cast_slice(&data),
            wgpu::BufferUsages::STORAGE,
        );
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("markers"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: screen.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: markers_buffer.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("markers"),
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
        pass.draw(0..6, 0..data.len() as u32);
    }
}
