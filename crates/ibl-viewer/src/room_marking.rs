//! The window's room tools (Grosch 2005 section 3.1, docs/ROOMS.md): the marks being edited over
//! a probe, and the room shown with them, without any GUI code (the panel, [`crate::room_panel`],
//! and the pointer, [`crate::view_state`], drive it).
//!
//! A new line goes to the view named after the camera that showed it: its yaw, pitch, vertical
//! field of view and pixel size are the marks file's `PerspectiveView` (no roll: the viewer has
//! none), so the saved pixel ends mean exactly what the user saw. Lines are removed last first;
//! "calibrate" runs `ibl_pipeline::room_calibrate::calibrate_marks`, the calculation of `ibl room
//! calibrate`, on the marks as they are; "save" writes the marks file (naming the probe viewed,
//! relative to the file) atomically through `ibl-io`, never over the probe or the room file.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_pipeline::room_calibrate::calibrate_marks;
use ibl_pipeline::room_input::{read_marks, read_room};
use ibl_room::marks::{Axis, LineMark, MARKS_FORMAT, MarksFile, MarksProbe, ViewMarks};
use ibl_room::vanishing::LineObservation;
use ibl_room::{PerspectiveView, Room};

use crate::ViewerError;
use crate::lines_pass::LineSegment;
use crate::room_overlay::{
    MarkedArc, OverlayView, RoomOverlay, line_arc, marked_arcs, marked_segments, room_arcs,
};

/// Shortest line accepted, pixels (the marks file's own minimum).
pub const MIN_LINE_PX: f64 = 2.0;

/// A line being drawn: where the drag started, where the pointer is, in the view it started in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PendingLine {
    /// The view the drag started in.
    pub view: PerspectiveView,
    /// The axis it will be assigned.
    pub axis: Axis,
    /// Where the drag started, view pixels.
    pub from: [f64; 2],
    /// Where the pointer is, view pixels.
    pub to: [f64; 2],
}

/// One line's residual in a calibration.
#[derive(Clone, Debug, PartialEq)]
pub struct LineResidual {
    /// The view it was marked in.
    pub view: String,
    /// Its index among that view's lines.
    pub line: usize,
    /// Its axis.
    pub axis: Axis,
    /// Angle between its great circle and its axis's vanishing point, degrees.
    pub residual_deg: f64,
}

/// What "calibrate" found.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibrationSummary {
    /// `world_from_probe` as `[yaw, pitch, roll]` degrees (a room file's `probe.rotation_deg`).
    pub rotation_deg: [f64; 3],
    /// RMS residual over all lines, degrees.
    pub rms_residual_deg: f64,
    /// Each line's residual, in the marks file's order.
    pub lines: Vec<LineResidual>,
    /// The probe's height above the floor, metres, when the marks have scale marks.
    pub probe_height_m: Option<f64>,
    /// Seconds it took.
    pub seconds: f64,
}

impl CalibrationSummary {
    /// The largest line residual, degrees.
    pub fn max_residual_deg(&self) -> f64 {
        self.lines
            .iter()
            .map(|l| l.residual_deg)
            .fold(0.0, f64::max)
    }

    /// One line of text, as `ibl room calibrate` prints it.
    pub fn line(&self) -> String {
        let [y, p, r] = self.rotation_deg;
        format!(
            "{} lines: rotation [yaw, pitch, roll] [{y:.3}, {p:.3}, {r:.3}] deg, RMS residual \
             {:.3} deg (largest {:.3})",
            self.lines.len(),
            self.rms_residual_deg,
            self.max_residual_deg()
        )
    }
}

/// The room tools' state for one probe.
#[derive(Clone, Debug)]
pub struct RoomSession {
    /// The marks: those read from `--marks`, with the lines added and removed since.
    pub marks: MarksFile,
    /// The marks file read at the start, if any.
    pub marks_path: Option<PathBuf>,
    /// The probe viewed (the saved marks name it).
    pub probe_path: PathBuf,
    /// The probe file's size when it is lat-long (saved with the marks), pixels.
    probe_size: Option<[u32; 2]>,
    /// The room file shown, if any.
    pub room_path: Option<PathBuf>,
    /// What is drawn: the marks' lines (kept in step with `marks`) and the room's edges.
    overlay: RoomOverlay,
    /// Draw the marked lines.
    pub show_marks: bool,
    /// Draw the room's edges.
    pub show_room: bool,
    /// Whether a left-drag in the view draws a line (instead of turning the camera).
    pub marking: bool,
    /// The axis of the next line.
    pub axis: Axis,
    /// The line being drawn.
    pub pending: Option<PendingLine>,
    /// Why the last line drawn was not added (too short), until one is.
    pub refused: Option<String>,
    /// Names of the views lines were added to, in order (the last is removed first).
    added: Vec<String>,
    /// Views this session made (removed again when their last line is).
    made_views: BTreeSet<String>,
    /// The last calibration, or why it failed; cleared when the lines change.
    pub calibration: Option<Result<CalibrationSummary, String>>,
    /// Where "save marks" writes.
    pub save_path: String,
    /// What the last "save marks" did (the file written, or why not).
    pub saved: Option<Result<String, String>>,
}

