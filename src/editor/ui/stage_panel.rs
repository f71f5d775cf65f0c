//! The stage, the camera and the shot: floor, background, lights with presets (edits of
//! the scene's `StageDoc`), the lens, views and bookmarks (the camera itself), and the
//! picture `render` takes (size presets, samples, the viewport's frame guide).

use crate::editor::edits::kinds;
use crate::editor::present::data::ControlNetChoice;
use bevy_egui::egui;

use super::{InspectorState, Panels};
use crate::formats::scene::{
    Antialias, BackgroundDoc, CameraDoc, LampDoc, MAX_LAMPS, ShotDoc, SpotDoc, StageDoc, ViewName,
};
use crate::formats::stage::{LightPreset, MAX_PICTURE_SIDE, MAX_SAMPLES, RESOLUTION_PRESETS};

/// The three sections, each folded away until opened.
pub fn stage_panel(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels) {
    let mut stage = panels.scene.stage.0.clone();
    egui::CollapsingHeader::new("Stage and lights").show(ui, |ui| {
        floor_rows(ui, &mut stage);
        background_rows(ui, &mut stage.background);
        light_rows(ui, &mut stage);
    });
    if stage != panels.scene.stage.0 {
        panels.push(kinds::Stage(stage));
    }
    if let Some(camera) = panels.scene.cameras.iter().next().map(|c| c.0) {
        egui::CollapsingHeader::new("Camera and lens").show(ui, |ui| {
            camera_rows(ui, state, panels, camera);
            fast_viewport_rows(ui, panels);
        });
    }
    let mut shot = panels.scene.shot.0;
    egui::CollapsingHeader::new("Shot").show(ui, |ui| {
        shot_rows(ui, state, &mut shot);
        conditioning_rows(ui, panels);
        frames_rows(ui, panels);
    });
    if shot != panels.scene.shot.0 {
        panels.push(kinds::Shot(shot));
    }
}

/// The fast viewport: on or off, and the share of the pixels drawn while the view moves.
fn fast_viewport_rows(ui: &mut egui::Ui, panels: &mut Panels) {
    let Some(fast) = panels.fast_viewport.as_deref_mut() else { return };
    let (mut enabled, mut scale) = (fast.enabled, fast.scale);
    ui.horizontal(|ui| {
        ui.checkbox(&mut enabled, "Fast viewport")
            .on_hover_text("While the view moves, draw it at a share of its pixels, without multisampling and with small shadows (for machines without a GPU); full quality once it is still.");
        ui.add_enabled(enabled, egui::Slider::new(&mut scale, 0.2..=1.0).fixed_decimals(2));
    });
    if (enabled, scale) != (fast.enabled, fast.scale) {
        (fast.enabled, fast.scale) = (enabled, scale);
    }
}

/// The ControlNet map drawn over the view inside the frame guide: off, or one of them.
fn conditioning_rows(ui: &mut egui::Ui, panels: &mut Panels) {
    use crate::editor::ui::conditioning::ConditioningMap;
    let Some(overlay) = panels.conditioning.as_deref_mut() else { return };
    let mut map = overlay.map;
    ui.label("ControlNet map over the view")
        .on_hover_text("drawn as render --controlnet writes it, inside the frame guide, as the figures are posed");
    ui.horizontal(|ui| {
        ui.selectable_value(&mut map, None, "off");
        for m in ConditioningMap::ALL {
            ui.selectable_value(&mut map, Some(m), m.label());
        }
    });
    if map != overlay.map {
        overlay.map = map;
    }
}

