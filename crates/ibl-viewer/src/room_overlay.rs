//! The room overlays of the probe viewer (Grosch 2005 section 3.1, docs/ROOMS.md): the lines of
//! a marks file and the edges of a reconstructed room drawn over the panorama in the current
//! view, as plain geometry: arcs of directions in, segments in output pixels out (the GPU draws
//! them, [`crate::lines_pass`]).
//!
//! Frames: the probe viewer's world frame is the probe's own frame (its lat-long layout,
//! CONVENTIONS section 2), the frame in which `ibl_room::PerspectiveView` turns a marks file's
//! views. A **marked line** joins two pixels of the view it was marked in; on the sphere of
//! directions around the probe it is the shorter great-circle arc between the directions of its
//! ends (both lie in front of that view, and so does the arc). A **room edge** joins two world
//! points (metres); seen from the probe centre `p` it is the arc between the probe directions
//! `world_from_probe^T (a - p)` and `world_from_probe^T (b - p)` (the room file's `probe.position`
//! and `rotation_deg`). A great circle projects to a straight line in any pinhole view, so the part
//! of an arc in front of the current perspective view is exactly one straight segment (the line
//! is straight in the view it was marked in, and wherever else it is seen); in the flat lat-long
//! view an arc is a curve, sampled every [`ARC_STEP_DEG`] and cut where it crosses the seam.
//! Everything is f64 until the output pixels.
//!
//! Colours: lines by their axis, x red, y green, z blue (as `room_views` draws them), with a disc
//! at each marked end; room edges white.

use std::collections::BTreeSet;
use std::f64::consts::PI;

use glam::{DMat3, DVec2, DVec3};
use ibl_core::LatLong;
use ibl_room::geometry::{Face, FaceShape};
use ibl_room::marks::{Axis, LineMark, MarksFile};
use ibl_room::{PerspectiveView, Room};

use crate::lines_pass::LineSegment;
use crate::probe_model::ProbeViewSettings;
use crate::probe_pass::ProbeProjection;
use crate::view_camera::OrbitControl;

/// Largest angle between two sampled directions of an arc in the flat view, degrees.
pub const ARC_STEP_DEG: f64 = 1.0;
/// Display colours of the marked lines by axis (x, y, z): pure red, green, blue.
pub const AXIS_COLOURS: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 1.0],
    [0.0, 1.0, 0.0, 1.0],
    [0.0, 0.0, 1.0, 1.0],
];
/// Display colour of the room's edges: white.
pub const ROOM_EDGE_COLOUR: [f32; 4] = [1.0, 1.0, 1.0, 1.0];
/// Half-width of every overlay line, pixels (at one pixel per point): lines 2 pixels wide.
pub const LINE_HALF_WIDTH_PX: f32 = 1.0;
/// Radius of the disc at each end of a marked line, pixels (at one pixel per point).
pub const END_RADIUS_PX: f32 = 3.5;

/// A direction is in front of a perspective view when its unit view-frame z is below
/// `-FRONT_MARGIN`: at most `1 / FRONT_MARGIN` focal lengths off the picture's centre, far
/// beyond any frame, which keeps every projected pixel finite.
const FRONT_MARGIN: f64 = 1e-9;
/// How far beyond the frame a segment is kept when clipped, pixels (wider than any line).
const CLIP_MARGIN_PX: f64 = 16.0;

/// The display colour of a marked line of `axis`.
pub fn axis_colour(axis: Axis) -> [f32; 4] {
    AXIS_COLOURS[axis.index()]
}

/// The shorter great-circle arc between two unit directions, probe frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionArc {
    /// Where it starts (unit).
    pub from: DVec3,
    /// Where it ends (unit).
    pub to: DVec3,
}

impl DirectionArc {
    /// The shorter arc from `a` to `b` (any lengths: they are normalised); `None` when either is
    /// zero or not finite, or they are (nearly) opposite, so that no arc is the shorter.
    pub fn new(a: DVec3, b: DVec3) -> Option<DirectionArc> {
        let (from, to) = (a.try_normalize()?, b.try_normalize()?);
        let arc = DirectionArc { from, to };
        (arc.angle_rad() < PI - 1e-6).then_some(arc)
    }

