//! Material changes in the probe viewer, live (Grosch 2005 section 4.3; issue 17, part 6): with
//! a room file open over its probe (`ibl view PROBE --room ROOM.toml`), a click on a surface of
//! the panorama picks its material group (through the room's depth map: the patch the probe
//! sees at that pixel), the panel sets the group's new reflectance `rho'`, and the viewer shows
//! the edited panorama: the group's pixels scaled by `rho' / rho` at once and the rest of the
//! room updated by the colour bleeding of `ibl room render --edit` (delta radiosity shot from the
//! changed patches, `bounces` times). A click can also place a new IES or EULUMDAT light
//! (section 4.2) on the surface it meets, moved off it along the surface's normal: its direct
//! light with shadows and its bounces join the panorama.
//!
//! Everything is computed by the library's own calls, off the UI thread ([`crate::worker`]):
//! `ibl_pipeline::room_estimate::estimate_room` once (the reflectance estimate, about 0.7 s for
//! the bundled apartment), then `ibl_pipeline::room_render::render_edits` per change (a few ms
//! for the edit and 20 ms for the panorama there), exactly what `ibl room render --edit`
//! writes for the same edits.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError};

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_pipeline::progress::Silent;
use ibl_pipeline::room_estimate::{EstimatedRoom, SamplingOptions, estimate_room};
use ibl_pipeline::room_render::{EditReport, LightSpec, RoomEdits, render_edits};
use ibl_room::depth_map::NO_PATCH;
use ibl_scene::description::IntensityScale;

use crate::ViewerError;
use crate::worker::LatestWorker;

/// Most bounces of colour bleeding the panel offers.
pub const MAX_BOUNCES: u32 = 4;
/// A placed light's distance from the clicked surface, metres, unless changed.
pub const DEFAULT_LIGHT_OFFSET_M: f32 = 0.3;
/// A placed light's peak, probe units per sr, unless changed (the worked example's).
pub const DEFAULT_LIGHT_PEAK: f32 = 40.0;

/// The light file offered first: the bundled `umbrella.ies` when the room sits in the
/// repository's `assets/rooms/NAME/` (as the worked example does), else none.
fn default_light_file(room: &Path) -> String {
    let bundled = room
        .parent()
        .map(|dir| dir.join("../../photometry/ies/umbrella.ies"));
    match bundled {
        Some(p) if p.is_file() => p.display().to_string(),
        _ => String::new(),
    }
}

/// A material group a click can pick.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupInfo {
    /// Its name in the room file.
    pub name: String,
    /// Its estimated reflectance (`None` for a light group or one the probe does not see).
    pub estimated: Option<Rgb>,
}

/// What a click reads: each probe pixel's material group, and the groups.
#[derive(Clone, Debug)]
pub struct PickTable {
    /// Per depth-map pixel, the group its patch belongs to (`u32::MAX`: none).
    groups_at: Image<u32>,
    /// Every group, by index.
    pub groups: Vec<GroupInfo>,
}

impl PickTable {
    fn new(estimated: &EstimatedRoom) -> PickTable {
        let room = &estimated.input.room;
        let depth = estimated.analysis.depth.samples();
        let groups_at = depth.map(|s| {
            if s.patch == NO_PATCH {
                u32::MAX
            } else {
                room.patches[s.patch as usize].group
            }
        });
        let groups = room
            .groups
            .iter()
            .zip(&estimated.analysis.estimate.groups)
            .map(|(g, e)| GroupInfo {
                name: g.name.clone(),
                estimated: e.reflectance.map(Rgb::from_array),
            })
            .collect();
        PickTable { groups_at, groups }
    }

    /// The group seen along `direction` (probe frame, unit), if any.
    pub fn group_towards(&self, direction: Vec3) -> Option<usize> {
        let (w, h) = (self.groups_at.width(), self.groups_at.height());
        if w == 0 || h == 0 {
            return None;
        }
        let (i, j) = LatLong::new(w, h).dir_to_pixel(direction.as_dvec3());
        let g = *self.groups_at.get(i, j);
        (g != u32::MAX).then_some(g as usize)
    }
}

