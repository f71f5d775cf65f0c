//! What Marionette reads and makes at most. Each limit is checked before anything is
//! allocated for it, and a file past one is refused with an error that names the limit.
//! The README's "Limits" section lists them.

/// The largest file any reader opens (a larger one is refused before it is read).
pub const MAX_FILE_BYTES: u64 = 512 << 20;

/// The most vertices one character or glTF accessor may hold.
pub const MAX_VERTICES: usize = 1 << 24;

/// The most joints a skeleton may have (a skin's joint index is 16 bits).
pub use crate::rig::MAX_JOINTS;

/// The most words and braces a brace-structured file (a CSE169 `.skel`, `.skin`, `.anim`,
/// `.morph`, a BVH's hierarchy) may hold.
pub const MAX_TOKENS: usize = 1 << 23;

/// The most frames `export --animation` and `render` sample from one clip (an hour at
/// 30 frames per second is 108,000).
pub const MAX_SAMPLED_FRAMES: usize = 120_000;

/// The most characters of a token an error message quotes.
pub const MAX_EXCERPT_CHARS: usize = 40;

/// The most characters of an error message (past a quoted excerpt, the rest is cut).
pub const MAX_MESSAGE_CHARS: usize = 600;

/// How many frames a clip `seconds` long takes sampled at `fps` (besides its first), or
/// why it cannot be sampled: more than [`MAX_SAMPLED_FRAMES`] (a clip keyed at 0 and 1e30
/// seconds would otherwise ask for `usize::MAX` frames).
pub fn sampled_frames(seconds: f32, fps: f32) -> Result<usize, String> {
    let frames = (f64::from(seconds.max(0.0)) * f64::from(fps)).ceil();
    if frames.is_finite() && frames <= MAX_SAMPLED_FRAMES as f64 {
        Ok(frames as usize)
    } else {
        Err(format!(
            "the clip is {seconds:.3e} s long: {frames:.3e} frames at {fps} frames per second, more than the \
             {MAX_SAMPLED_FRAMES} a clip is sampled into (MAX_SAMPLED_FRAMES)"
        ))
    }
}