    /// The angle between its ends, radians.
    pub fn angle_rad(&self) -> f64 {
        self.from
            .cross(self.to)
            .length()
            .atan2(self.from.dot(self.to))
    }

    /// The unit direction a fraction `t` of the way along (constant angular speed; exactly the
    /// ends at `t = 0` and `t = 1`).
    pub fn at(&self, t: f64) -> DVec3 {
        if t <= 0.0 {
            return self.from;
        }
        if t >= 1.0 {
            return self.to;
        }
        let angle = self.angle_rad();
        if angle < 1e-9 {
            return self.from.lerp(self.to, t).normalize_or(self.from);
        }
        let w0 = ((1.0 - t) * angle).sin();
        let w1 = (t * angle).sin();
        (self.from * w0 + self.to * w1).normalize_or(self.from)
    }

    /// How many pieces of at most `step_rad` radians cover it (at least 1).
    pub fn pieces(&self, step_rad: f64) -> usize {
        let n = (self.angle_rad() / step_rad.max(1e-6)).ceil();
        (n as usize).clamp(1, 100_000)
    }
}

/// The view the overlays are drawn in: the probe viewer's current frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OverlayView {
    /// Looking around from the probe centre: the pinhole the frame was drawn with.
    Perspective(PerspectiveView),
    /// The flat lat-long picture of `width x height` pixels (`x = u W`, `y = v H`).
    LatLong {
        /// Width, pixels.
        width: u32,
        /// Height, pixels.
        height: u32,
    },
}

/// The marks file's view of the probe viewer's look-around camera at `width x height` pixels:
/// yaw, pitch and vertical field of view of `orbit` in degrees, no roll (the viewer has none).
/// The same pinhole as [`OrbitControl::camera`] (tested), so a pixel of this view is the pixel
/// the user saw.
pub fn perspective_view(orbit: &OrbitControl, width: u32, height: u32) -> PerspectiveView {
    PerspectiveView {
        yaw_deg: f64::from(orbit.yaw).to_degrees(),
        pitch_deg: f64::from(orbit.pitch).to_degrees(),
        roll_deg: 0.0,
        vertical_fov_deg: f64::from(orbit.vertical_fov).to_degrees(),
        width,
        height,
    }
}

impl OverlayView {
    /// The view of a probe frame of `width x height` pixels drawn with `settings`.
    pub fn of_settings(settings: &ProbeViewSettings, width: u32, height: u32) -> OverlayView {
        match settings.projection {
            ProbeProjection::LookAround => {
                OverlayView::Perspective(perspective_view(&settings.orbit, width, height))
            }
            ProbeProjection::LatLong => OverlayView::LatLong { width, height },
        }
    }

    /// The frame's size, pixels.
    pub fn size(&self) -> (u32, u32) {
        match *self {
            OverlayView::Perspective(v) => (v.width, v.height),
            OverlayView::LatLong { width, height } => (width, height),
        }
    }

    /// Output pixel coordinates of a probe direction; `None` when it is not in front of a
    /// perspective view.
    pub fn project(&self, d: DVec3) -> Option<DVec2> {
        match *self {
            OverlayView::Perspective(view) => {
                let front = (view.probe_from_view().transpose() * d.normalize_or_zero()).z;
                if front < -FRONT_MARGIN {
                    view.project(d).map(|(x, y)| DVec2::new(x, y))
                } else {
                    None
                }
            }
            OverlayView::LatLong { width, height } => {
                let (u, v) = LatLong::dir_to_uv(d.normalize_or(DVec3::NEG_Z));
                Some(DVec2::new(u * f64::from(width), v * f64::from(height)))
            }
        }
    }
}

/// The arc in `view` as polylines of output pixels: in a perspective view the one straight
/// segment of its part in front of the camera (none when it lies behind), in the lat-long view
/// a curve of samples at most [`ARC_STEP_DEG`] apart, cut where it crosses the seam (each piece
/// reaching past the frame's edge to where the other begins).
pub fn project_arc(arc: &DirectionArc, view: &OverlayView) -> Vec<Vec<DVec2>> {
    match *view {
        OverlayView::Perspective(v) => perspective_run(arc, &v).into_iter().collect(),
        OverlayView::LatLong { width, height } => latlong_curve(arc, width, height),
    }
}

