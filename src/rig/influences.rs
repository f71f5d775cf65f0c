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
        groups
    }
}
