//! The automatic Manhattan-frame proposal on a synthetic panorama with a known rotation: the
//! synthetic room seen from its probe, each surface flat-shaded by its albedo and a fixed light
//! direction (3 x 3 supersampled, so edges are antialiased like a photograph's), must give the
//! rotation within 1 degree (issue 16).

use std::path::PathBuf;

use glam::{DMat3, Mat3, Vec3};
use ibl_core::{EulerDegrees, Image, LatLong, Rgb};
use ibl_room::{ManhattanSettings, Room, RoomFile, propose_manhattan_frame};

fn synthetic_panorama(room: &Room, width: usize) -> Image<Rgb> {
    let height = width / 2;
    let light = Vec3::new(0.3, 0.8, 0.5).normalize();
    Image::from_fn_par(width, height, |x, y| {
        let mut sum = Rgb::ZERO;
        for sy in 0..3 {
            for sx in 0..3 {
                let u = (x as f64 + (f64::from(sx) + 0.5) / 3.0) / width as f64;
                let v = (y as f64 + (f64::from(sy) + 0.5) / 3.0) / height as f64;
                let d = (room.world_from_probe * LatLong::uv_to_dir(u, v)).normalize();
                sum += match room.hit(room.probe_position, d, 0.0, f32::INFINITY) {
                    Some(hit) => {
                        let p = &room.patches[hit.patch as usize];
                        let albedo = room.groups[p.group as usize]
                            .measured_reflectance
                            .unwrap_or(Rgb::splat(2.0));
                        albedo * (0.35 + 0.65 * p.normal.dot(light).abs())
                    }
                    None => Rgb::splat(3.0),
                };
            }
        }
        sum / 9.0
    })
}

#[test]
fn proposal_finds_the_rotation_within_a_degree() {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/rooms/synthetic/room.toml");
    let file =
        RoomFile::from_toml(&std::fs::read_to_string(path).expect("room file")).expect("parses");
    let truth = EulerDegrees {
        yaw_deg: 17.0,
        pitch_deg: 2.5,
        roll_deg: -1.5,
    }
    .world_from_probe();
    let room = Room::new(&file.room, Vec3::from(file.probe.position), truth).expect("room");
    let panorama = synthetic_panorama(&room, 1024);
    let proposal =
        propose_manhattan_frame(&panorama, &ManhattanSettings::default()).expect("proposal");
    let m = proposal.world_from_probe;
    let found = DMat3::from_cols_array(&[
        m[0][0], m[1][0], m[2][0], m[0][1], m[1][1], m[2][1], m[0][2], m[1][2], m[2][2],
    ]);
    let d = found.transpose() * Mat3::as_dmat3(&truth);
    // atan2 of the rotation's sine and cosine: accurate for small angles (acos is not).
    let skew = glam::DVec3::new(
        d.y_axis.z - d.z_axis.y,
        d.z_axis.x - d.x_axis.z,
        d.x_axis.y - d.y_axis.x,
    );
    let angle = (0.5 * skew.length())
        .atan2(0.5 * (d.x_axis.x + d.y_axis.y + d.z_axis.z - 1.0))
        .to_degrees();
    println!("{proposal:?}\nangle to the truth: {angle:.4} deg");
    assert!(angle < 1.0, "{angle} degrees off: {proposal:?}");
    assert!(proposal.inliers.iter().all(|&n| n >= 5), "{proposal:?}");
    assert!(proposal.rms_residual_deg < 1.0);
}
