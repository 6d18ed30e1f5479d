//! The worked example of `docs/ROOMS.md`: the bundled apartment probe's marks reconstruct the
//! committed room file, and the estimate on it converges with physical reflectances.

use std::path::PathBuf;

use ibl_room::{
    AnalysisSettings, GroupKind, MarksFile, Room, RoomFile, analyse_room, calibrate,
    line_observations, probe_height, reconstruct,
};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/apartment")
}

#[test]
fn marks_reconstruct_the_committed_room() {
    let marks = MarksFile::from_json(
        &std::fs::read_to_string(dir().join("marks.json")).expect("marks file"),
    )
    .expect("marks parse");
    let calibration = calibrate(&line_observations(&marks)).expect("calibration");
    // Hand-made marks on a 512 x 256 probe: a fraction of a degree to a degree per line.
    assert!(calibration.rms_residual_deg < 1.5, "{calibration:?}");
    let scale = probe_height(&marks, calibration.world_from_probe()).expect("scale");
    let made = reconstruct(&marks, &calibration, &scale, "../../probes/apartment.exr")
        .expect("reconstruction");
    let committed =
        RoomFile::from_toml(&std::fs::read_to_string(dir().join("room.toml")).expect("room file"))
            .expect("room file parses");
    // The committed file was written from these marks by the room_report example; f32 text
    // round trip only.
    assert_eq!(made.room.boxes.len(), committed.room.boxes.len());
    for (a, b) in made.room.boxes.iter().zip(&committed.room.boxes) {
        for k in 0..3 {
            assert!((a.min[k] - b.min[k]).abs() < 1e-4 && (a.max[k] - b.max[k]).abs() < 1e-4);
        }
        assert_eq!(a.openings.len(), b.openings.len());
    }
    for k in 0..3 {
        assert!((made.probe.rotation_deg[k] - committed.probe.rotation_deg[k]).abs() < 1e-4);
        assert!((made.probe.position[k] - committed.probe.position[k]).abs() < 1e-5);
    }
}

#[test]
fn apartment_estimate_converges_to_physical_reflectances() {
    let file =
        RoomFile::from_toml(&std::fs::read_to_string(dir().join("room.toml")).expect("room file"))
            .expect("parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir().join(&file.probe.file))
        .expect("probe")
        .image;
    let analysis =
        analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ()).expect("analysis");
    let estimate = &analysis.estimate;
    assert!(estimate.converged && estimate.iterations.len() <= 5);
    for g in estimate
        .groups
        .iter()
        .filter(|g| g.kind == GroupKind::Surface)
    {
        let rho = g.reflectance.expect("surface");
        // No ground truth for a real room; what must hold is a physical reflectance, every
        // group seen (measured: wall 0.90 0.90 0.83, floor 0.83 0.61 0.36, door 0.17 0.08 0.04).
        assert!(g.estimated, "{}", g.name);
        assert!(
            rho.iter().all(|&c| c > 0.0 && c < 1.0),
            "{}: {rho:?}",
            g.name
        );
    }
    // The model closes the room: every form-factor ray meets a front side.
    for e in 0..analysis.form_factors.len() {
        assert!((analysis.form_factors.row_sum(e) - 1.0).abs() < 1e-5);
    }
}
