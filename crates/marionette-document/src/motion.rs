//! The one motion service: a character's pose at its clocks' times, for every kind of
//! motion, the same for the editor's `Animate` step, `export`, `render`, `generate`,
//! retargeting (its source sampled over time) and the command line's options.
//!
//! **Precedence**, written once ([`pose_at`]): the character's still pose (its document's
//! `pose`; in the editor, its joints as edited) is the base. Over it, in this order, the
//! last to set a joint winning:
//! 1. SMPL playback (its clip, a second clip blended in, stood upright) sets every joint;
//! 2. a keyframed clip (an `.anim`, a BVH, keys of one's own, a retargeted motion) sets the
//!    joints it has channels for and moves the root;
//! 3. the source's own clips (glTF, FBX) set the joints they key, the rest offsets and
//!    scales they key, and the morph weights they key.
//!
//! Every rotation is then clamped to its joint's limits. The still edits (preset, pose,
//! hands, IK, two-bone, look-at) go on top of that pose, parents before children
//! ([`crate::options`]).
//!
//! **One clock**: every motion runs on [`Clock`] in seconds ([`Clocked`] on its document);
//! an SMPL clip's frames are [`CLIP_FPS`] a second apart, turned into frames only here.

use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::AssetLibrary;
use marionette_formats::FormatError;
use marionette_formats::scene::{CharacterDoc, SourceDoc};
use marionette_rig::CharacterAsset;

pub use marionette_formats::scene::Clocked;
use marionette_rig::anim;
use marionette_rig::fk::RestOverride;
use marionette_rig::node_clip::NodeClip;
pub use marionette_rig::playback::{Clock, Span};
use marionette_rig::smpl::{self, CLIP_FPS};
use marionette_rig::{JointRotation, Skeleton};

/// SMPL playback: a clip, a second clip blended in by a weight, stood upright or not.
#[derive(Clone, Copy)]
pub struct SmplMotion<'a> {
    pub clip: &'a smpl::Clip,
    pub blend: Option<(&'a smpl::Clip, f32)>,
    pub upright: bool,
}

/// A source's own clip with a second blended in by a weight.
#[derive(Clone, Copy)]
pub struct NodeMotion<'a> {
    pub clip: &'a NodeClip,
    pub blend: Option<(&'a NodeClip, f32)>,
}

