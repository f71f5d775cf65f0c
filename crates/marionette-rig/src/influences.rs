//! A skin's influences: one joint's weight on a vertex, and the layouts the fast kernels
//! read: the vertices grouped by how many influences they have (the portable paths), in
//! blocks of eight consecutive ones with the joints they name (the AVX2 kernels, linear
//! blend and dual quaternions), and in blocks of sixteen (the AVX-512 linear blend ones).

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

/// A skin's vertices partitioned by influence count: `fixed[k - 1]` holds the vertices with
/// `k` influences (k = 1..=4), `wide` those with more (read from the compressed rows).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InfluenceGroups {
    pub fixed: [FixedGroup; 4],
    pub wide: Vec<u32>,
    /// One past the largest joint any influence names (0 for no influence).
    pub joint_bound: usize,
    /// The same vertices in blocks of [`LANES`] consecutive ones.
    pub blocks: LaneBlocks,
    /// And in blocks of [`WIDE_LANES`].
    pub wide_blocks: WideLaneBlocks,
}

/// How many vertices a block skins side by side (one per lane of a 256-bit register).
pub const LANES: usize = 8;

/// Eight weights, one per lane, aligned for one 256-bit load.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub struct LaneWeights(pub [f32; LANES]);

/// The vertices in blocks of [`LANES`] consecutive ones (block `b`: vertices `8b..8b + 8`)
/// with the joints their influences name between them ([`JointBlocks`]), and what the dual
/// quaternion kernel needs besides: a kernel transforms all eight by each of the block's
/// joints at once (the joint's matrix read once for eight vertices), reading and writing
/// the block's positions in order. Neighbouring vertices of a mesh share most of their
/// joints (SMPL's 6,890 vertices of four influences: 862 blocks of 6.9 joints). Sorting
/// vertices by their joints makes blocks of fewer (4.7), but reads and writes them out of
/// order, which in a crowd's cold cache cost more than it saved.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LaneBlocks {
    /// Each block's joints and their weights on its lanes.
    pub joints: JointBlocks<LaneWeights>,
    /// Each vertex's pivot: the joint of the first of its row's heaviest influences, in
    /// whose hemisphere dual quaternion skinning blends (0 for a vertex with none).
    pub pivots: Vec<u16>,
    /// The first [`PIVOT_ROWS`] distinct pivots, in order of first use: the rows of the dual
    /// quaternion kernel's table of hemispheres (SMPL has 24 pivots).
    pub pivot_rows: Vec<u16>,
    /// Each vertex's pivot's index in `pivot_rows` (0 where it has none there).
    pub lane_rows: Vec<u8>,
    /// For each block, how its lanes find their pivots.
    pub block_pivots: Vec<BlockPivots>,
}

/// The most pivots the dual quaternion kernel's table of hemispheres holds (one bit each).
pub const PIVOT_ROWS: usize = 32;

/// How a block's lanes find their pivots' hemispheres (dual quaternion skinning).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlockPivots {
    /// All eight share the pivot of this row of `pivot_rows` (SMPL: 474 of 862 blocks).
    Shared(u8),
    /// Each lane's pivot has its row.
    Rows,
    /// Some lane's pivot has none (a skin of more than [`PIVOT_ROWS`] pivots), or the block
    /// is the mesh's last and partial.
    Lanes,
}

impl LaneBlocks {
    /// Blocks the rows `influences[offsets[v]..offsets[v + 1]]`.
    pub fn build(offsets: &[u32], influences: &[Influence]) -> Self {
        let vertex_count = offsets.len().saturating_sub(1);
        let row = |v: usize| &influences[offsets[v] as usize..offsets[v + 1] as usize];
        let mut blocks = Self { joints: JointBlocks::build::<LANES>(offsets, influences), ..Self::default() };
        blocks.pivots = (0..vertex_count).map(|v| pivot(row(v))).collect();
        let lane_rows: Vec<Option<u8>> = blocks.pivots.iter().map(|&p| row_of(&mut blocks.pivot_rows, p)).collect();
        blocks.block_pivots = lane_rows.chunks(LANES).map(block_pivots).collect();
        blocks.lane_rows = lane_rows.into_iter().map(|r| r.unwrap_or(0)).collect();
        blocks
    }
}

/// How many vertices a wide block skins side by side (one per lane of a 512-bit register).
pub const WIDE_LANES: usize = 16;

/// Sixteen weights, one per lane, aligned for one 512-bit load.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(64))]
pub struct WideLaneWeights(pub [f32; WIDE_LANES]);

impl From<[f32; LANES]> for LaneWeights {
    fn from(lanes: [f32; LANES]) -> Self {
        Self(lanes)
    }
}

