//! Retargeting in documents: a character's motion (its SMPL clip, keyframed clip or glTF
//! clip) sampled as frames, carried onto another character through their humanoid maps
//! and baked into a keyframed clip the target plays like any other.

use std::path::Path;
use std::sync::Arc;

use marionette_formats::FormatError;
use marionette_formats::scene::{
    AnimDoc, CharacterDoc, MotionSourceDoc, PlaybackDoc, RetargetDoc, SceneDoc, SmplDoc, SourceDoc, is_motion_file,
};
use marionette_rig::anim::Clip;
use marionette_rig::character::SkinKind;
use marionette_rig::dqs::SkinningMethod;
use marionette_rig::fk::RestOverride;
use marionette_rig::humanoid::{HumanBone, HumanoidMap};
use marionette_rig::retarget::{Frame, Humanoid, Retargeter};
use marionette_rig::{CharacterAsset, JointRotation};

use crate::motion::CharacterMotion;

/// Frames a second at which motion is sampled for retargeting (the SMPL clips' rate).
pub const FPS: f32 = marionette_rig::smpl::CLIP_FPS;

pub use crate::library::Retargeting;

/// A character's humanoid map: found from its skeleton, with the document's bones
/// assigned by hand over it (an empty or unknown key takes the bone off).
pub fn humanoid_map(asset: &CharacterAsset, assigned: &std::collections::BTreeMap<HumanBone, String>) -> HumanoidMap {
    let skeleton = &asset.skeleton;
    let mut map = marionette_rig::humanoid::of_asset(asset).map(|d| d.map).unwrap_or_default();
    for (bone, key) in assigned {
        match marionette_formats::scene::joint_of_pose_key(skeleton, key) {
            Some(j) => map.insert(*bone, j),
            None => map.remove(bone),
        };
    }
    map
}

/// The height of a character's floor in its model space: its lowest skin vertex standing
/// in its initial pose, or its lowest joint where it has no mesh.
pub fn floor_of(asset: &CharacterAsset) -> f32 {
    let skeleton = &asset.skeleton;
    lowest_point(asset, &Frame::posed(skeleton.joint(0).rest_offset, skeleton.initial_pose()))
}

/// The floor a motion stands on, in the character's model space: the lowest its skin
/// reaches over the frames (its joints, for a skeleton without a mesh: a BVH's rest is
/// only its offsets and its place is the motion's), and for a character with a mesh no
/// higher than its own floor standing (a clip that leaves the ground throughout still
/// stands on it).
pub fn motion_floor(asset: &CharacterAsset, frames: &[Frame]) -> f32 {
    let lowest = frames.iter().map(|f| lowest_point(asset, f)).fold(f32::INFINITY, f32::min);
    match asset.skin_kind {
        SkinKind::Mesh if lowest.is_finite() => floor_of(asset).min(lowest),
        _ if lowest.is_finite() => lowest,
        _ => floor_of(asset),
    }
}

/// Whether a humanoid stands in its initial pose: its hips below its head (else its chest,
/// neck), the line between within 45° of up. A source that does not stands as in its
/// motion's first frame.
pub fn stands_upright(skeleton: &marionette_rig::Skeleton, map: &HumanoidMap) -> bool {
    let (_, at) =
        marionette_rig::retarget::world_frames(skeleton, skeleton.joint(0).rest_offset, &skeleton.initial_pose());
    let top = [HumanBone::Head, HumanBone::Neck, HumanBone::Chest].iter().find_map(|b| map.get(b));
    match (map.get(&HumanBone::Hips), top) {
        (Some(&hips), Some(&top)) => (at[top] - at[hips]).normalize_or_zero().y > std::f32::consts::FRAC_1_SQRT_2,
        _ => true,
    }
}

/// The lowest point of a character in a frame: of its skinned mesh, or of its joints
/// where it has none (never of the boxes drawn for its bones).
fn lowest_point(asset: &CharacterAsset, frame: &Frame) -> f32 {
    let skeleton = &asset.skeleton;
    let lowest = |points: &[glam::Vec3]| points.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    let skin = if asset.skin_kind == SkinKind::Mesh {
        let rest = RestOverride { offsets: frame.offsets.as_deref(), scales: None };
        let origin = frame.origin(skeleton);
        lowest(&super::posing::posed_positions_with_rest(asset, &frame.pose, rest, origin, SkinningMethod::Linear))
    } else {
        f32::INFINITY
    };
    if skin.is_finite() { skin } else { lowest(&frame.world(skeleton).1) }
}

