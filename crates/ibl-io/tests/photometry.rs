//! The photometric readers against files whose answers are known: synthetic IES and EULUMDAT
//! files with closed-form intensities (`tests/data/photometry/`, made by its `generate.py`), the
//! bundled real IES files (`assets/photometry/ies/`) and hostile inputs.
#![allow(clippy::unwrap_used)] // tests may panic

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use ibl_io::photometry::ies::{IesVersion, Tilt};
use ibl_io::photometry::{self, PhotometryLimits, Symmetry};
use ibl_io::{DecodeError, IoError, PhotometricFile, StatedFlux, read_photometry};
use ibl_light::{CandelaTable, EqualAreaMap};

fn synthetic(name: &str) -> PhotometricFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/photometry")
        .join(name);
    read_photometry(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn bundled_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/photometry/ies")
}

fn bundled() -> Vec<(String, PhotometricFile)> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(bundled_dir())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ies"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let file = read_photometry(&p).unwrap_or_else(|e| panic!("{e}"));
            (name, file)
        })
        .collect()
}

fn cos_d(a: f64) -> f64 {
    a.to_radians().cos()
}

fn sin_d(a: f64) -> f64 {
    a.to_radians().sin()
}

/// Every node of the expanded table against the closed form (values were written to 6
/// significant digits, so 1e-5 of the peak covers rounding).
fn check_nodes(table: &CandelaTable, f: impl Fn(f64, f64) -> f64) {
    let peak = f64::from(table.peak());
    for (h, &c) in table.horizontal_deg().iter().enumerate() {
        for (v, &g) in table.vertical_deg().iter().enumerate() {
            let got = f64::from(table.candela(h, v).unwrap());
            let want = f(f64::from(g), f64::from(c));
            assert!(
                (got - want).abs() <= 1e-5 * peak,
                "C {c} gamma {g}: {got} vs {want}"
            );
        }
    }
}

/// `h^2 / 4` for a grid step of `step_deg`: the relative flux error bound of linear chords of
/// `cos gamma` (ibl-light's flux tests derive it).
fn chord_bound(step_deg: f64) -> f64 {
    let h = step_deg.to_radians();
    h * h / 4.0
}

#[test]
fn ies_axial_2019_absolute_lambertian() {
    let PhotometricFile::Ies(f) = synthetic("axial_2019.ies") else {
        panic!()
    };
    assert_eq!(f.version, IesVersion::Lm63_2019);
    assert_eq!(f.symmetry, Symmetry::Axial);
    assert_eq!(f.stated_flux(), StatedFlux::Absolute);
    assert_eq!(f.keyword("TESTLAB"), Some("iblkit"));
    assert!(f.table.is_rotationally_symmetric());
    check_nodes(&f.table, |g, _| (1000.0 * cos_d(g)).max(0.0));
    // Lambertian downlight: pi I0, within the chords' h^2 / 4 (5 degree steps: 0.19 %).
    let error = f.table.flux() / (PI * 1000.0) - 1.0;
    assert!(error.abs() <= chord_bound(5.0), "{error}");
}

#[test]
fn ies_quadrant_2002_relative_with_multiplier_and_stated_lor() {
    let PhotometricFile::Ies(f) = synthetic("quadrant_2002.ies") else {
        panic!()
    };
    assert_eq!(f.version, IesVersion::Lm63_2002);
    assert_eq!(f.symmetry, Symmetry::Quadrant);
    assert_eq!(f.candela_scale(), 2.0);
    assert_eq!(f.light_output_ratio(), Some(0.5));
    assert!(
        f.keyword("OTHER").unwrap().contains('\n'),
        "[MORE] joins the previous keyword"
    );
    assert_eq!(f.table.horizontal_deg().len(), 17);
    check_nodes(&f.table, |_, c| 500.0 * (1.0 + 0.5 * cos_d(2.0 * c)));
    // 4 pi 500: constant in gamma (exact chords), the trapezoid rule exact on cos 2C, so only
    // the 6 written digits remain (1e-5).
    let flux = f.table.flux();
    assert!((flux / (4.0 * PI * 500.0) - 1.0).abs() < 1e-5, "{flux}");
    // The file's own figure: lamp lumens x its stated LOR, within the 0.5 %.
    let stated = f.stated_flux().luminaire_lumens().unwrap();
    assert!((flux / stated - 1.0).abs() < 5e-3);
}

