//! Keyframes for any character: key the selected joints (K) at the clip's time, delete,
//! copy and paste keys there, and a curve view of the selected joint's x, y, z channels
//! where keys are dragged in time and value, and a selected key's tangents (dragged, or
//! chosen by rule) and its channel's extrapolation are set. Every change is an
//! `Edit::Clip` with the new keys, so it is undone like any edit; `.anim` export.

use crate::editor::edits::kinds;
use bevy_egui::egui;

use super::{InspectorState, Panels};
use crate::formats::scene::{AnimDoc, CharacterId};
use crate::rig::JointRotation;
use crate::rig::anim::{Channel, Clip, Extrapolation, Key, SAME_TIME, Tangent};
use crate::scene::keyframes::{ClipPlayer, keyed};

const CURVE_HEIGHT: f32 = 170.0;
const KEY_RADIUS: f32 = 4.0;
/// Seconds of a tangent handle's run, in screen pixels.
const HANDLE_PX: f32 = 28.0;
const CHANNEL_COLORS: [egui::Color32; 3] = [
    egui::Color32::from_rgb(240, 80, 90),
    egui::Color32::from_rgb(120, 220, 60),
    egui::Color32::from_rgb(80, 140, 255),
];

/// A key picked in the curve view: its channel and time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PickedKey {
    pub channel: usize,
    pub time: f32,
}

/// The keyframe section of the joint panel for character `id`.
pub fn keyframe_panel(ui: &mut egui::Ui, state: &mut InspectorState, panels: &mut Panels, id: CharacterId) {
    let Some((character, player)) =
        panels.scene.characters.iter().find(|c| c.scene.id == id).map(|c| (c.character, c.player))
    else {
        return;
    };
    let joint_count = character.asset.skeleton.len();
    let pose: Vec<JointRotation> =
        character.joints.iter().map(|&e| panels.scene.poses.get(e).map_or(Default::default(), |p| p.0)).collect();
    let player = player.cloned();
    let selected = panels.selection.joints.clone();
    let mut anim: Option<AnimDoc> = None;
    egui::CollapsingHeader::new("Keyframes").default_open(true).show(ui, |ui| {
        ui.horizontal(|ui| {
            if ui.button("Key (K)").on_hover_text("key the selected joints (all when none) at this time").clicked() {
                anim = Some(keyed(player.as_ref(), joint_count, &selected, &pose));
            }
            let Some(player) = &player else { return };
            let t = player.state.time;
            if ui.button("Delete").on_hover_text("the selected joints' keys at this time").clicked() {
                anim = Some(with_clip(player, delete_keys(&player.clip, &selected, t)));
            }
            if ui.button("Copy").clicked() {
                state.copied_keys = selected.iter().map(|&j| (j, pose[j])).collect();
            }
            if ui.add_enabled(!state.copied_keys.is_empty(), egui::Button::new("Paste")).clicked() {
                let (joints, mut pasted) = (state.copied_keys.iter().map(|c| c.0).collect::<Vec<_>>(), pose.clone());
                state.copied_keys.iter().for_each(|&(j, r)| pasted[j] = r);
                anim = Some(keyed(Some(player), joint_count, &joints, &pasted));
            }
        });
        let Some(player) = &player else {
            ui.label("No keys yet: pose, then Key.");
            return;
        };
        ui.label(format!("time {:.2} s of {:.2}–{:.2}", player.state.time, player.clip.range.0, player.clip.range.1));
        if let Some(&joint) = selected.first() {
            if let Some(clip) = curve_view(ui, state, &player.clip, joint, player.state.time) {
                anim = Some(with_clip(player, clip));
            }
            if let Some(clip) = picked_key_rows(ui, state, &player.clip) {
                anim = Some(with_clip(player, clip));
            }
        } else {
            ui.label("Select a joint to see its curves.");
        }
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut state.anim_path).desired_width(140.0));
            if ui.button("Save .anim").clicked() {
                let path = std::path::PathBuf::from(&state.anim_path);
                let written = crate::formats::write_atomically(&path, |w| {
                    crate::formats::cse169_skin::write_anim(w, &player.clip)
                });
                panels.messages.push(match written {
                    Ok(()) => format!("saved the keys to {}", path.display()),
                    Err(e) => format!("{}: the keys were not saved: {e}", path.display()),
                });
            }
        });
    });
    if let Some(anim) = anim {
        panels.push(kinds::Clip { character: id, anim: Some(anim) });
    }
}

/// The player's state with `clip` as its own keys.
fn with_clip(player: &ClipPlayer, clip: Clip) -> AnimDoc {
    AnimDoc { keys: Some(clip), ..player.state.clone() }
}

/// `clip` without the keys of `joints` at `time`.
fn delete_keys(clip: &Clip, joints: &[usize], time: f32) -> Clip {
    let mut clip = clip.clone();
    for &j in joints {
        for axis in 0..3 {
            if let Some(c) = clip.channels.get_mut(Clip::joint_channel(j, axis)) {
                *c = c.with_keys(|keys| keys.retain(|k| (k.time - time).abs() > SAME_TIME));
            }
        }
    }
    clip
}

