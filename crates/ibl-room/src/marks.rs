//! The marks file (JSON, `"format": "iblkit.marks/1"`): what a user marked on perspective views
//! of the panorama (Grosch 2005, section 3.1: "the coordinate system is defined by picking
//! parallel lines and assigning them to vanishing points").
//!
//! Per view: the view itself ([`PerspectiveView`]), line segments each assigned to a world axis
//! (`x`, `y` = up, `z`), and named points. Then scale marks (the probe's height above the floor,
//! two points on one vertical line at a known distance, two floor points at a known distance) and
//! the shapes placed by constraints ([`crate::placement`]). Pixel coordinates are continuous
//! view coordinates (row 0 at the top; pixel `(i, j)` covers `[i, i + 1) x [j, j + 1)`).
//!
//! [`MarksFile::from_json`] is the only way in: it bounds the text's size and every count,
//! refuses unknown fields, checks every value and reference, and names the field at fault
//! (`views[1].lines[3].to`). It never panics (fuzzed: `fuzz/fuzz_targets/room_marks.rs`).

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};

use crate::RoomError;
use crate::description::{BoxFace, GroupDescription};
use crate::view::{MAX_VIEW_SIDE, PerspectiveView};

/// The format tag of version 1.
pub const MARKS_FORMAT: &str = "iblkit.marks/1";
/// Largest marks file, bytes.
pub const MAX_MARKS_BYTES: usize = 16 << 20;
/// Largest number of views, and of lines or points in all views together.
pub const MAX_MARKS: usize = 100_000;

/// A world axis a line is parallel to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    /// World +X (right).
    X,
    /// World +Y (up): vertical lines.
    Y,
    /// World +Z (backwards).
    Z,
}

impl Axis {
    /// All three.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        self as usize
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self as usize]
    }
}

/// A marks file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarksFile {
    /// [`MARKS_FORMAT`].
    pub format: String,
    /// The probe the marks were made on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<MarksProbe>,
    /// The views and what was marked on each.
    pub views: Vec<ViewMarks>,
    /// Scale marks (at least one to place shapes).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scale: Vec<ScaleMark>,
    /// Material groups of the shapes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupDescription>,
    /// Shapes placed by constraints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shapes: Vec<ShapeMark>,
    /// Largest patch area of the room made from the shapes, m^2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub patch_area_m2: Option<f32>,
}

/// Which probe the marks belong to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarksProbe {
    /// The probe's file, relative to the marks file.
    pub file: String,
    /// Its size, pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[u32; 2]>,
}

/// One view with its marks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewMarks {
    /// Name (unique).
    pub name: String,
    /// The view.
    pub camera: PerspectiveView,
    /// Segments along world axes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lines: Vec<LineMark>,
    /// Named points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<PointMark>,
}

/// A marked segment parallel to a world axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineMark {
    /// The axis it is parallel to.
    pub axis: Axis,
    /// One end, view pixels.
    pub from: [f64; 2],
    /// The other end, view pixels.
    pub to: [f64; 2],
}

/// A named point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointMark {
    /// Name, unique across all views.
    pub name: String,
    /// Position, view pixels.
    pub at: [f64; 2],
}

/// A mark fixing the scale of the reconstruction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ScaleMark {
    /// The probe centre's height above the floor.
    ProbeHeight {
        /// Metres.
        height_m: f64,
    },
    /// Two points on one vertical line, `lower` on the floor (Grosch: floor to ceiling).
    Vertical {
        /// The point on the floor.
        lower: String,
        /// The point above it.
        upper: String,
        /// Their distance, metres.
        distance_m: f64,
    },
    /// Two points on the floor.
    FloorDistance {
        /// First point.
        a: String,
        /// Second point.
        b: String,
        /// Their distance, metres.
        distance_m: f64,
    },
}