impl From<[f32; WIDE_LANES]> for WideLaneWeights {
    fn from(lanes: [f32; WIDE_LANES]) -> Self {
        Self(lanes)
    }
}

/// The vertices in blocks of [`WIDE_LANES`] consecutive ones (block `b`: vertices
/// `16b..16b + 16`), for the AVX-512 linear blend kernels: a joint's sixteen weights cost
/// one multiply-add where two blocks of eight cost two, and two neighbouring blocks of eight
/// share most of their joints (SMPL: 431 blocks of 8.6 joints against 862 of 6.9, 37 %
/// fewer multiply-adds).
pub type WideLaneBlocks = JointBlocks<WideLaneWeights>;

/// Vertices in blocks of consecutive ones, as many as a `W` holds weights (block `b`:
/// vertices `Lb..Lb + L`), with the joints their influences name between them.
#[derive(Debug, Clone, PartialEq)]
pub struct JointBlocks<W> {
    /// Block `b`'s joints and their weights are `joint_starts[b]..joint_starts[b + 1]` of
    /// `joints` and `weights`.
    pub joint_starts: Vec<u32>,
    /// Each block's joints, ascending.
    pub joints: Vec<u16>,
    /// For each of a block's joints, its weight on each lane's vertex (0 where it has none,
    /// and in the lanes past the last vertex).
    pub weights: Vec<W>,
}

impl<W> Default for JointBlocks<W> {
    fn default() -> Self {
        Self { joint_starts: vec![0], joints: Vec::new(), weights: Vec::new() }
    }
}

impl<W> JointBlocks<W> {
    /// Blocks the rows `influences[offsets[v]..offsets[v + 1]]`, `L` vertices a block.
    pub fn build<const L: usize>(offsets: &[u32], influences: &[Influence]) -> Self
    where
        W: From<[f32; L]>,
    {
        let mut blocks = Self::default();
        let vertex_count = offsets.len().saturating_sub(1);
        let row = |v: usize| &influences[offsets[v] as usize..offsets[v + 1] as usize];
        for first in (0..vertex_count).step_by(L) {
            let lanes = first..(first + L).min(vertex_count);
            let mut joints: Vec<u16> = lanes.clone().flat_map(|v| row(v).iter().map(|i| i.joint)).collect();
            joints.sort_unstable();
            joints.dedup();
            for &joint in &joints {
                let weight_of = |lane: usize| {
                    let v = first + lane;
                    let row = if v < lanes.end { row(v) } else { &[] };
                    row.iter().filter(|i| i.joint == joint).map(|i| i.weight).sum()
                };
                blocks.weights.push(W::from(std::array::from_fn(weight_of)));
            }
            blocks.joints.extend(joints);
            blocks.joint_starts.push(blocks.joints.len() as u32);
        }
        blocks
    }

    /// Block `b`'s joints and each one's weights on its lanes.
    #[inline(always)]
    pub fn block(&self, b: usize) -> (&[u16], &[W]) {
        let joints = self.joint_starts[b] as usize..self.joint_starts[b + 1] as usize;
        (&self.joints[joints.clone()], &self.weights[joints])
    }
}

/// `pivot`'s row in `rows`, added when new and there is room.
fn row_of(rows: &mut Vec<u16>, pivot: u16) -> Option<u8> {
    let at = rows.iter().position(|&p| p == pivot).or_else(|| {
        (rows.len() < PIVOT_ROWS).then(|| {
            rows.push(pivot);
            rows.len() - 1
        })
    });
    at.map(|at| at as u8)
}

/// How a block whose lanes' pivots have the rows `lanes` finds them.
fn block_pivots(lanes: &[Option<u8>]) -> BlockPivots {
    match lanes {
        [Some(first), ..] if lanes.len() == LANES && lanes.iter().all(|&r| r == Some(*first)) => {
            BlockPivots::Shared(*first)
        }
        _ if lanes.len() == LANES && lanes.iter().all(Option::is_some) => BlockPivots::Rows,
        _ => BlockPivots::Lanes,
    }
}

/// The joint of the first of the row's heaviest influences (0 for an empty row).
pub fn pivot(row: &[Influence]) -> u16 {
    let heaviest = row.iter().reduce(|best, i| if i.weight > best.weight { i } else { best });
    heaviest.map_or(0, |i| i.joint)
}

impl InfluenceGroups {
    /// Partitions the rows `influences[offsets[v]..offsets[v + 1]]`.
    pub fn build(offsets: &[u32], influences: &[Influence]) -> Self {
        let mut groups = Self {
            blocks: LaneBlocks::build(offsets, influences),
            wide_blocks: JointBlocks::build::<WIDE_LANES>(offsets, influences),
            ..Self::default()
        };
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
                _ => groups.wide.push(v as u32),
            }
        }
        groups
    }
}
