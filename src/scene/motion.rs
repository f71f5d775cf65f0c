//! Motion in the ECS: one system advances every player's clock (seconds, the rig's
//! [`Clock`]) and one poses every character whose motion changed by the document layer's
//! motion service ([`crate::document::motion::pose_at`]), so the picture shows the pose
//! `export` writes. Players: SMPL playback ([`SmplCharacter`]), a keyframed clip
//! ([`ClipPlayer`]), the source's own clips ([`NodeClipPlayer`]).

use bevy::ecs::component::Mutable;
use bevy::prelude::*;

use crate::document::motion::{Clock, Clocked, Playing, Span, keyframes_span, node_span, pose_at, smpl_span};
use crate::scene::keyframes::{ClipPlayer, RootTranslation};
use crate::scene::morphs::Morphs;
use crate::scene::node_clips::NodeClipPlayer;
use crate::scene::smpl::SmplCharacter;
use crate::scene::{Character, JointPose, RestOverrides};

/// Every kind of motion: clocks advanced, SMPL bodies reshaped, characters posed.
pub struct MotionPlugin;

impl Plugin for MotionPlugin {
    fn build(&self, app: &mut App) {
        app.add_systems(
            PostUpdate,
            (advance_clocks, super::smpl::reshape_bodies, pose_from_motion).chain().in_set(super::AnimateSteps::Motion),
        );
    }
}

/// Advances every playing clock by the frame time over its clip's span (reads `Time`;
/// writes a player only where it plays, so a paused one keeps the edits made on its pose).
fn advance_clocks(
    time: Res<Time>,
    mut bodies: Query<&mut SmplCharacter>,
    mut keyframes: Query<&mut ClipPlayer>,
    mut node_clips: Query<&mut NodeClipPlayer>,
) {
    let dt = time.delta_secs();
    for mut body in &mut bodies {
        let span = body.clip().map(smpl_span);
        advance(&mut body, span, dt, |b| &mut b.state);
    }
    for mut player in &mut keyframes {
        let span = Some(keyframes_span(&player.clip));
        advance(&mut player, span, dt, |p| &mut p.state);
    }
    for mut player in &mut node_clips {
        let span = player.clip().map(node_span);
        advance(&mut player, span, dt, |p| &mut p.state);
    }
}

/// `player`'s clock `dt` later over `span`, written only when it plays and has a clip.
fn advance<P: Component<Mutability = Mutable>, D: Clocked>(
    player: &mut Mut<P>,
    span: Option<Span>,
    dt: f32,
    state: impl Fn(&mut P) -> &mut D,
) {
    let clock: Clock = state(player.bypass_change_detection()).clock();
    if let (true, Some(span)) = (clock.playing, span) {
        state(player).set_clock(clock.advanced(span, dt));
    }
}

/// The motion a character plays, as its players hold it.
type Players<'a> = (Option<Ref<'a, SmplCharacter>>, Option<Ref<'a, ClipPlayer>>, Option<Ref<'a, NodeClipPlayer>>);

/// Poses every character whose motion changed (a clock, a clip, a blend) by the motion
/// service over its joints' poses (writes `JointPose`, `RootTranslation`, `RestOverrides`,
/// `Morphs`). A paused motion keeps the edits made on its pose.
fn pose_from_motion(
    mut characters: Query<(&Character, Players, &mut RootTranslation, &mut RestOverrides, Option<&mut Morphs>)>,
    mut poses: Query<&mut JointPose>,
) {
    for (character, (smpl, keyframes, node_clips), mut root, mut rest, morphs) in &mut characters {
        let changed = smpl.as_ref().is_some_and(Ref::is_changed)
            || keyframes.as_ref().is_some_and(Ref::is_changed)
            || node_clips.as_ref().is_some_and(Ref::is_changed);
        if !changed {
            continue;
        }
        let playing = Playing {
            smpl: smpl.as_deref().and_then(SmplCharacter::motion),
            keyframes: keyframes.as_deref().map(|p| (&*p.clip, p.state.clock())),
            node_clips: node_clips.as_deref().and_then(NodeClipPlayer::motion),
        };
        let skeleton = &character.asset.skeleton;
        // SMPL playback sets every joint: the joints' poses are not read under it.
        let still: Vec<_> = match playing.smpl {
            Some(_) => skeleton.initial_pose(),
            None => character.joints.iter().map(|&e| poses.get(e).map_or(Default::default(), |p| p.0)).collect(),
        };
        let weights = morphs.as_ref().map_or(Vec::new(), |m| m.weights.clone());
        let now = pose_at(skeleton, &still, &weights, &playing);
        for (&entity, rotation) in character.joints.iter().zip(now.rotations) {
            if let Ok(mut p) = poses.get_mut(entity) {
                p.set_if_neq(JointPose(rotation));
            }
        }
        root.set_if_neq(RootTranslation(now.root));
        let (offsets, scales) = now.rest.unwrap_or_default();
        rest.set_if_neq(RestOverrides { offsets, scales });
        if let Some(mut morphs) = morphs.filter(|m| m.weights != now.weights) {
            morphs.weights = now.weights;
        }
    }
}
