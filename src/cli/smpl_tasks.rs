//! The SMPL exercise's outputs: `frameNNN.obj` files for tasks 1–6, fast. No Bevy.
//!
//! Every frame goes through the same path as any character: shaped joints become rest
//! offsets, the matrix stack computes joint-to-world matrices, the palette is
//! `current · bind⁻¹` (bind rotations are identity, so `bind⁻¹ = T(−p_β)`), and linear
//! blend skinning moves the shaped vertices.

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};

use crate::formats::error::open;
use crate::formats::smpl::{clip_paths, parse_clip};
use crate::formats::{FormatError, write_atomically};
use crate::rig::fk::{RestOverride, forward_kinematics_with_rest};
use crate::rig::lbs::skin;
use crate::rig::smpl::{BlendMode, Clip, SmplModel, blend_rotation};
use crate::rig::{JointRotation, Skeleton};

/// β(1) and β(2) of the exercise (β(0) is all zeros).
// The exercise's printed digits, kept as printed (f32 rounds the last one).
#[allow(clippy::excessive_precision)]
pub const BETA1: [f32; 10] =
    [-1.711935, 2.352964, 2.285835, -0.073122, 1.501402, -1.790568, -0.391194, 2.078678, 1.461037, 2.297462];
#[allow(clippy::excessive_precision)]
pub const BETA2: [f32; 10] =
    [1.573618, 2.028960, -1.865066, 2.066879, 0.661796, -2.012298, -1.107509, 0.234408, 2.287534, 2.324443];

/// β(i) for i in 0..3.
pub fn exercise_beta(i: usize) -> [f32; 10] {
    match i {
        1 => BETA1,
        2 => BETA2,
        _ => [0.0; 10],
    }
}

/// Task 5's clip.
pub const TASK5_CLIP: &str = "smpl_quaternions_mosh_cmu_7516.txt";

/// How one frame is made.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSpec {
    pub betas: [f32; 10],
    /// Local rotations per joint (identity where unposed).
    pub rotations: Vec<Quat>,
    /// Added to a joint's absolute position: `(joint, delta, descendants_follow)`.
    pub translation: Option<(usize, Vec3, bool)>,
    /// Skin the mesh (task 1 shows shapes without skinning).
    pub skinned: bool,
}

/// Poses shaped SMPL bodies, caching the shape of the last β.
pub struct SmplPoser<'a> {
    pub model: &'a SmplModel,
    betas: Option<[f32; 10]>,
    shaped: Vec<Vec3>,
    joints: Vec<Vec3>,
    world: Vec<Mat4>,
    palette: Vec<Mat4>,
    pose: Vec<JointRotation>,
}

impl<'a> SmplPoser<'a> {
    pub fn new(model: &'a SmplModel) -> Self {
        let n = model.skeleton.len();
        Self {
            model,
            betas: None,
            shaped: Vec::new(),
            joints: Vec::new(),
            world: vec![Mat4::IDENTITY; n],
            palette: vec![Mat4::IDENTITY; n],
            pose: vec![JointRotation::Quat(Quat::IDENTITY); n],
        }
    }

    fn shape(&mut self, betas: &[f32; 10]) {
        if self.betas.as_ref() != Some(betas) {
            self.model.shaped_positions(betas, &mut self.shaped);
            self.joints = self.model.shaped_joints(betas);
            self.betas = Some(*betas);
        }
    }

    /// Joint-to-world matrices of a frame (model space).
    pub fn joint_matrices(&mut self, frame: &FrameSpec) -> &[Mat4] {
        self.shape(&frame.betas);
        let skeleton: &Skeleton = &self.model.skeleton;
        let mut offsets = self.model.rest_offsets(&self.joints);
        if let Some((j, delta, follow)) = frame.translation {
            offsets[j] += delta;
            if !follow {
                // An absolute translation: the children keep their absolute places.
                for &c in skeleton.children(j) {
                    offsets[c] -= delta;
                }
            }
        }
        for (p, q) in self.pose.iter_mut().zip(&frame.rotations) {
            *p = JointRotation::Quat(*q);
        }
        forward_kinematics_with_rest(
            skeleton,
            &self.pose,
            RestOverride::offsets(&offsets),
            Mat4::IDENTITY,
            &mut self.world,
        );
        &self.world
    }

