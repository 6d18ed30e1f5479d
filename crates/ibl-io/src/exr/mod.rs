//! OpenEXR reading and writing through the `exr` crate, behind a header check of our own.
//!
//! Reading: every compression `exr` decodes (NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA,
//! DWAB) and half/float/uint channels (converted to `f32`; uint as its numeric value). The image
//! is the first RGB layer found: parts in file order, and within a part the unprefixed `R`, `G`,
//! `B` channels before prefixed ones (`diffuse.R`, ...). Without any RGB layer, the first
//! luminance-only `Y` layer is read as grey (`r = g = b = Y`). The data window is placed inside the
//! display window (the returned image has the display window's size; pixels outside the data
//! window are 0, data outside the display window is cropped).
//!
//! Before `exr` sees the bytes, the `header` submodule parses every part header so that deep
//! data, chroma subsampling and compressions `exr` cannot decode (HTJ2K, or codes from newer
//! OpenEXR versions) give a [`DecodeError::Unsupported`] naming them, and so that sizes are
//! checked against [`Limits`] and against the file length: every chunk costs at least 16 bytes
//! (offset table entry plus chunk header), and compressed pixel data cannot shrink below a bound
//! per method (1:1 for NONE, 64:1 for RLE, 16:1 for B44, 4096:1 for the zlib/Huffman ones; DWA is
//! only bounded by its chunk count). This is needed: `exr` 1.74 itself rejects a 2^31-pixel-wide
//! window, but given a 30000 x 8000 window in a 569-byte file it asks for the 240-Mpixel buffer
//! before noticing the bytes are missing, and it reports HTJ2K as "block position exceeds total
//! size" rather than naming the compression.
//!
//! `exr` has internal asserts that hostile data might trip, so it runs under `catch_unwind` (a
//! panic becomes an `Invalid` error), and its chunks are decompressed in parallel by this module
//! with `par_iter`, whose panics reach that `catch_unwind`, rather than by `exr`'s own spawned
//! jobs, whose panics would abort the process.
//!
//! Writing: RGB scanlines, float (bit-exact) or half (rounded to nearest; finite values beyond
//! +-65504 are clamped to it), compressed with NONE, RLE, ZIPS, ZIP (default) or PIZ, all
//! lossless. (`exr` writes DWA lossily, up to 3 % even for float, so it is not offered.)

mod header;

use std::io::Cursor;
use std::panic::{AssertUnwindSafe, catch_unwind};

use ::exr::block::UncompressedBlock;
use ::exr::block::chunk::Chunk;
use ::exr::block::reader::ChunksReader;
use ::exr::image::read::image::LayersReader;
use ::exr::prelude as x;
use ::exr::prelude::{ReadChannels, ReadLayers, ReadSpecificChannel, WritableImage, f16};
use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::error::{DecodeError, EncodeError};
use crate::format::{Limits, RawImage};
use header::{Bounds, FileHeader, Part, compression_name, lines_per_chunk};

/// Sample precision of written channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ExrPrecision {
    /// 16-bit half floats (about 3 significant digits, largest value 65504).
    Half,
    /// 32-bit floats, written bit for bit.
    #[default]
    Float,
}

/// Lossless compression of written files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ExrCompression {
    /// No compression.
    None,
    /// Run-length encoding.
    Rle,
    /// zlib, one scanline per chunk.
    Zips,
    /// zlib, 16 scanlines per chunk: small files, the usual choice.
    #[default]
    Zip,
    /// Wavelet + Huffman, 32 scanlines per chunk: good for noisy photographs.
    Piz,
}

/// How [`encode`] writes an OpenEXR file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ExrOptions {
    /// Channel precision (default float).
    pub precision: ExrPrecision,
    /// Compression (default ZIP).
    pub compression: ExrCompression,
}

/// Which channels of which part become the image.
#[derive(Debug)]
enum Selection {
    Rgb([String; 3]),
    Grey(String),
}