/// The marks file's default save name: `<stem>-edited.json` beside `--marks`, or
/// `<probe stem>-marks.json` beside the probe.
pub fn default_marks_path(marks: Option<&Path>, probe: &Path) -> PathBuf {
    let stem = |p: &Path, fallback: &str| {
        p.file_stem()
            .map_or(fallback.to_string(), |s| s.to_string_lossy().into_owned())
    };
    match marks {
        Some(m) => m.with_file_name(format!("{}-edited.json", stem(m, "marks"))),
        None => probe.with_file_name(format!("{}-marks.json", stem(probe, "probe"))),
    }
}

/// The name of the view a camera makes: `yaw 24.0 pitch -5.0 fov 75.0 640x480`.
pub fn view_name(view: &PerspectiveView) -> String {
    let mut name = format!(
        "yaw {:.1} pitch {:.1} fov {:.1} {}x{}",
        view.yaw_deg, view.pitch_deg, view.vertical_fov_deg, view.width, view.height
    );
    if view.roll_deg != 0.0 {
        name += &format!(" roll {:.1}", view.roll_deg);
    }
    name
}

/// An empty marks file.
pub fn empty_marks() -> MarksFile {
    MarksFile {
        format: MARKS_FORMAT.to_string(),
        probe: None,
        views: Vec::new(),
        scale: Vec::new(),
        groups: Vec::new(),
        shapes: Vec::new(),
        patch_area_m2: None,
    }
}

/// `target` as seen from folder `folder`: relative where both resolve, else as given.
fn relative_to(target: &Path, folder: &Path) -> PathBuf {
    let absolute = |p: &Path| {
        p.canonicalize().unwrap_or_else(|_| {
            std::env::current_dir()
                .map(|d| d.join(p))
                .unwrap_or_else(|_| p.to_path_buf())
        })
    };
    let (t, f) = (absolute(target), absolute(folder));
    pathdiff::diff_paths(&t, &f).unwrap_or(t)
}

impl RoomSession {
    /// The tools for the probe at `probe_path` (its file's size `probe_size` when lat-long),
    /// with the marks of `marks` (or none) and the edges of the room file `room` (or none); a
    /// bad file is an error naming it.
    pub fn open(
        probe_path: &Path,
        probe_size: Option<[u32; 2]>,
        marks: Option<&Path>,
        room: Option<&Path>,
    ) -> Result<RoomSession, ViewerError> {
        let file = marks.map(read_marks).transpose()?;
        let room_input = room.map(read_room).transpose()?;
        Ok(RoomSession::new(
            probe_path,
            probe_size,
            file,
            marks,
            room_input.as_ref().map(|r| &r.room),
            room,
        ))
    }

    /// The tools over parsed marks (`None`: empty) read from `marks_path`, and `room`.
    pub fn new(
        probe_path: &Path,
        probe_size: Option<[u32; 2]>,
        marks: Option<MarksFile>,
        marks_path: Option<&Path>,
        room: Option<&Room>,
        room_path: Option<&Path>,
    ) -> RoomSession {
        let marks = marks.unwrap_or_else(empty_marks);
        RoomSession {
            overlay: RoomOverlay {
                marks: marked_arcs(&marks),
                edges: room.map(room_arcs).unwrap_or_default(),
            },
            marks,
            marks_path: marks_path.map(Path::to_path_buf),
            probe_path: probe_path.to_path_buf(),
            probe_size,
            room_path: room_path.map(Path::to_path_buf),
            show_marks: true,
            show_room: true,
            marking: false,
            axis: Axis::X,
            pending: None,
            refused: None,
            added: Vec::new(),
            made_views: BTreeSet::new(),
            calibration: None,
            save_path: default_marks_path(marks_path, probe_path)
                .display()
                .to_string(),
            saved: None,
        }
    }

