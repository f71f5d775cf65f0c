//! The project's own characters, made from code so they can be rebuilt
//! (`marionette gen-assets assets/`): a skeleton written here, a skin of capsules
//! (generalised cylinders) around its bones, and weights from the distance to the bones.
//! They are written in the 6.837 formats (`.skel`, `.obj`, `.attach`). No Bevy here.

use std::path::Path;

use glam::{Quat, Vec3};

use crate::{mit6837, obj};
use marionette_rig::bind::{Binding, bind_to_bones, bones};
use marionette_rig::{RawJoint, Skeleton, SkinWeights};

/// A joint of a design: name, parent name, absolute position, and the radius of the
/// capsule around the bone from its parent to it (0: no capsule).
struct Design {
    joints: &'static [(&'static str, Option<&'static str>, [f32; 3], f32)],
}

/// A wooden-puppet humanoid about 1 unit tall, standing on y = 0, facing +z, T-pose.
const PUPPET: Design = Design {
    joints: &[
        // A zero-length root above the pelvis, as in the 6.837 models: the root has no
        // weight column in `.attach`, so the pelvis carries the hips' weights.
        ("root", None, [0.0, 0.50, 0.0], 0.0),
        ("pelvis", Some("root"), [0.0, 0.50, 0.0], 0.0),
        ("spine", Some("pelvis"), [0.0, 0.62, 0.0], 0.085),
        ("chest", Some("spine"), [0.0, 0.76, 0.0], 0.095),
        ("neck", Some("chest"), [0.0, 0.82, 0.0], 0.04),
        ("head", Some("neck"), [0.0, 0.86, 0.0], 0.035),
        ("head_top", Some("head"), [0.0, 0.98, 0.01], 0.075),
        ("l_shoulder", Some("chest"), [0.11, 0.78, 0.0], 0.0),
        ("l_elbow", Some("l_shoulder"), [0.27, 0.78, 0.0], 0.038),
        ("l_wrist", Some("l_elbow"), [0.42, 0.78, 0.0], 0.032),
        ("l_hand", Some("l_wrist"), [0.49, 0.78, 0.0], 0.03),
        ("r_shoulder", Some("chest"), [-0.11, 0.78, 0.0], 0.0),
        ("r_elbow", Some("r_shoulder"), [-0.27, 0.78, 0.0], 0.038),
        ("r_wrist", Some("r_elbow"), [-0.42, 0.78, 0.0], 0.032),
        ("r_hand", Some("r_wrist"), [-0.49, 0.78, 0.0], 0.03),
        ("l_hip", Some("pelvis"), [0.065, 0.47, 0.0], 0.0),
        ("l_knee", Some("l_hip"), [0.07, 0.27, 0.0], 0.052),
        ("l_ankle", Some("l_knee"), [0.07, 0.06, 0.0], 0.042),
        ("l_toe", Some("l_ankle"), [0.075, 0.03, 0.10], 0.032),
        ("r_hip", Some("pelvis"), [-0.065, 0.47, 0.0], 0.0),
        ("r_knee", Some("r_hip"), [-0.07, 0.27, 0.0], 0.052),
        ("r_ankle", Some("r_knee"), [-0.07, 0.06, 0.0], 0.042),
        ("r_toe", Some("r_ankle"), [-0.075, 0.03, 0.10], 0.032),
    ],
};

/// A generated character in 6.837 form.
pub struct Generated {
    pub skeleton: Skeleton,
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub weights: SkinWeights,
}

/// Capsule resolution: segments around, rings per hemisphere cap, rings along the body.
const SEGMENTS: usize = 14;
const CAP_RINGS: usize = 4;
const BODY_RINGS: usize = 6;

/// Builds the puppet.
pub fn puppet() -> Generated {
    generate(&PUPPET)
}

fn generate(design: &Design) -> Generated {
    let index_of = |name: &str| design.joints.iter().position(|j| j.0 == name).expect("design parents exist");
    let raw: Vec<RawJoint> = design
        .joints
        .iter()
        .map(|&(name, parent, pos, _)| {
            let parent = parent.map(index_of);
            let offset = Vec3::from(pos) - parent.map_or(Vec3::ZERO, |p| Vec3::from(design.joints[p].2));
            RawJoint::new(name, parent, offset)
        })
        .collect();
    let skeleton = Skeleton::build(raw).expect("the design lists parents first");
    let joint_positions: Vec<Vec3> = design.joints.iter().map(|j| Vec3::from(j.2)).collect();

    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for &(_, parent, end, radius) in design.joints {
        let Some(parent) = parent else { continue };
        if radius <= 0.0 {
            continue;
        }
        let start = joint_positions[index_of(parent)];
        add_capsule(&mut positions, &mut triangles, start, Vec3::from(end), radius);
    }
    // A pelvis block across the hips.
    add_capsule(&mut positions, &mut triangles, Vec3::new(-0.045, 0.53, 0.0), Vec3::new(0.045, 0.53, 0.0), 0.075);

    let weights = bind_to_bones(&positions, &bones(&skeleton, &joint_positions), skeleton.len(), Binding::Smooth);
    Generated { skeleton, positions, triangles, weights }
}

