//! The window's widgets: the side panel (view, display, lights, the room tools of
//! [`crate::room_panel`], an outdoor sequence's of [`crate::sequence_panel`], the selected
//! object, saving),
//! the status line (frame rate, lights, shadow maps, GPU, messages) and the messages over an
//! empty or failed view.

use eframe::egui;
use ibl_core::tonemap::ToneCurve;
use ibl_extract::ModelSpec;
use ibl_light::{LightSource, Method};
use ibl_scene::description::{
    CompositeRule, LightingDescription, MaterialDescription, MaterialKind, RenderMode,
};
use ibl_scene::{AmbientBands, ShadowKind};

use crate::probe_pass::{ProbeLayer, ProbeProjection};
use crate::scene_renderer::GlossySource;
use crate::sequence_panel::sequence_section;
use crate::view_state::{Content, ProbeState, SceneCamera, SceneState};

/// Width of the side panel, points.
pub const SIDE_PANEL_WIDTH: f32 = 290.0;

/// The light sources a user can pick.
fn sources() -> Vec<ModelSpec> {
    let mut all: Vec<ModelSpec> = Method::ALL.into_iter().map(ModelSpec::from).collect();
    all.push(ModelSpec::Lights(LightSource::Sun));
    all
}

/// A light count the method accepts: the nearest power of two for median cut, 1 for the sun.
fn accepted_count(spec: ModelSpec, n: usize) -> usize {
    match spec {
        ModelSpec::Lights(LightSource::Sun) => 1,
        s if s.method() == Some(Method::MedianCut) => n.max(1).next_power_of_two().min(4096),
        _ => n.clamp(1, 4096),
    }
}

fn curve_name(c: ToneCurve) -> &'static str {
    match c {
        ToneCurve::Clamp => "clamp",
        ToneCurve::Reinhard => "Reinhard",
        ToneCurve::AcesFilmic => "ACES filmic",
    }
}

fn display_controls(ui: &mut egui::Ui, display: &mut ibl_core::tonemap::Display, automatic: f32) {
    ui.horizontal(|ui| {
        ui.add(
            egui::Slider::new(&mut display.exposure_stops, -24.0..=24.0)
                .text("exposure (stops)")
                .step_by(0.1),
        );
    });
    ui.horizontal(|ui| {
        if ui.button("auto exposure").clicked() {
            display.exposure_stops = automatic;
        }
        egui::ComboBox::from_label("tone curve")
            .selected_text(curve_name(display.curve))
            .show_ui(ui, |ui| {
                for c in [ToneCurve::Clamp, ToneCurve::Reinhard, ToneCurve::AcesFilmic] {
                    ui.selectable_value(&mut display.curve, c, curve_name(c));
                }
            });
    });
}

