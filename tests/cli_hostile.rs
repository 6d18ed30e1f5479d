//! Issue 13, "Hostile files and interrupted runs": each defect the hostile probe found, through the
//! binary. Before the fixes: `sh --from` exited 1 on a file that is not UTF-8; `/dev/zero` as an
//! SH file, a scene or a scene's `lights_file` grew to 4 GB and exited 1; 2000 spheres took
//! 9.7 GB; `convert --width 30000` wrote gigabytes; a FIFO as the probe hung for ever; an
//! interrupted write left its temporary file; `ibl info` spent minutes on a 2^28-pixel JPEG with
//! no way to lower the limit; an OBJ's `mtllib` could name a device or the OBJ itself; a closed
//! standard output made `println!` panic.

#![allow(clippy::unwrap_used)] // tests may panic

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{ibl, ibl_binary, probe, stderr};

/// Runs `ibl args` and expects exit 2 with `needle` in the message.
fn refused(args: &[&str], needle: &str) -> String {
    let o = ibl(args);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert!(e.contains(needle), "{args:?}: expected {needle:?} in: {e}");
    assert!(!e.contains("panicked"), "{args:?}: {e}");
    e
}

/// Waits for `child` at most `limit`; kills it and fails the test when it is still running.
fn wait_at_most(mut child: Child, limit: Duration, what: &str) -> std::process::Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{what}: still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn an_sh_file_that_is_not_utf8_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, b"\xff\xfe{\"bands\": 3}").unwrap();
    refused(
        &["sh", bad.to_str().unwrap(), "--from", "json"],
        "not UTF-8",
    );
}

#[cfg(unix)]
#[test]
fn devices_and_directories_are_refused_by_type_as_every_kind_of_input() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    let sky = probe("sky.exr");
    std::fs::write(
        &scene,
        format!(
            "version = 1\n[probe]\nfile = {sky:?}\n[render]\nmode = \"lights\"\n[lighting]\nlights_file = \"/dev/zero\"\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("o.exr");
    let out = out.to_str().unwrap();
    // Images are chosen by extension: a link with one reaches the device.
    let zero_hdr = dir.path().join("zero.hdr");
    std::os::unix::fs::symlink("/dev/zero", &zero_hdr).unwrap();
    let zero_hdr = zero_hdr.to_str().unwrap();
    let lights = dir.path().join("l.json");
    for args in [
        vec!["sh", "/dev/zero", "--from", "json"],
        vec!["render", "/dev/zero", "-o", out],
        vec!["info", zero_hdr],
        vec![
            "lights",
            zero_hdr,
            "-n",
            "4",
            "-o",
            lights.to_str().unwrap(),
        ],
    ] {
        refused(&args, "character device, not a regular file");
    }
    refused(
        &["render", scene.to_str().unwrap(), "-o", out],
        "character device",
    );
    let folder = dir.path().join("folder.hdr");
    std::fs::create_dir(&folder).unwrap();
    refused(&["info", folder.to_str().unwrap()], "a directory");
}

#[cfg(unix)]
#[test]
fn a_fifo_as_the_probe_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("probe.hdr");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success(), "mkfifo");
    for cmd in [vec!["info"], vec!["sh"], vec!["convert"]] {
        let mut args: Vec<&str> = cmd;
        args.push(fifo.to_str().unwrap());
        if args[0] == "convert" {
            args.push("out.exr");
        }
        let child = Command::new(ibl_binary())
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Before the fix `open` blocked until a writer came: for ever.
        let o = wait_at_most(child, Duration::from_secs(20), &format!("{args:?}"));
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("FIFO"), "{}", stderr(&o));
    }
}

