//! Byte-level round trips and hand-made files for Radiance HDR and PFM: RLE and flat `.hdr`
//! within RGBE precision, old-style RLE, `EXPOSURE=`, all eight orientations, and bit-exact PFM
//! in both byte orders, RGB and grey.

mod common;

use common::{awkward_floats, bits, hdr_test_image, max_rel_error};
use ibl_core::{Image, Rgb};
use ibl_io::{DecodeError, Limits, hdr, pfm};

/// RGBE keeps 8 mantissa bits for the largest channel; Radiance's decoder centres the truncation
/// interval, so the error is at most half a unit: 2^-8 of the pixel's largest channel.
const RGBE_TOLERANCE: f32 = 1.0 / 256.0 * (1.0 + 1e-6);

fn decode_hdr(bytes: &[u8]) -> ibl_io::RawImage {
    hdr::decode(bytes, &Limits::default()).expect("decodes")
}

#[test]
fn hdr_rle_round_trip_within_rgbe_precision() {
    for (w, h) in [(67, 13), (8, 3), (300, 2), (32767, 1)] {
        let img = hdr_test_image(w, h, w as u64);
        let bytes = hdr::encode(&img);
        let raw = decode_hdr(&bytes);
        assert_eq!(raw.details, "Radiance RGBE, RLE", "{w}x{h}");
        let err = max_rel_error(&img, &raw.image);
        assert!(err <= RGBE_TOLERANCE, "{w}x{h}: relative error {err}");
        // Re-encoding the decoded image reproduces the same bytes.
        assert_eq!(hdr::encode(&raw.image), bytes, "{w}x{h}");
    }
}

#[test]
fn hdr_flat_round_trip_and_rle_is_smaller() {
    for (w, h) in [(67, 13), (3, 4), (40000, 1)] {
        let img = hdr_test_image(w, h, 99);
        let flat = hdr::encode_flat(&img);
        let raw = decode_hdr(&flat);
        assert_eq!(raw.details, "Radiance RGBE, flat");
        assert!(max_rel_error(&img, &raw.image) <= RGBE_TOLERANCE);
        // Widths outside 8..=32767 cannot be RLE: `encode` falls back to flat.
        let rle = hdr::encode(&img);
        if (8..=32767).contains(&w) {
            assert!(rle.len() < flat.len(), "{} vs {}", rle.len(), flat.len());
        } else {
            assert_eq!(rle, flat);
        }
    }
    let black = Image::filled(512, 256, Rgb::ZERO);
    assert!(hdr::encode(&black).len() < 30_000);
}

#[test]
fn hdr_old_style_rle_decodes() {
    // Two scanlines of 300 pixels (a width new-style RLE could use, but these scanlines do not
    // start with 2, 2: old style). A repeat pixel (1, 1, 1, n) repeats the previous pixel
    // n << shift times; consecutive repeats shift by 8 more each.
    let a = [128, 64, 32, 130]; // (2.0, 1.0, 0.5) roughly
    let b = [200, 10, 10, 128];
    let c = [10, 10, 200, 127];
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 300\n".to_vec();
    for px in [a, [1, 1, 1, 43], [1, 1, 1, 1]] {
        bytes.extend_from_slice(&px); // a x (1 + 43 + (1 << 8)) = 300
    }
    for px in [b, [1, 1, 1, 10], c, [1, 1, 1, 32], [1, 1, 1, 1]] {
        bytes.extend_from_slice(&px); // b x 11, c x (1 + 32 + 256) = 289
    }
    let raw = decode_hdr(&bytes);
    assert_eq!(raw.details, "Radiance RGBE, old-style RLE");
    let img = raw.image;
    let rgb = |p: [u8; 4]| {
        let f = 2f32.powi(p[3] as i32 - 136);
        Rgb::new(
            (p[0] as f32 + 0.5) * f,
            (p[1] as f32 + 0.5) * f,
            (p[2] as f32 + 0.5) * f,
        )
    };
    assert!(img.row(0).iter().all(|&p| p == rgb(a)));
    assert!(img.row(1)[..11].iter().all(|&p| p == rgb(b)));
    assert!(img.row(1)[11..].iter().all(|&p| p == rgb(c)));

    // A run at the start of a scanline continues the previous scanline's last pixel.
    let mut bytes = b"#?RADIANCE\n\n-Y 2 +X 3\n".to_vec();
    for px in [a, b, c, [1, 1, 1, 3]] {
        bytes.extend_from_slice(&px);
    }
    let img = decode_hdr(&bytes).image;
    assert_eq!(img.row(1), &[rgb(c); 3]);
}

