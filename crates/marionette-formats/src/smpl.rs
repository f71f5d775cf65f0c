//! The SMPL exercise's text files (TAMU CSCE 450 A3): blendshape OBJs, hierarchy, per-shape
//! skeletons, skin weights and quaternion clips. See `rig::smpl` for the model.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use super::checks::is_normalisable;
use super::error::{FormatError, open, parse_number, read_lines};
use super::obj::parse_obj;
use marionette_rig::skinning::NormalisedRow;
use marionette_rig::smpl::{Clip, SmplModel};
use marionette_rig::{EulerOrder, RawJoint, Skeleton, SkinWeights};

/// Data lines of a file: lines that are not blank and not `#` comments, numbered.
fn data_lines(reader: impl BufRead, path: &Path) -> Result<Vec<(usize, String)>, FormatError> {
    Ok(read_lines(reader, path)?
        .into_iter()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .collect())
}

fn numbers<T: super::error::FileNumber>(line: &str, path: &Path, line_no: usize) -> Result<Vec<T>, FormatError> {
    line.split_whitespace().map(|t| parse_number(t, path, line_no)).collect()
}

/// `smpl_hierarchy.txt`: a count, then rows `index parent EULER_XYZ name`.
pub fn parse_hierarchy(reader: impl BufRead, path: &Path) -> Result<Skeleton, FormatError> {
    let lines = data_lines(reader, path)?;
    let (count_line, count) = lines
        .first()
        .ok_or_else(|| FormatError::syntax(path, 1, "expected the joint count, found the end of the file"))?;
    let count: usize = parse_number(count.trim(), path, *count_line)?;
    if count == 0 || count > marionette_rig::MAX_JOINTS {
        return Err(FormatError::syntax(
            path,
            *count_line,
            format!("expected a joint count in 1..={}, found {count}", marionette_rig::MAX_JOINTS),
        ));
    }
    let rows = &lines[1..];
    if rows.len() != count {
        let at = rows.last().map_or(*count_line, |r| r.0);
        return Err(FormatError::syntax(path, at, format!("expected {count} joint rows, found {}", rows.len())));
    }
    let mut raw = Vec::with_capacity(count);
    for (k, (n, line)) in rows.iter().enumerate() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.len() != 4 {
            return Err(FormatError::syntax(
                path,
                *n,
                format!("expected `index parent order name`, found {} fields", t.len()),
            ));
        }
        let index: usize = parse_number(t[0], path, *n)?;
        if index != k {
            return Err(FormatError::syntax(path, *n, format!("expected joint index {k}, found {index}")));
        }
        let parent: i64 = parse_number(t[1], path, *n)?;
        if parent >= k as i64 || parent < -1 || (parent == -1 && k > 0) {
            let allowed = if k == 0 { "-1 (the root)".to_string() } else { format!("0..{k}") };
            return Err(FormatError::syntax(path, *n, format!("expected a parent index in {allowed}, found {parent}")));
        }
        if t[2] != "EULER_XYZ" {
            return Err(FormatError::syntax(
                path,
                *n,
                format!("expected rotation order EULER_XYZ, found `{}`", super::error::excerpt(t[2])),
            ));
        }
        let mut joint = RawJoint::new(t[3], (parent >= 0).then_some(parent as usize), Vec3::ZERO);
        joint.initial_rotation = marionette_rig::JointRotation::Euler(Vec3::ZERO, EulerOrder::Xyz);
        raw.push(joint);
    }
    Skeleton::build(raw).map_err(|e| FormatError::rig(path, e))
}

/// `smpl_skelNN.txt`: a header `frames joints` (the frame count says 0: not trusted), then
/// one row of `joints` × (qx qy qz qw px py pz). Returns the absolute joint positions.
pub fn parse_skeleton_positions(
    reader: impl BufRead,
    path: &Path,
    joint_count: usize,
) -> Result<Vec<Vec3>, FormatError> {
    let lines = data_lines(reader, path)?;
    let (header_line, header) = lines
        .first()
        .ok_or_else(|| FormatError::syntax(path, 1, "expected `frames joints`, found the end of the file"))?;
    let h: Vec<usize> = numbers(header, path, *header_line)?;
    if h.len() != 2 || h[1] != joint_count {
        return Err(FormatError::syntax(
            path,
            *header_line,
            format!("expected `frames {joint_count}`, found `{}`", super::error::excerpt(header.trim())),
        ));
    }
    let (n, row) = lines.get(1).ok_or_else(|| {
        FormatError::syntax(path, *header_line, "expected a row of joint positions, found the end of the file")
    })?;
    let v: Vec<f32> = numbers(row, path, *n)?;
    if v.len() != 7 * joint_count {
        return Err(FormatError::syntax(
            path,
            *n,
            format!("expected {} numbers ({joint_count} × qx qy qz qw px py pz), found {}", 7 * joint_count, v.len()),
        ));
    }
    Ok(v.chunks_exact(7).map(|c| Vec3::new(c[4], c[5], c[6])).collect())
}