/// "Render frames…": the span, rate, turntable and files; then a progress bar and Cancel.
fn frames_rows(ui: &mut egui::Ui, panels: &mut Panels) {
    let Some(job) = panels.frames.as_deref_mut() else { return };
    ui.label("Render frames of the scene's clips");
    if job.running() {
        let (done, all) = job.progress();
        ui.horizontal(|ui| {
            let share = if all > 0 { done as f32 / all as f32 } else { 0.0 };
            ui.add(egui::ProgressBar::new(share).text(format!("{done} of {all}")).desired_width(150.0));
            if ui.button("Cancel").clicked() {
                job.cancel();
            }
        });
        ui.ctx().request_repaint();
        return;
    }
    let r = &mut job.request;
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut r.from).speed(0.05).prefix("from ").suffix(" s"));
        ui.add(egui::DragValue::new(&mut r.to).speed(0.05).prefix("to ").suffix(" s"));
        ui.add(egui::DragValue::new(&mut r.fps).range(1.0..=240.0).suffix(" fps"));
    });
    ui.horizontal(|ui| {
        let mut turn = r.turntable.is_some();
        ui.checkbox(&mut turn, "turntable");
        let mut seconds = r.turntable.unwrap_or(4.0);
        if turn {
            ui.add(egui::DragValue::new(&mut seconds).range(0.1..=600.0).suffix(" s a turn"));
        }
        r.turntable = turn.then_some(seconds);
    });
    ui.add(egui::TextEdit::singleline(&mut r.pattern).desired_width(230.0))
        .on_hover_text("one %04d for the frame number");
    ui.checkbox(&mut r.with_data, "with data")
        .on_hover_text("each frame's depth, normals, masks and OpenPose files, and one COCO file for all");
    controlnet_choice(
        ui,
        &mut r.controlnet,
        "each frame's OpenPose drawing and JSON, depth and normals as ControlNet reads them",
    );
    if ui.button("Render frames…").clicked()
        && let Err(e) = job.start(&panels.scene.capture())
    {
        panels.messages.push(e);
    }
}

/// The "ControlNet maps" box, and under it while on, the canny edges with their two
/// thresholds (`--canny LOW,HIGH`).
pub fn controlnet_choice(ui: &mut egui::Ui, choice: &mut ControlNetChoice, what: &str) {
    ui.checkbox(&mut choice.on, "ControlNet maps").on_hover_text(what);
    if !choice.on {
        return;
    }
    ui.horizontal(|ui| {
        ui.checkbox(&mut choice.canny, "canny edges")
            .on_hover_text("the picture's edges as ControlNet's canny preprocessor finds them (cv2.Canny)");
        if choice.canny {
            let t = &mut choice.thresholds;
            ui.add(egui::DragValue::new(&mut t.low).range(0.0..=1020.0).prefix("low "));
            ui.add(egui::DragValue::new(&mut t.high).range(0.0..=1020.0).prefix("high "));
        }
    });
}

/// An sRGB colour picker.
fn color(ui: &mut egui::Ui, c: &mut [f32; 3]) {
    ui.color_edit_button_rgb(c);
}

fn floor_rows(ui: &mut egui::Ui, stage: &mut StageDoc) {
    ui.horizontal(|ui| {
        ui.checkbox(&mut stage.floor, "floor");
        color(ui, &mut stage.floor_color);
        ui.checkbox(&mut stage.axes, "axes (A)");
    });
    ui.horizontal(|ui| {
        let mut fixed = stage.floor_size.is_some();
        ui.checkbox(&mut fixed, "floor size").on_hover_text("off: the floor grows with the scene");
        let mut size = stage.floor_size.unwrap_or(20.0);
        if fixed {
            ui.add(egui::DragValue::new(&mut size).speed(0.1).range(0.5..=1000.0).suffix(" m"));
        }
        stage.floor_size = fixed.then_some(size);
        ui.label("height");
        ui.add(egui::DragValue::new(&mut stage.floor_height).speed(0.01).suffix(" m"));
    });
}

fn background_rows(ui: &mut egui::Ui, background: &mut BackgroundDoc) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Background");
        let sky = crate::formats::stage::SKY;
        let kinds = [
            ("sky", BackgroundDoc::Sky),
            ("colour", BackgroundDoc::Color(sky)),
            ("gradient", BackgroundDoc::Gradient { top: sky, bottom: [0.9, 0.9, 0.88] }),
            ("transparent", BackgroundDoc::Transparent),
            ("picture", BackgroundDoc::Image { path: Default::default(), fill: false }),
        ];
        for (label, kind) in kinds {
            let same = std::mem::discriminant(background) == std::mem::discriminant(&kind);
            if ui.selectable_label(same, label).clicked() && !same {
                *background = kind;
            }
        }
        match background {
            BackgroundDoc::Color(c) => color(ui, c),
            BackgroundDoc::Gradient { top, bottom } => {
                color(ui, top);
                color(ui, bottom);
            }
            BackgroundDoc::Image { path, fill } => {
                let mut text = path.display().to_string();
                let typed = ui.add(egui::TextEdit::singleline(&mut text).hint_text("a PNG or JPEG file"));
                if typed.changed() {
                    *path = text.into();
                }
                ui.checkbox(fill, "fill").on_hover_text("cover the frame (else fit inside it)");
            }
            BackgroundDoc::Sky | BackgroundDoc::Transparent => {}
        }
    })
    .response
    .on_hover_text("transparent: a PNG with alpha from render (the viewport shows it clear)");
}

