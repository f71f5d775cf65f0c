//! `render --data`: the passes, keypoints and files against independent arithmetic (the
//! scene's camera worked out here in f64; numpy and pycocotools in
//! `scripts/check_data_picture.py`).

use std::path::{Path, PathBuf};
use std::process::Command;

use glam::{DMat3, DVec3};

use crate::common::scratch;

/// The camera the scenes set: (focus, yaw, pitch, distance, fov in degrees).
const FOCUS: [f64; 3] = [0.0, 0.9, 0.0];
const YAW: f64 = 0.0;
const PITCH: f64 = -0.2;
const DISTANCE: f64 = 4.0;
const FOV: f64 = 40.0;
const W: u32 = 320;
const H: u32 = 240;

fn camera_ron() -> String {
    format!(
        "camera: Some((focus: ({}, {}, {}), yaw: {YAW}, pitch: {PITCH}, distance: {DISTANCE}, fov: {FOV}))",
        FOCUS[0], FOCUS[1], FOCUS[2]
    )
}

/// A puppet of the scene: `name` at `x` (metres along x), turned by `yaw`.
fn puppet(name: &str, x: f64, yaw: f64) -> String {
    format!(
        "(source: Embedded(\"puppet\"), name: \"{name}\", placement: (translation: ({x}, 0.0, 0.0), yaw: {yaw}, scale: 1.0))"
    )
}

/// `render SCENE --data` of `characters` (RON) into `dir/shot.png`; the COCO file.
fn render_data(dir: &Path, characters: &[String], extra: &[&str]) -> serde_json::Value {
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, format!("(characters: [{}], {})", characters.join(", "), camera_ron())).unwrap();
    let out = dir.join("shot.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--data"])
        .args(["--width", &W.to_string(), "--height", &H.to_string()])
        .args(extra)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    serde_json::from_str(&std::fs::read_to_string(dir.join("shot.json")).unwrap()).unwrap()
}

/// The scene's camera: its rotation (yaw about y, then pitch about x), eye and focal length.
fn camera() -> (DMat3, DVec3, f64) {
    let rotation = DMat3::from_rotation_y(YAW) * DMat3::from_rotation_x(PITCH);
    let eye = DVec3::from(FOCUS) + rotation * DVec3::new(0.0, 0.0, DISTANCE);
    (rotation, eye, f64::from(H) / 2.0 / (FOV.to_radians() / 2.0).tan())
}

fn annotation<'a>(coco: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    coco["annotations"].as_array().unwrap().iter().find(|a| a["character"] == name).unwrap_or_else(|| panic!("{name}"))
}

/// A keypoint's (x, y, v) by COCO name.
fn keypoint(ann: &serde_json::Value, name: &str) -> (f64, f64, u64) {
    let k = ["nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder", "right_shoulder", "left_elbow"]
        .iter()
        .chain(&["right_elbow", "left_wrist", "right_wrist", "left_hip", "right_hip", "left_knee", "right_knee"])
        .chain(&["left_ankle", "right_ankle"])
        .position(|&n| n == name)
        .unwrap();
    let kp = ann["keypoints"].as_array().unwrap();
    (kp[3 * k].as_f64().unwrap(), kp[3 * k + 1].as_f64().unwrap(), kp[3 * k + 2].as_u64().unwrap())
}

fn read_depth(path: &Path) -> Vec<f32> {
    let image = exr::prelude::read_first_flat_layer_from_file(path).unwrap();
    let channel = &image.layer_data.channel_data.list[0];
    assert_eq!(channel.name.to_string(), "Z");
    match &channel.sample_data {
        exr::prelude::FlatSamples::F32(v) => v.clone(),
        other => panic!("expected 32-bit floats, found {other:?}"),
    }
}

