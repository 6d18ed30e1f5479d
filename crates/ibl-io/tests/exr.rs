//! OpenEXR: bit-exact float round trips for every written compression, half precision, and
//! reading of files the `exr` crate writes with other channel layouts (grey Y, RGBA, uint,
//! prefixed layers, several parts, data window inside a larger display window, tiles,
//! decreasing line order).

mod common;

use ::exr::prelude as x;
use ::exr::prelude::{SmallVec, WritableImage, f16};
use common::{awkward_floats, bits, hdr_test_image, max_rel_error};
use ibl_core::Rgb;
use ibl_io::exr::{ExrCompression, ExrOptions, ExrPrecision};
use ibl_io::{DecodeError, Limits, exr};

const ALL: [ExrCompression; 5] = [
    ExrCompression::None,
    ExrCompression::Rle,
    ExrCompression::Zips,
    ExrCompression::Zip,
    ExrCompression::Piz,
];

#[test]
fn float_round_trips_bit_exactly_with_every_compression() {
    let img = awkward_floats(37, 21);
    for compression in ALL {
        let options = ExrOptions {
            precision: ExrPrecision::Float,
            compression,
        };
        let bytes = exr::encode(&img, &options).expect("encodes");
        let raw = exr::decode(&bytes, &Limits::default()).expect("decodes");
        assert_eq!(bits(&raw.image), bits(&img), "{compression:?}");
        assert!(raw.details.ends_with(", float"), "{}", raw.details);
    }
    assert_eq!(ExrOptions::default().compression, ExrCompression::Zip);
    assert_eq!(ExrOptions::default().precision, ExrPrecision::Float);
    let raw = exr::decode(
        &exr::encode(&img, &ExrOptions::default()).expect("encodes"),
        &Limits::default(),
    );
    assert_eq!(raw.expect("decodes").details, "OpenEXR, ZIP, float");
}

#[test]
fn half_round_trip_within_half_precision() {
    // Half has a 10-bit mantissa: rounding to nearest errs by at most 2^-11 relative, for
    // normal values (>= 6.1e-5). The test image spans 1e-3 .. 1e4.
    let img = hdr_test_image(50, 20, 5);
    for compression in ALL {
        let options = ExrOptions {
            precision: ExrPrecision::Half,
            compression,
        };
        let raw = exr::decode(
            &exr::encode(&img, &options).expect("encodes"),
            &Limits::default(),
        )
        .expect("decodes");
        assert!(raw.details.ends_with(", half"), "{}", raw.details);
        for (p, q) in img.pixels().iter().zip(raw.image.pixels()) {
            for (a, b) in [(p.r, q.r), (p.g, q.g), (p.b, q.b)] {
                // Half floats keep 11 significant bits: round to nearest is within half an ulp,
                // 2^-11 relative.
                assert!(
                    (a - b).abs() <= a * (1.0 / 2048.0),
                    "{compression:?}: {a} -> {b}"
                );
            }
        }
        assert!(max_rel_error(&img, &raw.image) <= 1.0 / 2048.0);
    }
    // Out-of-range values clamp to the largest half instead of becoming infinite.
    let big = ibl_core::Image::filled(2, 2, Rgb::new(1e6, -1e6, 70000.0));
    let opts = ExrOptions {
        precision: ExrPrecision::Half,
        ..ExrOptions::default()
    };
    let raw = exr::decode(
        &exr::encode(&big, &opts).expect("encodes"),
        &Limits::default(),
    )
    .expect("decodes");
    assert_eq!(*raw.image.get(1, 1), Rgb::new(65504.0, -65504.0, 65504.0));
}

fn write(image: x::Image<x::Layers<x::AnyChannels<x::FlatSamples>>>) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut out).expect("exr writes");
    out.into_inner()
}

