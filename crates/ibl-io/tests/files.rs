//! File-level behaviour: every format written with `write_image` reads back with `read_image`,
//! writes are atomic and never land on an input, errors name the file and are classified for
//! the CLI's exit status, and PNG/JPEG input (8/16-bit, grey/RGB/RGBA) is decoded to linear.

mod common;

use std::path::Path;

use common::{bits, hdr_test_image, max_rel_error};
use ibl_core::tonemap::{Display, ToneCurve, srgb_to_linear};
use ibl_core::{Image, Rgb};
use ibl_io::{
    ExrOptions, ExrPrecision, ImageFormat, IoError, WriteOptions, ensure_output_is_not_input,
    read_image, write_image,
};

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn every_format_round_trips_through_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut img = hdr_test_image(64, 32, 4);
    // Include a NaN and a negative: they must come back clamped and counted where the format
    // keeps them (EXR float, PFM) and be written as 0 where it cannot (RGBE).
    *img.get_mut(0, 0) = Rgb::new(f32::NAN, -2.0, 1.0);
    let options = WriteOptions::default();
    for name in [
        "a.hdr", "a.exr", "a.pfm", "a.png", "a.jpg", "b.PIC", "c.jpeg",
    ] {
        let path = dir.path().join(name);
        write_image(&path, &img, &options).expect("writes");
        let loaded = read_image(&path).expect("reads");
        let format = ImageFormat::from_path(&path).expect("known extension");
        assert_eq!(loaded.format, format);
        assert_eq!((loaded.image.width(), loaded.image.height()), (64, 32));
        assert!(
            loaded.image.pixels().iter().all(|p| p.is_valid_radiance()),
            "{name}"
        );
        let (nonfinite, negative) = (
            loaded.report.nonfinite_values,
            loaded.report.negative_values,
        );
        match format {
            ImageFormat::Exr | ImageFormat::Pfm => {
                assert_eq!((nonfinite, negative), (1, 1), "{name}")
            }
            _ => assert_eq!((nonfinite, negative), (0, 0), "{name}"),
        }
        println!(
            "{name}: {} ({} bytes)",
            loaded.details,
            std::fs::metadata(&path).expect("meta").len()
        );
    }
    assert!(leftovers(dir.path()).is_empty());

    // EXR float and PFM are bit-exact once the two invalid values are sanitised.
    let mut clean = img.clone();
    ibl_io::sanitize(&mut clean);
    for name in ["a.exr", "a.pfm"] {
        assert_eq!(
            bits(&read_image(&dir.path().join(name)).expect("reads").image),
            bits(&clean),
            "{name}"
        );
    }
    let hdr = read_image(&dir.path().join("a.hdr")).expect("reads").image;
    assert!(max_rel_error(&clean, &hdr) <= 1.0 / 256.0 * (1.0 + 1e-6));

    // Half EXR through the options.
    let half = WriteOptions {
        exr: ExrOptions {
            precision: ExrPrecision::Half,
            ..ExrOptions::default()
        },
        ..options
    };
    write_image(&dir.path().join("h.exr"), &clean, &half).expect("writes");
    assert_eq!(
        read_image(&dir.path().join("h.exr"))
            .expect("reads")
            .details,
        "OpenEXR, ZIP, half"
    );
}

#[test]
fn png_output_uses_the_display_transform() {
    let dir = tempfile::tempdir().expect("tempdir");
    let img = Image::from_vec(
        3,
        1,
        vec![Rgb::splat(1.0), Rgb::splat(0.5), Rgb::splat(4.0)],
    )
    .expect("3 px");
    let path = dir.path().join("p.png");
    let clamp = WriteOptions {
        display: Display {
            exposure_stops: 0.0,
            curve: ToneCurve::Clamp,
        },
        ..WriteOptions::default()
    };
    write_image(&path, &img, &clamp).expect("writes");
    let back = read_image(&path).expect("reads").image;
    // 1.0 -> 255 -> 1.0; 0.5 -> 188 -> 0.5029; 4.0 clipped to 1.0.
    assert_eq!(back.get(0, 0).r, 1.0);
    assert!((back.get(1, 0).g - srgb_to_linear(188.0 / 255.0)).abs() < 1e-6);
    assert_eq!(back.get(2, 0).b, 1.0);
    let darker = WriteOptions {
        display: Display {
            exposure_stops: -2.0,
            curve: ToneCurve::Clamp,
        },
        ..WriteOptions::default()
    };
    write_image(&path, &img, &darker).expect("overwrites");
    let back = read_image(&path).expect("reads").image;
    // Clamp at exposure -2: 4.0 maps to code 255, whose sRGB decoding is 1 to f32 rounding (1e-6);
    // 1.0 maps to 0.25 exposed, whose 8-bit code decodes just under 0.26 (one 8-bit step there is
    // 0.005).
    assert!((back.get(2, 0).r - 1.0).abs() < 1e-6 && back.get(0, 0).r < 0.26);
}