#[test]
fn ies_plane_c0c180_1995_ballast_lamp_factor_multiplies() {
    let PhotometricFile::Ies(f) = synthetic("plane_c0c180_1995.ies") else {
        panic!()
    };
    assert_eq!(f.version, IesVersion::Lm63_1995);
    assert_eq!(f.symmetry, Symmetry::PlaneC0C180);
    assert_eq!(f.candela_scale(), 0.5);
    check_nodes(&f.table, |g, c| {
        (200.0 * (1.0 + 0.8 * cos_d(c)) * cos_d(g)).max(0.0)
    });
    // C270 mirrors C90 and C330 mirrors C30 (read between nodes at gamma 0: 200 (1 + 0.8 cos C)).
    let t = &f.table;
    assert!((t.intensity_deg(0.0, 330.0) - t.intensity_deg(0.0, 30.0)).abs() < 1e-3);
    let error = t.flux() / (PI * 200.0) - 1.0;
    assert!(error.abs() <= chord_bound(5.0), "{error}");
}

#[test]
fn ies_plane_c90c270_1991_commas_and_tilt_include() {
    let PhotometricFile::Ies(f) = synthetic("plane_c90c270_1991.ies") else {
        panic!()
    };
    assert_eq!(f.version, IesVersion::Lm63_1991);
    assert_eq!(f.symmetry, Symmetry::PlaneC90C270);
    assert_eq!(
        f.tilt,
        Tilt::Include {
            geometry: 1,
            angles_deg: vec![0.0, 45.0, 90.0],
            factors: vec![1.0, 0.95, 0.9]
        }
    );
    check_nodes(&f.table, |_, c| 300.0 * (1.0 + 0.5 * sin_d(c)));
    assert!((f.table.flux() / (4.0 * PI * 300.0) - 1.0).abs() < 1e-5);
}

#[test]
fn ies_full_1986_closes_the_turn() {
    let PhotometricFile::Ies(f) = synthetic("full_1986.ies") else {
        panic!()
    };
    assert_eq!(f.version, IesVersion::Lm63_1986);
    assert_eq!(f.symmetry, Symmetry::None);
    assert_eq!(f.text_lines.len(), 2);
    assert_eq!(
        f.stated_flux(),
        StatedFlux::Lamps {
            lamp_lumens: 2000.0
        }
    );
    assert_eq!(f.table.horizontal_deg().last(), Some(&360.0));
    check_nodes(&f.table, |_, c| {
        100.0 * (1.0 + 0.3 * cos_d(c) + 0.2 * sin_d(2.0 * c))
    });
    assert!((f.table.flux() / (4.0 * PI * 100.0) - 1.0).abs() < 1e-5);
}

/// An LDT file's table: nodes against `f` (cd/klm) times the lamp flux / 1000, the flux against
/// the stated `LORL x` lamp flux (0.5 %, the tolerance, unless `tolerance` is tighter),
/// and the downward fraction against `DFF`.
fn check_ldt(name: &str, symmetry: Symmetry, f: impl Fn(f64, f64) -> f64, tolerance: f64) {
    let PhotometricFile::Ldt(file) = synthetic(name) else {
        panic!()
    };
    assert_eq!(file.symmetry, symmetry, "{name}");
    let scale = file.candela_scale();
    check_nodes(&file.table, |g, c| f(g, c) * scale);
    let flux = file.table.flux();
    let stated = file.stated_flux().luminaire_lumens().unwrap();
    assert!(
        (flux / stated - 1.0).abs() <= tolerance.min(5e-3),
        "{name}: {flux} vs {stated}"
    );
    let down = file.table.flux_between_deg(0.0, 90.0) / flux * 100.0;
    // DFF is written to 6 digits of a percentage: 1e-3 points.
    assert!(
        (down - file.downward_flux_fraction_percent).abs() < 1e-3,
        "{name}: {down}"
    );
}