/// The part of `arc` in front of `view` as its two projected ends. The directions in front form
/// one interval of the arc (a shorter arc meets an open hemisphere in one piece), found on the
/// samples and refined at a cut end by bisection.
fn perspective_run(arc: &DirectionArc, view: &PerspectiveView) -> Option<Vec<DVec2>> {
    let view_from_probe = view.probe_from_view().transpose();
    let front = |t: f64| (view_from_probe * arc.at(t)).z < -FRONT_MARGIN;
    let n = arc.pieces(ARC_STEP_DEG.to_radians());
    let t = |k: usize| k as f64 / n as f64;
    let first = (0..=n).find(|&k| front(t(k)))?;
    let last = (first..=n).rev().find(|&k| front(t(k)))?;
    // Bisection between a parameter behind (`out`) and one in front (`inside`): 60 halvings of
    // at most a degree reach f64's resolution.
    let edge = |mut out: f64, mut inside: f64| {
        for _ in 0..60 {
            let mid = 0.5 * (out + inside);
            if front(mid) {
                inside = mid;
            } else {
                out = mid;
            }
        }
        inside
    };
    let t0 = if first == 0 {
        0.0
    } else {
        edge(t(first - 1), t(first))
    };
    let t1 = if last == n {
        1.0
    } else {
        edge(t(last + 1), t(last))
    };
    let project = |t: f64| view.project(arc.at(t)).map(|(x, y)| DVec2::new(x, y));
    Some(vec![project(t0)?, project(t1)?])
}

/// `arc` in the lat-long picture, cut at the seam.
fn latlong_curve(arc: &DirectionArc, width: u32, height: u32) -> Vec<Vec<DVec2>> {
    let (w, h) = (f64::from(width), f64::from(height));
    let n = arc.pieces(ARC_STEP_DEG.to_radians());
    let mut curves = Vec::new();
    let mut curve: Vec<DVec2> = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let (u, v) = LatLong::dir_to_uv(arc.at(k as f64 / n as f64));
        let p = DVec2::new(u * w, v * h);
        if let Some(&q) = curve.last()
            && (p.x - q.x).abs() > 0.5 * w
        {
            // Across the seam: this piece goes on past its edge, the next starts past the other.
            let shift = if p.x > q.x { -w } else { w };
            curve.push(DVec2::new(p.x + shift, p.y));
            curves.push(std::mem::take(&mut curve));
            curve.push(DVec2::new(q.x - shift, q.y));
        }
        curve.push(p);
    }
    curves.push(curve);
    curves
}

/// The part of segment `a b` inside the frame of `size` pixels widened by a margin
/// (Liang-Barsky); `None` when none is, or an end is not finite.
pub fn clip_to_frame(a: DVec2, b: DVec2, size: (u32, u32)) -> Option<(DVec2, DVec2)> {
    if !(a.is_finite() && b.is_finite()) {
        return None;
    }
    let (lo, hi) = (
        DVec2::splat(-CLIP_MARGIN_PX),
        DVec2::new(f64::from(size.0), f64::from(size.1)) + CLIP_MARGIN_PX,
    );
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                if r > t1 {
                    return None;
                }
                t0 = t0.max(r);
            } else {
                if r < t0 {
                    return None;
                }
                t1 = t1.min(r);
            }
        }
    }
    Some((a + d * t0, a + d * t1))
}

fn pixel(p: DVec2) -> [f32; 2] {
    [p.x as f32, p.y as f32]
}