#[test]
fn hdr_exposure_and_colorcorr_divide_pixel_values() {
    let img = hdr_test_image(40, 6, 3);
    let plain = decode_hdr(&hdr::encode(&img)).image;
    let bytes = hdr::encode(&img);
    let header_end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .expect("blank line")
        + 1;
    let with = |lines: &str| {
        let mut b = bytes[..header_end].to_vec();
        b.extend_from_slice(lines.as_bytes());
        b.extend_from_slice(&bytes[header_end..]);
        decode_hdr(&b)
    };
    let raw = with("EXPOSURE=2\nEXPOSURE=4.0\n");
    assert!(raw.details.contains("EXPOSURE 8"), "{}", raw.details);
    for (p, q) in plain.pixels().iter().zip(raw.image.pixels()) {
        assert_eq!(*q, *p * 0.125);
    }
    let raw = with("COLORCORR=1 2 4\nEXPOSURE=0.5\n");
    for (p, q) in plain.pixels().iter().zip(raw.image.pixels()) {
        let expect = Rgb::new(p.r * 2.0, p.g, p.b * 0.5);
        // COLORCORR and EXPOSURE scale channels by powers of two and f32 divisions: equal to one
        // f32 rounding (6e-8 relative); 1e-6.
        assert!(
            (q.r - expect.r).abs() <= 1e-6 * expect.r && q.g == expect.g,
            "{q:?} {expect:?}"
        );
    }
}

/// Writes `img` (already RGBE-exact) as flat pixels in the order a resolution string describes.
fn write_oriented(img: &Image<[u8; 4]>, res: &str) -> Vec<u8> {
    let (w, h) = (img.width(), img.height());
    let t: Vec<&str> = res.split(' ').collect();
    let transposed = t[0].ends_with('X');
    let (ys, xs) = if transposed {
        (t[2], t[0])
    } else {
        (t[0], t[2])
    };
    let rows: Vec<usize> = if ys.starts_with('-') {
        (0..h).collect()
    } else {
        (0..h).rev().collect()
    };
    let cols: Vec<usize> = if xs.starts_with('+') {
        (0..w).collect()
    } else {
        (0..w).rev().collect()
    };
    let mut out = format!("#?RADIANCE\n\n{res}\n").into_bytes();
    if transposed {
        for &x in &cols {
            for &y in &rows {
                out.extend_from_slice(img.get(x, y));
            }
        }
    } else {
        for &y in &rows {
            for &x in &cols {
                out.extend_from_slice(img.get(x, y));
            }
        }
    }
    out
}

#[test]
fn hdr_all_eight_orientations_give_row_zero_at_top() {
    let (w, h) = (5, 3);
    let rgbe = Image::from_fn_par(w, h, |x, y| {
        [128 + (x * 20) as u8, 128 + (y * 40) as u8, 200, 129]
    });
    let reference = decode_hdr(&write_oriented(&rgbe, &format!("-Y {h} +X {w}"))).image;
    // Pixel (x, y) really is the one we put there.
    assert_eq!(reference.get(4, 0).r, (128.0 + 80.0 + 0.5) / 128.0);
    assert_eq!(reference.get(0, 2).g, (128.0 + 80.0 + 0.5) / 128.0);
    for res in [
        format!("+Y {h} +X {w}"),
        format!("-Y {h} -X {w}"),
        format!("+Y {h} -X {w}"),
        format!("+X {w} -Y {h}"),
        format!("-X {w} -Y {h}"),
        format!("+X {w} +Y {h}"),
        format!("-X {w} +Y {h}"),
    ] {
        let raw = decode_hdr(&write_oriented(&rgbe, &res));
        assert_eq!(raw.image, reference, "{res}");
        assert!(raw.details.contains(&res), "{}", raw.details);
    }
}