/// The channel-name prefixes (layers) of a part, the unprefixed one first.
fn prefixes(part: &Part) -> Vec<&str> {
    let mut out = vec![""];
    for c in &part.channels {
        let p = c.name.rfind('.').map_or("", |i| &c.name[..=i]);
        if !out.contains(&p) {
            out.push(p);
        }
    }
    out
}

fn select(parts: &[Part]) -> Result<(usize, Selection), DecodeError> {
    let has = |part: &Part, name: &str| part.channels.iter().any(|c| c.name == name);
    for (i, part) in parts.iter().enumerate() {
        for p in prefixes(part) {
            for [r, g, b] in [["R", "G", "B"], ["r", "g", "b"]] {
                let names = [r, g, b].map(|c| format!("{p}{c}"));
                if names.iter().all(|n| has(part, n)) {
                    return Ok((i, Selection::Rgb(names)));
                }
            }
        }
    }
    for (i, part) in parts.iter().enumerate() {
        for p in prefixes(part) {
            let chroma = has(part, &format!("{p}RY")) || has(part, &format!("{p}BY"));
            if has(part, &format!("{p}Y")) && !chroma {
                return Ok((i, Selection::Grey(format!("{p}Y"))));
            }
        }
    }
    let names: Vec<&str> = parts
        .iter()
        .flat_map(|p| &p.channels)
        .map(|c| &*c.name)
        .collect();
    if names.iter().any(|n| n.ends_with("RY")) {
        return Err(DecodeError::Unsupported(
            "luminance/chroma OpenEXR (Y, RY, BY channels); convert it to RGB".into(),
        ));
    }
    // Name what is missing: an R-only file (a mask, one channel of a render) has an R channel,
    // so "without R, G, B or Y" would contradict its own list (issue 13, hostile 8).
    let missing: Vec<&str> = ["R", "G", "B"]
        .into_iter()
        .filter(|c| !names.iter().any(|n| n.rsplit('.').next() == Some(*c)))
        .collect();
    Err(DecodeError::Unsupported(format!(
        "OpenEXR file with neither the three colour channels R, G and B (missing {}) nor a luminance channel Y (its channels: {})",
        missing.join(", "),
        names.join(", ")
    )))
}

/// Checks one part's declared features and sizes; returns its validated data window size.
fn check_part(part: &Part, deep: bool, limits: &Limits) -> Result<(u64, u64), DecodeError> {
    if deep || part.kind.as_deref().is_some_and(|k| k.starts_with("deep")) {
        return Err(DecodeError::Unsupported("deep-data OpenEXR".into()));
    }
    let code = part
        .compression
        .ok_or_else(|| DecodeError::invalid("no compression attribute"))?;
    match compression_name(code) {
        Some(name @ ("HTJ2K256" | "HTJ2K32")) => {
            return Err(DecodeError::Unsupported(format!(
                "OpenEXR compression {name} (code {code}), which the exr crate cannot decode"
            )));
        }
        Some(_) => {}
        None => {
            return Err(DecodeError::Unsupported(format!(
                "OpenEXR compression code {code}, unknown to the exr crate (a newer method?)"
            )));
        }
    }
    if part.channels.is_empty() {
        return Err(DecodeError::invalid(
            "no channels attribute (or an empty one)",
        ));
    }
    for c in &part.channels {
        if c.sample_bytes().is_none() {
            return Err(DecodeError::invalid(format!(
                "channel {:?} has unknown pixel type {}",
                c.name, c.pixel_type
            )));
        }
        if c.x_sampling != 1 || c.y_sampling != 1 {
            return Err(DecodeError::Unsupported(format!(
                "subsampled OpenEXR channel {:?} ({} x {})",
                c.name, c.x_sampling, c.y_sampling
            )));
        }
    }
    let dw = part
        .data_window
        .ok_or_else(|| DecodeError::invalid("no dataWindow attribute"))?;
    let (w, h) = (dw.width(), dw.height());
    if w <= 0 || h <= 0 {
        return Err(DecodeError::invalid(format!(
            "empty data window ({w} x {h} pixels)"
        )));
    }
    limits.check(w as u64, h as u64)?;
    Ok((w as u64, h as u64))
}

