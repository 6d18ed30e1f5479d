//! GPU textures as data: a 2D image or a cube map with a mip chain ([`Texture`]), and the
//! texel formats the KTX2 ([`crate::ktx2`]) and DDS ([`crate::dds`]) containers hold
//! ([`TexelFormat`]).
//!
//! Values are linear f32 in memory, `channels` per texel (3: RGB radiance, 2: a two-channel
//! table such as the DFG look-up), rows top to bottom, faces in the order `+X -X +Y -Y +Z -Z`
//! (the GL/KTX/D3D cube orientation, CONVENTIONS section 3). Formats with an alpha channel are
//! written with alpha 1 and read without it.
//!
//! **Encodings.** Half floats round to nearest even and clamp to the largest finite half,
//! 65504 (a sun brighter than that saturates instead of becoming infinite). RGB9E5 follows
//! `EXT_texture_shared_exponent` (OpenGL 4.6 section 8.5.2, the Vulkan `E5B9G9R9` format):
//! `N = 9` mantissa bits, bias `B = 15`, exponent `max(-B - 1, floor(log2(max_c))) + 1 + B`
//! bumped by one when the largest mantissa rounds to 512; values clamp to 65408, and each
//! channel keeps 9 bits relative to the largest (the others lose precision when channels differ
//! by more than 2^9). R11G11B10 (read only) is the packed unsigned float of the same specs.

use half::f16;
use ibl_core::{Image, Rgb};

/// The texel formats iblkit reads and writes in KTX2 and DDS files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum TexelFormat {
    /// RGBA, 16-bit float each (`VK_FORMAT_R16G16B16A16_SFLOAT`, `DXGI_FORMAT_R16G16B16A16_FLOAT`).
    #[default]
    Rgba16Float,
    /// RGBA, 32-bit float each.
    Rgba32Float,
    /// RGB, 32-bit float each (read only: GPUs rarely sample it).
    Rgb32Float,
    /// RGB, 16-bit float each (read only).
    Rgb16Float,
    /// Shared-exponent RGB in 32 bits (`E5B9G9R9_UFLOAT_PACK32`, `R9G9B9E5_SHAREDEXP`).
    Rgb9E5,
    /// Packed unsigned floats R11 G11 B10 (read only).
    Rg11B10Float,
    /// RG, 16-bit float each (two-channel tables).
    Rg16Float,
    /// RG, 32-bit float each.
    Rg32Float,
}

impl TexelFormat {
    /// Bytes per texel.
    pub fn bytes_per_texel(self) -> usize {
        match self {
            TexelFormat::Rgba16Float => 8,
            TexelFormat::Rgba32Float => 16,
            TexelFormat::Rgb32Float => 12,
            TexelFormat::Rgb16Float => 6,
            TexelFormat::Rgb9E5 | TexelFormat::Rg11B10Float | TexelFormat::Rg16Float => 4,
            TexelFormat::Rg32Float => 8,
        }
    }

    /// Channels in memory after decoding: 3 (RGB) or 2 (RG).
    pub fn channels(self) -> usize {
        match self {
            TexelFormat::Rg16Float | TexelFormat::Rg32Float => 2,
            _ => 3,
        }
    }