#[test]
fn ldt_each_isym_expands_and_integrates_to_its_lor() {
    check_ldt(
        "isym1_lambertian.ldt",
        Symmetry::Axial,
        |g, _| (1000.0 / PI * cos_d(g)).max(0.0),
        chord_bound(5.0),
    );
    let exact = 1e-5; // constant in gamma, trapezoid-exact in C: only the 6 digits remain
    check_ldt(
        "isym2_comma.ldt",
        Symmetry::PlaneC0C180,
        |_, c| 50.0 * (1.0 + 0.5 * cos_d(c)),
        exact,
    );
    check_ldt(
        "isym3.ldt",
        Symmetry::PlaneC90C270,
        |_, c| 40.0 * (1.0 + 0.5 * sin_d(c)),
        exact,
    );
    check_ldt(
        "isym4.ldt",
        Symmetry::Quadrant,
        |_, c| 60.0 * (1.0 + 0.4 * cos_d(2.0 * c)),
        exact,
    );
    check_ldt(
        "isym0.ldt",
        Symmetry::None,
        |_, c| 70.0 * (1.0 + 0.3 * cos_d(c) + 0.2 * sin_d(2.0 * c)),
        exact,
    );
    let PhotometricFile::Ldt(f) = synthetic("isym3.ldt") else {
        panic!()
    };
    assert_eq!(f.lamp_sets.len(), 2);
    assert_eq!(f.candela_scale(), 3.0, "the first lamp set scales");
}

#[test]
fn every_bundled_file_reads_and_integrates_below_its_lamp_lumens() {
    let files = bundled();
    assert_eq!(files.len(), 29);
    for (name, file) in &files {
        let flux = file.table().flux();
        let lamps = file.stated_flux().lamp_lumens().unwrap();
        // A luminaire cannot emit more than its lamps: the implied LOR is at most 1 (0.5 %
        // slack, the tolerance, for files whose lamp lumens are the luminaire's).
        assert!(
            flux > 0.0 && flux <= lamps * 1.005,
            "{name}: {flux} lm of {lamps}"
        );
    }
}

#[test]
fn bundled_files_that_state_their_luminaire_lumens_match_within_half_a_percent() {
    let files = bundled();
    let get = |n: &str| &files.iter().find(|(name, _)| name == n).unwrap().1;
    // defined_diffuse.ies states "light output ratio: 0.5912" in its header: 2200 lm x 0.5912.
    let f = get("defined_diffuse.ies");
    let stated = f.stated_flux().luminaire_lumens().unwrap();
    assert!((stated - 2200.0 * 0.5912).abs() < 1e-9);
    assert!((f.table().flux() / stated - 1.0).abs() < 5e-3);
    // defined.ies states 13172.61 lamp lumens and no LOR; its lumens are the luminaire's own
    // (its table integrates to 99.8 % of them), the one such file among the 29.
    let f = get("defined.ies");
    assert!((f.table().flux() / 13172.61 - 1.0).abs() < 5e-3);
}

#[test]
fn the_equal_area_map_keeps_each_bundled_file_s_flux() {
    for (name, file) in &bundled() {
        let t = file.table();
        let map = EqualAreaMap::from_table(t, 128, 4);
        // 128^2 texels of 4^2 sub-samples (texels about 1.6 degrees): 0.5 % of the exact flux;
        // what is left is the midpoint rule at the tables' kinks and their dark edges.
        let ratio = map.flux() / t.flux();
        assert!((ratio - 1.0).abs() < 5e-3, "{name}: {ratio}");
    }
}