impl MarksFile {
    /// Parses and validates a marks file's text; errors name the field by its path.
    pub fn from_json(text: &str) -> Result<MarksFile, RoomError> {
        if text.len() > MAX_MARKS_BYTES {
            return Err(RoomError::Limits(format!(
                "the marks file is {} bytes (at most {MAX_MARKS_BYTES})",
                text.len()
            )));
        }
        let mut deserializer = serde_json::Deserializer::from_str(text);
        let file: MarksFile = serde_path_to_error::deserialize(&mut deserializer).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            RoomError::invalid(
                if path == "." || path == "?" {
                    "json".into()
                } else {
                    path
                },
                format!("{inner}"),
            )
        })?;
        deserializer
            .end()
            .map_err(|e| RoomError::invalid("json", e.to_string()))?;
        file.validate()?;
        Ok(file)
    }

    /// The file as pretty-printed JSON.
    pub fn to_json(&self) -> Result<String, RoomError> {
        serde_json::to_string_pretty(self)
            .map(|s| s + "\n")
            .map_err(|e| RoomError::Numerical(format!("writing JSON: {e}")))
    }

    /// Checks every value and reference.
    pub fn validate(&self) -> Result<(), RoomError> {
        if self.format != MARKS_FORMAT {
            return Err(RoomError::invalid(
                "format",
                format!("`{}` is not `{MARKS_FORMAT}`", self.format),
            ));
        }
        let lines: usize = self.views.iter().map(|v| v.lines.len()).sum();
        let points: usize = self.views.iter().map(|v| v.points.len()).sum();
        if self.views.len() > MAX_MARKS || lines > MAX_MARKS || points > MAX_MARKS {
            return Err(RoomError::Limits(format!(
                "{} views, {lines} lines, {points} points (at most {MAX_MARKS} each)",
                self.views.len()
            )));
        }
        let mut view_names = BTreeSet::new();
        let mut point_names = BTreeSet::new();
        for (v, view) in self.views.iter().enumerate() {
            let field = format!("views[{v}]");
            if !view_names.insert(view.name.as_str()) {
                return Err(RoomError::invalid(
                    format!("{field}.name"),
                    format!("view `{}` appears twice", view.name),
                ));
            }
            let c = &view.camera;
            for (name, value) in [
                ("yaw_deg", c.yaw_deg),
                ("pitch_deg", c.pitch_deg),
                ("roll_deg", c.roll_deg),
            ] {
                if !(value.is_finite() && value.abs() <= 720.0) {
                    return Err(RoomError::invalid(
                        format!("{field}.camera.{name}"),
                        format!("{value} is not a finite angle within 720 degrees"),
                    ));
                }
            }
            if !(c.vertical_fov_deg.is_finite()
                && c.vertical_fov_deg > 1.0
                && c.vertical_fov_deg < 170.0)
            {
                return Err(RoomError::invalid(
                    format!("{field}.camera.vertical_fov_deg"),
                    format!("{} is not in (1, 170)", c.vertical_fov_deg),
                ));
            }
            for (name, value) in [("width", c.width), ("height", c.height)] {
                if !(1..=MAX_VIEW_SIDE).contains(&value) {
                    return Err(RoomError::invalid(
                        format!("{field}.camera.{name}"),
                        format!("{value} is not in 1..={MAX_VIEW_SIDE}"),
                    ));
                }
            }
            let pixel = |f: String, p: [f64; 2]| -> Result<(), RoomError> {
                // Marks may lie outside the picture (a vanishing line's end), within reason.
                let limit = 4.0 * f64::from(MAX_VIEW_SIDE);
                if p.iter().all(|x| x.is_finite() && x.abs() <= limit) {
                    Ok(())
                } else {
                    Err(RoomError::invalid(
                        f,
                        format!("{p:?} is not a finite pixel position within {limit}"),
                    ))
                }
            };
            for (k, line) in view.lines.iter().enumerate() {
                let f = format!("{field}.lines[{k}]");
                pixel(format!("{f}.from"), line.from)?;
                pixel(format!("{f}.to"), line.to)?;
                let length = (line.to[0] - line.from[0]).hypot(line.to[1] - line.from[1]);
                if length < 2.0 {
                    return Err(RoomError::invalid(
                        format!("{f}.to"),
                        format!("the segment is {length:.2} pixels long (at least 2)"),
                    ));
                }
            }
            for (k, point) in view.points.iter().enumerate() {
                let f = format!("{field}.points[{k}]");
                pixel(format!("{f}.at"), point.at)?;
                if point.name.trim().is_empty() {
                    return Err(RoomError::invalid(format!("{f}.name"), "is empty"));
                }
                if !point_names.insert(point.name.as_str()) {
                    return Err(RoomError::invalid(
                        format!("{f}.name"),
                        format!("point `{}` is marked twice", point.name),
                    ));
                }
            }
        }
        let known = |f: String, name: &str| -> Result<(), RoomError> {
            if point_names.contains(name) {
                Ok(())
            } else {
                Err(RoomError::invalid(f, format!("no point is named `{name}`")))
            }
        };
        let positive = |f: String, v: f64| -> Result<(), RoomError> {
            if v.is_finite() && v > 0.0 && v < 1e4 {
                Ok(())
            } else {
                Err(RoomError::invalid(
                    f,
                    format!("{v} is not a positive distance below 10 km"),
                ))
            }
        };
        for (k, s) in self.scale.iter().enumerate() {
            let f = format!("scale[{k}]");
            match s {
                ScaleMark::ProbeHeight { height_m } => {
                    positive(format!("{f}.height_m"), *height_m)?;
                }
                ScaleMark::Vertical {
                    lower,
                    upper,
                    distance_m,
                } => {
                    known(format!("{f}.lower"), lower)?;
                    known(format!("{f}.upper"), upper)?;
                    positive(format!("{f}.distance_m"), *distance_m)?;
                }
                ScaleMark::FloorDistance { a, b, distance_m } => {
                    known(format!("{f}.a"), a)?;
                    known(format!("{f}.b"), b)?;
                    if a == b {
                        return Err(RoomError::invalid(
                            format!("{f}.b"),
                            "is the same point as a",
                        ));
                    }
                    positive(format!("{f}.distance_m"), *distance_m)?;
                }
            }
        }
        validate_shapes(self, &point_names)
    }

    /// The named point's view and pixel position.
    pub fn point(&self, name: &str) -> Option<(&PerspectiveView, [f64; 2])> {
        self.views.iter().find_map(|v| {
            v.points
                .iter()
                .find(|p| p.name == name)
                .map(|p| (&v.camera, p.at))
        })
    }
}