    /// Lines marked in all views.
    pub fn line_count(&self) -> usize {
        self.marks.views.iter().map(|v| v.lines.len()).sum()
    }

    /// Lines per axis (x, y, z).
    pub fn lines_per_axis(&self) -> [usize; 3] {
        let mut n = [0; 3];
        for line in self.marks.views.iter().flat_map(|v| &v.lines) {
            n[line.axis.index()] += 1;
        }
        n
    }

    /// Edges of the room drawn (0 without a room).
    pub fn room_edges(&self) -> usize {
        self.overlay.edges.len()
    }

    fn changed(&mut self) {
        self.overlay.marks = marked_arcs(&self.marks);
        self.calibration = None;
    }

    /// Adds a line of `axis` from `from` to `to` (pixels of `view`) to the view of that camera
    /// (made, and named after it, when the marks have none). Refused (`Err` with the reason)
    /// when shorter than [`MIN_LINE_PX`] or not finite.
    pub fn add_line(
        &mut self,
        view: PerspectiveView,
        axis: Axis,
        from: [f64; 2],
        to: [f64; 2],
    ) -> Result<(), String> {
        if !from.iter().chain(&to).all(|c| c.is_finite()) {
            return Err("the line's ends are not finite".into());
        }
        let length = (to[0] - from[0]).hypot(to[1] - from[1]);
        if length < MIN_LINE_PX {
            return Err(format!(
                "a line of {length:.1} pixels is too short (at least {MIN_LINE_PX})"
            ));
        }
        let index = match self.marks.views.iter().position(|v| v.camera == view) {
            Some(i) => i,
            None => {
                let base = view_name(&view);
                let taken = |n: &str| self.marks.views.iter().any(|v| v.name == n);
                let name = (1..)
                    .map(|k| {
                        if k == 1 {
                            base.clone()
                        } else {
                            format!("{base} #{k}")
                        }
                    })
                    .find(|n| !taken(n))
                    .unwrap_or_else(|| base.clone());
                self.made_views.insert(name.clone());
                self.marks.views.push(ViewMarks {
                    name,
                    camera: view,
                    lines: Vec::new(),
                    points: Vec::new(),
                });
                self.marks.views.len() - 1
            }
        };
        let v = &mut self.marks.views[index];
        v.lines.push(LineMark { axis, from, to });
        self.added.push(v.name.clone());
        self.changed();
        Ok(())
    }

    /// Removes the line added last (or, when none was added, the last line of the marks file);
    /// a view this session made goes with its last line. Whether a line was removed.
    pub fn delete_last_line(&mut self) -> bool {
        let from_added = loop {
            match self.added.pop() {
                Some(name) => {
                    if let Some(i) = self.marks.views.iter().position(|v| v.name == name)
                        && !self.marks.views[i].lines.is_empty()
                    {
                        break Some(i);
                    }
                }
                None => break None,
            }
        };
        let index =
            from_added.or_else(|| self.marks.views.iter().rposition(|v| !v.lines.is_empty()));
        let Some(i) = index else {
            return false;
        };
        self.marks.views[i].lines.pop();
        let v = &self.marks.views[i];
        if v.lines.is_empty() && v.points.is_empty() && self.made_views.remove(&v.name) {
            self.marks.views.remove(i);
        }
        self.changed();
        true
    }

    /// Runs the calibration of `ibl room calibrate` on the marks as they are and keeps the
    /// result (or why it failed) in [`RoomSession::calibration`]. Microseconds for tens of lines.
    pub fn calibrate(&mut self) {
        let started = Instant::now();
        let name = self
            .marks_path
            .as_ref()
            .map_or("the marks".to_string(), |p| p.display().to_string());
        let result = calibrate_marks(&self.marks, &name).map(|c| {
            // `line_observations` keeps the lines whose ends are distinct directions, in order.
            let labels = self.marks.views.iter().flat_map(|v| {
                v.lines.iter().enumerate().filter_map(move |(k, l)| {
                    LineObservation::new(
                        l.axis,
                        v.camera.direction(l.from[0], l.from[1]),
                        v.camera.direction(l.to[0], l.to[1]),
                    )
                    .map(|_| (v.name.clone(), k, l.axis))
                })
            });
            CalibrationSummary {
                rotation_deg: c.calibration.rotation_deg,
                rms_residual_deg: c.calibration.rms_residual_deg,
                lines: labels
                    .zip(&c.calibration.line_residuals_deg)
                    .map(|((view, line, axis), &residual_deg)| LineResidual {
                        view,
                        line,
                        axis,
                        residual_deg,
                    })
                    .collect(),
                probe_height_m: c.scale.map(|s| s.probe_height_m),
                seconds: 0.0,
            }
        });
        self.calibration = Some(
            result
                .map(|mut s| {
                    s.seconds = started.elapsed().as_secs_f64();
                    s
                })
                .map_err(|e| e.to_string()),
        );
    }