fn layer(
    size: (usize, usize),
    name: Option<&str>,
    channels: Vec<(&str, x::FlatSamples)>,
    encoding: x::Encoding,
) -> x::Layer<x::AnyChannels<x::FlatSamples>> {
    let list = channels
        .into_iter()
        .map(|(n, s)| x::AnyChannel::new(n, s))
        .collect();
    let attributes = match name {
        Some(n) => x::LayerAttributes::named(n),
        None => x::LayerAttributes::default(),
    };
    x::Layer::new(
        size,
        attributes,
        encoding,
        x::AnyChannels::sort(SmallVec::from_vec(list)),
    )
}

fn single(l: x::Layer<x::AnyChannels<x::FlatSamples>>) -> Vec<u8> {
    let bounds = x::IntegerBounds::new(l.attributes.layer_position, l.size);
    write(x::Image::from_layers(
        x::ImageAttributes::new(bounds),
        vec![l],
    ))
}

fn ramp(n: usize, scale: f32) -> Vec<f32> {
    (0..n).map(|i| i as f32 * scale).collect()
}

fn decode(bytes: &[u8]) -> ibl_io::RawImage {
    exr::decode(bytes, &Limits::default()).expect("decodes")
}

#[test]
fn grey_y_channel_becomes_equal_rgb() {
    let y: Vec<f16> = ramp(12, 0.5).into_iter().map(f16::from_f32).collect();
    let raw = decode(&single(layer(
        (4, 3),
        None,
        vec![("Y", x::FlatSamples::F16(y))],
        x::Encoding::FAST_LOSSLESS,
    )));
    assert_eq!(raw.details, "OpenEXR, RLE, half, grey from Y");
    assert_eq!(*raw.image.get(3, 2), Rgb::splat(5.5));
}

#[test]
fn rgba_and_uint_channels() {
    let n = 6 * 2;
    let rgba = vec![
        ("R", x::FlatSamples::F32(ramp(n, 1.0))),
        ("G", x::FlatSamples::F32(ramp(n, 2.0))),
        ("B", x::FlatSamples::F32(ramp(n, 3.0))),
        ("A", x::FlatSamples::F32(vec![0.5; n])),
    ];
    let raw = decode(&single(layer(
        (6, 2),
        None,
        rgba,
        x::Encoding::SMALL_LOSSLESS,
    )));
    assert_eq!(*raw.image.get(5, 1), Rgb::new(11.0, 22.0, 33.0));
    let uint = vec![
        ("R", x::FlatSamples::U32((0..n as u32).collect())),
        ("G", x::FlatSamples::U32(vec![7; n])),
        ("B", x::FlatSamples::U32(vec![1 << 20; n])),
    ];
    let raw = decode(&single(layer(
        (6, 2),
        None,
        uint,
        x::Encoding::UNCOMPRESSED,
    )));
    assert_eq!(raw.details, "OpenEXR, NONE, uint");
    assert_eq!(*raw.image.get(4, 1), Rgb::new(10.0, 7.0, 1048576.0));
}

#[test]
fn prefixed_layer_and_second_part_are_found() {
    let n = 4;
    let prefixed = vec![
        ("Z", x::FlatSamples::F32(vec![9.0; n])),
        ("diffuse.B", x::FlatSamples::F32(vec![3.0; n])),
        (
            "diffuse.G",
            x::FlatSamples::F16(vec![f16::from_f32(2.0); n]),
        ),
        ("diffuse.R", x::FlatSamples::F32(vec![1.0; n])),
    ];
    let raw = decode(&single(layer(
        (2, 2),
        None,
        prefixed,
        x::Encoding::SMALL_LOSSLESS,
    )));
    assert_eq!(*raw.image.get(1, 1), Rgb::new(1.0, 2.0, 3.0));
    assert!(
        raw.details.contains("mixed") && raw.details.contains("layer \"diffuse\""),
        "{}",
        raw.details
    );

    // Part 0 has only depth, part 1 is the colour image: part 1 is read.
    let depth = layer(
        (2, 2),
        Some("depth"),
        vec![("Z", x::FlatSamples::F32(vec![5.0; n]))],
        x::Encoding::SMALL_LOSSLESS,
    );
    let colour = layer(
        (2, 2),
        Some("colour"),
        vec![
            ("R", x::FlatSamples::F32(vec![4.0; n])),
            ("G", x::FlatSamples::F32(vec![5.0; n])),
            ("B", x::FlatSamples::F32(vec![6.0; n])),
        ],
        x::Encoding::SMALL_LOSSLESS,
    );
    let bytes = write(x::Image::from_layers(
        x::ImageAttributes::new(x::IntegerBounds::from_dimensions((2, 2))),
        vec![depth, colour],
    ));
    let raw = decode(&bytes);
    assert_eq!(*raw.image.get(0, 0), Rgb::new(4.0, 5.0, 6.0));
    assert!(raw.details.contains("part 2 of 2"), "{}", raw.details);
}

