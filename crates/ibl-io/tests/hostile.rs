//! The hostile-input corpus in `tests/hostile/` (repository root): every file either fails with
//! the error kind its README line names, or (for the NaN/Inf ones) loads with the counts named.
//! Nothing may panic. The README is the single list: every file must be listed and exist.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use ibl_io::{IoError, read_image};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/hostile")
}

/// One README line: `name | error|loads | [tag] what`.
struct Case {
    name: String,
    loads: bool,
    tag: String,
}

fn cases() -> Vec<Case> {
    let readme = std::fs::read_to_string(corpus_dir().join("README.md")).expect("README.md");
    readme
        .lines()
        .filter_map(|line| {
            let fields: Vec<&str> = line.split('|').map(str::trim).collect();
            let [name, outcome, what] = fields[..] else {
                return None;
            };
            if !(outcome == "error" || outcome == "loads") || name.contains(' ') {
                return None;
            }
            let tag = what.strip_prefix('[')?.split(']').next()?.to_owned();
            Some(Case {
                name: name.to_owned(),
                loads: outcome == "loads",
                tag,
            })
        })
        .collect()
}

fn kind(e: &IoError) -> &'static str {
    match e {
        IoError::Io { .. } => "Io",
        IoError::Invalid { .. } => "Invalid",
        IoError::Unsupported { .. } => "Unsupported",
        IoError::Limits { .. } => "Limits",
        IoError::SameAsInput { .. } => "SameAsInput",
    }
}

fn count(tag: &str, key: &str) -> u64 {
    tag.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key)?.strip_prefix('=')?.parse().ok())
        .unwrap_or_else(|| panic!("tag {tag:?} has no {key}="))
}

