//! A minimal OpenEXR header parser, run before the bytes are handed to the `exr` crate.
//!
//! `exr` trusts the header: given a data window of 2^31 x 2^31 it computes offset-table and pixel
//! buffer sizes from it, and it decodes compression codes it cannot handle into an unhelpful
//! "unknown compression method". So this module reads the attributes that matter (`channels`,
//! `compression`, `dataWindow`, `displayWindow`, `tiles`, `type`, `name`, `chunkCount`) of every
//! part, bounds every length by the bytes present, and lets [`super::decode`] check the sizes
//! against [`crate::Limits`] and against what the file can hold before `exr` allocates anything.

use crate::error::DecodeError;

/// OpenEXR magic number (little-endian 20000630).
pub(crate) const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// An integer rectangle, both corners inclusive (OpenEXR `box2i`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Bounds {
    pub x_min: i32,
    pub y_min: i32,
    pub x_max: i32,
    pub y_max: i32,
}

impl Bounds {
    /// Width in pixels (may be zero or negative for a malformed box).
    pub fn width(&self) -> i64 {
        i64::from(self.x_max) - i64::from(self.x_min) + 1
    }

    /// Height in pixels (may be zero or negative for a malformed box).
    pub fn height(&self) -> i64 {
        i64::from(self.y_max) - i64::from(self.y_min) + 1
    }
}

/// One channel of a `chlist`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Channel {
    pub name: String,
    /// 0 = uint, 1 = half, 2 = float.
    pub pixel_type: i32,
    pub x_sampling: i32,
    pub y_sampling: i32,
}

impl Channel {
    /// Bytes per sample, or `None` for an unknown pixel type.
    pub fn sample_bytes(&self) -> Option<u64> {
        match self.pixel_type {
            0 | 2 => Some(4),
            1 => Some(2),
            _ => None,
        }
    }

    /// `"uint"`, `"half"` or `"float"`.
    pub fn type_name(&self) -> &'static str {
        match self.pixel_type {
            0 => "uint",
            1 => "half",
            2 => "float",
            _ => "unknown",
        }
    }
}

/// The attributes of one part (a single-part file has one).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct Part {
    pub channels: Vec<Channel>,
    pub compression: Option<u8>,
    pub data_window: Option<Bounds>,
    pub display_window: Option<Bounds>,
    /// Tile width and height.
    pub tiles: Option<(u32, u32)>,
    /// The `type` attribute (`scanlineimage`, `tiledimage`, `deepscanline`, `deeptile`).
    pub kind: Option<String>,
    pub name: Option<String>,
    pub chunk_count: Option<i32>,
}

/// The parsed start of an OpenEXR file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct FileHeader {
    pub parts: Vec<Part>,
    /// Single-part tiled flag (version bit 9).
    pub tiled: bool,
    /// Non-image (deep) flag (version bit 11).
    pub deep: bool,
    /// Multi-part flag (version bit 12).
    pub multipart: bool,
    /// Offset of the first offset table, just after the header(s).
    pub end: usize,
}

/// The OpenEXR name of a compression code; `None` for codes this parser does not know.
pub(crate) fn compression_name(code: u8) -> Option<&'static str> {
    Some(match code {
        0 => "NONE",
        1 => "RLE",
        2 => "ZIPS",
        3 => "ZIP",
        4 => "PIZ",
        5 => "PXR24",
        6 => "B44",
        7 => "B44A",
        8 => "DWAA",
        9 => "DWAB",
        10 => "HTJ2K256",
        11 => "HTJ2K32",
        _ => return None,
    })
}

/// Scanlines per chunk for a compression code (OpenEXR 3 table).
pub(crate) fn lines_per_chunk(code: u8) -> u64 {
    match code {
        0..=2 => 1,
        3 | 5 => 16,
        4 | 6..=8 | 11 => 32,
        _ => 256,
    }
}

/// A bounds-checked cursor over the header bytes.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

