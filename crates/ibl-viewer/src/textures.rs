//! Linear radiance images on the GPU: upload as `Rgba16Float` (filterable everywhere, half the
//! memory of f32) and read back as `Image<Rgb>`.
//!
//! Half floats hold at most 65504; a probe with a brighter texel (a sun core can reach 1e5 and
//! more) is uploaded divided by a power of two `2^k` that brings its maximum under 32768, and the
//! shaders multiply by the returned scale. A power of two keeps every value exact up to half
//! precision (11 significant bits, a relative error of at most 2^-11 per texel).

use ibl_core::{Image, Rgb};

use crate::gpu::HDR_FORMAT;

/// Largest value a half texel is given (half's maximum is 65504).
const HALF_HEADROOM: f32 = 32768.0;

/// A radiance texture and the factor its texels must be multiplied by.
#[derive(Debug)]
pub struct HdrTexture {
    /// The texture (`Rgba16Float`).
    pub texture: wgpu::Texture,
    /// A view of every mip level.
    pub view: wgpu::TextureView,
    /// Radiance = texel value x `scale` (a power of two, 1 for most images).
    pub scale: f32,
}

/// The power of two by which texels are divided so that `max` fits a half float.
pub fn half_scale_for(max: f32) -> f32 {
    if !(max.is_finite() && max > HALF_HEADROOM) {
        return 1.0;
    }
    (max / HALF_HEADROOM).log2().ceil().exp2()
}

/// RGBA half texels of `image / scale` (alpha 1), row 0 first.
pub fn half_texels(image: &Image<Rgb>, scale: f32) -> Vec<half::f16> {
    let inverse = 1.0 / scale;
    let mut texels = Vec::with_capacity(image.len() * 4);
    for p in image.pixels() {
        texels.extend([
            half::f16::from_f32(p.r * inverse),
            half::f16::from_f32(p.g * inverse),
            half::f16::from_f32(p.b * inverse),
            half::f16::ONE,
        ]);
    }
    texels
}

/// Uploads `image` (linear radiance) into mip level 0 of a new `Rgba16Float` texture with
/// `mip_levels` levels (the others left for the caller), usable as a sampled texture plus
/// `extra_usage`.
pub fn upload_hdr(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    image: &Image<Rgb>,
    label: &str,
    mip_levels: u32,
    extra_usage: wgpu::TextureUsages,
) -> HdrTexture {
    let max = image
        .pixels()
        .iter()
        .map(|p| p.max_channel())
        .fold(0.0f32, f32::max);
    let scale = half_scale_for(max);
    let size = wgpu::Extent3d {
        width: image.width().max(1) as u32,
        height: image.height().max(1) as u32,
        depth_or_array_layers: 1,
    };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size,
        mip_level_count: mip_levels.max(1),
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: HDR_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST | extra_usage,
        view_formats: &[],
    });
    if !image.is_empty() {
        let texels = half_texels(image, scale);
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size.width * 8),
                rows_per_image: Some(size.height),
            },
            size,
        );
    }
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    HdrTexture {
        texture,
        view,
        scale,
    }
}

/// A 1 x 1 black radiance texture (bound where a scene has no photograph or no ambient).
pub fn black_texture(device: &wgpu::Device, queue: &wgpu::Queue, label: &str) -> HdrTexture {
    upload_hdr(
        device,
        queue,
        &Image::filled(1, 1, Rgb::ZERO),
        label,
        1,
        wgpu::TextureUsages::empty(),
    )
}

/// Bytes per row of a texture copy into a buffer, padded to wgpu's 256-byte alignment.
pub fn padded_bytes_per_row(width: u32, bytes_per_texel: u32) -> u32 {
    let unpadded = width * bytes_per_texel;
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    unpadded.div_ceil(align) * align
}

/// The probe's sampler: bilinear and trilinear between mips, wrapping in longitude, clamped at
/// the poles.
pub fn probe_sampler_descriptor() -> wgpu::SamplerDescriptor<'static> {
    wgpu::SamplerDescriptor {
        label: Some("probe"),
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        address_mode_w: wgpu::AddressMode::ClampToEdge,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_half_scale_is_a_power_of_two_that_fits() {
        assert_eq!(half_scale_for(1.0), 1.0);
        assert_eq!(half_scale_for(32768.0), 1.0);
        assert_eq!(half_scale_for(f32::NAN), 1.0);
        for max in [40000.0f32, 1.0e5, 3.3e7] {
            let s = half_scale_for(max);
            assert_eq!(s.log2().fract(), 0.0, "{s} is not a power of two");
            assert!(
                max / s <= HALF_HEADROOM && max / s > HALF_HEADROOM / 2.0,
                "{max} / {s}"
            );
        }
    }

    #[test]
    fn half_texels_keep_11_bits() {
        let image =
            Image::from_vec(2, 1, vec![Rgb::new(0.1, 1.0, 3.0e4), Rgb::splat(7.0)]).expect("2 x 1");
        let texels = half_texels(&image, 1.0);
        assert_eq!(texels.len(), 8);
        for (h, v) in texels
            .iter()
            .zip([0.1f32, 1.0, 3.0e4, 1.0, 7.0, 7.0, 7.0, 1.0])
        {
            // Half precision: 11 significant bits, a relative rounding error of at most 2^-11.
            assert!((h.to_f32() - v).abs() <= v * 2f32.powi(-11), "{h} vs {v}");
        }
    }

    #[test]
    fn rows_are_padded_to_256_bytes() {
        assert_eq!(padded_bytes_per_row(64, 4), 256);
        assert_eq!(padded_bytes_per_row(65, 4), 512);
        assert_eq!(padded_bytes_per_row(640, 8), 5120);
    }
}
