//! Bone heat binding (Baran and Popović, "Automatic Rigging and Animation of 3D
//! Characters", SIGGRAPH 2007): for each joint j, the weights w_j solve
//! `(−Δ + H) w_j = H p_j` on the mesh, where Δ is the cotangent Laplacian, `H_ii = k / d_i²`
//! with d_i the distance from vertex i to its nearest bone and k the number of equally near
//! bones it can see (0 when it sees none), and `p_j[i] = 1` when one of those bones is
//! j's. The system is scaled by each vertex's area, so it is symmetric: `(L + diag(H A)) w_j
//! = diag(H A) p_j`, factored once (sparse Cholesky) and solved for every joint.
//!
//! A vertex sees a bone when the segment from it to the bone's nearest point stays inside
//! the mesh (crosses no triangle away from the vertex) and leaves the surface outward
//! (within 60° of the vertex normal). Bones are each joint's segments to its children; a
//! joint without children (a leaf, such as a 6.837 hand, whose tip the `.skel` does not
//! hold) reaches into the part of the mesh beyond it. A piece of the mesh in which no
//! vertex sees a bone (or a vertex in no triangle) takes its nearest bones instead.

use glam::{DVec3, Vec3};

use super::bones::{Bone, segment_distance};
use super::skeleton::Skeleton;
use super::skinning::SkinWeights;
use super::triangle_tree::TriangleTree;

/// Bones within this factor of the nearest one count as equally near (Pinocchio's).
const TIE: f32 = 1.0001;
/// How far a leaf's bone reaches into the part of the mesh beyond it: this fraction of the
/// farthest vertex there (a hand's bone ends about at the wrist, not the fingertips).
pub const LEAF_REACH: f32 = 0.65;
/// Weights at or below this are dropped (Pinocchio's).
const SMALLEST_WEIGHT: f64 = 1e-8;

/// Why heat binding could not run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HeatError {
    #[error("the heat system could not be factored ({0})")]
    Factor(String),
}

/// The bones heat binds to: each joint's segments to its children (zero-length ones
/// skipped), and for each leaf joint a segment into the part of the mesh beyond it.
pub fn heat_bones(skeleton: &Skeleton, joints: &[Vec3], vertices: &[Vec3]) -> Vec<Bone> {
    let mut bones = distinct(super::bones::bones(skeleton, joints));
    let size = mesh_size(vertices);
    // A sample of the vertices (at most a few thousand) and how near each is to the bones
    // known so far.
    let step = vertices.len().div_ceil(LEAF_SAMPLES).max(1);
    let sample: Vec<Vec3> = vertices.iter().step_by(step).copied().collect();
    let everywhere: Vec<(Vec3, f32)> = sample
        .iter()
        .map(|&v| (v, bones.iter().map(|b| segment_distance(v, b.start, b.end)).fold(f32::INFINITY, f32::min)))
        .collect();
    let leaves: Vec<usize> =
        (0..skeleton.len()).filter(|&j| skeleton.children(j).is_empty() && skeleton.len() > 1).collect();
    for j in leaves {
        // How far the leaf may reach when its direction is sought: as far as the bone that
        // ends at it (its parent's), or the longest that starts there.
        let s = joints[j];
        let length = |b: &Bone| b.start.distance(b.end);
        let parent = bones.iter().filter(|b| b.end.distance(s) <= 1e-6 * size).map(length).fold(0.0f32, f32::max);
        let sibling = bones.iter().filter(|b| b.start.distance(s) <= 1e-6 * size).map(length).fold(0.0f32, f32::max);
        let limit = if parent > 0.0 {
            parent
        } else if sibling > 0.0 {
            sibling
        } else {
            0.25 * size
        };
        // Only the vertices nearer to this joint than to any other count (a foot's bone is
        // not drawn to the other foot).
        let mine: Vec<(Vec3, f32)> = everywhere
            .iter()
            .copied()
            .filter(|&(v, _)| joints.iter().all(|&o| o.distance(s) <= 1e-6 * size || v.distance(s) <= v.distance(o)))
            .collect();
        if let Some(end) = leaf_tip(s, limit, &mine, &everywhere).filter(|e| e.distance(s) > 1e-6 * size) {
            bones.push(Bone { joint: j, start: joints[j], end });
        }
    }
    bones
}

/// The bones without repeats. A joint whose children sit at one point (a 6.837 back, whose
/// two thighs start at the hips) has one bone there, not one per child: a repeated bone
/// would count twice in a vertex's heat and pull it from the neighbouring bones.
fn distinct(bones: Vec<Bone>) -> Vec<Bone> {
    let mut kept: Vec<Bone> = Vec::with_capacity(bones.len());
    for bone in bones {
        if !kept.contains(&bone) {
            kept.push(bone);
        }
    }
    kept
}

/// Vertices sampled to place leaf bones.
const LEAF_SAMPLES: usize = 4096;
/// Directions tried for a leaf bone (a Fibonacci sphere).
const LEAF_DIRECTIONS: usize = 512;
/// A leaf bone points at the vertices it explains that lie at least this fraction of the
/// farthest one's distance from its joint.
const EXTREMITY: f32 = 0.9;

