//! Geometry from the probe (Grosch 2005, section 3.1) on synthetic marks: the room's edges and
//! corners projected into perspective views of a probe with a known rotation and height, the
//! marked ends and points moved by 1-pixel Gaussian noise; the calibration must find the rotation
//! within 0.2 degrees and the scale within 1 % (issue 16), and the constraints must place the
//! shapes where they were.

use glam::{DMat3, DVec3};
use ibl_room::marks::{LineMark, MARKS_FORMAT, PointMark, ScaleMark, ViewMarks};
use ibl_room::placement::ShapeMark;
use ibl_room::{
    Axis, MarksFile, PerspectiveView, calibrate, line_observations, probe_height, reconstruct,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg32;

/// The true rotation and probe height.
fn truth() -> (DMat3, f64) {
    let r = DMat3::from_rotation_y(23f64.to_radians())
        * DMat3::from_rotation_x(3f64.to_radians())
        * DMat3::from_rotation_z(-2f64.to_radians());
    (r, 1.3)
}

/// Room extents (world, floor at y = 0, probe above the origin).
const LO: [f64; 3] = [-2.2, 0.0, -2.8];
const HI: [f64; 3] = [2.9, 2.6, 1.4];

fn views() -> Vec<PerspectiveView> {
    (0..8)
        .map(|k| PerspectiveView {
            yaw_deg: 45.0 * f64::from(k),
            pitch_deg: 0.0,
            roll_deg: 0.0,
            vertical_fov_deg: 100.0,
            width: 1024,
            height: 768,
        })
        .collect()
}

fn gaussian(rng: &mut Pcg32) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

struct Synth {
    world_from_probe: DMat3,
    probe: DVec3,
    views: Vec<PerspectiveView>,
}

impl Synth {
    fn project(&self, view: &PerspectiveView, p: DVec3) -> Option<[f64; 2]> {
        let d = (self.world_from_probe.transpose() * (p - self.probe)).normalize();
        let (x, y) = view.project(d)?;
        (x >= 0.0 && y >= 0.0 && x <= f64::from(view.width) && y <= f64::from(view.height))
            .then_some([x, y])
    }

    /// The view where `p` is nearest the centre, and its pixel.
    fn best_view(&self, p: DVec3) -> (usize, [f64; 2]) {
        self.views
            .iter()
            .enumerate()
            .filter_map(|(k, v)| self.project(v, p).map(|px| (k, px)))
            .min_by(|a, b| {
                let c = |px: [f64; 2]| (px[0] - 512.0).hypot(px[1] - 384.0);
                c(a.1).total_cmp(&c(b.1))
            })
            .expect("every point is in some view")
    }

    /// The visible part of the 3D segment `a b` in each view, as a line mark (ends moved by
    /// `sigma` pixels of Gaussian noise), when at least 80 pixels of it are in the view.
    fn segment_marks(
        &self,
        axis: Axis,
        a: DVec3,
        b: DVec3,
        sigma: f64,
        rng: &mut Pcg32,
    ) -> Vec<(usize, LineMark)> {
        let mut out = Vec::new();
        for (k, view) in self.views.iter().enumerate() {
            let samples: Vec<[f64; 2]> = (0..=400)
                .filter_map(|i| self.project(view, a + (b - a) * (f64::from(i) / 400.0)))
                .collect();
            let (Some(&from), Some(&to)) = (samples.first(), samples.last()) else {
                continue;
            };
            if (to[0] - from[0]).hypot(to[1] - from[1]) < 80.0 {
                continue;
            }
            let mut noisy =
                |p: [f64; 2]| [p[0] + sigma * gaussian(rng), p[1] + sigma * gaussian(rng)];
            out.push((
                k,
                LineMark {
                    axis,
                    from: noisy(from),
                    to: noisy(to),
                },
            ));
        }
        out
    }
}

fn corner(x: usize, y: usize, z: usize) -> DVec3 {
    DVec3::new([LO[0], HI[0]][x], [LO[1], HI[1]][y], [LO[2], HI[2]][z])
}

/// Marks of the room's twelve edges and of a box's vertical edges, plus named points.
fn synthetic_marks(sigma: f64, seed: u64) -> (MarksFile, Synth) {
    let (r, h) = truth();
    let synth = Synth {
        world_from_probe: r,
        probe: DVec3::new(0.0, h, 0.0),
        views: views(),
    };
    let mut rng = Pcg32::seed_from_u64(seed);
    let mut per_view: Vec<ViewMarks> = synth
        .views
        .iter()
        .enumerate()
        .map(|(k, v)| ViewMarks {
            name: format!("view{k}"),
            camera: *v,
            lines: Vec::new(),
            points: Vec::new(),
        })
        .collect();
    let mut edges = Vec::new();
    for i in 0..2 {
        for j in 0..2 {
            edges.push((Axis::X, corner(0, i, j), corner(1, i, j)));
            edges.push((Axis::Y, corner(i, 0, j), corner(i, 1, j)));
            edges.push((Axis::Z, corner(i, j, 0), corner(i, j, 1)));
        }
    }
    // A table's edges (x and z lines at its top, y lines at its legs).
    let (t0, t1) = (DVec3::new(0.5, 0.0, -1.9), DVec3::new(1.7, 0.75, -1.1));
    edges.push((
        Axis::X,
        DVec3::new(t0.x, t1.y, t1.z),
        DVec3::new(t1.x, t1.y, t1.z),
    ));
    edges.push((
        Axis::Z,
        DVec3::new(t1.x, t1.y, t0.z),
        DVec3::new(t1.x, t1.y, t1.z),
    ));
    edges.push((
        Axis::Y,
        DVec3::new(t1.x, 0.0, t1.z),
        DVec3::new(t1.x, t1.y, t1.z),
    ));
    edges.push((
        Axis::Y,
        DVec3::new(t0.x, 0.0, t1.z),
        DVec3::new(t0.x, t1.y, t1.z),
    ));
    for (axis, a, b) in edges {
        for (k, mark) in synth.segment_marks(axis, a, b, sigma, &mut rng) {
            per_view[k].lines.push(mark);
        }
    }
    let window = [DVec3::new(-1.0, 0.9, LO[2]), DVec3::new(0.6, 2.1, LO[2])];
    let door = [DVec3::new(HI[0], 0.0, -0.5), DVec3::new(HI[0], 2.05, 0.4)];
    let named: Vec<(String, DVec3)> = vec![
        ("c0".into(), corner(0, 0, 0)),
        ("c1".into(), corner(1, 0, 0)),
        ("c2".into(), corner(1, 0, 1)),
        ("c3".into(), corner(0, 0, 1)),
        ("k0".into(), corner(0, 1, 0)),
        ("k2".into(), corner(1, 1, 1)),
        ("w0".into(), window[0]),
        ("w1".into(), window[1]),
        ("d0".into(), door[0]),
        ("d1".into(), door[1]),
        ("t0".into(), DVec3::new(t0.x, 0.0, t1.z)),
        ("t1".into(), DVec3::new(t1.x, 0.0, t1.z)),
        ("t2".into(), DVec3::new(t1.x, 0.0, t0.z)),
        ("t1top".into(), DVec3::new(t1.x, t1.y, t1.z)),
    ];
    for (name, p) in named {
        let (k, px) = synth.best_view(p);
        per_view[k].points.push(PointMark {
            name,
            at: [
                px[0] + sigma * gaussian(&mut rng),
                px[1] + sigma * gaussian(&mut rng),
            ],
        });
    }
    let group = |name: &str, light: bool| ibl_room::description::GroupDescription {
        name: name.into(),
        kind: if light {
            ibl_room::GroupKind::Light
        } else {
            ibl_room::GroupKind::Surface
        },
        measured_reflectance: None,
    };
    let marks = MarksFile {
        format: MARKS_FORMAT.into(),
        probe: None,
        views: per_view,
        scale: vec![
            ScaleMark::Vertical {
                lower: "c0".into(),
                upper: "k0".into(),
                distance_m: HI[1] - LO[1],
            },
            ScaleMark::Vertical {
                lower: "c2".into(),
                upper: "k2".into(),
                distance_m: HI[1] - LO[1],
            },
        ],
        groups: vec![
            group("wall", false),
            group("floor", false),
            group("ceiling", false),
            group("window", true),
            group("door", false),
            group("table", false),
        ],
        shapes: vec![
            ShapeMark::Room {
                name: None,
                floor_corners: vec!["c0".into(), "c1".into(), "c2".into(), "c3".into()],
                ceiling_m: None,
                ceiling_point: Some("k2".into()),
                ceiling_above: Some("c2".into()),
                wall_group: "wall".into(),
                wall_groups: Default::default(),
                floor_group: "floor".into(),
                ceiling_group: "ceiling".into(),
            },
            ShapeMark::Opening {
                name: Some("window".into()),
                wall: ibl_room::description::BoxFace::NegZ,
                corners: ["w0".into(), "w1".into()],
                group: "window".into(),
                to_floor: false,
            },
            ShapeMark::Opening {
                name: Some("door".into()),
                wall: ibl_room::description::BoxFace::PosX,
                corners: ["d0".into(), "d1".into()],
                group: "door".into(),
                to_floor: true,
            },
            ShapeMark::Box {
                name: "table".into(),
                group: "table".into(),
                face_groups: Default::default(),
                footprint: vec!["t0".into(), "t1".into(), "t2".into()],
                against: Vec::new(),
                top_m: None,
                top_point: Some("t1top".into()),
                top_above: Some("t1".into()),
                to_ceiling: false,
            },
            ShapeMark::Mirror {
                name: "table2".into(),
                of: "table".into(),
                axis: Axis::X,
                through: None,
                at_m: Some(0.0),
            },
        ],
        patch_area_m2: Some(0.1),
    };
    (marks, synth)
}

fn angle_deg(a: DMat3, b: DMat3) -> f64 {
    let m = a.transpose() * b;
    // atan2 of the rotation's sine and cosine: accurate for small angles (acos is not).
    let skew = glam::DVec3::new(
        m.y_axis.z - m.z_axis.y,
        m.z_axis.x - m.x_axis.z,
        m.x_axis.y - m.y_axis.x,
    );
    (0.5 * skew.length())
        .atan2(0.5 * (m.x_axis.x + m.y_axis.y + m.z_axis.z - 1.0))
        .to_degrees()
}

#[test]
fn calibration_with_one_pixel_noise_is_within_a_fifth_of_a_degree() {
    let (r, h) = truth();
    let mut worst_angle = 0.0f64;
    let mut worst_scale = 0.0f64;
    let mut worst_residual = 0.0f64;
    for seed in 1..=8 {
        let (marks, _) = synthetic_marks(1.0, seed);
        let text = marks.to_json().expect("json");
        let marks = MarksFile::from_json(&text).expect("the file reads back");
        let lines = line_observations(&marks);
        assert!(lines.len() >= 20, "{} lines", lines.len());
        let calibration = calibrate(&lines).expect("calibration");
        let angle = angle_deg(calibration.world_from_probe(), r);
        let scale = probe_height(&marks, calibration.world_from_probe()).expect("scale");
        let scale_error = (scale.probe_height_m - h).abs() / h;
        worst_angle = worst_angle.max(angle);
        worst_scale = worst_scale.max(scale_error);
        // The residuals show the noise: 1 pixel at the ends of segments 80 pixels and longer
        // tilts a circle by up to about 1 degree (measured RMS at most 0.53 degrees).
        for vp in &calibration.vanishing_points {
            worst_residual = worst_residual.max(vp.rms_residual_deg);
            assert!(vp.rms_residual_deg < 1.0, "{vp:?}");
        }
    }
    // Issue 16: rotation within 0.2 degrees, scale within 1 %, with 1-pixel noise; over eight
    // noise draws the worst measured 0.0xx degrees and 0.x % (printed below).
    println!(
        "worst rotation error {worst_angle:.4} deg, scale error {:.3} %, residual {worst_residual:.3} deg",
        100.0 * worst_scale
    );
    assert!(worst_angle < 0.2, "{worst_angle}");
    assert!(worst_scale < 0.01, "{worst_scale}");
}

#[test]
fn noise_free_marks_give_the_exact_frame_and_room() {
    let (r, h) = truth();
    let (marks, _) = synthetic_marks(0.0, 1);
    let calibration = calibrate(&line_observations(&marks)).expect("calibration");
    // Exact marks: f64 rounding only (measured 1e-6 degrees).
    assert!(angle_deg(calibration.world_from_probe(), r) < 1e-4);
    assert!(calibration.rms_residual_deg < 1e-4);
    let scale = probe_height(&marks, calibration.world_from_probe()).expect("scale");
    assert!((scale.probe_height_m - h).abs() < 1e-6);
    let file = reconstruct(&marks, &calibration, &scale, "probe.exr").expect("room");
    let boxes = &file.room.boxes;
    assert_eq!(boxes.len(), 3);
    let close = |a: [f32; 3], b: [f64; 3]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (f64::from(*x) - y).abs() < 1e-4)
    };
    assert!(
        close(boxes[0].min, LO) && close(boxes[0].max, HI),
        "{:?}",
        boxes[0]
    );
    assert!(close(boxes[1].min, [0.5, 0.0, -1.9]) && close(boxes[1].max, [1.7, 0.75, -1.1]));
    // The mirror across x = 0.
    assert!(close(boxes[2].min, [-1.7, 0.0, -1.9]) && close(boxes[2].max, [-0.5, 0.75, -1.1]));
    let openings = &boxes[0].openings;
    assert_eq!(openings.len(), 2);
    let close2 = |a: [f32; 2], b: [f64; 2]| {
        a.iter()
            .zip(b)
            .all(|(x, y)| (f64::from(*x) - y).abs() < 1e-4)
    };
    assert!(close2(openings[0].min, [-1.0, 0.9]) && close2(openings[0].max, [0.6, 2.1]));
    assert!(close2(openings[1].min, [-0.5, 0.0]) && close2(openings[1].max, [0.4, 2.05]));
    assert!((f64::from(file.probe.position[1]) - h).abs() < 1e-5);
    // The room file round-trips through TOML and builds a room.
    let text = file.to_toml().expect("toml");
    let back = ibl_room::RoomFile::from_toml(&text).expect("reads back");
    assert_eq!(back, file);
    ibl_room::Room::from_file(&back).expect("a valid room");
}