/// The floor's depth at a grid of pixels equals the distance along the view axis to where
/// each pixel's ray meets the floor (≤ 1 mm); its normals point up within 0.5°.
#[test]
fn the_floors_depth_and_normals_are_the_ray_plane_arithmetic() {
    let dir = scratch("data-floor");
    render_data(&dir, &[puppet("a", 0.0, 0.0)], &[]);
    let depth = read_depth(&dir.join("shot.depth.exr"));
    let mask = image::open(dir.join("shot.mask.png")).unwrap().to_luma16();
    let normals = image::open(dir.join("shot.normal.png")).unwrap().to_rgb8();
    let (rotation, eye, f) = camera();
    let (mut checked, mut worst_mm, mut worst_degrees) = (0, 0.0f64, 0.0f64);
    for y in (0..H).step_by(8) {
        for x in (0..W).step_by(8) {
            // The ray through the pixel's centre, with a view-axis component of 1.
            let local = DVec3::new(
                (f64::from(x) + 0.5 - f64::from(W) / 2.0) / f,
                -(f64::from(y) + 0.5 - f64::from(H) / 2.0) / f,
                -1.0,
            );
            let ray = rotation * local;
            let i = (y * W + x) as usize;
            if ray.y >= 0.0 {
                assert!(depth[i].is_infinite(), "({x}, {y}) looks at the sky: {}", depth[i]);
                continue;
            }
            let expected = -eye.y / ray.y;
            let hit = eye + ray * expected;
            // The floor reaches at least 5 m from the origin; a character hides some of it.
            if hit.x.abs().max(hit.z.abs()) > 5.0 || mask.get_pixel(x, y).0[0] != 0 {
                continue;
            }
            worst_mm = worst_mm.max((f64::from(depth[i]) - expected).abs() * 1000.0);
            let n = normals.get_pixel(x, y).0.map(|c| f64::from(c) / 255.0 * 2.0 - 1.0);
            let up = rotation * DVec3::from(n);
            worst_degrees = worst_degrees.max(up.angle_between(DVec3::Y).to_degrees());
            checked += 1;
        }
    }
    eprintln!("floor: {checked} pixels, depth within {worst_mm:.4} mm, normals within {worst_degrees:.3}°");
    assert!(checked > 200, "{checked} floor pixels");
    assert!(worst_mm <= 1.0, "floor depth off by {worst_mm} mm");
    assert!(worst_degrees <= 0.5, "floor normal {worst_degrees}° from up");
}

/// The pictures' data against numpy's pinhole from the scene's camera alone (≤ 0.01 px),
/// pycocotools' masks, the OpenPose JSON; a prop in front of a wrist hides it; a character
/// half out of the picture has its outside points v = 0 and a box cut at the edge; each box
/// is its mask's.
#[test]
fn keypoints_masks_and_boxes_agree_with_independent_arithmetic() {
    let dir = scratch("data-keypoints");
    // Half the picture's width at the focus's depth: a puppet there stands half outside.
    let edge = DISTANCE * (FOV.to_radians() / 2.0).tan() * f64::from(W) / f64::from(H);
    let people = [puppet("front", -0.6, 0.0), puppet("edge", edge, 0.0)];
    let coco = render_data(&dir, &people, &[]);
    let front = annotation(&coco, "front");
    // A box between the front puppet's right wrist and the camera, 40 cm in front of it.
    let wrist: Vec<f64> = serde_json::from_value(front["joints_3d"]["RightHand"].clone()).unwrap();
    let (_, eye, _) = camera();
    let wrist = DVec3::from_slice(&wrist);
    let centre = wrist + (eye - wrist).normalize() * 0.4;
    let box_obj = dir.join("box.obj");
    write_box(&box_obj, centre, 0.08);
    assert_eq!(keypoint(front, "right_wrist").2, 2, "the wrist is seen before the box is there");
    let with_box =
        [people[0].clone(), people[1].clone(), format!("(source: File(\"{}\"), name: \"box\")", box_obj.display())];
    let coco = render_data(&dir, &with_box, &[]);
    let front = annotation(&coco, "front");
    assert_eq!(keypoint(front, "right_wrist").2, 1, "behind the box");
    assert_eq!(keypoint(front, "left_wrist").2, 2);
    assert_eq!(front["num_keypoints"], 12, "the puppet has no face points");
    let edge_ann = annotation(&coco, "edge");
    let bbox: Vec<u32> = serde_json::from_value(edge_ann["bbox"].clone()).unwrap();
    assert_eq!(bbox[0] + bbox[2], W, "the box is cut at the picture's edge: {bbox:?}");
    let outside = ["left_shoulder", "left_elbow", "left_wrist", "left_hip", "left_knee", "left_ankle"]
        .iter()
        .chain(&["right_shoulder", "right_elbow", "right_wrist", "right_hip", "right_knee", "right_ankle"])
        .map(|n| keypoint(edge_ann, n))
        .filter(|k| k.2 == 0)
        .count();
    assert!((3..12).contains(&outside), "{outside} of the edge puppet's points outside");
    // Each annotation's box is its mask's, read back from the mask picture.
    let mask = image::open(dir.join("shot.mask.png")).unwrap().to_luma16();
    for ann in coco["annotations"].as_array().unwrap() {
        let id = ann["instance_id"].as_u64().unwrap() as u16;
        let pixels: Vec<(u32, u32)> = mask.enumerate_pixels().filter(|p| p.2.0[0] == id).map(|p| (p.0, p.1)).collect();
        let lo = pixels.iter().fold((u32::MAX, u32::MAX), |a, p| (a.0.min(p.0), a.1.min(p.1)));
        let hi = pixels.iter().fold((0, 0), |a, p| (a.0.max(p.0), a.1.max(p.1)));
        let bbox: Vec<u32> = serde_json::from_value(ann["bbox"].clone()).unwrap();
        assert_eq!(bbox, [lo.0, lo.1, hi.0 - lo.0 + 1, hi.1 - lo.1 + 1], "{}", ann["character"]);
        assert_eq!(ann["area"].as_u64().unwrap() as usize, pixels.len());
    }
    python_check(&dir.join("shot.json"));
}