/// Largest uncompressed pixel block (one chunk) we let `exr` allocate: 256 MiB, far above any
/// real file (a 65536-wide float RGBA scanline block of 32 lines is 32 MiB).
const MAX_BLOCK_BYTES: u128 = 256 << 20;

/// Rejects headers that describe more data than the file could possibly hold, or blocks larger
/// than [`MAX_BLOCK_BYTES`].
fn check_file_size(
    header: &FileHeader,
    sizes: &[(u64, u64)],
    len: usize,
) -> Result<(), DecodeError> {
    let mut chunks: u128 = 0;
    let mut min_pixel_bytes: u128 = 0;
    for (part, &(w, h)) in header.parts.iter().zip(sizes) {
        let code = part.compression.unwrap_or(0);
        let tiled = header.tiled || part.kind.as_deref().is_some_and(|k| k.contains("tile"));
        chunks += match part.tiles.filter(|_| tiled) {
            Some((tw, th)) if tw == 0 || th == 0 => {
                return Err(DecodeError::invalid(format!("zero tile size {tw} x {th}")));
            }
            Some((tw, th)) => u128::from(w.div_ceil(u64::from(tw)) * h.div_ceil(u64::from(th))),
            None => u128::from(h.div_ceil(lines_per_chunk(code))),
        };
        let bytes_per_pixel: u64 = part.channels.iter().filter_map(|c| c.sample_bytes()).sum();
        // `exr` allocates up to one uncompressed block per chunk before checking the chunk's
        // size field against the file, so the block size itself must be bounded (hundreds of
        // channels make a block of a narrow image gigabytes; the fuzzer found one).
        let block_pixels = match part.tiles.filter(|_| tiled) {
            Some((tw, th)) => u128::from(tw) * u128::from(th),
            None => u128::from(w) * u128::from(lines_per_chunk(code)),
        };
        let block_bytes = block_pixels * u128::from(bytes_per_pixel);
        if block_bytes > MAX_BLOCK_BYTES {
            return Err(DecodeError::Limits(format!(
                "one pixel block would hold {block_bytes} bytes ({} channels, {bytes_per_pixel} \
                 bytes per pixel), over the {MAX_BLOCK_BYTES}-byte limit",
                part.channels.len()
            )));
        }
        let ratio: u128 = match code {
            0 => 1,
            1 => 64,
            6 | 7 => 16,
            8 | 9 => 1 << 20,
            _ => 4096,
        };
        min_pixel_bytes += u128::from(w) * u128::from(h) * u128::from(bytes_per_pixel) / ratio;
    }
    let needed = header.end as u128 + 16 * chunks + min_pixel_bytes;
    if needed > len as u128 {
        return Err(DecodeError::Limits(format!(
            "the header describes {chunks} chunks needing at least {needed} bytes, \
             but the file has only {len} bytes (truncated file?)"
        )));
    }
    Ok(())
}

/// Pixel storage filled by `exr`: the data window, row-major.
struct Pixels {
    width: usize,
    data: Vec<Rgb>,
}

impl Pixels {
    /// Storage for the size `exr` reports, allocated only when it equals the data window our own
    /// header parse already checked against the limits. A hostile file can make the two parses
    /// disagree (the fuzzer found one asking for 1.9 TB); then nothing is allocated, every write
    /// is dropped, and [`read_pixels`] reports the mismatch.
    fn new(size: x::Vec2<usize>, checked: (usize, usize)) -> Pixels {
        let data = if (size.width(), size.height()) == checked {
            vec![Rgb::ZERO; size.area()]
        } else {
            Vec::new()
        };
        Pixels {
            width: size.width(),
            data,
        }
    }

    fn set(&mut self, pos: x::Vec2<usize>, value: Rgb) {
        if let Some(p) = self.data.get_mut(pos.y() * self.width + pos.x()) {
            *p = value;
        }
    }
}

