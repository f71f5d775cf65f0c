//! Screenshots of the window (F12 or the panel's button): a PNG named by date and time in
//! a chosen folder, without the panels unless asked; the messages say where it went.

use std::path::{Path, PathBuf};

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

use bevy::window::PrimaryWindow;

use crate::editor::present::data::{ControlNetChoice, DataScene};
use crate::editor::present::readiness::CaptureGate;
use crate::editor::state::Messages;

/// A pending screenshot and the options of the next one.
#[derive(Resource)]
pub struct ScreenshotRequest {
    /// The folder field of the panel.
    pub dir_text: String,
    pub with_panels: bool,
    /// Write the data pictures beside it (the panels are then left out).
    pub with_data: bool,
    /// Write the maps ControlNet reads beside it (the panels are then left out).
    pub controlnet: ControlNetChoice,
    /// Frames left before the capture (the panels are hidden meanwhile).
    countdown: Option<u8>,
}

impl Default for ScreenshotRequest {
    fn default() -> Self {
        let dir =
            std::env::current_dir().map(|d| d.join("screenshots")).unwrap_or_else(|_| PathBuf::from("screenshots"));
        let dir_text = dir.display().to_string();
        Self {
            dir_text,
            with_panels: false,
            with_data: false,
            controlnet: ControlNetChoice::default(),
            countdown: None,
        }
    }
}

impl ScreenshotRequest {
    pub fn request(&mut self) {
        // Two frames without panels, so the captured frame has none.
        self.countdown = Some(if self.panels_shown() { 0 } else { 2 });
    }

    /// Whether a screenshot is counting down to its capture.
    pub fn pending(&self) -> bool {
        self.countdown.is_some()
    }

    /// Whether the panels are in the picture: asked for, and no data pictures (whose
    /// camera is the whole window's).
    fn panels_shown(&self) -> bool {
        self.with_panels && !self.with_data && !self.controlnet.on
    }

    /// Whether the panels are hidden this frame (for a screenshot without them).
    pub fn hide_ui(&self) -> bool {
        self.countdown.is_some() && !self.panels_shown()
    }
}

pub struct ScreenshotPlugin;

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ScreenshotRequest>()
            .add_systems(Last, take_requested_screenshot.after(crate::editor::present::readiness::UpdateCaptureGate));
    }
}

/// `YYYY-MM-DD_HH-MM-SS` (UTC) of a Unix time.
pub fn timestamp(unix_seconds: u64) -> String {
    let days = (unix_seconds / 86_400) as i64;
    let secs = unix_seconds % 86_400;
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}_{:02}-{:02}-{:02}", secs / 3600, secs / 60 % 60, secs % 60)
}

/// Counts down a request and captures the window (writes a `Screenshot` entity).
fn take_requested_screenshot(
    mut commands: Commands,
    mut request: ResMut<ScreenshotRequest>,
    mut messages: ResMut<Messages>,
    gate: Option<Res<CaptureGate>>,
    scene: DataScene,
    windows: Query<&Window, With<PrimaryWindow>>,
) {
    let Some(n) = request.countdown else { return };
    if n > 0 {
        request.countdown = Some(n - 1);
        return;
    }
    if let Some(gate) = &gate {
        if let Some(failed) = &gate.failed {
            request.countdown = None;
            messages.push(format!("no screenshot: {failed}"));
            return;
        }
        if !gate.is_ready() {
            // Pipelines still compiling or meshes not yet on the GPU: wait.
            return;
        }
    }
    request.countdown = None;
    let dir = PathBuf::from(request.dir_text.trim());
    if let Err(e) = std::fs::create_dir_all(&dir) {
        messages.push(format!("no screenshot: cannot create {}: {e}", dir.display()));
        return;
    }
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let path = dir.join(format!("marionette_{}.png", timestamp(now)));
    // The data pictures' frame is taken now, with the frame the capture draws.
    let size = windows.iter().next().map(|w| (w.physical_width(), w.physical_height()));
    let (data, controlnet) = (request.with_data, request.controlnet.maps());
    let frame = match (data || controlnet.is_some(), size) {
        (true, Some((w, h))) => match scene.frame(crate::scene::Slot(0), w, h) {
            Ok(frame) => Some(frame),
            Err(e) => {
                messages.push(format!("no data pictures: {e}"));
                None
            }
        },
        _ => None,
    };
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>, mut messages: ResMut<Messages>| {
            let beside = crate::editor::present::data::Beside { data, controlnet };
            let saved = save_png(&captured.image, &path)
                .and_then(|()| frame.as_ref().map_or(Ok(()), |frame| frame.write_all_beside(&path, beside)));
            match saved {
                Ok(()) if frame.is_some() => {
                    messages.push(format!("saved screenshot {} with its data", path.display()))
                }
                Ok(()) => messages.push(format!("saved screenshot {}", path.display())),
                Err(e) => messages.push(format!("no screenshot: {e}")),
            }
        },
    );
}

/// Writes a captured image as PNG (RGB), whole or not at all.
pub fn save_png(image: &Image, path: &Path) -> Result<(), String> {
    let rgb = image.clone().try_into_dynamic().map_err(|e| format!("unreadable capture: {e}"))?.to_rgb8();
    let mut bytes = Vec::new();
    rgb.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).map_err(|e| e.to_string())?;
    crate::formats::write_atomically(path, |w| std::io::Write::write_all(w, &bytes))
        .map_err(|e| format!("{}: {e}", path.display()))
}