    /// The frame's vertices, in source order.
    pub fn frame(&mut self, frame: &FrameSpec, out: &mut Vec<Vec3>) {
        self.joint_matrices(frame);
        out.resize(self.shaped.len(), Vec3::ZERO);
        if !frame.skinned {
            out.copy_from_slice(&self.shaped);
            return;
        }
        for ((p, w), j) in self.palette.iter_mut().zip(&self.world).zip(&self.joints) {
            *p = *w * Mat4::from_translation(-*j);
        }
        skin(&self.shaped, &self.model.weights, &self.palette, out);
    }
}

/// The frames of tasks 1–5.
pub fn task_frames(model: &SmplModel, data_dir: &Path, task: u32) -> Result<Vec<FrameSpec>, FormatError> {
    let n = model.skeleton.len();
    let joint = |name: &str| {
        model
            .skeleton
            .find(name)
            .ok_or_else(|| FormatError::other(data_dir, format!("expected a joint named {name} in the hierarchy")))
    };
    let rest = vec![Quat::IDENTITY; n];
    let spec =
        |b: usize| FrameSpec { betas: exercise_beta(b), rotations: rest.clone(), translation: None, skinned: true };
    Ok(match task {
        1 => (0..3).map(|b| FrameSpec { skinned: false, ..spec(b) }).collect(),
        2 | 3 => {
            let elbow = joint("L_Elbow")?;
            (0..3)
                .map(|b| FrameSpec { translation: Some((elbow, Vec3::new(0.0, 0.2, 0.0), task == 3)), ..spec(b) })
                .collect()
        }
        4 => {
            let shoulder = joint("L_Shoulder")?;
            (0..3)
                .map(|b| {
                    let mut s = spec(b);
                    s.rotations[shoulder] = task4_rotation();
                    s
                })
                .collect()
        }
        5 => {
            let clip_path = data_dir.join(TASK5_CLIP);
            let clip = parse_clip(open(&clip_path)?, &clip_path, n)?;
            (0..3)
                .flat_map(|b| (0..clip.frame_count()).map(move |f| (b, f)))
                .map(|(b, f)| FrameSpec { rotations: clip_frame(&model.skeleton, &clip, f), ..spec(b) })
                .collect()
        }
        _ => {
            return Err(FormatError::other(data_dir, format!("expected a task 1..=6, found {task}")));
        }
    })
}

/// Frame `f` of an SMPL clip as the motion service plays it (not stood upright).
fn clip_frame(skeleton: &Skeleton, clip: &Clip, f: usize) -> Vec<Quat> {
    use crate::document::motion::{Clock, Playing, SmplMotion, pose_at, smpl_frame_time};
    let clock = Clock { time: smpl_frame_time(f), playing: false, speed: 1.0, looping: false };
    let smpl = SmplMotion { clip, blend: None, upright: false };
    let playing = Playing { smpl: Some((smpl, clock)), ..Playing::default() };
    let still = skeleton.initial_pose();
    pose_at(skeleton, &still, &[], &playing).rotations.iter().map(JointRotation::to_quat).collect()
}

/// Task 4's shoulder rotation, (x, y, z, w) = (0, 0, −0.3827, 0.9239).
pub fn task4_rotation() -> Quat {
    Quat::from_xyzw(0.0, 0.0, -0.3827, 0.9239).normalize()
}

/// One segment of a `--sequence`: a clip's frame range played with a β.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    pub clip: String,
    pub from: usize,
    /// Inclusive; `None` plays to the clip's end.
    pub to: Option<usize>,
    pub betas: [f32; 10],
}

/// Parses `CLIP[:FROM-TO][:BETA],...` where CLIP is a clip file name or the end of one
/// (`7516` finds `smpl_quaternions_mosh_cmu_7516.txt`), FROM-TO an inclusive frame range
/// (`40-` to the end), and BETA `0`, `1`, `2` (the exercise's βs) or ten numbers joined
/// by `/`.
pub fn parse_sequence(spec: &str) -> Result<Vec<Segment>, String> {
    spec.split(',')
        .map(|seg| {
            let parts: Vec<&str> = seg.trim().split(':').collect();
            let bad = |why: &str| format!("sequence segment `{seg}`: {why} (expected CLIP[:FROM-TO][:BETA])");
            if parts.is_empty() || parts[0].is_empty() || parts.len() > 3 {
                return Err(bad("wrong number of fields"));
            }
            let (mut from, mut to) = (0, None);
            if let Some(range) = parts.get(1).filter(|r| !r.is_empty()) {
                let (a, b) = range.split_once('-').ok_or_else(|| bad("the range needs FROM-TO"))?;
                from = a.parse().map_err(|_| bad("FROM is not a frame number"))?;
                to = if b.is_empty() { None } else { Some(b.parse().map_err(|_| bad("TO is not a frame number"))?) };
                if to.is_some_and(|t| t < from) {
                    return Err(bad("TO is before FROM"));
                }
            }
            let betas = match parts.get(2) {
                None | Some(&"") => [0.0; 10],
                Some(&b) if b.len() == 1 && "012".contains(b) => exercise_beta(b.parse().unwrap_or(0)),
                Some(list) => {
                    let v: Vec<f32> = list
                        .split('/')
                        .map(|x| x.parse::<f32>().ok().filter(|b| b.is_finite()))
                        .collect::<Option<_>>()
                        .ok_or_else(|| bad("BETA is 0, 1, 2 or ten finite numbers joined by /"))?;
                    let mut b = [0.0; 10];
                    if v.len() > 10 {
                        return Err(bad("more than ten betas"));
                    }
                    b[..v.len()].copy_from_slice(&v);
                    b
                }
            };
            Ok(Segment { clip: parts[0].to_string(), from, to, betas })
        })
        .collect()
}

