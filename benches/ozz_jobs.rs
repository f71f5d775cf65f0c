//! The SMPL body as ozz-animation's `SkinningJob` takes it, for `benches/ozz/harness.cc`
//! (built outside the project against ozz's own `src/geometry/runtime/skinning_job.cc`):
//! one job per influence count K, the vertices of each in their own arrays (positions, K
//! joint indices, K − 1 weights: ozz's last weight is 1 − their sum), written to a file
//! with the palette and what each job must give (the plain-loop oracle's positions).

use glam::{Mat4, Vec3};
use marionette::rig::SkinWeights;

/// One of ozz's jobs: the vertices with `k` influences.
pub struct Job {
    k: usize,
    /// Which vertex of the mesh each is.
    vertices: Vec<u32>,
    positions: Vec<f32>,
    indices: Vec<u16>,
    weights: Vec<f32>,
}

/// The body split into ozz's jobs, one per influence count.
pub fn jobs(bind: &[Vec3], weights: &SkinWeights) -> Vec<Job> {
    let most = weights.max_influences();
    (1..=most)
        .map(|k| {
            let mut job =
                Job { k, vertices: Vec::new(), positions: Vec::new(), indices: Vec::new(), weights: Vec::new() };
            for (v, p) in bind.iter().enumerate() {
                let row = weights.of_vertex(v);
                if row.len() != k {
                    continue;
                }
                job.vertices.push(v as u32);
                job.positions.extend(p.to_array());
                job.indices.extend(row.iter().map(|i| i.joint));
                job.weights.extend(row[..k - 1].iter().map(|i| i.weight));
            }
            job
        })
        .filter(|job| !job.vertices.is_empty())
        .collect()
}

/// Writes the jobs and the palette for a C++ harness around ozz's own `skinning_job.cc`:
/// per job `k n`, then n·3 positions, n·k indices (u16), n·(k − 1) weights; then the
/// joint count and the palette (16 floats a matrix, column by column); then each job's
/// expected output (n·3 floats, from `want`, the oracle's positions in mesh order); all
/// little-endian.
pub fn dump(jobs: &[Job], palette: &[Mat4], want: &[Vec3], path: &std::path::Path) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    bytes.extend((jobs.len() as u32).to_le_bytes());
    for job in jobs {
        let n = job.vertices.len();
        bytes.extend((job.k as u32).to_le_bytes());
        bytes.extend((n as u32).to_le_bytes());
        job.positions.iter().for_each(|f| bytes.extend(f.to_le_bytes()));
        job.indices.iter().for_each(|i| bytes.extend(i.to_le_bytes()));
        job.weights.iter().for_each(|f| bytes.extend(f.to_le_bytes()));
    }
    bytes.extend((palette.len() as u32).to_le_bytes());
    palette.iter().flat_map(|m| m.to_cols_array()).for_each(|f| bytes.extend(f.to_le_bytes()));
    for job in jobs {
        let expected = job.vertices.iter().flat_map(|&v| want[v as usize].to_array());
        expected.for_each(|f| bytes.extend(f.to_le_bytes()));
    }
    std::fs::write(path, bytes)
}
