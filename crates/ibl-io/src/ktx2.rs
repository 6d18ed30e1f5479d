//! KTX 2.0 textures (Khronos KTX File Format Specification 2.0): 2D images and cube maps with
//! mip levels, uncompressed float formats and RGB9E5, no supercompression.
//!
//! Layout written: the 12-byte identifier, the header (`vkFormat`, `typeSize`, size, `layerCount
//! 0`, `faceCount` 1 or 6, `levelCount`, supercompression 0), the index, the level index (level
//! 0 first), one basic data format descriptor (Khronos Data Format Specification 1.3: model
//! RGBSDA, BT.709 primaries, linear transfer, one sample per channel; float samples flagged
//! FLOAT | SIGNED with bounds -1.0 / 1.0; RGB9E5 as six samples, a 9-bit mantissa of upper
//! bound 8448 and the shared 5-bit exponent of bias 15 per channel, as in that specification's
//! shared-exponent example), key/value data (`KTXwriter`; `KTXorientation = rd` for 2D), then the
//! levels **smallest first**, each aligned to `lcm(texel size, 4)`, faces `+X -X +Y -Y +Z -Z`
//! within a level, rows top to bottom.
//!
//! Reading accepts what this writer writes plus the other uncompressed float formats
//! ([`TexelFormat`]) and any order of levels in the file; every offset and length is checked
//! against the file and every size against [`Limits`] before anything is allocated. Arrays, 3D
//! textures, block-compressed formats (BC6H included) and supercompression are refused as
//! unsupported, naming what was found. Why our own codec: the `ktx2` crate only parses (it is
//! used by the tests as the independent reader of what we write), and no maintained crate
//! writes KTX2.

use crate::error::DecodeError;
use crate::format::Limits;
use crate::texture::{DecodedTexture, TexelFormat, Texture, TextureKind, TextureLevel};

/// The KTX 2.0 file identifier (defined beside the format detection, which needs it too).
pub use crate::format::KTX2_IDENTIFIER as IDENTIFIER;

/// Header, index and level-index sizes (bytes).
const HEADER_BYTES: usize = 12 + 9 * 4 + 4 * 4 + 2 * 8;

/// The Vulkan format number of a texel format.
pub fn vk_format(format: TexelFormat) -> u32 {
    match format {
        TexelFormat::Rgba16Float => 97,
        TexelFormat::Rgba32Float => 109,
        TexelFormat::Rgb32Float => 106,
        TexelFormat::Rgb16Float => 90,
        TexelFormat::Rgb9E5 => 123,
        TexelFormat::Rg11B10Float => 122,
        TexelFormat::Rg16Float => 83,
        TexelFormat::Rg32Float => 103,
    }
}

fn texel_format(vk: u32) -> Option<TexelFormat> {
    [
        TexelFormat::Rgba16Float,
        TexelFormat::Rgba32Float,
        TexelFormat::Rgb32Float,
        TexelFormat::Rgb16Float,
        TexelFormat::Rgb9E5,
        TexelFormat::Rg11B10Float,
        TexelFormat::Rg16Float,
        TexelFormat::Rg32Float,
    ]
    .into_iter()
    .find(|&f| vk_format(f) == vk)
}

/// `typeSize` of the header: the size of the format's data type (1 for packed formats is not
/// used here: KTX2 gives packed 32-bit formats typeSize 4).
fn type_size(format: TexelFormat) -> u32 {
    match format {
        TexelFormat::Rgba16Float | TexelFormat::Rgb16Float | TexelFormat::Rg16Float => 2,
        _ => 4,
    }
}

