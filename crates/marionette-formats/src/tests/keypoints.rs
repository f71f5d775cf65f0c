//! Keypoint files as detectors write them, and malformed ones refused with the field's path.

use std::path::Path;

use crate::keypoints::{BodyPoint, parse_keypoints};

fn parse(text: &str) -> Result<crate::keypoints::Keypoints, String> {
    parse_keypoints(text, Path::new("k.json")).map_err(|e| e.to_string())
}

/// `n` points, point k at (10k, 20k) with confidence 1 except those in `absent`.
fn flat(n: usize, absent: &[usize]) -> String {
    let values: Vec<String> = (0..n)
        .flat_map(|k| {
            let c = if absent.contains(&k) { 0.0 } else { 0.9 };
            [format!("{}", 10 * k), format!("{}", 20 * k), format!("{c}")]
        })
        .collect();
    format!("[{}]", values.join(", "))
}

#[test]
fn openpose_json_reads_18_or_25_points_by_name_with_hands_and_canvas() {
    let text = format!(
        r#"{{"canvas_width": 512, "canvas_height": 768, "people": [{{"pose_keypoints_2d": {}, "hand_left_keypoints_2d": {}}}]}}"#,
        flat(18, &[3]),
        flat(21, &[])
    );
    let k = parse(&text).unwrap();
    assert_eq!(k.size, Some((512.0, 768.0)));
    let p = &k.people[0];
    // OpenPose's order: point 2 the right shoulder, 5 the left; point 3 (the right elbow)
    // has confidence 0, so it is absent, not at (0, 0).
    assert_eq!(p.point(BodyPoint::RightShoulder).map(|q| (q.x, q.y)), Some((20.0, 40.0)));
    assert_eq!(p.point(BodyPoint::LeftShoulder).map(|q| (q.x, q.y)), Some((50.0, 100.0)));
    assert_eq!(p.point(BodyPoint::RightElbow), None);
    assert_eq!((p.left_hand.len(), p.right_hand.len()), (21, 0));
    let body25 = parse(&format!(r#"{{"people": [{{"pose_keypoints_2d": {}}}]}}"#, flat(25, &[]))).unwrap();
    assert_eq!(body25.size, None);
    assert_eq!(body25.people[0].point(BodyPoint::MidHip).map(|q| q.x), Some(80.0));
    assert_eq!(body25.people[0].point(BodyPoint::RightHeel).map(|q| q.x), Some(240.0));
}

#[test]
fn coco_keypoints_read_17_or_wholebodys_133_with_the_images_size() {
    let text = format!(
        r#"{{"images": [{{"id": 7, "width": 640, "height": 480}}], "annotations": [{{"image_id": 7, "keypoints": {}}}]}}"#,
        flat(17, &[])
    );
    let k = parse(&text).unwrap();
    assert_eq!(k.size, Some((640.0, 480.0)));
    // COCO's order: point 5 the left shoulder, 6 the right.
    assert_eq!(k.people[0].point(BodyPoint::LeftShoulder).map(|q| q.x), Some(50.0));
    assert_eq!(k.people[0].point(BodyPoint::RightShoulder).map(|q| q.x), Some(60.0));
    let whole = parse(&format!(r#"{{"annotations": [{{"keypoints": {}}}]}}"#, flat(133, &[]))).unwrap();
    let p = &whole.people[0];
    assert_eq!(p.point(BodyPoint::LeftBigToe).map(|q| q.x), Some(170.0));
    assert_eq!((p.left_hand.len(), p.right_hand.len()), (21, 21));
    assert_eq!(p.left_hand[0].map(|q| q.x), Some(910.0));
    assert_eq!(p.right_hand[20].map(|q| q.x), Some(1320.0));
    // The same person with its parts apart, as COCO-WholeBody's annotations hold them.
    let parts = format!(
        r#"{{"annotations": [{{"keypoints": {}, "foot_kpts": {}, "face_kpts": {}, "lefthand_kpts": {}, "righthand_kpts": {}}}]}}"#,
        flat(17, &[]),
        flat(6, &[]),
        flat(68, &[]),
        flat(21, &[]),
        flat(21, &[])
    );
    assert_eq!(parse(&parts).unwrap().people[0].left_hand.len(), 21);
}

#[test]
fn the_largest_person_is_taken_unless_one_is_named() {
    let small: String = "[100, 100, 1, 110, 100, 1]".into();
    let text = format!(
        r#"{{"people": [{{"pose_keypoints_2d": {}}}, {{"pose_keypoints_2d": {}}}]}}"#,
        small.replace(']', &format!(", {}]", vec!["0"; 48].join(", "))),
        flat(18, &[])
    );
    let k = parse(&text).unwrap();
    assert_eq!(k.person(None).unwrap().point(BodyPoint::Neck).map(|q| q.x), Some(10.0));
    assert_eq!(k.person(Some(0)).unwrap().point(BodyPoint::Nose).map(|q| q.x), Some(100.0));
    assert!(k.person(Some(2)).unwrap_err().contains("--person 2: the file has 2 people"));
}

#[test]
fn malformed_keypoint_files_are_refused_with_the_fields_path() {
    let cases = [
        (
            format!(r#"{{"people": [{{"pose_keypoints_2d": {}}}]}}"#, "[1, 2]"),
            "people[0].pose_keypoints_2d: 2 numbers, expected 54 or 75",
        ),
        (
            format!(r#"{{"people": [{{"pose_keypoints_2d": {}}}]}}"#, flat(18, &[]).replacen("10", "\"x\"", 1)),
            "people[0].pose_keypoints_2d[3]: expected a finite number",
        ),
        (r#"{"people": []}"#.to_string(), "people: expected at least one person, found none"),
        (
            format!(r#"{{"people": [{{"pose_keypoints_2d": {}}}]}}"#, flat(18, &(0..18).collect::<Vec<_>>())),
            "people[0]: every point absent",
        ),
        (
            format!(
                r#"{{"canvas_width": -5, "canvas_height": 10, "people": [{{"pose_keypoints_2d": {}}}]}}"#,
                flat(18, &[])
            ),
            "canvas_width: expected a positive size in pixels, found -5",
        ),
        (
            format!(
                r#"{{"people": [{{"pose_keypoints_2d": {}, "hand_left_keypoints_2d": [1, 2, 3]}}]}}"#,
                flat(18, &[])
            ),
            "people[0].hand_left_keypoints_2d: 3 numbers, expected 63",
        ),
        (
            r#"{"annotations": [{"keypoints": [1, 2, 3]}]}"#.to_string(),
            "annotations[0].keypoints: 3 numbers, expected 51 (17 points) or 399 (133)",
        ),
        (r#"{"people": [{"pose_keypoints_2d": [NaN]}]}"#.to_string(), "k.json:1: expected JSON"),
        (r#"{"faces": []}"#.to_string(), "expected OpenPose's `people` or COCO's `annotations`"),
    ];
    for (text, want) in cases {
        let got = parse(&text).unwrap_err();
        assert!(got.contains(want), "{text}: {got}");
    }
}

/// Points normalised to the canvas (controlnet_aux's) are scaled by it; a list of frames
/// (ComfyUI's POSE_KEYPOINT) gives its first; pixel points are left as they are.
#[test]
fn normalised_points_and_comfyui_lists_are_read_in_pixels() {
    let normalised: Vec<String> = (0..18).map(|k| format!("{}, {}, 1", 0.05 * k as f32, 0.04 * k as f32)).collect();
    let frame = format!(
        r#"{{"canvas_width": 512, "canvas_height": 768, "people": [{{"pose_keypoints_2d": [{}]}}]}}"#,
        normalised.join(", ")
    );
    for text in [frame.clone(), format!("[{frame}, {frame}]")] {
        let k = parse(&text).unwrap();
        let shoulder = k.people[0].point(BodyPoint::RightShoulder).unwrap();
        assert!((shoulder.x - 0.1 * 512.0).abs() < 1e-3 && (shoulder.y - 0.08 * 768.0).abs() < 1e-3, "{shoulder:?}");
    }
    let pixels = parse(&format!(
        r#"{{"canvas_width": 512, "canvas_height": 768, "people": [{{"pose_keypoints_2d": {}}}]}}"#,
        flat(18, &[])
    ))
    .unwrap();
    assert_eq!(pixels.people[0].point(BodyPoint::RightShoulder).map(|q| q.x), Some(20.0));
    assert!(parse("[1, 2]").unwrap_err().contains("expected a list of OpenPose frames"));
    let frames = crate::keypoints::parse_keypoint_frames(&format!("[{frame}, {frame}, {frame}]"), Path::new("k.json"));
    assert_eq!(frames.unwrap().len(), 3);
    let broken = format!(r#"[{frame}, {{"people": [{{"pose_keypoints_2d": [1, 2]}}]}}]"#);
    let e = crate::keypoints::parse_keypoint_frames(&broken, Path::new("k.json")).unwrap_err().to_string();
    assert!(e.contains("[1].people[0].pose_keypoints_2d: 2 numbers"), "{e}");
}
