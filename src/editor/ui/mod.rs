//! The egui panels: the scene panel (left), the joint panel (right) and an SMPL body's
//! panel inside the scene panel. They read the live scene and push [`Edit`]s; nothing here
//! writes the scene itself.

pub mod attach_panel;
pub mod clip_panel;
pub mod conditioning;
pub mod dialogs;
pub mod fit;
pub mod joint_panel;
pub mod keyframe_panel;
pub mod motion_panel;
pub mod open;
pub mod pose_panel;
pub mod recent;
pub mod scene_panel;
pub mod smpl_panel;
pub mod stage_panel;
pub mod unsaved;

use bevy::diagnostic::{DiagnosticsStore, FrameTimeDiagnosticsPlugin};
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy_egui::{EguiContexts, EguiPrimaryContextPass, egui};

use super::state::{Messages, Selection};
use crate::editor::edits::edit::{Edit, EditQueue, GestureHold};
use crate::editor::edits::history::History;
use crate::editor::interact::camera::fit_camera_viewport;
use crate::editor::interact::pointer::ViewportArea;
use crate::editor::present::screenshot::ScreenshotRequest;
use crate::editor::scene_doc::document::{Library, NextCharacterId, PendingScene, SceneReader};

/// Text fields and transient state of the panels.
#[derive(Resource)]
pub struct InspectorState {
    pub add_path: String,
    pub scene_path: String,
    /// The DOF being dragged and its value, shown in the viewport.
    pub active_dof: Option<String>,
    /// The keypoints last fitted, drawn over the view.
    pub keypoints: Option<fit::KeypointOverlay>,
    /// How many characters "Add crowd" adds.
    pub crowd_size: usize,
    /// Joint rotations copied to paste as keys.
    pub copied_keys: Vec<(usize, crate::rig::JointRotation)>,
    /// The key picked in the curve view.
    pub picked_key: Option<keyframe_panel::PickedKey>,
    /// Where "Save .anim" writes.
    pub anim_path: String,
    /// A pose copied by joint name, to paste.
    pub copied_pose: Vec<(String, crate::rig::JointRotation)>,
    /// The character the copied pose was taken from (its asset and humanoid map).
    pub copied_rig: Option<(std::sync::Arc<crate::rig::CharacterAsset>, crate::rig::humanoid::HumanoidMap)>,
    /// The name "Keep pose" keeps the pose under.
    pub pose_name: String,
    /// The file dialog.
    pub dialogs: dialogs::FileDialogs,
    /// The name "Keep view" keeps the camera under.
    pub bookmark_name: String,
    /// Show the shot's frame in the viewport.
    pub frame_guide: bool,
    /// The built-in body poses: mirrored, how much of each to blend in, and their
    /// thumbnails on the character (and humanoid map) they were drawn for.
    pub body_mirrored: bool,
    pub body_blend: f32,
    pub body_thumbnails: Option<BodyThumbnails>,
    /// The hands' shapes the sliders show (left, right).
    pub hand_shapes: [crate::rig::hands::HandShape; 2],
}

impl Default for InspectorState {
    fn default() -> Self {
        let cwd = std::env::current_dir().map(|d| d.display().to_string()).unwrap_or_default();
        Self {
            add_path: format!("{cwd}/"),
            scene_path: format!("{cwd}/scene.ron"),
            copied_keys: Vec::new(),
            picked_key: None,
            anim_path: format!("{cwd}/keys.anim"),
            copied_pose: Vec::new(),
            copied_rig: None,
            pose_name: "pose 1".into(),
            dialogs: Default::default(),
            active_dof: None,
            keypoints: None,
            crowd_size: 16,
            bookmark_name: "view 1".into(),
            frame_guide: true,
            body_mirrored: false,
            body_blend: 1.0,
            body_thumbnails: None,
            hand_shapes: [crate::rig::hands::HandShape::preset("relaxed").unwrap_or_default(); 2],
        }
    }
}