/// A shape placed by constraints (the marks file's `shapes`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeMark {
    /// The room's shell.
    Room {
        /// Name (default `room`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        /// Points where walls meet the floor (at least two, spanning both horizontal axes).
        floor_corners: Vec<String>,
        /// Ceiling height, metres ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ceiling_m: Option<f64>,
        /// ... or a point on the ceiling above a floor corner ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ceiling_point: Option<String>,
        /// ... namely this one.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ceiling_above: Option<String>,
        /// Group of the walls.
        wall_group: String,
        /// Group of particular walls (`"-z" = "window_wall"`).
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        wall_groups: BTreeMap<BoxFace, String>,
        /// Group of the floor.
        floor_group: String,
        /// Group of the ceiling.
        ceiling_group: String,
    },
    /// A window or door in a wall of the shell.
    Opening {
        /// Name for messages.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        /// The wall (a vertical face of the shell: `+x`, `-x`, `+z`, `-z`).
        wall: BoxFace,
        /// Two opposite corners marked on the wall.
        corners: [String; 2],
        /// The group filling it.
        group: String,
        /// Extend it down to the floor (a door).
        #[serde(default)]
        to_floor: bool,
    },
    /// Furniture standing on the floor.
    Box {
        /// Name (unique; `mirror` refers to it).
        name: String,
        /// Group of every face.
        group: String,
        /// Groups of particular faces.
        #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
        face_groups: BTreeMap<BoxFace, String>,
        /// Marked floor points at its base (at least one; the extent on each horizontal axis
        /// must be at least 1 cm after `against`).
        footprint: Vec<String>,
        /// Walls of the shell it stands against.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        against: Vec<BoxFace>,
        /// Height of its top, metres ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        top_m: Option<f64>,
        /// ... or a marked point of its top above a footprint point ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        top_point: Option<String>,
        /// ... namely this one ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        top_above: Option<String>,
        /// ... or up to the ceiling.
        #[serde(default)]
        to_ceiling: bool,
    },
    /// The mirror image of an earlier box.
    Mirror {
        /// Name (unique).
        name: String,
        /// The box mirrored.
        of: String,
        /// The axis normal to the mirror plane (`x` or `z`).
        axis: Axis,
        /// A marked floor point the plane passes through ...
        #[serde(default, skip_serializing_if = "Option::is_none")]
        through: Option<String>,
        /// ... or the plane's coordinate, metres.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        at_m: Option<f64>,
    },
}

