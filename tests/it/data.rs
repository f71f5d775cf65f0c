//! Tests on the real course data (`MARIONETTE_DATA`); reported as ignored when it is unset.

use std::process::Command;

use glam::{Mat4, Quat, Vec3};
use marionette::document::posing::posed_positions;
use marionette::formats::{load_character, obj};
use marionette::rig::JointRotation;

use crate::common::{assert_vec_close, data_dir, scratch};

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn all_four_6837_models_load() {
    let data = data_dir();
    for m in 1..=4 {
        let asset = load_character(&data.join(format!("mit6837/Model{m}.skel"))).unwrap();
        assert_eq!(asset.skeleton.len(), 18, "Model{m}");
        assert_eq!(asset.vertex_count(), 13336, "Model{m}");
        assert_eq!(asset.triangle_count(), 26668, "Model{m}");
        // File order is joint order (the .attach columns index it).
        let parents: Vec<Option<usize>> = (0..18).map(|j| asset.skeleton.parent(j)).collect();
        let expected =
            [-1, 0, 1, 0, 2, 4, 5, 6, 2, 8, 9, 10, 0, 12, 13, 0, 15, 16].map(|p: i32| (p >= 0).then_some(p as usize));
        assert_eq!(parents, expected.to_vec(), "Model{m}");
        assert!(asset.skin.weights.max_influences() <= 17);
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn exporting_model1_at_rest_returns_the_obj_vertices() {
    let data = data_dir();
    let skel = data.join("mit6837/Model1.skel");
    let out = scratch("export-rest").join("rest.obj");
    let status = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("export")
        .arg(&skel)
        .arg("--out")
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let source =
        obj::parse_obj(std::io::BufReader::new(std::fs::File::open(data.join("mit6837/Model1.obj")).unwrap()), &skel)
            .unwrap();
    let exported = obj::parse_obj(std::io::BufReader::new(std::fs::File::open(&out).unwrap()), &out).unwrap();
    assert_eq!(exported.positions.len(), source.positions.len());
    assert_eq!(exported.triangles, source.triangles);
    let worst = source.positions.iter().zip(&exported.positions).map(|(a, b)| a.distance(*b)).fold(0.0f32, f32::max);
    assert!(worst <= 1e-5, "largest difference {worst}");
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn export_clamps_and_rejects_unknown_joints() {
    let data = data_dir();
    let out = scratch("export-bad").join("bad.obj");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["export"])
        .arg(data.join("mit6837/Model1.skel"))
        .arg("--out")
        .arg(&out)
        .args(["--pose", "nosuchjoint=0,0,0"])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--pose: no character has a joint named or numbered `nosuchjoint`"), "{stderr}");
    assert!(!out.exists(), "a failed export writes nothing");
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn cse169_skeletons_load_with_their_joint_counts() {
    let data = data_dir();
    for (file, joints) in [("test.skel", 6), ("wasp.skel", 23), ("dragon.skel", 81)] {
        let asset = load_character(&data.join("cse169/project1").join(file)).unwrap();
        assert_eq!(asset.skeleton.len(), joints, "{file}");
        assert_eq!(asset.vertex_count(), joints * 8, "{file}: one box per joint");
    }
    for file in ["legacy/dragon.skel", "project2/wasp.skel", "project2/tube.skel"] {
        load_character(&data.join("cse169").join(file)).unwrap();
    }
    let test = load_character(&data.join("cse169/project1/test.skel")).unwrap();
    let knee = test.skeleton.find("knee_r").unwrap();
    // pose -3 1 2 with x in [-2, 0] and y, z locked at 0.
    assert_eq!(test.skeleton.joint(knee).initial_rotation, JointRotation::euler_xyz(-2.0, 0.0, 0.0));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn rotating_the_root_rigidly_rotates_every_skinned_vertex() {
    let data = data_dir();
    let asset = load_character(&data.join("mit6837/Model1.skel")).unwrap();
    let rest = posed_positions(&asset, &asset.skeleton.rest_pose(), Mat4::IDENTITY);
    let mut pose = asset.skeleton.rest_pose();
    pose[0] = JointRotation::euler_xyz(0.3, -1.1, 0.7);
    let rotated = posed_positions(&asset, &pose, Mat4::IDENTITY);
    let pivot = asset.skeleton.joint(0).rest_offset;
    let r = pose[0].to_quat();
    for (a, b) in rest.iter().zip(&rotated) {
        assert_vec_close(*b, pivot + r * (*a - pivot), 1e-5);
    }
    // And a bone box skeleton, placed in the world.
    let wasp = load_character(&data.join("cse169/project1/wasp.skel")).unwrap();
    let placement = Mat4::from_rotation_translation(Quat::from_rotation_y(0.8), Vec3::new(2.0, 0.0, -1.0));
    let at_rest = posed_positions(&wasp, &wasp.skeleton.rest_pose(), placement);
    let mut pose = wasp.skeleton.rest_pose();
    pose[0] = JointRotation::euler_xyz(0.0, 0.0, 0.5);
    let turned = posed_positions(&wasp, &pose, placement);
    let pivot = placement.transform_point3(wasp.skeleton.joint(0).rest_offset);
    let world_r = Quat::from_rotation_y(0.8) * pose[0].to_quat() * Quat::from_rotation_y(0.8).inverse();
    for (a, b) in at_rest.iter().zip(&turned) {
        assert_vec_close(*b, pivot + world_r * (*a - pivot), 1e-4);
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn info_reports_joints_vertices_and_weight_checks() {
    let data = data_dir();
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .arg("info")
        .arg(data.join("mit6837/Model2.skel"))
        .output()
        .unwrap();
    assert!(output.status.success());
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(text.contains("joints: 18"), "{text}");
    assert!(text.contains("vertices: 13336"), "{text}");
    assert!(text.contains("triangles: 26668"), "{text}");
    assert!(text.contains("influences per vertex: max"), "{text}");
}
