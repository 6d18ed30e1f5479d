//! DirectDraw Surface (`.dds`) textures: 2D images and cube maps with mip levels in float
//! formats and RGB9E5 (Microsoft "DDS programming guide": `DDS_HEADER`, `DDS_PIXELFORMAT`,
//! `DDS_HEADER_DXT10`).
//!
//! Written: `"DDS "`, the 124-byte header (`CAPS | HEIGHT | WIDTH | PIXELFORMAT | PITCH |
//! MIPMAPCOUNT`, pitch = width x texel size, caps `TEXTURE | COMPLEX | MIPMAP`, cube caps with
//! all six faces), the pixel format with FourCC `DX10`, then the DX10 header (DXGI format,
//! `TEXTURE2D`, `TEXTURECUBE` for cubes, array size 1) and the data **face-major**: every level
//! of +X, then every level of -X, and so on, rows top to bottom (the D3D layout; a KTX2 file is
//! level-major instead).
//!
//! Read: the same, plus the legacy D3DFMT FourCC codes for float formats (113 `A16B16G16R16F`,
//! 116 `A32B32G32R32F`, 112 `G16R16F`, 115 `G32R32F`) and DXGI R32G32B32_FLOAT, R11G11B10_FLOAT.
//! Sizes are checked against [`Limits`] and the data length against the file before any
//! allocation; volume textures, arrays of more than one texture, partial cube maps and block
//! compression (BC6H included) are refused as unsupported. Why our own codec: the `ddsfile`
//! crate reads headers but leaves the data layout and every size check to the caller, and it is
//! used by the tests as an independent reader of what we write.

use crate::error::DecodeError;
use crate::format::Limits;
use crate::texture::{DecodedTexture, TexelFormat, Texture, TextureKind, TextureLevel};

const MAGIC: &[u8; 4] = b"DDS ";
const HEADER_BYTES: usize = 4 + 124;
const DX10_BYTES: usize = 20;

const DDSD_CAPS: u32 = 0x1;
const DDSD_HEIGHT: u32 = 0x2;
const DDSD_WIDTH: u32 = 0x4;
const DDSD_PITCH: u32 = 0x8;
const DDSD_PIXELFORMAT: u32 = 0x1000;
const DDSD_MIPMAPCOUNT: u32 = 0x2_0000;
const DDSD_DEPTH: u32 = 0x80_0000;
const DDPF_FOURCC: u32 = 0x4;
const DDSCAPS_COMPLEX: u32 = 0x8;
const DDSCAPS_TEXTURE: u32 = 0x1000;
const DDSCAPS_MIPMAP: u32 = 0x40_0000;
const DDSCAPS2_CUBEMAP: u32 = 0x200;
const DDSCAPS2_ALL_FACES: u32 = 0xFC00;
const DDSCAPS2_VOLUME: u32 = 0x20_0000;
const DIMENSION_TEXTURE2D: u32 = 3;
const MISC_TEXTURECUBE: u32 = 0x4;

/// The DXGI format number of a texel format.
pub fn dxgi_format(format: TexelFormat) -> u32 {
    match format {
        TexelFormat::Rgba32Float => 2,
        TexelFormat::Rgb32Float => 6,
        TexelFormat::Rgba16Float => 10,
        TexelFormat::Rg32Float => 16,
        TexelFormat::Rg11B10Float => 26,
        TexelFormat::Rg16Float => 34,
        TexelFormat::Rgb9E5 => 67,
        // No DXGI format: never written (not writable), never matched when reading.
        TexelFormat::Rgb16Float => u32::MAX,
    }
}

fn from_dxgi(code: u32) -> Result<TexelFormat, DecodeError> {
    let f = match code {
        2 => TexelFormat::Rgba32Float,
        6 => TexelFormat::Rgb32Float,
        10 => TexelFormat::Rgba16Float,
        16 => TexelFormat::Rg32Float,
        26 => TexelFormat::Rg11B10Float,
        34 => TexelFormat::Rg16Float,
        67 => TexelFormat::Rgb9E5,
        94..=96 => {
            return Err(DecodeError::Unsupported(format!(
                "DDS DXGI format {code} (BC6H block compression is not decoded)"
            )));
        }
        _ => {
            return Err(DecodeError::Unsupported(format!(
                "DDS DXGI format {code} (iblkit reads float formats and R9G9B9E5)"
            )));
        }
    };
    Ok(f)
}