const TRUNCATED: &str = "header ends early (truncated file)";

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], DecodeError> {
        let s = self
            .bytes
            .get(self.pos..self.pos.saturating_add(n))
            .ok_or_else(|| DecodeError::invalid(TRUNCATED))?;
        self.pos += n;
        Ok(s)
    }

    fn i32(&mut self) -> Result<i32, DecodeError> {
        let b = self.take(4)?;
        Ok(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// A null-terminated string of at most 255 bytes (empty = end of a list).
    fn name(&mut self) -> Result<String, DecodeError> {
        let rest = &self.bytes[self.pos.min(self.bytes.len())..];
        let n = rest.iter().take(256).position(|&b| b == 0).ok_or_else(|| {
            if rest.len() < 256 {
                DecodeError::invalid(TRUNCATED)
            } else {
                DecodeError::invalid("attribute or channel name longer than 255 bytes")
            }
        })?;
        let s = String::from_utf8_lossy(&rest[..n]).into_owned();
        self.pos += n + 1;
        Ok(s)
    }
}

fn parse_box(v: &[u8]) -> Result<Bounds, DecodeError> {
    let mut c = Cursor { bytes: v, pos: 0 };
    Ok(Bounds {
        x_min: c.i32()?,
        y_min: c.i32()?,
        x_max: c.i32()?,
        y_max: c.i32()?,
    })
}

fn parse_channels(v: &[u8]) -> Result<Vec<Channel>, DecodeError> {
    let mut c = Cursor { bytes: v, pos: 0 };
    let mut out = Vec::new();
    loop {
        let name = c.name()?;
        if name.is_empty() {
            return Ok(out);
        }
        let pixel_type = c.i32()?;
        c.take(4)?; // pLinear + reserved
        let x_sampling = c.i32()?;
        let y_sampling = c.i32()?;
        out.push(Channel {
            name,
            pixel_type,
            x_sampling,
            y_sampling,
        });
    }
}

fn parse_part(c: &mut Cursor<'_>) -> Result<Part, DecodeError> {
    let mut part = Part::default();
    loop {
        let name = c.name()?;
        if name.is_empty() {
            return Ok(part);
        }
        let _type_name = c.name()?;
        let size = usize::try_from(c.i32()?)
            .map_err(|_| DecodeError::invalid(format!("negative size of attribute {name:?}")))?;
        let value = c.take(size)?;
        let text = || {
            String::from_utf8_lossy(value)
                .trim_end_matches('\0')
                .to_owned()
        };
        match name.as_str() {
            "channels" => part.channels = parse_channels(value)?,
            "compression" => part.compression = value.first().copied(),
            "dataWindow" => part.data_window = Some(parse_box(value)?),
            "displayWindow" => part.display_window = Some(parse_box(value)?),
            "tiles" => {
                let mut t = Cursor {
                    bytes: value,
                    pos: 0,
                };
                part.tiles = Some((t.i32()? as u32, t.i32()? as u32));
            }
            "type" => part.kind = Some(text()),
            "name" => part.name = Some(text()),
            "chunkCount" => {
                part.chunk_count = Some(
                    Cursor {
                        bytes: value,
                        pos: 0,
                    }
                    .i32()?,
                )
            }
            _ => {}
        }
    }
}

/// Parses the magic number, version flags and every part header.
pub(crate) fn parse(bytes: &[u8]) -> Result<FileHeader, DecodeError> {
    if !bytes.starts_with(&MAGIC) {
        return Err(crate::format::wrong_magic("an OpenEXR file", bytes));
    }
    let mut c = Cursor { bytes, pos: 4 };
    let version = c.take(4)?;
    if version[0] != 2 {
        return Err(DecodeError::Unsupported(format!(
            "OpenEXR file version {}",
            version[0]
        )));
    }
    let flags = u32::from_le_bytes([version[0], version[1], version[2], version[3]]);
    let tiled = flags & 0x200 != 0;
    let deep = flags & 0x800 != 0;
    let multipart = flags & 0x1000 != 0;
    let mut parts = vec![parse_part(&mut c)?];
    if multipart {
        // Headers follow one another until an empty header (a lone null byte).
        while c.bytes.get(c.pos).is_some_and(|&b| b != 0) {
            parts.push(parse_part(&mut c)?);
        }
        c.take(1)?;
    }
    Ok(FileHeader {
        parts,
        tiled,
        deep,
        multipart,
        end: c.pos,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attr(out: &mut Vec<u8>, name: &str, ty: &str, value: &[u8]) {
        out.extend_from_slice(name.as_bytes());
        out.push(0);
        out.extend_from_slice(ty.as_bytes());
        out.push(0);
        out.extend_from_slice(&(value.len() as i32).to_le_bytes());
        out.extend_from_slice(value);
    }

    #[test]
    fn parses_a_minimal_header() {
        let mut b = MAGIC.to_vec();
        b.extend_from_slice(&[2, 0, 0, 0]);
        let mut ch = b"Y\0".to_vec();
        ch.extend_from_slice(&[1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0]);
        attr(&mut b, "channels", "chlist", &ch);
        attr(&mut b, "compression", "compression", &[9]);
        let window: Vec<u8> = [0i32, 0, 9, 4]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        attr(&mut b, "dataWindow", "box2i", &window);
        b.push(0);
        let h = parse(&b).expect("parses");
        assert_eq!(h.end, b.len());
        let p = &h.parts[0];
        assert_eq!(p.channels[0].name, "Y");
        assert_eq!(p.channels[0].type_name(), "half");
        assert_eq!(p.compression.and_then(compression_name), Some("DWAB"));
        let w = p.data_window.expect("window");
        assert_eq!((w.width(), w.height()), (10, 5));
        // Every truncation is an error, never a panic.
        for n in 0..b.len() - 1 {
            assert!(parse(&b[..n]).is_err(), "prefix {n}");
        }
    }
}