/// Maps between the curve view's data (time, value) and screen.
struct Frame {
    rect: egui::Rect,
    t: (f32, f32),
    v: (f32, f32),
}

impl Frame {
    fn to_screen(&self, t: f32, v: f32) -> egui::Pos2 {
        let x = self.rect.left() + (t - self.t.0) / (self.t.1 - self.t.0) * self.rect.width();
        let y = self.rect.bottom() - (v - self.v.0) / (self.v.1 - self.v.0) * self.rect.height();
        egui::pos2(x, y)
    }

    fn to_data(&self, p: egui::Pos2) -> (f32, f32) {
        let t = self.t.0 + (p.x - self.rect.left()) / self.rect.width() * (self.t.1 - self.t.0);
        let v = self.v.0 + (self.rect.bottom() - p.y) / self.rect.height() * (self.v.1 - self.v.0);
        (t, v)
    }

    /// Value units per screen pixel, and time units per pixel.
    fn per_pixel(&self) -> (f32, f32) {
        ((self.t.1 - self.t.0) / self.rect.width(), (self.v.1 - self.v.0) / self.rect.height())
    }
}

/// The selected joint's x, y, z curves over the clip's range with their keys; a key is
/// picked by a click and dragged in time and value, its tangent handles dragged to set
/// its slopes. Returns the edited clip.
fn curve_view(ui: &mut egui::Ui, state: &mut InspectorState, clip: &Clip, joint: usize, now: f32) -> Option<Clip> {
    let channels: Vec<usize> = (0..3).map(|a| Clip::joint_channel(joint, a)).collect();
    let (start, end) = clip.range;
    let span = (end - start).max(0.5);
    let t = (start - 0.05 * span, start + 1.05 * span);
    let samples: Vec<Vec<(f32, f32)>> = channels
        .iter()
        .map(|&c| match clip.channels.get(c).filter(|ch| !ch.keys().is_empty()) {
            Some(ch) => (0..=120).map(|i| t.0 + (t.1 - t.0) * i as f32 / 120.0).map(|x| (x, ch.value_at(x))).collect(),
            None => Vec::new(),
        })
        .collect();
    let values = samples.iter().flatten().map(|s| s.1);
    let (lo, hi) = values.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (-1.0, 1.0) };
    let pad = ((hi - lo) * 0.15).max(0.1);
    let (response, painter) = ui.allocate_painter(egui::vec2(ui.available_width(), CURVE_HEIGHT), egui::Sense::click());
    let frame = Frame { rect: response.rect.shrink(6.0), t, v: (lo - pad, hi + pad) };
    painter.rect_filled(response.rect, 3.0, egui::Color32::from_gray(24));
    let zero = frame.to_screen(t.0, 0.0).y;
    painter.hline(frame.rect.x_range(), zero, egui::Stroke::new(1.0, egui::Color32::from_gray(70)));
    let x_now = frame.to_screen(now, 0.0).x;
    painter.vline(x_now, frame.rect.y_range(), egui::Stroke::new(1.0, egui::Color32::from_rgb(250, 210, 60)));
    for (axis, curve) in samples.iter().enumerate() {
        let points: Vec<egui::Pos2> = curve.iter().map(|&(x, v)| frame.to_screen(x, v)).collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, CHANNEL_COLORS[axis])));
    }
    if response.clicked() {
        state.picked_key = None;
    }
    let mut edited = None;
    for (axis, &c) in channels.iter().enumerate() {
        let Some(channel) = clip.channels.get(c) else { continue };
        for (k, key) in channel.keys().iter().enumerate() {
            let at = frame.to_screen(key.time, key.value);
            let picked = state.picked_key.is_some_and(|p| p.channel == c && (p.time - key.time).abs() <= SAME_TIME);
            let id = ui.make_persistent_id(("key", c, k));
            let hit = ui.interact(
                egui::Rect::from_center_size(at, egui::vec2(12.0, 12.0)),
                id,
                egui::Sense::click_and_drag(),
            );
            if hit.clicked() || hit.drag_started() {
                state.picked_key = Some(PickedKey { channel: c, time: key.time });
            }
            if hit.dragged()
                && let Some(p) = hit.interact_pointer_pos()
            {
                let (time, value) = frame.to_data(p);
                let time = time.clamp(t.0, t.1);
                state.picked_key = Some(PickedKey { channel: c, time });
                edited = Some(edit_key(clip, c, k, |key| {
                    key.time = time;
                    key.value = value;
                }));
            }
            let color = if picked { egui::Color32::WHITE } else { CHANNEL_COLORS[axis] };
            painter.circle_filled(at, KEY_RADIUS, color);
            if picked {
                edited = tangent_handles(ui, &painter, &frame, clip, c, k).or(edited);
            }
        }
    }
    edited
}

