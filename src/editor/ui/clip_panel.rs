//! Clip panels: a keyframed clip's (play, pause, loop, the timeline and speed, taking it
//! off) and a source's own clips' (which clip, the same controls, a second clip blended
//! in).

use bevy_egui::egui;

use super::smpl_panel::slider;
use crate::formats::scene::{AnimDoc, PlaybackDoc};
use crate::scene::keyframes::ClipPlayer;
use crate::scene::node_clips::NodeClipPlayer;

/// Draws the clip's controls; returns the new state (none: the clip taken off) when one
/// was changed.
pub fn clip_panel(ui: &mut egui::Ui, player: &ClipPlayer) -> Option<Option<AnimDoc>> {
    let mut state = player.state.clone();
    let mut remove = false;
    let title = match (&state.keys, &state.retarget) {
        (None, Some(_)) => "Clip (another character's motion)".to_string(),
        _ => format!("Clip {}", state.file.file_name().map(|f| f.to_string_lossy()).unwrap_or_default()),
    };
    egui::CollapsingHeader::new(title).default_open(true).show(ui, |ui| {
        ui.horizontal(|ui| {
            if ui.button(if state.playing { "Pause" } else { "Play" }).clicked() {
                state.playing = !state.playing;
            }
            ui.checkbox(&mut state.looping, "loop");
            remove = ui.small_button("Remove clip").clicked();
        });
        let (start, end) = player.clip.range;
        ui.add(slider(&mut state.time, start..=end.max(start)).text("time (s)").max_decimals(2));
        ui.add(slider(&mut state.speed, 0.1..=3.0).text("speed"));
        ui.label(format!(
            "{} channels, {} keys",
            player.clip.channels.len(),
            player.clip.channels.iter().map(|c| c.keys().len()).sum::<usize>()
        ));
    });
    if remove {
        return Some(None);
    }
    (state != player.state).then_some(Some(state))
}

/// Draws the controls of a source's own clips; returns the new state when one was changed.
pub fn playback_panel(ui: &mut egui::Ui, player: &NodeClipPlayer) -> Option<PlaybackDoc> {
    let mut state = player.state.clone();
    let names: Vec<&str> = player.clips.iter().map(|c| c.name.as_str()).collect();
    egui::CollapsingHeader::new(format!("Animations ({})", names.len())).default_open(true).show(ui, |ui| {
        clip_choice(ui, "clip", &names, &mut state.clip);
        let Some(clip) = player.clip() else { return };
        if state.clip != player.state.clip {
            state.time = 0.0;
        }
        ui.horizontal(|ui| {
            if ui.button(if state.playing { "Pause" } else { "Play" }).clicked() {
                state.playing = !state.playing;
            }
            ui.checkbox(&mut state.looping, "loop");
        });
        ui.add(slider(&mut state.time, 0.0..=clip.duration()).text("time (s)").max_decimals(2));
        ui.add(slider(&mut state.speed, 0.1..=3.0).text("speed"));
        clip_choice(ui, "blend with", &names, &mut state.blend_clip);
        if state.blend_clip.is_some() {
            ui.add(slider(&mut state.blend, 0.0..=1.0).text("blend"));
        }
    });
    (state != player.state).then_some(state)
}

/// A drop-down of the clips by name (or none).
fn clip_choice(ui: &mut egui::Ui, label: &str, names: &[&str], choice: &mut Option<String>) {
    super::smpl_panel::named_choice(ui, label, names, choice, str::to_string);
}
