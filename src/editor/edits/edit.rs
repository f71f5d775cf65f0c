//! Edits: each user action on the scene as a value ([`Edit`]), the queue they wait in for
//! the next `Animate`, and what holds a gesture open. Shared by the panels, the viewport's
//! tools, the pose library and the history; applied by `commands`.

use bevy::prelude::*;

use crate::formats::scene::{
    AnimDoc, AttachDoc, BindingDoc, CameraDoc, CharacterDoc, CharacterId, LibraryPoseDoc, PlacementDoc, PlaybackDoc,
    ShotDoc, SkinningDoc, SmplDoc, StageDoc, ViewDoc,
};

use crate::rig::JointRotation;

/// One user action on the scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Turn joints (by index) to these rotations, clamped to their limits.
    Pose {
        character: CharacterId,
        joints: Vec<(usize, JointRotation)>,
    },
    /// Move, turn or scale a character.
    Place {
        character: CharacterId,
        placement: PlacementDoc,
    },
    /// Display mode, visibility, weight colours, heat map, tint.
    View {
        character: CharacterId,
        view: ViewDoc,
    },
    Rename {
        character: CharacterId,
        name: String,
    },
    /// β, clips, time, playback and blend of an SMPL body.
    Smpl {
        character: CharacterId,
        state: SmplDoc,
    },
    /// Weights from the file (`None`) or computed from the bones.
    Rebind {
        character: CharacterId,
        binding: Option<BindingDoc>,
    },
    /// Linear blend or dual quaternion skinning.
    Skinning {
        character: CharacterId,
        method: SkinningDoc,
    },
    /// Skinning by the GPU compute shader (`true`) or on the CPU.
    SkinOnGpu {
        character: CharacterId,
        on: bool,
    },
    /// A keyframed clip on a character, its time and playback (none: no clip).
    Clip {
        character: CharacterId,
        anim: Option<AnimDoc>,
    },
    /// Clip, time, playback and blend of a source's own clips (glTF animations).
    Playback {
        character: CharacterId,
        state: PlaybackDoc,
    },
    /// Morph target weights.
    Morph {
        character: CharacterId,
        weights: Vec<f32>,
    },
    /// A pose kept in the scene's library under `name` (none: taken out).
    Library {
        name: String,
        pose: Option<LibraryPoseDoc>,
    },
    /// Held by a joint of another character (none: let go), standing at `placement` (where
    /// it stands when attached or let go, so that undo puts it back exactly).
    Attach {
        character: CharacterId,
        attached: Option<AttachDoc>,
        placement: PlacementDoc,
    },
    /// Standard bones assigned by hand (bone → pose key; an empty key takes the bone off),
    /// over those found from the skeleton.
    Humanoid {
        character: CharacterId,
        bones: std::collections::BTreeMap<crate::rig::humanoid::HumanBone, String>,
    },
    /// Floor, lights, background, axes.
    Stage(StageDoc),
    /// The picture `render` takes.
    Shot(ShotDoc),
    /// A camera view kept under `name` (none: taken out).
    Bookmark {
        name: String,
        camera: Option<CameraDoc>,
    },
    /// A character from its document (a fresh id is given when it has none).
    Add(Box<CharacterDoc>),
    Remove(CharacterId),
}

impl Edit {
    /// The character it edits (none for the stage).
    pub fn character(&self) -> Option<CharacterId> {
        match self {
            Edit::Pose { character, .. }
            | Edit::Place { character, .. }
            | Edit::View { character, .. }
            | Edit::Rename { character, .. }
            | Edit::Smpl { character, .. }
            | Edit::Rebind { character, .. }
            | Edit::Skinning { character, .. }
            | Edit::SkinOnGpu { character, .. }
            | Edit::Clip { character, .. }
            | Edit::Morph { character, .. }
            | Edit::Playback { character, .. }
            | Edit::Attach { character, .. }
            | Edit::Humanoid { character, .. }
            | Edit::Remove(character) => Some(*character),
            Edit::Add(doc) => doc.id,
            Edit::Stage(_) | Edit::Shot(_) | Edit::Library { .. } | Edit::Bookmark { .. } => None,
        }
    }
}

impl Edit {
    /// Whether `self` and `other` set the same thing (within a gesture, only the first
    /// value of each thing is kept): the same kind of edit of the same character, or the
    /// same pose of the library. Poses, adds and removes are judged by the history itself.
    pub fn same_slot(&self, other: &Edit) -> bool {
        match (self, other) {
            (Edit::Library { name: a, .. }, Edit::Library { name: b, .. }) => a == b,
            (Edit::Bookmark { name: a, .. }, Edit::Bookmark { name: b, .. }) => a == b,
            _ => std::mem::discriminant(self) == std::mem::discriminant(other) && self.character() == other.character(),
        }
    }
}

/// Edits waiting for this frame's `Animate`.
#[derive(Resource, Default, Debug)]
pub struct EditQueue(pub Vec<Edit>);

impl EditQueue {
    pub fn push(&mut self, edit: Edit) {
        self.0.push(edit);
    }
}

/// Held while a gesture goes on without a mouse button held: a widget of the panels held
/// or typed into (a slider drag, a name being typed), or a rotation being typed in the
/// viewport. The gesture stays one undo step, even between mouse presses.
#[derive(Resource, Default, Debug, PartialEq, Eq)]
pub struct GestureHold {
    pub panels: bool,
    pub typing: bool,
}

impl GestureHold {
    pub fn held(&self) -> bool {
        self.panels || self.typing
    }
}
