//! The SMPL exercise: loading, the exercise's known matrices, tasks and sequencing.

use std::io::Cursor;
use std::process::Command;

use glam::{Mat3, Quat, Vec3};
use marionette::cli::smpl_tasks::{
    FrameSpec, SmplPoser, exercise_beta, parse_sequence, sequence_frames, task_frames, task4_rotation,
};
use marionette::formats::smpl::{load_smpl_dir, parse_clip, parse_skin};
use marionette::rig::smpl::BlendMode;

use crate::common::{assert_vec_close, data_dir, path, scratch};

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn smpl_folder_loads_as_one_character() {
    let data = data_dir();
    let (model, warnings) = load_smpl_dir(&data.join("smpl")).unwrap();
    assert_eq!(model.skeleton.len(), 24);
    assert_eq!(model.base_positions.len(), 6890);
    assert_eq!(model.triangles.len(), 13776);
    assert_eq!(model.shape_count(), 10);
    assert_eq!(model.weights.max_influences(), 4);
    assert!(warnings.is_empty(), "{warnings:?}");
    let asset = marionette::formats::load_character(&data.join("smpl")).unwrap();
    assert_eq!(asset.skeleton.find("L_Elbow"), Some(18));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn task4_joint_matrices_match_the_exercise_to_4_decimals() {
    let data = data_dir();
    let (model, _) = load_smpl_dir(&data.join("smpl")).unwrap();
    let frames = task_frames(&model, &data.join("smpl"), 4).unwrap();
    let mut poser = SmplPoser::new(&model);
    let world = poser.joint_matrices(&frames[0]).to_vec();
    let at = |name: &str| world[model.skeleton.find(name).unwrap()];
    let close = |a: f32, b: f32| (a - b).abs() < 5e-5 + 1e-9;
    let check = |name: &str, rows: [[f32; 3]; 3], t: [f32; 3]| {
        let m = at(name);
        let r = Mat3::from_mat4(m);
        for (i, row) in rows.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                // Row i, column j.
                assert!(
                    close((r.col(j)[i] * 1e4).round() / 1e4, *v),
                    "{name} R[{i}][{j}] = {} (expected {v})",
                    r.col(j)[i]
                );
            }
        }
        for (k, &expected) in t.iter().enumerate() {
            assert!(
                close((m.w_axis[k] * 1e4).round() / 1e4, expected),
                "{name} t[{k}] = {} (expected {expected})",
                m.w_axis[k]
            );
        }
    };
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    // The exercise prints these matrices to 4 decimals: 0.7071 is its text, not a constant.
    #[allow(clippy::approx_constant)]
    let rotated = [[0.7071, 0.7071, 0.0], [-0.7071, 0.7071, 0.0], [0.0, 0.0, 1.0]];
    check("L_Collar", identity, [0.0762, 0.1916, 0.0010]);
    check("L_Shoulder", rotated, [0.1991, 0.2368, -0.0181]);
    check("L_Wrist", rotated, [0.5655, -0.1337, -0.0484]);
    assert!(task4_rotation().abs_diff_eq(Quat::from_rotation_z(-std::f32::consts::FRAC_PI_4), 1e-4));
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn task2_moves_only_elbow_weighted_vertices_by_its_weight() {
    let data = data_dir();
    let (model, _) = load_smpl_dir(&data.join("smpl")).unwrap();
    let elbow = model.skeleton.find("L_Elbow").unwrap();
    for (task, follows) in [(2, false), (3, true)] {
        let frames = task_frames(&model, &data.join("smpl"), task).unwrap();
        for frame in &frames {
            let mut poser = SmplPoser::new(&model);
            let (mut moved, mut rest) = (Vec::new(), Vec::new());
            poser.frame(frame, &mut moved);
            poser.frame(&FrameSpec { translation: None, ..frame.clone() }, &mut rest);
            for v in 0..moved.len() {
                let w: f32 = if follows {
                    // The elbow's whole subtree follows it.
                    model
                        .weights
                        .of_vertex(v)
                        .iter()
                        .filter(|i| is_in_subtree(&model.skeleton, i.joint as usize, elbow))
                        .map(|i| i.weight)
                        .sum()
                } else {
                    model.weights.weight(v, elbow)
                };
                assert_vec_close(moved[v] - rest[v], Vec3::new(0.0, 0.2 * w, 0.0), 2e-6);
            }
        }
    }
}

