//! The warning a reader gives for weight rows it normalised.

use std::path::Path;

/// One warning line for a set of normalised weight rows.
pub fn normalised_warnings(path: &Path, rows: &[marionette_rig::skinning::NormalisedRow]) -> Vec<String> {
    if rows.is_empty() {
        return Vec::new();
    }
    let (lo, hi) = rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| (lo.min(r.sum), hi.max(r.sum)));
    vec![format!(
        "{}: {} weight rows did not sum to 1 (sums {}..{}; first at vertex {}) and were normalised",
        path.display(),
        rows.len(),
        sum_text(lo),
        sum_text(hi),
        rows[0].vertex
    )]
}

/// A weight sum for a message: four decimals, or scientific notation when huge.
fn sum_text(sum: f64) -> String {
    if sum.abs() < 1e6 { format!("{sum:.4}") } else { format!("{sum:.3e}") }
}
