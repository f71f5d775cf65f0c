//! The Khronos glTF sample models (`$MARIONETTE_DATA/khronos`), each posed at rest and at
//! two times of each of its animations, against the spec read on its own
//! ([`gltf_spec`](super::gltf_spec), double precision): every vertex within 5e-6 of the
//! model's size.

use glam::{DVec3, Vec3};
use marionette::document::posing::posed_gltf;
use marionette::rig::dqs::SkinningMethod;

use super::gltf_spec::SpecFile;

/// The largest distance between our vertices and the reference's, and the model's size
/// (the diagonal of its bounds at rest).
pub fn worst_against_spec(path: &std::path::Path) -> (f64, f64, usize) {
    let spec = SpecFile::read(path);
    let ours = marionette::formats::gltf_import::load_gltf(path).unwrap_or_else(|e| panic!("{e}"));
    let rest = spec.posed(None);
    let (lo, hi) = rest.iter().fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let size = (hi - lo).length();
    let mut cases: Vec<(Option<(usize, f64)>, Option<String>)> = vec![(None, None)];
    for a in 0..spec.animations().len() {
        for u in [0.3, 0.7] {
            cases.push((Some((a, u * spec.duration(a))), Some(a.to_string())));
        }
    }
    let mut worst = 0.0f64;
    for (animation, clip) in &cases {
        let expected = spec.posed(*animation);
        let time = animation.map_or(0.0, |(_, t)| t as f32);
        let (posed, _) = posed_gltf(&ours, clip.as_deref(), time, &[], SkinningMethod::Linear)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(posed.len(), expected.len(), "{}", path.display());
        let off =
            posed.iter().zip(&expected).map(|(p, q): (&Vec3, &DVec3)| (p.as_dvec3() - *q).length()).fold(0.0, f64::max);
        worst = worst.max(off);
    }
    (worst, size, cases.len())
}

#[test]
fn every_khronos_model_poses_as_the_spec_says() {
    let Some(data) = crate::common::optional_data_dir() else { return };
    let mut files: Vec<_> = std::fs::read_dir(data.join("khronos"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    files.sort();
    assert!(files.len() >= 8, "{files:?}");
    let mut failed = Vec::new();
    for path in &files {
        let (worst, size, poses) = worst_against_spec(path);
        let name = path.file_name().unwrap().to_string_lossy();
        eprintln!("{name:<24} {poses:2} poses  worst {worst:.3e}  size {size:.3}  ratio {:.2e}", worst / size);
        if worst > 5e-6 * size {
            failed.push(format!("{name}: {worst:e} of {size}"));
        }
    }
    assert!(failed.is_empty(), "{failed:?}");
}
