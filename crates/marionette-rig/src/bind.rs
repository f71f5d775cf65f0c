//! Skin binding from geometry: weights from each vertex's distance to the bones.

use glam::{Mat4, Vec3};

use super::skeleton::Skeleton;
use super::skinning::SkinWeights;

pub use super::bones::{Bone, bones, segment_distance};

/// Rigid binding: each vertex to the joint of the nearest bone.
pub fn nearest_bone_weights(positions: &[Vec3], bones: &[Bone]) -> SkinWeights {
    let joints: Vec<u16> = positions
        .iter()
        .map(|&p| {
            bones
                .iter()
                .min_by(|x, y| segment_distance(p, x.start, x.end).total_cmp(&segment_distance(p, y.start, y.end)))
                .map_or(0, |b| b.joint as u16)
        })
        .collect();
    SkinWeights::rigid(&joints)
}

/// Smooth binding: the nearest `max_bones` bones weigh `1 / (d² + ε)²`, bones more than
/// `falloff` times farther than the nearest are dropped, weights are summed per joint and
/// normalised. `ε` is a small fraction of the skeleton's size so a vertex on a bone does
/// not blow up.
pub fn smooth_bone_weights(
    positions: &[Vec3],
    bones: &[Bone],
    joint_count: usize,
    max_bones: usize,
    falloff: f32,
) -> SkinWeights {
    let size = bones.iter().map(|b| b.start.distance(b.end)).fold(0.0f32, f32::max).max(1e-6);
    let eps = (0.02 * size).powi(2);
    let mut distances: Vec<(f32, usize)> = Vec::with_capacity(bones.len());
    let rows: Vec<Vec<(usize, f32)>> = positions
        .iter()
        .map(|&p| {
            distances.clear();
            distances.extend(bones.iter().enumerate().map(|(i, b)| (segment_distance(p, b.start, b.end), i)));
            distances.sort_by(|a, b| a.0.total_cmp(&b.0));
            let nearest = distances.first().map_or(0.0, |d| d.0);
            // Relative to the nearest bone's (which gets 1), in f64: far vertices neither
            // underflow to 0 nor overflow; normalised rows are the same as 1 / (d² + ε)².
            let nearest_term = f64::from(nearest).powi(2) + f64::from(eps);
            let mut row: Vec<(usize, f32)> = Vec::new();
            for &(d, i) in distances.iter().take(max_bones.max(1)) {
                if d > falloff * nearest + 1e-6 && !row.is_empty() {
                    break;
                }
                let w = (nearest_term / (f64::from(d).powi(2) + f64::from(eps))).powi(2) as f32;
                match row.iter_mut().find(|(j, _)| *j == bones[i].joint) {
                    Some((_, acc)) => *acc += w,
                    None => row.push((bones[i].joint, w)),
                }
            }
            row
        })
        .collect();
    match SkinWeights::from_rows(rows, joint_count) {
        Ok((weights, _)) => weights,
        // Only a vertex at a non-finite distance gets here (the readers reject such input).
        Err(_) => nearest_bone_weights(positions, bones),
    }
}

/// The frame of a bone from `a` to `b`, as in the FABRIK/skinning exercise: centre
/// `c = (a + b) / 2`, `w` = the unit bone direction, `v` = the part of the parent bone's
/// direction perpendicular to `w` (normalised; `(0, 1, 0)` at the root or when parallel),
/// `u = v × w`; the matrix has columns `[u v w c]` (bone space → model space).
pub fn bone_frame(a: Vec3, b: Vec3, parent_direction: Option<Vec3>) -> glam::Mat4 {
    let w = (b - a).normalize_or(Vec3::Z);
    let perpendicular = |d: Vec3| {
        let v = d - d.dot(w) * w;
        (v.length_squared() > 1e-10).then(|| v.normalize())
    };
    let v = parent_direction
        .and_then(perpendicular)
        .or_else(|| perpendicular(Vec3::Y))
        .or_else(|| perpendicular(Vec3::X))
        .unwrap_or(Vec3::X);
    let u = v.cross(w);
    glam::Mat4::from_cols(u.extend(0.0), v.extend(0.0), w.extend(0.0), ((a + b) / 2.0).extend(1.0))
}

/// How a skin is bound from its skeleton's bones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Binding {
    /// Each vertex rigidly to its nearest bone.
    Nearest,
    /// The nearest few bones, falling off with distance.
    Smooth,
    /// Bone heat (Baran and Popović 2007; see [`super::heat`]): weights diffused over the
    /// mesh from the bones each vertex sees.
    Heat,
}

/// Bones blended by the smooth binding, and how much farther than the nearest a bone may be.
pub const SMOOTH_MAX_BONES: usize = 3;
pub const SMOOTH_FALLOFF: f32 = 1.6;

/// Weights for a mesh (`vertices` in model space, `triangles`) from the bones of
/// `skeleton` at its rest pose. Only heat binding uses the triangles, and only it can fail
/// (a system that cannot be factored).
pub fn bind_to_skeleton(
    skeleton: &Skeleton,
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    binding: Binding,
) -> Result<SkinWeights, super::heat::HeatError> {
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    super::fk::forward_kinematics(skeleton, &skeleton.rest_pose(), Mat4::IDENTITY, &mut world);
    let joints = super::fk::joint_positions(&world);
    match binding {
        Binding::Heat => super::heat::heat_weights(skeleton, &joints, vertices, triangles),
        _ => Ok(bind_to_bones(vertices, &bones(skeleton, &joints), skeleton.len(), binding)),
    }
}

/// Weights for `vertices` from given bones (when the joint positions are known exactly).
/// A skeleton without bones (one joint, or all joints in one place) binds every vertex to
/// the root.
pub fn bind_to_bones(vertices: &[Vec3], bones: &[Bone], joint_count: usize, binding: Binding) -> SkinWeights {
    if bones.is_empty() {
        return SkinWeights::rigid(&vec![0; vertices.len()]);
    }
    match binding {
        Binding::Nearest => nearest_bone_weights(vertices, bones),
        // Without the mesh's triangles heat has nothing to diffuse over: smooth is closest.
        Binding::Smooth | Binding::Heat => {
            smooth_bone_weights(vertices, bones, joint_count, SMOOTH_MAX_BONES, SMOOTH_FALLOFF)
        }
    }
}