/// What a character plays, each motion on its clock.
#[derive(Clone, Copy, Default)]
pub struct Playing<'a> {
    pub smpl: Option<(SmplMotion<'a>, Clock)>,
    /// A keyframed clip, its joints already matched to the character's.
    pub keyframes: Option<(&'a anim::Clip, Clock)>,
    pub node_clips: Option<(NodeMotion<'a>, Clock)>,
}

impl Playing<'_> {
    /// Whether nothing plays.
    pub fn is_empty(&self) -> bool {
        self.smpl.is_none() && self.keyframes.is_none() && self.node_clips.is_none()
    }

    /// Every motion's clock set to `t` seconds, paused.
    pub fn paused_at(mut self, t: f32) -> Self {
        let pause = |c: &mut Clock| *c = Clock { time: t, playing: false, ..*c };
        self.smpl.iter_mut().for_each(|(_, c)| pause(c));
        self.keyframes.iter_mut().for_each(|(_, c)| pause(c));
        self.node_clips.iter_mut().for_each(|(_, c)| pause(c));
        self
    }

    /// The seconds the motions run over together: from the earliest start to the latest
    /// end; none when nothing plays.
    pub fn range(&self) -> Option<(f32, f32)> {
        let spans = [
            self.smpl.map(|(m, _)| smpl_span(m.clip)),
            self.keyframes.map(|(k, _)| keyframes_span(k)),
            self.node_clips.map(|(m, _)| node_span(m.clip)),
        ];
        spans.into_iter().flatten().map(|s| (s.start, s.end)).reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
    }
}

/// The time of an SMPL clip's frame `f` (seconds).
pub fn smpl_frame_time(f: usize) -> f32 {
    f as f32 / CLIP_FPS
}

/// An SMPL clip's frame (fractional) at `seconds`: a time within 1e-4 of a frame's
/// stands on that frame, so a frame's time in seconds samples the frame itself.
pub fn smpl_frame_at(seconds: f32) -> f32 {
    let frames = seconds * CLIP_FPS;
    if (frames - frames.round()).abs() < 1e-4 { frames.round() } else { frames }
}

/// Where an SMPL clip's clock runs: its frames, [`CLIP_FPS`] a second.
pub fn smpl_span(clip: &smpl::Clip) -> Span {
    Span::sampled(clip.frame_count(), CLIP_FPS)
}

/// Where a keyframed clip's clock runs: its keyed range.
pub fn keyframes_span(clip: &anim::Clip) -> Span {
    Span::keyed(clip.range.0, clip.range.1)
}

/// Where a source's clip's clock runs: from 0 to its duration.
pub fn node_span(clip: &NodeClip) -> Span {
    Span::keyed(0.0, clip.duration())
}

/// A character's pose from its motion: rotations, where the root is moved, the rest a clip
/// keys, and the morph weights.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionPose {
    /// Every joint's rotation, clamped to its limits.
    pub rotations: Vec<JointRotation>,
    /// The root joint's translation (model space) where a keyframed clip moves it, in
    /// place of its rest offset.
    pub root: Option<Vec3>,
    /// Every joint's rest offset and scale where the source's clips key them.
    pub rest: Option<(Vec<Vec3>, Vec<Vec3>)>,
    /// One weight per morph target.
    pub weights: Vec<f32>,
}

impl MotionPose {
    /// The still pose and weights, nothing playing.
    pub fn still(skeleton: &Skeleton, still: &[JointRotation], weights: &[f32]) -> Self {
        pose_at(skeleton, still, weights, &Playing::default())
    }

    /// The model-space move the matrix stack starts from: the root from its rest offset
    /// to where the keyframed clip puts it.
    pub fn origin(&self, skeleton: &Skeleton) -> Mat4 {
        let rest = skeleton.joint(0).rest_offset;
        self.root.map_or(Mat4::IDENTITY, |t| Mat4::from_translation(t - rest))
    }

    /// The rest offsets and scales the matrix stack takes in place of the skeleton's.
    pub fn rest_override(&self) -> RestOverride<'_> {
        self.rest.as_ref().map_or_else(Default::default, |(o, s)| RestOverride { offsets: Some(o), scales: Some(s) })
    }

    /// The root joint's translation in model space, all motion counted.
    pub fn root_translation(&self, skeleton: &Skeleton) -> Vec3 {
        let offset = self.rest.as_ref().map_or(skeleton.joint(0).rest_offset, |(o, _)| o[0]);
        self.origin(skeleton).transform_point3(offset)
    }

    /// Every joint's transform to the world, the character placed at `placement`.
    pub fn joint_to_world(&self, skeleton: &Skeleton, placement: Mat4) -> Vec<Mat4> {
        let mut matrices = vec![Mat4::IDENTITY; skeleton.len()];
        let origin = placement * self.origin(skeleton);
        marionette_rig::fk::forward_kinematics_with_rest(
            skeleton,
            &self.rotations,
            self.rest_override(),
            origin,
            &mut matrices,
        );
        matrices
    }
}