fn from_exr_error(e: ::exr::error::Error) -> DecodeError {
    match e {
        ::exr::error::Error::NotSupported(m) => DecodeError::Unsupported(format!("OpenEXR {m}")),
        ::exr::error::Error::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            DecodeError::invalid("pixel data ends early (truncated file)")
        }
        other => DecodeError::invalid(other.to_string()),
    }
}

fn text(name: &str) -> Result<x::Text, DecodeError> {
    x::Text::new_or_none(name)
        .ok_or_else(|| DecodeError::invalid(format!("channel name {name:?} is not Latin-1")))
}

/// The size (width, height) of the first part's data window, from the header alone (no pixel is
/// decoded; `bytes` may be only the start of the file).
pub fn header_size(bytes: &[u8]) -> Result<(usize, usize), DecodeError> {
    let parsed = header::parse(bytes)?;
    let window = parsed
        .parts
        .first()
        .and_then(|p| p.data_window)
        .ok_or_else(|| DecodeError::invalid("no dataWindow in the header"))?;
    let size = |v: i64| usize::try_from(v).map_err(|_| DecodeError::invalid("empty dataWindow"));
    Ok((size(window.width())?, size(window.height())?))
}

/// Bounds what `exr` will allocate, judged on the headers exactly as `exr` parsed them (a hostile
/// file with repeated attributes can make our own header parse and `exr`'s disagree, so the
/// checks in [`check_file_size`] are repeated here on `exr`'s view): each uncompressed block at
/// most [`MAX_BLOCK_BYTES`], and an offset table that fits in the file.
fn check_parsed_headers(
    headers: &[::exr::meta::header::Header],
    len: usize,
) -> Result<(), DecodeError> {
    for h in headers {
        let block = h.max_block_byte_size() as u128;
        if block > MAX_BLOCK_BYTES {
            return Err(DecodeError::Limits(format!(
                "one pixel block would hold {block} bytes, over the {MAX_BLOCK_BYTES}-byte limit"
            )));
        }
        if (h.chunk_count as u128) * 8 > len as u128 {
            return Err(DecodeError::Limits(format!(
                "the header lists {} chunks, more than a {len}-byte file can index",
                h.chunk_count
            )));
        }
    }
    Ok(())
}

/// A DWAA/DWAB block starts with eleven little-endian u64 counters (OpenEXR's DWA chunk
/// header): version, unknown uncompressed and compressed sizes, AC, DC and RLE compressed sizes,
/// RLE uncompressed and raw sizes, AC and DC coefficient counts, AC compression. `exr` allocates
/// by the sizes and counts before it reads the sections (a fuzzed file asked for 2^51 AC
/// values, which aborts the process), so they are bounded here first: no section decodes to
/// more than [`DWA_EXPANSION`] times the block's largest uncompressed size, plus 64 KiB for the
/// 8 x 8 padding of tiny blocks. A real block is far within that.
fn check_dwa_counters(
    chunk: &Chunk,
    headers: &[::exr::meta::header::Header],
) -> Result<(), DecodeError> {
    use ::exr::block::chunk::CompressedBlock;
    use ::exr::compression::Compression;
    let Some(header) = headers.get(chunk.layer_index) else {
        return Ok(()); // `exr` reports the bad index itself.
    };
    if !matches!(
        header.compression,
        Compression::DWAA(_) | Compression::DWAB(_)
    ) {
        return Ok(());
    }
    let data = match &chunk.compressed_block {
        CompressedBlock::ScanLine(b) => &b.compressed_pixels_le,
        CompressedBlock::Tile(b) => &b.compressed_pixels_le,
        _ => return Ok(()), // deep data is refused before any block is read
    };
    // The block's own uncompressed size, computed as `exr` does before decompressing; a block
    // `exr` cannot place is left for it to refuse.
    let Ok(section) = header
        .get_block_data_indices(&chunk.compressed_block)
        .and_then(|indices| header.get_absolute_block_pixel_coordinates(indices))
    else {
        return Ok(());
    };
    let expected =
        (section.size.area() as u64).saturating_mul(header.channels.bytes_per_pixel as u64);
    // Stored raw (as `exr` checks first) or empty: nothing is decoded by the counters.
    if data.is_empty() || data.len() as u64 == expected {
        return Ok(());
    }
    let bound = expected
        .saturating_mul(DWA_EXPANSION)
        .saturating_add(1 << 16);
    let counter = |i: usize| {
        data.get(8 * i..8 * i + 8)
            .and_then(|b| b.try_into().ok())
            .map(u64::from_le_bytes)
    };
    // Counters 1 (unknown uncompressed size), 6 and 7 (RLE sizes) are bytes; 8 and 9 (AC and DC
    // counts) are u16 values.
    for (i, bytes_each) in [(1, 1), (6, 1), (7, 1), (8, 2), (9, 2)] {
        let Some(v) = counter(i) else {
            return Ok(()); // a truncated header: `exr` refuses it
        };
        if v.saturating_mul(bytes_each) > bound {
            return Err(DecodeError::Limits(format!(
                "a DWA block's header asks for {v} values in section {i}, more than its {expected}-byte \
                 block can hold"
            )));
        }
    }
    Ok(())
}

