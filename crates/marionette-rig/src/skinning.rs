//! Linear blend skinning (skeletal subspace deformation) over plain slices, flat normals
//! and weight colours. No allocation per call: callers own every buffer.

use std::sync::Arc;

use glam::{Mat4, Vec3, Vec3A};

use super::RigError;
pub use super::influences::Influence;
use super::influences::InfluenceGroups;

/// How a character's vertices follow its joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize)]
pub enum SkinningMethod {
    /// Linear blend skinning: the weighted sum of the palette matrices.
    #[default]
    Linear,
    /// Dual quaternion skinning: the normalised weighted sum of unit dual quaternions.
    DualQuaternion,
}

impl SkinningMethod {
    pub fn is_linear(&self) -> bool {
        *self == SkinningMethod::Linear
    }
}

/// Sparse per-vertex influences, stored compressed: the influences of vertex `v` are
/// `influences[offsets[v]..offsets[v + 1]]`. Any number per vertex. Never changed once
/// built, so a clone shares them: the characters of one model (a crowd of SMPL bodies of
/// different shapes) skin from one copy in the cache.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SkinWeights {
    offsets: Arc<[u32]>,
    influences: Arc<[Influence]>,
    /// The same rows partitioned by influence count, for the fast kernel.
    groups: Arc<InfluenceGroups>,
}

/// A vertex whose weights did not sum to 1 and were normalised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalisedRow {
    pub vertex: usize,
    /// The row's sum before normalising (f64: f32 weights may sum past f32::MAX).
    pub sum: f64,
}

/// Rows whose sum differs from 1 by more than this are reported when normalised.
pub const WEIGHT_SUM_TOLERANCE: f32 = 1e-3;

impl SkinWeights {
    /// Builds from one list of (joint, weight) per vertex. Zero weights are dropped; rows
    /// are normalised to sum to 1 and those off by more than [`WEIGHT_SUM_TOLERANCE`]
    /// are returned. A row with no positive weight, a negative weight or a joint out of
    /// range is an error.
    pub fn from_rows<I, R>(rows: I, joint_count: usize) -> Result<(Self, Vec<NormalisedRow>), RigError>
    where
        I: IntoIterator<Item = R>,
        R: IntoIterator<Item = (usize, f32)>,
    {
        let (mut offsets, mut influences) = (vec![0], Vec::new());
        let mut normalised = Vec::new();
        for (vertex, row) in rows.into_iter().enumerate() {
            let start = influences.len();
            for (joint, weight) in row {
                if joint >= joint_count {
                    return Err(RigError::InfluenceJointOutOfRange { vertex, joint, count: joint_count });
                }
                if !weight.is_finite() || weight < 0.0 {
                    return Err(RigError::BadWeight { vertex, joint, weight });
                }
                if weight > 0.0 {
                    influences.push(Influence { joint: joint as u16, weight });
                }
            }
            let row = &mut influences[start..];
            // Summed in f64: finite f32 weights never overflow it (3e38 + 3e38 does in f32).
            let sum: f64 = row.iter().map(|i| f64::from(i.weight)).sum();
            if sum <= 0.0 {
                return Err(RigError::NoInfluence { vertex });
            }
            if (sum - 1.0).abs() > f64::from(WEIGHT_SUM_TOLERANCE) {
                normalised.push(NormalisedRow { vertex, sum });
            }
            row.iter_mut().for_each(|i| i.weight = (f64::from(i.weight) / sum) as f32);
            if influences.len() > u32::MAX as usize {
                return Err(RigError::TooManyInfluences);
            }
            offsets.push(influences.len() as u32);
        }
        Ok((Self::of_rows(offsets, influences), normalised))
    }

    /// The rows `influences[offsets[v]..offsets[v + 1]]`, and their groups.
    fn of_rows(offsets: Vec<u32>, influences: Vec<Influence>) -> Self {
        let groups = Arc::new(InfluenceGroups::build(&offsets, &influences));
        Self { offsets: offsets.into(), influences: influences.into(), groups }
    }