    /// Writes the marks to `path` (`.json`) atomically, naming the probe relative to it; never
    /// over the probe or the room file.
    pub fn save(&self, path: &Path) -> Result<(), ViewerError> {
        if path.extension().and_then(|e| e.to_str()) != Some("json") {
            return Err(ViewerError::Parameter(format!(
                "{}: a marks file is written as .json",
                path.display()
            )));
        }
        let mut inputs = vec![self.probe_path.as_path()];
        if let Some(room) = &self.room_path {
            inputs.push(room.as_path());
        }
        ibl_io::ensure_output_is_not_input(path, &inputs)?;
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let mut marks = self.marks.clone();
        let file = relative_to(&self.probe_path, folder)
            .to_string_lossy()
            .into_owned();
        let same_probe = marks.probe.as_ref().is_some_and(|p| p.file == file);
        let size = match &marks.probe {
            Some(p) if same_probe => p.size,
            _ => self.probe_size,
        };
        marks.probe = Some(MarksProbe { file, size });
        let problem = |e: ibl_room::RoomError| ViewerError::Input {
            path: path.to_path_buf(),
            problem: e.to_string(),
        };
        marks.validate().map_err(problem)?;
        let text = marks.to_json().map_err(problem)?;
        ibl_io::write_atomically(path, text.as_bytes())?;
        Ok(())
    }