/// How many times a DWA block's largest uncompressed size any of its sections may decode to.
const DWA_EXPANSION: u64 = 8;

/// Compressed chunks decompressed together: bounds the extra memory to that many blocks.
const CHUNK_BATCH: usize = 64;

/// `exr`'s `ReadImage::from_buffered`, except that chunks are decompressed with `par_iter` on
/// rayon's global pool rather than jobs spawned on a fresh pool: a panic in a spawned job would
/// abort the process (and leave `exr` waiting forever with a panic handler), while a panic in
/// `par_iter` reaches the caller's `catch_unwind`. It also saves creating a pool per file.
fn decode_layers<'s, L: ReadLayers<'s>>(
    bytes: &[u8],
    read_layers: &'s L,
) -> Result<L::Layers, DecodeError> {
    let chunks = ::exr::block::read(Cursor::new(bytes), false).map_err(from_exr_error)?;
    check_parsed_headers(chunks.headers(), bytes.len())?;
    let mut layers = read_layers
        .create_layers_reader(chunks.headers())
        .map_err(from_exr_error)?;
    let mut chunks = chunks
        .filter_chunks(false, |meta, tile, block| {
            layers.filter_block(meta, tile, block)
        })
        .map_err(from_exr_error)?;
    let meta = chunks.meta_data().clone();
    loop {
        let batch: Vec<Chunk> = chunks
            .by_ref()
            .take(CHUNK_BATCH)
            .collect::<Result<_, _>>()
            .map_err(from_exr_error)?;
        if batch.is_empty() {
            break;
        }
        for chunk in &batch {
            check_dwa_counters(chunk, &meta.headers)?;
        }
        let blocks: Vec<_> = batch
            .into_par_iter()
            .map(|chunk| UncompressedBlock::decompress_chunk(chunk, &meta, false))
            .collect();
        for block in blocks {
            let block = block.map_err(from_exr_error)?;
            layers
                .read_block(&meta.headers, block)
                .map_err(from_exr_error)?;
        }
    }
    Ok(layers.into_layers())
}

/// Runs `exr` on the bytes for the selected channels; returns the data window's pixels.
fn read_pixels(
    bytes: &[u8],
    selection: &Selection,
    checked: (usize, usize),
) -> Result<(x::Vec2<usize>, Pixels), DecodeError> {
    let reader = x::read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels();
    let layer = match selection {
        Selection::Rgb([r, g, b]) => {
            let read = reader
                .required(text(r)?)
                .required(text(g)?)
                .required(text(b)?)
                .collect_pixels(
                    |size, _| Pixels::new(size, checked),
                    |px: &mut Pixels, pos, (r, g, b): (f32, f32, f32)| {
                        px.set(pos, Rgb::new(r, g, b))
                    },
                )
                .first_valid_layer();
            decode_layers(bytes, &read)?
        }
        Selection::Grey(y) => {
            let read = reader
                .required(text(y)?)
                .collect_pixels(
                    |size, _| Pixels::new(size, checked),
                    |px: &mut Pixels, pos, (v,): (f32,)| px.set(pos, Rgb::splat(v)),
                )
                .first_valid_layer();
            let layer = decode_layers(bytes, &read)?;
            return consistent(layer.size, layer.channel_data.pixels, checked);
        }
    };
    consistent(layer.size, layer.channel_data.pixels, checked)
}