/// The frames of a sequence: segments one after another; consecutive segments overlap by
/// `transition` frames in which α goes from 0 (first transition frame: the outgoing
/// segment) to 1 (N-th: the incoming one); β blends linearly, rotations by `mode`.
/// Root translation is ignored, as in task 5.
pub fn sequence_frames(
    model: &SmplModel,
    data_dir: &Path,
    segments: &[Segment],
    transition: usize,
    mode: BlendMode,
) -> Result<Vec<FrameSpec>, FormatError> {
    let n = model.skeleton.len();
    let clips = clip_paths(data_dir);
    let mut loaded: Vec<(String, Clip)> = Vec::new();
    let mut plays: Vec<Vec<FrameSpec>> = Vec::new();
    for seg in segments {
        let path = find_clip(&clips, &seg.clip).ok_or_else(|| {
            FormatError::other(data_dir, format!("no clip matches `{}` (clips: {})", seg.clip, clip_names(&clips)))
        })?;
        if !loaded.iter().any(|(p, _)| *p == path.display().to_string()) {
            loaded.push((path.display().to_string(), parse_clip(open(&path)?, &path, n)?));
        }
        let clip = &loaded.iter().find(|(p, _)| *p == path.display().to_string()).expect("just loaded").1;
        let last = clip.frame_count().saturating_sub(1);
        let to = seg.to.unwrap_or(last);
        if seg.from > last || to > last {
            return Err(FormatError::other(
                &path,
                format!("expected frames within 0..={last}, found {}-{to}", seg.from),
            ));
        }
        plays.push(
            (seg.from..=to)
                .map(|f| FrameSpec {
                    betas: seg.betas,
                    rotations: clip_frame(&model.skeleton, clip, f),
                    translation: None,
                    skinned: true,
                })
                .collect(),
        );
    }
    let mut frames: Vec<FrameSpec> = Vec::new();
    for play in plays {
        let overlap = transition.min(frames.len()).min(play.len());
        let start = frames.len() - overlap;
        for k in 0..overlap {
            let alpha = if overlap <= 1 { 1.0 } else { k as f32 / (overlap - 1) as f32 };
            let out = &mut frames[start + k];
            let inc = &play[k];
            for (b, bi) in out.betas.iter_mut().zip(inc.betas) {
                *b += alpha * (bi - *b);
            }
            for (q, qi) in out.rotations.iter_mut().zip(&inc.rotations) {
                *q = blend_rotation(*q, *qi, alpha, mode);
            }
        }
        frames.extend(play.into_iter().skip(overlap));
    }
    Ok(frames)
}

fn find_clip(clips: &[PathBuf], name: &str) -> Option<PathBuf> {
    clips
        .iter()
        .find(|p| {
            p.file_name().is_some_and(|f| f == name)
                || p.file_stem().is_some_and(|s| s.to_string_lossy().ends_with(name))
        })
        .cloned()
}

fn clip_names(clips: &[PathBuf]) -> String {
    clips.iter().filter_map(|p| p.file_name()).map(|n| n.to_string_lossy().into_owned()).collect::<Vec<_>>().join(", ")
}

