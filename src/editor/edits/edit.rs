//! Edits: each user action on the scene as a command that knows how to make itself and
//! what undoes it ([`Command`]; the kinds are in `kinds`), the [`Edit`] that holds any of
//! them, the queue they wait in for the next `Animate`, and what holds a gesture open.
//! Shared by the panels, the viewport's tools, the pose library and the history; applied
//! by `commands`.

use std::any::Any;

use bevy::prelude::*;

use crate::formats::scene::CharacterId;

/// A change to the scene that makes itself and tells what undoes it.
pub trait Command: Any + std::fmt::Debug + Send + Sync {
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
    fn write(self: Box<Self>, world: &mut World) -> Result<(), String>;
}

/// A command that sets one thing: the same command holding what is there now undoes it.
pub trait Setter: Sized + Clone + PartialEq + std::fmt::Debug + Send + Sync + 'static {
    fn character(&self) -> Option<CharacterId>;

    /// The named entry it sets, for edits of a library kept by name.
    fn entry(&self) -> Option<&str> {
        None
    }

    /// This command with the value the scene has now.
    fn read(&self, world: &World) -> Result<Self, String>;

    fn set(self, world: &mut World) -> Result<(), String>;

    /// What else undo must give back, applied after the value (a clip setting the joints
    /// gives back their rotations).
    fn also_undo(&self, _world: &World) -> Result<Vec<Edit>, String> {
        Ok(Vec::new())
    }
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
        let mut undo = self.also_undo(world)?;
        undo.push(Edit::from(now));
        Ok(undo)
    }

    fn write(self: Box<Self>, world: &mut World) -> Result<(), String> {
        self.set(world)
    }
}

/// A command as a value: cloned, compared, told apart by its kind.
trait Held: Command {
    fn clone_edit(&self) -> Edit;
    fn same_as(&self, other: &dyn Held) -> bool;
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

impl<C: Command + Clone + PartialEq> Held for C {
    fn clone_edit(&self) -> Edit {
        Edit(Box::new(self.clone()))
    }

    fn same_as(&self, other: &dyn Held) -> bool {
        other.as_any().downcast_ref::<C>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// One user action on the scene: any command.
pub struct Edit(Box<dyn Held>);

impl<C: Command + Clone + PartialEq> From<C> for Edit {
    fn from(command: C) -> Edit {
        Edit(Box::new(command))
    }
}

impl Clone for Edit {
    fn clone(&self) -> Edit {
        self.0.clone_edit()
    }
}

impl PartialEq for Edit {
    fn eq(&self, other: &Edit) -> bool {
        self.0.same_as(&*other.0)
    }
}

impl std::fmt::Debug for Edit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl Edit {
    /// The character it edits (none for the stage and the libraries).
    pub fn character(&self) -> Option<CharacterId> {
        self.0.character()
    }

    /// What undoes it in the scene as it is now (see [`Command::undo`]).
    pub fn undo(&self, world: &mut World) -> Result<Vec<Edit>, String> {
        self.0.undo(world)
    }

    /// Makes the change.
    pub fn write(self, world: &mut World) -> Result<(), String> {
        self.0.write(world)
    }

    /// The command, when it is of kind `C`.
    pub fn get<C: Command>(&self) -> Option<&C> {
        self.0.as_any().downcast_ref()
    }

    pub fn get_mut<C: Command>(&mut self) -> Option<&mut C> {
        self.0.as_any_mut().downcast_mut()
    }

    /// Whether `self` and `other` set the same thing (within a gesture, only the first
    /// value of each thing is kept): the same kind of edit of the same character, or the
    /// same entry of a library. Poses, adds and removes are judged by the history itself.
    pub fn same_slot(&self, other: &Edit) -> bool {
        self.0.as_any().type_id() == other.0.as_any().type_id()
            && self.character() == other.character()
            && self.0.entry() == other.0.entry()
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