fn light_rows(ui: &mut egui::Ui, stage: &mut StageDoc) {
    ui.horizontal_wrapped(|ui| {
        ui.label("Preset");
        for preset in LightPreset::ALL {
            if ui.button(preset.name()).clicked() {
                *stage = preset.lighting(stage);
            }
        }
    });
    ui.label("Sun");
    ui.add(egui::Slider::new(&mut stage.sun.azimuth, -180.0..=180.0).suffix("°").text("azimuth"))
        .on_hover_text("0°: from the front (+z), 90°: from the right (+x)");
    ui.add(egui::Slider::new(&mut stage.sun.elevation, -10.0..=90.0).suffix("°").text("elevation"));
    ui.horizontal(|ui| {
        ui.add(egui::Slider::new(&mut stage.sun.illuminance, 0.0..=20_000.0).suffix(" lx"));
        color(ui, &mut stage.sun.color);
    });
    ui.horizontal(|ui| {
        ui.checkbox(&mut stage.shadows, "shadows");
        ui.add_enabled(stage.shadows, egui::Checkbox::new(&mut stage.soft_shadows, "soft edges"))
            .on_hover_text("shadows' edges softened; sharp ones draw faster without a GPU");
    });
    ui.horizontal(|ui| {
        ui.label("Ambient");
        ui.add(egui::Slider::new(&mut stage.ambient.brightness, 0.0..=2000.0));
        color(ui, &mut stage.ambient.color);
    });
    let mut remove = None;
    for (i, lamp) in stage.lamps.iter_mut().enumerate() {
        ui.push_id(("lamp", i), |ui| {
            if lamp_rows(ui, i, lamp) {
                remove = Some(i);
            }
        });
    }
    if let Some(i) = remove {
        stage.lamps.remove(i);
    }
    if stage.lamps.len() < MAX_LAMPS && ui.button("Add a lamp").clicked() {
        stage.lamps.push(LampDoc::default());
    }
}

/// One lamp's position, light, shadows and spot; whether "remove" was pressed.
fn lamp_rows(ui: &mut egui::Ui, i: usize, lamp: &mut LampDoc) -> bool {
    let mut remove = false;
    egui::Frame::group(ui.style()).show(ui, |ui| {
        ui.horizontal(|ui| {
            ui.label(format!("Lamp {}", i + 1));
            for k in 0..3 {
                ui.add(egui::DragValue::new(&mut lamp.position[k]).speed(0.02).max_decimals(2));
            }
            remove = ui.small_button("×").on_hover_text("remove the lamp").clicked();
        });
        ui.horizontal(|ui| {
            ui.add(egui::Slider::new(&mut lamp.intensity, 0.0..=4_000_000.0).logarithmic(true).suffix(" lm"));
            color(ui, &mut lamp.color);
            ui.checkbox(&mut lamp.shadows, "shadows");
        });
        ui.horizontal(|ui| {
            let mut spot = lamp.spot.is_some();
            ui.checkbox(&mut spot, "spot at");
            let mut s = lamp.spot.unwrap_or(SpotDoc { aim: glam::Vec3::new(0.0, 1.0, 0.0), angle: 30.0 });
            if spot {
                for k in 0..3 {
                    ui.add(egui::DragValue::new(&mut s.aim[k]).speed(0.02).max_decimals(2));
                }
                ui.add(egui::DragValue::new(&mut s.angle).range(1.0..=89.0).suffix("°"));
            }
            lamp.spot = spot.then_some(s);
        });
    });
    remove
}

