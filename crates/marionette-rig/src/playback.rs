//! The playback clock every kind of motion runs on (keyframed clips, a source's own clips,
//! SMPL clips): a time advanced by the frame time at a speed, looping or stopping at the
//! clip's end.

/// Where a clip's time runs: from `start`; a clip that does not loop stops at `end` (at
/// `start` when played backwards); a looping one wraps every `period` after `start`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub start: f32,
    pub end: f32,
    pub period: f32,
}

impl Span {
    /// A clip keyed from `start` to `end` (seconds): it loops over that range.
    pub fn keyed(start: f32, end: f32) -> Self {
        Self { start, end, period: end - start }
    }

    /// A clip of `frames` frames, timed in frames: it stops on its last frame and loops
    /// through the step from its last frame back to its first.
    pub fn frames(frames: usize) -> Self {
        Self::sampled(frames, 1.0)
    }

    /// A clip of `frames` frames `fps` a second, timed in seconds: it stops on its last
    /// frame and loops through the step from its last frame back to its first.
    pub fn sampled(frames: usize, fps: f32) -> Self {
        let n = frames as f32;
        Self { start: 0.0, end: (n - 1.0).max(0.0) / fps, period: n / fps }
    }
}

/// A clip's clock: its time, whether it plays, at what speed, whether it loops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    pub time: f32,
    pub playing: bool,
    pub speed: f32,
    pub looping: bool,
}

impl Clock {
    /// The clock `dt` later over `span`: a paused clock keeps its time; a looping one
    /// wraps into the span (a span of no length holds its start); one that does not loop
    /// stops at the end it runs into.
    pub fn advanced(self, span: Span, dt: f32) -> Self {
        if !self.playing {
            return self;
        }
        let t = self.time + dt * self.speed;
        let (time, playing) = if self.looping {
            if span.period > 0.0 {
                (span.start + (t - span.start).rem_euclid(span.period), true)
            } else {
                (span.start, true)
            }
        } else if t >= span.end && self.speed >= 0.0 {
            (span.end, false)
        } else if t <= span.start && self.speed < 0.0 {
            (span.start, false)
        } else {
            (t, true)
        };
        Self { time, playing, ..self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clock(time: f32, speed: f32, looping: bool) -> Clock {
        Clock { time, playing: true, speed, looping }
    }

    #[test]
    fn a_looping_clip_wraps_into_its_span() {
        let c = clock(1.9, 1.0, true).advanced(Span::keyed(0.5, 2.0), 0.3);
        assert!((c.time - 0.7).abs() < 1e-6 && c.playing, "{c:?}");
        // Backwards it wraps from the start to the end.
        let c = clock(0.6, -1.0, true).advanced(Span::keyed(0.5, 2.0), 0.3);
        assert!((c.time - 1.8).abs() < 1e-6, "{c:?}");
        // Frames: past the last frame (9) it runs to the tenth step, back to frame 0.
        let c = clock(9.0, 2.0, true).advanced(Span::frames(10), 0.75);
        assert!((c.time - 0.5).abs() < 1e-6, "{c:?}");
    }

    #[test]
    fn a_clip_that_does_not_loop_stops_at_the_end_it_runs_into() {
        let c = clock(1.9, 1.0, false).advanced(Span::keyed(0.5, 2.0), 0.3);
        assert_eq!((c.time, c.playing), (2.0, false));
        let c = clock(8.5, 1.0, false).advanced(Span::frames(10), 1.0);
        assert_eq!((c.time, c.playing), (9.0, false), "on the last frame");
        let c = clock(0.6, -1.0, false).advanced(Span::keyed(0.5, 2.0), 0.3);
        assert_eq!((c.time, c.playing), (0.5, false));
    }

    #[test]
    fn a_paused_clock_and_a_span_of_no_length_hold_still() {
        let paused = Clock { playing: false, ..clock(1.0, 1.0, true) };
        assert_eq!(paused.advanced(Span::keyed(0.0, 2.0), 0.5), paused);
        let c = clock(3.0, 1.0, true).advanced(Span::keyed(3.0, 3.0), 0.5);
        assert_eq!((c.time, c.playing), (3.0, true));
    }
}
