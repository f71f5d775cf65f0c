//! A skin's influences: one joint's weight on a vertex, and the layouts the fast kernels
//! read: the vertices grouped by how many influences they have (dual quaternions), and in
//! blocks of eight that share their joints (linear blend).

use std::ops::Range;

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
    /// For each of `wide`, the joint of the first of its row's heaviest influences (the one
    /// whose hemisphere dual quaternion skinning blends in).
    pub wide_pivots: Vec<u16>,
    /// One past the largest joint any influence names (0 for no influence).
    pub joint_bound: usize,
    /// The same vertices in blocks of [`LANES`] that share their joints.
    pub blocks: LaneBlocks,
}

/// How many vertices a block skins side by side (one per lane of a 256-bit register).
pub const LANES: usize = 8;

/// Blocks never mix vertices of different tiles of this many (so a chunk of the mesh that
/// starts and ends on tile boundaries reads only its own blocks).
pub const TILE_VERTICES: usize = 4096;

/// A block takes no more vertices once its joints would number more than this.
const BLOCK_JOINTS: usize = 8;

/// Eight weights, one per lane, aligned for one 256-bit load.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C, align(32))]
pub struct LaneWeights(pub [f32; LANES]);

/// The vertices in blocks of [`LANES`] whose influences name few joints between them: a
/// kernel blends each of a block's joints into all eight vertices at once (the joint's
/// matrix read once for eight vertices, not once for each). Within each tile of
/// [`TILE_VERTICES`], the vertices are sorted by the joints they name, so neighbours share
/// them (SMPL's 6,890 vertices of four influences: 879 blocks of 4.7 joints).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LaneBlocks {
    /// Each block's vertices; a block of fewer repeats its last vertex in the lanes left.
    pub vertices: Vec<[u32; LANES]>,
    /// Block `b`'s joints and their weights are `joint_starts[b]..joint_starts[b + 1]` of
    /// `joints` and `weights`.
    pub joint_starts: Vec<u32>,
    /// Each block's joints, ascending.
    pub joints: Vec<u16>,
    /// For each of a block's joints, its weight on each lane's vertex (0 where it has none).
    pub weights: Vec<LaneWeights>,
    /// Tile `t`'s blocks are `tile_starts[t]..tile_starts[t + 1]`.
    pub tile_starts: Vec<u32>,
}

impl LaneBlocks {
    /// Blocks the rows `influences[offsets[v]..offsets[v + 1]]`, tile by tile.
    pub fn build(offsets: &[u32], influences: &[Influence]) -> Self {
        let mut blocks = Self { joint_starts: vec![0], tile_starts: vec![0], ..Self::default() };
        let vertex_count = offsets.len().saturating_sub(1);
        let mut sorted_joints = Vec::new();
        for tile in (0..vertex_count).step_by(TILE_VERTICES) {
            let tile = tile..(tile + TILE_VERTICES).min(vertex_count);
            // Each vertex's joints, ascending and without repeats: the key its block is found by.
            sorted_joints.clear();
            let mut keys = Vec::with_capacity(tile.len());
            for v in tile.clone() {
                let start = sorted_joints.len();
                sorted_joints.extend(influences[offsets[v] as usize..offsets[v + 1] as usize].iter().map(|i| i.joint));
                sorted_joints[start..].sort_unstable();
                let mut unique = start;
                for k in start..sorted_joints.len() {
                    if unique == start || sorted_joints[unique - 1] != sorted_joints[k] {
                        sorted_joints[unique] = sorted_joints[k];
                        unique += 1;
                    }
                }
                sorted_joints.truncate(unique);
                keys.push((v as u32, start..unique));
            }
            keys.sort_by(|a, b| sorted_joints[a.1.clone()].cmp(&sorted_joints[b.1.clone()]).then(a.0.cmp(&b.0)));
            let mut block: Vec<u32> = Vec::with_capacity(LANES);
            let mut joints: Vec<u16> = Vec::with_capacity(BLOCK_JOINTS);
            for (v, key) in keys {
                let key = &sorted_joints[key];
                let new_joints = key.iter().filter(|j| !joints.contains(j)).count();
                if block.len() == LANES || (!block.is_empty() && joints.len() + new_joints > BLOCK_JOINTS) {
                    blocks.push_block(&block, &mut joints, offsets, influences);
                    block.clear();
                }
                block.push(v);
                for &j in key {
                    if !joints.contains(&j) {
                        joints.push(j);
                    }
                }
            }
            if !block.is_empty() {
                blocks.push_block(&block, &mut joints, offsets, influences);
            }
            blocks.tile_starts.push(blocks.vertices.len() as u32);
        }
        blocks
    }

    /// Appends the block of `vertices` (1 to [`LANES`]), whose influences name `joints`
    /// (emptied).
    fn push_block(&mut self, vertices: &[u32], joints: &mut Vec<u16>, offsets: &[u32], influences: &[Influence]) {
        let last = *vertices.last().expect("a block has a vertex");
        let lanes: [u32; LANES] = std::array::from_fn(|i| vertices.get(i).copied().unwrap_or(last));
        joints.sort_unstable();
        for &joint in joints.iter() {
            let weight_of = |v: u32| {
                let row = &influences[offsets[v as usize] as usize..offsets[v as usize + 1] as usize];
                row.iter().filter(|i| i.joint == joint).map(|i| i.weight).sum()
            };
            self.weights.push(LaneWeights(lanes.map(weight_of)));
        }
        self.joints.append(joints);
        self.joint_starts.push(self.joints.len() as u32);
        self.vertices.push(lanes);
    }

    /// The blocks of the tiles that hold vertices `first..first + len` (some of their
    /// vertices may lie outside).
    pub fn covering(&self, first: usize, len: usize) -> Range<usize> {
        if len == 0 {
            return 0..0;
        }
        let tiles = first / TILE_VERTICES..(first + len).div_ceil(TILE_VERTICES);
        self.tile_starts[tiles.start] as usize..self.tile_starts[tiles.end] as usize
    }
}

impl InfluenceGroups {
    /// Partitions the rows `influences[offsets[v]..offsets[v + 1]]`.
    pub fn build(offsets: &[u32], influences: &[Influence]) -> Self {
        let mut groups = Self { blocks: LaneBlocks::build(offsets, influences), ..Self::default() };
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
        groups
    }
}