/// What the panels read, and where they send edits and requests.
#[derive(SystemParam)]
pub struct Panels<'w, 's> {
    pub scene: SceneReader<'w, 's>,
    /// Each character's skinned vertices (for heights).
    pub skins: Query<'w, 's, &'static crate::scene::SkinScratch>,
    /// Joint matrices (for the pose library's thumbnails).
    pub joint_matrices: Query<'w, 's, &'static crate::scene::CurrentJointToWorld>,
    pub edits: ResMut<'w, EditQueue>,
    pub selection: ResMut<'w, Selection>,
    pub history: ResMut<'w, History>,
    pub messages: ResMut<'w, Messages>,
    /// Whether the scene differs from its file.
    pub saved: ResMut<'w, crate::editor::state::SavedState>,
    pub library: ResMut<'w, Library>,
    pub ids: ResMut<'w, NextCharacterId>,
    pub pending: ResMut<'w, PendingScene>,
    /// A camera the panels ask for.
    pub camera_request: ResMut<'w, crate::editor::state::camera::CameraRequest>,
    /// "Render frames…" (none in an app without the inspector).
    pub frames: Option<ResMut<'w, crate::editor::present::frames_job::FramesJob>>,
    /// The recent files (none in an app without the inspector: nothing is remembered).
    pub recent: Option<ResMut<'w, crate::editor::ui::recent::RecentFiles>>,
    /// The fast viewport's setting.
    pub fast_viewport: Option<ResMut<'w, crate::editor::present::fast_viewport::FastViewport>>,
    /// Symmetry and the limb handles.
    pub posing: PosingTools<'w>,
    /// The ControlNet map over the view (none in an app without it).
    pub conditioning: Option<ResMut<'w, crate::editor::ui::conditioning::ConditioningOverlay>>,
}

/// The body poses' thumbnails, drawn for one character with one humanoid map.
pub type BodyThumbnails =
    (crate::formats::scene::CharacterId, crate::rig::humanoid::HumanoidMap, Vec<crate::formats::scene::LibraryPoseDoc>);

/// The posing tools' settings the panels change.
#[derive(SystemParam)]
pub struct PosingTools<'w> {
    pub symmetry: Option<ResMut<'w, crate::editor::state::Symmetry>>,
    pub handles: Option<ResMut<'w, crate::editor::state::LimbHandles>>,
}

impl Panels<'_, '_> {
    pub fn push(&mut self, edit: impl Into<Edit>) {
        self.edits.push(edit);
    }

    /// Every character's box in the world as it stands (skinned, placed).
    pub fn world_boxes(&self) -> Vec<(Vec3, Vec3)> {
        self.scene
            .characters
            .iter()
            .filter_map(|c| {
                let (lo, hi) = self.skins.get(c.entity).ok()?.bounds;
                Some(crate::editor::scene_doc::arrange::world_box(lo, hi, &c.placement.0))
            })
            .collect()
    }

    /// A character's height as it stands (its skinned vertices, times its scale).
    pub fn height(&self, entity: Entity) -> Option<f32> {
        let placement = self.scene.characters.get(entity).ok()?.placement;
        let (lo, hi) = self.skins.get(entity).ok()?.bounds;
        Some((hi.y - lo.y) * placement.scale)
    }
}

/// What is drawn over the viewport besides the panels: the frame time, the hovered joint.
#[derive(SystemParam)]
pub struct ViewportOverlays<'w> {
    diagnostics: Res<'w, DiagnosticsStore>,
    draw_mode: Option<Res<'w, crate::editor::present::redraw::DrawMode>>,
    hovered: Res<'w, crate::editor::state::HoveredJoint>,
    gizmo: Res<'w, crate::editor::interact::rotate_gizmo::RotateGizmo>,
    moving: Res<'w, crate::editor::interact::move_gizmo::MoveGizmo>,
    fast: Option<Res<'w, crate::editor::present::fast_viewport::FastView>>,
}

pub struct InspectorPlugin;

impl Plugin for InspectorPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<InspectorState>()
            .init_resource::<crate::editor::ui::recent::RecentFiles>()
            .init_resource::<ViewportArea>()
            .init_resource::<crate::editor::present::frames_job::FramesJob>()
            .add_systems(Update, crate::editor::present::frames_job::finish_frames_job)
            .add_systems(Startup, (save_to_the_opened_scene, fit::show_startup_keypoints))
            .add_systems(PostUpdate, fit_camera_viewport)
            .add_systems(EguiPrimaryContextPass, inspector_ui)
            .add_systems(Update, (open_dropped_files, scene_panel::file_shortcuts));
    }
}