#[test]
fn hdr_bottom_up_rle_file() {
    let img = hdr_test_image(64, 9, 11);
    let standard = hdr::encode(&img);
    // Same scanlines in reverse order under "+Y 9 +X 64".
    let header = b"#?RADIANCE\nSOFTWARE=iblkit\nFORMAT=32-bit_rle_rgbe\n\n-Y 9 +X 64\n";
    assert!(standard.starts_with(header));
    let pixel_data = |b: &[u8]| {
        let blank = b.windows(2).position(|w| w == b"\n\n").expect("blank line") + 2;
        let res_end = blank
            + b[blank..]
                .iter()
                .position(|&c| c == b'\n')
                .expect("newline")
            + 1;
        b[res_end..].to_vec()
    };
    let lines: Vec<Vec<u8>> = (0..9)
        .map(|y| {
            pixel_data(&hdr::encode(
                &Image::from_vec(64, 1, img.row(y).to_vec()).expect("row"),
            ))
        })
        .collect();
    assert_eq!(lines.concat(), pixel_data(&standard));
    let mut bottom_up =
        b"#?RADIANCE\nSOFTWARE=iblkit\nFORMAT=32-bit_rle_rgbe\n\n+Y 9 +X 64\n".to_vec();
    for line in lines.iter().rev() {
        bottom_up.extend_from_slice(line);
    }
    assert_eq!(decode_hdr(&bottom_up).image, decode_hdr(&standard).image);
}

#[test]
fn hdr_checks_sizes_before_allocating() {
    let img = hdr_test_image(64, 4, 1);
    let bytes = hdr::encode(&img);
    let tight = Limits {
        max_width: 63,
        ..Limits::default()
    };
    assert!(matches!(
        hdr::decode(&bytes, &tight),
        Err(DecodeError::Limits(_))
    ));
    let few = Limits {
        max_pixels: 255,
        ..Limits::default()
    };
    assert!(matches!(
        hdr::decode(&bytes, &few),
        Err(DecodeError::Limits(_))
    ));
    // Every strict prefix fails cleanly.
    for n in (0..bytes.len()).step_by(7) {
        assert!(
            hdr::decode(&bytes[..n], &Limits::default()).is_err(),
            "prefix {n}"
        );
    }
}

#[test]
fn pfm_round_trips_bit_exactly() {
    for order in [pfm::ByteOrder::LittleEndian, pfm::ByteOrder::BigEndian] {
        for (w, h) in [(1, 1), (7, 5), (64, 33)] {
            let img = awkward_floats(w, h);
            let bytes = pfm::encode(&img, order);
            let scale = if order == pfm::ByteOrder::LittleEndian {
                "-1.0"
            } else {
                "1.0"
            };
            assert_eq!(
                bytes.len(),
                format!("PF\n{w} {h}\n{scale}\n").len() + w * h * 12
            );
            let raw = pfm::decode(&bytes, &Limits::default()).expect("decodes");
            assert_eq!(bits(&raw.image), bits(&img), "{order:?} {w}x{h}");
        }
        let grey = Image::from_fn_par(9, 4, |x, y| {
            [f32::NAN, -0.0, 1e-40, -7.25][(x + y) % 4] * (x as f32 + 1.0)
        });
        let bytes = pfm::encode_grey(&grey, order);
        let raw = pfm::decode(&bytes, &Limits::default()).expect("decodes");
        assert!(raw.details.starts_with("PFM, grey"));
        for (p, &g) in raw.image.pixels().iter().zip(grey.pixels()) {
            assert_eq!(
                [p.r.to_bits(), p.g.to_bits(), p.b.to_bits()],
                [g.to_bits(); 3]
            );
        }
    }
}

#[test]
fn pfm_rows_are_stored_bottom_up() {
    let img = Image::from_fn_par(2, 3, |x, y| Rgb::splat((10 * y + x) as f32));
    let bytes = pfm::encode(&img, pfm::ByteOrder::LittleEndian);
    let data = &bytes[bytes.len() - 2 * 3 * 12..];
    // The first stored float is the bottom-left pixel, (0, 2) = 20.
    assert_eq!(
        f32::from_le_bytes([data[0], data[1], data[2], data[3]]),
        20.0
    );
    for n in 0..bytes.len() {
        assert!(
            pfm::decode(&bytes[..n], &Limits::default()).is_err(),
            "prefix {n}"
        );
    }
}
