//! The textures one frame is drawn into, at the output size, and reading them back.
//!
//! - `gbuffer_depth`, `gbuffer_id`, `gbuffer_normals`, `msaa_depth`: the scene's geometry pass,
//!   4 samples per pixel (`scene_pass.wgsl`): what shading needs of the surface each sample
//!   sees. The shading pass averages the samples' composites into `radiance`, which is what
//!   differential rendering wants: the CPU renderer averages its sample composites the same way,
//!   so an edge pixel mixes object and background by the fraction of samples the object covers.
//!   `coverage` holds that fraction.
//! - `light_masks`: the lights each screen tile's real surfaces need (`light_tiles.rs`).
//! - `radiance`: linear radiance (`Rgba16Float`), the frame an EXR is written from.
//! - `overlay`: premultiplied display-space colour drawn over the picture (selection, regions).
//! - `display`: the tone-mapped sRGB picture (`Rgba8Unorm`), what the window shows and a PNG
//!   is written from.

use ibl_core::{Image, Rgb};

use crate::ViewerError;
use crate::gpu::{DEPTH_FORMAT, DISPLAY_FORMAT, GBUFFER_FORMATS, GpuContext, HDR_FORMAT};
use crate::textures::padded_bytes_per_row;

/// Samples per pixel of the scene pass.
pub const MSAA_SAMPLES: u32 = 4;
/// Format of the object-coverage target.
pub const COVERAGE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
/// Format of the overlay target.
pub const OVERLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// Largest output side, pixels.
pub const MAX_OUTPUT_SIDE: u32 = 8192;

/// The textures of one frame size.
#[derive(Debug)]
pub struct FrameTargets {
    /// Width and height, pixels.
    pub size: (u32, u32),
    /// The geometry pass's view depth, surface ids and normals ([`GBUFFER_FORMATS`]).
    pub gbuffer: [wgpu::TextureView; 3],
    /// Multisampled depth (reversed: 1 near, 0 far).
    pub msaa_depth: wgpu::TextureView,
    /// Per 8 x 8 pixel tile, the lights that can change its real surfaces (`light_tiles.rs`).
    pub light_masks: wgpu::Buffer,
    /// Radiance, the mean of the samples' composites.
    pub radiance: wgpu::Texture,
    /// View of `radiance`.
    pub radiance_view: wgpu::TextureView,
    /// Object coverage.
    pub coverage: wgpu::Texture,
    /// View of `coverage`.
    pub coverage_view: wgpu::TextureView,
    /// Overlay colour, premultiplied.
    pub overlay_view: wgpu::TextureView,
    /// Tone-mapped picture.
    pub display: wgpu::Texture,
    /// View of `display`.
    pub display_view: wgpu::TextureView,
}

/// A frame read back to the CPU.
#[derive(Clone, Debug)]
pub struct FrameImages {
    /// Linear radiance.
    pub radiance: Image<Rgb>,
    /// Fraction of each pixel covered by a virtual object.
    pub coverage: Image<f32>,
    /// The tone-mapped picture, sRGB.
    pub display: Image<[u8; 3]>,
}

