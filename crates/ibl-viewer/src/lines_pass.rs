//! Antialiased line segments drawn over the tone-mapped picture (`lines_pass.wgsl`), the room
//! overlays' pass ([`crate::room_overlay`] computes the segments on the CPU with the camera the
//! frame used), beside [`crate::markers_pass`]'s light markers. Over the display target, so the
//! lines keep their colour whatever the exposure: a pixel whose centre lies within
//! `half_width - 0.5` pixels of a segment is exactly the segment's colour. Segments of one
//! polyline meet at cuts across their mean tangent instead of overlapping round ends, so a
//! curve made of many short segments has an even edge.

use bytemuck::{Pod, Zeroable};

use crate::frame_targets::FrameTargets;
use crate::gpu::GpuContext;
use crate::overlay_pipeline::OverlayPipeline;

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
    overlay: OverlayPipeline,
}

impl LinesPass {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> LinesPass {
        LinesPass {
            overlay: OverlayPipeline::new(
                gpu,
                "lines",
                "lines_pass.wgsl",
                include_str!("lines_pass.wgsl"),
                "vs_line",
                "fs_line",
            ),
        }
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
        self.overlay.record(
            gpu,
            encoder,
            targets,
            [w as f32, h as f32, 0.0, 0.0],
            &data,
            timestamps,
        );
    }
}
