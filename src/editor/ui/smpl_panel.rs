//! An SMPL body's panel: β sliders, clip, playback, timeline and blending.

use bevy_egui::egui;

use crate::formats::scene::SmplDoc;
use crate::scene::smpl::SmplCharacter;

/// The number of shape coefficients shown.
const SHAPE_SLIDERS: usize = 10;

/// Draws the body's controls; returns its new state when one was changed.
pub fn smpl_panel(ui: &mut egui::Ui, body: &SmplCharacter) -> Option<SmplDoc> {
    let mut state = body.state.clone();
    egui::CollapsingHeader::new("SMPL shape and motion").default_open(true).show(ui, |ui| {
        shape_sliders(ui, &mut state);
        let names: Vec<&str> = body.clips.iter().map(|c| c.0.as_str()).collect();
        clip_choice(ui, "clip", &names, &mut state.clip);
        if state.clip != body.state.clip {
            state.time = 0.0;
        }
        if body.clip().is_some() {
            playback_rows(ui, body, &names, &mut state);
        }
    });
    (state != body.state).then_some(state)
}

fn shape_sliders(ui: &mut egui::Ui, state: &mut SmplDoc) {
    let mut betas = state.betas.clone();
    betas.resize(SHAPE_SLIDERS.max(betas.len()), 0.0);
    let mut changed = false;
    for (b, beta) in betas.iter_mut().enumerate().take(SHAPE_SLIDERS) {
        changed |= ui.add(slider(beta, -3.0..=3.0).text(format!("β{}", b + 1)).max_decimals(3)).changed();
    }
    if ui.small_button("Zero the shape").clicked() {
        betas.iter_mut().for_each(|b| *b = 0.0);
        changed = true;
    }
    if changed {
        state.betas = betas;
    }
}

fn playback_rows(ui: &mut egui::Ui, body: &SmplCharacter, names: &[&str], state: &mut SmplDoc) {
    ui.horizontal(|ui| {
        if ui.button(if state.playing { "Pause" } else { "Play" }).clicked() {
            state.playing = !state.playing;
        }
        ui.checkbox(&mut state.looping, "loop");
        ui.checkbox(&mut state.upright, "upright");
    });
    let last = body.clip().map_or(0.0, |k| crate::document::motion::smpl_span(k).end);
    ui.add(slider(&mut state.time, 0.0..=last).text("time (s)").max_decimals(2));
    ui.add(slider(&mut state.speed, 0.1..=3.0).text("speed"));
    clip_choice(ui, "blend with", names, &mut state.blend_clip);
    if state.blend_clip.is_some() {
        ui.add(slider(&mut state.blend, 0.0..=1.0).text("blend"));
    }
}

/// A drop-down of the folder's clips (or none), shown without the file name's decoration.
fn clip_choice(ui: &mut egui::Ui, label: &str, names: &[&str], choice: &mut Option<String>) {
    let short = |n: &str| n.trim_start_matches("smpl_quaternions_").trim_end_matches(".txt").to_string();
    named_choice(ui, label, names, choice, short);
}

/// A drop-down of named things (or none), each shown as `shown` writes its name.
pub fn named_choice(
    ui: &mut egui::Ui,
    label: &str,
    names: &[&str],
    choice: &mut Option<String>,
    shown: impl Fn(&str) -> String,
) {
    let selected = choice.as_deref().map_or("(none)".to_string(), &shown);
    egui::ComboBox::from_label(label).selected_text(selected).show_ui(ui, |ui| {
        ui.selectable_value(choice, None, "(none)");
        for &n in names {
            ui.selectable_value(choice, Some(n.to_string()), shown(n));
        }
    });
}

/// A slider that leaves a value from a file outside its range as it is until it is moved
/// (so showing it is no edit).
pub fn slider(value: &mut f32, range: std::ops::RangeInclusive<f32>) -> egui::Slider<'_> {
    egui::Slider::new(value, range).clamping(egui::SliderClamping::Edits)
}