#[test]
fn a_scene_whose_shapes_exceed_the_triangle_limit_is_refused_before_building() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("spheres.toml");
    let mut text = format!("version = 1\n[probe]\nfile = {:?}\n", probe("sky.exr"));
    for i in 0..2000 {
        text.push_str(&format!(
            "[[object]]\nshape = \"sphere\"\nradius = 0.01\ncenter = [0.0, 0.0, -{i}.5]\n"
        ));
    }
    std::fs::write(&scene, text).unwrap();
    let out = dir.path().join("o.exr");
    let start = Instant::now();
    let e = refused(
        &[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        "over the limit of 20000000",
    );
    assert!(e.contains("spheres.toml"), "names the scene: {e}");
    // Refused from the description: no sphere was built (9.7 GB and minutes before).
    assert!(start.elapsed() < Duration::from_secs(30));
}

#[test]
fn outputs_over_the_pixel_limit_are_refused_before_resampling() {
    let dir = tempfile::tempdir().unwrap();
    let sky = probe("sky.exr");
    for (to, width) in [
        ("cube-hcross", "30000"),
        ("angular", "30000"),
        ("latlong", "40000"),
    ] {
        let out = dir.path().join(format!("{to}.exr"));
        let start = Instant::now();
        refused(
            &[
                "convert",
                &sky,
                out.to_str().unwrap(),
                "--to",
                to,
                "--width",
                width,
            ],
            "over the limit of 268435456 pixels",
        );
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{to}: refused late"
        );
        assert!(!out.exists());
    }
    // The limit is the user's to lower: 512 x 256 passes 2^28 but not 100000.
    let out = dir.path().join("small.exr");
    refused(
        &[
            "--max-pixels",
            "100000",
            "convert",
            &sky,
            out.to_str().unwrap(),
            "--width",
            "512",
        ],
        "over the limit of 100000",
    );
}

#[test]
fn the_pixel_limit_is_lowered_by_an_option_or_the_environment() {
    let sky = probe("sky.exr"); // 512 x 256 = 131072 pixels
    refused(
        &["--max-pixels", "100000", "info", &sky],
        "over the limit of 100000",
    );
    refused(
        &["info", &sky, "--max-pixels", "100000"],
        "over the limit of 100000",
    );
    let env = |value: &str| {
        Command::new(ibl_binary())
            .args(["info", &sky])
            .env("IBL_MAX_PIXELS", value)
            .output()
            .unwrap()
    };
    let o = env("100000");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("over the limit of 100000"));
    assert_eq!(env("200000").status.code(), Some(0));
    let o = env("lots");
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("IBL_MAX_PIXELS"), "{}", stderr(&o));
    refused(&["--max-pixels", "0", "info", &sky], "--max-pixels");
}

#[test]
fn info_header_reads_a_huge_image_s_header_only() {
    let dir = tempfile::tempdir().unwrap();
    // A PFM header announcing 16384 x 16384 (2^28 pixels, 3 GiB of floats) and no pixel data:
    // the full read refuses it as truncated; the header is what `--header` needs.
    let huge = dir.path().join("huge.pfm");
    std::fs::write(&huge, b"PF\n16384 16384\n-1.0\n").unwrap();
    let start = Instant::now();
    let o = ibl(&["info", huge.to_str().unwrap(), "--header", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(start.elapsed() < Duration::from_secs(10));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["width"], 16384);
    assert_eq!(v["height"], 16384);
    assert_eq!(v["mapping"], "angular");
    assert_eq!(v["within_limits"], true);
    let o = ibl(&[
        "--max-pixels",
        "1000",
        "info",
        huge.to_str().unwrap(),
        "--header",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["within_limits"], false);
    // The bundled probe's header agrees with its full read.
    let o = ibl(&["info", &probe("sky.hdr"), "--header"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("512 x 256"));
}

/// The hidden temporary files in `dir`.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with(".iblkit-")
        })
        .collect()
}

