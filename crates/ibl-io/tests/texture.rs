//! KTX2 and DDS textures: what we write is read back by independent parsers (the `ktx2` and
//! `ddsfile` crates) with the right header, data format descriptor and data, round-trips through
//! our reader within each format's precision, loads as an image through `read_image` (a cube
//! as its six faces side by side), and hostile variants give errors, never panics.

#![allow(clippy::unwrap_used)] // tests may panic

use ibl_io::{
    ImageFormat, Limits, TexelFormat, Texture, TextureKind, TextureLevel, dds, ktx2, read_image,
    read_texture, write_texture,
};

/// A texture with a full mip chain whose values encode (level, face, texel).
fn texture(kind: TextureKind, size: usize, channels: usize) -> Texture {
    let levels = (0..=size.trailing_zeros() as usize)
        .map(|m| {
            let s = size >> m;
            let faces = (0..kind.faces())
                .map(|f| {
                    (0..s * s * channels)
                        .map(|k| 0.25 * (m as f32 + 1.0) + 0.5 * f as f32 + (k % 97) as f32 / 8.0)
                        .collect()
                })
                .collect();
            TextureLevel {
                width: s,
                height: s,
                faces,
            }
        })
        .collect();
    Texture {
        kind,
        channels,
        levels,
    }
}

/// Largest error allowed by a format for values up to `max` (its rounding).
fn precision(format: TexelFormat, max: f32) -> f32 {
    match format {
        TexelFormat::Rgba32Float | TexelFormat::Rg32Float => 0.0,
        // Half: 11 significant bits, rounding to nearest: 2^-11 relative.
        TexelFormat::Rgba16Float | TexelFormat::Rg16Float => max * 2f32.powi(-11),
        // RGB9E5: half a unit of the 9-bit mantissa of the largest channel.
        _ => max * 2f32.powi(-9),
    }
}

fn assert_close(a: &Texture, b: &Texture, format: TexelFormat) {
    assert_eq!(
        (a.kind, a.channels, a.levels.len()),
        (b.kind, b.channels, b.levels.len())
    );
    for (la, lb) in a.levels.iter().zip(&b.levels) {
        assert_eq!((la.width, la.height), (lb.width, lb.height));
        for (fa, fb) in la.faces.iter().zip(&lb.faces) {
            for (ta, tb) in fa.chunks(a.channels).zip(fb.chunks(a.channels)) {
                let max = ta.iter().cloned().fold(0.0f32, f32::max);
                for (x, y) in ta.iter().zip(tb) {
                    assert!(
                        (x - y).abs() <= precision(format, max),
                        "{x} {y} {format:?}"
                    );
                }
            }
        }
    }
}

const RGB_FORMATS: [TexelFormat; 3] = [
    TexelFormat::Rgba16Float,
    TexelFormat::Rgba32Float,
    TexelFormat::Rgb9E5,
];
const RG_FORMATS: [TexelFormat; 2] = [TexelFormat::Rg16Float, TexelFormat::Rg32Float];

fn cases() -> Vec<(Texture, TexelFormat)> {
    let mut v = Vec::new();
    for f in RGB_FORMATS {
        v.push((texture(TextureKind::Cube, 16, 3), f));
        v.push((texture(TextureKind::Flat, 8, 3), f));
    }
    for f in RG_FORMATS {
        v.push((texture(TextureKind::Flat, 32, 2), f));
    }
    v
}

