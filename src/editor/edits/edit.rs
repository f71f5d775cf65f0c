//! Edits: each user action on the scene as a command that knows how to make itself and
//! what undoes it ([`Command`]; the kinds are in `character_edits` and `scene_edits`), the
//! [`Edit`] that holds any of them, the queue they wait in for the next `Animate`, and
//! what holds a gesture open. Shared by the panels, the viewport's tools, the pose library
//! and the history; applied by `commands`.

use bevy::prelude::*;

use crate::formats::scene::CharacterId;

pub use crate::editor::edits::character_edits::{
    Add, Attach, Clip, Humanoid, Morph, Place, Playback, Pose, Rebind, Remove, Rename, SkinOnGpu, Skinning, Smpl, View,
};
pub use crate::editor::edits::scene_edits::{Bookmark, Library, Shot, Stage};

/// A change to the scene that makes itself and tells what undoes it.
pub trait Command: Into<Edit> {
    /// The character it edits (none for the stage and the libraries).
    fn character(&self) -> Option<CharacterId> {
        None
    }

    /// The named entry it sets, for edits of a library kept by name.
    fn entry(&self) -> Option<&str> {
        None
    }

    /// What undoes it in the scene as it is now, to be applied last first; empty when it
    /// would change nothing.
    fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String>;

    /// Makes the change.
    fn write(self, world: &mut World) -> Result<(), String>;
}

/// A command that sets one thing: the same command holding what is there now undoes it.
pub trait Setter: Sized + PartialEq + Into<Edit> {
    /// Setting it poses the joints (from a clip): undo gives them back their rotations.
    const POSES: bool = false;

    fn character(&self) -> Option<CharacterId>;

    /// The named entry it sets, for edits of a library kept by name.
    fn entry(&self) -> Option<&str> {
        None
    }

    /// This command with the value the scene has now.
    fn read(&self, world: &World) -> Result<Self, String>;

    fn set(self, world: &mut World) -> Result<(), String>;
}

impl<S: Setter> Command for S {
    fn character(&self) -> Option<CharacterId> {
        Setter::character(self)
    }

    fn entry(&self) -> Option<&str> {
        Setter::entry(self)
    }

    fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
        let now = self.read(world)?;
        if now == *self {
            return Ok(Vec::new());
        }
        let mut undo = Vec::with_capacity(2);
        if let (true, Some(id)) = (S::POSES, Setter::character(self)) {
            undo.push(crate::editor::edits::access::current_pose(world, id)?);
        }
        undo.push(now.into());
        Ok(undo)
    }

    fn write(self, world: &mut World) -> Result<(), String> {
        self.set(world)
    }
}

/// Declares [`Edit`], one variant per command kind, and hands each call to the kind.
macro_rules! edits {
    ($($(#[$doc:meta])* $kind:ident,)*) => {
        /// One user action on the scene: one of the commands.
        #[derive(Clone, Debug, PartialEq)]
        pub enum Edit {
            $($(#[$doc])* $kind($kind),)*
        }

        $(impl From<$kind> for Edit {
            fn from(command: $kind) -> Edit {
                Edit::$kind(command)
            }
        })*

        impl Edit {
            /// The character it edits (none for the stage and the libraries).
            pub fn character(&self) -> Option<CharacterId> {
                match self { $(Edit::$kind(c) => Command::character(c),)* }
            }

            fn entry(&self) -> Option<&str> {
                match self { $(Edit::$kind(c) => Command::entry(c),)* }
            }

            /// What undoes it in the scene as it is now (see [`Command::undo`]).
            pub fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
                match self { $(Edit::$kind(c) => c.undo(world),)* }
            }

            /// Makes the change.
            pub fn write(self, world: &mut World) -> Result<(), String> {
                match self { $(Edit::$kind(c) => c.write(world),)* }
            }
        }
    };
}

edits! {
    /// Turn joints (by index) to these rotations, clamped to their limits.
    Pose,
    /// Move, turn or scale a character.
    Place,
    /// Display mode, visibility, weight colours, heat map, tint.
    View,
    Rename,
    /// β, clips, time, playback and blend of an SMPL body.
    Smpl,
    /// Weights from the file or computed from the bones.
    Rebind,
    /// Linear blend or dual quaternion skinning.
    Skinning,
    /// Skinning by the GPU compute shader or on the CPU.
    SkinOnGpu,
    /// A keyframed clip on a character, its time and playback (none: no clip).
    Clip,
    /// Clip, time, playback and blend of a source's own clips (glTF animations).
    Playback,
    /// Morph target weights.
    Morph,
    /// A pose kept in the scene's library by name (none: taken out).
    Library,
    /// Held by a joint of another character, or let go.
    Attach,
    /// Standard bones assigned by hand.
    Humanoid,
    /// Floor, lights, background, axes.
    Stage,
    /// The picture `render` takes.
    Shot,
    /// A camera view kept by name (none: taken out).
    Bookmark,
    /// A character from its document (a fresh id is given when it has none).
    Add,
    Remove,
}

impl Edit {
    /// Whether `self` and `other` set the same thing (within a gesture, only the first
    /// value of each thing is kept): the same kind of edit of the same character, or the
    /// same entry of a library. Poses, adds and removes are judged by the history itself.
    pub fn same_slot(&self, other: &Edit) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
            && self.character() == other.character()
            && self.entry() == other.entry()
    }
}

/// Edits waiting for this frame's `Animate`.
#[derive(Resource, Default, Debug)]
pub struct EditQueue(pub Vec<Edit>);

impl EditQueue {
    pub fn push(&mut self, edit: impl Into<Edit>) {
        self.0.push(edit.into());
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
