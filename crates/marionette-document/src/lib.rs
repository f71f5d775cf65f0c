//! The document layer, no Bevy: what the editor and the command line share. The asset
//! library (characters by source), scene documents and files, the layout of characters
//! side by side, the default and crowd scenes, posing by `--pose`/`--ik` specs, and export
//! (OBJ posing, glTF, animations). `export`, `info`, `bind`, `smpl` and `gen-assets` run on
//! it alone; the editor calls it.

pub mod annotate;
pub mod crowd;
pub mod default_scene;
pub mod drawing;
pub mod export;
pub mod fit;
pub mod frames;
pub mod generate;
pub mod layout;
pub mod library;
pub mod motion;
pub mod options;
pub mod picture;
pub mod posing;
pub mod retarget;
pub mod scenes;
pub mod webdataset;

pub use library::{AssetLibrary, LoadedPart, SmplSet, own_motion, rebind};