fn camera_rows(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels, camera: CameraDoc) {
    let mut c = camera;
    ui.horizontal(|ui| {
        let mut ortho = c.ortho.is_some();
        ui.radio_value(&mut ortho, false, "perspective");
        ui.radio_value(&mut ortho, true, "orthographic (5)");
        if ortho != c.ortho.is_some() {
            c = c.toggled_ortho();
        }
    });
    match &mut c.ortho {
        Some(height) => {
            ui.add(egui::Slider::new(height, 0.05..=100.0).logarithmic(true).suffix(" m").text("view height"));
        }
        None => {
            ui.add(egui::Slider::new(&mut c.fov, 5.0..=120.0).suffix("°").text("field of view"));
            let mut mm = c.focal_length_mm();
            if ui
                .add(egui::Slider::new(&mut mm, 10.0..=300.0).logarithmic(true).suffix(" mm").text("focal length"))
                .changed()
            {
                c.fov = CameraDoc::fov_of_focal_length(mm);
            }
        }
    }
    ui.horizontal_wrapped(|ui| {
        for (view, key) in [
            (ViewName::Front, "1"),
            (ViewName::Right, "3"),
            (ViewName::Top, "7"),
            (ViewName::Back, "Ctrl 1"),
            (ViewName::Left, "Ctrl 3"),
            (ViewName::ThreeQuarter, "9"),
        ] {
            if ui.button(view.name()).on_hover_text(format!("numpad {key}")).clicked() {
                c = c.looking_from(view);
            }
        }
    });
    bookmark_rows(ui, state, panels, &mut c);
    if c != camera {
        panels.camera_request.0 = Some(c);
    }
}

/// "Keep view" under a name; each kept view with Go and ×.
fn bookmark_rows(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels, camera: &mut CameraDoc) {
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut state.bookmark_name).desired_width(110.0));
        if ui.button("Keep view").clicked() && !state.bookmark_name.trim().is_empty() {
            panels.push(kinds::Bookmark { name: state.bookmark_name.trim().to_string(), camera: Some(*camera) });
        }
    });
    let kept: Vec<(String, CameraDoc)> = panels.scene.bookmarks.0.iter().map(|(n, c)| (n.clone(), *c)).collect();
    for (name, kept) in kept {
        ui.horizontal(|ui| {
            if ui.button(format!("Go: {name}")).clicked() {
                *camera = kept;
            }
            if ui.small_button("×").on_hover_text("forget this view").clicked() {
                panels.push(kinds::Bookmark { name, camera: None });
            }
        });
    }
}

fn shot_rows(ui: &mut egui::Ui, state: &mut InspectorState, shot: &mut ShotDoc) {
    let current = RESOLUTION_PRESETS.iter().find(|p| (p.1, p.2) == (shot.width, shot.height)).map_or("custom", |p| p.0);
    egui::ComboBox::from_label("size").selected_text(current).show_ui(ui, |ui| {
        for (name, w, h) in RESOLUTION_PRESETS {
            if ui.selectable_label((w, h) == (shot.width, shot.height), format!("{name} ({w}×{h})")).clicked() {
                (shot.width, shot.height) = (w, h);
            }
        }
    });
    let most = MAX_PICTURE_SIDE / shot.samples.max(1);
    ui.horizontal(|ui| {
        ui.add(egui::DragValue::new(&mut shot.width).range(16..=most).suffix(" px"));
        ui.label("×");
        ui.add(egui::DragValue::new(&mut shot.height).range(16..=most).suffix(" px"));
    });
    ui.horizontal(|ui| {
        ui.label("samples");
        ui.add(egui::Slider::new(&mut shot.samples, 1..=MAX_SAMPLES))
            .on_hover_text("supersampling for stills: each pixel the mean of N×N");
    });
    egui::ComboBox::from_label("edges").selected_text(shot.antialias.name()).show_ui(ui, |ui| {
        for antialias in Antialias::ALL {
            ui.selectable_value(&mut shot.antialias, antialias, antialias.name());
        }
    });
    shot.width = shot.width.min(MAX_PICTURE_SIDE / shot.samples);
    shot.height = shot.height.min(MAX_PICTURE_SIDE / shot.samples);
    ui.checkbox(&mut state.frame_guide, "frame guide in the viewport");
}
