//! Commands on the scene as a whole: the pose library, the stage, the shot, the camera's
//! bookmarks.

use bevy::prelude::*;

use crate::editor::edits::edit::Setter;
use crate::editor::state::camera::Bookmarks;
use crate::editor::state::{PoseLibrary, ShotSettings, StageSettings};
use crate::formats::scene::{CameraDoc, CharacterId, LibraryPoseDoc, ShotDoc, StageDoc};

/// A pose kept in the scene's library under `name` (none: taken out).
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    pub name: String,
    pub pose: Option<LibraryPoseDoc>,
}

impl Setter for Library {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn entry(&self) -> Option<&str> {
        Some(&self.name)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Library { name: self.name.clone(), pose: world.resource::<PoseLibrary>().0.get(&self.name).cloned() })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let mut library = world.resource_mut::<PoseLibrary>();
        match self.pose {
            Some(pose) => library.0.insert(self.name, pose),
            None => library.0.remove(&self.name),
        };
        Ok(())
    }
}

/// A camera view kept under `name` (none: taken out).
#[derive(Clone, Debug, PartialEq)]
pub struct Bookmark {
    pub name: String,
    pub camera: Option<CameraDoc>,
}

impl Setter for Bookmark {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn entry(&self) -> Option<&str> {
        Some(&self.name)
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Bookmark { name: self.name.clone(), camera: world.resource::<Bookmarks>().0.get(&self.name).copied() })
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        let mut bookmarks = world.resource_mut::<Bookmarks>();
        match self.camera {
            Some(camera) => bookmarks.0.insert(self.name, camera),
            None => bookmarks.0.remove(&self.name),
        };
        Ok(())
    }
}

/// Floor, lights, background, axes.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage(pub StageDoc);

impl Setter for Stage {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Stage(world.resource::<StageSettings>().0.clone()))
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        world.resource_mut::<StageSettings>().0 = self.0;
        Ok(())
    }
}

/// The picture `render` takes.
#[derive(Clone, Debug, PartialEq)]
pub struct Shot(pub ShotDoc);

impl Setter for Shot {
    fn character(&self) -> Option<CharacterId> {
        None
    }

    fn read(&self, world: &World) -> Result<Self, String> {
        Ok(Shot(world.resource::<ShotSettings>().0))
    }

    fn set(self, world: &mut World) -> Result<(), String> {
        world.resource_mut::<ShotSettings>().0 = self.0;
        Ok(())
    }
}