/// A leaf's bone end. Its direction is first the one in which a segment of length `limit`
/// from `start` brings the leaf's `region` nearest to the skeleton (the least sum over the
/// region's vertices, each with its distance to the known bones, of the nearer of that and
/// the segment): the segment that runs into the part of the mesh no other bone explains (a
/// head, a hand, a foot). It is then turned to the extremity of that part: the mean
/// direction of the vertices anywhere that the segment explains better than the known
/// bones and that lie at least [`EXTREMITY`] of the farthest one's distance (the top of a
/// head, the toes, the fingertips). The bone reaches [`LEAF_REACH`] of the way to the
/// farthest region vertex that its ray explains better than the known bones. None when it
/// explains none.
fn leaf_tip(start: Vec3, limit: f32, region: &[(Vec3, f32)], everywhere: &[(Vec3, f32)]) -> Option<Vec3> {
    let along = |v: Vec3, u: Vec3, reach: f32| {
        let d = v - start;
        let t = d.dot(u).clamp(0.0, reach);
        (d - t * u).length()
    };
    let score = |u: Vec3| -> f32 { region.iter().map(|&(v, k)| k.min(along(v, u, limit))).sum() };
    let golden = std::f32::consts::PI * (3.0 - 5.0f32.sqrt());
    let direction = (0..LEAF_DIRECTIONS)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / LEAF_DIRECTIONS as f32;
            let r = (1.0 - y * y).sqrt();
            let a = golden * i as f32;
            Vec3::new(r * a.cos(), y, r * a.sin())
        })
        .min_by(|a, b| score(*a).total_cmp(&score(*b)))?;
    let explained: Vec<Vec3> =
        everywhere.iter().filter(|&&(v, k)| along(v, direction, limit) < k).map(|&(v, _)| v - start).collect();
    let farthest = explained.iter().map(|d| d.length()).fold(0.0f32, f32::max);
    let direction = explained
        .iter()
        .filter(|d| d.length() >= EXTREMITY * farthest)
        .sum::<Vec3>()
        .try_normalize()
        .unwrap_or(direction);
    let reach = region
        .iter()
        .filter(|&&(v, k)| along(v, direction, f32::INFINITY) < k)
        .map(|&(v, _)| (v - start).dot(direction))
        .fold(0.0f32, f32::max);
    (reach > 0.0).then(|| start + direction * reach * LEAF_REACH)
}

fn mesh_size(vertices: &[Vec3]) -> f32 {
    let (lo, hi) = super::skinning::bounds(vertices);
    (hi - lo).length().max(1e-6)
}

/// What a vertex is near: its nearest bones (within [`TIE`]) and the distance to them, and
/// which of those it sees.
struct Nearest {
    distance: f32,
    /// Indices into the bones, with whether the vertex sees each.
    bones: Vec<(usize, bool)>,
}

/// Heat weights for a mesh from its skeleton at rest (joint positions `joints`, model
/// space).
pub fn heat_weights(
    skeleton: &Skeleton,
    joints: &[Vec3],
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
) -> Result<SkinWeights, HeatError> {
    let bones = heat_bones(skeleton, joints, vertices);
    if bones.is_empty() {
        return Ok(SkinWeights::rigid(&vec![0; vertices.len()]));
    }
    let n = vertices.len();
    let size = mesh_size(vertices);
    let tree = TriangleTree::new(vertices, triangles);
    let normals = vertex_normals(vertices, triangles);
    let nearest: Vec<Nearest> =
        vertices.iter().zip(&normals).map(|(&v, &normal)| near_bones(v, normal, &bones, &tree, size)).collect();

    let (laplacian, area) = cotangent_laplacian(vertices, triangles);
    // H_ii: the visible equally-near bones over the squared distance; a piece of the mesh
    // where no vertex sees a bone (or a vertex in no triangle) counts its nearest as seen.
    let mut seen: Vec<Vec<usize>> =
        nearest.iter().map(|m| m.bones.iter().filter(|b| b.1).map(|b| b.0).collect()).collect();
    for piece in pieces(n, triangles) {
        if piece.iter().all(|&i| seen[i].is_empty()) {
            for &i in &piece {
                seen[i] = nearest[i].bones.iter().map(|b| b.0).collect();
            }
        }
    }
    let heat: Vec<f64> =
        (0..n).map(|i| seen[i].len() as f64 / (1e-8 + f64::from(nearest[i].distance)).powi(2) * area[i]).collect();

    // The joints that own bones, each a column of the right-hand side.
    let mut owners: Vec<usize> = bones.iter().map(|b| b.joint).collect();
    owners.sort_unstable();
    owners.dedup();
    let column = |joint: usize| owners.binary_search(&joint).expect("an owner");
    let mut triplets: Vec<faer::sparse::Triplet<usize, usize, f64>> = laplacian;
    for (i, h) in heat.iter().enumerate() {
        // A vertex in no triangle has no row of its own: 1 keeps the matrix definite.
        let isolated = area[i] == 0.0;
        triplets.push(faer::sparse::Triplet::new(i, i, if isolated { 1.0 } else { *h }));
    }
    let matrix = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| HeatError::Factor(format!("{e:?}")))?;
    let mut rhs = faer::Mat::<f64>::zeros(n, owners.len());
    for i in 0..n {
        if area[i] == 0.0 {
            continue;
        }
        for &b in &seen[i] {
            rhs[(i, column(bones[b].joint))] = heat[i];
        }
    }
    let llt = matrix.sp_cholesky(faer::Side::Lower).map_err(|e| HeatError::Factor(format!("{e:?}")))?;
    use faer::linalg::solvers::Solve;
    let solved = llt.solve(&rhs);

    let rows: Vec<Vec<(usize, f32)>> = (0..n)
        .map(|i| {
            let mut row: Vec<(usize, f32)> = owners
                .iter()
                .enumerate()
                .filter_map(|(c, &joint)| {
                    let w = solved[(i, c)].min(1.0);
                    (w > SMALLEST_WEIGHT).then_some((joint, w as f32))
                })
                .collect();
            if row.is_empty() || area[i] == 0.0 {
                // Nothing reached it (or it is in no triangle): its nearest bones.
                row = nearest[i].bones.iter().map(|&(b, _)| (bones[b].joint, 1.0)).collect();
            }
            row
        })
        .collect();
    SkinWeights::from_rows(rows, skeleton.len())
        .map(|(weights, _)| weights)
        .map_err(|e| HeatError::Factor(e.to_string()))
}

