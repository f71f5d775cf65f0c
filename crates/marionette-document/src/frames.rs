//! Frame sequences for `render --from A --to B --fps N --out dir/frame_%04d.png`: the
//! times of the frames, where each picture goes, and the turntable's turn at each.

use std::path::{Path, PathBuf};

use marionette_formats::limits::MAX_SAMPLED_FRAMES;

/// A frame sequence, a frame pattern or a picture size that cannot be.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FramesError {
    #[error("expected --from at or before --to, found {from} and {to}")]
    Order { from: f64, to: f64 },
    #[error("expected --fps above 0, found {0}")]
    Fps(f64),
    #[error("expected --turntable above 0 seconds, found {0}")]
    Turntable(f32),
    #[error(
        "{frames} frames from {from} s to {to} s at {fps} per second: more than the {MAX_SAMPLED_FRAMES} a render writes (MAX_SAMPLED_FRAMES)"
    )]
    TooMany { frames: f64, from: f64, to: f64, fps: f64 },
    #[error("expected one %d or %04d in --out for the frame number, found {0}")]
    Pattern(String),
    #[error("{0}")]
    Picture(String),
}

/// Frames from `from` to `to` seconds (both included where `to` falls on a frame) at `fps`
/// frames per second; with `turntable`, the camera goes once round the scene every that
/// many seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameSequence {
    pub from: f32,
    pub to: f32,
    pub fps: f32,
    pub turntable: Option<f32>,
}

impl FrameSequence {
    /// Each frame's time: `from + k / fps` up to `to` (a hair of rounding allowed, so that
    /// 0 to 1 at 10 fps is 11 frames). Refused when the times are not finite and in order,
    /// or there would be more than [`MAX_SAMPLED_FRAMES`].
    pub fn times(&self) -> Result<Vec<f32>, FramesError> {
        let (from, to, fps) = (f64::from(self.from), f64::from(self.to), f64::from(self.fps));
        if !(from.is_finite() && to.is_finite() && from <= to) {
            return Err(FramesError::Order { from, to });
        }
        if !(fps.is_finite() && fps > 0.0) {
            return Err(FramesError::Fps(fps));
        }
        if let Some(seconds) = self.turntable.filter(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(FramesError::Turntable(seconds));
        }
        let last = ((to - from) * fps + 1e-6).floor();
        if last + 1.0 > MAX_SAMPLED_FRAMES as f64 {
            return Err(FramesError::TooMany { frames: last + 1.0, from, to, fps });
        }
        Ok((0..=last as usize).map(|k| (from + k as f64 / fps) as f32).collect())
    }

    /// The camera's turn (radians about the vertical) at time `t`: one whole turn per
    /// turntable period from the first frame; none without a turntable.
    pub fn turn_at(&self, t: f32) -> f32 {
        self.turntable.map_or(0.0, |seconds| std::f32::consts::TAU * (t - self.from) / seconds)
    }
}

/// The path of frame `n` from `pattern`: its one `%d` or `%0Nd` (N digits, zero-padded)
/// replaced by `n`. Refused without exactly one.
pub fn frame_path(pattern: &Path, n: usize) -> Result<PathBuf, FramesError> {
    let (start, width, tail) = pattern_parts(pattern)?;
    Ok(PathBuf::from(format!("{start}{n:0width$}{tail}")))
}

/// The file a whole sequence shares (its COCO file): the pattern with `all` for the frame
/// number and `extension` for its own (`f_%04d.png`, `json` → `f_all.json`).
pub fn sequence_path(pattern: &Path, extension: &str) -> Result<PathBuf, FramesError> {
    let (start, _, tail) = pattern_parts(pattern)?;
    Ok(PathBuf::from(format!("{start}all{tail}")).with_extension(extension))
}

