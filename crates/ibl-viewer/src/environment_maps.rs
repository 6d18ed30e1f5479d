//! The probe on the GPU: a lat-long radiance texture with a box-filtered mip chain (the probe
//! viewer's minification, mirror reflections, the background) and a second chain prefiltered
//! with normalised Phong lobes (glossy reflections), both built on the GPU by
//! `environment_maps.wgsl`.
//!
//! Level `k >= 1` of the glossy chain is prefiltered with exponent
//! `e_k = e_1 / 4^(k - 1)`, `e_1 = 2 ln 2 / (1.5 delta_1)^2`, where `delta_1 = 4 pi / W` is the
//! angular size of a level-1 texel: a lobe's half-maximum angle `acos(2^(-1 / e))`, about
//! `sqrt(2 ln 2 / e)`, is then 1.5 texels of its own level, so each level is as sharp as its
//! resolution allows. A material of exponent `e` reads the chain at the fractional level
//! `1 + log4(e_1 / e)` (trilinear between the two nearest lobes); level 0, the probe itself,
//! stands for `4 e_1` and sharper. This is the one place to swap in `ibl-mapping`'s CPU GGX prefilter when it lands:
//! [`EnvironmentMaps::glossy_level`] is all the shader needs to know about the chain.

use bytemuck::{Pod, Zeroable};
use ibl_core::{Image, Rgb};

use crate::gpu::{GpuContext, HDR_FORMAT};
use crate::textures::upload_hdr;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PrefilterUniform {
    exponent: f32,
    texel_solid_angle: f32,
    levels: f32,
    pad: f32,
}

/// The probe's textures.
#[derive(Debug)]
pub struct EnvironmentMaps {
    /// Radiance with a box-filtered mip chain.
    pub probe: wgpu::TextureView,
    /// Phong-prefiltered chain (level 0 is the probe itself).
    pub glossy: wgpu::TextureView,
    /// Radiance = texel x `scale`.
    pub scale: f32,
    /// Mip levels of both chains.
    pub levels: u32,
    /// Exponent of level 1 of the glossy chain.
    pub first_exponent: f32,
    /// Probe size, texels.
    pub size: (u32, u32),
}

/// Mip levels of a `width x height` lat-long chain: halvings until the smaller side is 4.
pub fn mip_levels(width: u32, height: u32) -> u32 {
    let smaller = width.min(height).max(1);
    (smaller.ilog2().saturating_sub(1)).max(1)
}

/// Exponent of level 1 of the glossy chain of a probe `width` texels wide.
pub fn first_exponent(width: u32) -> f32 {
    let delta = 4.0 * std::f32::consts::PI / width.max(2) as f32;
    2.0 * std::f32::consts::LN_2 / (1.5 * delta).powi(2)
}

impl EnvironmentMaps {
    /// The fractional glossy level for Phong exponent `e` (0 for exponents above `e_1`).
    pub fn glossy_level(&self, exponent: f32) -> f32 {
        glossy_level(self.first_exponent, self.levels, exponent)
    }

    /// Uploads a lat-long probe and builds both chains.
    pub fn new(gpu: &GpuContext, probe: &Image<Rgb>) -> EnvironmentMaps {
        let device = &gpu.device;
        let (w, h) = (probe.width().max(1) as u32, probe.height().max(1) as u32);
        let levels = mip_levels(w, h);
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let source = upload_hdr(device, &gpu.queue, probe, "probe", levels, attach);
        let glossy = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("glossy probe"),
            size: source.texture.size(),
            mip_level_count: levels,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HDR_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("environment_maps.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("environment_maps.wgsl").into()),
        });
        let sampler = device.create_sampler(&crate::textures::probe_sampler_descriptor());
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("prefilter"),
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
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("prefilter"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(entry),
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
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &[Some(HDR_FORMAT.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let downsample = pipeline("fs_downsample");
        let prefilter = pipeline("fs_prefilter");
        let level_view = |texture: &wgpu::Texture, level: u32| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                base_mip_level: level,
                mip_level_count: Some(1),
                ..Default::default()
            })
        };
        let e1 = first_exponent(w);
        let texel_solid_angle = 4.0 * std::f32::consts::PI / (w as f32 * h as f32);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("environment maps"),
        });
        let full_source = source
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        let draw = |encoder: &mut wgpu::CommandEncoder,
                    pipeline: &wgpu::RenderPipeline,
                    target: &wgpu::TextureView,
                    input: &wgpu::TextureView,
                    uniform: PrefilterUniform| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("prefilter"),
                size: std::mem::size_of::<PrefilterUniform>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            gpu.queue
                .write_buffer(&buffer, 0, bytemuck::bytes_of(&uniform));
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("prefilter"),
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buffer.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(input),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::Sampler(&sampler),
                    },
                ],
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("environment level"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
        };
        let no_uniform = PrefilterUniform {
            exponent: 1.0,
            texel_solid_angle,
            levels: levels as f32,
            pad: 0.0,
        };
        for level in 1..levels {
            let target = level_view(&source.texture, level);
            let input = level_view(&source.texture, level - 1);
            draw(&mut encoder, &downsample, &target, &input, no_uniform);
        }
        encoder.copy_texture_to_texture(
            source.texture.as_image_copy(),
            glossy.as_image_copy(),
            source.texture.size(),
        );
        for level in 1..levels {
            let target = level_view(&glossy, level);
            let uniform = PrefilterUniform {
                exponent: e1 / 4f32.powi(level as i32 - 1),
                ..no_uniform
            };
            draw(&mut encoder, &prefilter, &target, &full_source, uniform);
        }
        gpu.queue.submit([encoder.finish()]);
        EnvironmentMaps {
            probe: full_source,
            glossy: glossy.create_view(&wgpu::TextureViewDescriptor::default()),
            scale: source.scale,
            levels,
            first_exponent: e1,
            size: (w, h),
        }
    }
}

/// See [`EnvironmentMaps::glossy_level`].
pub fn glossy_level(first_exponent: f32, levels: u32, exponent: f32) -> f32 {
    // Not positive, or NaN: the roughest level.
    if exponent.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return levels.saturating_sub(1) as f32;
    }
    (1.0 + 0.5 * (first_exponent / exponent).log2()).clamp(0.0, levels.saturating_sub(1) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chain_stops_at_4_texels() {
        assert_eq!(mip_levels(512, 256), 7);
        assert_eq!(mip_levels(4, 2), 1);
        assert_eq!(mip_levels(8, 4), 1);
        assert_eq!(mip_levels(16, 8), 2);
    }

    #[test]
    fn each_level_halves_the_lobe_width() {
        let e1 = first_exponent(512);
        // delta_1 = 4 pi / 512; the half-maximum angle of e_1 is 1.5 texels of level 1.
        let half_max = (0.5f32.powf(1.0 / e1)).acos();
        let texel = 4.0 * std::f32::consts::PI / 512.0;
        assert!(
            (half_max / texel - 1.5).abs() < 0.01,
            "{}",
            half_max / texel
        );
        // Level 0 (the probe itself) stands for exponent 4 e_1 and sharper.
        assert_eq!(glossy_level(e1, 7, e1 * 4.0), 0.0);
        assert_eq!(glossy_level(e1, 7, e1 * 100.0), 0.0);
        assert!((glossy_level(e1, 7, e1 * 2.0) - 0.5).abs() < 1e-6);
        assert!((glossy_level(e1, 7, e1) - 1.0).abs() < 1e-6);
        assert!((glossy_level(e1, 7, e1 / 16.0) - 3.0).abs() < 1e-5);
        assert_eq!(glossy_level(e1, 7, 1e-6), 6.0);
    }
}