/// Fails when `exr` read a different image size than our header parse checked.
fn consistent(
    size: x::Vec2<usize>,
    pixels: Pixels,
    checked: (usize, usize),
) -> Result<(x::Vec2<usize>, Pixels), DecodeError> {
    if (size.width(), size.height()) != checked || pixels.data.len() != size.area() {
        return Err(DecodeError::invalid(format!(
            "inconsistent header: the selected part's data window is {} x {} but the layer \
             decoded is {} x {} (a corrupt header, or a multi-part file whose first RGB part is \
             not the selected one)",
            checked.0,
            checked.1,
            size.width(),
            size.height()
        )));
    }
    Ok((size, pixels))
}

/// Copies the data window's pixels into an image the size of the display window.
fn place(pixels: Vec<Rgb>, dw: Bounds, disp: Bounds) -> Result<Image<Rgb>, DecodeError> {
    let (dw_w, dw_h) = (dw.width() as usize, dw.height() as usize);
    if dw == disp {
        return Image::from_vec(dw_w, dw_h, pixels)
            .map_err(|e| DecodeError::invalid(e.to_string()));
    }
    let (w, h) = (disp.width() as usize, disp.height() as usize);
    let mut out = vec![Rgb::ZERO; w * h];
    // Overlap in display-window coordinates (i64: no overflow for any i32 corners).
    let x0 = i64::from(dw.x_min.max(disp.x_min));
    let x1 = i64::from(dw.x_max.min(disp.x_max));
    let y0 = i64::from(dw.y_min.max(disp.y_min));
    let y1 = i64::from(dw.y_max.min(disp.y_max));
    if x0 <= x1 && y0 <= y1 {
        let n = (x1 - x0 + 1) as usize;
        for y in y0..=y1 {
            let src =
                (y - i64::from(dw.y_min)) as usize * dw_w + (x0 - i64::from(dw.x_min)) as usize;
            let dst =
                (y - i64::from(disp.y_min)) as usize * w + (x0 - i64::from(disp.x_min)) as usize;
            if let (Some(s), Some(d)) = (pixels.get(src..src + n), out.get_mut(dst..dst + n)) {
                d.copy_from_slice(s);
            }
        }
    }
    Image::from_vec(w, h, out).map_err(|e| DecodeError::invalid(e.to_string()))
}