/// The mask's pixels are those the transparent render draws opaque (up to the edges'
/// antialiasing: the pixels that differ lie on the silhouette).
#[test]
fn the_mask_is_the_transparent_pictures_opaque_pixels() {
    let dir = scratch("data-transparent");
    render_data(&dir, &[puppet("a", 0.0, 0.4)], &["--transparent"]);
    let mask = image::open(dir.join("shot.mask.png")).unwrap().to_luma16();
    let picture = image::open(dir.join("shot.png")).unwrap().to_rgba8();
    let inside = |x: u32, y: u32| mask.get_pixel(x, y).0[0] != 0;
    let (mut area, mut differ, mut off_edge) = (0, 0, 0);
    for (x, y, p) in picture.enumerate_pixels() {
        area += usize::from(inside(x, y));
        if (p.0[3] > 127) != inside(x, y) {
            differ += 1;
            let on_edge = [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)].iter().any(|&(dx, dy)| {
                let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                nx >= 0 && ny >= 0 && nx < W as i32 && ny < H as i32 && inside(nx as u32, ny as u32) != inside(x, y)
            });
            off_edge += usize::from(!on_edge);
        }
    }
    assert!(area > 1000, "{area}");
    assert_eq!(off_edge, 0, "{differ} pixels differ, {off_edge} of them away from the silhouette's edge");
}

/// A frame sequence writes a set of passes per frame and one COCO file with an image per
/// frame, each character keeping its instance id.
#[test]
fn a_sequence_writes_passes_per_frame_and_one_coco_file() {
    let dir = scratch("data-sequence");
    let scene = dir.join("scene.ron");
    std::fs::write(
        &scene,
        format!("(characters: [{}, {}], {})", puppet("a", -0.5, 0.0), puppet("b", 0.5, 0.0), camera_ron()),
    )
    .unwrap();
    let out = dir.join("f_%02d.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--data", "--turntable", "1"])
        .args(["--from", "0", "--to", "0.5", "--fps", "4", "--width", "96", "--height", "64"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    for n in 0..3 {
        for suffix in
            ["png", "depth.exr", "depth.png", "normal.png", "mask.png", "parts.png", "openpose.png", "openpose.json"]
        {
            assert!(dir.join(format!("f_{n:02}.{suffix}")).is_file(), "f_{n:02}.{suffix}");
        }
    }
    let coco: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("f_all.json")).unwrap()).unwrap();
    assert_eq!(coco["images"].as_array().unwrap().len(), 3);
    for ann in coco["annotations"].as_array().unwrap() {
        let expected = if ann["character"] == "a" { 1 } else { 2 };
        assert_eq!(ann["instance_id"], expected);
    }
}