/// The segments of `polylines` that fall in the frame of `size` pixels, clipped to it; where two
/// of one polyline join (not at a clipped end), each stops at the cut across their mean tangent.
pub fn polyline_segments(
    polylines: &[Vec<DVec2>],
    size: (u32, u32),
    half_width: f32,
    colour: [f32; 4],
) -> Vec<LineSegment> {
    let mut out = Vec::new();
    for line in polylines {
        let mut points: Vec<DVec2> = Vec::with_capacity(line.len());
        for &p in line {
            if points.last().is_none_or(|q| (p - *q).length() > 1e-9) {
                points.push(p);
            }
        }
        let direction = |k: usize| (points[k + 1] - points[k]).try_normalize();
        let cut = |a: Option<DVec2>, b: Option<DVec2>| {
            let t = (a? + b?).try_normalize()?;
            Some([t.x as f32, t.y as f32])
        };
        let last = points.len().saturating_sub(2);
        for k in 0..points.len().saturating_sub(1) {
            let (a, b) = (points[k], points[k + 1]);
            let Some((ca, cb)) = clip_to_frame(a, b, size) else {
                continue;
            };
            let mut s = LineSegment::new(pixel(ca), pixel(cb), half_width, colour);
            if k > 0 && ca == a {
                s.cut_from = cut(direction(k - 1), direction(k)).unwrap_or([0.0; 2]);
            }
            if k < last && cb == b {
                s.cut_to = cut(direction(k), direction(k + 1)).unwrap_or([0.0; 2]);
            }
            out.push(s);
        }
    }
    out
}

/// A marked line as the arc it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarkedArc {
    /// The world axis it was assigned to.
    pub axis: Axis,
    /// The arc between its ends' directions.
    pub arc: DirectionArc,
}

/// The arc of a line marked in `view`: between the probe directions of its end pixels (`None`
/// when both are one direction).
pub fn line_arc(view: &PerspectiveView, line: &LineMark) -> Option<DirectionArc> {
    DirectionArc::new(
        view.direction(line.from[0], line.from[1]),
        view.direction(line.to[0], line.to[1]),
    )
}

/// Every marked line of every view of `marks`, in file order.
pub fn marked_arcs(marks: &MarksFile) -> Vec<MarkedArc> {
    marks
        .views
        .iter()
        .flat_map(|v| {
            v.lines
                .iter()
                .filter_map(|l| line_arc(&v.camera, l).map(|arc| MarkedArc { axis: l.axis, arc }))
        })
        .collect()
}

/// Every edge of `faces` (rectangle outlines, their holes' outlines, polygon sides), world
/// frame, metres, in face order; an edge two faces share (a filled opening and its hole, two
/// faces of a box) once.
pub fn face_edges(faces: &[Face]) -> Vec<[DVec3; 2]> {
    let mut seen = BTreeSet::new();
    let mut edges = Vec::new();
    // Ends to 0.1 mm, in either order.
    let key = |p: DVec3| (p * 1e4).round().to_array().map(|c| c as i64);
    let mut add = |a: DVec3, b: DVec3| {
        let (ka, kb) = (key(a), key(b));
        if ka != kb && seen.insert(if ka < kb { (ka, kb) } else { (kb, ka) }) {
            edges.push([a, b]);
        }
    };
    for face in faces {
        let at = |s: f32, t: f32| face.point(s, t).as_dvec3();
        let outline = |add: &mut dyn FnMut(DVec3, DVec3), corners: &[DVec3]| {
            for (k, &a) in corners.iter().enumerate() {
                add(a, corners[(k + 1) % corners.len()]);
            }
        };
        match &face.shape {
            FaceShape::Rectangle { size, holes } => {
                let [u, v] = *size;
                outline(&mut add, &[at(0.0, 0.0), at(u, 0.0), at(u, v), at(0.0, v)]);
                for h in holes {
                    outline(
                        &mut add,
                        &[
                            at(h[0], h[1]),
                            at(h[2], h[1]),
                            at(h[2], h[3]),
                            at(h[0], h[3]),
                        ],
                    );
                }
            }
            FaceShape::Polygon { points } => {
                let corners: Vec<DVec3> = points.iter().map(|p| at(p.x, p.y)).collect();
                outline(&mut add, &corners);
            }
        }
    }
    edges
}