/// Checks the shapes' references (points, groups, boxes, walls) before anything is solved.
pub(crate) fn validate_shapes(marks: &MarksFile, points: &BTreeSet<&str>) -> Result<(), RoomError> {
    let groups: BTreeSet<&str> = marks.groups.iter().map(|g| g.name.as_str()).collect();
    let point = |f: String, name: &str| -> Result<(), RoomError> {
        if points.contains(name) {
            Ok(())
        } else {
            Err(RoomError::invalid(f, format!("no point is named `{name}`")))
        }
    };
    let group = |f: String, name: &str| -> Result<(), RoomError> {
        if groups.contains(name) {
            Ok(())
        } else {
            Err(RoomError::invalid(f, format!("no group is named `{name}`")))
        }
    };
    let mut boxes = BTreeSet::new();
    let mut rooms = 0;
    for (k, shape) in marks.shapes.iter().enumerate() {
        let f = format!("shapes[{k}]");
        match shape {
            ShapeMark::Room {
                floor_corners,
                ceiling_m,
                ceiling_point,
                ceiling_above,
                wall_group,
                wall_groups,
                floor_group,
                ceiling_group,
                ..
            } => {
                rooms += 1;
                if k != 0 {
                    return Err(RoomError::invalid(
                        f,
                        "the room must be the first shape (the others refer to its walls)",
                    ));
                }
                if floor_corners.len() < 2 {
                    return Err(RoomError::invalid(
                        format!("{f}.floor_corners"),
                        "needs at least two points",
                    ));
                }
                for (i, c) in floor_corners.iter().enumerate() {
                    point(format!("{f}.floor_corners[{i}]"), c)?;
                }
                match (ceiling_m, ceiling_point, ceiling_above) {
                    (Some(h), None, None) => {
                        if !(h.is_finite() && *h > 0.0 && *h < 1e3) {
                            return Err(RoomError::invalid(
                                format!("{f}.ceiling_m"),
                                format!("{h} is not a height in (0, 1000) m"),
                            ));
                        }
                    }
                    (None, Some(p), Some(a)) => {
                        point(format!("{f}.ceiling_point"), p)?;
                        point(format!("{f}.ceiling_above"), a)?;
                    }
                    _ => {
                        return Err(RoomError::invalid(
                            f,
                            "give ceiling_m, or ceiling_point with ceiling_above",
                        ));
                    }
                }
                group(format!("{f}.wall_group"), wall_group)?;
                group(format!("{f}.floor_group"), floor_group)?;
                group(format!("{f}.ceiling_group"), ceiling_group)?;
                for (face, g) in wall_groups {
                    if face.axis() == 1 {
                        return Err(RoomError::invalid(
                            format!("{f}.wall_groups.{}", face.name()),
                            "is not a wall",
                        ));
                    }
                    group(format!("{f}.wall_groups.{}", face.name()), g)?;
                }
            }
            ShapeMark::Opening {
                wall,
                corners,
                group: g,
                ..
            } => {
                if wall.axis() == 1 {
                    return Err(RoomError::invalid(
                        format!("{f}.wall"),
                        format!("{} is not a wall", wall.name()),
                    ));
                }
                point(format!("{f}.corners[0]"), &corners[0])?;
                point(format!("{f}.corners[1]"), &corners[1])?;
                group(format!("{f}.group"), g)?;
            }
            ShapeMark::Box {
                name,
                group: g,
                face_groups,
                footprint,
                against,
                top_m,
                top_point,
                top_above,
                to_ceiling,
            } => {
                if !boxes.insert(name.as_str()) {
                    return Err(RoomError::invalid(
                        format!("{f}.name"),
                        format!("box `{name}` is defined twice"),
                    ));
                }
                group(format!("{f}.group"), g)?;
                for (face, fg) in face_groups {
                    group(format!("{f}.face_groups.{}", face.name()), fg)?;
                }
                if footprint.is_empty() {
                    return Err(RoomError::invalid(
                        format!("{f}.footprint"),
                        "needs at least one point",
                    ));
                }
                for (i, p) in footprint.iter().enumerate() {
                    point(format!("{f}.footprint[{i}]"), p)?;
                }
                for (i, wall) in against.iter().enumerate() {
                    if wall.axis() == 1 {
                        return Err(RoomError::invalid(
                            format!("{f}.against[{i}]"),
                            format!("{} is not a wall", wall.name()),
                        ));
                    }
                }
                match (top_m, top_point, top_above, to_ceiling) {
                    (Some(h), None, None, false) => {
                        if !(h.is_finite() && *h > 0.0 && *h < 1e3) {
                            return Err(RoomError::invalid(
                                format!("{f}.top_m"),
                                format!("{h} is not a height in (0, 1000) m"),
                            ));
                        }
                    }
                    (None, Some(p), Some(a), false) => {
                        point(format!("{f}.top_point"), p)?;
                        if !footprint.contains(a) {
                            return Err(RoomError::invalid(
                                format!("{f}.top_above"),
                                format!("`{a}` is not one of the footprint's points"),
                            ));
                        }
                    }
                    (None, None, None, true) => {}
                    _ => {
                        return Err(RoomError::invalid(
                            f,
                            "give top_m, top_point with top_above, or to_ceiling",
                        ));
                    }
                }
            }
            ShapeMark::Mirror {
                name,
                of,
                axis,
                through,
                at_m,
            } => {
                if !boxes.contains(of.as_str()) {
                    return Err(RoomError::invalid(
                        format!("{f}.of"),
                        format!("no earlier box is named `{of}`"),
                    ));
                }
                if *axis == Axis::Y {
                    return Err(RoomError::invalid(
                        format!("{f}.axis"),
                        "a mirror plane is vertical: x or z",
                    ));
                }
                match (through, at_m) {
                    (Some(p), None) => point(format!("{f}.through"), p)?,
                    (None, Some(c)) if c.is_finite() && c.abs() < 1e4 => {}
                    _ => {
                        return Err(RoomError::invalid(
                            f,
                            "give either through (a floor point) or at_m",
                        ));
                    }
                }
                if !boxes.insert(name.as_str()) {
                    return Err(RoomError::invalid(
                        format!("{f}.name"),
                        format!("box `{name}` is defined twice"),
                    ));
                }
            }
        }
    }
    if !marks.shapes.is_empty() && rooms != 1 {
        return Err(RoomError::invalid(
            "shapes",
            "the shapes need exactly one `room` (the first)",
        ));
    }
    Ok(())
}