/// The error kind of a decode and whether its message has `needle`.
fn fails(result: Result<impl Sized, DecodeError>, kind: &str, needle: &str) {
    let Err(e) = result else {
        panic!("expected a {kind} error with {needle:?}")
    };
    let got = match &e {
        DecodeError::Invalid(_) => "Invalid",
        DecodeError::Unsupported(_) => "Unsupported",
        DecodeError::Limits(_) => "Limits",
    };
    assert_eq!(got, kind, "{e}");
    assert!(e.to_string().contains(needle), "{e:?} lacks {needle:?}");
}

const HEAD: &str = "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n";

#[test]
fn hostile_ies_files_fail_clearly() {
    let l = PhotometryLimits::default();
    let d = |s: &str| photometry::ies::decode(s.as_bytes(), &l);
    fails(d(""), "Invalid", "empty");
    fails(
        d("IESNA:LM-63-2002\n1 -1 1 2 1 1 2 0 0 0\n"),
        "Invalid",
        "no TILT=",
    );
    fails(d("IESNA:LM-63-2030\nTILT=NONE\n"), "Unsupported", "line 1");
    fails(
        d("IESNA:LM-63-2002\nTILT=lamp.tlt\n"),
        "Unsupported",
        "line 2: TILT=lamp.tlt",
    );
    let body = |numbers: &str| format!("{HEAD}{numbers}");
    fails(
        d(&body("1 -1 1 2 1 2 2 0 0 0\n1 1 0\n0 90\n0\n1 1\n")),
        "Unsupported",
        "type B",
    );
    fails(
        d(&body("1 -1 1 2 1 3 2 0 0 0\n1 1 0\n0 90\n0\n1 1\n")),
        "Unsupported",
        "type A",
    );
    fails(d(&body("1 -1 1 99999 1 1 2 0 0 0\n")), "Limits", "line 4");
    fails(
        d(&body("1 -1 1 3000 3000 1 2 0 0 0\n1 1 0\n")),
        "Limits",
        "over the limit",
    );
    fails(
        d(&body("1 -1 1 37 5 1 2 0 0 0\n1 1 0\n0 5 10\n")),
        "Limits",
        "holds only 3",
    );
    fails(
        d(&body("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n1 -2\n")),
        "Invalid",
        "line 8: the candela value at horizontal angle 0 and vertical angle 90 is negative",
    );
    fails(
        d(&body("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n90 0\n0\n1 1\n")),
        "Invalid",
        "line 6: vertical angle 2 of 2",
    );
    fails(
        d(&body("1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0 45\n1 1 1 1\n")),
        "Invalid",
        "0 to 45",
    );
    fails(
        d(&body("1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n1 1\n7\n")),
        "Invalid",
        "line 9: \"7\" follows",
    );
    fails(
        d(&body("1 0 1 2 1 1 2 0 0 0\n")),
        "Invalid",
        "lumens per lamp is 0",
    );
    fails(
        d(&body("1 -1 1 2 1 1 2 0 0 NaN\n")),
        "Invalid",
        "opening height",
    );
    fails(d(&body("1 -1 1 2 1 1 2 0 0 0\n")), "Invalid", "ends");
    // END and a DOS end-of-file mark after the table are fine.
    let ok = d(&body(
        "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n1 1\nEND\n\u{1a}",
    ));
    assert!(ok.is_ok(), "{ok:?}");
}