fn probe_panel(ui: &mut egui::Ui, p: &mut ProbeState) {
    ui.heading("Probe");
    ui.label(p.model.path.display().to_string());
    ui.label(format!(
        "{} x {} lat-long (from {}); {}",
        p.model.latlong.width(),
        p.model.latlong.height(),
        p.model.mapping.name(),
        p.model.details
    ));
    ui.separator();
    ui.label("View");
    ui.horizontal(|ui| {
        ui.selectable_value(
            &mut p.settings.projection,
            ProbeProjection::LookAround,
            "look around",
        );
        ui.selectable_value(
            &mut p.settings.projection,
            ProbeProjection::LatLong,
            "lat-long",
        );
    });
    ui.horizontal(|ui| {
        ui.selectable_value(&mut p.settings.layer, ProbeLayer::Radiance, "radiance");
        ui.selectable_value(
            &mut p.settings.layer,
            ProbeLayer::ShIrradiance,
            "SH irradiance / pi",
        );
    });
    let mut fov = p.settings.orbit.vertical_fov.to_degrees();
    if ui
        .add(egui::Slider::new(&mut fov, 10.0..=150.0).text("field of view (deg)"))
        .changed()
    {
        p.settings.orbit.vertical_fov = fov.to_radians();
    }
    ui.horizontal(|ui| {
        for (k, name) in ["+X", "-X", "+Y", "-Y", "+Z", "-Z"].iter().enumerate() {
            if ui
                .button(*name)
                .on_hover_text(format!("key {}", k + 1))
                .clicked()
            {
                let (yaw, pitch) = crate::view_state::axis_view(k);
                p.settings.orbit.yaw = yaw;
                p.settings.orbit.pitch = pitch;
                p.settings.projection = ProbeProjection::LookAround;
            }
        }
    });
    ui.add(egui::Slider::new(&mut p.settings.sharpen, 0.0..=2.0).text("Laplacian sharpening"));
    ui.separator();
    ui.label("Display");
    let automatic = ibl_core::tonemap::auto_exposure_stops(&p.model.latlong);
    display_controls(ui, &mut p.settings.display, automatic);
    ui.separator();
    ui.label("Lights");
    light_source_controls(ui, &mut p.settings.spec, &mut p.settings.lights);
    let mut bands = p.settings.bands as u32;
    if ui
        .add(egui::Slider::new(&mut bands, 1..=8).text("SH bands"))
        .changed()
    {
        p.settings.bands = bands as usize;
    }
    ui.checkbox(&mut p.settings.overlays.lights, "lights");
    ui.checkbox(&mut p.settings.overlays.regions, "their regions");
    ui.checkbox(&mut p.settings.overlays.dominant, "dominant light");
    if p.overlay_busy() {
        ui.label("computing...");
    } else if let Some(o) = p.overlay() {
        ui.label(format!(
            "{} lights ({}), {:.0} ms",
            o.set.lights.len(),
            o.set.provenance.extraction.name(),
            p.overlay_seconds * 1e3
        ));
        if let Some(d) = &o.dominant {
            ui.label(format!(
                "dominant light: {:.1}% of the power, confidence {:.2}",
                100.0 * d.share,
                d.confidence
            ));
        }
    }
    ui.separator();
    let look_around = p.settings.projection == ProbeProjection::LookAround;
    crate::room_panel::room_section(ui, &mut p.room, look_around);
    if p.room.room_path.is_some() {
        ui.separator();
        crate::room_panel::materials_section(ui, &p.room, &mut p.edit);
    }
    ui.separator();
    if let Some((d, l)) = p.cursor {
        let elevation = d.y.clamp(-1.0, 1.0).asin().to_degrees();
        let azimuth = d.x.atan2(-d.z).to_degrees();
        ui.label(format!(
            "cursor: azimuth {azimuth:.1}, elevation {elevation:.1} deg"
        ));
        ui.label(format!(
            "radiance {:.4} {:.4} {:.4} (luminance {:.4})",
            l.r,
            l.g,
            l.b,
            l.luminance()
        ));
    } else {
        ui.label("cursor: outside the view");
    }
}

fn light_source_controls(ui: &mut egui::Ui, spec: &mut ModelSpec, lights: &mut usize) {
    egui::ComboBox::from_label("light method")
        .selected_text(spec.to_string())
        .show_ui(ui, |ui| {
            for s in sources() {
                ui.selectable_value(spec, s, s.to_string());
            }
        });
    let mut n = *lights as u32;
    if ui
        .add(
            egui::Slider::new(&mut n, 1..=256)
                .logarithmic(true)
                .text("lights"),
        )
        .changed()
    {
        *lights = n as usize;
    }
    *lights = accepted_count(*spec, *lights);
}

/// The hybrid ambient's bands: `auto` (the count the scene's samples and occlusion rays give,
/// shown on the slider) or a count of the user's.
fn ambient_bands_row(ui: &mut egui::Ui, lighting: &mut LightingDescription) {
    ui.horizontal(|ui| {
        let mut auto = lighting.ambient_bands == AmbientBands::Auto;
        let mut bands = lighting
            .ambient_bands
            .resolve(lighting.spp, lighting.ao_samples) as u32;
        if ui
            .checkbox(&mut auto, "auto bands")
            .on_hover_text("the rays' bands from the samples and rays a pixel traces")
            .changed()
        {
            lighting.ambient_bands = if auto {
                AmbientBands::Auto
            } else {
                AmbientBands::Fixed(bands)
            };
        }
        let slider = egui::Slider::new(&mut bands, 1..=8).text("ambient SH bands");
        if ui.add_enabled(!auto, slider).changed() {
            lighting.ambient_bands = AmbientBands::Fixed(bands);
        }
    });
}