#[test]
fn png_input_variants_decode_to_linear() {
    use image::{ImageBuffer, Luma, LumaA, Rgb as IRgb, Rgba};
    let dir = tempfile::tempdir().expect("tempdir");
    let p = |n: &str| dir.path().join(n);
    ImageBuffer::<IRgb<u16>, _>::from_fn(4, 2, |x, y| {
        IRgb([x as u16 * 20000, y as u16 * 65535, 32768])
    })
    .save(p("rgb16.png"))
    .expect("saves");
    ImageBuffer::<Luma<u8>, _>::from_fn(4, 2, |x, _| Luma([x as u8 * 80]))
        .save(p("grey8.png"))
        .expect("saves");
    ImageBuffer::<LumaA<u16>, _>::from_fn(4, 2, |_, _| LumaA([65535, 0]))
        .save(p("greya16.png"))
        .expect("saves");
    ImageBuffer::<Rgba<u8>, _>::from_fn(4, 2, |_, _| Rgba([255, 128, 0, 10]))
        .save(p("rgba8.png"))
        .expect("saves");

    let rgb16 = read_image(&p("rgb16.png")).expect("reads");
    assert!(rgb16.details.contains("16-bit RGB"), "{}", rgb16.details);
    let px = rgb16.image.get(3, 1);
    // 16-bit codes decode through the exact sRGB EOTF in f32: equal to rounding (1e-7); 1e-6 is 16
    // ulps.
    assert!((px.r - srgb_to_linear(60000.0 / 65535.0)).abs() < 1e-6 && px.g == 1.0);
    // As above: the exact EOTF of 32768/65535, to f32 rounding.
    assert!((px.b - srgb_to_linear(32768.0 / 65535.0)).abs() < 1e-6);
    let grey = read_image(&p("grey8.png")).expect("reads");
    assert_eq!(
        *grey.image.get(2, 0),
        Rgb::splat(srgb_to_linear(160.0 / 255.0))
    );
    assert_eq!(
        *read_image(&p("greya16.png"))
            .expect("reads")
            .image
            .get(0, 0),
        Rgb::ONE
    );
    let rgba = read_image(&p("rgba8.png")).expect("reads");
    assert!(rgba.details.contains("8-bit RGBA"));
    assert_eq!(rgba.image.get(1, 1).b, 0.0);
}

#[test]
fn output_never_overwrites_an_input() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = dir.path().join("in.hdr");
    write_image(&input, &hdr_test_image(8, 4, 1), &WriteOptions::default()).expect("writes");
    let same =
        |out: &Path| ensure_output_is_not_input(out, &[Path::new("/nonexistent/x.exr"), &input]);
    assert!(matches!(same(&input), Err(IoError::SameAsInput { .. })));
    std::fs::create_dir(dir.path().join("sub")).expect("mkdir");
    assert!(matches!(
        same(&dir.path().join("sub/../in.hdr")),
        Err(IoError::SameAsInput { .. })
    ));
    assert!(matches!(
        same(&dir.path().join(".").join("in.hdr")),
        Err(IoError::SameAsInput { .. })
    ));
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&input, dir.path().join("link.hdr")).expect("symlink");
        assert!(matches!(
            same(&dir.path().join("link.hdr")),
            Err(IoError::SameAsInput { .. })
        ));
        std::fs::hard_link(&input, dir.path().join("hard.hdr")).expect("hard link");
        assert!(matches!(
            same(&dir.path().join("hard.hdr")),
            Err(IoError::SameAsInput { .. })
        ));
    }
    assert!(same(&dir.path().join("out.hdr")).is_ok());
    assert!(same(&dir.path().join("in.exr")).is_ok());
    let err = IoError::SameAsInput {
        path: input.clone(),
    };
    assert!(err.is_bad_input() && err.to_string().contains("in.hdr"));
}

#[test]
fn errors_name_the_file_and_are_classified() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("missing.exr");
    let err = read_image(&missing).expect_err("missing");
    assert!(
        matches!(&err, IoError::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
    );
    assert!(
        err.is_bad_input() && err.to_string().contains("missing.exr"),
        "{err}"
    );

    let err = read_image(&dir.path().join("image.tiff")).expect_err("unknown extension");
    assert!(matches!(err, IoError::Unsupported { .. }) && err.is_bad_input());

    let img = hdr_test_image(4, 4, 1);
    let err = write_image(
        &dir.path().join("no/such/dir/out.exr"),
        &img,
        &WriteOptions::default(),
    )
    .expect_err("no directory");
    // The user's path: bad input (exit 2), issue 13.
    assert!(
        matches!(err, IoError::Io { .. }) && err.is_bad_input(),
        "{err}"
    );
    assert!(
        err.to_string().contains("out.exr") && err.to_string().contains("cannot write"),
        "{err}"
    );

    let empty = Image::from_vec(0, 0, Vec::<Rgb>::new()).expect("empty");
    let err = write_image(&dir.path().join("e.hdr"), &empty, &WriteOptions::default())
        .expect_err("empty");
    assert!(!err.is_bad_input());
    assert!(!dir.path().join("e.hdr").exists() && leftovers(dir.path()).is_empty());

    // A failed write leaves the previous file intact.
    let target = dir.path().join("keep.pfm");
    write_image(&target, &img, &WriteOptions::default()).expect("writes");
    let before = std::fs::read(&target).expect("reads");
    assert!(
        write_image(
            &target.with_extension("xyz"),
            &img,
            &WriteOptions::default()
        )
        .is_err()
    );
    assert_eq!(std::fs::read(&target).expect("reads"), before);
}
