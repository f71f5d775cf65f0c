//! What Marionette reads and makes at most. Each limit is checked before anything is
//! allocated for it, and a file past one is refused with an error that names the limit.
//! docs/limits.md lists them.

/// The largest file any reader opens (a larger one is refused before it is read).
pub const MAX_FILE_BYTES: u64 = 512 << 20;

/// The most vertices one character or glTF accessor may hold.
pub const MAX_VERTICES: usize = 1 << 24;

/// The most joints a skeleton may have (a skin's joint index is 16 bits).
pub use marionette_rig::MAX_JOINTS;

/// The most words and braces a brace-structured file (a CSE169 `.skel`, `.skin`, `.anim`,
/// `.morph`, a BVH's hierarchy) may hold.
pub const MAX_TOKENS: usize = 1 << 23;

/// The most keys a track of a clip that `export --animation` writes may hold (an hour
/// keyed at 30 frames per second is 108,000).
pub const MAX_SAMPLED_FRAMES: usize = 120_000;

/// The most characters of a token an error message quotes.
pub const MAX_EXCERPT_CHARS: usize = 40;

/// The most characters of an error message (past a quoted excerpt, the rest is cut).
pub const MAX_MESSAGE_CHARS: usize = 600;