/// The points a character stands on: the lowest skin vertices (at most 4,096 a foot) that
/// each foot joint of its map, or a joint below it (toes), moves most, as their joints
/// move them: each in its joint's frame turned, in model units (a joint's scale, such as a
/// Mixamo armature's 0.01, taken out).
pub fn soles(asset: &CharacterAsset, map: &HumanoidMap) -> Vec<marionette_rig::retarget::Sole> {
    const MOST: usize = 4096;
    let (skin, skeleton) = (&asset.skin, &asset.skeleton);
    let dominant = |v: usize| {
        let row = skin.weights.of_vertex(v);
        row.iter().max_by(|a, b| a.weight.total_cmp(&b.weight)).map(|i| usize::from(i.joint))
    };
    let mut out = Vec::new();
    for &foot in [HumanBone::LeftFoot, HumanBone::RightFoot].iter().filter_map(|b| map.get(b)) {
        let mut own: Vec<usize> = (0..skin.weights.vertex_count())
            .filter(|&v| dominant(v).is_some_and(|j| j == foot || skeleton.is_below(j, foot)))
            .collect();
        own.sort_by(|&a, &b| skin.bind_positions[a].y.total_cmp(&skin.bind_positions[b].y));
        out.extend(own.into_iter().take(MOST).map(|v| {
            let p = skin.bind_positions[v];
            let parts = skin.weights.of_vertex(v).iter().map(|i| {
                let j = usize::from(i.joint);
                // In the joint's frame turned but not scaled (its scale is the rig's units).
                let (scale, _, _) = asset.bind_world_to_joint[j].inverse().to_scale_rotation_translation();
                (j, i.weight, scale * asset.bind_world_to_joint[j].transform_point3(p))
            });
            parts.collect()
        }));
    }
    out
}

/// A character's own motion as frames at [`FPS`] over its clips' range, as the motion
/// service poses it ([`crate::motion`]): its SMPL clip, its keyframed clip, its glTF clip.
/// None when it has no motion of its own; refused for a motion that is itself retargeted.
pub fn motion_frames(
    library: &mut super::AssetLibrary,
    c: &CharacterDoc,
    asset: &CharacterAsset,
) -> Result<Option<Vec<Frame>>, FormatError> {
    let keyframes = match c.anim.as_ref().map(|anim| (&anim.keys, &anim.retarget, &anim.file)) {
        None => None,
        Some((Some(keys), _, _)) => Some(keys.clone()),
        Some((None, Some(_), _)) => {
            return Err(FormatError::other(
                Path::new(&c.name),
                "expected a clip of its own to retarget, found a retargeted one",
            ));
        }
        Some((None, None, file)) => Some((*library.keyframe_clip(file)?).clone()),
    };
    let (motion, _) = CharacterMotion::of(library, c, asset, keyframes)?;
    let playing = motion.playing();
    if playing.is_empty() {
        return Ok(None);
    }
    let frames = crate::motion::sampled_frames(&asset.skeleton, motion.still(), &playing, FPS, "retarget")
        .map_err(|e| FormatError::other(Path::new(&c.name), e))?;
    Ok(Some(frames))
}

/// The document of the character a file brings, playing the clip `clip` names (see
/// [`MotionSourceDoc::File`]).
pub fn file_motion_doc(
    library: &mut super::AssetLibrary,
    path: &Path,
    clip: Option<&str>,
) -> Result<CharacterDoc, FormatError> {
    let source = SourceDoc::File(path.to_path_buf());
    let asset = library.load(&source)?;
    let mut doc = library.new_character_doc(source.clone(), &asset);
    if is_motion_file(path) {
        doc.anim = Some(AnimDoc::of(path));
    } else if let Some(spec) = clip {
        if is_motion_file(Path::new(spec)) {
            doc.anim = Some(AnimDoc::of(spec));
        } else if marionette_formats::smpl::is_smpl_dir(path) {
            let set = library.smpl(path)?;
            let name = set.clips.iter().map(|(n, _)| n.clone()).find(|n| n.trim_end_matches(".txt").ends_with(spec));
            let name = name.ok_or_else(|| {
                FormatError::other(path, format!("expected an SMPL clip ending in `{spec}`, found none"))
            })?;
            doc.smpl = Some(SmplDoc { clip: Some(name), upright: true, ..SmplDoc::default() });
        } else {
            let part = library.part_of_source(&source);
            let found = part.as_ref().and_then(|p| super::posing::find_clip(&p.clips, spec));
            let found = found.ok_or_else(|| {
                FormatError::other(path, format!("expected a clip named or numbered `{spec}`, found none"))
            })?;
            doc.playback = Some(PlaybackDoc { clip: Some(found.name.clone()), ..PlaybackDoc::default() });
        }
    } else if marionette_formats::smpl::is_smpl_dir(path) {
        let set = library.smpl(path)?;
        doc.smpl =
            Some(SmplDoc { clip: set.clips.first().map(|(n, _)| n.clone()), upright: true, ..SmplDoc::default() });
    } else if let Some(first) = library.part_of_source(&source).and_then(|p| p.clips.first().cloned()) {
        doc.playback = Some(PlaybackDoc { clip: Some(first.name.clone()), ..PlaybackDoc::default() });
    }
    Ok(doc)
}