    /// The same rows in memory of their own (a clone shares them): for timing a kernel
    /// without warming the caches for the characters that share these.
    pub fn unshared(&self) -> Self {
        Self::of_rows(self.offsets.to_vec(), self.influences.to_vec())
    }

    /// Every vertex bound rigidly to one joint.
    pub fn rigid(joint_of_vertex: &[u16]) -> Self {
        let offsets: Vec<u32> = (0..=joint_of_vertex.len() as u32).collect();
        let influences: Vec<Influence> =
            joint_of_vertex.iter().map(|&joint| Influence { joint, weight: 1.0 }).collect();
        Self::of_rows(offsets, influences)
    }

    /// Where each vertex's row starts in [`influences`](Self::influences) (one more entry
    /// than vertices: the last is the end).
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// Every vertex's influences, row after row.
    pub fn influences(&self) -> &[Influence] {
        &self.influences
    }

    /// The rows partitioned by influence count (see [`super::lbs`]).
    pub fn groups(&self) -> &InfluenceGroups {
        &self.groups
    }

    pub fn vertex_count(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn of_vertex(&self, v: usize) -> &[Influence] {
        &self.influences[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }

    /// Largest number of influences on one vertex.
    pub fn max_influences(&self) -> usize {
        self.offsets.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0)
    }

    pub fn total_influences(&self) -> usize {
        self.influences.len()
    }

    /// The weight of `joint` on vertex `v` (0 when it has none).
    pub fn weight(&self, v: usize, joint: usize) -> f32 {
        self.of_vertex(v).iter().filter(|i| i.joint as usize == joint).map(|i| i.weight).sum()
    }
}

/// How two bindings of the same mesh agree: the share of vertices whose heaviest joint is
/// the same (0–1), and the mean over vertices of the L1 distance of their rows (0–2).
/// Vertices beyond the shorter binding are not counted.
pub fn agreement(ours: &SkinWeights, theirs: &SkinWeights) -> (f64, f64) {
    let n = ours.vertex_count().min(theirs.vertex_count());
    if n == 0 {
        return (1.0, 0.0);
    }
    let heaviest =
        |w: &SkinWeights, v: usize| w.of_vertex(v).iter().max_by(|a, b| a.weight.total_cmp(&b.weight)).map(|i| i.joint);
    let agreeing = (0..n).filter(|&v| heaviest(ours, v) == heaviest(theirs, v)).count();
    let l1: f64 = (0..n)
        .map(|v| {
            let joints = ours.of_vertex(v).iter().chain(theirs.of_vertex(v)).map(|i| i.joint as usize);
            let mut joints: Vec<usize> = joints.collect();
            joints.sort_unstable();
            joints.dedup();
            joints.iter().map(|&j| f64::from((ours.weight(v, j) - theirs.weight(v, j)).abs())).sum::<f64>()
        })
        .sum();
    (agreeing as f64 / n as f64, l1 / n as f64)
}

/// Skins bind-pose vertices: `out[v] = Σ w · palette[j] · bind[v]` over v's influences.
/// The plain loop, kept as the oracle of the fast kernel [`super::lbs::skin`].
///
/// `bind_positions` are in the bind (model) space, `palette[j]` is
/// `current_joint_to_world · bind_world_to_joint`, `out` is in world space.
///
/// # Panics
/// When the lengths of `bind_positions`, `weights` and `out` differ, or an influence names
/// a joint beyond the palette.
pub fn skin_positions(bind_positions: &[Vec3], weights: &SkinWeights, palette: &[Mat4], out: &mut [Vec3]) {
    assert_eq!(bind_positions.len(), weights.vertex_count(), "one weight row per vertex");
    assert_eq!(out.len(), bind_positions.len(), "one output per vertex");
    let offsets = &weights.offsets;
    for (v, (p, o)) in bind_positions.iter().zip(out.iter_mut()).enumerate() {
        let row = &weights.influences[offsets[v] as usize..offsets[v + 1] as usize];
        let mut acc = Vec3::ZERO;
        for inf in row {
            acc += inf.weight * palette[inf.joint as usize].transform_point3(*p);
        }
        *o = acc;
    }
}

/// Normals skinned with the positions: the bind pose's, and where the skinned ones go
/// (`out[v] = (Σ wᵢ · palette[jᵢ])₃ₓ₃ · bind[v]`, as ozz's `SkinningJob` does, not
/// normalised; for palettes that scale unevenly, the caller passes the inverse transposes'
/// palette for normals, as ozz asks).
pub struct Normals<'a> {
    pub bind: &'a [Vec3],
    pub out: &'a mut [Vec3],
}