#[test]
fn ktx2_files_parse_with_the_ktx2_crate_and_round_trip() {
    for (tex, format) in cases() {
        let bytes = ktx2::encode(&tex, format).unwrap();
        let reader = ::ktx2::Reader::new(&bytes[..]).unwrap();
        let h = reader.header();
        assert_eq!(h.format.map(|f| f.value()), Some(ktx2::vk_format(format)));
        assert_eq!(
            (h.pixel_width, h.pixel_height),
            (tex.size().0 as u32, tex.size().1 as u32)
        );
        assert_eq!(h.face_count, tex.kind.faces() as u32);
        assert_eq!((h.layer_count, h.pixel_depth), (0, 0));
        assert_eq!(h.level_count as usize, tex.levels.len());
        assert!(h.supercompression_scheme.is_none());
        assert!(reader.writer().is_some_and(|w| w.starts_with("iblkit")));
        // Our data format descriptor is the one the ktx2 crate builds from the Khronos tables,
        // and so is typeSize.
        let (expected, type_size) = ::ktx2::dfd::Basic::from_format(h.format.unwrap()).unwrap();
        assert_eq!(reader.basic_dfd(), Some(&expected), "{format:?}");
        assert_eq!(h.type_size, type_size, "{format:?}");
        for (m, level) in reader.levels().enumerate() {
            let l = &tex.levels[m];
            let n = l.width * l.height * tex.kind.faces() * format.bytes_per_texel();
            assert_eq!(level.data.len(), n, "level {m}");
            assert_eq!(level.uncompressed_byte_length as usize, n);
            // Level data starts on a multiple of lcm(texel size, 4).
            let offset = level.data.as_ptr() as usize - bytes.as_ptr() as usize;
            assert_eq!(offset % format.bytes_per_texel().max(4), 0);
        }
        // First texel of the last face of level 0, decoded by hand from the bytes.
        let back = ktx2::decode(&bytes, &Limits::default()).unwrap();
        assert_eq!(back.format, format);
        assert_close(&tex, &back.texture, format);
    }
}

#[test]
fn dds_files_parse_with_the_ddsfile_crate_and_round_trip() {
    for (tex, format) in cases() {
        let bytes = dds::encode(&tex, format).unwrap();
        let parsed = ddsfile::Dds::read(&bytes[..]).unwrap();
        assert_eq!(
            parsed.get_dxgi_format().map(|f| f as u32),
            Some(dds::dxgi_format(format))
        );
        assert_eq!(parsed.get_width() as usize, tex.size().0);
        assert_eq!(parsed.get_height() as usize, tex.size().1);
        assert_eq!(parsed.get_num_mipmap_levels() as usize, tex.levels.len());
        assert_eq!(parsed.get_num_array_layers() as usize, tex.kind.faces());
        let per_face: usize = tex
            .levels
            .iter()
            .map(|l| l.width * l.height * format.bytes_per_texel())
            .sum();
        assert_eq!(parsed.data.len(), per_face * tex.kind.faces());
        // Face-major: the first bytes of face 1 are level 0 of -X.
        let mut first = Vec::new();
        format.encode_texel(
            &tex.levels[0].faces[tex.kind.faces() - 1][..tex.channels],
            &mut first,
        );
        let at = per_face * (tex.kind.faces() - 1);
        assert_eq!(&parsed.data[at..at + first.len()], &first[..]);
        let back = dds::decode(&bytes, &Limits::default()).unwrap();
        assert_eq!(back.format, format);
        assert_close(&tex, &back.texture, format);
    }
}