fn scene_panel(ui: &mut egui::Ui, s: &mut SceneState, gpu_changed: &mut bool) {
    ui.heading("Scene");
    ui.label(s.model.path.display().to_string());
    ui.separator();
    // An outdoor sequence's lights come from its frames, a room's live display's from the
    // room (crate::room_live): neither has a [lighting] to edit.
    if s.sequence.is_some() || s.fixed_lighting {
        if let Some(sequence) = &mut s.sequence {
            sequence_section(ui, sequence);
        } else if let Some(l) = s.renderer_lighting_summary() {
            ui.label(l);
        }
        ui.separator();
        ui.label("Display");
        let automatic = crate::headless::auto_exposure(&s.model);
        display_controls(ui, &mut s.display, automatic);
        ui.separator();
        object_panel(ui, s, gpu_changed);
        return;
    }
    ui.label("Lighting");
    let d = &mut s.model.description;
    let mut mode = match d.render.mode {
        RenderMode::Hybrid => RenderMode::Hybrid,
        _ => RenderMode::Lights,
    };
    ui.horizontal(|ui| {
        ui.selectable_value(&mut mode, RenderMode::Lights, "lights");
        ui.selectable_value(
            &mut mode,
            RenderMode::Hybrid,
            "hybrid (lights + SH ambient)",
        );
    });
    if mode != RenderMode::Hybrid && d.render.mode == RenderMode::Reference {
        // Untouched: keep the file's reference mode.
    } else {
        d.render.mode = mode;
    }
    let mut spec = ModelSpec::Lights(d.lighting.method);
    let mut n = d.lighting.lights as usize;
    light_source_controls(ui, &mut spec, &mut n);
    if let ModelSpec::Lights(source) = spec {
        d.lighting.method = source;
    }
    d.lighting.lights = n as u32;
    ui.horizontal(|ui| {
        ui.selectable_value(&mut d.lighting.shadows, ShadowKind::Hard, "hard shadows");
        ui.selectable_value(
            &mut d.lighting.shadows,
            ShadowKind::Soft,
            "soft (light's cone)",
        );
    });
    if mode == RenderMode::Hybrid {
        ambient_bands_row(ui, &mut d.lighting);
    }
    ui.horizontal(|ui| {
        ui.label("composite");
        ui.selectable_value(
            &mut d.render.composite,
            CompositeRule::Difference,
            "difference",
        );
        ui.selectable_value(&mut d.render.composite, CompositeRule::Ratio, "ratio");
    });
    ui.horizontal(|ui| {
        ui.label("glossy");
        ui.selectable_value(&mut s.glossy, GlossySource::Lights, "lights");
        ui.selectable_value(
            &mut s.glossy,
            GlossySource::Environment,
            "prefiltered probe",
        );
    });
    egui::ComboBox::from_label("shadow maps")
        .selected_text(format!("{0} x {0}", s.shadow_tile))
        .show_ui(ui, |ui| {
            for t in [256, 512, 1024, 2048] {
                ui.selectable_value(&mut s.shadow_tile, t, format!("{t} x {t}"));
            }
        });
    ui.add(egui::Slider::new(&mut s.background_rays, 1..=4).text("background rays per axis"));
    if let Some(l) = s.lighting() {
        ui.label(format!(
            "{} ({:.0} ms)",
            l.summary,
            s.lighting_seconds * 1e3
        ));
    }
    if s.lighting_busy() {
        ui.label("computing the lights...");
    }
    ui.separator();
    ui.label("Display");
    let automatic = crate::headless::auto_exposure(&s.model);
    display_controls(ui, &mut s.display, automatic);
    ui.separator();
    ui.label("Camera");
    ui.horizontal(|ui| {
        if ui.button("scene camera").clicked() {
            s.camera = SceneCamera::File;
        }
        if !s.camera_movable() {
            ui.label("(the photograph fixes the camera)");
        }
    });
    ui.separator();
    object_panel(ui, s, gpu_changed);
    ui.separator();
    let label = ui.label("Save the edited scene to (Ctrl+S)");
    ui.text_edit_singleline(&mut s.save_path)
        .labelled_by(label.id);
}

