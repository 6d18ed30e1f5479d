//! The probe viewer's pass (`probe_pass.wgsl`): the probe from its centre or flat, sharpened,
//! or its SH irradiance, with region borders in the overlay. Writes the frame's single-sample
//! radiance target directly (a full-screen pass needs no multisampling).

use bytemuck::{Pod, Zeroable};
use ibl_core::Image;

use crate::environment_maps::EnvironmentMaps;
use crate::frame_targets::{FrameTargets, OVERLAY_FORMAT};
use crate::gpu::{GpuContext, HDR_FORMAT};
use crate::gpu_scene::mat3_columns;
use crate::textures::HdrTexture;
use crate::view_camera::OutputCamera;

/// How the probe is laid out on the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProbeProjection {
    /// A pinhole view from the probe's centre.
    #[default]
    LookAround,
    /// The whole lat-long image, flat (the probe's own frame).
    LatLong,
}

/// What the probe view shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProbeLayer {
    /// The probe's radiance.
    #[default]
    Radiance,
    /// `E / pi` of the probe's SH irradiance (a white Lambertian surface facing each direction).
    ShIrradiance,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ProbeUniform {
    world_from_camera: [[f32; 4]; 4],
    intrinsics: [f32; 4],
    viewport: [f32; 4],
    probe_from_world: [[f32; 4]; 4],
    params: [f32; 4],
    modes: [u32; 4],
}

/// What one probe frame draws.
pub struct ProbeFrame<'a> {
    /// The camera (look around).
    pub camera: OutputCamera,
    /// World to probe frame (identity for a probe viewed on its own).
    pub probe_from_world: glam::Mat3,
    /// The layout.
    pub projection: ProbeProjection,
    /// The layer.
    pub layer: ProbeLayer,
    /// Laplacian sharpening strength (0: none).
    pub sharpen: f32,
    /// The probe.
    pub environment: &'a EnvironmentMaps,
    /// `E / pi` map (any size) and whether to draw region borders.
    pub irradiance: &'a HdrTexture,
    /// Region border mask (R8), shown when `show_regions`.
    pub regions: &'a wgpu::TextureView,
    /// Whether region borders are drawn.
    pub show_regions: bool,
}

/// The pipeline.
#[derive(Debug)]
pub struct ProbePass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
    sampler: wgpu::Sampler,
}

/// Uploads a 0/1 mask as an `R8Unorm` texture (at least 1 x 1).
pub fn mask_texture(gpu: &GpuContext, mask: Option<&Image<u8>>) -> wgpu::TextureView {
    let empty = Image::filled(1, 1, 0u8);
    let mask = mask.unwrap_or(&empty);
    let size = wgpu::Extent3d {
        width: mask.width() as u32,
        height: mask.height() as u32,
        depth_or_array_layers: 1,
    };
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("region borders"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bytes: Vec<u8> = mask
        .pixels()
        .iter()
        .map(|&m| if m > 0 { 255 } else { 0 })
        .collect();
    gpu.queue.write_texture(
        texture.as_image_copy(),
        &bytes,
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(size.width),
            rows_per_image: Some(size.height),
        },
        size,
    );
    texture.create_view(&wgpu::TextureViewDescriptor::default())
}

impl ProbePass {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> ProbePass {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("probe_pass.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("probe_pass.wgsl").into()),
        });
        let texture = |binding, filterable| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("probe pass"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture(1, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                texture(3, true),
                texture(4, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("probe pass"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("probe pass"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fullscreen"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_probe"),
                compilation_options: Default::default(),
                targets: &[Some(HDR_FORMAT.into()), Some(OVERLAY_FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("probe view"),
            size: std::mem::size_of::<ProbeUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        ProbePass {
            pipeline,
            layout,
            uniform,
            sampler: device.create_sampler(&crate::textures::probe_sampler_descriptor()),
        }
    }

    /// Records the pass into `targets.radiance` and `targets.overlay`.
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        targets: &FrameTargets,
        frame: &ProbeFrame<'_>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) {
        let (w, h) = targets.size;
        let (pw, ph) = frame.environment.size;
        let c = &frame.camera;
        // Minification: probe texels per output pixel, as a mip level.
        let texels_per_pixel = match frame.projection {
            ProbeProjection::LatLong => pw as f32 / w as f32,
            ProbeProjection::LookAround => {
                (1.0 / c.focal_px.y) / (std::f32::consts::TAU / pw as f32)
            }
        };
        let lod = texels_per_pixel
            .max(1.0)
            .log2()
            .min(frame.environment.levels as f32 - 1.0);
        let uniform = ProbeUniform {
            world_from_camera: mat3_columns(c.world_from_camera),
            intrinsics: [
                c.focal_px.x,
                c.focal_px.y,
                c.principal_px.x,
                c.principal_px.y,
            ],
            viewport: [w as f32, h as f32, pw as f32, ph as f32],
            probe_from_world: mat3_columns(frame.probe_from_world),
            params: [
                frame.environment.scale,
                frame.sharpen.max(0.0),
                frame.irradiance.scale,
                lod,
            ],
            modes: [
                match frame.projection {
                    ProbeProjection::LookAround => 0,
                    ProbeProjection::LatLong => 1,
                },
                match frame.layer {
                    ProbeLayer::Radiance => 0,
                    ProbeLayer::ShIrradiance => 1,
                },
                u32::from(frame.show_regions),
                0,
            ],
        };
        gpu.queue
            .write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let view = wgpu::BindingResource::TextureView;
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("probe pass"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: self.uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: view(&frame.environment.probe),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: view(&frame.irradiance.view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: view(frame.regions),
                },
            ],
        });
        let target = |view| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("probe"),
            color_attachments: &[
                target(&targets.radiance_view),
                target(&targets.overlay_view),
            ],
            depth_stencil_attachment: None,
            timestamp_writes: timestamps,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}
