//! `[room]`: the room of Grosch 2005 (sections 3.1 to 3.3) that `ibl room` reconstructs and
//! estimates, validated field by field. Documented for users in `docs/SCENES.md` (section
//! `[room]`) and `docs/ROOMS.md`.
//!
//! A room is a set of planar surfaces in the **world frame** of `docs/CONVENTIONS.md` (+Y up,
//! -Z forward, +X right), lengths in **metres**, each assigned to a **material group**:
//! - `[[room.rectangle]]`: a corner and two orthogonal edges (front side `edge_u x edge_v`),
//!   with optional rectangular holes, each left open or filled by another group (a window in a
//!   wall);
//! - `[[room.box]]`: an axis-aligned box, faces outward (furniture) or inward (the room's shell),
//!   one group for all faces or one per face, faces left out (the bottom of a box standing on the
//!   floor), openings in faces (windows and doors of the shell);
//! - `[[room.polygon]]`: a planar simple polygon, counter-clockwise seen from its front.
//!
//! A group is a `surface` (its reflectance is estimated) or a `light` (a window or lamp: its
//! radiosity comes from the probe and it gets no reflectance). The patch area threshold of section
//! 3.3 (`patch_area_m2`) says how finely every surface is cut into patches.
//!
//! A **room file** is a scene file with a `[probe]` and a `[room]` table: the probe's `position`
//! and `rotation_deg` (`world_from_probe`) place the probe in the room. This module holds the
//! data and its checks only; the faces, patches and radiosity are `ibl-room`'s.
//!
//! Every error names the field by its path (`room.box[1].openings[0].min`).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::field::{DescriptionError, invalid};
use crate::polygon::polygon_frame;

/// Smallest accepted patch area threshold, m^2 (1 cm x 1 cm).
pub const MIN_PATCH_AREA_M2: f32 = 1e-4;
/// Largest accepted patch area threshold, m^2.
pub const MAX_PATCH_AREA_M2: f32 = 100.0;
/// Largest accepted coordinate magnitude, metres (a room, not a city).
pub const MAX_COORDINATE_M: f32 = 1e4;

/// The `[room]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoomDescription {
    /// Largest patch area, m^2 (Grosch section 3.3's area threshold).
    #[serde(default = "default_patch_area")]
    pub patch_area_m2: f32,
    /// Material groups (`[[room.group]]`).
    #[serde(default, rename = "group", skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<GroupDescription>,
    /// Rectangles (`[[room.rectangle]]`).
    #[serde(default, rename = "rectangle", skip_serializing_if = "Vec::is_empty")]
    pub rectangles: Vec<RectangleDescription>,
    /// Boxes (`[[room.box]]`).
    #[serde(default, rename = "box", skip_serializing_if = "Vec::is_empty")]
    pub boxes: Vec<BoxDescription>,
    /// Polygons (`[[room.polygon]]`).
    #[serde(default, rename = "polygon", skip_serializing_if = "Vec::is_empty")]
    pub polygons: Vec<PolygonDescription>,
}

fn default_patch_area() -> f32 {
    0.05
}

/// A material group.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupDescription {
    /// Unique name (`wall`, `floor`, `window`).
    pub name: String,
    /// Whether the group reflects light (estimated) or is a light source (from the probe).
    #[serde(default)]
    pub kind: GroupKind,
    /// A reflectance measured by other means, linear RGB in [0, 1]: shown beside the estimate
    /// (Grosch's "Real" column of Table 1) and used as the albedo when a synthetic room is
    /// rendered. Surfaces only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_reflectance: Option<[f32; 3]>,
}

/// What a group is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupKind {
    /// A diffuse reflector: `rho = B / E` is estimated.
    #[default]
    Surface,
    /// A light source (window, lamp): radiosity from the probe, no reflectance.
    Light,
}

impl GroupKind {
    /// The name used in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            GroupKind::Surface => "surface",
            GroupKind::Light => "light",
        }
    }
}

/// A rectangle: `corner + s edge_u + t edge_v` for `s, t` in [0, 1]; front side `edge_u x edge_v`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleDescription {
    /// Name in messages and reports (default `rectangle[i]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Material group.
    pub group: String,
    /// One corner, world frame, metres.
    pub corner: [f32; 3],
    /// First edge from the corner, metres.
    pub edge_u: [f32; 3],
    /// Second edge from the corner, metres, orthogonal to `edge_u`.
    pub edge_v: [f32; 3],
    /// Rectangular holes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub holes: Vec<HoleDescription>,
}

/// A hole in a rectangle, in metres along `edge_u` and `edge_v` from the corner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HoleDescription {
    /// Lower corner `(s, t)`, metres along the edges.
    pub min: [f32; 2],
    /// Upper corner `(s, t)`, metres along the edges.
    pub max: [f32; 2],
    /// A group filling the hole flush with the rectangle (a window, a door); open if absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<String>,
}