#[test]
fn a_vanishing_point_in_one_view_is_the_ray_through_it() {
    // The paper's image-plane vanishing point: two image lines of one axis meet at (x, y), and
    // the direction through that pixel is the least-squares point on the sphere.
    let (marks, _) = synthetic_marks(0.0, 1);
    let view = &marks.views[0];
    let x_lines: Vec<&LineMark> = view.lines.iter().filter(|l| l.axis == Axis::X).collect();
    assert!(x_lines.len() >= 2);
    let line = |l: &LineMark| {
        let p = DVec3::new(l.from[0], l.from[1], 1.0);
        let q = DVec3::new(l.to[0], l.to[1], 1.0);
        p.cross(q)
    };
    let vp = line(x_lines[0]).cross(line(x_lines[1]));
    let (px, py) = (vp.x / vp.z, vp.y / vp.z);
    let through = view.camera.direction(px, py);
    let calibration = calibrate(&line_observations(&marks)).expect("calibration");
    let x = DVec3::from_array(calibration.vanishing_points[0].direction);
    assert!(through.cross(x).length() < 1e-6, "{through} vs {x}");
}

#[test]
fn marks_file_errors_name_the_field() {
    let (marks, _) = synthetic_marks(0.0, 1);
    let good = marks.to_json().expect("json");
    let cases = [
        (
            good.replacen("iblkit.marks/1", "iblkit.marks/9", 1),
            "format",
        ),
        (
            good.replacen("\"axis\": \"x\"", "\"axis\": \"w\"", 1),
            "views[0].lines[0].axis",
        ),
        (
            good.replacen(
                "\"vertical_fov_deg\": 100.0",
                "\"vertical_fov_deg\": 200.0",
                1,
            ),
            "views[0].camera.vertical_fov_deg",
        ),
        (
            good.replacen("\"lower\": \"c0\"", "\"lower\": \"nowhere\"", 1),
            "scale[0].lower",
        ),
        (
            good.replacen("\"wall_group\": \"wall\"", "\"wall_group\": \"paint\"", 1),
            "shapes[0].wall_group",
        ),
        ("{".to_string(), "json"),
        ("[]".to_string(), "json"),
    ];
    for (text, field) in cases {
        match MarksFile::from_json(&text) {
            Err(ibl_room::RoomError::Invalid { field: f, problem }) => {
                assert_eq!(f, field, "{problem}");
            }
            other => panic!("{field}: {other:?}"),
        }
    }
}