fn object_panel(ui: &mut egui::Ui, s: &mut SceneState, gpu_changed: &mut bool) {
    let count = s.model.object_count();
    ui.label(format!("Objects ({count})"));
    ui.horizontal_wrapped(|ui| {
        for i in 0..count {
            let name = s.model.object_name(i);
            if ui.selectable_label(s.selected == Some(i), name).clicked() {
                s.selected = Some(i);
            }
        }
    });
    let Some(i) = s.selected.filter(|&i| i < count) else {
        ui.label(
            "click an object to select it; drag to move it, Shift-drag turns, Ctrl-drag scales",
        );
        return;
    };
    let entry = &mut s.model.description.object[i];
    let mut t = entry.translate.unwrap_or_default();
    let mut r = entry.rotate_deg.unwrap_or_default();
    ui.horizontal(|ui| {
        ui.label("translate");
        for v in &mut t {
            ui.add(egui::DragValue::new(v).speed(0.005));
        }
    });
    ui.horizontal(|ui| {
        ui.label("yaw pitch roll");
        for v in &mut r {
            ui.add(egui::DragValue::new(v).speed(0.5).suffix(" deg"));
        }
    });
    if Some(t) != entry.translate && (entry.translate.is_some() || t != [0.0; 3]) {
        entry.translate = Some(t);
    }
    if Some(r) != entry.rotate_deg && (entry.rotate_deg.is_some() || r != [0.0; 3]) {
        entry.rotate_deg = Some(r);
    }
    let mut factor = 1.0f32;
    ui.horizontal(|ui| {
        ui.label("scale");
        if ui.button("-10%").clicked() {
            factor = 0.9;
        }
        if ui.button("+10%").clicked() {
            factor = 1.0 / 0.9;
        }
    });
    if factor != 1.0 {
        s.model.scale(i, factor);
    }
    let before = s.model.material_description(i);
    let mut m = before.clone();
    material_controls(ui, &mut m);
    if m != before {
        s.model.set_material(i, m);
        *gpu_changed = true;
    }
}

fn material_controls(ui: &mut egui::Ui, m: &mut MaterialDescription) {
    let name = |k: MaterialKind| match k {
        MaterialKind::Diffuse => "diffuse",
        MaterialKind::Glossy => "glossy",
        MaterialKind::Mirror => "mirror",
    };
    let before = m.kind;
    ui.horizontal(|ui| {
        ui.label("material");
        for k in [
            MaterialKind::Diffuse,
            MaterialKind::Glossy,
            MaterialKind::Mirror,
        ] {
            ui.selectable_value(&mut m.kind, k, name(k));
        }
    });
    if m.kind != before {
        // Keep only the fields the new kind takes (the scene format refuses the others).
        match m.kind {
            MaterialKind::Diffuse => {
                m.specular = None;
                m.exponent = None;
                m.albedo = m.albedo.or(Some([0.5; 3]));
            }
            MaterialKind::Glossy => {
                let a = m.albedo.unwrap_or([0.5; 3]);
                let s = m.specular.unwrap_or([0.3; 3]);
                // albedo + specular <= 1 per channel.
                m.albedo = Some(std::array::from_fn(|k| a[k].min(1.0 - s[k])));
                m.specular = Some(s);
                m.exponent = m.exponent.or(Some(50.0));
            }
            MaterialKind::Mirror => {
                m.albedo = None;
                m.exponent = None;
                m.specular = m.specular.or(Some([0.9; 3]));
            }
        }
    }
    if let Some(a) = &mut m.albedo {
        ui.horizontal(|ui| {
            ui.label("albedo");
            ui.color_edit_button_rgb(a);
        });
    }
    if let Some(s) = &mut m.specular {
        ui.horizontal(|ui| {
            ui.label(if m.kind == MaterialKind::Mirror {
                "reflectance"
            } else {
                "specular"
            });
            ui.color_edit_button_rgb(s);
        });
    }
    if let Some(e) = &mut m.exponent {
        ui.add(
            egui::Slider::new(e, 1.0..=10000.0)
                .logarithmic(true)
                .text("Phong exponent"),
        );
    }
    if m.kind == MaterialKind::Glossy
        && let (Some(a), Some(s)) = (&mut m.albedo, m.specular)
    {
        for k in 0..3 {
            a[k] = a[k].min(1.0 - s[k]).max(0.0);
        }
    }
}

