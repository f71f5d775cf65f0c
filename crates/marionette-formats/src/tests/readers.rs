//! Readers: valid inputs from memory, then each malformed input with its exact message.

use std::io::Cursor;

use crate::{cse169, mit6837, obj, off};
use glam::Vec3;
use marionette_rig::JointRotation;

const SKEL_6837: &str = "0.5 0.5 0.5 -1\n0 0.1 0 0\n0 0.2 0 1\n";

fn skel_err(text: &str) -> String {
    mit6837::parse_skel(Cursor::new(text), path("m.skel")).unwrap_err().to_string()
}

#[test]
fn mit6837_skel_reads_offsets_and_parents() {
    let s = mit6837::parse_skel(Cursor::new(SKEL_6837), path("m.skel")).unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(s.parent(2), Some(1));
    assert_eq!(s.joint(0).rest_offset, Vec3::splat(0.5));
    assert_eq!(s.joint(1).name, "joint1");
    let named = mit6837::parse_skel(Cursor::new("0 0 0 -1 hips\n0 1 0 0 chest\n"), path("m.skel")).unwrap();
    assert_eq!(named.find("chest"), Some(1));
}

#[test]
fn mit6837_skel_with_three_numbers_on_a_line() {
    assert_eq!(skel_err("0 0 0 -1\n1 2 3\n"), "m.skel:2: expected 4 numbers (x y z parent), found 3");
}

#[test]
fn mit6837_skel_with_a_word_for_a_number() {
    assert_eq!(skel_err("0 0 zero -1\n"), "m.skel:1: expected a number, found `zero`");
}

#[test]
fn mit6837_skel_with_a_parent_out_of_range() {
    assert_eq!(
        skel_err("0 0 0 -1\n0 0 0 5\n"),
        "m.skel:2: parent index 5 of joint 1 refers to a joint not defined before it (expected -1 or 0..1)"
    );
}

#[test]
fn mit6837_skel_with_a_joint_that_is_its_own_parent() {
    assert_eq!(
        skel_err("0 0 0 -1\n0 0 0 1\n"),
        "m.skel:2: parent index 1 of joint 1 refers to itself (expected -1 or 0..1)"
    );
}

#[test]
fn mit6837_skel_with_two_roots() {
    assert_eq!(
        skel_err("0 0 0 -1\n0 0 0 -1\n"),
        "m.skel:2: joint 1 is a second root (parent -1); expected a parent index in 0..1"
    );
}

#[test]
fn mit6837_skel_empty() {
    assert_eq!(skel_err("\n\n"), "m.skel:1: expected at least one joint line `x y z parent`, found none");
}

fn attach_err(text: &str, vertices: usize) -> String {
    mit6837::parse_attach(Cursor::new(text), path("m.attach"), 3, vertices).unwrap_err().to_string()
}

#[test]
fn mit6837_attach_reads_and_normalises() {
    let (w, normalised) = mit6837::parse_attach(Cursor::new("0.25 0.75 \n0.5 0.3\n"), path("m.attach"), 3, 2).unwrap();
    assert_eq!(w.vertex_count(), 2);
    assert_eq!(w.weight(0, 2), 0.75);
    assert_eq!(w.weight(0, 0), 0.0, "the root has no column");
    assert_eq!(normalised.len(), 1, "the second row sums to 0.8");
    assert!((w.weight(1, 1) - 0.625).abs() < 1e-6);
}

#[test]
fn mit6837_attach_with_fewer_lines_than_vertices() {
    assert_eq!(attach_err("0.5 0.5\n", 3), "m.attach:1: expected 3 weight lines (one per mesh vertex), found 1");
}

#[test]
fn mit6837_attach_with_more_lines_than_vertices() {
    assert_eq!(
        attach_err("0.5 0.5\n1 0\n", 1),
        "m.attach:2: expected 1 weight lines (one per mesh vertex), found more"
    );
}

#[test]
fn mit6837_attach_with_a_short_row() {
    assert_eq!(
        attach_err("0.5 0.5\n1\n", 2),
        "m.attach:2: expected 2 weights (one per joint except the root), found 1"
    );
}

#[test]
fn mit6837_attach_with_a_negative_weight() {
    assert_eq!(attach_err("-0.5 1.5\n", 1), "m.attach:1: expected weights >= 0, found -0.5");
}

#[test]
fn mit6837_attach_with_an_all_zero_row() {
    assert_eq!(attach_err("0 0\n", 1), "m.attach:1: expected at least one positive weight, found none");
}

#[test]
fn mit6837_attach_with_a_word() {
    assert_eq!(attach_err("0.5 half\n", 1), "m.attach:1: expected a number, found `half`");
}

const TEST_SKEL: &str = "balljoint root {\r\n\toffset 0 0 0\r\n\tboxmin -0.2 -0.3 -0.15\r\n\tpose 0 0.1 0\r\n\tballjoint knee{\r\n\t\toffset 0 -1 0\r\n\t\trotxlimit -2 0\r\n\t\tpose 5 0.5 0\r\n\t}\r\n\tballjoint other {offset 1 0 0 rotylimit 0 0 pose 0 1 0}\r\n}\r\n";

