//! The command line's posing options — `--skinning`, `--anim`/`--retarget`, `--clip`,
//! `--time`, `--pose`, `--ik` — applied to a scene document in one place, the same way for
//! `render`, `edit` and `export` and for every kind of input (a scene, character files, a
//! glTF or FBX file): each input becomes a scene document first, then these options change
//! it. An option that names what no character has (a joint, a clip) fails.
//!
//! Order: skinning; the clip `--anim` names on the characters it fits (or, with
//! `--retarget`, the humanoids); `--clip` on the characters whose file has it; every clip
//! paused at `--time`; then `--pose` and `--ik` on top of each character's pose at that
//! time. A character posed by `--pose`/`--ik` keeps that still pose: its clips are baked
//! into it (the root's travel into its placement), so every command shows the same figure.

use glam::{Mat4, Vec3};

use marionette_formats::scene::{AnimDoc, Clocked, PlaybackDoc, SceneDoc, pose_key};
use marionette_rig::dqs::SkinningMethod;
use marionette_rig::playback::Clock;

use crate::AssetLibrary;
use marionette_formats::FormatError;

/// An option that cannot be carried out: it names what no character has, or what it
/// needs cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum OptionsError {
    #[error(transparent)]
    Format(#[from] FormatError),
    #[error(transparent)]
    Pose(#[from] crate::posing::PoseSpecError),
    #[error("--retarget: no character has a humanoid map (two legs, two arms) to take the motion")]
    NoHumanoid,
    #[error("{}: its {channels} channels fit no character (3 for the root, then 3 per joint, or joints by name)", file.display())]
    ClipFitsNone { file: std::path::PathBuf, channels: usize },
    #[error("{file}: no clip `{spec}` (its clips: {clips})")]
    NoSuchClip { file: String, spec: String, clips: String },
    #[error("no file has a clip `{spec}` ({files})")]
    NoFileHasClip { spec: String, files: String },
    #[error("--preset {preset}: no character has a humanoid map (hips, two legs)")]
    NoHumanoidForPreset { preset: String },
    #[error(transparent)]
    Fit(#[from] crate::fit::FitError),
    #[error("{option}: no character has a humanoid map (hips, two legs, two arms) to fit")]
    NoHumanoidToFit { option: &'static str },
    #[error("{option}: no character has a joint named or numbered `{joint}` ({known})")]
    UnknownJoint { option: &'static str, joint: String, known: String },
}
use crate::posing::{IkSpec, LookAtSpec, PoseSpec, TwoBoneSpec, apply_pose_specs, find_clip, solve_constraints};

/// The posing specs of the command line, applied to every character that has the joint
/// (or, for the hands, mapped fingers) in this order.
#[derive(Clone, Debug, Default)]
pub struct PoseSpecs {
    /// `--preset NAME[:mirrored]`: a built-in body pose on every humanoid, stood on the floor.
    pub preset: Option<crate::posing::BodyPoseSpec>,
    /// `--pose JOINT=rx,ry,rz`.
    pub poses: Vec<PoseSpec>,
    /// `--hand SIDE=NAME`.
    pub hands: Vec<crate::posing::HandSpec>,
    /// `--ik JOINT=x,y,z`.
    pub ik: Vec<IkSpec>,
    /// `--two-bone JOINT=x,y,z[@x,y,z]`.
    pub two_bone: Vec<TwoBoneSpec>,
    /// `--look-at JOINT=x,y,z`.
    pub look_at: Vec<LookAtSpec>,
    /// `--fit FILE.json`: the first humanoid posed, and the camera placed, to match a pose
    /// detector's keypoints.
    pub fit: Option<crate::fit::FitSpec>,
    /// `--fit-sequence DIR`: per-frame keypoint files fitted into a clip on the first
    /// humanoid.
    pub fit_sequence: Option<crate::fit::SequenceSpec>,
}

impl PoseSpecs {
    /// The size of the picture a fit's keypoints were found in (`--fit`'s file, or
    /// `--fit-sequence`'s first), where the file gives it and can be read.
    pub fn fitted_picture_size(&self) -> Option<(u32, u32)> {
        let (file, person) = match (&self.fit, &self.fit_sequence) {
            (Some(fit), _) => (fit.file.clone(), fit.person),
            (None, Some(sequence)) => (crate::fit::frame_files(&sequence.frames).ok()?.remove(0), sequence.person),
            (None, None) => return None,
        };
        crate::fit::file_picture_size(&file, person)
    }
}

/// What the command line asks of the characters.
#[derive(Clone, Debug, Default)]
pub struct PoseOptions {
    /// `--pose`, `--hand`, `--ik`, `--two-bone`, `--look-at`.
    pub specs: PoseSpecs,
    /// `--skinning`: every character skinned this way.
    pub skinning: Option<SkinningMethod>,
    /// `--anim FILE` (or `--retarget FILE`): a clip on every character it fits.
    pub anim: Option<AnimDoc>,
    /// `--clip NAME|INDEX`: a glTF or FBX file's own clip on the characters it moves.
    pub clip: Option<String>,
    /// `--time T`: every clip paused at T seconds.
    pub time: Option<f32>,
    /// A still picture or mesh: without `--time`, every clip paused where its document has
    /// it (a picture is never taken of a clip that plays on while the renderer warms up).
    pub still: bool,
}

impl PoseOptions {
    /// Whether the options pose a still figure (which baking clips into it gives).
    pub fn poses_joints(&self) -> bool {
        !self.specs.poses.is_empty()
            || !self.specs.ik.is_empty()
            || !self.specs.two_bone.is_empty()
            || !self.specs.look_at.is_empty()
            || !self.specs.hands.is_empty()
            || self.specs.preset.is_some()
            || self.specs.fit.is_some()
    }
}

/// Applies `options` to `doc`. Returns what is worth saying (what each retargeting did,
/// IK reports), or what named something no character has.
pub fn apply_options(
    doc: &mut SceneDoc,
    options: &PoseOptions,
    library: &mut AssetLibrary,
) -> Result<Vec<String>, OptionsError> {
    let mut notes = Vec::new();
    if let Some(method) = options.skinning {
        doc.characters.iter_mut().for_each(|c| c.skinning = method);
    }
    if let Some(anim) = &options.anim {
        put_clip_on_fitting_characters(doc, anim, library, &mut notes)?;
    }
    if let Some(spec) = &options.clip {
        play_own_clip(doc, spec, library)?;
    }
    if let Some(spec) = &options.specs.fit_sequence {
        notes.push(fit_clip(doc, spec, library)?);
    }
    match options.time {
        Some(t) => pause_clips_at(doc, t),
        None if options.still => pause_clips(doc),
        None => {}
    }
    if options.poses_joints() {
        notes.extend(pose_characters(doc, options, library)?);
    }
    Ok(notes)
}

/// Puts the clip on every character whose skeleton it fits (3 channels for the root, 3 per
/// joint, or joints by name); a retargeted motion on every humanoid (worked out here, so a
/// motion that cannot be carried is refused now, and described). The characters' own clips
/// stop. Fails when it fits none.
fn put_clip_on_fitting_characters(
    doc: &mut SceneDoc,
    anim: &AnimDoc,
    library: &mut AssetLibrary,
    notes: &mut Vec<String>,
) -> Result<(), OptionsError> {
    if let Some(settings) = &anim.retarget {
        let scene = doc.clone();
        // The source, found once (when a character can take its motion).
        let mut source = None;
        let mut fitted = 0;
        for c in &mut doc.characters {
            let Ok(asset) = library.shaped(c) else { continue };
            if marionette_rig::humanoid::of_asset(&asset).is_none() {
                continue;
            }
            if source.is_none() {
                let found = crate::retarget::motion_source_doc(library, &scene, &settings.from);
                source = Some(found?);
            }
            let from = source.as_ref().expect("found above");
            let done = crate::retarget::retarget(library, from, c, &asset, settings)?;
            notes.push(crate::retarget::describe(&done, &from.name, &c.name, &asset.skeleton));
            c.anim = Some(anim.clone());
            c.playback = None;
            fitted += 1;
        }
        return match fitted {
            0 => Err(OptionsError::NoHumanoid),
            _ => Ok(()),
        };
    }
    let clip = library.keyframe_clip(&anim.file)?;
    let mut fitted = 0;
    for c in &mut doc.characters {
        let fits = |a: &marionette_rig::CharacterAsset| match clip.joint_names.is_empty() {
            true => 3 + 3 * a.skeleton.len() == clip.channels.len(),
            false => a.skeleton.joints().iter().any(|j| clip.joint_names.contains(&j.name)),
        };
        if library.load(&c.source).is_ok_and(|a| fits(&a)) {
            c.anim = Some(anim.clone());
            c.playback = None;
            fitted += 1;
        }
    }
    match fitted {
        0 => Err(OptionsError::ClipFitsNone { file: anim.file.clone(), channels: clip.channels.len() }),
        _ => Ok(()),
    }
}

/// Plays the file's own clip `spec` (name, or index as `info` numbers them) on every
/// character it moves. Fails on a file that has clips but none `spec` names, or when no
/// character's file has it, listing the clips there are.
fn play_own_clip(doc: &mut SceneDoc, spec: &str, library: &mut AssetLibrary) -> Result<(), OptionsError> {
    // Each file once, in order: its clips as `info` lists them, and whether `spec` found one.
    let mut files: Vec<(String, Vec<String>, bool)> = Vec::new();
    for c in &mut doc.characters {
        let Some(part) = library.part_of_source(&c.source) else { continue };
        let file = c.source.path().map_or(c.name.clone(), |p| p.display().to_string());
        if !files.iter().any(|f| f.0 == file) {
            files.push((file.clone(), Vec::new(), false));
        }
        let entry = files.iter_mut().find(|f| f.0 == file).expect("just added");
        for k in part.clips.iter() {
            let name = format!("{} `{}`", k.index, k.name);
            if !entry.1.contains(&name) {
                entry.1.push(name);
            }
        }
        if let Some(clip) = find_clip(&part.clips, spec) {
            let state = c.playback.take().unwrap_or(PlaybackDoc { playing: true, ..Default::default() });
            c.playback = Some(PlaybackDoc { clip: Some(clip.name.clone()), ..state });
            entry.2 = true;
        }
    }
    if let Some((file, clips, _)) = files.iter().find(|(_, clips, found)| !found && !clips.is_empty()) {
        return Err(OptionsError::NoSuchClip { file: file.clone(), spec: spec.to_owned(), clips: clips.join(", ") });
    }
    if !files.iter().any(|f| f.2) {
        let listed: Vec<String> = files.iter().map(|f| format!("{}: none", f.0)).collect();
        let files =
            if listed.is_empty() { "no character comes from a glTF or FBX file".into() } else { listed.join("; ") };
        return Err(OptionsError::NoFileHasClip { spec: spec.to_owned(), files });
    }
    Ok(())
}

/// Every clip of the document paused where it is.
fn pause_clips(doc: &mut SceneDoc) {
    for c in &mut doc.characters {
        for_each_clock(c, |clock| clock.set_clock(Clock { playing: false, ..clock.clock() }));
    }
}

/// Every clip of the document (keyframes, SMPL, a file's own) paused at `t` seconds.
pub fn pause_clips_at(doc: &mut SceneDoc, t: f32) {
    for c in &mut doc.characters {
        for_each_clock(c, |clock| clock.pause_at(t));
    }
}

/// `f` on the clock of each motion `c` plays (its keyframed clip; its SMPL and own clips
/// where one is chosen).
fn for_each_clock(c: &mut marionette_formats::scene::CharacterDoc, mut f: impl FnMut(&mut dyn Clocked)) {
    c.anim.iter_mut().for_each(|a| f(a));
    c.smpl.iter_mut().filter(|s| s.clip.is_some()).for_each(|s| f(s));
    c.playback.iter_mut().filter(|p| p.clip.is_some()).for_each(|p| f(p));
}

/// `--pose` then `--ik` on every character that has the joints, on top of its pose now;
/// its clips baked into that still pose. Fails on a joint no character has.
fn pose_characters(
    doc: &mut SceneDoc,
    options: &PoseOptions,
    library: &mut AssetLibrary,
) -> Result<Vec<String>, OptionsError> {
    let scene = doc.clone();
    let mut notes = Vec::new();
    let mut used = vec![
        false;
        options.specs.poses.len()
            + options.specs.ik.len()
            + options.specs.two_bone.len()
            + options.specs.look_at.len()
    ];
    let mut joints_seen = Vec::new();
    let mut preset_used = false;
    let mut fitted: Option<crate::fit::Fitted> = None;
    for c in &mut doc.characters {
        let asset = match library.shaped(c) {
            Ok(asset) => asset,
            Err(e) => {
                joints_seen.push(format!("{}: not loaded: {e}", c.name));
                continue;
            }
        };
        let skeleton = &asset.skeleton;
        let names: Vec<&str> = skeleton.joints().iter().map(|j| j.name.as_str()).collect();
        joints_seen.push(format!("{}: {}", c.name, crate::posing::name_list(&names)));
        let has = |joint: &str| skeleton.resolve(joint).is_some();
        let poses: Vec<PoseSpec> = options.specs.poses.iter().filter(|p| has(&p.joint)).cloned().collect();
        let ik: Vec<IkSpec> = options.specs.ik.iter().filter(|p| has(&p.joint)).cloned().collect();
        let two_bone: Vec<TwoBoneSpec> = options.specs.two_bone.iter().filter(|p| has(&p.joint)).cloned().collect();
        let look_at: Vec<LookAtSpec> = options.specs.look_at.iter().filter(|p| has(&p.joint)).cloned().collect();
        if poses.is_empty()
            && ik.is_empty()
            && two_bone.is_empty()
            && look_at.is_empty()
            && options.specs.hands.is_empty()
            && options.specs.preset.is_none()
            && options.specs.fit.is_none()
        {
            continue;
        }
        let names = options.specs.poses.iter().map(|p| &p.joint).chain(options.specs.ik.iter().map(|p| &p.joint));
        let names = names
            .chain(options.specs.two_bone.iter().map(|p| &p.joint))
            .chain(options.specs.look_at.iter().map(|p| &p.joint));
        names.zip(&mut used).filter(|(j, _)| has(j)).for_each(|(_, u)| *u = true);
        let (mut pose, root_shift) = crate::export::still_pose(library, &scene, c, &asset)?;
        // The humanoid map, once, for the body pose, the hands and the look-at.
        let map = if options.specs.hands.is_empty()
            && look_at.is_empty()
            && options.specs.preset.is_none()
            && options.specs.fit.is_none()
        {
            Default::default()
        } else {
            crate::retarget::humanoid_map(&asset, &c.humanoid)
        };
        if let Some(spec) = &options.specs.preset {
            match crate::posing::body_posed(skeleton, &map, &pose, spec, spec.blend) {
                Some((posed, limited)) => {
                    pose = posed;
                    notes.push(format!("{}: {}", c.name, crate::posing::describe_body_pose(skeleton, spec, &limited)));
                    preset_used = true;
                }
                None => notes.push(format!("{}: no humanoid map (hips, two legs); {} skipped", c.name, spec.name)),
            }
        }
        let placement = c.placement.to_mat4() * Mat4::from_translation(root_shift);
        let fits_here = options.specs.fit.as_ref().filter(|_| fitted.is_none());
        if let Some(spec) = fits_here {
            match crate::fit::fit_file(&asset, &map, placement, crate::fit::is_smpl(&c.source), spec) {
                Ok(fit) => {
                    pose.clone_from(&fit.pose);
                    notes.push(format!("{}: {}", c.name, fit.describe()));
                    fitted = Some(fit);
                }
                Err(crate::fit::FitError::NoHumanoid) => {}
                Err(e) => return Err(e.into()),
            }
        }
        let fitted_here = fits_here.is_some() && fitted.is_some();
        apply_pose_specs(skeleton, &mut pose, &poses)?;
        let hands = crate::posing::apply_hand_specs(skeleton, &map, &mut pose, &options.specs.hands);
        notes.extend(hands.into_iter().map(|n| format!("{}: {n}", c.name)));
        // A body pose stands on the floor before the goals are solved: they are where the
        // written pose reaches.
        let placement = match options.specs.preset.is_some() || fitted_here {
            true => crate::posing::stood_on_floor(&asset, &pose, placement),
            false => placement,
        };
        if let (true, Some(fit)) = (fitted_here, &mut fitted) {
            // The camera moves with the character, so the picture is the same.
            fit.camera.focus += (placement * fit.placement.inverse()).w_axis.truncate();
        }
        let goals = (&ik[..], &two_bone[..], &look_at[..]);
        let reports = solve_constraints(skeleton, &map, &mut pose, placement, goals)?;
        notes.extend(reports.lines(skeleton, &c.name));
        let initial = skeleton.initial_pose();
        c.pose =
            (0..skeleton.len()).filter(|&j| pose[j] != initial[j]).map(|j| (pose_key(skeleton, j), pose[j])).collect();
        if root_shift != Vec3::ZERO || options.specs.preset.is_some() || fitted_here {
            c.placement = marionette_formats::scene::PlacementDoc::from_mat4(placement);
        }
        bake_clips(c);
    }
    let specs = options
        .specs
        .poses
        .iter()
        .map(|p| ("--pose", &p.joint))
        .chain(options.specs.ik.iter().map(|p| ("--ik", &p.joint)));
    let specs = specs.chain(options.specs.two_bone.iter().map(|p| ("--two-bone", &p.joint)));
    let specs = specs.chain(options.specs.look_at.iter().map(|p| ("--look-at", &p.joint)));
    if let (Some(spec), false) = (&options.specs.preset, preset_used) {
        return Err(OptionsError::NoHumanoidForPreset { preset: spec.name.clone() });
    }
    match (&options.specs.fit, fitted) {
        (Some(_), None) => return Err(OptionsError::NoHumanoidToFit { option: "--fit" }),
        (Some(spec), Some(fit)) => frame_the_fit(doc, fit.camera, fit.size, &spec.file),
        _ => {}
    }
    if let Some((option, joint)) = specs.zip(&used).find(|(_, u)| !**u).map(|(s, _)| s) {
        let known = joints_seen.join("; ");
        return Err(OptionsError::UnknownJoint { option, joint: joint.clone(), known });
    }
    Ok(notes)
}

/// The scene seen as the keypoints' picture was: the fitted camera, the picture's size,
/// and the picture itself behind the figures where it lies beside the keypoint file.
fn frame_the_fit(
    doc: &mut SceneDoc,
    camera: marionette_formats::stage::CameraDoc,
    size: (u32, u32),
    file: &std::path::Path,
) {
    doc.camera = Some(camera);
    (doc.shot.width, doc.shot.height) = size;
    if let Some(path) = crate::fit::picture_beside(file) {
        doc.stage.background = marionette_formats::stage::BackgroundDoc::Image { path, fill: false };
    }
}

/// `--fit-sequence`: the clip fitted to the keypoint files on the first humanoid, its first
/// frame on the floor, and the scene seen by the first frame's camera.
fn fit_clip(
    doc: &mut SceneDoc,
    spec: &crate::fit::SequenceSpec,
    library: &mut AssetLibrary,
) -> Result<String, OptionsError> {
    for k in 0..doc.characters.len() {
        let c = &doc.characters[k];
        let Ok(asset) = library.shaped(c) else { continue };
        let map = crate::retarget::humanoid_map(&asset, &c.humanoid);
        let placement = c.placement.to_mat4();
        let mut fitted = match crate::fit::fit_sequence(&asset, &map, placement, crate::fit::is_smpl(&c.source), spec) {
            Err(crate::fit::FitError::NoHumanoid) => continue,
            fitted => fitted?,
        };
        let skeleton = &asset.skeleton;
        let (root, pose) = fitted.clip.pose_at(skeleton, 0.0, &skeleton.initial_pose());
        let first = placement * Mat4::from_translation(root - skeleton.joint(0).rest_offset);
        let lift = (crate::posing::stood_on_floor(&asset, &pose, first) * first.inverse()).w_axis.truncate();
        fitted.camera.focus += lift;
        let note = format!("{}: {}", c.name, fitted.describe());
        let c = &mut doc.characters[k];
        c.placement = marionette_formats::scene::PlacementDoc::from_mat4(Mat4::from_translation(lift) * placement);
        c.anim = Some(AnimDoc { keys: Some(fitted.clip), ..AnimDoc::default() });
        c.playback = None;
        c.smpl.iter_mut().for_each(|s| (s.clip, s.blend_clip) = (None, None));
        let first_file = crate::fit::frame_files(&spec.frames)?.remove(0);
        frame_the_fit(doc, fitted.camera, fitted.size, &first_file);
        return Ok(note);
    }
    Err(OptionsError::NoHumanoidToFit { option: "--fit-sequence" })
}

/// A character posed by hand holds its still pose: its clips are off.
fn bake_clips(c: &mut marionette_formats::scene::CharacterDoc) {
    c.anim = None;
    if let Some(playback) = &mut c.playback {
        (playback.clip, playback.blend_clip, playback.playing) = (None, None, false);
    }
    if let Some(smpl) = &mut c.smpl {
        (smpl.clip, smpl.blend_clip, smpl.playing) = (None, None, false);
    }
}

/// A file's characters (each where its file puts it) posed by `options` as a still, as
/// `export FILE --out F.obj` writes them: every vertex and triangle, in file order.
pub fn posed_file(
    path: &std::path::Path,
    options: &PoseOptions,
) -> Result<(Vec<glam::Vec3>, Vec<[u32; 3]>), OptionsError> {
    let mut library = AssetLibrary::default();
    let mut doc = crate::scenes::file_doc(&mut library, path)?;
    let options = PoseOptions { still: true, ..options.clone() };
    apply_options(&mut doc, &options, &mut library)?;
    Ok(crate::export::scene_mesh_from(&mut library, &doc)?)
}
