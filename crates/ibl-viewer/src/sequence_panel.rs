//! The "Sequence" section of the scene panel (Jensen, Andersen & Madsen 2006): play, pause, step
//! and the rate; the sky as the ambient or as shadowed lights; the frame shown with its local time and sky; the estimated sun `P_d` and sky
//! `P_a` (RGB, with their standard errors and the inliers of the robust fit); a chart of both
//! (green channel) over the frames played; the relit map. The state is
//! [`crate::sequence_state`]'s.

use eframe::egui;

use crate::sequence_state::SequenceState;

/// Height of the chart, points.
const CHART_HEIGHT: f32 = 90.0;
/// Colours of the sun and sky series (as the `ibl outdoor` chart: warm sun, blue sky).
const SUN_COLOUR: egui::Color32 = egui::Color32::from_rgb(240, 170, 60);
const SKY_COLOUR: egui::Color32 = egui::Color32::from_rgb(90, 150, 255);

fn rgb_text(v: [f32; 3]) -> String {
    format!("{:.3} {:.3} {:.3}", v[0], v[1], v[2])
}

/// The section for `sequence`.
pub fn sequence_section(ui: &mut egui::Ui, sequence: &mut SequenceState) {
    sequence.upload_thumbnail(ui.ctx());
    ui.label("Sequence (sun and sky per frame)");
    ui.horizontal(|ui| {
        let label = if sequence.playing { "pause" } else { "play" };
        if ui.button(label).clicked() {
            sequence.playing = !sequence.playing;
        }
        if ui.button("next frame").clicked() {
            sequence.step_requested = true;
        }
    });
    ui.add(
        egui::Slider::new(&mut sequence.rate, 0.1..=60.0)
            .logarithmic(true)
            .text("frames per second"),
    );
    egui::ComboBox::from_label("sky")
        .selected_text(match sequence.sky_lights {
            0 => "ambient (no sky shadows)".to_string(),
            n => format!("{n} shadowed lights"),
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut sequence.sky_lights, 0, "ambient (no sky shadows)");
            for n in [4, 8, 16] {
                ui.selectable_value(&mut sequence.sky_lights, n, format!("{n} shadowed lights"));
            }
        })
        .response
        .on_hover_text("the estimated sky split by median cut into lights with their own shadows: the objects' sky shadow, from the next frame");
    let count = sequence
        .frame_count()
        .map_or("a video".to_string(), |n| format!("{n} frames"));
    match sequence.setup_seconds {
        Some(t) => ui.label(format!("{count}; offline step {t:.2} s")),
        None => ui.label(format!("{count}; offline step running...")),
    };
    if let Some(f) = sequence.current() {
        let e = &f.result.estimate;
        ui.label(format!(
            "frame {} ({}), {}, {} sky",
            f.index,
            f.name,
            f.local_time,
            format!("{:?}", f.result.sky_condition).to_lowercase()
        ));
        ui.colored_label(SUN_COLOUR, format!("sun P_d  {}", rgb_text(e.sun)))
            .on_hover_text(format!("standard error {}", rgb_text(e.sun_std)));
        ui.colored_label(SKY_COLOUR, format!("sky P_a  {}", rgb_text(e.sky)))
            .on_hover_text(format!("standard error {}", rgb_text(e.sky_std)));
        ui.label(format!(
            "{} of {} samples inliers; estimate {:.1} ms",
            e.inliers,
            e.samples,
            f.estimate_seconds * 1e3
        ));
    }
    chart(ui, sequence);
    if let Some(texture) = &sequence.relit_texture {
        ui.label("relit environment map (the sun left out)");
        let width = ui.available_width();
        ui.image((texture.id(), egui::vec2(width, 0.5 * width)));
    }
}

/// `P_d` and `P_a` (green) of the frames played, oldest left, on one scale from 0.
fn chart(ui: &mut egui::Ui, sequence: &SequenceState) {
    let width = ui.available_width();
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, CHART_HEIGHT), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, egui::Color32::from_gray(24));
    let frames = &sequence.history;
    if frames.len() < 2 {
        return;
    }
    let top = frames
        .iter()
        .map(|f| f.result.estimate.sun[1].max(f.result.estimate.sky[1]))
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let point = |k: usize, v: f32| {
        egui::pos2(
            rect.left() + rect.width() * k as f32 / (frames.len() - 1) as f32,
            rect.bottom() - rect.height() * (v / top).clamp(0.0, 1.0),
        )
    };
    for (colour, pick) in [(SUN_COLOUR, 0usize), (SKY_COLOUR, 1usize)] {
        let points: Vec<egui::Pos2> = frames
            .iter()
            .enumerate()
            .map(|(k, f)| {
                let e = &f.result.estimate;
                point(k, if pick == 0 { e.sun[1] } else { e.sky[1] })
            })
            .collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, colour)));
    }
    painter.text(
        rect.left_top() + egui::vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{top:.3}"),
        egui::FontId::proportional(11.0),
        egui::Color32::from_gray(180),
    );
}