/// An axis-aligned box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxDescription {
    /// Name in messages and reports (default `box[i]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Lower corner, world frame, metres.
    pub min: [f32; 3],
    /// Upper corner, world frame, metres; larger than `min` on every axis.
    pub max: [f32; 3],
    /// Which way the faces' fronts point.
    #[serde(default)]
    pub facing: Facing,
    /// Material group of every face not in `face_groups`.
    pub group: String,
    /// Material group per face (`"+y" = "table_top"`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub face_groups: BTreeMap<BoxFace, String>,
    /// Faces left out (the bottom of a box on the floor, the back against a wall).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub omit: Vec<BoxFace>,
    /// Openings in faces (windows and doors of a room's shell).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub openings: Vec<OpeningDescription>,
}

/// Which way a box's faces point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Facing {
    /// Fronts outside (furniture).
    #[default]
    Outward,
    /// Fronts inside (the room's shell seen from the probe).
    Inward,
}

/// A face of an axis-aligned box, by the axis and side of its plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum BoxFace {
    /// The face at `max.x`.
    #[serde(rename = "+x")]
    PosX,
    /// The face at `min.x`.
    #[serde(rename = "-x")]
    NegX,
    /// The face at `max.y` (a box's top, a room's ceiling).
    #[serde(rename = "+y")]
    PosY,
    /// The face at `min.y` (a box's bottom, a room's floor).
    #[serde(rename = "-y")]
    NegY,
    /// The face at `max.z`.
    #[serde(rename = "+z")]
    PosZ,
    /// The face at `min.z`.
    #[serde(rename = "-z")]
    NegZ,
}

impl BoxFace {
    /// All six, in file order.
    pub const ALL: [BoxFace; 6] = [
        BoxFace::PosX,
        BoxFace::NegX,
        BoxFace::PosY,
        BoxFace::NegY,
        BoxFace::PosZ,
        BoxFace::NegZ,
    ];

    /// The name used in files (`+x`).
    pub fn name(self) -> &'static str {
        match self {
            BoxFace::PosX => "+x",
            BoxFace::NegX => "-x",
            BoxFace::PosY => "+y",
            BoxFace::NegY => "-y",
            BoxFace::PosZ => "+z",
            BoxFace::NegZ => "-z",
        }
    }

    /// The world axis normal to the face (0 = x, 1 = y, 2 = z).
    pub fn axis(self) -> usize {
        match self {
            BoxFace::PosX | BoxFace::NegX => 0,
            BoxFace::PosY | BoxFace::NegY => 1,
            BoxFace::PosZ | BoxFace::NegZ => 2,
        }
    }

    /// Whether the face lies at the box's `max` (else `min`) on its axis.
    pub fn at_max(self) -> bool {
        matches!(self, BoxFace::PosX | BoxFace::PosY | BoxFace::PosZ)
    }

    /// The two world axes `(u, v)` an opening's coordinates run along: x faces `(z, y)`, y faces
    /// `(x, z)`, z faces `(x, y)`.
    pub fn in_plane_axes(self) -> (usize, usize) {
        match self.axis() {
            0 => (2, 1),
            1 => (0, 2),
            _ => (0, 1),
        }
    }

    /// The face of `axis` at `max` or `min`.
    pub fn of_axis(axis: usize, at_max: bool) -> BoxFace {
        match (axis, at_max) {
            (0, true) => BoxFace::PosX,
            (0, false) => BoxFace::NegX,
            (1, true) => BoxFace::PosY,
            (1, false) => BoxFace::NegY,
            (_, true) => BoxFace::PosZ,
            (_, false) => BoxFace::NegZ,
        }
    }
}

/// An opening in a box face, in **world coordinates** along the face's two in-plane axes
/// ([`BoxFace::in_plane_axes`]: `[z, y]` on x faces, `[x, z]` on y faces, `[x, y]` on z faces).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpeningDescription {
    /// The face.
    pub face: BoxFace,
    /// Lower corner, metres, world coordinates along the face's axes.
    pub min: [f32; 2],
    /// Upper corner, metres.
    pub max: [f32; 2],
    /// A group filling the opening flush with the face (a window, a door); open if absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fill: Option<String>,
}

/// A planar simple polygon, counter-clockwise seen from its front.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolygonDescription {
    /// Name in messages and reports (default `polygon[i]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Material group.
    pub group: String,
    /// At least three vertices, world frame, metres, in one plane.
    pub vertices: Vec<[f32; 3]>,
}

/// Largest number of vertices of one polygon.
pub const MAX_POLYGON_VERTICES: usize = 256;
/// Largest number of surfaces (rectangles, boxes and polygons together) and of groups.
pub const MAX_SURFACES: usize = 10_000;