/// An SMPL body's face points come from its landmark vertices: seen facing the camera,
/// hidden (v = 1) facing away.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the SMPL model)")]
fn an_smpl_bodys_face_is_seen_from_the_front_and_hidden_from_behind() {
    let smpl = crate::common::data_dir().join("smpl").canonicalize().unwrap();
    for (yaw, seen) in [(0.0, 2), (std::f64::consts::PI, 1)] {
        let dir = scratch(&format!("data-smpl-{seen}"));
        let body = format!(
            "(source: File(\"{}\"), name: \"body\", smpl: Some(()), placement: (translation: (0.0, 0.0, 0.0), yaw: {yaw}, scale: 1.0))",
            smpl.display()
        );
        let coco = render_data(&dir, &[body], &[]);
        let ann = annotation(&coco, "body");
        for name in ["nose", "left_eye", "right_eye"] {
            assert_eq!(keypoint(ann, name).2, seen, "{name} at yaw {yaw}");
        }
        python_check(&dir.join("shot.json"));
    }
}

/// Runs the independent checks (numpy, pycocotools) on a COCO file of a scene of this
/// module's camera.
fn python_check(shot: &PathBuf) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_data_picture.py");
    let numbers = [FOCUS[0], FOCUS[1], FOCUS[2], YAW, PITCH, DISTANCE, FOV].map(|x| x.to_string());
    let output = Command::new("python3")
        .arg(&script)
        .arg(shot)
        .args(&numbers)
        .output()
        .expect("python3 with numpy, pycocotools and pillow (scripts/ensure-tools.sh installs them)");
    let said = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{said}{}", String::from_utf8_lossy(&output.stderr));
    eprintln!("{said}");
}