/// The document of the humanoid `from` names: a character of `scene`, or a file's.
pub fn motion_source_doc(
    library: &mut super::AssetLibrary,
    scene: &SceneDoc,
    from: &MotionSourceDoc,
) -> Result<CharacterDoc, FormatError> {
    match from {
        MotionSourceDoc::Character(id) => {
            scene.characters.iter().find(|c| c.id == Some(*id)).cloned().ok_or_else(|| {
                FormatError::other(
                    Path::new(&id.to_string()),
                    "expected a character of the scene to take the motion of, found none",
                )
            })
        }
        MotionSourceDoc::File { path, clip } => file_motion_doc(library, path, clip.as_deref()),
    }
}

/// The motion of `source` carried onto `target` (whose asset is `target_asset`) as
/// `settings` ask, baked into a keyframed clip of the joints the source drives. Worked out
/// once per command for each source, target and settings: the library keeps it.
pub fn retarget(
    library: &mut super::AssetLibrary,
    source: &CharacterDoc,
    target: &CharacterDoc,
    target_asset: &CharacterAsset,
    settings: &RetargetDoc,
) -> Result<Arc<Retargeting>, FormatError> {
    let key = retargeting_key(source, target, settings);
    if let Some(done) = library.retargetings.get(&key) {
        return Ok(done.clone());
    }
    let done = Arc::new(work_out_retargeting(library, source, target, target_asset, settings)?);
    library.retargetings.insert(key, done.clone());
    Ok(done)
}

/// What a retargeting depends on: the source's document and the target's less where their
/// clips are playing (the whole motion is carried), the target's less the motion it is
/// about to be given, and the settings.
fn retargeting_key(source: &CharacterDoc, target: &CharacterDoc, settings: &RetargetDoc) -> String {
    let target = CharacterDoc { anim: None, playback: None, ..target.clone() };
    let (source, target) = (without_playhead(source), without_playhead(&target));
    ron::to_string(&(source, target, settings)).expect("scene documents serialise")
}

fn without_playhead(doc: &CharacterDoc) -> CharacterDoc {
    let mut doc = doc.clone();
    doc.anim.iter_mut().for_each(|a| (a.time, a.playing) = (0.0, false));
    doc.smpl.iter_mut().for_each(|s| (s.time, s.playing) = (0.0, false));
    doc.playback.iter_mut().for_each(|p| (p.time, p.playing) = (0.0, false));
    doc
}

fn work_out_retargeting(
    library: &mut super::AssetLibrary,
    source: &CharacterDoc,
    target: &CharacterDoc,
    target_asset: &CharacterAsset,
    settings: &RetargetDoc,
) -> Result<Retargeting, FormatError> {
    let here = |what: String| FormatError::other(Path::new(&target.name), what);
    let source_asset = library.shaped(source)?;
    let source_frames = motion_frames(library, source, &source_asset)?
        .ok_or_else(|| here(format!("expected {} to have a motion of its own, found none", source.name)))?;
    let (s_map, t_map) = (humanoid_map(&source_asset, &source.humanoid), humanoid_map(target_asset, &target.humanoid));
    let (s_skel, t_skel) = (&source_asset.skeleton, &target_asset.skeleton);
    let s_floor = motion_floor(&source_asset, &source_frames);
    // A character playing its own clip stands on the clip's floor: the clip onto itself is
    // the clip.
    let same_rig = source_asset.skeleton == target_asset.skeleton && s_map == t_map;
    let t_floor = if same_rig { s_floor } else { floor_of(target_asset) };
    let (s_soles, t_soles) = (soles(&source_asset, &s_map), soles(target_asset, &t_map));
    // A source whose rest does not stand (a motion capture lying along +x at zero rotations)
    // stands as in its first frame.
    let stands = source_frames.first().filter(|_| !stands_upright(s_skel, &s_map));
    let s_rest_floor = stands.map_or_else(|| floor_of(&source_asset), |f| lowest_point(&source_asset, f));
    let retargeter = Retargeter::new(
        Humanoid { skeleton: s_skel, map: &s_map, floor: s_floor, rest_floor: s_rest_floor, soles: &s_soles, stands },
        Humanoid {
            skeleton: t_skel,
            map: &t_map,
            floor: t_floor,
            rest_floor: floor_of(target_asset),
            soles: &t_soles,
            stands: None,
        },
        settings.rest,
    )
    .ok_or_else(|| {
        here(format!(
            "expected both {} and {} to have hips and two legs in their humanoid maps",
            source.name, target.name
        ))
    })?;
    let report = retargeter.motion(&source_frames, FPS, settings.plant_feet);
    let clip = Clip::from_frames(t_skel, &report.frames, FPS, &retargeter.driven());
    let leg_ratio = retargeter.leg_ratio();
    Ok(Retargeting { clip, report, leg_ratio, source_frames, floors: (s_floor, t_floor) })
}

