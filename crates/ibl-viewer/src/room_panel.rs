//! The "Room" section of the probe viewer's side panel (Grosch 2005 section 3.1): what the marks
//! and the room hold, the overlays' switches, marking lines (the axis of the next one, removing
//! the last), calibrating with every line's residual, and saving the marks; and the room's
//! materials changed by clicking ([`materials_section`]). The state and what the buttons do are
//! [`crate::room_marking`]'s and [`crate::room_edit`]'s.

use eframe::egui;
use ibl_room::Axis;

use crate::room_edit::{MAX_BOUNCES, RoomEditSession};
use crate::room_marking::RoomSession;
use crate::room_overlay::axis_colour;
use ibl_core::Rgb;

fn colour32(c: [f32; 4]) -> egui::Color32 {
    let [r, g, b, _] = c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8);
    // Pure blue is hard to read on the dark panel: lighten it for the text only.
    if [r, g, b] == [0, 0, 255] {
        egui::Color32::from_rgb(90, 140, 255)
    } else {
        egui::Color32::from_rgb(r, g, b)
    }
}

/// The section for `room`; `look_around` says whether the view can be marked (not the flat one).
pub fn room_section(ui: &mut egui::Ui, room: &mut RoomSession, look_around: bool) {
    ui.label("Room");
    let [x, y, z] = room.lines_per_axis();
    let source = room
        .marks_path
        .as_ref()
        .map_or("new marks".to_string(), |p| p.display().to_string());
    ui.label(format!(
        "{source}: {} lines (x {x}, y {y}, z {z}) in {} views",
        room.line_count(),
        room.marks.views.len()
    ));
    ui.horizontal(|ui| {
        ui.checkbox(&mut room.show_marks, "show marks");
        if let Some(path) = &room.room_path {
            ui.checkbox(&mut room.show_room, "show room")
                .on_hover_text(format!("{}: {} edges", path.display(), room.room_edges()));
        }
    });
    if ui
        .toggle_value(&mut room.marking, "mark lines (M)")
        .changed()
    {
        room.pending = None;
    }
    if room.marking {
        if look_around {
            ui.label("left-drag draws a line, right-drag turns the view");
        } else {
            ui.label("switch to \"look around\" to mark lines");
        }
    }
    ui.horizontal(|ui| {
        ui.label("next line's axis");
        for axis in Axis::ALL {
            let text = egui::RichText::new(axis.name()).color(colour32(axis_colour(axis)));
            ui.radio_value(&mut room.axis, axis, text)
                .on_hover_text(format!("key {}", axis.name().to_uppercase()));
        }
    });
    if let Some(why) = &room.refused {
        ui.label(format!("not added: {why}"));
    }
    ui.horizontal(|ui| {
        if ui
            .add_enabled(
                room.line_count() > 0,
                egui::Button::new("delete last line (Backspace)"),
            )
            .clicked()
        {
            room.delete_last_line();
        }
        if ui.button("calibrate").clicked() {
            room.calibrate();
        }
    });
    calibration(ui, room);
    let label = ui.label("Save the marks to");
    ui.horizontal(|ui| {
        ui.text_edit_singleline(&mut room.save_path)
            .labelled_by(label.id);
    });
    if ui.button("save marks").clicked() {
        let path = std::path::PathBuf::from(&room.save_path);
        room.saved = Some(
            room.save(&path)
                .map(|()| format!("saved {}", path.display()))
                .map_err(|e| e.to_string()),
        );
    }
    match &room.saved {
        Some(Ok(m)) => {
            ui.label(m.as_str());
        }
        Some(Err(e)) => {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e.as_str());
        }
        None => {}
    }
}

fn calibration(ui: &mut egui::Ui, room: &RoomSession) {
    match &room.calibration {
        None => {}
        Some(Err(e)) => {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e.as_str());
        }
        Some(Ok(c)) => {
            ui.label(c.line());
            if let Some(h) = c.probe_height_m {
                ui.label(format!("probe {h:.3} m above the floor"));
            }
            ui.label(format!("({:.1} ms)", c.seconds * 1e3));
            egui::CollapsingHeader::new("residual per line")
                .default_open(true)
                .show(ui, |ui| {
                    egui::Grid::new("residuals").striped(true).show(ui, |ui| {
                        ui.label("view");
                        ui.label("line");
                        ui.label("axis");
                        ui.label("deg");
                        ui.end_row();
                        for l in &c.lines {
                            ui.label(l.view.as_str());
                            ui.label(l.line.to_string());
                            ui.colored_label(colour32(axis_colour(l.axis)), l.axis.name());
                            ui.label(format!("{:.3}", l.residual_deg));
                            ui.end_row();
                        }
                    });
                });
        }
    }
}