/// Writes `frame000.obj`, `frame001.obj`, ... into `out_dir` (created), one `v` per vertex
/// then the base mesh's faces; frames are spread over the machine's cores. `tick` is
/// called once per written frame.
pub fn write_frames(
    model: &SmplModel,
    frames: &[FrameSpec],
    out_dir: &Path,
    tick: &(dyn Fn() + Sync),
) -> Result<(), FormatError> {
    std::fs::create_dir_all(out_dir).map_err(|e| FormatError::io(out_dir, e))?;
    let faces = faces_text(&model.triangles);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(frames.len().max(1));
    let chunk = frames.len().div_ceil(threads.max(1)).max(1);
    std::thread::scope(|scope| {
        let handles: Vec<_> = frames
            .chunks(chunk)
            .enumerate()
            .map(|(c, part)| {
                let faces = &faces;
                scope.spawn(move || -> Result<(), FormatError> {
                    let mut poser = SmplPoser::new(model);
                    let mut positions = Vec::new();
                    let mut text = Vec::with_capacity(faces.len() * 2);
                    for (k, frame) in part.iter().enumerate() {
                        poser.frame(frame, &mut positions);
                        let path = out_dir.join(format!("frame{:03}.obj", c * chunk + k));
                        if let Some(v) = positions.iter().position(|p| !p.is_finite()) {
                            return Err(FormatError::other(
                                &path,
                                format!("vertex {} is not a finite point: not written", v + 1),
                            ));
                        }
                        text.clear();
                        vertices_text(&positions, &mut text);
                        text.extend_from_slice(faces);
                        write_atomically(&path, |w| w.write_all(&text)).map_err(|e| FormatError::io(&path, e))?;
                        tick();
                    }
                    Ok(())
                })
            })
            .collect();
        handles
            .into_iter()
            .try_for_each(|h| h.join().unwrap_or_else(|_| Err(FormatError::other(out_dir, "a writer thread panicked"))))
    })
}

/// `v x y z` lines (shortest round-trip decimal forms, by zmij).
fn vertices_text(positions: &[Vec3], out: &mut Vec<u8>) {
    let mut buffer = zmij::Buffer::new();
    for p in positions {
        out.extend_from_slice(b"v ");
        out.extend_from_slice(buffer.format(p.x).as_bytes());
        out.push(b' ');
        out.extend_from_slice(buffer.format(p.y).as_bytes());
        out.push(b' ');
        out.extend_from_slice(buffer.format(p.z).as_bytes());
        out.push(b'\n');
    }
}

/// The `f` lines, the same for every frame.
fn faces_text(triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut out = Vec::with_capacity(triangles.len() * 20);
    for t in triangles {
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out
}

/// The straightforward way, kept as the measuring stick for `--naive`: per frame it
/// re-derives the shaped mesh and skeleton, builds every joint matrix from scratch, skins
/// each vertex by summing weighted full matrices, and writes line by line through a
/// `BufWriter` (like a C++ `ofstream`), on one thread.
pub fn write_frames_naive(
    model: &SmplModel,
    frames: &[FrameSpec],
    out_dir: &Path,
    tick: &(dyn Fn() + Sync),
) -> Result<(), FormatError> {
    std::fs::create_dir_all(out_dir).map_err(|e| FormatError::io(out_dir, e))?;
    for (k, frame) in frames.iter().enumerate() {
        let mut shaped = Vec::new();
        model.shaped_positions(&frame.betas, &mut shaped);
        let joints = model.shaped_joints(&frame.betas);
        let pose: Vec<JointRotation> = frame.rotations.iter().map(|&q| JointRotation::Quat(q)).collect();
        let mut world = vec![Mat4::IDENTITY; joints.len()];
        let offsets = model.rest_offsets(&joints);
        forward_kinematics_with_rest(
            &model.skeleton,
            &pose,
            RestOverride::offsets(&offsets),
            Mat4::IDENTITY,
            &mut world,
        );
        let path = out_dir.join(format!("frame{k:03}.obj"));
        let mut file = std::io::BufWriter::new(std::fs::File::create(&path).map_err(|e| FormatError::io(&path, e))?);
        for (v, x) in shaped.iter().enumerate() {
            let mut m = Mat4::ZERO;
            for inf in model.weights.of_vertex(v) {
                let j = inf.joint as usize;
                m += (world[j] * Mat4::from_translation(-joints[j])) * inf.weight;
            }
            let p = m.transform_point3(*x);
            if !p.is_finite() {
                return Err(FormatError::other(&path, format!("vertex {} is not a finite point", v + 1)));
            }
            writeln!(file, "v {} {} {}", p.x, p.y, p.z).map_err(|e| FormatError::io(&path, e))?;
        }
        for t in &model.triangles {
            writeln!(file, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).map_err(|e| FormatError::io(&path, e))?;
        }
        tick();
    }
    Ok(())
}