/// A vertex's nearest bones and which it sees.
fn near_bones(v: Vec3, normal: Vec3, bones: &[Bone], tree: &TriangleTree, size: f32) -> Nearest {
    let distances: Vec<f32> = bones.iter().map(|b| segment_distance(v, b.start, b.end)).collect();
    let distance = distances.iter().copied().fold(f32::INFINITY, f32::min);
    let near = distances.iter().enumerate().filter(|&(_, &d)| d <= distance * TIE + 1e-12).map(|(b, _)| b);
    let bones = near
        .map(|b| {
            let p = project(v, bones[b].start, bones[b].end);
            (b, sees(v, p, normal, tree, size))
        })
        .collect();
    Nearest { distance, bones }
}

/// The nearest point to `p` on the segment `a`–`b`.
fn project(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-20)).clamp(0.0, 1.0);
    a + t * ab
}

/// Whether the vertex at `v` (normal `normal`) sees the bone point `p`: the segment leaves
/// the surface outward (within 60° of the normal, seen from the bone) and crosses no
/// triangle farther than a thousandth of the mesh's size from the vertex.
fn sees(v: Vec3, p: Vec3, normal: Vec3, tree: &TriangleTree, size: f32) -> bool {
    let length = v.distance(p);
    if length <= 1e-3 * size {
        return true;
    }
    if (v - p).normalize().dot(normal) <= 0.5 {
        return false;
    }
    !tree.segment_hits(v, p, 1e-3 * size / length, 1.0)
}

/// Each vertex's normal: the mean of its triangles' unit normals (zero for a vertex in
/// none).
fn vertex_normals(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        t.iter().for_each(|&i| sum[i as usize] += n);
    }
    sum.into_iter().map(Vec3::normalize_or_zero).collect()
}

/// The cotangent Laplacian's entries (`−(cot α + cot β)` off the diagonal, their sum on
/// it) and each vertex's area (twice the area of its triangles), in f64.
fn cotangent_laplacian(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
) -> (Vec<faer::sparse::Triplet<usize, usize, f64>>, Vec<f64>) {
    let mut entries = Vec::with_capacity(triangles.len() * 9);
    let mut area = vec![0.0f64; vertices.len()];
    let at = |i: u32| vertices[i as usize].as_dvec3();
    for t in triangles {
        let twice = (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0])).length();
        for k in 0..3 {
            area[t[k] as usize] += twice;
            // The corner k is opposite the edge (i, j).
            let (i, j) = (t[(k + 1) % 3], t[(k + 2) % 3]);
            let cot = cotangent(at(i) - at(t[k]), at(j) - at(t[k]));
            let (i, j) = (i as usize, j as usize);
            entries.push(faer::sparse::Triplet::new(i, j, -cot));
            entries.push(faer::sparse::Triplet::new(j, i, -cot));
            entries.push(faer::sparse::Triplet::new(i, i, cot));
            entries.push(faer::sparse::Triplet::new(j, j, cot));
        }
    }
    (entries, area)
}

/// The cotangent of the angle between `u` and `v` (Pinocchio's guard against a zero sine).
fn cotangent(u: DVec3, v: DVec3) -> f64 {
    u.dot(v) / (1e-6 + u.cross(v).length())
}

/// The mesh's pieces: vertices joined by triangles (a vertex in none is a piece alone).
fn pieces(n: usize, triangles: &[[u32; 3]]) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in triangles {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0] as usize), root(&mut parent, t[k] as usize));
            parent[a] = b;
        }
    }
    let mut groups: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
    for i in 0..n {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    groups.into_values().collect()
}
