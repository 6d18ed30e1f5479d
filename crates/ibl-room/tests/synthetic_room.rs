//! The reflectance estimate on the synthetic room of `assets/rooms/synthetic/` against the
//! albedos it was rendered with by iblkit's own path tracer (`probe.exr`, made by the
//! `render_synthetic_room` example; its noise is in `render.json`).

use std::path::PathBuf;

use ibl_room::reflectance::PatchRole;
use ibl_room::{
    AnalysisSettings, GroupKind, Room, RoomFile, RoomReport, analyse_room, important_patches,
};

fn assets() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/synthetic")
}

#[test]
fn synthetic_room_reflectances_match_the_rendered_albedos() {
    let dir = assets();
    let text = std::fs::read_to_string(dir.join("room.toml")).expect("room file");
    let file = RoomFile::from_toml(&text).expect("room file parses");
    let room = Room::from_file(&file).expect("room");
    let probe = ibl_io::read_image(&dir.join(&file.probe.file))
        .expect("probe")
        .image;
    assert!(probe.width() >= 1024 && probe.height() >= 512);
    let analysis =
        analyse_room(&room, &probe, &AnalysisSettings::default(), &|_, _, _| ()).expect("analysis");
    let important = important_patches(&room, &analysis.estimate, 16);
    let report = RoomReport::new(&room, &analysis, Some(&important));
    let markdown = report.to_markdown();
    println!("{markdown}");
    let estimate = &analysis.estimate;
    assert!(estimate.converged, "not converged:\n{markdown}");
    assert!(estimate.iterations.len() <= 5, "{markdown}");
    let mut mostly_hidden = 0;
    for g in &estimate.groups {
        if g.kind == GroupKind::Light {
            continue;
        }
        let truth = g
            .measured_reflectance
            .expect("every surface has its albedo");
        let rho = g.reflectance.expect("surface");
        let error = (0..3)
            .map(|c| (rho[c] - truth[c]).abs())
            .fold(0.0, f32::max);
        // Seen groups within 0.02, mostly hidden ones (under half their area seen) within 0.04
        // (issue 16). The render's noise on a group's mean radiance (render.json) is 0.2 % (wall) to
        // 2.2 % (chest, the least seen) relative: 0.012 absolute at the chest's 0.55, one sigma.
        // Measured largest errors: table 0.015, ceiling 0.012, chest 0.004.
        let bound = if g.seen_area_fraction < 0.5 {
            mostly_hidden += 1;
            0.04
        } else {
            0.02
        };
        assert!(g.estimated, "{} not seen", g.name);
        assert!(
            error <= bound,
            "{}: {rho:?} vs {truth:?} (error {error:.4} > {bound})\n{markdown}",
            g.name
        );
    }
    assert!(mostly_hidden >= 1, "the room has a mostly hidden group");
    assert!(estimate.patches.iter().any(|p| p.role == PatchRole::Hidden));
    // The window carries the light: it must be among the important patches.
    let window = room.group_index("window").expect("window group") as u32;
    assert!(
        important
            .important
            .iter()
            .any(|l| room.patches[l.patch as usize].group == window)
    );
}