#[test]
fn hostile_ldt_files_fail_clearly() {
    let l = PhotometryLimits::default();
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/photometry/isym3.ldt"),
    )
    .unwrap();
    let lines: Vec<&str> = good.lines().collect();
    let with = |k: usize, v: &str| {
        let mut l2 = lines.clone();
        l2[k - 1] = v;
        l2.join("\n")
    };
    let d = |s: &str| photometry::ldt::decode(s.as_bytes(), &l);
    fails(d(""), "Invalid", "empty");
    fails(d(&with(3, "7")), "Invalid", "line 3");
    fails(
        d(&with(4, "6")),
        "Invalid",
        "Nc is 6, but Isym 3 needs a positive multiple of 4",
    );
    fails(d(&with(4, "100000")), "Limits", "line 4");
    fails(d(&with(6, "3000")), "Limits", "holds only");
    fails(d(&with(23, "abc")), "Invalid", "line 23 (LORL");
    fails(
        d(&with(29, "0")),
        "Invalid",
        "line 29: the total flux of lamp set 1 is 0",
    );
    fails(d(&with(26, "99999")), "Limits", "lamp sets");
    fails(d(&lines[..30].join("\n")), "Invalid", "ends");
    // C angles out of order, and a stored range that does not start at C90.
    let c0 = 26 + 12 + 10 + 1;
    fails(d(&with(c0 + 1, "400")), "Invalid", "C angle 2 of 8");
    fails(
        d(&with(c0 + 2, "80")),
        "Invalid",
        "stores the planes C90 to C270",
    );
    fails(
        d(&format!("{}\n1\n", lines.join("\n"))),
        "Invalid",
        "follows the last intensity",
    );
}

#[test]
fn cut_files_never_panic() {
    // Every prefix of a small file of each format (every 3rd byte): an error or a table, never
    // a panic (the fuzz targets do this at random for longer).
    let l = PhotometryLimits::default();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/photometry");
    for (name, ies) in [("plane_c90c270_1991.ies", true), ("isym3.ldt", false)] {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        for end in (0..bytes.len()).step_by(3) {
            let cut = &bytes[..end];
            if ies {
                let _ = photometry::ies::decode(cut, &l);
            } else {
                let _ = photometry::ldt::decode(cut, &l);
            }
        }
    }
}

#[test]
fn mutated_files_never_panic() {
    // Seeded random byte edits (overwrite with any byte, including non-ASCII, digits and
    // separators; delete; duplicate a span) of one file of each format: an error or a table,
    // never a panic, and every table read integrates to a finite flux.
    use rand::{Rng, SeedableRng};
    let l = PhotometryLimits::default();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/photometry");
    let mut rng = rand_pcg::Pcg64::seed_from_u64(17);
    for (name, ies) in [("quadrant_2002.ies", true), ("isym2_comma.ldt", false)] {
        let original = std::fs::read(dir.join(name)).unwrap();
        for _ in 0..1500 {
            let mut bytes = original.clone();
            for _ in 0..rng.random_range(1..4) {
                let at = rng.random_range(0..bytes.len());
                match rng.random_range(0..4) {
                    0 => bytes[at] = rng.random(),
                    1 => bytes[at] = b"0123456789-.,eE \n"[rng.random_range(0..17)],
                    2 => {
                        bytes.remove(at);
                    }
                    _ => {
                        let end = (at + rng.random_range(1..40)).min(bytes.len());
                        let span = bytes[at..end].to_vec();
                        bytes.splice(at..at, span);
                    }
                }
            }
            let table = if ies {
                photometry::ies::decode(&bytes, &l).map(|f| f.table)
            } else {
                photometry::ldt::decode(&bytes, &l).map(|f| f.table)
            };
            if let Ok(t) = table {
                assert!(t.flux().is_finite());
            }
        }
    }
}

#[test]
fn file_errors_name_the_file() {
    let e = read_photometry(Path::new("missing/lamp.ies")).unwrap_err();
    assert!(matches!(e, IoError::Io { .. }) && e.is_bad_input());
    let e = read_photometry(Path::new("lamp.xyz")).unwrap_err();
    assert!(matches!(e, IoError::Unsupported { .. }) && e.to_string().starts_with("lamp.xyz"));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("bad.IES");
    std::fs::write(&p, "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 1 2 2 0 0 0\n").unwrap();
    let e = read_photometry(&p).unwrap_err();
    assert!(
        e.is_bad_input() && e.to_string().contains("bad.IES: unsupported: line 3"),
        "{e}"
    );
}