/// A new goniometric light placed by a click (Grosch 2005 section 4.2): on the surface the
/// probe sees along `towards`, moved off it along its normal. Movable (a later click sets
/// `towards` again: [`RoomEditSession::moving`]) and rotatable (`rotation_deg`).
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedLight {
    /// Its IES or EULUMDAT file.
    pub file: PathBuf,
    /// The direction clicked, probe frame (unit).
    pub towards: Vec3,
    /// Distance from the surface along its front normal, metres.
    pub offset_m: f32,
    /// The table's peak, probe units per sr (`peak_intensity` of an edits file).
    pub peak_intensity: f32,
    /// Yaw, pitch and roll of the light's frame, degrees (0: aimed straight down; an edits
    /// file's `rotation_deg`).
    pub rotation_deg: [f32; 3],
}

/// A request to the worker: the edits to show.
#[derive(Clone, Debug, PartialEq)]
struct EditRequest {
    materials: Vec<(String, Rgb)>,
    lights: Vec<PlacedLight>,
    bounces: u32,
}

impl EditRequest {
    /// Whether it changes nothing.
    fn is_empty(&self) -> bool {
        self.materials.is_empty() && self.lights.is_empty()
    }
}

/// The edits file's form of a placed light: its world position from the room's geometry (the
/// surface hit along the click's ray from the probe, moved along the surface's normal), turned
/// by its rotation, white.
fn light_spec(room: &ibl_room::Room, light: &PlacedLight) -> Result<LightSpec, String> {
    let direction = (room.world_from_probe * light.towards).normalize_or_zero();
    let hit = room
        .hit(room.probe_position, direction, 0.0, f32::INFINITY)
        .ok_or_else(|| "the click meets no surface of the room".to_string())?;
    let patch = &room.patches[hit.patch as usize];
    let normal = if hit.front {
        patch.normal
    } else {
        -patch.normal
    };
    Ok(LightSpec {
        file: light.file.clone(),
        position: room.probe_position + direction * hit.distance_m + normal * light.offset_m,
        rotation_deg: light.rotation_deg,
        colour: Rgb::ONE,
        scale: IntensityScale::PeakIntensity(light.peak_intensity),
    })
}

/// The worker's answer.
struct EditAnswer {
    /// The request it answers.
    request: EditRequest,
    /// The panorama after the edits (probe units, the probe's lat-long).
    after: Image<Rgb>,
    /// What the edit did, one line.
    report: String,
    /// Seconds of the edit and the panorama.
    seconds: f64,
    /// The pick table, made with the first answer.
    table: Option<Arc<PickTable>>,
}

/// The estimate, made by the worker on its first request and kept.
fn answer(
    room: &Path,
    cache: &Mutex<Option<EstimatedRoom>>,
    request: EditRequest,
) -> Result<EditAnswer, String> {
    let mut cache = cache.lock().unwrap_or_else(PoisonError::into_inner);
    let mut table = None;
    if cache.is_none() {
        let estimated =
            estimate_room(room, &SamplingOptions::default(), &Silent).map_err(|e| e.to_string())?;
        table = Some(Arc::new(PickTable::new(&estimated)));
        *cache = Some(estimated);
    }
    let Some(estimated) = cache.as_ref() else {
        return Err("the room's estimate is missing".into());
    };
    let started = std::time::Instant::now();
    let lights = request
        .lights
        .iter()
        .map(|l| light_spec(&estimated.input.room, l))
        .collect::<Result<Vec<_>, _>>()?;
    let edits = RoomEdits {
        bounces: request.bounces,
        materials: request.materials.clone(),
        lights,
        source: room.to_path_buf(),
        ..RoomEdits::none()
    };
    let assets = edits.load().map_err(|e| e.to_string())?;
    let pictures = render_edits(estimated, &edits, &assets, room).map_err(|e| e.to_string())?;
    Ok(EditAnswer {
        request,
        after: pictures.after,
        report: report_line(&pictures.report),
        seconds: started.elapsed().as_secs_f64(),
        table,
    })
}

/// What an edit did, one line for the panel.
fn report_line(r: &EditReport) -> String {
    format!(
        "{} group{} changed, {} light{} added, {} bounce{} of colour bleeding (the last changed {:.2} %); edit {:.1} ms, panorama {:.1} ms",
        r.materials.len(),
        if r.materials.len() == 1 { "" } else { "s" },
        r.lights.len(),
        if r.lights.len() == 1 { "" } else { "s" },
        r.bounces,
        if r.bounces == 1 { "" } else { "s" },
        100.0 * r.last_bounce_relative,
        r.seconds_edit * 1e3,
        r.seconds_render * 1e3
    )
}

