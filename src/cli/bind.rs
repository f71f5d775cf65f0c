//! `marionette bind`: weights for a mesh that has none, from a skeleton's bones.

use std::path::Path;

use anyhow::Result;

use super::write_file;
use crate::formats::obj;

/// Runs `bind` with its flags.
pub fn run(a: &super::args::BindArgs) -> Result<()> {
    let method = if a.smooth { super::args::BindMethod::Smooth } else { a.method };
    bind(&a.mesh, &a.skeleton, &a.out, method.into(), a.against.as_deref())
}

pub fn bind(
    mesh_path: &Path,
    skeleton_path: &Path,
    out: &Path,
    binding: crate::rig::bind::Binding,
    against: Option<&Path>,
) -> Result<()> {
    use crate::formats::{error::open, mit6837, off};
    use crate::rig::bind::bind_to_skeleton;
    let mesh = match mesh_path.extension().and_then(|e| e.to_str()) {
        Some("off") => off::parse_off(open(mesh_path)?, mesh_path)?,
        _ => obj::parse_obj(open(mesh_path)?, mesh_path)?,
    };
    let skeleton = crate::formats::character::load_skeleton(skeleton_path)?;
    let started = std::time::Instant::now();
    let weights = bind_to_skeleton(&skeleton, &mesh.positions, &mesh.triangles, binding)
        .map_err(|e| anyhow::anyhow!("{}: {e}", mesh_path.display()))?;
    let seconds = started.elapsed().as_secs_f64();
    write_file(out, |w| mit6837::write_attach(w, &weights, skeleton.len()))?;
    println!(
        "wrote {} ({} vertices, {} joints, {binding:?} binding in {seconds:.3} s)",
        out.display(),
        mesh.positions.len(),
        skeleton.len()
    );
    if let Some(reference) = against {
        let (theirs, _) = mit6837::parse_attach(open(reference)?, reference, skeleton.len(), mesh.positions.len())?;
        let (agree, l1) = crate::rig::skinning::agreement(&weights, &theirs);
        println!(
            "against {}: heaviest joint agrees on {:.1} % of the vertices; mean L1 {l1:.3}",
            reference.display(),
            100.0 * agree
        );
    }
    Ok(())
}
