//! Antialiased line segments drawn over the tone-mapped picture (`lines_pass.wgsl`), the room
//! overlays' pass ([`crate::room_overlay`] computes the segments on the CPU with the camera the
//! frame used), beside [`crate::markers_pass`]'s light markers. Over the display target, so the
//! lines keep their colour whatever the exposure: a pixel whose centre lies within
//! `half_width - 0.5` pixels of a segment is exactly the segment's colour. Segments of one
//! polyline meet at cuts across their mean tangent instead of overlapping round ends, so a
//! curve made of many short segments has an even edge.

use bytemuck::{Pod, Zeroable};
use wgpu::util::DeviceExt;

use crate::frame_targets::FrameTargets;
use crate::gpu::{DISPLAY_FORMAT, GpuContext};

/// One segment, in output pixels (continuous coordinates: pixel `(i, j)` covers `[i, i + 1) x
/// [j, j + 1)`, row 0 at the top). A segment of length 0 is a disc of radius `half_width`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineSegment {
    /// One end, pixels.
    pub from: [f32; 2],
    /// The other end, pixels.
    pub to: [f32; 2],
    /// Half the line's width, pixels (the fringe adds half a pixel each side).
    pub half_width: f32,
    /// Display colour (sRGB-encoded, straight alpha).
    pub colour: [f32; 4],
    /// Where `from` joins the previous segment of a polyline: the unit mean of the two
    /// directions (pointing along this one), across which this segment stops; zero: a round end.
    pub cut_from: [f32; 2],
    /// The same where `to` joins the next segment.
    pub cut_to: [f32; 2],
}

impl LineSegment {
    /// A segment with round ends.
    pub fn new(from: [f32; 2], to: [f32; 2], half_width: f32, colour: [f32; 4]) -> LineSegment {
        LineSegment {
            from,
            to,
            half_width,
            colour,
            cut_from: [0.0; 2],
            cut_to: [0.0; 2],
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuSegment {
    ends: [f32; 4],
    style: [f32; 4],
    colour: [f32; 4],
    cuts: [f32; 4],
}

/// The pipeline.
#[derive(Debug)]
pub struct LinesPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

impl LinesPass {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> LinesPass {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("lines_pass.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("lines_pass.wgsl").into()),
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
            label: Some("lines"),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform),
                buffer(1, wgpu::BufferBindingType::Storage { read_only: true }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lines"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("lines"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_line"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_line"),
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
        LinesPass { pipeline, layout }
    }

    /// Draws `segments` over `targets.display`, in order (later ones on top).
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        segments: &[LineSegment],
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        if segments.is_empty() {
            return;
        }
        let data: Vec<GpuSegment> = segments
            .iter()
            .map(|s| {
                let a = s.colour[3];
                GpuSegment {
                    ends: [s.from[0], s.from[1], s.to[0], s.to[1]],
                    style: [s.half_width.max(0.0), 0.0, 0.0, 0.0],
                    colour: [s.colour[0] * a, s.colour[1] * a, s.colour[2] * a, a],
                    cuts: [s.cut_from[0], s.cut_from[1], s.cut_to[0], s.cut_to[1]],
                }
            })
            .collect();
        let (w, h) = targets.size;
        let screen = [w as f32, h as f32, 0.0, 0.0];
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
        let segments_buffer = init(
            "segments",
            bytemuck::cast_slice(&data),
            wgpu::BufferUsages::STORAGE,
        );
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lines"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: screen.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: segments_buffer.as_entire_binding(),
                },
            ],
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("lines"),
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