impl RoomDescription {
    /// Checks every value, naming the field at fault (paths start with `room.`).
    pub fn validate(&self) -> Result<(), DescriptionError> {
        let a = self.patch_area_m2;
        if !(a.is_finite() && (MIN_PATCH_AREA_M2..=MAX_PATCH_AREA_M2).contains(&a)) {
            return Err(invalid(
                "room.patch_area_m2",
                format!("{a} is not in [{MIN_PATCH_AREA_M2}, {MAX_PATCH_AREA_M2}] m^2"),
            ));
        }
        if self.groups.is_empty() {
            return Err(invalid(
                "room.group",
                "a room needs at least one [[room.group]]",
            ));
        }
        let surfaces = self.rectangles.len() + self.boxes.len() + self.polygons.len();
        if surfaces == 0 {
            return Err(invalid(
                "room",
                "a room needs at least one rectangle, box or polygon",
            ));
        }
        if surfaces > MAX_SURFACES || self.groups.len() > MAX_SURFACES {
            return Err(invalid(
                "room",
                format!(
                    "{surfaces} surfaces and {} groups (at most {MAX_SURFACES} each)",
                    self.groups.len()
                ),
            ));
        }
        let mut kinds = BTreeMap::new();
        for (i, g) in self.groups.iter().enumerate() {
            let field = format!("room.group[{i}]");
            if g.name.trim().is_empty() {
                return Err(invalid(format!("{field}.name"), "is empty"));
            }
            if kinds.insert(g.name.as_str(), g.kind).is_some() {
                return Err(invalid(
                    format!("{field}.name"),
                    format!("group `{}` is defined twice", g.name),
                ));
            }
            if let Some(r) = g.measured_reflectance {
                if g.kind == GroupKind::Light {
                    return Err(invalid(
                        format!("{field}.measured_reflectance"),
                        "a light group has no reflectance",
                    ));
                }
                if !r.iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c)) {
                    return Err(invalid(
                        format!("{field}.measured_reflectance"),
                        format!("{r:?} is not a reflectance in [0, 1]"),
                    ));
                }
            }
        }
        let group = |field: String, name: &str| -> Result<(), DescriptionError> {
            if kinds.contains_key(name) {
                Ok(())
            } else {
                Err(invalid(
                    field,
                    format!("no [[room.group]] is named `{name}`"),
                ))
            }
        };
        for (i, r) in self.rectangles.iter().enumerate() {
            let field = format!("room.rectangle[{i}]");
            group(format!("{field}.group"), &r.group)?;
            r.validate(&field)?;
            for (k, h) in r.holes.iter().enumerate() {
                if let Some(fill) = &h.fill {
                    group(format!("{field}.holes[{k}].fill"), fill)?;
                }
            }
        }
        for (i, b) in self.boxes.iter().enumerate() {
            let field = format!("room.box[{i}]");
            group(format!("{field}.group"), &b.group)?;
            for (face, g) in &b.face_groups {
                group(format!("{field}.face_groups.{}", face.name()), g)?;
            }
            b.validate(&field)?;
            for (k, o) in b.openings.iter().enumerate() {
                if let Some(fill) = &o.fill {
                    group(format!("{field}.openings[{k}].fill"), fill)?;
                }
            }
        }
        for (i, p) in self.polygons.iter().enumerate() {
            let field = format!("room.polygon[{i}]");
            group(format!("{field}.group"), &p.group)?;
            p.validate(&field)?;
        }
        Ok(())
    }

    /// The index of the group named `name`.
    pub fn group_index(&self, name: &str) -> Option<usize> {
        self.groups.iter().position(|g| g.name == name)
    }
}

impl RectangleDescription {
    fn validate(&self, field: &str) -> Result<(), DescriptionError> {
        coordinate3(&format!("{field}.corner"), self.corner)?;
        coordinate3(&format!("{field}.edge_u"), self.edge_u)?;
        coordinate3(&format!("{field}.edge_v"), self.edge_v)?;
        let u = glam::Vec3::from(self.edge_u);
        let v = glam::Vec3::from(self.edge_v);
        let (lu, lv) = (u.length(), v.length());
        if lu < 1e-3 || lv < 1e-3 {
            return Err(invalid(
                format!("{field}.edge_{}", if lu < 1e-3 { "u" } else { "v" }),
                "is shorter than 1 mm",
            ));
        }
        // Orthogonal to 1e-3 rad: the rectangle's corners stay within 1 mm per metre of a
        // true rectangle, below any reconstruction's accuracy.
        if (u.dot(v) / (lu * lv)).abs() > 1e-3 {
            return Err(invalid(
                format!("{field}.edge_v"),
                "is not orthogonal to edge_u (|cos| > 1e-3)",
            ));
        }
        let rects: Vec<(usize, [f32; 2], [f32; 2])> = self
            .holes
            .iter()
            .enumerate()
            .map(|(k, h)| (k, h.min, h.max))
            .collect();
        holes(field, "holes", &rects, [lu, lv])
    }
}

