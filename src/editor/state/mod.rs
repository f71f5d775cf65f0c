//! The editor's shared state, the room every other room uses and that uses none of them:
//! what the app opens with, the messages, the selection, a joint drag under way, the
//! characters that failed to load, the scene's stage, shot and pose library, the joint under
//! the cursor, the pinned joints, and the camera's model (`camera`).

pub mod camera;

use std::collections::BTreeMap;
use std::path::PathBuf;

use bevy::prelude::*;

use crate::formats::scene::CharacterId;

/// What the app opens with: a scene file, character files, or (empty) the default scene.
#[derive(Resource, Clone, Debug, Default)]
pub struct StartupPaths(pub Vec<PathBuf>);

/// Pose and IK edits from the command line, applied to every character of the startup
/// scene that has the named joint (`--pose`, then `--ik`), and the skinning method.
#[derive(Resource, Clone, Debug, Default)]
pub struct StartupEdits {
    /// `--pose`, `--hand`, `--ik`, `--two-bone`, `--look-at`.
    pub pose: crate::document::options::PoseSpecs,
    /// `--skinning`: every character skinned this way.
    pub skinning: Option<crate::rig::dqs::SkinningMethod>,
    /// `--match-height`: every character scaled to the first one's height.
    pub match_height: bool,
    /// `--anim` and `--time`: a keyframed clip on every character it fits.
    pub anim: Option<crate::formats::scene::AnimDoc>,
    /// `--time`: every clip of the scene (keyframes, SMPL, glTF) sampled there, paused.
    pub time: Option<f32>,
    /// `--clip`: a glTF file's animation (name or index) on the characters it moves.
    pub clip: Option<String>,
    /// `--view`: the characters framed from this side.
    pub view: Option<crate::formats::scene::ViewName>,
    /// `--ortho`: an orthographic lens, framed to the characters.
    pub ortho: bool,
    /// `--transparent`: no background and no floor (a PNG with alpha).
    pub transparent: bool,
    /// `--recover`: the scene is a recovery file, saved nowhere yet.
    pub recovered: bool,
    /// `render` of one picture: clips paused where the scene has them.
    pub still: bool,
}

impl StartupEdits {
    /// The posing options, as every command applies them.
    pub fn pose_options(&self) -> crate::document::options::PoseOptions {
        crate::document::options::PoseOptions {
            specs: self.pose.clone(),
            skinning: self.skinning,
            anim: self.anim.clone(),
            clip: self.clip.clone(),
            time: self.time,
            still: self.still,
        }
    }
}

/// Messages for the user (load errors, warnings, where files went), newest last.
#[derive(Resource, Clone, Debug, Default)]
pub struct Messages(pub Vec<String>);

impl Messages {
    pub fn push(&mut self, m: impl Into<String>) {
        let m = m.into();
        info!("{m}");
        self.0.push(m);
    }
}

/// The selected character (by scene id) and joints.
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct Selection {
    pub character: Option<CharacterId>,
    pub joints: Vec<usize>,
}

/// Characters of the current scene that failed to load: kept as their documents were, so
/// saving writes them back unchanged.
#[derive(Resource, Clone, Debug, Default)]
pub struct UnloadedCharacters(pub Vec<crate::formats::scene::CharacterDoc>);

/// A drag under way.
#[derive(Debug, Clone)]
pub struct Drag {
    pub character: CharacterId,
    pub joint: usize,
    /// The drag plane: through the joint, facing the camera.
    pub plane_point: Vec3,
    pub plane_normal: Vec3,
    /// Pinned joints of that character and where they must stay (world).
    pub pins: Vec<(usize, Vec3)>,
    /// Where the button went down (window pixels): the pose changes only once the cursor
    /// has moved beyond the click slop from it, so a click is no edit.
    pub pressed_at: Vec2,
    pub moved: bool,
}

#[derive(Resource, Default)]
pub struct JointDrag {
    pub active: Option<Drag>,
    /// The last solve's note (reached or not, limited), shown in the panel.
    pub note: String,
}

/// Whether the scene differs from its file: the history state it was saved or opened at,
/// whether the startup options changed it, and a save made this frame (its state is
/// recorded once the frame's edits are applied).
#[derive(Resource, Clone, Debug, Default)]
pub struct SavedState {
    pub at: u64,
    pub changed_at_start: bool,
    pub saved_now: bool,
}

impl SavedState {
    /// Whether the scene in the history state `state` (a gesture under way or not) has
    /// changes its file does not.
    pub fn unsaved(&self, state: u64, gesture_open: bool) -> bool {
        self.changed_at_start || gesture_open || state != self.at
    }
}

/// Scene-wide view settings: the scene file's own type (floor, shadows, axes, floor
/// height), held as a resource.
#[derive(Resource, Clone, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct StageSettings(pub crate::formats::scene::StageDoc);

/// The picture `render` takes (size, samples): the scene file's own type, held as a
/// resource; the viewport's frame guide shows its shape.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct ShotSettings(pub crate::formats::scene::ShotDoc);

/// A handle in the viewport that poses a limb or the head: a two-bone limb's target and
/// pole, or where the head looks (world points; a handle moved re-solves its limb).
#[derive(Clone, Debug, PartialEq)]
pub enum LimbHandle {
    TwoBone { character: CharacterId, end: usize, target: Vec3, pole: Vec3 },
    LookAt { character: CharacterId, head: usize, target: Vec3 },
}

/// The handles shown, and the one being dragged (its index, its drag plane's point and
/// normal).
#[derive(Resource, Default, Debug)]
pub struct LimbHandles {
    pub handles: Vec<LimbHandle>,
    pub dragged: Option<(usize, Vec3, Vec3)>,
    /// Handles moved since their limb was last solved.
    pub moved: Vec<usize>,
}

/// Posing with symmetry: a joint turned on one side turns its twin on the other, mirrored
/// through the humanoid map, in the same undo step.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Symmetry(pub bool);

/// The scene's poses by name (the scene file's `poses`).
#[derive(Resource, Clone, Debug, Default, PartialEq)]
pub struct PoseLibrary(pub BTreeMap<String, crate::formats::scene::LibraryPoseDoc>);

/// The joint under the cursor (highlighted, and named in a tooltip, before a click).
#[derive(Resource, Default, Debug)]
pub struct HoveredJoint(pub Option<JointHit>);

/// A joint found under the cursor.
#[derive(Debug, Clone, Copy)]
pub struct JointHit {
    pub entity: Entity,
    pub id: CharacterId,
    pub joint: usize,
    /// World position.
    pub position: Vec3,
}

/// Pinned joints per character id.
#[derive(Resource, Default)]
pub struct Pins(pub BTreeMap<CharacterId, Vec<usize>>);

/// Whether the pointer belongs to the viewport this frame (false while egui uses it):
/// written by the interaction room, read by the tools and the fast viewport.
#[derive(Resource)]
pub struct ViewportHasPointer(pub bool);

impl Default for ViewportHasPointer {
    fn default() -> Self {
        Self(true)
    }
}
