//! Shapes placed by constraints on marked points (Grosch 2005, section 3.1: "simple geometric
//! primitives like rectangles or boxes can be placed in the scene using constraints like
//! coplanarity, parallelism, orthogonality and symmetry", after van den Heuvel 1998), and the
//! room file they make.
//!
//! The calibrated frame makes every box axis-aligned (parallel and orthogonal to the room's
//! walls by construction); the scale puts the probe at `(0, h, 0)` above the floor `y = 0`. A
//! marked point becomes a 3D point by the constraint its use implies:
//! - **on the floor**: the probe ray through it meets `y = 0`;
//! - **on a wall**: the ray meets the wall's plane (an opening's corners);
//! - **above a floor point**: the point of the vertical line through that floor point closest to
//!   the ray (a box's top corner above its bottom corner, the ceiling above a floor corner).
//!
//! Shapes (`shapes` in the marks file, resolved in order):
//! - `room`: the shell, an inward box over the extent of its marked floor corners, up to the
//!   ceiling; one wall group (or one per wall), a floor and a ceiling group;
//! - `opening`: a window or door in a wall of the shell through two opposite marked corners,
//!   filled by its group (`to_floor` extends it down to the floor: a door);
//! - `box`: furniture standing on the floor over the extent of its marked footprint points,
//!   `against` walls extending it to them (its faces there and its bottom are left out: they
//!   lie on other surfaces), the top at a height, above a marked point, or at the ceiling;
//! - `mirror`: the mirror image of an earlier box across a plane `axis = c` through a marked floor
//!   point or at a given coordinate (symmetry).

use std::collections::BTreeMap;

use glam::{DMat3, DVec3};
use ibl_scene::description::ProbeDescription;

use crate::RoomError;
use crate::description::{
    BoxDescription, BoxFace, Facing, OpeningDescription, ROOM_FORMAT_VERSION, RoomDescription,
    RoomFile,
};
use crate::marks::MarksFile;
pub use crate::marks::ShapeMark;
use crate::scale::{Scale, point_direction};
use crate::vanishing::Calibration;

/// Marked points as world points under a calibration and scale.
struct Points<'a> {
    marks: &'a MarksFile,
    world_from_probe: DMat3,
    probe: DVec3,
}

impl Points<'_> {
    fn direction(&self, name: &str) -> Result<DVec3, RoomError> {
        point_direction(self.marks, self.world_from_probe, name)
    }

    /// Where the ray of `name` meets the plane `axis = value`.
    fn on_plane(
        &self,
        field: &str,
        name: &str,
        axis: usize,
        value: f64,
    ) -> Result<DVec3, RoomError> {
        let d = self.direction(name)?;
        let t = (value - self.probe[axis]) / d[axis];
        if !(t.is_finite() && t > 1e-6) {
            return Err(RoomError::invalid(
                field,
                format!(
                    "the ray of point `{name}` does not meet the plane {} = {value:.3} m in front \
                     of the probe",
                    ["x", "y", "z"][axis]
                ),
            ));
        }
        Ok(self.probe + d * t)
    }

    fn on_floor(&self, field: &str, name: &str) -> Result<DVec3, RoomError> {
        self.on_plane(field, name, 1, 0.0)
    }

    /// Height of the point of the vertical through `base` closest to the ray of `name`.
    fn above(&self, field: &str, name: &str, base: DVec3) -> Result<f64, RoomError> {
        let d = self.direction(name)?;
        let w = base - self.probe;
        let denom = 1.0 - d.y * d.y;
        if denom < 1e-9 {
            return Err(RoomError::invalid(
                field,
                format!("point `{name}` is straight up or down: it fixes no height"),
            ));
        }
        let s = (d.y * d.dot(w) - w.y) / denom;
        Ok(base.y + s)
    }
}

fn extent(points: &[DVec3], axis: usize) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[axis]), hi.max(p[axis]))
        })
}

