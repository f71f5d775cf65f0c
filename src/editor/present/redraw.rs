//! The editor draws only when something changes. Bevy's reactive update mode sleeps until
//! input or a window event; this plugin asks for the next frame while something moves by
//! itself: a clip playing, the renderer getting ready (pipelines compiling, meshes on their
//! way to the GPU), a frames job running, a screenshot counting down. egui asks for its own
//! frames (an animation, a text cursor). [`DrawMode`] says which it is, for the readout.

use bevy::prelude::*;
use bevy::window::RequestRedraw;
use bevy::winit::{UpdateMode, WinitSettings};

use crate::editor::present::frames_job::FramesJob;
use crate::editor::present::readiness::{CaptureGate, UpdateCaptureGate};
use crate::editor::present::screenshot::ScreenshotRequest;
use crate::scene::keyframes::ClipPlayer;
use crate::scene::node_clips::NodeClipPlayer;
use crate::scene::smpl::SmplCharacter;

/// The longest the editor may sleep, as a timed job of another room asked this frame (the
/// autosave, due in so long): the sleep after this frame ends then at the latest.
#[derive(Resource, Default, Debug)]
pub struct WakeWithin(Option<std::time::Duration>);

impl WakeWithin {
    /// Wakes the editor within `within` (the shortest of the frame's asks holds).
    pub fn ask(&mut self, within: std::time::Duration) {
        self.0 = Some(self.0.map_or(within, |w| w.min(within)));
    }
}

/// Why the editor draws frames unasked (none: it waits for input).
#[derive(Resource, Default, Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrawMode(pub Option<&'static str>);

/// Frames on change only, and the frames things that move by themselves need.
pub struct RedrawPlugin;

/// The longest the editor sleeps without input (Bevy's desktop settings wake it every 5 s
/// when focused: a frame on llvmpipe costs a tenth of a core over such a wait).
const LONGEST_SLEEP: std::time::Duration = std::time::Duration::from_secs(60);

impl Plugin for RedrawPlugin {
    fn build(&self, app: &mut App) {
        let settings = WinitSettings {
            focused_mode: UpdateMode::reactive(LONGEST_SLEEP),
            unfocused_mode: UpdateMode::reactive_low_power(LONGEST_SLEEP),
        };
        app.insert_resource(settings)
            .init_resource::<DrawMode>()
            .init_resource::<WakeWithin>()
            .add_systems(Last, ask_for_frames_while_busy.after(UpdateCaptureGate))
            .add_systems(
                PreUpdate,
                drop_unchanged_modifiers
                    .after(bevy_egui::EguiPreUpdateSet::ProcessInput)
                    .before(bevy_egui::EguiPreUpdateSet::BeginPass),
            );
    }
}

/// What keeps the editor drawing, if anything: the first of a playing clip, the renderer
/// getting ready, a frames job, a screenshot under way.
pub fn busy_with(
    keyframes: &Query<&ClipPlayer>,
    bodies: &Query<&SmplCharacter>,
    node_clips: &Query<&NodeClipPlayer>,
    gate: Option<&CaptureGate>,
    frames: Option<&FramesJob>,
    screenshot: Option<&ScreenshotRequest>,
) -> Option<&'static str> {
    let playing = keyframes.iter().any(|p| p.state.playing)
        || bodies.iter().any(|b| b.state.playing && b.clip().is_some())
        || node_clips.iter().any(|p| p.state.playing && p.clip().is_some());
    if playing {
        Some("playing")
    } else if gate.is_some_and(|g| !g.is_ready() && g.failed.is_none()) {
        Some("preparing")
    } else if frames.is_some_and(FramesJob::running) {
        Some("rendering frames")
    } else if screenshot.is_some_and(ScreenshotRequest::pending) {
        Some("screenshot")
    } else {
        None
    }
}

/// Asks for the next frame while the editor is busy (writes `RequestRedraw`, `DrawMode`).
#[allow(clippy::too_many_arguments)]
fn ask_for_frames_while_busy(
    keyframes: Query<&ClipPlayer>,
    bodies: Query<&SmplCharacter>,
    node_clips: Query<&NodeClipPlayer>,
    gate: Option<Res<CaptureGate>>,
    frames: Option<Res<FramesJob>>,
    screenshot: Option<Res<ScreenshotRequest>>,
    mut mode: ResMut<DrawMode>,
    mut wake: ResMut<WakeWithin>,
    mut settings: ResMut<WinitSettings>,
    mut redraw: MessageWriter<RequestRedraw>,
) {
    let sleep = wake.0.take().map_or(LONGEST_SLEEP, |w| w.clamp(std::time::Duration::from_millis(1), LONGEST_SLEEP));
    let wanted = WinitSettings {
        focused_mode: UpdateMode::reactive(sleep),
        unfocused_mode: UpdateMode::reactive_low_power(sleep),
    };
    if settings.focused_mode != wanted.focused_mode || settings.unfocused_mode != wanted.unfocused_mode {
        *settings = wanted;
    }
    let busy = busy_with(&keyframes, &bodies, &node_clips, gate.as_deref(), frames.as_deref(), screenshot.as_deref());
    mode.set_if_neq(DrawMode(busy));
    if busy.is_some() {
        redraw.write(RequestRedraw);
    }
}

/// bevy_egui hands egui the modifier keys as an event every frame; egui, seeing an event,
/// asks for another frame, and the editor would never sleep. The event stays where the
/// modifiers changed (egui reads their state from the input besides).
fn drop_unchanged_modifiers(
    mut inputs: Query<&mut bevy_egui::EguiInput>,
    mut last: Local<Option<bevy_egui::egui::Modifiers>>,
) {
    for mut input in &mut inputs {
        let mut seen = *last;
        input.0.events.retain(|event| match event {
            bevy_egui::egui::Event::ModifiersChanged(m) => seen.replace(*m) != Some(*m),
            _ => true,
        });
        *last = seen;
    }
}