#[test]
fn files_on_disk_load_as_images_and_cubes_as_strips() {
    let dir = tempfile::tempdir().unwrap();
    let cube = texture(TextureKind::Cube, 8, 3);
    for ext in ["ktx2", "dds"] {
        let path = dir.path().join(format!("cube.{ext}"));
        write_texture(&path, &cube, TexelFormat::Rgba32Float).unwrap();
        let loaded = read_image(&path).unwrap();
        assert_eq!(loaded.format, ImageFormat::from_path(&path).unwrap());
        assert!(loaded.details.contains("cube") && loaded.details.contains("4 levels"));
        let img = loaded.image;
        assert_eq!((img.width(), img.height()), (48, 8));
        for f in 0..6 {
            for (k, chunk) in cube.levels[0].faces[f].chunks(3).enumerate() {
                let p = img.get(f * 8 + k % 8, k / 8);
                assert_eq!([p.r, p.g, p.b], [chunk[0], chunk[1], chunk[2]]);
            }
        }
        let all = read_texture(&path, &Limits::default()).unwrap();
        assert_eq!(all.texture, cube);
    }
    // A two-channel table reads with blue 0; a plain image writes as one 2D level.
    let table = texture(TextureKind::Flat, 4, 2);
    let path = dir.path().join("lut.ktx2");
    write_texture(&path, &table, TexelFormat::Rg32Float).unwrap();
    let p = *read_image(&path).unwrap().image.get(1, 0);
    assert_eq!(
        [p.r, p.g, p.b],
        [
            table.levels[0].faces[0][2],
            table.levels[0].faces[0][3],
            0.0
        ]
    );
    let img = ibl_core::Image::filled(6, 3, ibl_core::Rgb::new(1.0, 2.0, 3.0));
    let path = dir.path().join("flat.dds");
    ibl_io::write_image(&path, &img, &ibl_io::WriteOptions::default()).unwrap();
    assert_eq!(read_image(&path).unwrap().image, img);
    // Formats that cannot hold the channels are refused before writing.
    assert!(write_texture(&path, &table, TexelFormat::Rgba16Float).is_err());
    assert!(write_texture(&dir.path().join("x.exr"), &cube, TexelFormat::Rgba16Float).is_err());
}

/// Every prefix of a valid file, and single-byte corruptions of its header, decode to an error
/// or a bounded texture, never a panic.
#[test]
fn hostile_variants_are_refused_without_panicking() {
    let limits = Limits {
        max_width: 4096,
        max_height: 4096,
        max_pixels: 1 << 22,
    };
    for (tex, format) in [
        (texture(TextureKind::Cube, 4, 3), TexelFormat::Rgba16Float),
        (texture(TextureKind::Flat, 8, 2), TexelFormat::Rg32Float),
    ] {
        type Decoder = fn(&[u8], &Limits) -> Result<ibl_io::DecodedTexture, ibl_io::DecodeError>;
        let pairs: [(Vec<u8>, Decoder); 2] = [
            (ktx2::encode(&tex, format).unwrap(), ktx2::decode),
            (dds::encode(&tex, format).unwrap(), dds::decode),
        ];
        for (bytes, decode) in pairs {
            for len in 0..bytes.len() {
                assert!(
                    decode(&bytes[..len], &limits).is_err(),
                    "prefix {len} accepted"
                );
            }
            for at in 0..bytes.len().min(240) {
                for v in [0u8, 1, 6, 0x7f, 0xff] {
                    let mut b = bytes.clone();
                    b[at] = v;
                    if let Ok(t) = decode(&b, &limits) {
                        let (w, h) = t.texture.size();
                        assert!(w * h * t.texture.kind.faces() <= limits.max_pixels);
                    }
                }
            }
        }
    }
    // Sizes over the limits are refused before allocating, naming the limit.
    let tex = texture(TextureKind::Flat, 4, 3);
    let mut b = ktx2::encode(&tex, TexelFormat::Rgba16Float).unwrap();
    b[20..24].copy_from_slice(&100_000u32.to_le_bytes());
    assert!(matches!(
        ktx2::decode(&b, &Limits::default()),
        Err(ibl_io::DecodeError::Limits(_))
    ));
    let mut b = dds::encode(&tex, TexelFormat::Rgba16Float).unwrap();
    b[16..20].copy_from_slice(&100_000u32.to_le_bytes());
    assert!(dds::decode(&b, &Limits::default()).is_err());
    // Block compression is named as unsupported.
    let mut b = ktx2::encode(&tex, TexelFormat::Rgba16Float).unwrap();
    b[12..16].copy_from_slice(&143u32.to_le_bytes());
    let e = ktx2::decode(&b, &Limits::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("BC6H"), "{e}");
}
