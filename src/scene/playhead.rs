//! The one playback clock of the ECS's players (keyframed clips, the sources' own clips,
//! SMPL clips): each says where its clock stands and what span its clip runs over, and one
//! system advances them all by the rig's [`Clock`].

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

use crate::rig::playback::{Clock, Span};

/// A component that plays a clip on a clock.
pub trait Playhead: Component<Mutability = Mutable> {
    /// Its clock: time, playing, speed (in the span's units a second), looping.
    fn clock(&self) -> Clock;
    /// Stores the clock's time and whether it still plays.
    fn set_clock(&mut self, clock: Clock);
    /// The span its clip runs over; none without a clip (the clock stands still).
    fn span(&self) -> Option<Span>;
}

/// Advances every playing `P` by the frame time (reads `Time`; writes `P` only where it
/// plays, so a paused player keeps the slider edits made on its pose).
pub fn advance_playheads<P: Playhead>(time: Res<Time>, mut players: Query<&mut P>) {
    let dt = time.delta_secs();
    for mut player in &mut players {
        let clock = player.clock();
        if !clock.playing {
            continue;
        }
        if let Some(span) = player.span() {
            player.set_clock(clock.advanced(span, dt));
        }
    }
}
