//! The app around the ECS core, in rooms by purpose: [`interact`] (who has the pointer, the
//! orbit camera, picking, IK drags, the rotation gizmo, shortcuts), [`ui`] (the egui panels
//! and dialogs), [`edits`] (edits as commands with undo and redo, the pose library),
//! [`present`] (stage, drawing, readiness, screenshots, the headless renderer) and
//! [`scene_doc`] (the scene's identity, capture and spawning from documents). Files,
//! layout and export are the Bevy-free [`crate::document`] layer's.
//!
//! The ECS is the only live model. The panels, the shortcuts and drags in the viewport read
//! it and push [`edits::edit::Edit`]s, applied in `Animate`; a `SceneDoc` is built only to
//! save, duplicate or remove (what a history entry needs). The order is declared once, in
//! [`order`].
//!
//! Plugins (one per capability): [`present::view::ViewPlugin`] (stage, scene, edits and
//! history, drawing; also used headless), [`InteractionPlugin`] (camera input, picking, IK
//! drag, gizmo, shortcuts), [`ui::InspectorPlugin`], [`present::screenshot::ScreenshotPlugin`], [`ui::conditioning::ConditioningOverlayPlugin`].

pub mod bench;
pub mod cores;
pub mod edits;
pub mod interact;
pub mod order;
pub mod present;
pub mod scene_doc;
pub mod state;
pub mod ui;

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::window::WindowResolution;

use crate::scene::{MarionetteSystems, RigCorePlugin, SkinningPlugin};
pub use cores::{task_pools, windowless_plugins};
use interact::camera::orbit_camera_input;
pub use present::view::{ScenePlugin, ViewPlugin, apply_pending_scene};
use state::camera::OrbitCamera;
pub use state::{Messages, Selection, StartupEdits, StartupPaths, UnloadedCharacters};

/// Mouse and keyboard in the viewport: orbit camera, picking, shortcuts.
pub struct InteractionPlugin;

impl Plugin for InteractionPlugin {
    fn build(&self, app: &mut App) {
        order::add_editor_order(app);
        app.add_plugins((
            interact::ik_drag::IkDragPlugin,
            interact::limb_handles::LimbHandlesPlugin,
            interact::rotate_gizmo::RotateGizmoPlugin,
            interact::move_gizmo::MoveGizmoPlugin,
        ));
        app.init_resource::<interact::pointer::ViewportHasPointer>()
            .init_resource::<interact::pointer::PointerOwner>()
            .init_resource::<interact::picking::PointerPress>()
            .init_resource::<state::HoveredJoint>()
            .add_systems(
                Update,
                (interact::pointer::track_egui_pointer, interact::picking::hover_joint)
                    .chain()
                    .in_set(order::EditorSystems::Pointer),
            )
            .add_systems(
                Update,
                (
                    orbit_camera_input,
                    interact::camera::apply_camera_request,
                    interact::picking::pick_joint_on_click,
                    interact::shortcuts::scene_shortcuts,
                    interact::shortcuts::frame_selection,
                    interact::shortcuts::view_shortcuts,
                )
                    .chain()
                    .in_set(order::EditorSystems::Viewport),
            );
    }
}

/// Opens the editor window on `paths` (or on the default scene), with the files `library`
/// already read, and runs until closed.
pub fn run(paths: Vec<PathBuf>, edits: StartupEdits, library: crate::document::AssetLibrary) {
    ui::unsaved::install_panic_hook(ui::unsaved::Autosave::from_env().file);
    App::new()
        .add_plugins(DefaultPlugins.set(task_pools()).set(WindowPlugin {
            primary_window: Some(Window {
                title: "Marionette".into(),
                resolution: WindowResolution::new(1280, 800),
                ..default()
            }),
            // A close request asks first where there are unsaved changes (`UnsavedWorkPlugin`).
            close_when_requested: false,
            ..default()
        }))
        .add_plugins(bevy_egui::EguiPlugin::default())
        .add_plugins(bevy::diagnostic::FrameTimeDiagnosticsPlugin::default())
        // egui lives on its own full-window camera (see `spawn_window_camera`).
        .insert_resource(bevy_egui::EguiGlobalSettings { auto_create_primary_context: false, ..default() })
        .insert_resource(ClearColor(present::stage::SKY))
        .insert_resource(StartupPaths(paths))
        .insert_resource(edits)
        .insert_resource(scene_doc::document::Library(library))
        // The viewport between the default panels (1280 − 2 × 250 wide, 800 high).
        .insert_resource(state::camera::FramingAspect(780.0 / 800.0))
        .add_plugins((
            RigCorePlugin,
            SkinningPlugin,
            ViewPlugin,
            InteractionPlugin,
            ui::InspectorPlugin,
            ui::recent::RecentFilesPlugin,
            ui::unsaved::UnsavedWorkPlugin,
            present::screenshot::ScreenshotPlugin,
            ui::conditioning::ConditioningOverlayPlugin,
            present::redraw::RedrawPlugin,
            present::fast_viewport::FastViewportPlugin,
        ))
        // The inspector's edits (bevy_egui's pass) land before the chain that animates,
        // solves, runs the matrix stack and skins: an edit is skinned the frame it is made.
        .configure_sets(PostUpdate, MarionetteSystems::Animate.after(bevy_egui::EguiPostUpdateSet::EndPass))
        .add_systems(Startup, spawn_window_camera)
        .add_systems(PostUpdate, present::stage::show_gradient_backdrop.in_set(order::EditorSystems::Present))
        .run();
}

/// The 3D view (whose viewport is the area between the panels) and, drawn over the whole
/// window after it, a camera that carries egui's context and renders nothing else.
fn spawn_window_camera(mut commands: Commands) {
    let orbit = OrbitCamera::default();
    commands.spawn((Camera3d::default(), orbit, orbit.transform(), present::stage::slot_camera(crate::scene::Slot(0))));
    commands.spawn((
        Camera2d,
        Camera { order: 1, clear_color: ClearColorConfig::None, ..default() },
        bevy_egui::PrimaryEguiContext,
    ));
}