/// [`skin_positions`] with normals, the plain loop: each normal turned by each influence's
/// matrix (its 3×3 part) and the results blended with the weights (not normalised). The
/// oracle of [`lbs::skin_with_normals`](super::lbs::skin_with_normals).
///
/// # Panics
/// As [`skin_positions`], or when the normals' lengths differ from the positions'.
pub fn skin_positions_and_normals(
    bind_positions: &[Vec3],
    weights: &SkinWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
    normals: Normals,
) {
    skin_positions(bind_positions, weights, palette, out);
    assert!(normals.bind.len() == out.len() && normals.out.len() == out.len(), "one normal per vertex");
    let offsets = &weights.offsets;
    for (v, (n, o)) in normals.bind.iter().zip(normals.out.iter_mut()).enumerate() {
        let row = &weights.influences[offsets[v] as usize..offsets[v + 1] as usize];
        *o = row.iter().map(|inf| inf.weight * palette[inf.joint as usize].transform_vector3(*n)).sum();
    }
}

/// The axis-aligned box `(min, max)` around `points` (both zero for none).
pub fn bounds(points: &[Vec3]) -> (Vec3, Vec3) {
    bounds_of(points.iter().copied())
}

/// [`bounds`] of points as they come (none stored).
fn bounds_of(points: impl Iterator<Item = Vec3>) -> (Vec3, Vec3) {
    points.map(Vec3A::from).fold(Bounds::EMPTY, Bounds::with).pair()
}

/// A box grown point by point in 16-byte lanes: one SIMD min and max per point (the
/// crowd's skin phase spent half its kernel's time in `Vec3`'s lane-by-lane min and max).
#[derive(Debug, Clone, Copy)]
pub struct Bounds {
    lo: Vec3A,
    hi: Vec3A,
}

impl Bounds {
    /// The box around no point.
    pub const EMPTY: Self = Self { lo: Vec3A::splat(f32::INFINITY), hi: Vec3A::splat(f32::NEG_INFINITY) };

    /// The box between two corners (the empty box when `lo` exceeds `hi`).
    pub fn between(lo: Vec3A, hi: Vec3A) -> Self {
        Self { lo, hi }
    }

    /// This box grown to hold `p`.
    #[inline]
    pub fn with(self, p: Vec3A) -> Self {
        Self { lo: self.lo.min(p), hi: self.hi.max(p) }
    }

    /// The box around both.
    pub fn union(self, other: Self) -> Self {
        Self { lo: self.lo.min(other.lo), hi: self.hi.max(other.hi) }
    }

    /// `(min, max)`, both zero for the empty box.
    pub fn pair(self) -> (Vec3, Vec3) {
        if self.lo.x > self.hi.x { (Vec3::ZERO, Vec3::ZERO) } else { (self.lo.into(), self.hi.into()) }
    }
}

/// For each joint, the box of the bind positions of the vertices it influences (an empty
/// box, min above max, for a joint that influences none).
pub fn influence_boxes(bind_positions: &[Vec3], weights: &SkinWeights, joint_count: usize) -> Vec<(Vec3, Vec3)> {
    let mut boxes = vec![(Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)); joint_count];
    for (v, &p) in bind_positions.iter().enumerate() {
        for inf in weights.of_vertex(v) {
            let (lo, hi) = &mut boxes[inf.joint as usize];
            (*lo, *hi) = (lo.min(p), hi.max(p));
        }
    }
    boxes
}