/// The pose of a character whose still pose is `still` (one rotation per joint) and whose
/// morph weights are `weights` while it plays `playing`, each motion at its clock's time,
/// by the precedence of this module.
pub fn pose_at(skeleton: &Skeleton, still: &[JointRotation], weights: &[f32], playing: &Playing) -> MotionPose {
    let mut now = MotionPose { rotations: still.to_vec(), root: None, rest: None, weights: weights.to_vec() };
    if let Some((m, clock)) = playing.smpl {
        let blend = m.blend;
        let frames = smpl_frame_at(clock.time);
        now.rotations = smpl::BlendSampler::default().playback_pose(m.clip, blend, frames, clock.looping, m.upright);
    }
    if let Some((clip, clock)) = playing.keyframes {
        let (root, rotations) = clip.pose_at_unclamped(skeleton, clock.time, &now.rotations);
        (now.root, now.rotations) = (Some(root), rotations);
        if let Some(offsets) = clip.offsets_at(skeleton, clock.time) {
            now.rest = Some((offsets, skeleton.joints().iter().map(|j| j.rest_scale).collect()));
        }
    }
    if let Some((m, clock)) = playing.node_clips {
        let sample = marionette_rig::node_clip::pose_mix(skeleton, m.clip, m.blend, clock.time, &mut now.rotations);
        if m.clip.moves_rest() || m.blend.is_some_and(|(k, _)| k.moves_rest()) {
            now.rest = Some((sample.offsets, sample.scales));
        }
        now.weights = marionette_rig::node_clip::weights_mix(&now.weights, m.clip, m.blend, clock.time);
    }
    for (j, r) in now.rotations.iter_mut().enumerate() {
        *r = r.clamped(&skeleton.joint(j).limits);
    }
    now
}

/// The frames of `playing` (each clock from the start of its clips' range) at `fps` over
/// that range, on `still`: the root's translation in model space, the pose, and the
/// offsets of the joints a keyframed clip moves (a motion capture's joints below its root;
/// the rest a source's own clips key is the rig's own, which retargeting leaves as it is),
/// for `purpose` (what the frames are for: "retarget"). Refused when there would be more than
/// [`MAX_SAMPLED_FRAMES`](marionette_formats::limits::MAX_SAMPLED_FRAMES).
pub fn sampled_frames(
    skeleton: &Skeleton,
    still: &[JointRotation],
    playing: &Playing,
    fps: f32,
    purpose: &'static str,
) -> Result<Vec<marionette_rig::retarget::Frame>, TooManyFrames> {
    let Some((start, end)) = playing.range() else { return Ok(Vec::new()) };
    let most = marionette_formats::limits::MAX_SAMPLED_FRAMES;
    let n = ((end - start).max(0.0) * fps).round();
    if n.is_nan() || n >= most as f32 {
        return Err(TooManyFrames { purpose, most, fps, start, end });
    }
    let moves_joints = playing.keyframes.is_some_and(|(clip, _)| !clip.offsets.is_empty());
    let frame = |f: usize| {
        let t = start + f as f32 / fps;
        let now = pose_at(skeleton, still, &[], &playing.paused_at(t));
        let root = now.root_translation(skeleton);
        let offsets = now.rest.map(|(offsets, _)| offsets).filter(|_| moves_joints);
        marionette_rig::retarget::Frame { root, pose: now.rotations, offsets }
    };
    Ok((0..=n as usize).map(frame).collect())
}

/// A motion too long to sample.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("expected a clip of at most {most} frames at {fps} a second to {purpose}, found {end} − {start} s")]
pub struct TooManyFrames {
    pub purpose: &'static str,
    pub most: usize,
    pub fps: f32,
    pub start: f32,
    pub end: f32,
}

/// What a character of a scene document plays, found in the asset library: its SMPL
/// clips, its keyframed clip, its source's own clips, each with its document's clock.
#[derive(Default)]
pub struct CharacterMotion {
    smpl: Option<SmplPlayback>,
    keyframes: Option<(anim::Clip, Clock)>,
    node_clips: Option<NodePlayback>,
    /// Its still pose (its document's pose over its source's) and morph weights.
    still: Vec<JointRotation>,
    weights: Vec<f32>,
}

/// SMPL playback as a document sets it: the clips found, a second blended in by a weight.
struct SmplPlayback {
    clip: Arc<smpl::Clip>,
    blend: Option<(Arc<smpl::Clip>, f32)>,
    upright: bool,
    clock: Clock,
}