/// An axis-aligned cube of half side `half` at `centre`, as OBJ.
fn write_box(path: &Path, centre: DVec3, half: f64) {
    let mut text = String::new();
    for k in 0..8 {
        let s = |bit: i32| if k & bit == 0 { -half } else { half };
        let p = centre + DVec3::new(s(1), s(2), s(4));
        text += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for f in [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]] {
        text += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    std::fs::write(path, text).unwrap();
}

/// The OpenPose drawing in ControlNet's reference colours (the table of `controlnet_aux`'s
/// `draw_bodypose`, written out here): each point a disc in its colour, each limb between
/// two points at 60 % of its colour, on black.
#[test]
fn the_openpose_drawing_has_controlnets_colours_and_limbs() {
    const COLOURS: [[u8; 3]; 18] = [
        [255, 0, 0],
        [255, 85, 0],
        [255, 170, 0],
        [255, 255, 0],
        [170, 255, 0],
        [85, 255, 0],
        [0, 255, 0],
        [0, 255, 85],
        [0, 255, 170],
        [0, 255, 255],
        [0, 170, 255],
        [0, 85, 255],
        [0, 0, 255],
        [85, 0, 255],
        [170, 0, 255],
        [255, 0, 255],
        [255, 0, 170],
        [255, 0, 85],
    ];
    // ControlNet's limbs over its 18 points (from 1): the first arm and leg limbs.
    const LIMBS: [[usize; 2]; 12] =
        [[2, 3], [2, 6], [3, 4], [4, 5], [6, 7], [7, 8], [2, 9], [9, 10], [10, 11], [2, 12], [12, 13], [13, 14]];
    // BODY_25's index of each of ControlNet's 18 points (nose, neck, right arm, left arm,
    // right leg, left leg, eyes, ears).
    const FROM_25: [usize; 18] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18];
    let dir = scratch("data-openpose");
    render_data(&dir, &[puppet("a", 0.0, 0.3)], &[]);
    // The keypoint reader (`--fit`'s) reads the OpenPose JSON (BODY_25) and the COCO file
    // (17 points) the render wrote, each point under the same name in both.
    use marionette::formats::keypoints::{COCO_17, read_keypoints};
    let (open, coco) = (read_keypoints(&dir.join("shot.openpose.json")), read_keypoints(&dir.join("shot.json")));
    let (open, coco) = (open.unwrap(), coco.unwrap());
    assert_eq!(coco.size, Some((W as f32, H as f32)));
    let (a, b) = (open.person(None).unwrap(), coco.person(None).unwrap());
    let shared: Vec<_> = COCO_17.iter().filter_map(|&n| Some((n, a.point(n)?, b.point(n)?))).collect();
    assert!(shared.len() >= 12, "{} points in both", shared.len());
    for (name, p, q) in shared {
        assert!((p.x - q.x).abs() <= 1.0 && (p.y - q.y).abs() <= 1.0, "{name:?}: {p:?} and {q:?}");
    }
    let drawing = image::open(dir.join("shot.openpose.png")).unwrap().to_rgb8();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("shot.openpose.json")).unwrap()).unwrap();
    let body: Vec<f64> = serde_json::from_value(json["people"][0]["pose_keypoints_2d"].clone()).unwrap();
    let point = |k: usize| {
        let j = FROM_25[k];
        (body[3 * j + 2] > 0.0).then(|| (body[3 * j], body[3 * j + 1]))
    };
    let pixel = |(x, y): (f64, f64)| drawing.get_pixel(x as u32, y as u32).0;
    let mut points = 0;
    for (k, colour) in COLOURS.iter().enumerate() {
        let Some(p) = point(k) else { continue };
        points += 1;
        // A later point's disc (radius 4) may cover this one's centre.
        let covered = (k + 1..18).filter_map(point).any(|q| (q.0 - p.0).powi(2) + (q.1 - p.1).powi(2) <= 16.0);
        if !covered {
            assert_eq!(pixel(p), *colour, "point {k} at {p:?}");
        }
    }
    let mut limbs = 0;
    for (k, [a, b]) in LIMBS.iter().enumerate() {
        let (Some(a), Some(b)) = (point(a - 1), point(b - 1)) else { continue };
        let length = ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt();
        if length < 10.0 {
            continue;
        }
        // Midway, away from both points' discs (later limbs may cross: the first drawn at
        // the middle of a limb is not always its own, so count those that are).
        let middle = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
        let dim = COLOURS[k].map(|c| (f64::from(c) * 0.6) as u8);
        limbs += usize::from(pixel(middle) == dim);
    }
    assert_eq!(points, 13, "the puppet's neck and 12 limb points (no face)");
    assert!(limbs >= 10, "{limbs} limbs in their colour at 60 %");
    assert_eq!(drawing.get_pixel(0, 0).0, [0, 0, 0], "on black");
}

/// `render --controlnet` at `width` × `height` of `characters` (RON) into `dir/shot.png`,
/// with `--data` for the metric passes to hold the maps to, and `extra` arguments.
fn render_controlnet(dir: &Path, characters: &[String], width: u32, height: u32, extra: &[&str]) {
    let scene = dir.join("scene.ron");
    std::fs::write(&scene, format!("(characters: [{}], {})", characters.join(", "), camera_ron())).unwrap();
    let out = dir.join("shot.png");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", scene.to_str().unwrap(), "--out", out.to_str().unwrap(), "--data", "--controlnet"])
        .args(["--width", &width.to_string(), "--height", &height.to_string()])
        .args(extra)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
}