/// Reads an edits file for the viewer: the panorama's edits (materials, lights, objects); a
/// `[view]` (a moved camera's picture) is `ibl room render`'s, not the viewer's, and is refused.
pub fn read_panorama_edits(edits: &Path) -> Result<RoomEdits, ViewerError> {
    let read = RoomEdits::read(edits)?;
    if read.view.is_some() {
        return Err(ViewerError::Input {
            path: edits.to_path_buf(),
            problem: "has a [view]: the viewer shows the edited panorama and looks around it itself (render the moved camera's picture with `ibl room render --edit`)"
                .into(),
        });
    }
    Ok(read)
}

/// The room `room`'s panorama after the edits file `edits` (`ibl room render --edit`'s
/// picture, every manipulation of Grosch 2005 section 4 but the moved camera), for a probe
/// shown as `shown` (its size must be the room probe's).
pub fn edited_panorama(
    room: &Path,
    edits: &Path,
    shown: &Image<Rgb>,
) -> Result<Image<Rgb>, ViewerError> {
    let read = read_panorama_edits(edits)?;
    let assets = read.load()?;
    let estimated = estimate_room(room, &SamplingOptions::default(), &Silent)?;
    let after = render_edits(&estimated, &read, &assets, room)?.after;
    if (after.width(), after.height()) != (shown.width(), shown.height()) {
        return Err(ViewerError::Input {
            path: room.to_path_buf(),
            problem: format!(
                "its probe is {} x {}, the probe shown {} x {}: view the room's own probe",
                after.width(),
                after.height(),
                shown.width(),
                shown.height()
            ),
        });
    }
    Ok(after)
}

/// The material editing of a room shown over its probe.
pub struct RoomEditSession {
    worker: LatestWorker<EditRequest, Result<EditAnswer, String>>,
    /// The room file.
    pub room_path: PathBuf,
    /// Whether a click on the panorama picks the surface's group.
    pub picking: bool,
    /// The group picked last.
    pub picked: Option<usize>,
    /// The direction (probe frame) it was picked along.
    pub picked_towards: Option<Vec3>,
    /// The new reflectances, by group name, in the order they were made.
    pub materials: Vec<(String, Rgb)>,
    /// Whether a click on the panorama places a light (instead of picking).
    pub placing: bool,
    /// The lights placed.
    pub lights: Vec<PlacedLight>,
    /// The placed light the next click moves (it then clears; placing and picking wait).
    pub moving: Option<usize>,
    /// The file, offset and peak the next light is placed with.
    pub light_file: String,
    /// See `light_file`.
    pub light_offset_m: f32,
    /// See `light_file`.
    pub light_peak: f32,
    /// Bounces of colour bleeding.
    pub bounces: u32,
    /// Whether the edited panorama is shown (else the probe as it was).
    pub show_edited: bool,
    requested: Option<EditRequest>,
    /// The groups and what each pixel shows, once the estimate is made.
    pub table: Option<Arc<PickTable>>,
    /// The last answer's report line and seconds, or its error.
    pub last: Option<Result<(String, f64), String>>,
    /// The latest edited panorama, its answer's number and the request it answers.
    latest: Option<(u64, Arc<Image<Rgb>>, EditRequest)>,
    answers: u64,
    /// The answer whose panorama the renderer shows (`None`: the probe as it was).
    displayed: Option<u64>,
}

impl RoomEditSession {
    /// A session for the room file `room` (the estimate starts at once on the worker).
    pub fn new(room: &Path) -> RoomEditSession {
        let cache = Mutex::new(None);
        let path = room.to_path_buf();
        let mut session = RoomEditSession {
            worker: LatestWorker::new("ibl-view room edits", move |r: EditRequest| {
                answer(&path, &cache, r)
            }),
            room_path: room.to_path_buf(),
            picking: false,
            picked: None,
            picked_towards: None,
            placing: false,
            lights: Vec::new(),
            moving: None,
            light_file: default_light_file(room),
            light_offset_m: DEFAULT_LIGHT_OFFSET_M,
            light_peak: DEFAULT_LIGHT_PEAK,
            materials: Vec::new(),
            bounces: 1,
            show_edited: true,
            requested: None,
            table: None,
            last: None,
            latest: None,
            answers: 0,
            displayed: None,
        };
        session.submit_if_changed();
        session
    }