/// The room's materials, changed by clicking (Grosch 2005 section 4.3; [`crate::room_edit`]):
/// switched on here once a room file is open, then a click on the panorama picks a surface's
/// group, a colour sets its new reflectance and the edited panorama with its colour bleeding
/// replaces the probe.
pub fn materials_section(
    ui: &mut egui::Ui,
    room: &RoomSession,
    edit: &mut Option<RoomEditSession>,
) {
    let Some(path) = &room.room_path else {
        return;
    };
    ui.label("Materials (Grosch 4.3)");
    let Some(session) = edit else {
        if ui
            .button("edit the room's materials")
            .on_hover_text("estimates the room's reflectances (about a second), then a click on a surface picks its group")
            .clicked()
        {
            *edit = Some(RoomEditSession::new(path));
        }
        return;
    };
    ui.horizontal(|ui| {
        if ui
            .checkbox(&mut session.picking, "click picks a surface")
            .changed()
            && session.picking
        {
            session.placing = false;
        }
        ui.checkbox(&mut session.show_edited, "show the edits");
    });
    ui.add(
        egui::Slider::new(&mut session.bounces, 1..=MAX_BOUNCES).text("bounces of colour bleeding"),
    );
    if session.table.is_none() {
        ui.label("estimating the room...");
    }
    if let (Some(g), Some(table)) = (session.picked, session.table.clone())
        && let Some(info) = table.groups.get(g)
    {
        match (info.estimated, session.reflectance(g)) {
            (Some(estimated), Some(now)) => {
                ui.label(format!(
                    "{}: estimated reflectance {:.3} {:.3} {:.3}",
                    info.name, estimated.r, estimated.g, estimated.b
                ));
                let mut rgb = now.to_array();
                ui.horizontal(|ui| {
                    ui.label("new reflectance");
                    if ui.color_edit_button_rgb(&mut rgb).changed() {
                        session.set_reflectance(g, Rgb::from_array(rgb));
                    }
                });
            }
            _ => {
                ui.label(format!(
                    "{}: a light or unseen group (no reflectance)",
                    info.name
                ));
            }
        }
    } else if session.table.is_some() {
        ui.label("click a surface of the panorama to pick its group");
    }
    for (name, rho) in &session.materials {
        ui.label(format!("{name} -> {:.3} {:.3} {:.3}", rho.r, rho.g, rho.b));
    }
    ui.separator();
    ui.label("Lights (Grosch 4.2)");
    if ui
        .checkbox(&mut session.placing, "click places a light")
        .on_hover_text("on the surface clicked, moved off it along its normal, aimed straight down")
        .changed()
        && session.placing
    {
        session.picking = false;
    }
    ui.horizontal(|ui| {
        ui.label("IES / LDT file");
        ui.text_edit_singleline(&mut session.light_file);
    });
    ui.add(
        egui::Slider::new(&mut session.light_offset_m, 0.0..=1.5).text("metres off the surface"),
    );
    ui.add(
        egui::Slider::new(&mut session.light_peak, 1.0..=400.0)
            .logarithmic(true)
            .text("peak, probe units / sr"),
    );
    placed_lights(ui, session);
    let edited = !session.materials.is_empty() || !session.lights.is_empty();
    if edited && ui.button("undo all").clicked() {
        session.materials.clear();
        session.lights.clear();
        session.moving = None;
    }
    match &session.last {
        Some(Ok((line, _))) if edited => {
            ui.label(line.as_str());
        }
        Some(Err(e)) => {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e.as_str());
        }
        _ => {}
    }
}

/// Each placed light: its file, a button that makes the next click move it, its offset, peak
/// and turn (yaw, pitch, roll), and a button that removes it. Every change re-renders the edits
/// on the worker (Grosch 2005 section 4.2: the lights are movable and rotatable).
fn placed_lights(ui: &mut egui::Ui, session: &mut RoomEditSession) {
    let mut remove = None;
    for k in 0..session.lights.len() {
        let n = k + 1;
        ui.label(format!("light {n}: {}", session.lights[k].file.display()));
        ui.horizontal(|ui| {
            let moving = session.moving == Some(k);
            let label = if moving {
                format!("click a surface for light {n}")
            } else {
                format!("move light {n}")
            };
            if ui.selectable_label(moving, label).clicked() {
                session.moving = if moving { None } else { Some(k) };
            }
            if ui.button(format!("remove light {n}")).clicked() {
                remove = Some(k);
            }
        });
        let light = &mut session.lights[k];
        ui.horizontal(|ui| {
            ui.label(format!("turn light {n}"))
                .on_hover_text("yaw, pitch, roll in degrees (0 0 0: aimed straight down)");
            for value in &mut light.rotation_deg {
                ui.add(
                    egui::DragValue::new(value)
                        .range(-180.0..=180.0)
                        .speed(1.0)
                        .suffix("\u{b0}"),
                );
            }
        });
        ui.horizontal(|ui| {
            ui.add(
                egui::DragValue::new(&mut light.offset_m)
                    .range(0.0..=1.5)
                    .speed(0.01)
                    .suffix(" m off"),
            );
            ui.add(
                egui::DragValue::new(&mut light.peak_intensity)
                    .range(1.0..=400.0)
                    .speed(1.0)
                    .suffix(" peak"),
            );
        });
    }
    if let Some(k) = remove {
        session.remove_light(k);
    }
}