/// The keyframed clip an `AnimDoc` plays on `target` in `scene`: its keys, its file's, or
/// the motion it retargets.
pub fn anim_clip(
    library: &mut super::AssetLibrary,
    scene: &SceneDoc,
    target: &CharacterDoc,
    target_asset: &CharacterAsset,
    anim: &AnimDoc,
) -> Result<Clip, FormatError> {
    match (&anim.keys, &anim.retarget) {
        (Some(keys), _) => Ok(keys.clone()),
        (None, Some(settings)) => {
            let source = motion_source_doc(library, scene, &settings.from)?;
            Ok(retarget(library, &source, target, target_asset, settings)?.clip.clone())
        }
        (None, None) => Ok((*library.keyframe_clip(&anim.file)?).clone()),
    }
}

/// One line on what a retargeting did: frames, the leg ratio, the frames each foot was
/// planted, and the joints the target's limits clamped (with how many frames).
pub fn describe(done: &Retargeting, source: &str, target: &str, skeleton: &marionette_rig::Skeleton) -> String {
    let report = &done.report;
    let planted = |k: usize| report.planted[k].iter().filter(|&&p| p).count();
    let mut clamped: std::collections::BTreeMap<usize, usize> = Default::default();
    report.clamped.iter().for_each(|&(_, j)| *clamped.entry(j).or_default() += 1);
    let clamped: Vec<String> = clamped.iter().map(|(&j, n)| format!("{} ({n})", skeleton.joint(j).name)).collect();
    format!(
        "{target}: {} frames of {source}'s motion, leg ratio {:.3}, feet planted in {} (left) and {} (right) frames; clamped by the limits: {}",
        report.frames.len(),
        done.leg_ratio,
        planted(0),
        planted(1),
        if clamped.is_empty() { "none".to_string() } else { clamped.join(", ") }
    )
}

/// What a pose named by joints of `source` (its skeleton and map, where known) gives
/// `target` (posed as `current`), mirrored left to right first when asked: the joints by
/// name where the target has every one named (a rig of the same family); otherwise the
/// pose carried through the humanoid maps, each bone the source's names drive pointing as
/// the source's does, under the target's own parents.
pub fn pose_onto(
    target: (&marionette_rig::Skeleton, &HumanoidMap),
    current: &[JointRotation],
    pose: &[(String, JointRotation)],
    source: Option<(&marionette_rig::Skeleton, &HumanoidMap)>,
    mirrored: bool,
) -> Vec<(usize, JointRotation)> {
    use marionette_formats::scene::joint_of_pose_key;
    let pose = if mirrored { marionette_rig::mirror::mirrored_pose(pose) } else { pose.to_vec() };
    let by_name: Vec<(usize, JointRotation)> =
        pose.iter().filter_map(|(key, r)| Some((joint_of_pose_key(target.0, key)?, *r))).collect();
    let Some((s, s_map)) = source.filter(|_| by_name.len() < pose.len()) else { return by_name };
    let mut full = s.initial_pose();
    let mut named = Vec::new();
    for (key, r) in &pose {
        if let Some(j) = joint_of_pose_key(s, key) {
            full[j] = *r;
            named.push(j);
        }
    }
    let side = |(skeleton, map)| Humanoid { skeleton, map, floor: 0.0, rest_floor: 0.0, soles: &[], stands: None };
    let rest = marionette_rig::retarget::RestAlignment::Directions;
    match Retargeter::new(side((s, s_map)), side(target), rest) {
        Some(retargeter) => retargeter.pose_over(&full, current, &named),
        None => by_name,
    }
}
