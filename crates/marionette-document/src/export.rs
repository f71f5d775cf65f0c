//! Exporting a scene: every character of a document as glTF, shaped (SMPL β, morph
//! weights), posed by its pose and its clip at its time (keyframes, a glTF file's own
//! animation, SMPL playback), placed and tinted; clips as glTF animations.

use marionette_formats::FormatError;
use marionette_formats::gltf::{GltfCharacter, GltfMesh, Motion, write_glb};
use marionette_formats::limits::MAX_SAMPLED_FRAMES;
use marionette_formats::scene::{CharacterDoc, SceneDoc};
use marionette_rig::fk::RestOverride;
use marionette_rig::node_clip::NodeClip;

use crate::motion::{CharacterMotion, MotionPose};
use crate::retarget::FPS;

/// The name a clip from `file` goes out under: the file's stem, else `otherwise`.
pub fn clip_name(file: &std::path::Path, otherwise: &str) -> String {
    file.file_stem().map_or_else(|| otherwise.to_owned(), |s| s.to_string_lossy().into_owned())
}

/// A keyframed clip as glTF splines ([`spline_clip`](marionette_rig::keyframe_splines::spline_clip)):
/// key for key, times from its start, its joints without keys left at `rest`; refused
/// where a track would need more than
/// [`MAX_SAMPLED_FRAMES`](marionette_formats::limits::MAX_SAMPLED_FRAMES) keys.
pub fn keyframes_as_splines(
    clip: &marionette_rig::anim::Clip,
    skeleton: &marionette_rig::Skeleton,
    rest: &[marionette_rig::JointRotation],
    name: &str,
) -> Result<NodeClip, TooManyKeys> {
    marionette_rig::keyframe_splines::spline_clip(clip, skeleton, rest, name, MAX_SAMPLED_FRAMES).map_err(TooManyKeys)
}

/// A keyframed clip with more keys a track than an export writes.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0} (MAX_SAMPLED_FRAMES)")]
pub struct TooManyKeys(pub String);

/// A character's pose, motion and keyed rest for export.
struct Posed {
    /// Where it stands (its document's placement, or where its holder carries it).
    placement: marionette_formats::scene::PlacementDoc,
    /// Its pose now, from the motion service.
    now: MotionPose,
    root: glam::Vec3,
    /// Rest offsets and scales a clip keys (the root's offset is `root`).
    rest: Option<(Vec<glam::Vec3>, Vec<glam::Vec3>)>,
    motion: Option<Motion>,
    /// The name of `motion`'s animation.
    motion_name: String,
    /// The source's own clips, written key for key (with `animated`).
    clips: std::sync::Arc<[marionette_rig::node_clip::NodeClip]>,
}

/// Every character of a scene document as glTF: its shape, its pose, its clip (keyframes,
/// its source's own animation, SMPL playback) at its time, its placement and tint; with
/// `animated`, the clips as glTF animations.
pub fn scene_glb(doc: &SceneDoc, mesh: GltfMesh, animated: bool) -> Result<Vec<u8>, FormatError> {
    scene_glb_from(&mut super::AssetLibrary::default(), doc, mesh, animated)
}

/// [`scene_glb`] with the files `library` has read (and reads).
pub fn scene_glb_from(
    library: &mut super::AssetLibrary,
    doc: &SceneDoc,
    mesh: GltfMesh,
    animated: bool,
) -> Result<Vec<u8>, FormatError> {
    let loaded = load_posed(library, doc, animated)?;
    let characters: Vec<GltfCharacter> = loaded
        .iter()
        .map(|(c, asset, posed)| GltfCharacter {
            name: &c.name,
            asset,
            pose: &posed.now.rotations,
            root: posed.root,
            rest: posed.rest_override(),
            placement: posed.placement,
            tint: c.view.tint,
            motion: posed.motion.clone(),
            motion_name: posed.motion_name.clone(),
            clips: &posed.clips,
            morph_weights: &posed.now.weights,
        })
        .collect();
    write_glb(&characters, mesh).map_err(|e| FormatError::other(std::path::Path::new("the exported scene"), e))
}

