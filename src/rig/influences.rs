//! A skin's influences: one joint's weight on a vertex, and the vertices grouped by how many
//! influences they have (the layout the fast kernels read).

/// One joint's influence on a vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Influence {
    pub joint: u16,
    pub weight: f32,
}

/// Vertices with the same number of influences, in rows of `k` joints and weights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FixedGroup {
    /// The vertices of the group, ascending.
    pub vertices: Vec<u32>,
    /// `k` joints per vertex, heaviest first (a stable sort: among equal weights the row's
    /// order stays, so the first is also the first of the heaviest in the row).
    pub joints: Vec<u16>,
    /// `k` weights per vertex (summing to 1).
    pub weights: Vec<f32>,
}

/// Vertices per block of [`JointRuns`]: runs never cross a block, so a chunk of whole
/// blocks (as the skinning of a large mesh on several threads takes them) is a range of
/// runs.
pub const RUN_BLOCK_VERTICES: usize = 16_384;

/// The rows of one influence count `k` regrouped into runs of vertices influenced by the
/// same joints, so that a kernel loads those joints' matrices once per run rather than once
/// per vertex (an SMPL body's 6,890 rows of four make 530 runs). Within each block of
/// [`RUN_BLOCK_VERTICES`] vertices the rows are sorted by their joints.
///
/// Only [`InfluenceGroups::build`] makes one (its fields are private), so every vertex it
/// names is one of the rows it was built from: the kernels rely on it to index without a
/// check.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointRuns {
    /// Each run's `k` joints (ascending; the rest of the four unused) and one past its last
    /// row.
    runs: Vec<([u16; 4], u32)>,
    /// Each block's first run, and one past the last block's last.
    block_starts: Vec<u32>,
    /// Each row's vertex.
    vertices: Vec<u32>,
    /// Each row's `k` weights, in the order of its run's joints.
    weights: Vec<f32>,
}

impl JointRuns {
    /// Regroups the rows of `group` (`k` influences each).
    fn build(group: &FixedGroup, k: usize) -> Self {
        let mut rows: Vec<(usize, [u16; 4], [f32; 4])> = (group.vertices.iter().enumerate())
            .map(|(r, &v)| {
                let mut pairs: Vec<(u16, f32)> =
                    (0..k).map(|i| (group.joints[r * k + i], group.weights[r * k + i])).collect();
                pairs.sort_by_key(|&(j, _)| j);
                let (mut joints, mut weights) = ([0; 4], [0.0; 4]);
                for (i, (j, w)) in pairs.into_iter().enumerate() {
                    (joints[i], weights[i]) = (j, w);
                }
                (v as usize, joints, weights)
            })
            .collect();
        rows.sort_by_key(|&(v, joints, _)| (v / RUN_BLOCK_VERTICES, joints));
        let mut runs = Self::default();
        let mut block = None;
        for (v, joints, weights) in rows {
            let new_block = block != Some(v / RUN_BLOCK_VERTICES);
            if new_block || runs.runs.last().map(|r| r.0) != Some(joints) {
                if let Some(last) = runs.runs.last_mut() {
                    last.1 = runs.vertices.len() as u32;
                }
                while new_block && runs.block_starts.len() <= v / RUN_BLOCK_VERTICES {
                    runs.block_starts.push(runs.runs.len() as u32);
                }
                block = Some(v / RUN_BLOCK_VERTICES);
                runs.runs.push((joints, 0));
            }
            runs.vertices.push(v as u32);
            runs.weights.extend_from_slice(&weights[..k]);
        }
        if let Some(last) = runs.runs.last_mut() {
            last.1 = runs.vertices.len() as u32;
        }
        runs.block_starts.push(runs.runs.len() as u32);
        runs
    }

    /// The vertices and the weights (`k` each) of the rows `rows`.
    pub fn rows(&self, rows: std::ops::Range<usize>, k: usize) -> (&[u32], &[f32]) {
        (&self.vertices[rows.clone()], &self.weights[rows.start * k..rows.end * k])
    }

    /// The runs whose vertices lie in `first..first + len` (and only those: a block holds
    /// only its own vertices) and the first of their rows.
    ///
    /// # Panics
    /// When the range is not [`whole_blocks`] of a mesh of `vertex_count`.
    pub fn in_range(&self, first: usize, len: usize, vertex_count: usize) -> (&[([u16; 4], u32)], usize) {
        assert!(whole_blocks(first, len, vertex_count), "runs are taken a block at a time");
        let end = first + len;
        let blocks = self.block_starts.len() - 1;
        let bound = |vertex: usize| self.block_starts[vertex.div_ceil(RUN_BLOCK_VERTICES).min(blocks)] as usize;
        let (lo, hi) = (bound(first), bound(end));
        let first_row = if lo == 0 { 0 } else { self.runs[lo - 1].1 as usize };
        (&self.runs[lo..hi], first_row)
    }
}

/// Whether `first..first + len` starts and ends at the ends of blocks of
/// [`RUN_BLOCK_VERTICES`] or of a mesh of `vertex_count` (the runs of a block mix its
/// vertices, so only such a range is a range of runs).
pub fn whole_blocks(first: usize, len: usize, vertex_count: usize) -> bool {
    let end = first + len;
    first.is_multiple_of(RUN_BLOCK_VERTICES) && (end.is_multiple_of(RUN_BLOCK_VERTICES) || end == vertex_count)
}

/// A skin's vertices partitioned by influence count: `fixed[k - 1]` holds the vertices with
/// `k` influences (k = 1..=4), `wide` those with more (read from the compressed rows).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InfluenceGroups {
    pub fixed: [FixedGroup; 4],
    /// The rows of `fixed[k - 1]` in runs of the same joints.
    pub runs: [JointRuns; 4],
    pub wide: Vec<u32>,
    /// For each of `wide`, the joint of the first of its row's heaviest influences (the one
    /// whose hemisphere dual quaternion skinning blends in).
    pub wide_pivots: Vec<u16>,
    /// One past the largest joint any influence names (0 for no influence).
    pub joint_bound: usize,
}

impl InfluenceGroups {
    /// Partitions the rows `influences[offsets[v]..offsets[v + 1]]`.
    pub fn build(offsets: &[u32], influences: &[Influence]) -> Self {
        let mut groups = Self::default();
        for (v, w) in offsets.windows(2).enumerate() {
            let row = &influences[w[0] as usize..w[1] as usize];
            groups.joint_bound = row.iter().map(|i| i.joint as usize + 1).fold(groups.joint_bound, usize::max);
            match row.len() {
                k @ 1..=4 => {
                    let group = &mut groups.fixed[k - 1];
                    let mut sorted = [Influence { joint: 0, weight: 0.0 }; 4];
                    sorted[..k].copy_from_slice(row);
                    sorted[..k].sort_by(|a, b| b.weight.total_cmp(&a.weight));
                    group.vertices.push(v as u32);
                    group.joints.extend(sorted[..k].iter().map(|i| i.joint));
                    group.weights.extend(sorted[..k].iter().map(|i| i.weight));
                }
                _ => {
                    groups.wide.push(v as u32);
                    let heaviest = row.iter().fold(row[0], |best, &i| if i.weight > best.weight { i } else { best });
                    groups.wide_pivots.push(heaviest.joint);
                }
            }
        }
        groups.runs = std::array::from_fn(|i| JointRuns::build(&groups.fixed[i], i + 1));
        groups
    }
}