/// A pattern's text before its `%d` (or `%04d`), the number's width, and the text after.
fn pattern_parts(pattern: &Path) -> Result<(String, usize, String), FramesError> {
    let text = pattern.to_string_lossy();
    let expected = || FramesError::Pattern(text.to_string());
    let (start, rest) = text.split_once('%').ok_or_else(expected)?;
    let digits_end = rest.find('d').ok_or_else(expected)?;
    let width = &rest[..digits_end];
    let tail = &rest[digits_end + 1..];
    let valid_width = width.is_empty() || (width.starts_with('0') && width.len() <= 3 && width.parse::<u8>().is_ok());
    if !valid_width || tail.contains('%') {
        return Err(expected());
    }
    Ok((start.to_string(), width.parse().unwrap_or(0), tail.to_string()))
}

/// The picture's size, samples and smoothing asked for on the command line (each none: the
/// scene's).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PictureRequest {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub samples: Option<u32>,
    pub antialias: Option<marionette_formats::scene::Antialias>,
}

impl PictureRequest {
    /// The picture: what was asked for, the rest as the scene's `shot` says; refused beyond
    /// the GPU's texture size.
    pub fn resolved(
        self,
        shot: &marionette_formats::scene::ShotDoc,
    ) -> Result<marionette_formats::scene::ShotDoc, FramesError> {
        let picture = marionette_formats::scene::ShotDoc {
            width: self.width.unwrap_or(shot.width),
            height: self.height.unwrap_or(shot.height),
            samples: self.samples.unwrap_or(shot.samples),
            antialias: self.antialias.unwrap_or(shot.antialias),
        };
        picture.validate().map(|()| picture).map_err(FramesError::Picture)
    }
}

/// The pictures a render writes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pictures {
    /// One picture of the scene as it opens.
    Still,
    /// One per frame, into the files `out` numbers (`frame_%04d.png`).
    Sequence(FrameSequence),
    /// A contact sheet: every pose of the scene's library on its characters, in a grid.
    PoseSheet,
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::{FrameSequence, frame_path, sequence_path};

    /// Frame sequences: 0 to 1 s at 10 fps is 11 frames at k/10 s; a turntable turns once per
    /// period; the file pattern takes one `%d` or `%0Nd`; nonsense is refused with a message.
    #[test]
    fn frame_sequences_number_their_frames_and_files() {
        let sequence = FrameSequence { from: 0.0, to: 1.0, fps: 10.0, turntable: Some(2.0) };
        let times = sequence.times().unwrap();
        assert_eq!(times.len(), 11);
        assert!((times[7] - 0.7).abs() < 1e-6 && times[10] == 1.0);
        assert!((sequence.turn_at(0.5) - std::f32::consts::FRAC_PI_2).abs() < 1e-6, "a quarter turn in half a period");
        let thirds = FrameSequence { from: 0.0, to: 1.0, fps: 3.0, turntable: None };
        assert_eq!(thirds.times().unwrap().len(), 4, "1 s at 3 fps: 0, 1/3, 2/3, 1");
        assert_eq!(frame_path(Path::new("out/frame_%04d.png"), 7).unwrap(), Path::new("out/frame_0007.png"));
        assert_eq!(frame_path(Path::new("f%d.png"), 12).unwrap(), Path::new("f12.png"));
        assert_eq!(sequence_path(Path::new("out/f_%04d.png"), "json").unwrap(), Path::new("out/f_all.json"));
        for bad in ["frame.png", "f_%x.png", "f_%04d_%d.png", "f_%4d.png"] {
            let e = frame_path(Path::new(bad), 0).unwrap_err();
            assert!(e.to_string().contains("expected one %d or %04d"), "{bad}: {e}");
        }
        let backwards = FrameSequence { from: 2.0, to: 1.0, fps: 10.0, turntable: None };
        assert!(backwards.times().unwrap_err().to_string().contains("--from at or before --to"));
        let endless = FrameSequence { from: 0.0, to: 1e30, fps: 10.0, turntable: None };
        assert!(endless.times().unwrap_err().to_string().contains("MAX_SAMPLED_FRAMES"));
    }
}