#[test]
fn cse169_skel_reads_nested_joints_with_defaults_and_clamping() {
    let s = cse169::parse_skel(Cursor::new(TEST_SKEL), path("t.skel")).unwrap();
    assert_eq!(s.len(), 3);
    assert_eq!(s.joint(1).name, "knee");
    assert_eq!(s.parent(2), Some(0));
    assert_eq!(s.joint(1).rest_offset, Vec3::new(0.0, -1.0, 0.0));
    let b = s.joint(0).bone_box.unwrap();
    assert_eq!((b.min, b.max), (Vec3::new(-0.2, -0.3, -0.15), Vec3::splat(0.1)), "boxmax defaults to 0.1");
    // x clamps to [-2, 0]: 5 -> 0; y is unlimited.
    assert_eq!(s.joint(1).initial_rotation, JointRotation::euler_xyz(0.0, 0.5, 0.0));
    // y locked at 0.
    assert_eq!(s.joint(2).initial_rotation, JointRotation::euler_xyz(0.0, 0.0, 0.0));
    assert_eq!(s.joint(0).initial_rotation, JointRotation::euler_xyz(0.0, 0.1, 0.0));
}

#[test]
fn cse169_tokenizer_handles_cr_crlf_lf_and_glued_braces() {
    let tokens = cse169::tokenize(Cursor::new("a{\rb\r\nc}\nd"), path("x")).unwrap();
    let got: Vec<(&str, usize)> = tokens.iter().map(|t| (t.text.as_str(), t.line)).collect();
    assert_eq!(got, vec![("a", 1), ("{", 1), ("b", 2), ("c", 3), ("}", 3), ("d", 4)]);
}

fn cse_err(text: &str) -> String {
    cse169::parse_skel(Cursor::new(text), path("t.skel")).unwrap_err().to_string()
}

#[test]
fn cse169_skel_with_a_missing_number() {
    assert_eq!(cse_err("balljoint r {\n offset 1 2\n}\n"), "t.skel:3: expected a number (offset z), found `}`");
}

#[test]
fn cse169_skel_with_an_unknown_keyword() {
    assert_eq!(
        cse_err("balljoint r {\n  offest 1 2 3\n}"),
        "t.skel:2: expected offset, boxmin, boxmax, rotxlimit, rotylimit, rotzlimit, pose, balljoint or `}`, found `offest`"
    );
}

#[test]
fn cse169_skel_with_an_unclosed_brace() {
    assert_eq!(
        cse_err("balljoint r {\n offset 1 2 3\n"),
        "t.skel:2: expected offset, boxmin, boxmax, rotxlimit, rotylimit, rotzlimit, pose, balljoint or `}`, found the end of the file"
    );
}

#[test]
fn cse169_skel_with_two_roots() {
    assert_eq!(
        cse_err("balljoint a { }\nballjoint b { }\n"),
        "t.skel:2: expected the end of the file after the root joint (one root per skeleton), found `balljoint`"
    );
}

#[test]
fn cse169_skel_without_a_name() {
    assert_eq!(cse_err("balljoint {\n}"), "t.skel:1: expected a joint name, found `{`");
}

#[test]
fn cse169_skel_empty() {
    assert_eq!(cse_err("  \r\n"), "t.skel:1: expected `balljoint`, found the end of the file");
}

#[test]
fn obj_reads_positions_in_source_order_and_triangulates() {
    let text = "# c\nv 0 0 0\nv 1 0 0\nvn 0 0 1\nv 1 1 0\nv 0 1 0\nf 1//1 2//1 3//1 4//1\nf -1 -2 -3\n";
    let m = obj::parse_obj(Cursor::new(text), path("m.obj")).unwrap();
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [3, 2, 1]]);
}

#[test]
fn obj_round_trips_through_the_writer() {
    let m = obj::parse_obj(Cursor::new("v 0.125 -2 3.5\nv 1 0 0\nv 0 1e-3 0\nf 1 2 3\n"), path("m.obj")).unwrap();
    let mut text = Vec::new();
    obj::write_obj(&mut text, &m.positions, &m.triangles).unwrap();
    let back = obj::parse_obj(Cursor::new(text), path("w.obj")).unwrap();
    assert_eq!(back, m);
}

#[test]
fn obj_with_a_face_index_out_of_range() {
    let e = obj::parse_obj(Cursor::new("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), path("m.obj")).unwrap_err();
    assert_eq!(e.to_string(), "m.obj:4: expected a vertex index in 1..=3, found 4");
}

#[test]
fn obj_with_a_short_vertex() {
    let e = obj::parse_obj(Cursor::new("v 0 0\n"), path("m.obj")).unwrap_err();
    assert_eq!(e.to_string(), "m.obj:1: expected 3 numbers after `v`, found 2");
}

#[test]
fn obj_with_a_two_corner_face() {
    let e = obj::parse_obj(Cursor::new("v 0 0 0\nf 1 1\n"), path("m.obj")).unwrap_err();
    assert_eq!(e.to_string(), "m.obj:2: expected at least 3 vertex indices after `f`, found 2");
}

#[test]
fn off_reads_vertices_and_faces() {
    let m = off::parse_off(Cursor::new("OFF\n4 2 0\n0 0 0 \n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 \n3 0 2 3\n"), path("m.off"))
        .unwrap();
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn off_without_its_header() {
    let e = off::parse_off(Cursor::new("4 2 0\n"), path("m.off")).unwrap_err();
    assert_eq!(e.to_string(), "m.off:1: expected `OFF`, found `4 2 0`");
}

#[test]
fn off_with_too_few_vertices() {
    let e = off::parse_off(Cursor::new("OFF\n3 1 0\n0 0 0\n"), path("m.off")).unwrap_err();
    assert_eq!(e.to_string(), "m.off:2: expected 3 vertices, found 1 before the end of the file");
}

#[test]
fn off_with_a_face_index_out_of_range() {
    let e = off::parse_off(Cursor::new("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), path("m.off")).unwrap_err();
    assert_eq!(e.to_string(), "m.off:6: expected a vertex index below 3, found 3");
}

fn path(s: &str) -> &std::path::Path {
    std::path::Path::new(s)
}