    /// Short name, e.g. `rgba16f`, `rgb9e5`.
    pub fn name(self) -> &'static str {
        match self {
            TexelFormat::Rgba16Float => "rgba16f",
            TexelFormat::Rgba32Float => "rgba32f",
            TexelFormat::Rgb32Float => "rgb32f",
            TexelFormat::Rgb16Float => "rgb16f",
            TexelFormat::Rgb9E5 => "rgb9e5",
            TexelFormat::Rg11B10Float => "rg11b10f",
            TexelFormat::Rg16Float => "rg16f",
            TexelFormat::Rg32Float => "rg32f",
        }
    }

    /// Looks a writable format up by its [`TexelFormat::name`] (`rgba16f`, `rgba32f`, `rgb9e5`,
    /// `rg16f`, `rg32f`).
    pub fn from_name(name: &str) -> Option<TexelFormat> {
        [
            TexelFormat::Rgba16Float,
            TexelFormat::Rgba32Float,
            TexelFormat::Rgb9E5,
            TexelFormat::Rg16Float,
            TexelFormat::Rg32Float,
        ]
        .into_iter()
        .find(|f| f.name() == name.to_ascii_lowercase())
    }

    /// Whether iblkit writes this format.
    pub fn is_writable(self) -> bool {
        matches!(
            self,
            TexelFormat::Rgba16Float
                | TexelFormat::Rgba32Float
                | TexelFormat::Rgb9E5
                | TexelFormat::Rg16Float
                | TexelFormat::Rg32Float
        )
    }

    /// Decodes one texel into `out` (`channels()` values).
    pub fn decode_texel(self, b: &[u8], out: &mut [f32]) {
        let f32_at =
            |k: usize| f32::from_le_bytes([b[4 * k], b[4 * k + 1], b[4 * k + 2], b[4 * k + 3]]);
        let f16_at = |k: usize| f16::from_le_bytes([b[2 * k], b[2 * k + 1]]).to_f32();
        match self {
            TexelFormat::Rgba16Float | TexelFormat::Rgb16Float | TexelFormat::Rg16Float => {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = f16_at(k);
                }
            }
            TexelFormat::Rgba32Float | TexelFormat::Rgb32Float | TexelFormat::Rg32Float => {
                for (k, o) in out.iter_mut().enumerate() {
                    *o = f32_at(k);
                }
            }
            TexelFormat::Rgb9E5 => {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                out.copy_from_slice(&rgb9e5_decode(v));
            }
            TexelFormat::Rg11B10Float => {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                out[0] = small_float(v & 0x7ff, 6);
                out[1] = small_float((v >> 11) & 0x7ff, 6);
                out[2] = small_float((v >> 22) & 0x3ff, 5);
            }
        }
    }

    /// Appends one texel of `channels()` values (alpha 1 added for RGBA formats).
    pub fn encode_texel(self, v: &[f32], out: &mut Vec<u8>) {
        let half = |x: f32| f16::from_f32(x.min(f16::MAX.to_f32())).to_le_bytes();
        match self {
            TexelFormat::Rgba16Float => {
                for &x in v.iter().chain(&[1.0]) {
                    out.extend_from_slice(&half(x));
                }
            }
            TexelFormat::Rg16Float | TexelFormat::Rgb16Float => {
                for &x in v {
                    out.extend_from_slice(&half(x));
                }
            }
            TexelFormat::Rgba32Float => {
                for &x in v.iter().chain(&[1.0]) {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            TexelFormat::Rg32Float | TexelFormat::Rgb32Float => {
                for &x in v {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            TexelFormat::Rgb9E5 => {
                out.extend_from_slice(&rgb9e5_encode([v[0], v[1], v[2]]).to_le_bytes());
            }
            TexelFormat::Rg11B10Float => {
                // Not written (see `is_writable`); encoded as zero rather than panicking.
                out.extend_from_slice(&[0; 4]);
            }
        }
    }
}

/// An unsigned float with a 5-bit exponent (bias 15) and `mantissa_bits` bits (the R11/G11/B10
/// channels of `B10G11R11_UFLOAT`).
fn small_float(bits: u32, mantissa_bits: u32) -> f32 {
    let e = (bits >> mantissa_bits) as i32;
    let m = (bits & ((1 << mantissa_bits) - 1)) as f32 / (1u32 << mantissa_bits) as f32;
    match e {
        0 => m * 2f32.powi(-14),
        31 => {
            if m == 0.0 {
                f32::INFINITY
            } else {
                f32::NAN
            }
        }
        _ => (1.0 + m) * 2f32.powi(e - 15),
    }
}

/// Largest RGB9E5 value, `511 / 512 * 2^16`.
pub const RGB9E5_MAX: f32 = 65408.0;

/// Packs linear RGB into RGB9E5 (see the module note); negative and NaN values become 0.
pub fn rgb9e5_encode(rgb: [f32; 3]) -> u32 {
    const N: i32 = 9;
    const B: i32 = 15;
    let c = rgb.map(|x| {
        if x > 0.0 {
            f64::from(x.min(RGB9E5_MAX))
        } else {
            0.0
        }
    });
    let max_c = c[0].max(c[1]).max(c[2]);
    let floor_log2 = if max_c > 0.0 {
        max_c.log2().floor() as i32
    } else {
        -B - 1
    };
    let mut exp = floor_log2.max(-B - 1) + 1 + B;
    let scale = |e: i32| 2f64.powi(e - B - N);
    if (max_c / scale(exp) + 0.5).floor() as i32 == 1 << N {
        exp += 1;
    }
    let m = c.map(|x| ((x / scale(exp) + 0.5).floor() as u32).min(511));
    m[0] | (m[1] << 9) | (m[2] << 18) | ((exp as u32) << 27)
}

/// Unpacks RGB9E5: `mantissa * 2^(exponent - 15 - 9)`.
pub fn rgb9e5_decode(v: u32) -> [f32; 3] {
    let scale = 2f32.powi((v >> 27) as i32 - 24);
    [
        (v & 0x1ff) as f32 * scale,
        ((v >> 9) & 0x1ff) as f32 * scale,
        ((v >> 18) & 0x1ff) as f32 * scale,
    ]
}

/// Whether a texture is one 2D image per level or a cube map (six faces per level).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureKind {
    /// One image per level.
    Flat,
    /// Six square faces per level, `+X -X +Y -Y +Z -Z`.
    Cube,
}

impl TextureKind {
    /// Faces per level: 1 or 6.
    pub fn faces(self) -> usize {
        match self {
            TextureKind::Flat => 1,
            TextureKind::Cube => 6,
        }
    }
}

/// One mip level: `faces` images of `width x height x channels` f32, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureLevel {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// One entry per face (1 or 6).
    pub faces: Vec<Vec<f32>>,
}

/// A texture: a 2D image or cube map with its mip levels, level 0 the largest.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Flat or cube.
    pub kind: TextureKind,
    /// Values per texel in memory: 3 (RGB) or 2 (RG).
    pub channels: usize,
    /// The levels, level 0 first; level `m` is `max(1, W >> m) x max(1, H >> m)`.
    pub levels: Vec<TextureLevel>,
}