#[test]
fn data_window_is_placed_in_the_display_window() {
    let mut l = layer(
        (3, 2),
        None,
        vec![
            ("R", x::FlatSamples::F32(ramp(6, 1.0))),
            ("G", x::FlatSamples::F32(vec![1.0; 6])),
            ("B", x::FlatSamples::F32(vec![1.0; 6])),
        ],
        x::Encoding::SMALL_LOSSLESS,
    );
    l.attributes.layer_position = x::Vec2(2, 1);
    // Display window (0,0)-(5,3): 6 x 4.
    let bytes = write(x::Image::from_layers(
        x::ImageAttributes::new(x::IntegerBounds::from_dimensions((6, 4))),
        vec![l],
    ));
    let raw = decode(&bytes);
    assert_eq!((raw.image.width(), raw.image.height()), (6, 4));
    assert_eq!(*raw.image.get(2, 1), Rgb::new(0.0, 1.0, 1.0));
    assert_eq!(*raw.image.get(4, 2), Rgb::new(5.0, 1.0, 1.0));
    assert_eq!(*raw.image.get(0, 0), Rgb::ZERO);
    assert_eq!(*raw.image.get(5, 3), Rgb::ZERO);
    assert!(
        raw.details.contains("data window (2, 1)-(4, 2)"),
        "{}",
        raw.details
    );
}

#[test]
fn tiles_and_decreasing_line_order() {
    let img = hdr_test_image(45, 30, 8);
    let samples = |f: fn(&Rgb) -> f32| x::FlatSamples::F32(img.pixels().iter().map(f).collect());
    let channels = || {
        vec![
            ("R", samples(|p| p.r)),
            ("G", samples(|p| p.g)),
            ("B", samples(|p| p.b)),
        ]
    };
    let tiled = x::Encoding {
        compression: x::Compression::ZIP16,
        blocks: x::Blocks::Tiles(x::Vec2(16, 8)),
        line_order: x::LineOrder::Increasing,
    };
    let decreasing = x::Encoding {
        line_order: x::LineOrder::Decreasing,
        ..x::Encoding::SMALL_LOSSLESS
    };
    for encoding in [tiled, decreasing] {
        let raw = decode(&single(layer((45, 30), None, channels(), encoding)));
        assert_eq!(bits(&raw.image), bits(&img), "{encoding:?}");
    }
}