/// `smpl_skin.txt`: header `vertices joints influences`, then per vertex `influences`
/// pairs `joint weight` (no count prefix, whatever the file's comment says).
pub fn parse_skin(
    reader: impl BufRead,
    path: &Path,
    joint_count: usize,
) -> Result<(SkinWeights, Vec<NormalisedRow>), FormatError> {
    let lines = data_lines(reader, path)?;
    let (header_line, header) = lines.first().ok_or_else(|| {
        FormatError::syntax(path, 1, "expected `vertices joints influences`, found the end of the file")
    })?;
    let h: Vec<usize> = numbers(header, path, *header_line)?;
    if h.len() != 3 {
        return Err(FormatError::syntax(
            path,
            *header_line,
            format!("expected 3 numbers (vertices joints influences), found {}", h.len()),
        ));
    }
    let (vertices, joints, per_vertex) = (h[0], h[1], h[2]);
    if joints != joint_count {
        return Err(FormatError::syntax(
            path,
            *header_line,
            format!("expected {joint_count} joints (the hierarchy's), found {joints}"),
        ));
    }
    let rows = &lines[1..];
    if rows.len() != vertices {
        let at = rows.last().map_or(*header_line, |r| r.0);
        return Err(FormatError::syntax(path, at, format!("expected {vertices} vertex rows, found {}", rows.len())));
    }
    let mut parsed = Vec::with_capacity(vertices);
    for (n, line) in rows {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if !tokens.len().is_multiple_of(2) || tokens.len() / 2 != per_vertex {
            return Err(FormatError::syntax(
                path,
                *n,
                format!(
                    "expected {} numbers ({per_vertex} joint weight pairs), found {}",
                    2 * u128::from(per_vertex as u64),
                    tokens.len()
                ),
            ));
        }
        let mut row = Vec::with_capacity(per_vertex);
        for pair in tokens.chunks_exact(2) {
            let j: usize = parse_number(pair[0], path, *n)?;
            if j >= joint_count {
                return Err(FormatError::syntax(
                    path,
                    *n,
                    format!("expected a joint index below {joint_count}, found {j}"),
                ));
            }
            let w: f32 = parse_number(pair[1], path, *n)?;
            if w < 0.0 {
                return Err(FormatError::syntax(path, *n, format!("expected weights >= 0, found {w}")));
            }
            row.push((j, w));
        }
        if row.iter().all(|&(_, w)| w <= 0.0) {
            return Err(FormatError::syntax(path, *n, "expected at least one positive weight, found none"));
        }
        parsed.push(row);
    }
    SkinWeights::from_rows(parsed, joint_count).map_err(|e| FormatError::rig(path, e))
}

/// `smpl_quaternions_*.txt`: header `frames joints`, then per frame the root position and
/// `joints` quaternions (x y z w).
pub fn parse_clip(reader: impl BufRead, path: &Path, joint_count: usize) -> Result<Clip, FormatError> {
    let lines = data_lines(reader, path)?;
    let (header_line, header) = lines
        .first()
        .ok_or_else(|| FormatError::syntax(path, 1, "expected `frames joints`, found the end of the file"))?;
    let h: Vec<usize> = numbers(header, path, *header_line)?;
    if h.len() != 2 || h[1] != joint_count {
        return Err(FormatError::syntax(
            path,
            *header_line,
            format!("expected `frames {joint_count}`, found `{}`", super::error::excerpt(header.trim())),
        ));
    }
    let rows = &lines[1..];
    if h[0] == 0 {
        return Err(FormatError::syntax(path, *header_line, "expected at least one frame, found a frame count of 0"));
    }
    if rows.len() != h[0] {
        let at = rows.last().map_or(*header_line, |r| r.0);
        return Err(FormatError::syntax(path, at, format!("expected {} frames, found {}", h[0], rows.len())));
    }
    let width = 3 + 4 * joint_count;
    let mut clip = Clip {
        name: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
        root_positions: Vec::new(),
        rotations: Vec::new(),
        joint_count,
    };
    for (n, line) in rows {
        let v: Vec<f32> = numbers(line, path, *n)?;
        if v.len() != width {
            return Err(FormatError::syntax(
                path,
                *n,
                format!("expected {width} numbers (root x y z, then {joint_count} × qx qy qz qw), found {}", v.len()),
            ));
        }
        clip.root_positions.push(Vec3::new(v[0], v[1], v[2]));
        for (joint, q) in v[3..].chunks_exact(4).enumerate() {
            let q = Quat::from_xyzw(q[0], q[1], q[2], q[3]);
            // A zero (or overflowing) quaternion normalises to NaN.
            if !is_normalisable(q) {
                return Err(FormatError::syntax(
                    path,
                    *n,
                    format!(
                        "expected a rotation for joint {joint}, found the quaternion {q}, which cannot be normalised"
                    ),
                ));
            }
            clip.rotations.push(q.normalize());
        }
    }
    Ok(clip)
}