#[test]
fn every_hostile_file_errors_or_loads_as_documented() {
    let cases = cases();
    assert!(
        cases.len() >= 40,
        "only {} cases parsed from README.md",
        cases.len()
    );
    let listed: BTreeSet<&str> = cases.iter().map(|c| c.name.as_str()).collect();
    let on_disk: BTreeSet<String> = std::fs::read_dir(corpus_dir())
        .expect("corpus directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n != "README.md" && n != "generate.py")
        .collect();
    let on_disk_ref: BTreeSet<&str> = on_disk.iter().map(String::as_str).collect();
    assert_eq!(listed, on_disk_ref, "README.md and the directory disagree");

    let mut failures = Vec::new();
    for case in &cases {
        let path = corpus_dir().join(&case.name);
        let size = std::fs::metadata(&path).expect("file").len();
        // A size bound, not a tolerance: the corpus files must stay small (64 KiB) to keep the
        // repository light.
        assert!(size < 64 * 1024, "{} is {size} bytes", case.name);
        let outcome = std::panic::catch_unwind(|| read_image(&path));
        let Ok(result) = outcome else {
            failures.push(format!("{}: PANICKED", case.name));
            continue;
        };
        match (&result, case.loads) {
            (Ok(img), true) => {
                let r = &img.report;
                println!(
                    "{:28} loads: {}x{}, {} negative, {} non-finite values clamped ({})",
                    case.name,
                    img.image.width(),
                    img.image.height(),
                    r.negative_values,
                    r.nonfinite_values,
                    img.details
                );
                if r.nonfinite_values != count(&case.tag, "nonfinite")
                    || r.negative_values != count(&case.tag, "negative")
                {
                    failures.push(format!(
                        "{}: counts {r:?}, README says [{}]",
                        case.name, case.tag
                    ));
                }
                if !img.image.pixels().iter().all(|p| p.is_valid_radiance()) {
                    failures.push(format!(
                        "{}: invalid values left after sanitising",
                        case.name
                    ));
                }
            }
            (Err(e), false) => {
                println!("{:28} error ({}): {e}", case.name, kind(e));
                if kind(e) != case.tag {
                    failures.push(format!(
                        "{}: {} error, README says {}: {e}",
                        case.name,
                        kind(e),
                        case.tag
                    ));
                }
                if !e.is_bad_input() {
                    failures.push(format!("{}: not classed as bad input: {e}", case.name));
                }
                if !e.to_string().contains(&case.name) {
                    failures.push(format!(
                        "{}: message does not name the file: {e}",
                        case.name
                    ));
                }
            }
            (Ok(img), false) => failures.push(format!(
                "{}: loaded ({}) but should fail",
                case.name, img.details
            )),
            (Err(e), true) => failures.push(format!("{}: failed but should load: {e}", case.name)),
        }
    }
    assert!(
        failures.is_empty(),
        "hostile corpus failures:\n{}",
        failures.join("\n")
    );
}

/// Deterministic random corruption of valid files of every format: byte flips, truncation and
/// spliced garbage. Decoding may fail but must never panic, and what loads must have the
/// header's size.
#[test]
fn mutated_files_never_panic() {
    use ibl_core::{Image, Rgb};
    use ibl_io::exr::{ExrCompression, ExrOptions, ExrPrecision};
    use ibl_io::{Limits, exr, hdr, ldr, pfm};
    use rand::{Rng, SeedableRng};

    let img = Image::from_fn_par(40, 12, |x, y| {
        if y % 3 == 0 {
            Rgb::splat(0.5)
        } else {
            Rgb::new(x as f32 * 0.3, y as f32, 1.0 / (1 + x) as f32)
        }
    });
    let srgb = ibl_core::tonemap::to_srgb8(&img, &ibl_core::tonemap::Display::default());
    let mut seeds: Vec<(&str, Vec<u8>)> = vec![
        ("hdr rle", hdr::encode(&img)),
        ("hdr flat", hdr::encode_flat(&img)),
        ("pfm", pfm::encode(&img, pfm::ByteOrder::BigEndian)),
        ("png", ldr::encode_png(&srgb).expect("png")),
        ("jpeg", ldr::encode_jpeg(&srgb, 80).expect("jpeg")),
    ];
    for compression in [
        ExrCompression::None,
        ExrCompression::Rle,
        ExrCompression::Zip,
        ExrCompression::Piz,
    ] {
        for precision in [ExrPrecision::Half, ExrPrecision::Float] {
            let options = ExrOptions {
                precision,
                compression,
            };
            seeds.push(("exr", exr::encode(&img, &options).expect("exr")));
        }
    }
    let limits = Limits {
        max_width: 4096,
        max_height: 4096,
        max_pixels: 1 << 22,
    };
    let decode = |name: &str, b: &[u8]| match name {
        "exr" => exr::decode(b, &limits),
        "pfm" => pfm::decode(b, &limits),
        "png" | "jpeg" => ldr::decode(b, &limits),
        _ => hdr::decode(b, &limits),
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(2024);
    let (mut loaded, mut failed) = (0, 0);
    for (name, seed) in &seeds {
        for _ in 0..300 {
            let mut b = seed.clone();
            match rng.random_range(0..4) {
                0 => {
                    for _ in 0..rng.random_range(1..8) {
                        let i = rng.random_range(0..b.len());
                        b[i] = rng.random();
                    }
                }
                1 => b.truncate(rng.random_range(0..b.len())),
                2 => {
                    let i = rng.random_range(0..b.len());
                    let junk: Vec<u8> =
                        (0..rng.random_range(1..64)).map(|_| rng.random()).collect();
                    b.splice(i..i, junk);
                }
                _ => {
                    // Overwrite a 4-byte field with an extreme integer (sizes, offsets, counts).
                    let i = rng.random_range(0..b.len().saturating_sub(4));
                    let v =
                        [0u32, 1, 0x7fff_ffff, 0xffff_ffff, 0x8000_0000][rng.random_range(0..5)];
                    b[i..i + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
            match std::panic::catch_unwind(|| decode(name, &b)) {
                Err(_) => panic!("{name}: decoder panicked on a mutated file"),
                Ok(Ok(raw)) => {
                    loaded += 1;
                    assert!(raw.image.len() <= 1 << 22);
                }
                Ok(Err(_)) => failed += 1,
            }
        }
    }
    println!("mutated files: {loaded} loaded, {failed} rejected, none panicked");
}