fn from_legacy_fourcc(code: u32) -> Result<TexelFormat, DecodeError> {
    match code {
        113 => Ok(TexelFormat::Rgba16Float),
        116 => Ok(TexelFormat::Rgba32Float),
        112 => Ok(TexelFormat::Rg16Float),
        115 => Ok(TexelFormat::Rg32Float),
        _ => {
            let text: String = code
                .to_le_bytes()
                .iter()
                .map(|&b| if b.is_ascii_graphic() { b as char } else { '?' })
                .collect();
            Err(DecodeError::Unsupported(format!(
                "DDS pixel format FourCC {code} ({text:?}); iblkit reads DX10 float formats and \
                 the D3DFMT float codes 112, 113, 115, 116"
            )))
        }
    }
}

/// Encodes a texture as DDS (DX10 header) in `format`.
pub fn encode(texture: &Texture, format: TexelFormat) -> Result<Vec<u8>, String> {
    texture.validate()?;
    if !format.is_writable() || format.channels() != texture.channels {
        return Err(format!(
            "cannot write {} channels as {}",
            texture.channels,
            format.name()
        ));
    }
    let (w, h) = texture.size();
    let levels = texture.levels.len() as u32;
    let bpt = format.bytes_per_texel();
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    let flags =
        DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT | DDSD_PITCH | DDSD_MIPMAPCOUNT;
    for v in [124, flags, h as u32, w as u32, (w * bpt) as u32, 0, levels] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&[0u8; 44]); // dwReserved1[11]
    // DDS_PIXELFORMAT: size, flags, FourCC "DX10", bit count and masks unused.
    for v in [32, DDPF_FOURCC, u32::from_le_bytes(*b"DX10"), 0, 0, 0, 0, 0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let cube = texture.kind == TextureKind::Cube;
    let mut caps = DDSCAPS_TEXTURE;
    if levels > 1 || cube {
        caps |= DDSCAPS_COMPLEX;
    }
    if levels > 1 {
        caps |= DDSCAPS_MIPMAP;
    }
    let caps2 = if cube {
        DDSCAPS2_CUBEMAP | DDSCAPS2_ALL_FACES
    } else {
        0
    };
    for v in [caps, caps2, 0, 0, 0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let misc = if cube { MISC_TEXTURECUBE } else { 0 };
    for v in [dxgi_format(format), DIMENSION_TEXTURE2D, misc, 1, 0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for face in 0..texture.kind.faces() {
        for level in &texture.levels {
            for texel in level.faces[face].chunks_exact(texture.channels) {
                format.encode_texel(texel, &mut out);
            }
        }
    }
    Ok(out)
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Decodes a DDS file held in memory (every level, every face).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<DecodedTexture, DecodeError> {
    if bytes.len() < 4 || &bytes[..4] != MAGIC {
        return Err(crate::format::wrong_magic("a DDS file (\"DDS \")", bytes));
    }
    if bytes.len() < HEADER_BYTES {
        return Err(DecodeError::invalid("the DDS header is truncated"));
    }
    let field = |k: usize| u32_at(bytes, 4 + 4 * k);
    if field(0) != 124 || field(18) != 32 {
        return Err(DecodeError::invalid(format!(
            "DDS header size {} / pixel format size {} (must be 124 / 32)",
            field(0),
            field(18)
        )));
    }
    let (flags, height, width, mip_count) = (field(1), field(2), field(3), field(6));
    let (pf_flags, fourcc) = (field(19), field(20));
    let (caps2,) = (field(27),);
    if flags & DDSD_DEPTH != 0 || caps2 & DDSCAPS2_VOLUME != 0 {
        return Err(DecodeError::Unsupported("a DDS volume texture".into()));
    }
    if pf_flags & DDPF_FOURCC == 0 {
        return Err(DecodeError::Unsupported(
            "a DDS file without a FourCC (8-bit RGB masks are not HDR; iblkit reads float formats)"
                .into(),
        ));
    }
    let mut data_start = HEADER_BYTES;
    let mut cube = caps2 & DDSCAPS2_CUBEMAP != 0;
    let format = if fourcc == u32::from_le_bytes(*b"DX10") {
        if bytes.len() < HEADER_BYTES + DX10_BYTES {
            return Err(DecodeError::invalid("the DDS DX10 header is truncated"));
        }
        let dx = |k: usize| u32_at(bytes, HEADER_BYTES + 4 * k);
        let (dxgi, dimension, misc, array) = (dx(0), dx(1), dx(2), dx(3));
        if dimension != DIMENSION_TEXTURE2D {
            return Err(DecodeError::Unsupported(format!(
                "DDS resource dimension {dimension} (only 2D textures and cube maps)"
            )));
        }
        if array > 1 {
            return Err(DecodeError::Unsupported(format!(
                "a DDS texture array ({array} entries)"
            )));
        }
        cube |= misc & MISC_TEXTURECUBE != 0;
        data_start += DX10_BYTES;
        from_dxgi(dxgi)?
    } else {
        from_legacy_fourcc(fourcc)?
    };
    if cube && caps2 & DDSCAPS2_CUBEMAP != 0 && caps2 & DDSCAPS2_ALL_FACES != DDSCAPS2_ALL_FACES {
        return Err(DecodeError::Unsupported(
            "a DDS cube map without all six faces".into(),
        ));
    }
    let kind = if cube {
        TextureKind::Cube
    } else {
        TextureKind::Flat
    };
    if cube && width != height {
        return Err(DecodeError::invalid(format!(
            "cube faces of {width} x {height} are not square"
        )));
    }
    let faces = kind.faces();
    limits.check(u64::from(width), u64::from(height) * faces as u64)?;
    let full_chain = 64 - u64::from(width.max(height)).leading_zeros();
    let levels = if flags & DDSD_MIPMAPCOUNT != 0 {
        mip_count.max(1)
    } else {
        1
    };
    if levels > full_chain {
        return Err(DecodeError::invalid(format!(
            "mip count {mip_count} is more than a {width} x {height} chain holds ({full_chain})"
        )));
    }
    let (w, h) = (width as usize, height as usize);
    let bpt = format.bytes_per_texel();
    let level_bytes: Vec<usize> = (0..levels as usize)
        .map(|m| (w >> m).max(1) * (h >> m).max(1) * bpt)
        .collect();
    let per_face: usize = level_bytes.iter().sum();
    let needed = per_face * faces;
    let data = &bytes[data_start..];
    if data.len() < needed {
        return Err(DecodeError::Limits(format!(
            "the header says {w} x {h}, {faces} face(s), {levels} level(s) of {} ({needed} bytes) \
             but only {} bytes follow (truncated file?)",
            format.name(),
            data.len()
        )));
    }
    let channels = format.channels();
    let mut out_levels: Vec<TextureLevel> = level_bytes
        .iter()
        .enumerate()
        .map(|(m, _)| TextureLevel {
            width: (w >> m).max(1),
            height: (h >> m).max(1),
            faces: Vec::with_capacity(faces),
        })
        .collect();
    let mut pos = 0;
    for _ in 0..faces {
        for (m, &n) in level_bytes.iter().enumerate() {
            let texels = n / bpt;
            let mut v = vec![0.0f32; texels * channels];
            for (t, o) in data[pos..pos + n]
                .chunks_exact(bpt)
                .zip(v.chunks_exact_mut(channels))
            {
                format.decode_texel(t, o);
            }
            out_levels[m].faces.push(v);
            pos += n;
        }
    }
    let mut details = format!(
        "DDS, {}, {} level{}, {}",
        if cube { "cube" } else { "2D" },
        levels,
        if levels == 1 { "" } else { "s" },
        format.name()
    );
    if data.len() > needed {
        details.push_str(&format!(", {} trailing bytes ignored", data.len() - needed));
    }
    Ok(DecodedTexture {
        texture: Texture {
            kind,
            channels,
            levels: out_levels,
        },
        format,
        details,
    })
}