/// Every character of a scene document posed (as [`scene_glb`] poses it) and placed in the
/// world, as one mesh: the characters' vertices in document order, their triangles
/// renumbered to match.
pub fn scene_mesh(doc: &SceneDoc) -> Result<(Vec<glam::Vec3>, Vec<[u32; 3]>), FormatError> {
    scene_mesh_from(&mut super::AssetLibrary::default(), doc)
}

/// [`scene_mesh`] with the files `library` has read (and reads).
pub fn scene_mesh_from(
    library: &mut super::AssetLibrary,
    doc: &SceneDoc,
) -> Result<(Vec<glam::Vec3>, Vec<[u32; 3]>), FormatError> {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for posed in scene_posed(library, doc)? {
        let first = positions.len() as u32;
        positions.extend(posed.vertices);
        triangles.extend(posed.triangles.iter().map(|t| t.map(|v| v + first)));
    }
    Ok((positions, triangles))
}

/// A scene's character posed and placed in the world: its skin's vertices (in its file's
/// order), its triangles, and each joint's transform to the world.
#[derive(Debug, Clone)]
pub struct PosedInWorld {
    pub vertices: Vec<glam::Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub joint_to_world: Vec<glam::Mat4>,
}

/// Every character of a scene document posed (as [`scene_glb`] poses it) and placed in the
/// world, in document order.
pub fn scene_posed(library: &mut super::AssetLibrary, doc: &SceneDoc) -> Result<Vec<PosedInWorld>, FormatError> {
    let mut out = Vec::new();
    for (c, asset, posed) in load_posed(library, doc, false)? {
        let mut asset = asset;
        if posed.now.weights.iter().any(|&w| w != 0.0) {
            std::sync::Arc::make_mut(&mut asset).skin.bind_positions = asset.morphed_positions(&posed.now.weights);
        }
        let placement = posed.placement.to_mat4();
        let world = placement * posed.now.origin(&asset.skeleton);
        let vertices = crate::posing::posed_positions_with_rest(
            &asset,
            &posed.now.rotations,
            posed.now.rest_override(),
            world,
            c.skinning,
        );
        let joint_to_world = posed.now.joint_to_world(&asset.skeleton, placement);
        out.push(PosedInWorld { vertices, triangles: asset.skin.triangles.clone(), joint_to_world });
    }
    Ok(out)
}

/// A scene's character with its shaped asset and its pose.
type PosedCharacter<'a> = (&'a CharacterDoc, std::sync::Arc<marionette_rig::CharacterAsset>, Posed);

/// Every character of `doc` with its shaped asset and its pose; attached characters placed
/// where their holding joints carry them.
fn load_posed<'a>(
    library: &mut super::AssetLibrary,
    doc: &'a SceneDoc,
    animated: bool,
) -> Result<Vec<PosedCharacter<'a>>, FormatError> {
    let mut loaded = Vec::new();
    for c in &doc.characters {
        let asset = library.shaped(c)?;
        let posed = posed(library, doc, c, &asset, animated)?;
        loaded.push((c, asset, posed));
    }
    for i in 0..loaded.len() {
        let Some(attached) = &loaded[i].0.attached else { continue };
        let holder = loaded.iter().find(|(h, ..)| h.id == Some(attached.to));
        if let Some(joint_world) = holder.and_then(|(_, asset, posed)| posed.joint_world(asset, &attached.joint)) {
            loaded[i].2.placement = attached.placement(joint_world);
        }
    }
    Ok(loaded)
}

/// A character's still pose now — its document's pose under its motion at its clocks'
/// times ([`crate::motion`]) — and how far its motion has moved its root from the
/// skeleton's rest offset (model space).
pub fn still_pose(
    library: &mut super::AssetLibrary,
    scene: &SceneDoc,
    c: &CharacterDoc,
    asset: &marionette_rig::CharacterAsset,
) -> Result<(Vec<marionette_rig::JointRotation>, glam::Vec3), FormatError> {
    let (motion, _) = character_motion(library, scene, c, asset)?;
    let now = motion.pose_now(&asset.skeleton);
    let root = now.root_translation(&asset.skeleton);
    Ok((now.rotations, root - asset.skeleton.joint(0).rest_offset))
}