/// A texture file as read, with its stored format.
#[derive(Clone, Debug, PartialEq)]
pub struct DecodedTexture {
    /// The texture, decoded to f32.
    pub texture: Texture,
    /// The texel format stored in the file.
    pub format: TexelFormat,
    /// Human-readable summary, e.g. `"KTX2, cube, 9 levels, rgba16f"`.
    pub details: String,
}

impl Texture {
    /// Checks the shape: at least one level, every level the halved size of the previous with
    /// the right face count and data length, cube faces square, 2 or 3 channels.
    pub fn validate(&self) -> Result<(), String> {
        let first = self
            .levels
            .first()
            .ok_or("a texture needs at least one level")?;
        if !(2..=3).contains(&self.channels) {
            return Err(format!("{} channels (expected 2 or 3)", self.channels));
        }
        if self.kind == TextureKind::Cube && first.width != first.height {
            return Err(format!(
                "cube faces must be square, got {} x {}",
                first.width, first.height
            ));
        }
        for (m, l) in self.levels.iter().enumerate() {
            let (w, h) = ((first.width >> m).max(1), (first.height >> m).max(1));
            if l.width != w || l.height != h || l.faces.len() != self.kind.faces() {
                return Err(format!(
                    "level {m} is {} x {} with {} faces, expected {w} x {h} with {}",
                    l.width,
                    l.height,
                    l.faces.len(),
                    self.kind.faces()
                ));
            }
            if l.faces.iter().any(|f| f.len() != w * h * self.channels) {
                return Err(format!("level {m} holds the wrong number of values"));
            }
        }
        if first.width == 0 || first.height == 0 {
            return Err("zero texture size".into());
        }
        Ok(())
    }