/// The OpenPose map is the annotator's own drawing of the same points (its `draw_bodypose`
/// and `draw_handpose` taken from the `controlnet_aux` wheel,
/// scripts/check_controlnet_openpose.py): one and three people, 512×512 and 640×480, and a
/// figure with both hands. Its JSON, read back by the annotator's JSON reader
/// (`decode_json_as_poses`), draws the same picture.
#[test]
fn the_controlnet_openpose_map_is_the_annotators_drawing() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_controlnet_openpose.py");
    let three = [puppet("a", -0.9, 0.4), puppet("b", 0.0, 0.0), puppet("c", 0.9, -0.5)];
    for (people, (w, h)) in [(&three[1..2], (512, 512)), (&three[..], (640, 480)), (&three[..], (512, 512))] {
        let dir = scratch(&format!("controlnet-openpose-{}-{w}x{h}", people.len()));
        render_controlnet(&dir, people, w, h, &[]);
        let output = Command::new("python3")
            .arg(&script)
            .arg(dir.join("shot.png"))
            .output()
            .expect("python3 with numpy and opencv (scripts/ensure-tools.sh installs them)");
        let said = String::from_utf8_lossy(&output.stdout);
        assert!(output.status.success(), "{said}{}", String::from_utf8_lossy(&output.stderr));
        assert!(said.contains(&format!("{} people", people.len())), "{said}");
        eprintln!("{said}");
    }
    // Hands where the fingers are mapped: a Mixamo rig waving, one hand open, one pointing.
    let dir = scratch("controlnet-openpose-hands");
    let out = dir.join("shot.png");
    let mixamo = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs/mixamo.glb");
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", mixamo.to_str().unwrap(), "--out", out.to_str().unwrap(), "--controlnet"])
        .args(["--preset", "wave", "--hand", "left=open", "--hand", "right=point", "--width", "640", "--height", "480"])
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let output = Command::new("python3").arg(&script).arg(&out).output().unwrap();
    let said = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{said}{}", String::from_utf8_lossy(&output.stderr));
    assert!(said.contains("1 people (2 hands)"), "{said}");
    eprintln!("{said}");
}

/// `dir/shot.cn-canny.png` is, pixel for pixel, `cv2.Canny` of the picture at `low`, `high`
/// (scripts/check_controlnet_canny.py).
fn the_canny_edges_are_opencvs(dir: &Path, low: &str, high: &str) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_controlnet_canny.py");
    let output = Command::new("python3")
        .arg(&script)
        .arg(dir.join("shot.png"))
        .args([low, high])
        .output()
        .expect("python3 with numpy and opencv (scripts/ensure-tools.sh installs them)");
    let said = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{said}{}", String::from_utf8_lossy(&output.stderr));
    eprintln!("{said}");
}

/// The depth map is relative inverse depth: 255 at the nearest shown point, 0 where nothing
/// is, never darker for a nearer pixel; the normal map is the camera-frame normals with x
/// turned to the viewer's left (a surface facing left is red), nothing facing the viewer;
/// the 18-point JSON carries the canvas.
#[test]
fn the_controlnet_depth_and_normal_maps_follow_its_conventions() {
    let dir = scratch("controlnet-maps");
    render_controlnet(&dir, &[puppet("a", -0.4, 0.9), puppet("b", 0.5, -0.9)], W, H, &["--canny"]);
    the_canny_edges_are_opencvs(&dir, "100", "200");
    let depth = read_depth(&dir.join("shot.depth.exr"));
    let map = image::open(dir.join("shot.cn-depth.png")).unwrap().to_luma8();
    let values: Vec<u8> = map.pixels().map(|p| p.0[0]).collect();
    let mut shown: Vec<(f32, u8)> =
        depth.iter().zip(&values).filter(|(d, _)| d.is_finite()).map(|(&d, &v)| (d, v)).collect();
    assert!(depth.iter().zip(&values).all(|(d, &v)| d.is_finite() || v == 0), "nothing is black");
    shown.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(shown[0].1, 255, "the nearest shown point is white");
    assert!(shown.windows(2).all(|p| p[0].1 >= p[1].1), "farther is never brighter");
    assert!(shown.iter().all(|&(_, v)| v >= 1), "what is shown is not black");

    let camera_frame = image::open(dir.join("shot.normal.png")).unwrap().to_rgb8();
    let controlnet = image::open(dir.join("shot.cn-normal.png")).unwrap().to_rgb8();
    let (mut left, mut right) = (0, 0);
    for (i, (ours, theirs)) in camera_frame.pixels().zip(controlnet.pixels()).enumerate() {
        if !depth[i].is_finite() {
            assert_eq!(theirs.0, [128, 128, 255], "nothing faces the viewer");
            continue;
        }
        let [x, y, z] = ours.0.map(i32::from);
        let [r, g, b] = theirs.0.map(i32::from);
        assert!(
            (r - (255 - x)).abs() <= 1 && g == y && b == z,
            "pixel {i}: camera {:?}, ControlNet {:?}",
            ours.0,
            theirs.0
        );
        // Facing the viewer's left (x < 0 in the camera frame): red above the middle.
        if x < 100 {
            assert!(r > 155, "a surface facing left is red: {:?}", theirs.0);
            left += 1;
        } else if x > 155 {
            right += 1;
        }
    }
    assert!(left > 50 && right > 50, "surfaces facing both ways: {left} left, {right} right");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("shot.cn-openpose.json")).unwrap()).unwrap();
    assert_eq!(
        (json["canvas_width"].as_u64(), json["canvas_height"].as_u64()),
        (Some(u64::from(W)), Some(u64::from(H)))
    );
    let people = json["people"].as_array().unwrap();
    assert_eq!(people.len(), 2);
    assert!(people.iter().all(|p| p["pose_keypoints_2d"].as_array().unwrap().len() == 54), "18 points a person");
}