/// What `c` plays in `scene` (its keyframed clip worked out: its keys, its file's, or the
/// motion it retargets), and the pose keys that name no joint.
pub fn character_motion(
    library: &mut super::AssetLibrary,
    scene: &SceneDoc,
    c: &CharacterDoc,
    asset: &marionette_rig::CharacterAsset,
) -> Result<(CharacterMotion, Vec<String>), FormatError> {
    let keyframes = match &c.anim {
        Some(anim) => Some(super::retarget::anim_clip(library, scene, c, asset, anim)?),
        None => None,
    };
    CharacterMotion::of(library, c, asset, keyframes)
}

/// A character's pose from its document and its motion at its clocks' times, and (with
/// `animated`) its clips to write as animations.
fn posed(
    library: &mut super::AssetLibrary,
    scene: &SceneDoc,
    c: &marionette_formats::scene::CharacterDoc,
    asset: &marionette_rig::CharacterAsset,
    animated: bool,
) -> Result<Posed, FormatError> {
    let skeleton = &asset.skeleton;
    let (motion, notes) = character_motion(library, scene, c, asset)?;
    notes.iter().for_each(|n| eprintln!("warning: {n}"));
    let now = motion.pose_now(skeleton);
    let root = now.root_translation(skeleton);
    let rest = now.rest.as_ref().map(|(offsets, scales)| {
        let mut offsets = offsets.clone();
        offsets[0] = skeleton.joint(0).rest_offset;
        (offsets, scales.clone())
    });
    let mut posed = Posed {
        placement: c.placement,
        now,
        root,
        rest,
        motion: None,
        motion_name: String::new(),
        clips: std::sync::Arc::new([]),
    };
    if !animated {
        return Ok(posed);
    }
    if let (Some(anim), Some(clip)) = (&c.anim, motion.keyframes()) {
        let clip_file = if anim.file.as_os_str().is_empty() { std::path::Path::new(&c.name) } else { &anim.file };
        let splines = keyframes_as_splines(clip, skeleton, motion.still(), &clip_name(clip_file, &c.name))
            .map_err(|e| FormatError::other(clip_file, e))?;
        posed.clips = std::sync::Arc::new([splines]);
    }
    if let Some(part) = library.part_of_source(&c.source) {
        // Keyframes on a part whose clips key its root under folded nodes go out in
        // their frame, which the export writes above the root.
        let frame = part.clips.first().map_or(glam::Mat4::IDENTITY, |k| k.root_parent);
        let keyframes = posed.clips.iter().map(|k| marionette_rig::keyframe_splines::reframed(k.clone(), frame));
        posed.clips = part.clips.iter().cloned().chain(keyframes).collect();
    }
    if let Some(name) = c.smpl.as_ref().and_then(|s| s.clip.as_ref()).filter(|_| motion.has_smpl()) {
        let frames = crate::motion::sampled_frames(skeleton, motion.still(), &motion.smpl_only(), FPS, "export")
            .map_err(|e| FormatError::other(std::path::Path::new(&c.name), e))?;
        (posed.motion_name, posed.motion) = (smpl_clip_name(name), Some(smpl_motion(&frames)));
    }
    Ok(posed)
}

impl Posed {
    /// The rest offsets and scales its clip keys, for the glTF writer (the root's is `root`).
    fn rest_override(&self) -> RestOverride<'_> {
        self.rest.as_ref().map_or_else(Default::default, |(o, s)| RestOverride { offsets: Some(o), scales: Some(s) })
    }

    /// The world transform of the joint `key` names (a pose key), posed.
    fn joint_world(&self, asset: &marionette_rig::CharacterAsset, key: &str) -> Option<glam::Mat4> {
        let skeleton = &asset.skeleton;
        let joint = marionette_formats::scene::joint_of_pose_key(skeleton, key)?;
        Some(self.now.joint_to_world(skeleton, self.placement.to_mat4())[joint])
    }
}

/// An SMPL body's frames as a motion at its 30 frames per second.
fn smpl_motion(frames: &[marionette_rig::retarget::Frame]) -> Motion {
    let mut motion = Motion::default();
    for (f, frame) in frames.iter().enumerate() {
        motion.times.push(crate::motion::smpl_frame_time(f));
        motion.poses.push(frame.pose.clone());
        motion.roots.push(frame.root);
    }
    motion
}

/// An SMPL clip's name without its file's `.txt`.
fn smpl_clip_name(file: &str) -> String {
    file.strip_suffix(".txt").unwrap_or(file).to_string()
}
