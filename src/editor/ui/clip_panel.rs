//! A keyframed clip's panel: play, pause, loop, the timeline and speed, and taking it off.

use bevy_egui::egui;

use super::smpl_panel::slider;
use crate::formats::scene::AnimDoc;
use crate::scene::keyframes::ClipPlayer;

/// Draws the clip's controls; returns the new state (none: the clip taken off) when one
/// was changed.
pub fn clip_panel(ui: &mut egui::Ui, player: &ClipPlayer) -> Option<Option<AnimDoc>> {
    let mut state = player.state.clone();
    let mut remove = false;
    let title = format!("Clip {}", state.file.file_name().map(|f| f.to_string_lossy()).unwrap_or_default());
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
