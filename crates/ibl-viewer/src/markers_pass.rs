//! Light markers drawn over the tone-mapped picture (`markers_pass.wgsl`), so they keep their
//! colour whatever the exposure. Marker positions are computed on the CPU with the same camera
//! the frame used ([`crate::view_camera::OutputCamera::project`]) or the lat-long layout.

use bytemuck::{Pod, Zeroable};

use crate::frame_targets::FrameTargets;
use crate::gpu::GpuContext;
use crate::overlay_pipeline::OverlayPipeline;

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
    overlay: OverlayPipeline,
}

impl MarkersPass {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> MarkersPass {
        MarkersPass {
            overlay: OverlayPipeline::new(
                gpu,
                "markers",
                "markers_pass.wgsl",
                include_str!("markers_pass.wgsl"),
                "vs_marker",
                "fs_marker",
            ),
        }
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
        self.overlay.record(
            gpu,
            encoder,
            targets,
            [w as f32, h as f32, 0.5 * line_width.max(1.0), 0.0],
            &data,
            timestamps,
        );
    }
}