/// Points the scene path box (what Save writes) at the scene the editor was opened on.
fn save_to_the_opened_scene(paths: Option<Res<super::state::StartupPaths>>, mut state: ResMut<InspectorState>) {
    let (Some(paths), Ok(cwd)) = (paths, std::env::current_dir()) else { return };
    state.scene_path = crate::document::scenes::initial_save_path(&paths.0, &cwd).display().to_string();
}

/// Draws the panels (their edits land in this frame's `Animate`); the viewport is what
/// they leave free. While a widget is held or typed into, the gesture stays open.
fn inspector_ui(
    mut contexts: EguiContexts,
    mut state: ResMut<InspectorState>,
    mut panels: Panels,
    mut shot: ResMut<ScreenshotRequest>,
    mut viewport_area: ResMut<ViewportArea>,
    mut hold: ResMut<GestureHold>,
    overlays: ViewportOverlays,
) -> Result {
    if shot.hide_ui() {
        // A screenshot without panels shows the whole window.
        viewport_area.set_if_neq(ViewportArea(None));
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?.clone();
    let mut ui = egui::Ui::new(
        ctx.clone(),
        "viewport".into(),
        egui::UiBuilder::new().layer_id(egui::LayerId::background()).max_rect(ctx.viewport_rect()),
    );
    state.active_dof = None;
    egui::Panel::left("scene_panel").resizable(true).default_size(250.0).show(&mut ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| scene_panel::scene_panel(ui, &mut state, &mut panels, &mut shot));
    });
    egui::Panel::right("joint_panel").resizable(true).default_size(250.0).show(&mut ui, |ui| {
        egui::ScrollArea::vertical().show(ui, |ui| joint_panel::joint_panel(ui, &mut state, &mut panels));
    });
    let central = ui.available_rect_before_wrap();
    let area = ViewportArea(Some(Rect::new(central.min.x, central.min.y, central.max.x, central.max.y)));
    viewport_area.set_if_neq(area);
    // The fast view, drawn at a fraction of the pixels while the view moves, fills it.
    let fast = overlays.fast.as_ref().and_then(|f| f.shown);
    if let Some(texture) = fast {
        let whole = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        ui.painter().image(texture, central, whole, egui::Color32::WHITE);
    }
    // The ControlNet map over the view (and over the fast view), in the frame guide.
    if let Some(texture) = panels.conditioning.as_ref().and_then(|c| c.texture()) {
        let frame = crate::editor::ui::conditioning::frame_rect(central, &panels.scene.shot.0);
        let whole = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        ui.painter().image(texture, frame, whole, egui::Color32::WHITE);
    }
    if let Some(points) = &state.keypoints {
        points.draw(ui.painter(), central);
    }
    dialogs::show(&ctx, &mut state, &mut panels, &mut shot);
    let mode = overlays.draw_mode.as_deref().copied().unwrap_or_default();
    let fast_scale = fast.and(panels.fast_viewport.as_ref().map(|s| s.scale));
    frame_time_readout(&ctx, central, &overlays.diagnostics, mode, fast_scale);
    if state.frame_guide {
        frame_guide(&ctx, central, &panels.scene.shot.0);
    }
    hovered_joint_tooltip(&ctx, &panels, &overlays.hovered);
    if let Some(text) =
        state.active_dof.as_ref().or(overlays.gizmo.readout.as_ref()).or(overlays.moving.readout.as_ref())
    {
        egui::Area::new("active_dof".into()).anchor(egui::Align2::CENTER_TOP, [0.0, 36.0]).show(&ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.add(
                    egui::Label::new(egui::RichText::new(text).size(20.0).strong())
                        .wrap_mode(egui::TextWrapMode::Extend),
                )
            });
        });
    }
    let panels = ctx.egui_is_using_pointer() || ctx.egui_wants_keyboard_input();
    if hold.panels != panels {
        hold.panels = panels;
    }
    Ok(())
}

