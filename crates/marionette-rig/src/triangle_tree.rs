//! A bounding volume hierarchy over a mesh's triangles, for segment-against-mesh tests
//! (which bones a vertex can see).

use glam::Vec3;

/// Triangles per leaf.
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// A leaf: its triangles are `triangles[first..first + count]`; an inner node (count
    /// 0): its children are `first` and `first + 1` in `nodes`.
    first: u32,
    count: u32,
}

/// The triangles of a mesh in a tree of boxes.
#[derive(Debug, Clone)]
pub struct TriangleTree {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
}

impl TriangleTree {
    /// Builds the tree (median splits along the longest axis of the centres).
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let mut tris: Vec<[Vec3; 3]> = triangles
            .iter()
            .filter_map(|t| {
                Some([*positions.get(t[0] as usize)?, *positions.get(t[1] as usize)?, *positions.get(t[2] as usize)?])
            })
            .collect();
        let mut nodes = vec![Node { lo: Vec3::ZERO, hi: Vec3::ZERO, first: 0, count: 0 }];
        // (node, range of `tris`) still to split.
        let mut todo = vec![(0usize, 0usize, tris.len())];
        while let Some((node, start, end)) = todo.pop() {
            let (lo, hi) = bounds(&tris[start..end]);
            nodes[node].lo = lo;
            nodes[node].hi = hi;
            if end - start <= LEAF_SIZE {
                nodes[node].first = start as u32;
                nodes[node].count = (end - start) as u32;
                continue;
            }
            let centre = |t: &[Vec3; 3]| t[0] + t[1] + t[2];
            let (clo, chi) = tris[start..end]
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), t| (l.min(centre(t)), h.max(centre(t))));
            let extent = chi - clo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let middle = (start + end) / 2;
            tris[start..end].select_nth_unstable_by(middle - start, |a, b| centre(a)[axis].total_cmp(&centre(b)[axis]));
            let left = nodes.len();
            nodes.push(Node { lo, hi, first: 0, count: 0 });
            nodes.push(Node { lo, hi, first: 0, count: 0 });
            nodes[node].first = left as u32;
            todo.push((left, start, middle));
            todo.push((left + 1, middle, end));
        }
        Self { nodes, triangles: tris }
    }

    /// Whether the segment `a + t (b − a)` meets a triangle at some `t` in `(t0, t1)`.
    pub fn segment_hits(&self, a: Vec3, b: Vec3, t0: f32, t1: f32) -> bool {
        if self.triangles.is_empty() {
            return false;
        }
        let d = b - a;
        let inverse = d.recip();
        let mut todo = vec![0usize];
        while let Some(n) = todo.pop() {
            let node = self.nodes[n];
            if !box_meets(node.lo, node.hi, a, inverse, t0, t1) {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                if self.triangles[range].iter().any(|t| triangle_hit(a, d, t).is_some_and(|t| t > t0 && t < t1)) {
                    return true;
                }
            } else {
                todo.push(node.first as usize);
                todo.push(node.first as usize + 1);
            }
        }
        false
    }
}

/// The nearest `t ≥ 0` at which the line `origin + t·direction` crosses one of the mesh's
/// triangles (every one tried: for a mesh that moves, where a tree would be rebuilt each
/// time); triangles with an index out of range are skipped.
pub fn first_hit(positions: &[Vec3], triangles: &[[u32; 3]], origin: Vec3, direction: Vec3) -> Option<f32> {
    triangles
        .iter()
        .filter_map(|t| {
            let corner = |k: usize| positions.get(t[k] as usize).copied();
            let tri = [corner(0)?, corner(1)?, corner(2)?];
            triangle_hit(origin, direction, &tri).filter(|&t| t >= 0.0)
        })
        .min_by(f32::total_cmp)
}

fn bounds(tris: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    tris.iter().flatten().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)))
}

/// Whether the segment's part in `[t0, t1]` meets the box (slab test; `inverse` is
/// `1 / direction`, infinite along an axis the segment does not move in).
fn box_meets(lo: Vec3, hi: Vec3, a: Vec3, inverse: Vec3, t0: f32, t1: f32) -> bool {
    let (mut near, mut far) = (t0, t1);
    for k in 0..3 {
        let (s0, s1) = ((lo[k] - a[k]) * inverse[k], (hi[k] - a[k]) * inverse[k]);
        let (s0, s1) = if s0 <= s1 { (s0, s1) } else { (s1, s0) };
        // NaN (0 × ∞: the segment lies in the slab's plane) leaves the range as it is.
        if s0 > near {
            near = s0;
        }
        if s1 < far {
            far = s1;
        }
    }
    near <= far
}

/// Where the line `a + t d` crosses triangle `t` (Möller–Trumbore): its `t`.
fn triangle_hit(a: Vec3, d: Vec3, tri: &[Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (tri[1] - tri[0], tri[2] - tri[0]);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = a - tri[0];
    let u = s.dot(p) / det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some(e2.dot(q) / det)
}