/// Appends a closed capsule around the segment `a`–`b`: a cylinder of `radius` with
/// hemispherical caps, `SEGMENTS` around, counter-clockwise outward faces.
fn add_capsule(positions: &mut Vec<Vec3>, triangles: &mut Vec<[u32; 3]>, a: Vec3, b: Vec3, radius: f32) {
    let axis = (b - a).normalize();
    let rotation = Quat::from_rotation_arc(Vec3::Z, axis);
    let first = positions.len() as u32;
    // Rings: (distance along the axis from a, ring radius).
    let mut rings = Vec::new();
    for k in 1..=CAP_RINGS {
        let phi = std::f32::consts::FRAC_PI_2 * (1.0 - k as f32 / CAP_RINGS as f32);
        rings.push((-radius * phi.sin(), radius * phi.cos()));
    }
    let length = a.distance(b);
    for k in 1..BODY_RINGS {
        rings.push((length * k as f32 / BODY_RINGS as f32, radius));
    }
    for k in 0..CAP_RINGS {
        let phi = std::f32::consts::FRAC_PI_2 * (k as f32 / CAP_RINGS as f32);
        rings.push((length + radius * phi.sin(), radius * phi.cos()));
    }
    positions.push(a - axis * radius);
    for &(z, r) in &rings {
        for s in 0..SEGMENTS {
            let theta = std::f32::consts::TAU * s as f32 / SEGMENTS as f32;
            positions.push(a + rotation * Vec3::new(r * theta.cos(), r * theta.sin(), z));
        }
    }
    positions.push(b + axis * radius);
    let ring = |k: usize, s: usize| first + 1 + (k * SEGMENTS + s % SEGMENTS) as u32;
    let bottom = first;
    let top = positions.len() as u32 - 1;
    for s in 0..SEGMENTS {
        triangles.push([bottom, ring(0, s + 1), ring(0, s)]);
        for k in 0..rings.len() - 1 {
            triangles.push([ring(k, s), ring(k, s + 1), ring(k + 1, s + 1)]);
            triangles.push([ring(k, s), ring(k + 1, s + 1), ring(k + 1, s)]);
        }
        let last = rings.len() - 1;
        triangles.push([ring(last, s), ring(last, s + 1), top]);
    }
}

/// Writes `NAME.skel`, `NAME.obj` and `NAME.attach` into `dir`.
pub fn write_6837(generated: &Generated, dir: &Path, name: &str) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut skel = String::new();
    for j in generated.skeleton.joints() {
        let o = j.rest_offset;
        skel += &format!("{} {} {} {} {}\n", o.x, o.y, o.z, j.parent.map_or(-1, |p| p as i64), j.name);
    }
    std::fs::write(dir.join(format!("{name}.skel")), skel)?;
    let mut obj_text = Vec::new();
    obj::write_obj(&mut obj_text, &generated.positions, &generated.triangles)?;
    std::fs::write(dir.join(format!("{name}.obj")), obj_text)?;
    let mut attach = Vec::new();
    mit6837::write_attach(&mut attach, &generated.weights, generated.skeleton.len())?;
    std::fs::write(dir.join(format!("{name}.attach")), attach)?;
    Ok(())
}

/// The puppet as shipped in `assets/` (embedded in the binary), read through the same
/// 6.837 readers as any user file.
pub fn embedded_puppet() -> marionette_rig::CharacterAsset {
    use std::io::Cursor;
    const SKEL: &str = include_str!("../../../assets/puppet.skel");
    const OBJ: &str = include_str!("../../../assets/puppet.obj");
    const ATTACH: &str = include_str!("../../../assets/puppet.attach");
    let read = || -> Result<marionette_rig::CharacterAsset, crate::FormatError> {
        let skeleton = mit6837::parse_skel(Cursor::new(SKEL), Path::new("assets/puppet.skel"))?;
        let mesh = obj::parse_obj(Cursor::new(OBJ), Path::new("assets/puppet.obj"))?;
        let (weights, _) = mit6837::parse_attach(
            Cursor::new(ATTACH),
            Path::new("assets/puppet.attach"),
            skeleton.len(),
            mesh.positions.len(),
        )?;
        let skin = marionette_rig::Skin::untextured(mesh.positions, mesh.triangles, weights);
        marionette_rig::CharacterAsset::new("puppet", skeleton, skin, Vec::new())
            .map_err(|e| crate::FormatError::rig(Path::new("assets/puppet.obj"), e))
    };
    read().expect("the embedded puppet is valid (rebuild it with `marionette gen-assets assets`)")
}