/// The ControlNet normal map agrees with the depth it came from: normals worked out from
/// the metric depth by finite differences (the pixels back-projected through the scene's
/// camera), put in Normal 1.1's frame, lie within 15° (median) of the decoded map over the
/// characters.
#[test]
fn the_controlnet_normals_agree_with_the_depth_they_came_from() {
    let dir = scratch("controlnet-normals-depth");
    render_controlnet(&dir, &[puppet("a", -0.4, 0.9), puppet("b", 0.5, -0.9)], W, H, &["--canny", "50,150"]);
    the_canny_edges_are_opencvs(&dir, "50", "150");
    let depth = read_depth(&dir.join("shot.depth.exr"));
    let mask = image::open(dir.join("shot.mask.png")).unwrap().to_luma16();
    let map = image::open(dir.join("shot.cn-normal.png")).unwrap().to_rgb8();
    let (_, _, f) = camera();
    let (cx, cy) = (f64::from(W) / 2.0, f64::from(H) / 2.0);
    // A pixel's point in OpenCV's camera frame (x right, y down, z forward).
    let at = |u: u32, v: u32| {
        let d = f64::from(depth[(v * W + u) as usize]);
        DVec3::new((f64::from(u) + 0.5 - cx) / f * d, (f64::from(v) + 0.5 - cy) / f * d, d)
    };
    let mut angles = Vec::new();
    for v in 1..H - 1 {
        for u in 1..W - 1 {
            let id = mask.get_pixel(u, v).0[0];
            let around = [(u - 1, v), (u + 1, v), (u, v - 1), (u, v + 1)];
            if id == 0 || around.iter().any(|&(a, b)| mask.get_pixel(a, b).0[0] != id) {
                continue;
            }
            let n = (at(u + 1, v) - at(u - 1, v)).cross(at(u, v + 1) - at(u, v - 1));
            if n.length() < 1e-12 {
                continue;
            }
            let n = if n.dot(at(u, v)) > 0.0 { -n.normalize() } else { n.normalize() };
            // Normal 1.1: left, up, towards the viewer.
            let wanted = DVec3::new(-n.x, -n.y, -n.z);
            let got = DVec3::from(map.get_pixel(u, v).0.map(|c| f64::from(c) / 255.0 * 2.0 - 1.0));
            angles.push(wanted.angle_between(got).to_degrees());
        }
    }
    angles.sort_by(f64::total_cmp);
    let median = angles[angles.len() / 2];
    eprintln!("{} pixels: median {median:.2}°", angles.len());
    assert!(angles.len() > 500 && median <= 15.0, "{} pixels, median {median}°", angles.len());
}