    /// A cube map with mip levels from six faces per level (GL orientation, level 0 first).
    pub fn from_cube_levels(levels: &[[Image<Rgb>; 6]]) -> Texture {
        Texture {
            kind: TextureKind::Cube,
            channels: 3,
            levels: levels
                .iter()
                .map(|faces| TextureLevel {
                    width: faces[0].width(),
                    height: faces[0].height(),
                    faces: faces.iter().map(rgb_values).collect(),
                })
                .collect(),
        }
    }

    /// A 2D texture with mip levels from one image per level (level 0 first).
    pub fn from_image_levels(levels: &[Image<Rgb>]) -> Texture {
        Texture {
            kind: TextureKind::Flat,
            channels: 3,
            levels: levels
                .iter()
                .map(|img| TextureLevel {
                    width: img.width(),
                    height: img.height(),
                    faces: vec![rgb_values(img)],
                })
                .collect(),
        }
    }

    /// A one-level two-channel 2D texture of `width x height` `[r, g]` texels, row-major.
    pub fn from_rg(width: usize, height: usize, texels: &[[f32; 2]]) -> Texture {
        Texture {
            kind: TextureKind::Flat,
            channels: 2,
            levels: vec![TextureLevel {
                width,
                height,
                faces: vec![texels.iter().flatten().copied().collect()],
            }],
        }
    }

    /// Width and height of level 0.
    pub fn size(&self) -> (usize, usize) {
        self.levels.first().map_or((0, 0), |l| (l.width, l.height))
    }
}

/// The `r, g, b` values of an image, row-major.
fn rgb_values(img: &Image<Rgb>) -> Vec<f32> {
    img.pixels().iter().flat_map(|p| [p.r, p.g, p.b]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb9e5_round_trips_within_its_precision() {
        for rgb in [
            [1.0, 0.5, 0.25],
            [3e4, 2.0, 0.0],
            [1e-3, 2e-3, 5e-4],
            [65408.0, 1.0, 1.0],
        ] {
            let back = rgb9e5_decode(rgb9e5_encode(rgb));
            let max = rgb.iter().cloned().fold(0.0f32, f32::max);
            for c in 0..3 {
                // Half a unit of the 9-bit mantissa of the largest channel: max * 2^-9.
                assert!(
                    (back[c] - rgb[c]).abs() <= max / 512.0 * 1.0001,
                    "{rgb:?} {back:?}"
                );
            }
        }
        // Exact for representable values; clamps above the maximum; zero and negatives are 0.
        assert_eq!(
            rgb9e5_decode(rgb9e5_encode([1.0, 2.0, 0.5])),
            [1.0, 2.0, 0.5]
        );
        assert_eq!(rgb9e5_decode(rgb9e5_encode([1e9, 0.0, 0.0]))[0], RGB9E5_MAX);
        assert_eq!(
            rgb9e5_decode(rgb9e5_encode([-1.0, f32::NAN, 0.0])),
            [0.0; 3]
        );
        // The exponent bump when the mantissa rounds up to 512.
        let v = rgb9e5_encode([511.9, 0.0, 0.0]);
        assert_eq!(rgb9e5_decode(v)[0], 512.0);
    }

    #[test]
    fn half_clamps_instead_of_overflowing() {
        let mut out = Vec::new();
        TexelFormat::Rg16Float.encode_texel(&[1e6, 0.5], &mut out);
        let mut back = [0.0; 2];
        TexelFormat::Rg16Float.decode_texel(&out, &mut back);
        assert_eq!(back, [65504.0, 0.5]);
    }

    #[test]
    fn packed_small_floats_decode() {
        // 1.0 in R11 (e = 15, m = 0), 2.0 in G11, 0.5 in B10.
        let v: u32 = (15 << 6) | ((16 << 6) << 11) | ((14 << 5) << 22);
        let mut out = [0.0; 3];
        TexelFormat::Rg11B10Float.decode_texel(&v.to_le_bytes(), &mut out);
        assert_eq!(out, [1.0, 2.0, 0.5]);
    }
}