/// What the user asked for in the side panel this frame; the window carries it out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PanelRequests {
    /// "save frame" was pressed.
    pub save_frame: bool,
    /// "save scene" was pressed.
    pub save_scene: bool,
    /// A material was edited: the GPU copy must be rewritten.
    pub materials_changed: bool,
}

/// The side panel for what is open.
pub fn side_panel(ui: &mut egui::Ui, content: &mut Content) -> PanelRequests {
    let mut requests = PanelRequests::default();
    egui::Panel::right("controls")
        .default_size(SIDE_PANEL_WIDTH)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                match content {
                    Content::Empty => {
                        ui.heading("ibl view");
                        ui.label("Drop a probe (.exr, .hdr, .pfm, ...) or a scene (.toml) here.");
                    }
                    Content::Probe(p) => probe_panel(ui, p),
                    Content::Scene(s) => scene_panel(ui, s, &mut requests.materials_changed),
                }
                ui.separator();
                ui.horizontal(|ui| {
                    requests.save_frame = ui.button("save frame (F12)").clicked();
                    requests.save_scene = matches!(content, Content::Scene(s) if !s.fixed_lighting)
                        && ui.button("save scene").clicked();
                });
            });
        });
    requests
}

/// What the status line reports beside the content.
#[derive(Clone, Copy, Debug)]
pub struct StatusLine<'a> {
    /// Frames per second over the last second.
    pub fps: f64,
    /// The GPU adapter, one line.
    pub adapter: &'a str,
    /// The last error, shown in red until the next successful action.
    pub error: Option<&'a str>,
    /// The last message (opened or saved files).
    pub message: Option<&'a str>,
}

/// The status line.
pub fn status_bar(ui: &mut egui::Ui, content: &Content, status: StatusLine<'_>) {
    egui::Panel::bottom("status").show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.label(format!("{:.1} fps", status.fps));
            match content {
                Content::Scene(s) => {
                    let lights = s.lighting().map_or(0, |l| l.lights.len());
                    let points = s.lighting().map_or(0, |l| l.luminaires.len());
                    let points = match points {
                        0 => String::new(),
                        n => format!(" + {n} point lights"),
                    };
                    ui.label(format!(
                        "{lights} lights{points}, shadow maps {}^2",
                        s.drawn_shadow_tile()
                    ));
                    if let Some(t) = s.pass_times() {
                        ui.label(format!("GPU {:.1} ms", t.total() * 1e3));
                    }
                    if let Some(i) = s.hovered {
                        ui.label(format!("under the cursor: {}", s.model.object_name(i)));
                    }
                    if s.model.is_edited() {
                        ui.label("edited");
                    }
                }
                Content::Probe(p) => {
                    if let Some(o) = p.overlay() {
                        ui.label(format!("{} lights", o.set.lights.len()));
                    }
                    if p.marking_lines() {
                        ui.label(format!("marking {} lines", p.room.axis.name()));
                    }
                }
                Content::Empty => {}
            }
            ui.label(status.adapter);
            if let Some(e) = status.error {
                ui.colored_label(egui::Color32::from_rgb(255, 110, 100), e);
            } else if let Some(m) = status.message {
                ui.label(m);
            }
        });
    });
}

/// Text over the view when nothing is shown.
pub fn central_messages(
    ui: &mut egui::Ui,
    content: &Content,
    error: Option<&str>,
    rect: egui::Rect,
) {
    if !matches!(content, Content::Empty) {
        return;
    }
    let text = match error {
        Some(e) => format!("{e}\n\nDrop a probe or a scene file onto the window."),
        None => "Drop a probe or a scene file onto the window.".to_string(),
    };
    ui.painter().text(
        rect.center(),
        egui::Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(16.0),
        egui::Color32::from_gray(200),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_snap_to_what_the_method_makes() {
        let median_cut = ModelSpec::from(Method::MedianCut);
        assert_eq!(accepted_count(median_cut, 12), 16);
        assert_eq!(accepted_count(median_cut, 16), 16);
        assert_eq!(accepted_count(ModelSpec::Lights(LightSource::Sun), 12), 1);
        assert_eq!(accepted_count(ModelSpec::from(Method::LightGen), 12), 12);
    }
}