/// World segments seen from the probe centre `probe_position` (world, metres) as arcs of probe
/// directions, `world_from_probe^T (p - probe_position)`; a segment through the centre is left
/// out.
pub fn edge_arcs(
    edges: &[[DVec3; 2]],
    probe_position: DVec3,
    world_from_probe: DMat3,
) -> Vec<DirectionArc> {
    let probe_from_world = world_from_probe.transpose();
    edges
        .iter()
        .filter_map(|[a, b]| {
            DirectionArc::new(
                probe_from_world * (*a - probe_position),
                probe_from_world * (*b - probe_position),
            )
        })
        .collect()
}

/// What the room overlays draw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoomOverlay {
    /// The marked lines.
    pub marks: Vec<MarkedArc>,
    /// The room's edges seen from its probe.
    pub edges: Vec<DirectionArc>,
}

impl RoomOverlay {
    /// The overlay of a marks file's lines and a room's edges (its faces seen from its probe).
    pub fn new(marks: Option<&MarksFile>, room: Option<&Room>) -> RoomOverlay {
        RoomOverlay {
            marks: marks.map(marked_arcs).unwrap_or_default(),
            edges: room.map(room_arcs).unwrap_or_default(),
        }
    }

    /// Whether it draws nothing.
    pub fn is_empty(&self) -> bool {
        self.marks.is_empty() && self.edges.is_empty()
    }

    /// The segments to draw in `view`, sizes times `scale` (pixels per point): the room's edges
    /// in white, then the marked lines in their axis's colour with a disc at each end.
    pub fn segments(&self, view: &OverlayView, scale: f32) -> Vec<LineSegment> {
        let mut out = Vec::new();
        for edge in &self.edges {
            out.extend(polyline_segments(
                &project_arc(edge, view),
                view.size(),
                LINE_HALF_WIDTH_PX * scale,
                ROOM_EDGE_COLOUR,
            ));
        }
        for line in &self.marks {
            marked_segments(line, view, scale, &mut out);
        }
        out
    }
}

/// The room's face edges as arcs from its probe.
pub fn room_arcs(room: &Room) -> Vec<DirectionArc> {
    edge_arcs(
        &face_edges(&room.faces),
        room.probe_position.as_dvec3(),
        room.world_from_probe.as_dmat3(),
    )
}