    /// The segments to draw in `view` (sizes times `scale`, pixels per point): the room's edges
    /// and the marked lines as switched on, and the line being drawn.
    pub fn segments(&self, view: &OverlayView, scale: f32) -> Vec<LineSegment> {
        let shown = RoomOverlay {
            marks: if self.show_marks {
                self.overlay.marks.clone()
            } else {
                Vec::new()
            },
            edges: if self.show_room {
                self.overlay.edges.clone()
            } else {
                Vec::new()
            },
        };
        let mut segments = shown.segments(view, scale);
        if let Some(p) = &self.pending {
            let line = LineMark {
                axis: p.axis,
                from: p.from,
                to: p.to,
            };
            if let Some(arc) = line_arc(&p.view, &line) {
                let marked = MarkedArc { axis: p.axis, arc };
                marked_segments(&marked, view, scale, &mut segments);
            }
        }
        segments
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(yaw_deg: f64) -> PerspectiveView {
        PerspectiveView {
            yaw_deg,
            pitch_deg: -5.0,
            roll_deg: 0.0,
            vertical_fov_deg: 75.0,
            width: 640,
            height: 480,
        }
    }

    fn apartment() -> RoomSession {
        let marks =
            MarksFile::from_json(include_str!("../../../assets/rooms/apartment/marks.json"))
                .expect("the worked example");
        RoomSession::new(
            Path::new("probe.exr"),
            Some([512, 256]),
            Some(marks),
            Some(Path::new("marks.json")),
            None,
            None,
        )
    }

    #[test]
    fn lines_go_to_the_view_of_their_camera_and_come_off_last_first() {
        let mut s = apartment();
        let before = s.marks.clone();
        s.add_line(camera(30.0), Axis::Y, [100.0, 50.0], [101.0, 300.0])
            .expect("added");
        s.add_line(camera(30.0), Axis::X, [10.0, 400.0], [300.0, 420.0])
            .expect("added");
        s.add_line(camera(45.0), Axis::Z, [10.0, 10.0], [50.0, 60.0])
            .expect("added");
        assert_eq!(s.marks.views.len(), before.views.len() + 2);
        let v = &s.marks.views[before.views.len()];
        assert_eq!(v.name, "yaw 30.0 pitch -5.0 fov 75.0 640x480");
        assert_eq!(v.camera, camera(30.0));
        assert_eq!(v.lines.len(), 2);
        assert!(s.marks.validate().is_ok());
        // Too short, or not finite: refused.
        assert!(
            s.add_line(camera(30.0), Axis::X, [1.0, 1.0], [2.0, 1.5])
                .is_err()
        );
        assert!(
            s.add_line(camera(30.0), Axis::X, [f64::NAN, 1.0], [200.0, 1.0])
                .is_err()
        );
        // A camera whose name rounds to a taken one gets a view of its own.
        s.add_line(camera(30.01), Axis::X, [10.0, 10.0], [100.0, 10.0])
            .expect("added");
        assert!(
            s.marks
                .views
                .iter()
                .any(|v| v.name == "yaw 30.0 pitch -5.0 fov 75.0 640x480 #2")
        );
        for _ in 0..4 {
            assert!(s.delete_last_line());
        }
        assert_eq!(s.marks, before, "back to the file's marks");
        // Then the file's own lines, last first.
        assert!(s.delete_last_line());
        assert_eq!(s.line_count(), 12);
        assert_eq!(s.marks.views[4].lines.len(), 0, "the left view's line");
        assert_eq!(s.marks.views.len(), 5, "a view of the file stays");
    }

    #[test]
    fn calibrate_gives_what_ibl_room_calibrate_prints() {
        let mut s = apartment();
        s.calibrate();
        let c = s
            .calibration
            .clone()
            .expect("ran")
            .expect("the worked example calibrates");
        // docs/ROOMS.md: 13 lines, [24.009, 0.069, 0.080] deg, RMS 0.762 (largest 2.068), 1.370 m.
        assert_eq!(c.lines.len(), 13);
        assert!(
            (c.rotation_deg[0] - 24.009).abs() < 5e-4,
            "{:?}",
            c.rotation_deg
        );
        assert!((c.rms_residual_deg - 0.762).abs() < 5e-4);
        assert!((c.max_residual_deg() - 2.068).abs() < 5e-4);
        assert!((c.probe_height_m.expect("scaled") - 1.370).abs() < 5e-4);
        assert_eq!(c.lines[0].view, "front");
        assert_eq!(c.lines[12].view, "left");
        assert!(
            c.line()
                .starts_with("13 lines: rotation [yaw, pitch, roll] [24.009,")
        );
        // An edit clears it; too few lines is a message, not a panic.
        s.delete_last_line();
        assert!(s.calibration.is_none());
        let mut empty = RoomSession::new(Path::new("p.exr"), None, None, None, None, None);
        empty.calibrate();
        assert!(matches!(empty.calibration, Some(Err(_))));
    }

    #[test]
    fn saved_marks_read_back_and_never_overwrite_the_probe() {
        let dir = tempfile::tempdir().expect("temp dir");
        let probe = dir.path().join("probe.exr");
        std::fs::write(&probe, b"not really a probe").expect("written");
        let mut s = RoomSession::new(&probe, Some([512, 256]), None, None, None, None);
        assert_eq!(
            PathBuf::from(&s.save_path),
            dir.path().join("probe-marks.json")
        );
        s.add_line(camera(0.0), Axis::X, [10.5, 20.25], [300.0, 40.0])
            .expect("added");
        let out = dir.path().join("sub").join("marks.json");
        std::fs::create_dir(dir.path().join("sub")).expect("folder");
        s.save(&out).expect("saved");
        let back = MarksFile::from_json(&std::fs::read_to_string(&out).expect("read"))
            .expect("valid marks");
        assert_eq!(back.views, s.marks.views, "pixels and cameras exactly");
        let named = back.probe.expect("names the probe");
        assert_eq!(named.file, "../probe.exr");
        assert_eq!(named.size, Some([512, 256]));
        // Not over the probe (nor anything but a .json).
        assert!(s.save(&probe).expect_err("an image").is_bad_input());
        assert!(s.save(&dir.path().join("marks.txt")).is_err());
        let odd = dir.path().join("probe.json");
        std::fs::write(&odd, b"a probe named .json").expect("written");
        let t = RoomSession::new(&odd, None, None, None, None, None);
        let err = t.save(&odd).expect_err("the probe itself");
        assert!(
            err.is_bad_input() && err.to_string().contains("probe.json"),
            "{err}"
        );
        assert_eq!(std::fs::read(&probe).expect("read"), b"not really a probe");
        assert_eq!(std::fs::read(&odd).expect("read"), b"a probe named .json");
    }
}