/// Whether a folder holds the SMPL exercise's files.
pub fn is_smpl_dir(dir: &Path) -> bool {
    dir.is_dir() && dir.join("smpl_00.obj").is_file() && dir.join("smpl_skin.txt").is_file()
}

/// The hierarchy file, under either spelling.
fn hierarchy_path(dir: &Path) -> PathBuf {
    let right = dir.join("smpl_hierarchy.txt");
    if right.is_file() { right } else { dir.join("smpl_hiearchy.txt") }
}

/// The clips in a folder (`smpl_quaternions_*.txt`), sorted by name.
pub fn clip_paths(dir: &Path) -> Vec<PathBuf> {
    let mut clips: Vec<PathBuf> = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("smpl_quaternions_") && n.ends_with(".txt"))
        })
        .collect();
    clips.sort();
    clips
}

/// Loads the model from a folder: base mesh and shape targets `smpl_00.obj`..`smpl_10.obj`
/// (targets are full meshes, stored as deltas), skeletons, hierarchy and skin.
pub fn load_smpl_dir(dir: &Path) -> Result<(SmplModel, Vec<String>), FormatError> {
    let hierarchy = hierarchy_path(dir);
    let skeleton = parse_hierarchy(open(&hierarchy)?, &hierarchy)?;
    let n = skeleton.len();
    let base_path = dir.join("smpl_00.obj");
    let base = parse_obj(open(&base_path)?, &base_path)?;
    let joints_path = dir.join("smpl_skel00.txt");
    let base_joints = parse_skeleton_positions(open(&joints_path)?, &joints_path, n)?;
    let mut vertex_deltas = Vec::new();
    let mut joint_deltas = Vec::new();
    for b in 1.. {
        let obj_path = dir.join(format!("smpl_{b:02}.obj"));
        if !obj_path.is_file() {
            break;
        }
        let target = parse_obj(open(&obj_path)?, &obj_path)?;
        if target.positions.len() != base.positions.len() {
            return Err(FormatError::other(
                &obj_path,
                format!(
                    "expected {} vertices (as smpl_00.obj), found {}",
                    base.positions.len(),
                    target.positions.len()
                ),
            ));
        }
        let skel_path = dir.join(format!("smpl_skel{b:02}.txt"));
        let joints = parse_skeleton_positions(open(&skel_path)?, &skel_path, n)?;
        vertex_deltas.push(target.positions.iter().zip(&base.positions).map(|(t, b)| *t - *b).collect());
        joint_deltas.push(joints.iter().zip(&base_joints).map(|(t, b)| *t - *b).collect());
    }
    let skin_path = dir.join("smpl_skin.txt");
    let (weights, normalised) = parse_skin(open(&skin_path)?, &skin_path, n)?;
    if weights.vertex_count() != base.positions.len() {
        return Err(FormatError::other(
            &skin_path,
            format!("expected {} weight rows (as smpl_00.obj), found {}", base.positions.len(), weights.vertex_count()),
        ));
    }
    let warnings = super::weight_warnings::normalised_warnings(&skin_path, &normalised);
    let model = SmplModel {
        skeleton,
        base_positions: base.positions,
        vertex_deltas,
        base_joints,
        joint_deltas,
        triangles: base.triangles,
        weights,
    };
    Ok((model, warnings))
}