/// A box that holds every linear-blend-skinned vertex without skinning one: a skinned
/// vertex is a weighted mean of `palette[j] · p` over its joints j, and each of those
/// lies in joint j's influence box moved by `palette[j]`, so the union of the moved boxes
/// holds it. (Both zero when no joint influences a vertex.)
pub fn influence_hull_bounds(boxes: &[(Vec3, Vec3)], palette: &[Mat4]) -> (Vec3, Vec3) {
    let corners = boxes.iter().zip(palette).filter(|((lo, hi), _)| lo.x <= hi.x).flat_map(|(&(lo, hi), m)| {
        (0..8).map(move |k| {
            let pick = |bit: usize, a: f32, b: f32| if k & bit == 0 { a } else { b };
            m.transform_point3(Vec3::new(pick(1, lo.x, hi.x), pick(2, lo.y, hi.y), pick(4, lo.z, hi.z)))
        })
    });
    bounds_of(corners)
}

/// Unshares the vertices of every triangle and gives each the triangle's unit normal:
/// `out_positions[3t + k] = positions[triangles[t][k]]`, `out_normals[3t + k]` = the
/// normal of t (counter-clockwise front; +y for a degenerate triangle, so no NaN
/// reaches the GPU).
///
/// # Panics
/// When the outputs are not 3 entries per triangle or an index is out of range.
pub fn flat_shade(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    out_positions: &mut [[f32; 3]],
    out_normals: &mut [[f32; 3]],
) {
    assert_eq!(out_positions.len(), triangles.len() * 3);
    assert_eq!(out_normals.len(), triangles.len() * 3);
    let corners = out_positions.chunks_exact_mut(3).zip(out_normals.chunks_exact_mut(3));
    for (tri, (p, n)) in triangles.iter().zip(corners) {
        let [a, b, c] = tri.map(|i| Vec3A::from(positions[i as usize]));
        let normal = (b - a).cross(c - a).normalize_or(Vec3A::Y).to_array();
        p.copy_from_slice(&[a.to_array(), b.to_array(), c.to_array()]);
        n.fill(normal);
    }
}

/// A distinct colour per joint: hues spaced by the golden angle, saturated, bright.
pub fn joint_colors(joint_count: usize) -> Vec<[f32; 3]> {
    (0..joint_count).map(|j| hsv_to_rgb((j as f32 * 0.618_034).fract(), 0.75, 0.95)).collect()
}

/// Each vertex's colour is the weight-blended colour of its joints.
pub fn weight_colors(weights: &SkinWeights, colors: &[[f32; 3]], out: &mut [[f32; 3]]) {
    assert_eq!(out.len(), weights.vertex_count());
    for (v, o) in out.iter_mut().enumerate() {
        let mut c = Vec3::ZERO;
        for inf in weights.of_vertex(v) {
            c += inf.weight * Vec3::from(colors[inf.joint as usize]);
        }
        *o = c.to_array();
    }
}

/// A heat map of one joint's weights: blue (0) through green to red (1).
pub fn heat_colors(weights: &SkinWeights, joint: usize, out: &mut [[f32; 3]]) {
    assert_eq!(out.len(), weights.vertex_count());
    for (v, o) in out.iter_mut().enumerate() {
        let w = weights.weight(v, joint).clamp(0.0, 1.0);
        *o = hsv_to_rgb((1.0 - w) * 0.66, 0.85, 0.95);
    }
}

/// HSV (all in [0, 1]) to linear-ish RGB.
pub fn hsv_to_rgb(h: f32, s: f32, v: f32) -> [f32; 3] {
    let h6 = (h.rem_euclid(1.0)) * 6.0;
    let c = v * s;
    let x = c * (1.0 - ((h6 % 2.0) - 1.0).abs());
    let (r, g, b) = match h6 as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r + m, g + m, b + m]
}