/// Appends a marked line's segments in `view` to `out`: the line, then a disc at each end in
/// front of the view.
pub fn marked_segments(
    line: &MarkedArc,
    view: &OverlayView,
    scale: f32,
    out: &mut Vec<LineSegment>,
) {
    let colour = axis_colour(line.axis);
    out.extend(polyline_segments(
        &project_arc(&line.arc, view),
        view.size(),
        LINE_HALF_WIDTH_PX * scale,
        colour,
    ));
    for end in [line.arc.from, line.arc.to] {
        if let Some(p) = view.project(end)
            && clip_to_frame(p, p, view.size()).is_some()
        {
            out.push(LineSegment::new(
                pixel(p),
                pixel(p),
                END_RADIUS_PX * scale,
                colour,
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_room::RoomFile;

    fn view(yaw_deg: f64, pitch_deg: f64, roll_deg: f64) -> PerspectiveView {
        PerspectiveView {
            yaw_deg,
            pitch_deg,
            roll_deg,
            vertical_fov_deg: 75.0,
            width: 640,
            height: 480,
        }
    }

    fn apartment_marks() -> MarksFile {
        MarksFile::from_json(include_str!("../../../assets/rooms/apartment/marks.json"))
            .expect("the worked example's marks")
    }

    fn apartment_room() -> Room {
        let file = RoomFile::from_toml(include_str!("../../../assets/rooms/apartment/room.toml"))
            .expect("the worked example's room");
        Room::from_file(&file).expect("resolves")
    }

    #[test]
    fn marked_lines_project_back_to_their_pixels_in_their_own_view() {
        let marks = apartment_marks();
        let mut checked = 0;
        for v in &marks.views {
            for line in &v.lines {
                let arc = line_arc(&v.camera, line).expect("distinct ends");
                let runs = project_arc(&arc, &OverlayView::Perspective(v.camera));
                assert_eq!(runs.len(), 1, "one straight segment");
                let [a, b] = [runs[0][0], runs[0][1]];
                // f64 through a normalised direction and back: 1e-9 px measured, 1e-6 asked.
                for (p, q) in [(a, line.from), (b, line.to)] {
                    assert!(
                        (p - DVec2::from_array(q)).length() < 1e-6,
                        "{p} vs {q:?} in view {}",
                        v.name
                    );
                }
                checked += 1;
            }
        }
        assert_eq!(checked, 13, "every line of the worked example");
    }

    #[test]
    fn a_line_is_straight_in_another_view_and_cut_where_it_goes_behind() {
        let marked = view(10.0, -5.0, 2.0);
        let line = LineMark {
            axis: Axis::X,
            from: [40.0, 300.0],
            to: [600.0, 120.0],
        };
        let arc = line_arc(&marked, &line).expect("an arc");
        // Seen from a view turned 50 degrees: the arc's part in front is one straight segment,
        // and every sample of the arc in front lies on it.
        let other = view(60.0, 10.0, 0.0);
        let ov = OverlayView::Perspective(other);
        let runs = project_arc(&arc, &ov);
        assert_eq!(runs.len(), 1);
        let (a, b) = (runs[0][0], runs[0][1]);
        let along = (b - a).normalize();
        for k in 0..=20 {
            if let Some(p) = ov.project(arc.at(k as f64 / 20.0)) {
                let off = (p - a).perp_dot(along).abs();
                assert!(off < 1e-6 * (p - a).length().max(1.0), "{off} px off");
            }
        }
        // Seen from behind: nothing.
        let behind = OverlayView::Perspective(view(190.0, 5.0, 0.0));
        assert!(project_arc(&arc, &behind).is_empty());
        // Half behind: the run ends at the horizon of the view, far outside the frame.
        let side = OverlayView::Perspective(view(100.0, 0.0, 0.0));
        let runs = project_arc(&arc, &side);
        assert_eq!(runs.len(), 1);
        let far = runs[0][0].length().max(runs[0][1].length());
        assert!(far > 1e5, "the cut end is at {far} px");
    }

    #[test]
    fn room_edges_land_where_the_view_projects_their_corners() {
        let room = apartment_room();
        let edges = face_edges(&room.faces);
        // The shell box's 12 edges and 4 openings' 4 each; a filled opening shares its hole's.
        assert_eq!(edges.len(), 12 + 4 * 4);
        let position = room.probe_position.as_dvec3();
        let world_from_probe = room.world_from_probe.as_dmat3();
        let probe_from_world = world_from_probe.transpose();
        let arcs = edge_arcs(&edges, position, world_from_probe);
        assert_eq!(arcs.len(), edges.len());
        let mut checked = 0;
        for (edge, arc) in edges.iter().zip(&arcs) {
            // A view looking at the edge's midpoint, wide enough for both ends to lie in front.
            let mid = probe_from_world * (0.5 * (edge[0] + edge[1]) - position);
            let yaw = (-mid.x).atan2(-mid.z).to_degrees();
            let pitch = (mid.y / mid.length())
                .asin()
                .to_degrees()
                .clamp(-80.0, 80.0);
            let v = PerspectiveView {
                vertical_fov_deg: 150.0,
                ..view(yaw, pitch, 0.0)
            };
            let (Some(pa), Some(pb)) = (
                v.project(probe_from_world * (edge[0] - position)),
                v.project(probe_from_world * (edge[1] - position)),
            ) else {
                continue;
            };
            let runs = project_arc(arc, &OverlayView::Perspective(v));
            assert_eq!(runs.len(), 1);
            for (p, q) in [(runs[0][0], pa), (runs[0][1], pb)] {
                let q = DVec2::new(q.0, q.1);
                assert!((p - q).length() < 1e-6 * q.length().max(1.0), "{p} vs {q}");
            }
            // A point along the 3-D edge lands on the drawn segment.
            let inner = probe_from_world * (edge[0].lerp(edge[1], 0.3) - position);
            let (x, y) = v.project(inner).expect("in front");
            let (a, b) = (runs[0][0], runs[0][1]);
            let off = (DVec2::new(x, y) - a).perp_dot((b - a).normalize()).abs();
            assert!(off < 1e-6 * (b - a).length(), "{off} px off the segment");
            checked += 1;
        }
        assert!(checked >= 20, "{checked} edges checked");
    }

    #[test]
    fn the_overlay_view_is_the_viewer_camera() {
        let orbit = OrbitControl {
            target: glam::Vec3::ZERO,
            distance: 0.0,
            yaw: 0.7,
            pitch: -0.3,
            vertical_fov: 1.1,
        };
        let camera = orbit.camera(640, 480);
        let view = perspective_view(&orbit, 640, 480);
        for (x, y) in [(320.0, 240.0), (10.5, 20.25), (630.0, 470.0)] {
            let d = camera.ray(x, y);
            let (px, py) = view.project(d.as_dvec3()).expect("in front");
            // The f32 camera against the f64 view: 1e-3 px.
            assert!((px - f64::from(x)).abs() < 1e-3 && (py - f64::from(y)).abs() < 1e-3);
        }
    }

    #[test]
    fn the_flat_view_cuts_an_arc_at_the_seam() {
        // Behind the probe (+Z is u = 0 and 1), crossing the seam.
        let arc = DirectionArc::new(DVec3::new(-0.3, 0.2, 1.0), DVec3::new(0.4, -0.1, 1.0))
            .expect("an arc");
        let view = OverlayView::LatLong {
            width: 512,
            height: 256,
        };
        let curves = project_arc(&arc, &view);
        assert_eq!(curves.len(), 2);
        // Each piece reaches past its edge of the picture.
        let xs: Vec<f64> = curves.iter().flatten().map(|p| p.x).collect();
        assert!(xs.iter().any(|&x| x < 0.0) && xs.iter().any(|&x| x > 512.0));
        // Samples are the arc's directions in the lat-long layout.
        for p in curves.iter().flatten() {
            assert!((0.0..=256.0).contains(&p.y));
        }
        let start = view.project(arc.from).expect("always");
        assert!((curves[0][0] - start).length() < 1e-9);
    }

    #[test]
    fn segments_are_clipped_to_the_frame() {
        let size = (100, 50);
        let (a, b) = clip_to_frame(DVec2::new(-1e9, 25.0), DVec2::new(1e9, 25.0), size)
            .expect("crosses the frame");
        assert!((a.x + CLIP_MARGIN_PX).abs() < 1e-6 && (b.x - 100.0 - CLIP_MARGIN_PX).abs() < 1e-6);
        assert!(clip_to_frame(DVec2::new(-500.0, -500.0), DVec2::new(-400.0, 0.0), size).is_none());
        assert!(clip_to_frame(DVec2::new(f64::NAN, 0.0), DVec2::ZERO, size).is_none());
    }

    #[test]
    fn the_overlay_colours_lines_by_axis_and_edges_white() {
        let marks = apartment_marks();
        let room = apartment_room();
        let overlay = RoomOverlay::new(Some(&marks), Some(&room));
        assert_eq!(overlay.marks.len(), 13);
        let front = OverlayView::Perspective(marks.views[0].camera);
        let segments = overlay.segments(&front, 1.0);
        // The front view's five lines, each with its two ends, in its axis's colour.
        for line in &marks.views[0].lines {
            let colour = axis_colour(line.axis);
            let ends = segments
                .iter()
                .filter(|s| s.from == s.to && s.colour == colour)
                .filter(|s| {
                    [line.from, line.to].iter().any(|q| {
                        (f64::from(s.from[0]) - q[0]).abs() < 1e-3
                            && (f64::from(s.from[1]) - q[1]).abs() < 1e-3
                    })
                })
                .count();
            assert!(ends >= 2, "{line:?}: {ends} end discs");
        }
        assert!(segments.iter().any(|s| s.colour == ROOM_EDGE_COLOUR));
        // The flat view draws every line and edge somewhere.
        let flat = overlay.segments(
            &OverlayView::LatLong {
                width: 512,
                height: 256,
            },
            1.0,
        );
        let lines = flat
            .iter()
            .filter(|s| s.colour != ROOM_EDGE_COLOUR && s.from != s.to);
        assert!(lines.count() >= 13);
        assert!(flat.iter().filter(|s| s.colour == ROOM_EDGE_COLOUR).count() >= 28);
    }
}
