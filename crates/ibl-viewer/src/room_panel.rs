//! The "Room" section of the probe viewer's side panel (Grosch 2005 section 3.1): what the marks
//! and the room hold, the overlays' switches, marking lines (the axis of the next one, removing
//! the last), calibrating with every line's residual, and saving the marks. The state and what
//! the buttons do are [`crate::room_marking`]'s.

use eframe::egui;
use ibl_room::Axis;

use crate::room_marking::RoomSession;
use crate::room_overlay::axis_colour;

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