impl BoxDescription {
    fn validate(&self, field: &str) -> Result<(), DescriptionError> {
        coordinate3(&format!("{field}.min"), self.min)?;
        coordinate3(&format!("{field}.max"), self.max)?;
        for axis in 0..3 {
            if self.max[axis] - self.min[axis] < 1e-3 {
                return Err(invalid(
                    format!("{field}.max"),
                    format!(
                        "{:?} is not above min {:?} by at least 1 mm on every axis",
                        self.max, self.min
                    ),
                ));
            }
        }
        for (k, face) in self.omit.iter().enumerate() {
            if self.omit[..k].contains(face) {
                return Err(invalid(
                    format!("{field}.omit[{k}]"),
                    format!("face {} is listed twice", face.name()),
                ));
            }
        }
        if self.omit.len() == 6 {
            return Err(invalid(format!("{field}.omit"), "leaves out every face"));
        }
        for face in BoxFace::ALL {
            let (ua, va) = face.in_plane_axes();
            let rects: Vec<(usize, [f32; 2], [f32; 2])> = self
                .openings
                .iter()
                .enumerate()
                .filter(|(_, o)| o.face == face)
                .map(|(k, o)| {
                    (
                        k,
                        [o.min[0] - self.min[ua], o.min[1] - self.min[va]],
                        [o.max[0] - self.min[ua], o.max[1] - self.min[va]],
                    )
                })
                .collect();
            if let Some(&(k, _, _)) = rects.first()
                && self.omit.contains(&face)
            {
                return Err(invalid(
                    format!("{field}.openings[{k}].face"),
                    format!("face {} is omitted", face.name()),
                ));
            }
            let size = [self.max[ua] - self.min[ua], self.max[va] - self.min[va]];
            holes(field, "openings", &rects, size)?;
        }
        Ok(())
    }

    /// The group of `face`.
    pub fn face_group(&self, face: BoxFace) -> &str {
        self.face_groups.get(&face).unwrap_or(&self.group)
    }
}

impl PolygonDescription {
    fn validate(&self, field: &str) -> Result<(), DescriptionError> {
        let n = self.vertices.len();
        if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
            return Err(invalid(
                format!("{field}.vertices"),
                format!("has {n} vertices (3 to {MAX_POLYGON_VERTICES})"),
            ));
        }
        for (k, v) in self.vertices.iter().enumerate() {
            coordinate3(&format!("{field}.vertices[{k}]"), *v)?;
        }
        polygon_frame(&self.vertices)
            .map(|_| ())
            .map_err(|problem| invalid(format!("{field}.vertices"), problem))
    }
}

/// Checks rectangular holes `(index in the list, min, max)` in a `size[0] x size[1]` rectangle
/// (coordinates from its corner): inside, at least 1 mm wide, not overlapping each other.
fn holes(
    field: &str,
    list: &str,
    rects: &[(usize, [f32; 2], [f32; 2])],
    size: [f32; 2],
) -> Result<(), DescriptionError> {
    // Holes may touch the rectangle's border within 0.1 mm of rounding.
    const SLACK: f32 = 1e-4;
    for (n, &(k, lo, hi)) in rects.iter().enumerate() {
        let f = format!("{field}.{list}[{k}]");
        if !(lo.iter().chain(hi.iter()).all(|c| c.is_finite())) {
            return Err(invalid(format!("{f}.min"), "is not finite"));
        }
        if hi[0] - lo[0] < 1e-3 || hi[1] - lo[1] < 1e-3 {
            return Err(invalid(
                format!("{f}.max"),
                "is not above min by at least 1 mm on both axes",
            ));
        }
        if lo[0] < -SLACK || lo[1] < -SLACK {
            return Err(invalid(format!("{f}.min"), "lies outside the surface"));
        }
        if hi[0] > size[0] + SLACK || hi[1] > size[1] + SLACK {
            return Err(invalid(format!("{f}.max"), "lies outside the surface"));
        }
        for &(j, lo2, hi2) in &rects[..n] {
            let overlap = lo[0] < hi2[0] - SLACK
                && lo2[0] < hi[0] - SLACK
                && lo[1] < hi2[1] - SLACK
                && lo2[1] < hi[1] - SLACK;
            if overlap {
                return Err(invalid(f.clone(), format!("overlaps {list}[{j}]")));
            }
        }
    }
    Ok(())
}

fn coordinate3(field: &str, v: [f32; 3]) -> Result<(), DescriptionError> {
    if v.iter()
        .all(|x| x.is_finite() && x.abs() <= MAX_COORDINATE_M)
    {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v:?} is not finite or beyond {MAX_COORDINATE_M} m"),
        ))
    }
}