fn texture(
    gpu: &GpuContext,
    label: &str,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    samples: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size.0,
            height: size.1,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl FrameTargets {
    /// Targets of `width x height` (each side 1 to [`MAX_OUTPUT_SIDE`]).
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Result<FrameTargets, ViewerError> {
        let max = MAX_OUTPUT_SIDE.min(gpu.max_texture_side());
        if !(1..=max).contains(&width) || !(1..=max).contains(&height) {
            return Err(ViewerError::Parameter(format!(
                "the frame size {width} x {height} is not within 1..={max} on both sides"
            )));
        }
        let size = (width, height);
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let sampled = attach | wgpu::TextureUsages::TEXTURE_BINDING;
        let readable = sampled | wgpu::TextureUsages::COPY_SRC;
        let view = |t: &wgpu::Texture| t.create_view(&wgpu::TextureViewDescriptor::default());
        let labels = ["gbuffer depth", "gbuffer id", "gbuffer normals"];
        let gbuffer = std::array::from_fn(|k| {
            let format = GBUFFER_FORMATS[k];
            view(&texture(
                gpu,
                labels[k],
                size,
                format,
                MSAA_SAMPLES,
                sampled,
            ))
        });
        let msaa_depth = texture(gpu, "msaa depth", size, DEPTH_FORMAT, MSAA_SAMPLES, attach);
        let light_masks = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light masks"),
            size: crate::light_tiles::mask_bytes(size),
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let radiance = texture(gpu, "radiance", size, HDR_FORMAT, 1, readable);
        let coverage = texture(gpu, "coverage", size, COVERAGE_FORMAT, 1, readable);
        let overlay = texture(gpu, "overlay", size, OVERLAY_FORMAT, 1, sampled);
        let display = texture(gpu, "display", size, DISPLAY_FORMAT, 1, readable);
        Ok(FrameTargets {
            size,
            gbuffer,
            msaa_depth: view(&msaa_depth),
            light_masks,
            radiance_view: view(&radiance),
            radiance,
            coverage_view: view(&coverage),
            coverage,
            overlay_view: view(&overlay),
            display_view: view(&display),
            display,
        })
    }

    /// Copies the radiance, the coverage and the picture to the CPU (waits for the GPU).
    pub fn read_back(&self, gpu: &GpuContext) -> Result<FrameImages, ViewerError> {
        let (w, h) = self.size;
        let radiance = read_texture(gpu, &self.radiance, 8)?;
        let coverage = read_texture(gpu, &self.coverage, 1)?;
        let display = read_texture(gpu, &self.display, 4)?;
        let (w, h) = (w as usize, h as usize);
        let radiance: Vec<Rgb> = radiance
            .chunks_exact(8)
            .map(|t| {
                let c = |k: usize| half::f16::from_le_bytes([t[k], t[k + 1]]).to_f32();
                Rgb::new(c(0), c(2), c(4))
            })
            .collect();
        let coverage: Vec<f32> = coverage.iter().map(|&c| f32::from(c) / 255.0).collect();
        let display: Vec<[u8; 3]> = display
            .chunks_exact(4)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let image_error = |e: ibl_core::image::ImageError| ViewerError::Gpu(e.to_string());
        Ok(FrameImages {
            radiance: Image::from_vec(w, h, radiance).map_err(image_error)?,
            coverage: Image::from_vec(w, h, coverage).map_err(image_error)?,
            display: Image::from_vec(w, h, display).map_err(image_error)?,
        })
    }
}

/// The texels of mip level 0 of a 2-D texture with `bytes_per_texel`, rows packed (no padding).
pub fn read_texture(
    gpu: &GpuContext,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
) -> Result<Vec<u8>, ViewerError> {
    let (w, h) = (texture.width(), texture.height());
    let padded = padded_bytes_per_row(w, bytes_per_texel);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read back"),
        size: u64::from(padded) * u64::from(h),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu
        .device
        .create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("read back"),
        });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([encoder.finish()]);
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = sender.send(result);
    });
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| ViewerError::Gpu(format!("waiting for the read-back: {e}")))?;
    receiver
        .recv()
        .map_err(|e| ViewerError::Gpu(format!("read-back: {e}")))?
        .map_err(|e| ViewerError::Gpu(format!("read-back: {e}")))?;
    let row = (w * bytes_per_texel) as usize;
    let mut texels = Vec::with_capacity(row * h as usize);
    {
        let mapped = buffer
            .get_mapped_range(..)
            .map_err(|e| ViewerError::Gpu(format!("read-back: {e}")))?;
        for y in 0..h as usize {
            let start = y * padded as usize;
            texels.extend_from_slice(&mapped[start..start + row]);
        }
    }
    buffer.unmap();
    Ok(texels)
}