/// `clip` with key `k` of channel `c` changed by `change`.
fn edit_key(clip: &Clip, c: usize, k: usize, change: impl FnOnce(&mut Key)) -> Clip {
    let mut clip = clip.clone();
    clip.channels[c] = clip.channels[c].with_keys(|keys| change(&mut keys[k]));
    clip
}

/// The picked key's in and out tangent handles; dragging one sets that side's slope.
fn tangent_handles(
    ui: &mut egui::Ui,
    painter: &egui::Painter,
    frame: &Frame,
    clip: &Clip,
    c: usize,
    k: usize,
) -> Option<Clip> {
    let channel = &clip.channels[c];
    let key = channel.keys()[k];
    let (slope_in, slope_out) = channel.slopes(k);
    let at = frame.to_screen(key.time, key.value);
    let (dt, _) = frame.per_pixel();
    let mut edited = None;
    for (side, slope) in [(-1.0f32, slope_in), (1.0, slope_out)] {
        let run = side * HANDLE_PX * dt;
        let end = frame.to_screen(key.time + run, key.value + slope * run);
        let end = at + (end - at).normalized() * HANDLE_PX;
        painter.line_segment([at, end], egui::Stroke::new(1.0, egui::Color32::from_gray(200)));
        painter.rect_filled(
            egui::Rect::from_center_size(end, egui::vec2(6.0, 6.0)),
            0.0,
            egui::Color32::from_gray(220),
        );
        let id = ui.make_persistent_id(("tangent", c, k, side as i32));
        let hit = ui.interact(egui::Rect::from_center_size(end, egui::vec2(10.0, 10.0)), id, egui::Sense::drag());
        if hit.dragged()
            && let Some(p) = hit.interact_pointer_pos()
        {
            let (t, v) = frame.to_data(p);
            let run = t - key.time;
            if run * side > 1e-4 {
                let slope = (v - key.value) / run;
                edited = Some(edit_key(clip, c, k, |key| {
                    if side < 0.0 {
                        key.tangent_in = Tangent::Fixed(slope);
                    } else {
                        key.tangent_out = Tangent::Fixed(slope);
                    }
                }));
            }
        }
    }
    edited
}

/// The picked key's tangent rules and its channel's extrapolation, as choices.
fn picked_key_rows(ui: &mut egui::Ui, state: &InspectorState, clip: &Clip) -> Option<Clip> {
    let picked = state.picked_key?;
    let channel = clip.channels.get(picked.channel)?;
    let k = channel.keys().iter().position(|key| (key.time - picked.time).abs() <= SAME_TIME)?;
    let key = channel.keys()[k];
    let (mut tangent_in, mut tangent_out) = (key.tangent_in, key.tangent_out);
    let (mut before, mut after) = (channel.before, channel.after);
    ui.label(format!("key at {:.3} s = {:.3}", key.time, key.value));
    tangent_choice(ui, "in", &mut tangent_in);
    tangent_choice(ui, "out", &mut tangent_out);
    extrapolation_choice(ui, "before", &mut before);
    extrapolation_choice(ui, "after", &mut after);
    if (tangent_in, tangent_out, before, after) == (key.tangent_in, key.tangent_out, channel.before, channel.after) {
        return None;
    }
    let mut clip = edit_key(clip, picked.channel, k, |key| {
        key.tangent_in = tangent_in;
        key.tangent_out = tangent_out;
    });
    let keys = clip.channels[picked.channel].keys().to_vec();
    clip.channels[picked.channel] = Channel::new(keys, before, after);
    Some(clip)
}

fn tangent_choice(ui: &mut egui::Ui, label: &str, tangent: &mut Tangent) {
    let name = |t: &Tangent| match t {
        Tangent::Flat => "flat".to_string(),
        Tangent::Step => "step (hold)".to_string(),
        Tangent::Linear => "linear".to_string(),
        Tangent::Smooth => "smooth".to_string(),
        Tangent::Fixed(s) => format!("{s:.3}"),
    };
    egui::ComboBox::from_label(format!("tangent {label}")).selected_text(name(tangent)).show_ui(ui, |ui| {
        for t in [Tangent::Flat, Tangent::Linear, Tangent::Smooth, Tangent::Step] {
            ui.selectable_value(tangent, t, name(&t));
        }
    });
}

fn extrapolation_choice(ui: &mut egui::Ui, label: &str, mode: &mut Extrapolation) {
    let modes = [
        (Extrapolation::Constant, "constant"),
        (Extrapolation::Linear, "linear"),
        (Extrapolation::Cycle, "cycle"),
        (Extrapolation::CycleOffset, "cycle offset"),
        (Extrapolation::Bounce, "bounce"),
    ];
    let shown = modes.iter().find(|m| m.0 == *mode).map_or("", |m| m.1);
    egui::ComboBox::from_label(format!("extrapolate {label}")).selected_text(shown).show_ui(ui, |ui| {
        for (m, name) in modes {
            ui.selectable_value(mode, m, name);
        }
    });
}