#[test]
fn luminance_chroma_and_empty_images_are_refused() {
    let n = 4;
    let yc = vec![
        ("Y", x::FlatSamples::F16(vec![f16::ONE; n])),
        ("RY", x::FlatSamples::F16(vec![f16::ZERO; n])),
        ("BY", x::FlatSamples::F16(vec![f16::ZERO; n])),
    ];
    let bytes = single(layer((2, 2), None, yc, x::Encoding::SMALL_LOSSLESS));
    let err = exr::decode(&bytes, &Limits::default()).expect_err("chroma is unsupported");
    assert!(
        matches!(&err, DecodeError::Unsupported(m) if m.contains("RY")),
        "{err}"
    );
    let empty = ibl_core::Image::from_vec(0, 0, Vec::<Rgb>::new()).expect("empty");
    assert!(exr::encode(&empty, &ExrOptions::default()).is_err());
    // Limits apply to the data window before exr allocates.
    let img = hdr_test_image(40, 10, 2);
    let bytes = exr::encode(&img, &ExrOptions::default()).expect("encodes");
    let tight = Limits {
        max_height: 9,
        ..Limits::default()
    };
    assert!(matches!(
        exr::decode(&bytes, &tight),
        Err(DecodeError::Limits(_))
    ));
    for n in (0..bytes.len()).step_by(13) {
        assert!(
            exr::decode(&bytes[..n], &Limits::default()).is_err(),
            "prefix {n}"
        );
    }
}

/// An R-only file (a mask, one channel of a render) is refused by what it lacks: the message
/// names the missing channels and lists the ones it has (issue 13, hostile 8: it used to say
/// "without R, G, B or Y channels (channels: R)").
#[test]
fn an_r_only_file_is_refused_naming_what_is_missing() {
    let r = vec![("R", x::FlatSamples::F32(vec![1.0; 4]))];
    let bytes = single(layer((2, 2), None, r, x::Encoding::SMALL_LOSSLESS));
    let err = exr::decode(&bytes, &Limits::default()).expect_err("one channel is not colour");
    let DecodeError::Unsupported(m) = &err else {
        panic!("{err}")
    };
    assert!(
        m.contains("missing G, B") && m.contains("its channels: R"),
        "{m}"
    );
}

/// The lossy and lossless-for-half compressions only the `exr` crate writes (PXR24, B44, B44A,
/// DWAA, DWAB) are read by our decoder exactly as the crate's own reader reads them: the
/// compressions are lossy on writing, so the reference is the crate's decoding, not the input.
#[test]
fn dwa_b44_pxr24_match_the_exr_crates_own_reader() {
    let img = hdr_test_image(67, 41, 9);
    let half = |f: fn(&Rgb) -> f32| {
        x::FlatSamples::F16(img.pixels().iter().map(|p| f16::from_f32(f(p))).collect())
    };
    let compressions = [
        ("PXR24", x::Compression::PXR24),
        ("B44", x::Compression::B44),
        ("B44A", x::Compression::B44A),
        ("DWAA", x::Compression::DWAA(None)),
        ("DWAB", x::Compression::DWAB(None)),
    ];
    for (name, compression) in compressions {
        let encoding = x::Encoding {
            compression,
            ..x::Encoding::SMALL_LOSSLESS
        };
        let channels = vec![
            ("R", half(|p| p.r)),
            ("G", half(|p| p.g)),
            ("B", half(|p| p.b)),
        ];
        let bytes = single(layer((67, 41), None, channels, encoding));
        let ours = decode(&bytes);
        assert!(ours.details.contains(name), "{name}: {}", ours.details);
        let reference = reference_reader::read_first_rgba_layer_from_file_bytes(&bytes);
        for (i, p) in ours.image.pixels().iter().enumerate() {
            let r = reference[i];
            assert_eq!(
                [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()],
                [r[0].to_bits(), r[1].to_bits(), r[2].to_bits()],
                "{name}: pixel {i}"
            );
        }
    }
}

mod reference_reader {
    //! The `exr` crate's own RGBA reader over an in-memory file, as the reference decoding.
    use ::exr::prelude::*;

    /// Reads the first RGB(A) layer as f32 triples, row 0 at the top.
    pub fn read_first_rgba_layer_from_file_bytes(bytes: &[u8]) -> Vec<[f32; 3]> {
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |size, _| (size.0, vec![[0.0f32; 3]; size.0 * size.1]),
                |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    px[pos.1 * *w + pos.0] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(std::io::Cursor::new(bytes.to_vec()))
            .expect("the exr crate reads its own file");
        image.layer_data.channel_data.pixels.1
    }
}