#[cfg(unix)]
#[test]
fn an_interrupted_write_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    // A 4096 x 4096 PFM (200 MB of zeros) converted format-only: the run is mostly its write.
    let input = dir.path().join("in.pfm");
    let mut bytes = b"PF\n4096 4096\n-1.0\n".to_vec();
    bytes.resize(bytes.len() + 4096 * 4096 * 12, 0);
    std::fs::write(&input, bytes).unwrap();
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let out = out_dir.join("o.pfm");
    for signal in ["TERM", "INT"] {
        let mut caught = false;
        for _attempt in 0..5 {
            let mut child = Command::new(ibl_binary())
                .args(["convert", input.to_str().unwrap(), out.to_str().unwrap()])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .unwrap();
            // Wait for the write's temporary file (not the folder check's), then interrupt.
            // Whatever was left afterwards fails the test, the check's file included (CI caught
            // a signal between the check's create and remove, which left `.iblkit-check-PID`).
            let writing_now = || {
                temporaries(&out_dir)
                    .iter()
                    .any(|p| p.extension().is_some_and(|e| e == "tmp"))
            };
            let start = Instant::now();
            while !writing_now()
                && child.try_wait().unwrap().is_none()
                && start.elapsed() < Duration::from_secs(60)
            {
                std::thread::sleep(Duration::from_micros(500));
            }
            let writing = writing_now();
            if writing {
                // The shell's built-in `kill` (no procps needed).
                let kill = format!("kill -{signal} {}", child.id());
                Command::new("sh").args(["-c", &kill]).status().unwrap();
            }
            let status = child.wait().unwrap();
            let _ = std::fs::remove_file(&out);
            if writing && !status.success() {
                caught = true;
                assert!(
                    temporaries(&out_dir).is_empty(),
                    "SIG{signal} left {:?}",
                    temporaries(&out_dir)
                );
                break;
            }
        }
        assert!(caught, "SIG{signal}: never caught the write in progress");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn temporary_files_a_killed_run_left_are_cleaned_by_the_next_write() {
    let dir = tempfile::tempdir().unwrap();
    // Left by process 4294967000 (above Linux's largest id, so never running), two minutes ago.
    let stale = dir.path().join(".iblkit-tmp-4294967000-abc.tmp");
    let fresh = dir.path().join(".iblkit-tmp-4294967001-abc.tmp");
    let other = dir.path().join(".hidden-but-not-ours.tmp");
    for p in [&stale, &fresh, &other] {
        std::fs::write(p, b"partial").unwrap();
    }
    let two_minutes_ago = std::time::SystemTime::now() - Duration::from_secs(120);
    for p in [&stale, &other] {
        std::fs::File::options()
            .write(true)
            .open(p)
            .unwrap()
            .set_modified(two_minutes_ago)
            .unwrap();
    }
    let out = dir.path().join("lights.json");
    let o = ibl(&[
        "lights",
        &probe("sky.exr"),
        "-n",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stale.exists(), "the stale temporary file is removed");
    assert!(
        fresh.exists(),
        "a recent one is kept (its writer may live elsewhere)"
    );
    assert!(other.exists(), "files not named as ours are never touched");
}

#[test]
fn an_obj_material_library_must_be_a_regular_file_other_than_the_obj() {
    let dir = tempfile::tempdir().unwrap();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let cases = [
        ("self.obj", "mtllib self.obj\n", "names the OBJ file itself"),
        #[cfg(unix)]
        ("device.obj", "mtllib /dev/zero\n", "character device"),
    ];
    for (name, head, needle) in cases {
        let obj = dir.path().join(name);
        std::fs::write(&obj, format!("{head}{tri}")).unwrap();
        let e = ibl_io::read_mesh(&obj, &ibl_io::MeshLimits::default()).unwrap_err();
        assert!(
            e.is_bad_input() && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
}

#[test]
fn a_reader_that_goes_away_ends_the_run_quietly() {
    let mut child = Command::new(ibl_binary())
        .args(["info", &probe("sky.exr"), "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the read end before the probe is read and described.
    drop(child.stdout.take());
    let o = wait_at_most(child, Duration::from_secs(30), "info into a closed pipe");
    let e = stderr(&o);
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(o.status.code(), Some(141), "{e}");
}