/// A source's clips and which play: the clip and one blended in by a weight, by index.
struct NodePlayback {
    clips: Arc<[NodeClip]>,
    clip: usize,
    blend: Option<(usize, f32)>,
    clock: Clock,
}

impl CharacterMotion {
    /// The motion of `c` (whose shaped asset is `asset`); `keyframes` is the keyframed clip
    /// its `anim` plays (its keys, its file's, or the motion it retargets), matched to its
    /// joints here. Its pose keys that name no joint are returned as notes.
    pub fn of(
        library: &mut AssetLibrary,
        c: &CharacterDoc,
        asset: &CharacterAsset,
        keyframes: Option<anim::Clip>,
    ) -> Result<(Self, Vec<String>), FormatError> {
        let skeleton = &asset.skeleton;
        let (still, notes) = crate::scenes::pose_from_doc(asset, c);
        // One weight per morph target: the document's, zero where it sets none.
        let weights = (0..asset.morphs.len()).map(|k| c.morphs.get(k).copied().unwrap_or(0.0)).collect();
        let mut motion = Self { still, weights, ..Self::default() };
        if let (Some(clip), Some(anim)) = (keyframes, &c.anim) {
            motion.keyframes = Some((clip.retargeted(skeleton, &anim.names), anim.clock()));
        }
        if let (Some(part), Some(playback)) = (library.part_of_source(&c.source), &c.playback) {
            let find = |name: &Option<String>| part.clips.iter().position(|k| Some(&k.name) == name.as_ref());
            if let Some(k) = find(&playback.clip) {
                let blend = find(&playback.blend_clip).map(|b| (b, playback.blend));
                let clock = playback.clock();
                motion.node_clips = Some(NodePlayback { clips: part.clips.clone(), clip: k, blend, clock });
            }
        }
        if let (Some(doc), SourceDoc::File(dir)) = (&c.smpl, &c.source)
            && let Some(name) = &doc.clip
        {
            let set = library.smpl(dir)?;
            let find = |wanted: &String| set.clips.iter().find(|(n, _)| n == wanted).map(|(_, k)| k.clone());
            if let Some(clip) = find(name) {
                let blend = doc.blend_clip.as_ref().and_then(find).map(|k| (k, doc.blend));
                motion.smpl = Some(SmplPlayback { clip, blend, upright: doc.upright, clock: doc.clock() });
            }
        }
        Ok((motion, notes))
    }

    /// Its motions, borrowed.
    pub fn playing(&self) -> Playing<'_> {
        Playing {
            smpl: self.smpl.as_ref().map(|s| {
                let blend = s.blend.as_ref().map(|(k, w)| (&**k, *w));
                (SmplMotion { clip: &s.clip, blend, upright: s.upright }, s.clock)
            }),
            keyframes: self.keyframes.as_ref().map(|(clip, clock)| (clip, *clock)),
            node_clips: self.node_clips.as_ref().map(|n| {
                let blend = n.blend.map(|(b, w)| (&n.clips[b], w));
                (NodeMotion { clip: &n.clips[n.clip], blend }, n.clock)
            }),
        }
    }

    /// Its SMPL playback alone, on its still pose.
    pub fn smpl_only(&self) -> Playing<'_> {
        Playing { smpl: self.playing().smpl, ..Playing::default() }
    }

    /// Its still pose: its document's pose over its source's.
    pub fn still(&self) -> &[JointRotation] {
        &self.still
    }

    /// Its pose now: [`pose_at`] at its clocks' times.
    pub fn pose_now(&self, skeleton: &Skeleton) -> MotionPose {
        pose_at(skeleton, &self.still, &self.weights, &self.playing())
    }

    /// Its keyframed clip, as matched to its joints.
    pub fn keyframes(&self) -> Option<&anim::Clip> {
        self.keyframes.as_ref().map(|(k, _)| k)
    }

    /// Whether it plays an SMPL clip.
    pub fn has_smpl(&self) -> bool {
        self.smpl.is_some()
    }
}
