//! The editor's system order, declared once. In `Update` the pointer's owners go first:
//! who has it (panels or viewport), then the rotation gizmo, the move gizmo, then IK drags, then the
//! viewport's own input (orbit, picking, shortcuts). In `PostUpdate`, in the first step of
//! the scene's `Animate` (`AnimateSteps::Document`, before every playback): a pending scene
//! replaces the world, then the queued edits apply, then the characters' views follow their
//! documents; then the scene's own chain, `Solve → MatrixStack → Skin → Draw`, and in `Draw`
//! the characters re-placed once skinned, then the stage, the camera and the drawing. Plugins put their systems in these sets and
//! import nothing else of each other to be ordered.

use bevy::prelude::*;

use crate::scene::MarionetteSystems;

/// The editor's sets, in the order they run (see the module).
#[derive(SystemSet, Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EditorSystems {
    /// `Update`: whether the pointer belongs to the panels or the viewport; the hovered joint.
    Pointer,
    /// `Update`: the rotation gizmo's drags and typed turns.
    Gizmo,
    /// `Update`: the move gizmo's drags and typed moves (after the rotation gizmo's).
    MoveGizmo,
    /// `Update`: pins and IK drags of joints.
    Drag,
    /// `Update`: orbiting, picking, the viewport's shortcuts.
    Viewport,
    /// `PostUpdate`, in `Animate`: a scene opened replaces the world.
    OpenScene,
    /// `PostUpdate`, in `Animate`: the queued edits, undo and redo.
    Edits,
    /// `PostUpdate`, in `Animate`: the characters' views follow their documents.
    SyncViews,
    /// `PostUpdate`, in `Draw`: characters re-placed once skinned (side by side, one height).
    Arrange,
    /// `PostUpdate`, in `Draw`: the stage, the camera, and drawing skeletons and tools.
    Present,
}

/// Configures [`EditorSystems`] (added by the plugins that use them, once).
pub struct EditorOrderPlugin;

impl Plugin for EditorOrderPlugin {
    fn build(&self, app: &mut App) {
        use EditorSystems::*;
        app.configure_sets(Update, (Pointer, Gizmo, MoveGizmo, Drag, Viewport).chain())
            .configure_sets(
                PostUpdate,
                (OpenScene, Edits, SyncViews).chain().in_set(crate::scene::AnimateSteps::Document),
            )
            .configure_sets(PostUpdate, (Arrange, Present).chain().in_set(MarionetteSystems::Draw))
            // A camera's lens set in `Present` is the lens of the frame it is set in.
            .configure_sets(PostUpdate, Present.before(bevy::camera::CameraUpdateSystems));
    }
}

/// Adds [`EditorOrderPlugin`] unless the app has it.
pub fn add_editor_order(app: &mut App) {
    if !app.is_plugin_added::<EditorOrderPlugin>() {
        app.add_plugins(EditorOrderPlugin);
    }
}
