//! Room files: every error names its field; patches cover every surface exactly once.

use glam::{Mat3, Vec3};
use ibl_room::{Room, RoomError, RoomFile};

const GOOD: &str = r#"
version = 1
[probe]
file = "probe.exr"
position = [0.0, 1.2, 0.0]
[room]
patch_area_m2 = 0.1
[[room.group]]
name = "wall"
[[room.group]]
name = "window"
kind = "light"
[[room.box]]
min = [-2.0, 0.0, -2.0]
max = [2.0, 2.5, 2.0]
facing = "inward"
group = "wall"
openings = [{ face = "-z", min = [-0.5, 1.0], max = [0.5, 2.0], fill = "window" }]
[[room.rectangle]]
group = "wall"
corner = [-1.0, 0.5, 1.0]
edge_u = [2.0, 0.0, 0.0]
edge_v = [0.0, 1.0, 0.0]
holes = [{ min = [0.5, 0.25], max = [1.0, 0.75] }]
[[room.polygon]]
group = "wall"
vertices = [[-1.0, 0.01, -1.0], [1.0, 0.01, -1.0], [1.0, 0.01, 0.0], [0.0, 0.01, 0.0], [0.0, 0.01, 1.0], [-1.0, 0.01, 1.0]]
"#;

fn field_of(text: &str) -> String {
    match RoomFile::from_toml(text) {
        Err(RoomError::Invalid { field, .. }) => field,
        other => panic!("expected an invalid-field error, got {other:?}"),
    }
}

#[test]
fn errors_name_the_field() {
    RoomFile::from_toml(GOOD).expect("the good file parses");
    let cases = [
        (GOOD.replace("version = 1", "version = 7"), "version"),
        (
            GOOD.replace("patch_area_m2 = 0.1", "patch_area_m2 = 0.0"),
            "room.patch_area_m2",
        ),
        (
            GOOD.replace("kind = \"light\"", "kind = \"lamp\""),
            "room.group[1].kind",
        ),
        (
            GOOD.replace("fill = \"window\"", "fill = \"glass\""),
            "room.box[0].openings[0].fill",
        ),
        (
            GOOD.replace("max = [0.5, 2.0]", "max = [0.5, 2.6]"),
            "room.box[0].openings[0].max",
        ),
        (
            GOOD.replace("edge_v = [0.0, 1.0, 0.0]", "edge_v = [0.3, 1.0, 0.0]"),
            "room.rectangle[0].edge_v",
        ),
        (
            GOOD.replace(
                "[0.0, 0.01, 1.0], [-1.0, 0.01, 1.0]",
                "[0.0, 0.5, 1.0], [-1.0, 0.01, 1.0]",
            ),
            "room.polygon[0].vertices",
        ),
        (
            GOOD.replace("facing = \"inward\"", "facing = \"inward\"\ncolour = 3"),
            "room.box[0]",
        ),
        (
            GOOD.replace("name = \"window\"", "name = \"wall\""),
            "room.group[1].name",
        ),
        ("version = ".to_string(), "toml"),
    ];
    for (text, field) in cases {
        let got = field_of(&text);
        assert!(got.starts_with(field), "{field}: got {got}");
    }
}

#[test]
fn patches_cover_every_surface_once() {
    let file = RoomFile::from_toml(GOOD).expect("parses");
    let room = Room::new(&file.room, Vec3::new(0.0, 1.2, 0.0), Mat3::IDENTITY).expect("room");
    let area: f32 = room.patches.iter().map(|p| p.area_m2).sum();
    // Shell 2 (4 x 4) + 4 (4 x 2.5) = 72 m^2 (the window fills its opening), rectangle 2 - 0.25,
    // L-shaped polygon 3: 76.75 m^2, to f32 rounding of ~1000 patch areas.
    assert!((area - 76.75).abs() < 1e-3, "{area}");
    assert!(room.patches.iter().all(|p| p.area_m2 <= 0.1 + 1e-6));
    let window = room.group_index("window").expect("window") as u32;
    let window_area: f32 = room
        .patches
        .iter()
        .filter(|p| p.group == window)
        .map(|p| p.area_m2)
        .sum();
    assert!((window_area - 1.0).abs() < 1e-5);
    // Fronts: the shell's face inward, towards the room's centre.
    for p in room
        .patches
        .iter()
        .filter(|p| room.faces[p.face as usize].name.starts_with("box[0]"))
    {
        assert!(p.normal.dot(Vec3::new(0.0, 1.25, 0.0) - p.centroid) > 0.0);
    }
}