/// Decodes an OpenEXR file held in memory (values as stored, converted to `f32`, not sanitised).
pub fn decode(bytes: &[u8], limits: &Limits) -> Result<RawImage, DecodeError> {
    let header = header::parse(bytes)?;
    let sizes = header
        .parts
        .iter()
        .map(|p| check_part(p, header.deep, limits))
        .collect::<Result<Vec<_>, _>>()?;
    check_file_size(&header, &sizes, bytes.len())?;
    let (index, selection) = select(&header.parts)?;
    let part = &header.parts[index];
    let dw = part
        .data_window
        .ok_or_else(|| DecodeError::invalid("no dataWindow attribute"))?;
    let disp = match part.display_window {
        Some(d) if d.width() > 0 && d.height() > 0 => {
            limits.check(d.width() as u64, d.height() as u64)?;
            d
        }
        _ => dw,
    };

    let checked = (dw.width() as usize, dw.height() as usize);
    let (size, pixels) = catch_unwind(AssertUnwindSafe(|| read_pixels(bytes, &selection, checked)))
        .map_err(|_| DecodeError::invalid("the OpenEXR decoder failed on inconsistent data"))??;
    debug_assert_eq!((size.width(), size.height()), checked);
    let image = place(pixels.data, dw, disp)?;

    let code = part.compression.unwrap_or(0);
    let channel_names: Vec<&str> = match &selection {
        Selection::Rgb(n) => n.iter().map(String::as_str).collect(),
        Selection::Grey(y) => vec![y.as_str()],
    };
    let mut types: Vec<&str> = Vec::new();
    for c in part
        .channels
        .iter()
        .filter(|c| channel_names.contains(&c.name.as_str()))
    {
        if !types.contains(&c.type_name()) {
            types.push(c.type_name());
        }
    }
    let mut details = format!(
        "OpenEXR, {}, {}",
        compression_name(code).unwrap_or("?"),
        if types.len() == 1 {
            types[0].to_owned()
        } else {
            format!("mixed {}", types.join("/"))
        }
    );
    if let Selection::Grey(y) = &selection {
        details.push_str(&format!(", grey from {y}"));
    } else if let Some(n) = channel_names.first().and_then(|r| r.strip_suffix('R'))
        && !n.is_empty()
    {
        details.push_str(&format!(", layer {:?}", n.trim_end_matches('.')));
    }
    if header.parts.len() > 1 {
        details.push_str(&format!(", part {} of {}", index + 1, header.parts.len()));
    }
    if dw != disp {
        details.push_str(&format!(
            ", data window ({}, {})-({}, {}) in display window ({}, {})-({}, {})",
            dw.x_min, dw.y_min, dw.x_max, dw.y_max, disp.x_min, disp.y_min, disp.x_max, disp.y_max
        ));
    }
    Ok(RawImage { image, details })
}

/// Encodes an image as a scanline RGB OpenEXR file.
pub fn encode(image: &Image<Rgb>, options: &ExrOptions) -> Result<Vec<u8>, EncodeError> {
    if image.is_empty() {
        return Err(EncodeError::new(
            "an empty image cannot be written as OpenEXR",
        ));
    }
    let (w, h) = (image.width(), image.height());
    let compression = match options.compression {
        ExrCompression::None => x::Compression::Uncompressed,
        ExrCompression::Rle => x::Compression::RLE,
        ExrCompression::Zips => x::Compression::ZIP1,
        ExrCompression::Zip => x::Compression::ZIP16,
        ExrCompression::Piz => x::Compression::PIZ,
    };
    let encoding = x::Encoding {
        compression,
        blocks: x::Blocks::ScanLines,
        line_order: x::LineOrder::Increasing,
    };
    let attributes = x::LayerAttributes {
        software_name: x::Text::new_or_none("iblkit"),
        ..x::LayerAttributes::default()
    };
    let px = image.pixels();
    let at = move |pos: x::Vec2<usize>| px.get(pos.y() * w + pos.x()).copied().unwrap_or_default();
    let mut out = Cursor::new(Vec::new());
    let result = match options.precision {
        ExrPrecision::Float => {
            let channels = x::SpecificChannels::rgb(move |pos| {
                let p = at(pos);
                (p.r, p.g, p.b)
            });
            x::Image::from_layer(x::Layer::new((w, h), attributes, encoding, channels))
                .write()
                .to_buffered(&mut out)
        }
        ExrPrecision::Half => {
            let half = |v: f32| {
                let v = if v.is_finite() {
                    v.clamp(-65504.0, 65504.0)
                } else {
                    v
                };
                f16::from_f32(v)
            };
            let channels = x::SpecificChannels::rgb(move |pos| {
                let p = at(pos);
                (half(p.r), half(p.g), half(p.b))
            });
            x::Image::from_layer(x::Layer::new((w, h), attributes, encoding, channels))
                .write()
                .to_buffered(&mut out)
        }
    };
    result.map_err(|e| EncodeError::new(format!("OpenEXR writer: {e}")))?;
    Ok(out.into_inner())
}