/// The basic data format descriptor of `format` (with its leading `dfdTotalSize`).
fn data_format_descriptor(format: TexelFormat) -> Vec<u8> {
    // (bitOffset, bitLength - 1, channelType, lower, upper)
    let mut samples: Vec<(u16, u8, u8, u32, u32)> = Vec::new();
    const FLOAT_SIGNED: u8 = 0x80 | 0x40;
    const EXPONENT: u8 = 0x20;
    let float_channels = |channels: &[u8], bits: u16| -> Vec<(u16, u8, u8, u32, u32)> {
        channels
            .iter()
            .enumerate()
            .map(|(k, &ch)| {
                (
                    k as u16 * bits,
                    (bits - 1) as u8,
                    ch | FLOAT_SIGNED,
                    0xBF80_0000,
                    0x3F80_0000,
                )
            })
            .collect()
    };
    match format {
        TexelFormat::Rgba16Float => samples.extend(float_channels(&[0, 1, 2, 15], 16)),
        TexelFormat::Rgba32Float => samples.extend(float_channels(&[0, 1, 2, 15], 32)),
        TexelFormat::Rgb32Float => samples.extend(float_channels(&[0, 1, 2], 32)),
        TexelFormat::Rgb16Float => samples.extend(float_channels(&[0, 1, 2], 16)),
        TexelFormat::Rg16Float => samples.extend(float_channels(&[0, 1], 16)),
        TexelFormat::Rg32Float => samples.extend(float_channels(&[0, 1], 32)),
        TexelFormat::Rgb9E5 => {
            for ch in 0..3u8 {
                samples.push((u16::from(ch) * 9, 8, ch, 0, 8448));
                samples.push((27, 4, ch | EXPONENT, 15, 31));
            }
        }
        TexelFormat::Rg11B10Float => {
            for (ch, off, bits) in [(0u8, 0u16, 11u8), (1, 11, 11), (2, 22, 10)] {
                samples.push((off, bits - 1, ch | 0x80, 0, 0x3F80_0000));
            }
        }
    }
    let block_size = 24 + 16 * samples.len();
    let mut d = Vec::with_capacity(4 + block_size);
    d.extend_from_slice(&((4 + block_size) as u32).to_le_bytes());
    d.extend_from_slice(&0u32.to_le_bytes()); // vendor 0 (Khronos), descriptor type 0 (basic)
    d.extend_from_slice(&2u16.to_le_bytes()); // version 2 (spec 1.3)
    d.extend_from_slice(&(block_size as u16).to_le_bytes());
    d.extend_from_slice(&[1, 1, 1, 0]); // RGBSDA, BT.709, linear, straight alpha
    d.extend_from_slice(&[0, 0, 0, 0]); // texel block 1 x 1 x 1 x 1
    let mut planes = [0u8; 8];
    planes[0] = format.bytes_per_texel() as u8;
    d.extend_from_slice(&planes);
    for (offset, length, channel, lower, upper) in samples {
        d.extend_from_slice(&offset.to_le_bytes());
        d.extend_from_slice(&[length, channel, 0, 0, 0, 0]);
        d.extend_from_slice(&lower.to_le_bytes());
        d.extend_from_slice(&upper.to_le_bytes());
    }
    d
}

/// Key/value data: sorted keys, each entry `length, key NUL value NUL`, padded to 4 bytes.
fn key_values(kind: TextureKind) -> Vec<u8> {
    let writer = format!("iblkit {}", env!("CARGO_PKG_VERSION"));
    let mut pairs: Vec<(&str, &str)> = vec![("KTXwriter", writer.as_str())];
    if kind == TextureKind::Flat {
        pairs.insert(0, ("KTXorientation", "rd"));
    }
    let mut out = Vec::new();
    for (k, v) in pairs {
        let len = k.len() + 1 + v.len() + 1;
        out.extend_from_slice(&(len as u32).to_le_bytes());
        out.extend_from_slice(k.as_bytes());
        out.push(0);
        out.extend_from_slice(v.as_bytes());
        out.push(0);
        while !out.len().is_multiple_of(4) {
            out.push(0);
        }
    }
    out
}

fn lcm4(n: usize) -> usize {
    let mut m = n.max(1);
    while !m.is_multiple_of(4) {
        m += n.max(1);
    }
    m
}