    /// Whether the worker is estimating or editing.
    pub fn busy(&self) -> bool {
        self.worker.busy()
    }

    /// The reflectance group `g` has now: the user's, or the estimate.
    pub fn reflectance(&self, g: usize) -> Option<Rgb> {
        let table = self.table.as_ref()?;
        let name = &table.groups.get(g)?.name;
        self.materials
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, r)| *r)
            .or(table.groups[g].estimated)
    }

    /// Sets group `g`'s new reflectance (clamped to [0, 1]).
    pub fn set_reflectance(&mut self, g: usize, rho: Rgb) {
        let Some(name) = self
            .table
            .as_ref()
            .and_then(|t| t.groups.get(g))
            .map(|i| i.name.clone())
        else {
            return;
        };
        let rho = Rgb::new(
            rho.r.clamp(0.0, 1.0),
            rho.g.clamp(0.0, 1.0),
            rho.b.clamp(0.0, 1.0),
        );
        match self.materials.iter_mut().find(|(n, _)| *n == name) {
            Some(entry) => entry.1 = rho,
            None => self.materials.push((name, rho)),
        }
    }

    /// What a click along `direction` (probe frame) does: moves the light chosen to move there,
    /// else places a light when placing is on, else picks the group there when picking is on.
    pub fn click(&mut self, direction: Vec3) {
        if let Some(k) = self.moving.take() {
            if let Some(light) = self.lights.get_mut(k) {
                light.towards = direction;
            }
        } else if self.placing {
            self.lights.push(PlacedLight {
                file: PathBuf::from(self.light_file.trim()),
                towards: direction,
                offset_m: self.light_offset_m,
                peak_intensity: self.light_peak,
                rotation_deg: [0.0; 3],
            });
        } else if self.picking {
            self.pick(direction);
        }
    }

    /// Removes placed light `k` (a pending move of it, or of a later one, is dropped).
    pub fn remove_light(&mut self, k: usize) {
        if k < self.lights.len() {
            self.lights.remove(k);
            if self.moving.is_some_and(|m| m >= k) {
                self.moving = None;
            }
        }
    }

    /// Picks the group seen along `direction` (probe frame).
    pub fn pick(&mut self, direction: Vec3) {
        if let Some(table) = &self.table {
            self.picked = table.group_towards(direction);
            self.picked_towards = Some(direction);
        }
    }

    /// The edits as they are now.
    fn current(&self) -> EditRequest {
        EditRequest {
            materials: self.materials.clone(),
            lights: self.lights.clone(),
            bounces: self.bounces.clamp(1, MAX_BOUNCES),
        }
    }

    /// Asks for the edits as they are now, unless they were asked for already.
    fn submit_if_changed(&mut self) {
        let request = self.current();
        if self.requested.as_ref() != Some(&request) {
            self.worker.submit(request.clone());
            self.requested = Some(request);
        }
    }

    /// Submits changed edits and takes a finished answer; returns the panorama to show when it
    /// changed: the latest edited one, or `original` when the edits are switched off or none
    /// is made.
    pub fn poll(&mut self, original: &Arc<Image<Rgb>>) -> Option<Arc<Image<Rgb>>> {
        self.submit_if_changed();
        if let Some(done) = self.worker.poll() {
            match done.result {
                Ok(a) => {
                    if a.table.is_some() {
                        self.table = a.table;
                    }
                    self.last = Some(Ok((a.report, a.seconds)));
                    self.answers += 1;
                    self.latest = Some((self.answers, Arc::new(a.after), a.request));
                }
                Err(e) => self.last = Some(Err(e)),
            }
        }
        let wanted = match &self.latest {
            Some((n, _, request)) if self.show_edited && !request.is_empty() => Some(*n),
            _ => None,
        };
        if wanted == self.displayed {
            return None;
        }
        self.displayed = wanted;
        match (&self.latest, wanted) {
            (Some((_, image, _)), Some(_)) => Some(Arc::clone(image)),
            _ => Some(Arc::clone(original)),
        }
    }

    /// Whether what is shown is the answer to the edits as they are now.
    pub fn shows_current_edits(&self) -> bool {
        match &self.latest {
            Some((n, _, answered)) => {
                *answered == self.current() && (self.displayed == Some(*n) || answered.is_empty())
            }
            None => false,
        }
    }
}