/// The room file the marks' shapes make under `calibration` and `scale`, with the probe's file
/// name `probe_file`.
pub fn reconstruct(
    marks: &MarksFile,
    calibration: &Calibration,
    scale: &Scale,
    probe_file: &str,
) -> Result<RoomFile, RoomError> {
    let h = scale.probe_height_m;
    let pts = Points {
        marks,
        world_from_probe: calibration.world_from_probe(),
        probe: DVec3::new(0.0, h, 0.0),
    };
    let Some(ShapeMark::Room {
        name: room_name,
        floor_corners,
        ceiling_m,
        ceiling_point,
        ceiling_above,
        wall_group,
        wall_groups,
        floor_group,
        ceiling_group,
    }) = marks.shapes.first()
    else {
        return Err(RoomError::invalid(
            "shapes",
            "no `room` shape: nothing to reconstruct",
        ));
    };
    let corners: Vec<DVec3> = floor_corners
        .iter()
        .enumerate()
        .map(|(i, c)| pts.on_floor(&format!("shapes[0].floor_corners[{i}]"), c))
        .collect::<Result<_, _>>()?;
    let (x0, x1) = extent(&corners, 0);
    let (z0, z1) = extent(&corners, 2);
    if x1 - x0 < 0.1 || z1 - z0 < 0.1 {
        return Err(RoomError::invalid(
            "shapes[0].floor_corners",
            format!(
                "the corners span {:.3} m x {:.3} m: the room needs at least 10 cm on both axes",
                x1 - x0,
                z1 - z0
            ),
        ));
    }
    let ceiling = match (ceiling_m, ceiling_point, ceiling_above) {
        (Some(c), _, _) => *c,
        (None, Some(p), Some(a)) => {
            let base = pts.on_floor("shapes[0].ceiling_above", a)?;
            pts.above("shapes[0].ceiling_point", p, base)?
        }
        _ => return Err(RoomError::invalid("shapes[0]", "no ceiling height")),
    };
    if ceiling <= h {
        return Err(RoomError::invalid(
            "shapes[0]",
            format!("the ceiling ({ceiling:.3} m) is not above the probe ({h:.3} m)"),
        ));
    }
    let lo = [x0, 0.0, z0];
    let hi = [x1, ceiling, z1];
    let wall_plane = |face: BoxFace| -> f64 {
        if face.at_max() {
            hi[face.axis()]
        } else {
            lo[face.axis()]
        }
    };
    let mut face_groups = BTreeMap::new();
    face_groups.insert(BoxFace::NegY, floor_group.clone());
    face_groups.insert(BoxFace::PosY, ceiling_group.clone());
    for (face, g) in wall_groups {
        face_groups.insert(*face, g.clone());
    }
    let mut shell = BoxDescription {
        name: Some(room_name.clone().unwrap_or_else(|| "room".into())),
        min: lo.map(|v| v as f32),
        max: hi.map(|v| v as f32),
        facing: Facing::Inward,
        group: wall_group.clone(),
        face_groups,
        omit: Vec::new(),
        openings: Vec::new(),
    };
    let mut boxes: Vec<BoxDescription> = Vec::new();
    for (k, shape) in marks.shapes.iter().enumerate().skip(1) {
        let f = format!("shapes[{k}]");
        match shape {
            ShapeMark::Room { .. } => {
                return Err(RoomError::invalid(f, "a second room"));
            }
            ShapeMark::Opening {
                wall,
                corners,
                group,
                to_floor,
                ..
            } => {
                let (ua, va) = wall.in_plane_axes();
                let plane = wall_plane(*wall);
                let a =
                    pts.on_plane(&format!("{f}.corners[0]"), &corners[0], wall.axis(), plane)?;
                let b =
                    pts.on_plane(&format!("{f}.corners[1]"), &corners[1], wall.axis(), plane)?;
                let clamp_u = |v: f64| v.clamp(lo[ua], hi[ua]);
                let clamp_v = |v: f64| v.clamp(lo[va], hi[va]);
                let mut min = [clamp_u(a[ua].min(b[ua])), clamp_v(a[va].min(b[va]))];
                let max = [clamp_u(a[ua].max(b[ua])), clamp_v(a[va].max(b[va]))];
                if *to_floor {
                    min[1] = 0.0;
                }
                shell.openings.push(OpeningDescription {
                    face: *wall,
                    min: min.map(|v| v as f32),
                    max: max.map(|v| v as f32),
                    fill: Some(group.clone()),
                });
            }
            ShapeMark::Box {
                name,
                group,
                face_groups,
                footprint,
                against,
                top_m,
                top_point,
                top_above,
                to_ceiling,
            } => {
                let feet: Vec<DVec3> = footprint
                    .iter()
                    .enumerate()
                    .map(|(i, p)| pts.on_floor(&format!("{f}.footprint[{i}]"), p))
                    .collect::<Result<_, _>>()?;
                let (mut bx0, mut bx1) = extent(&feet, 0);
                let (mut bz0, mut bz1) = extent(&feet, 2);
                let mut omit = vec![BoxFace::NegY];
                for wall in against {
                    let plane = wall_plane(*wall);
                    match (wall.axis(), wall.at_max()) {
                        (0, true) => bx1 = plane,
                        (0, false) => bx0 = plane,
                        (_, true) => bz1 = plane,
                        (_, false) => bz0 = plane,
                    }
                    omit.push(*wall);
                }
                let top = match (top_m, top_point, top_above, to_ceiling) {
                    (Some(t), _, _, _) => *t,
                    (None, Some(p), Some(a), _) => {
                        let i = footprint.iter().position(|q| q == a).unwrap_or(0);
                        pts.above(&format!("{f}.top_point"), p, feet[i])?
                    }
                    (_, _, _, true) => ceiling,
                    _ => return Err(RoomError::invalid(f, "no top")),
                };
                if *to_ceiling {
                    omit.push(BoxFace::PosY);
                }
                if bx1 - bx0 < 0.01 || bz1 - bz0 < 0.01 || top < 0.01 {
                    return Err(RoomError::invalid(
                        format!("{f}.footprint"),
                        format!(
                            "box `{name}` would be {:.3} x {:.3} m, {top:.3} m high (at least 1 cm \
                             each): mark more footprint points or put it against a wall",
                            bx1 - bx0,
                            bz1 - bz0
                        ),
                    ));
                }
                boxes.push(BoxDescription {
                    name: Some(name.clone()),
                    min: [bx0, 0.0, bz0].map(|v| v as f32),
                    max: [bx1, top.min(ceiling), bz1].map(|v| v as f32),
                    facing: Facing::Outward,
                    group: group.clone(),
                    face_groups: face_groups.clone(),
                    omit,
                    openings: Vec::new(),
                });
            }
            ShapeMark::Mirror {
                name,
                of,
                axis,
                through,
                at_m,
            } => {
                let source = boxes
                    .iter()
                    .find(|b| b.name.as_deref() == Some(of.as_str()))
                    .cloned()
                    .ok_or_else(|| RoomError::invalid(format!("{f}.of"), "no such box"))?;
                let a = axis.index();
                let c = match (through, at_m) {
                    (Some(p), _) => pts.on_floor(&format!("{f}.through"), p)?[a],
                    (None, Some(c)) => *c,
                    _ => return Err(RoomError::invalid(f, "no mirror plane")),
                };
                let mut mirrored = source.clone();
                mirrored.name = Some(name.clone());
                mirrored.min[a] = (2.0 * c - f64::from(source.max[a])) as f32;
                mirrored.max[a] = (2.0 * c - f64::from(source.min[a])) as f32;
                let flip = |face: BoxFace| {
                    if face.axis() == a {
                        BoxFace::of_axis(a, !face.at_max())
                    } else {
                        face
                    }
                };
                mirrored.omit = source.omit.iter().map(|&f| flip(f)).collect();
                mirrored.face_groups = source
                    .face_groups
                    .iter()
                    .map(|(&f, g)| (flip(f), g.clone()))
                    .collect();
                boxes.push(mirrored);
            }
        }
    }
    let mut all = vec![shell];
    all.extend(boxes);
    let room = RoomDescription {
        patch_area_m2: marks.patch_area_m2.unwrap_or(0.05),
        groups: marks.groups.clone(),
        rectangles: Vec::new(),
        boxes: all,
        polygons: Vec::new(),
    };
    let rotation = calibration.rotation_deg;
    let file = RoomFile {
        version: ROOM_FORMAT_VERSION,
        probe: ProbeDescription {
            file: probe_file.into(),
            rotation_deg: rotation.map(|v| v as f32),
            radiance_scale: 1.0,
            position: [0.0, h as f32, 0.0],
        },
        room,
    };
    file.validate()?;
    Ok(file)
}