fn is_in_subtree(s: &marionette::rig::Skeleton, mut j: usize, root: usize) -> bool {
    loop {
        if j == root {
            return true;
        }
        match s.parent(j) {
            Some(p) => j = p,
            None => return false,
        }
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn shapes_follow_the_blendshape_formula_and_rest_skinning_returns_them() {
    let data = data_dir();
    let dir = data.join("smpl");
    let (model, _) = load_smpl_dir(&dir).unwrap();
    // β = e_3 gives exactly smpl_03.obj.
    let target = marionette::formats::obj::parse_obj(
        std::io::BufReader::new(std::fs::File::open(dir.join("smpl_03.obj")).unwrap()),
        path("smpl_03.obj"),
    )
    .unwrap();
    let mut e3 = [0.0; 10];
    e3[2] = 1.0;
    let mut shaped = Vec::new();
    model.shaped_positions(&e3, &mut shaped);
    for (a, b) in shaped.iter().zip(&target.positions) {
        assert_vec_close(*a, *b, 1e-6);
    }
    // Skinning at rest returns the shaped mesh, for each β.
    for b in 0..3 {
        let betas = exercise_beta(b);
        let frame = FrameSpec { betas, rotations: vec![Quat::IDENTITY; 24], translation: None, skinned: true };
        let mut poser = SmplPoser::new(&model);
        let mut out = Vec::new();
        poser.frame(&frame, &mut out);
        model.shaped_positions(&betas, &mut shaped);
        for (a, s) in out.iter().zip(&shaped) {
            assert_vec_close(*a, *s, 1e-5);
        }
    }
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn task5_has_480_frames_and_the_cli_writes_numbered_objs() {
    let data = data_dir();
    let dir = data.join("smpl");
    let (model, _) = load_smpl_dir(&dir).unwrap();
    let frames = task_frames(&model, &dir, 5).unwrap();
    assert_eq!(frames.len(), 480);
    assert_eq!(frames[160].betas, exercise_beta(1));
    assert_eq!(frames[0].rotations, frames[160].rotations);
    let out = scratch("smpl-task1").join("out1");
    let status = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["smpl", "--data"])
        .arg(&dir)
        .args(["--task", "1", "--out"])
        .arg(&out)
        .status()
        .unwrap();
    assert!(status.success());
    let names: Vec<String> = {
        let mut v: Vec<String> =
            std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    };
    assert_eq!(names, vec!["frame000.obj", "frame001.obj", "frame002.obj"]);
    let f1 = marionette::formats::obj::parse_obj(
        std::io::BufReader::new(std::fs::File::open(out.join("frame001.obj")).unwrap()),
        path("f"),
    )
    .unwrap();
    let mut shaped = Vec::new();
    model.shaped_positions(&exercise_beta(1), &mut shaped);
    assert_eq!(f1.positions, shaped, "the OBJ writer round-trips f32 exactly");
    assert_eq!(f1.triangles, model.triangles);
}

#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn sequences_parse_and_transitions_go_from_the_outgoing_to_the_incoming_clip() {
    let segs = parse_sequence("7516:0-99:1,8806:20-:2").unwrap();
    assert_eq!(segs.len(), 2);
    assert_eq!((segs[0].from, segs[0].to, segs[0].betas), (0, Some(99), exercise_beta(1)));
    assert_eq!((segs[1].from, segs[1].to), (20, None));
    assert!(parse_sequence("7516:9-3").unwrap_err().contains("TO is before FROM"));
    assert!(parse_sequence("7516:0-3:x").is_err());
    let data = data_dir();
    let dir = data.join("smpl");
    let (model, _) = load_smpl_dir(&dir).unwrap();
    let a = parse_clip(
        std::io::BufReader::new(std::fs::File::open(dir.join("smpl_quaternions_mosh_cmu_7516.txt")).unwrap()),
        path("a"),
        24,
    )
    .unwrap();
    let b = parse_clip(
        std::io::BufReader::new(std::fs::File::open(dir.join("smpl_quaternions_mosh_cmu_8806.txt")).unwrap()),
        path("b"),
        24,
    )
    .unwrap();
    let n = 10;
    let frames = sequence_frames(&model, &dir, &segs, n, BlendMode::Nlerp).unwrap();
    assert_eq!(frames.len(), 100 + 140 - n);
    // First transition frame (α = 0) is the outgoing clip; the N-th (α = 1) the incoming.
    let first = 100 - n;
    assert_eq!(frames[first].betas, exercise_beta(1));
    for j in 0..24 {
        assert!(frames[first].rotations[j].abs_diff_eq(a.frame(first)[j], 1e-6));
        let incoming = b.frame(20 + n - 1)[j];
        let got = frames[first + n - 1].rotations[j];
        assert!(got.abs_diff_eq(incoming, 1e-5) || got.abs_diff_eq(-incoming, 1e-5));
    }
    assert!((frames[first + n - 1].betas[0] - exercise_beta(2)[0]).abs() < 1e-6);
    // Halfway, β is halfway.
    let mid = frames[first + 4].betas[0];
    let expect = exercise_beta(1)[0] + (4.0 / 9.0) * (exercise_beta(2)[0] - exercise_beta(1)[0]);
    assert!((mid - expect).abs() < 1e-5);
}

#[test]
fn smpl_skin_rows_of_the_wrong_width_are_errors() {
    let e = parse_skin(Cursor::new("# c\n2 3 2\n0 0.5 1 0.5\n0 1\n"), path("skin.txt"), 3).unwrap_err();
    assert_eq!(e.to_string(), "skin.txt:4: expected 4 numbers (2 joint weight pairs), found 2");
    let e = parse_skin(Cursor::new("2 3 2\n0 0.5 1 0.5\n"), path("skin.txt"), 3).unwrap_err();
    assert_eq!(e.to_string(), "skin.txt:2: expected 2 vertex rows, found 1");
    let e = parse_skin(Cursor::new("1 4 1\n0 1\n"), path("skin.txt"), 3).unwrap_err();
    assert_eq!(e.to_string(), "skin.txt:1: expected 3 joints (the hierarchy's), found 4");
}

#[test]
fn smpl_clips_with_short_rows_are_errors() {
    let e = parse_clip(Cursor::new("1 2\n0 0 0 0 0 0 1\n"), path("clip.txt"), 2).unwrap_err();
    assert_eq!(e.to_string(), "clip.txt:2: expected 11 numbers (root x y z, then 2 × qx qy qz qw), found 7");
}