/// Files dropped on the window: a `.ron` opens as the scene, a `.anim` plays on the
/// selected character, others are added as characters (and kept in the recent files).
pub fn open_dropped_files(
    mut drops: MessageReader<bevy::window::FileDragAndDrop>,
    mut state: ResMut<InspectorState>,
    mut panels: Panels,
) {
    for drop in drops.read() {
        if let bevy::window::FileDragAndDrop::DroppedFile { path_buf, .. } = drop {
            open::open_path(&path_buf.to_string_lossy(), &mut state, &mut panels);
        }
    }
}

/// The frame time (ms, smoothed) and frames per second in the viewport's top-right corner,
/// and whether the editor draws on its own (and why) or only on change.
fn frame_time_readout(
    ctx: &egui::Context,
    viewport: egui::Rect,
    diagnostics: &DiagnosticsStore,
    mode: crate::editor::present::redraw::DrawMode,
    fast: Option<f32>,
) {
    let smoothed = |path| diagnostics.get(path).and_then(bevy::diagnostic::Diagnostic::smoothed);
    let (Some(ms), Some(fps)) =
        (smoothed(&FrameTimeDiagnosticsPlugin::FRAME_TIME), smoothed(&FrameTimeDiagnosticsPlugin::FPS))
    else {
        return;
    };
    // Pinned by its right edge, so a longer number grows leftwards, never under the panel.
    let corner = viewport.right_top() + egui::vec2(-10.0, 8.0);
    egui::Area::new("frame_time".into()).pivot(egui::Align2::RIGHT_TOP).fixed_pos(corner).show(ctx, |ui| {
        // Idle, the text stays the same: a text of another size would have egui lay it out
        // again in a frame of its own, and that frame would change it again.
        let text = match (mode.0, fast) {
            (_, Some(scale)) => format!("{ms:>7.1} ms · {fps:>3.0} fps · fast view ×{scale:.2}"),
            (Some(why), None) => format!("{ms:>7.1} ms · {fps:>3.0} fps · {why}"),
            (None, None) => "drawn on change".to_string(),
        };
        let text = egui::RichText::new(text).monospace().color(egui::Color32::WHITE);
        ui.add(egui::Label::new(text).wrap_mode(egui::TextWrapMode::Extend));
    });
}

/// The shot's frame in the viewport: what `render` takes at the shot's aspect (the
/// viewport's height or width, centred), the rest dimmed.
fn frame_guide(ctx: &egui::Context, viewport: egui::Rect, shot: &crate::formats::scene::ShotDoc) {
    let frame = crate::editor::ui::conditioning::frame_rect(viewport, shot);
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, "frame guide".into()));
    let dim = egui::Color32::from_black_alpha(110);
    for outside in [
        egui::Rect::from_min_max(viewport.min, egui::pos2(frame.min.x, viewport.max.y)),
        egui::Rect::from_min_max(egui::pos2(frame.max.x, viewport.min.y), viewport.max),
        egui::Rect::from_min_max(egui::pos2(frame.min.x, viewport.min.y), egui::pos2(frame.max.x, frame.min.y)),
        egui::Rect::from_min_max(egui::pos2(frame.min.x, frame.max.y), egui::pos2(frame.max.x, viewport.max.y)),
    ] {
        if outside.is_positive() {
            painter.rect_filled(outside, 0.0, dim);
        }
    }
    painter.rect_stroke(
        frame,
        0.0,
        egui::Stroke::new(1.0, egui::Color32::from_white_alpha(160)),
        egui::StrokeKind::Inside,
    );
}

/// The joint under the cursor, named beside it: "character · joint (index)".
fn hovered_joint_tooltip(ctx: &egui::Context, panels: &Panels, hovered: &crate::editor::state::HoveredJoint) {
    let Some(hit) = hovered.0 else { return };
    let Ok(c) = panels.scene.characters.get(hit.entity) else { return };
    let (sc, character) = (c.scene, c.character);
    let (Some(pointer), Some(joint)) = (ctx.pointer_hover_pos(), character.asset.skeleton.joints().get(hit.joint))
    else {
        return;
    };
    egui::Area::new("hovered_joint".into()).fixed_pos(pointer + egui::vec2(14.0, 10.0)).show(ctx, |ui| {
        let text = format!("{} · {} ({})", sc.name, joint.name, hit.joint);
        egui::Frame::popup(ui.style())
            .show(ui, |ui| ui.add(egui::Label::new(text).wrap_mode(egui::TextWrapMode::Extend)));
    });
}