/// Encodes a texture as KTX2 in `format`. Errors if the texture is malformed, the format is not
/// writable or does not hold the texture's channel count.
pub fn encode(texture: &Texture, format: TexelFormat) -> Result<Vec<u8>, String> {
    texture.validate()?;
    if !format.is_writable() || format.channels() != texture.channels {
        return Err(format!(
            "cannot write {} channels as {}",
            texture.channels,
            format.name()
        ));
    }
    let levels = texture.levels.len();
    let (w, h) = texture.size();
    let dfd = data_format_descriptor(format);
    let kvd = key_values(texture.kind);
    let dfd_offset = HEADER_BYTES + 24 * levels;
    let kvd_offset = dfd_offset + dfd.len();
    let align = lcm4(format.bytes_per_texel());
    let mut data_start = kvd_offset + kvd.len();
    data_start = data_start.div_ceil(align) * align;
    // Level data, smallest level first in the file.
    let mut level_bytes: Vec<Vec<u8>> = texture
        .levels
        .iter()
        .map(|l| {
            let mut b =
                Vec::with_capacity(l.faces.len() * l.width * l.height * format.bytes_per_texel());
            for face in &l.faces {
                for texel in face.chunks_exact(texture.channels) {
                    format.encode_texel(texel, &mut b);
                }
            }
            b
        })
        .collect();
    let mut offsets = vec![0usize; levels];
    let mut pos = data_start;
    for m in (0..levels).rev() {
        pos = pos.div_ceil(align) * align;
        offsets[m] = pos;
        pos += level_bytes[m].len();
    }
    let mut out = Vec::with_capacity(pos);
    out.extend_from_slice(&IDENTIFIER);
    let faces = texture.kind.faces() as u32;
    for v in [
        vk_format(format),
        type_size(format),
        w as u32,
        h as u32,
        0,
        0,
        faces,
        levels as u32,
        0,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for v in [
        dfd_offset as u32,
        dfd.len() as u32,
        kvd_offset as u32,
        kvd.len() as u32,
    ] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&0u64.to_le_bytes()); // no supercompression global data
    out.extend_from_slice(&0u64.to_le_bytes());
    for m in 0..levels {
        let len = level_bytes[m].len() as u64;
        for v in [offsets[m] as u64, len, len] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    for m in (0..levels).rev() {
        out.resize(offsets[m], 0);
        out.append(&mut level_bytes[m]);
    }
    Ok(out)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Decodes a KTX2 file held in memory (every level, every face; values as stored).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<DecodedTexture, DecodeError> {
    if bytes.len() < 12 || bytes[..12] != IDENTIFIER {
        return Err(crate::format::wrong_magic("a KTX2 file", bytes));
    }
    if bytes.len() < HEADER_BYTES {
        return Err(DecodeError::invalid("the KTX2 header is truncated"));
    }
    let field = |k: usize| u32_at(bytes, 12 + 4 * k);
    let (vk, width, height, depth, layers, faces, level_count, scheme) = (
        field(0),
        field(2),
        field(3),
        field(4),
        field(5),
        field(6),
        field(7),
        field(8),
    );
    let format = texel_format(vk).ok_or_else(|| {
        DecodeError::Unsupported(format!(
            "KTX2 vkFormat {vk} (iblkit reads uncompressed float formats and RGB9E5; \
             block-compressed formats such as BC6H (143, 144) are not decoded)"
        ))
    })?;
    if scheme != 0 {
        return Err(DecodeError::Unsupported(format!(
            "KTX2 supercompression scheme {scheme}"
        )));
    }
    if depth > 1 {
        return Err(DecodeError::Unsupported(format!(
            "a 3D KTX2 texture (depth {depth})"
        )));
    }
    if layers > 1 {
        return Err(DecodeError::Unsupported(format!(
            "a KTX2 texture array ({layers} layers)"
        )));
    }
    let kind = match faces {
        1 => TextureKind::Flat,
        6 => TextureKind::Cube,
        _ => {
            return Err(DecodeError::invalid(format!(
                "faceCount {faces} (must be 1 or 6)"
            )));
        }
    };
    if kind == TextureKind::Cube && width != height {
        return Err(DecodeError::invalid(format!(
            "cube faces of {width} x {height} are not square"
        )));
    }
    limits.check(u64::from(width), u64::from(height) * u64::from(faces))?;
    let full_chain = 64 - u64::from(width.max(height)).leading_zeros();
    let levels = level_count.max(1);
    if levels > full_chain {
        return Err(DecodeError::invalid(format!(
            "levelCount {level_count} is more than a {width} x {height} chain holds ({full_chain})"
        )));
    }
    let index_end = HEADER_BYTES + 24 * levels as usize;
    if bytes.len() < index_end {
        return Err(DecodeError::invalid("the KTX2 level index is truncated"));
    }
    let (w, h) = (width as usize, height as usize);
    let bpt = format.bytes_per_texel();
    let channels = format.channels();
    let mut out_levels = Vec::with_capacity(levels as usize);
    for m in 0..levels as usize {
        let at = HEADER_BYTES + 24 * m;
        let (offset, length) = (u64_at(bytes, at), u64_at(bytes, at + 8));
        let (lw, lh) = ((w >> m).max(1), (h >> m).max(1));
        let expected = (lw * lh * faces as usize * bpt) as u64;
        if length != expected {
            return Err(DecodeError::invalid(format!(
                "level {m} holds {length} bytes, a {lw} x {lh} x {faces} {} level needs {expected}",
                format.name()
            )));
        }
        let end = offset
            .checked_add(length)
            .filter(|&e| e <= bytes.len() as u64);
        let Some(end) = end else {
            return Err(DecodeError::Limits(format!(
                "level {m} ({length} bytes at offset {offset}) lies beyond the file's {} bytes \
                 (truncated file?)",
                bytes.len()
            )));
        };
        let data = &bytes[offset as usize..end as usize];
        let face_bytes = lw * lh * bpt;
        let faces_data = data
            .chunks_exact(face_bytes)
            .map(|face| {
                let mut v = vec![0.0f32; lw * lh * channels];
                for (t, o) in face.chunks_exact(bpt).zip(v.chunks_exact_mut(channels)) {
                    format.decode_texel(t, o);
                }
                v
            })
            .collect();
        out_levels.push(TextureLevel {
            width: lw,
            height: lh,
            faces: faces_data,
        });
    }
    let texture = Texture {
        kind,
        channels,
        levels: out_levels,
    };
    let details = format!(
        "KTX2, {}, {} level{}, {}",
        if kind == TextureKind::Cube {
            "cube"
        } else {
            "2D"
        },
        levels,
        if levels == 1 { "" } else { "s" },
        format.name()
    );
    Ok(DecodedTexture {
        texture,
        format,
        details,
    })
}
