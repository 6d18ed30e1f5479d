//! One frame of the probe viewer, the same code in the window and headless: the probe pass, the
//! display transform, the light markers and the room overlays' lines.

use glam::Mat3;

use crate::ViewerError;
use crate::display_pass::DisplayPass;
use crate::environment_maps::EnvironmentMaps;
use crate::frame_targets::FrameTargets;
use crate::gpu::GpuContext;
use crate::lighting::ProbeOverlay;
use crate::lines_pass::{LineSegment, LinesPass};
use crate::markers_pass::MarkersPass;
use crate::probe_model::{ProbeModel, ProbeViewSettings};
use crate::probe_pass::{ProbeFrame, ProbePass, mask_texture};
use crate::textures::{HdrTexture, black_texture, upload_hdr};
use crate::timing::{PROBE_PASSES, PassTimer, PassTimes};

/// The GPU state of a probe.
pub struct ProbeRenderer {
    environment: EnvironmentMaps,
    probe_pass: ProbePass,
    display: DisplayPass,
    markers: MarkersPass,
    lines: LinesPass,
    irradiance: HdrTexture,
    regions: wgpu::TextureView,
    overlay: Option<ProbeOverlay>,
    targets: FrameTargets,
    timer: Option<PassTimer>,
}

impl ProbeRenderer {
    /// Uploads a probe for frames of `width x height`.
    pub fn new(
        gpu: &GpuContext,
        model: &ProbeModel,
        width: u32,
        height: u32,
    ) -> Result<ProbeRenderer, ViewerError> {
        let renderer = ProbeRenderer {
            environment: EnvironmentMaps::new(gpu, &model.latlong),
            probe_pass: ProbePass::new(gpu),
            display: DisplayPass::new(gpu),
            markers: MarkersPass::new(gpu),
            lines: LinesPass::new(gpu),
            irradiance: black_texture(&gpu.device, &gpu.queue, "no irradiance"),
            regions: mask_texture(gpu, None),
            overlay: None,
            targets: FrameTargets::new(gpu, width, height)?,
            timer: PassTimer::new(gpu, &PROBE_PASSES),
        };
        gpu.take_errors()?;
        Ok(renderer)
    }

    /// The frame's textures.
    pub fn targets(&self) -> &FrameTargets {
        &self.targets
    }

    /// The overlay drawn now.
    pub fn overlay(&self) -> Option<&ProbeOverlay> {
        self.overlay.as_ref()
    }

    /// Changes the output size (no-op when equal).
    pub fn resize(&mut self, gpu: &GpuContext, width: u32, height: u32) -> Result<(), ViewerError> {
        if self.targets.size != (width, height) {
            self.targets = FrameTargets::new(gpu, width, height)?;
        }
        Ok(())
    }

    /// Replaces the probe shown (an edited panorama of the same lat-long layout) and rebuilds
    /// its mip chains.
    pub fn set_probe(&mut self, gpu: &GpuContext, latlong: &ibl_core::Image<ibl_core::Rgb>) {
        self.environment = EnvironmentMaps::new(gpu, latlong);
    }

    /// Replaces the overlay (from the worker).
    pub fn set_overlay(&mut self, gpu: &GpuContext, overlay: ProbeOverlay) {
        self.irradiance = upload_hdr(
            &gpu.device,
            &gpu.queue,
            &overlay.irradiance_over_pi,
            "sh irradiance",
            1,
            wgpu::TextureUsages::empty(),
        );
        self.regions = mask_texture(gpu, overlay.region_borders.as_ref());
        self.overlay = Some(overlay);
    }

    /// Draws a frame and submits it; `scale` sizes the markers (pixels per point).
    pub fn render(&mut self, gpu: &GpuContext, settings: &ProbeViewSettings, scale: f32) -> f64 {
        self.render_with(gpu, settings, scale, &[])
    }

    /// [`ProbeRenderer::render`] with `segments` (output pixels, [`crate::room_overlay`]) drawn
    /// over the markers; returns the CPU seconds.
    pub fn render_with(
        &mut self,
        gpu: &GpuContext,
        settings: &ProbeViewSettings,
        scale: f32,
        segments: &[LineSegment],
    ) -> f64 {
        let started = std::time::Instant::now();
        let (w, h) = self.targets.size;
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("probe frame"),
            });
        let frame = ProbeFrame {
            camera: settings.camera(w, h),
            probe_from_world: Mat3::IDENTITY,
            projection: settings.projection,
            layer: settings.layer,
            sharpen: settings.sharpen,
            environment: &self.environment,
            irradiance: &self.irradiance,
            regions: &self.regions,
            show_regions: settings.overlays.regions && self.overlay.is_some(),
        };
        {
            let t = self.timer.as_mut().and_then(|t| t.writes(0));
            self.probe_pass
                .record(gpu, &mut encoder, &self.targets, &frame, t);
        }
        {
            let t = self.timer.as_mut().and_then(|t| t.writes(1));
            self.display
                .record(gpu, &mut encoder, &self.targets, &settings.display, t);
        }
        let markers = self
            .overlay
            .as_ref()
            .map(|o| settings.markers(o, w, h, scale))
            .unwrap_or_default();
        if !markers.is_empty() {
            let t = self.timer.as_mut().and_then(|t| t.writes(2));
            self.markers
                .record(gpu, &mut encoder, &self.targets, &markers, 2.0 * scale, t);
        }
        if !segments.is_empty() {
            let t = self.timer.as_mut().and_then(|t| t.writes(3));
            self.lines
                .record(gpu, &mut encoder, &self.targets, segments, t);
        }
        if let Some(timer) = self.timer.as_mut() {
            timer.resolve(&mut encoder);
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(timer) = self.timer.as_mut() {
            timer.after_submit();
        }
        started.elapsed().as_secs_f64()
    }

    /// Reads the pass times of the last frame (waiting for them with `wait`).
    pub fn read_pass_times(&mut self, gpu: &GpuContext, wait: bool) -> Option<PassTimes> {
        self.timer.as_mut()?.read(gpu, wait)
    }
}
