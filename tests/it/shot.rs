//! The picture: lights, background and lens as `render` draws them. The sun from the left
//! lights the characters' left halves, from the right their right halves; a transparent
//! picture is clear around the characters and opaque on them; an orthographic front view
//! draws a character at one size whatever the camera's distance; supersampling averages;
//! each character is drawn in its own colours.

use std::path::{Path, PathBuf};
use std::process::Command;

use marionette::formats::scene::{BackgroundDoc, CameraDoc, CharacterDoc, SceneDoc, SourceDoc, StageDoc, SunDoc};

use crate::common::scratch;

/// Renders `scene` with `flags` into `out` (64×96 unless the flags say).
fn render(scene: &Path, flags: &[&str], out: &Path) -> image::RgbaImage {
    let output = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", "--width", "64", "--height", "96"])
        .args(flags)
        .arg("--out")
        .arg(out)
        .arg(scene)
        .output()
        .unwrap();
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    image::open(out).unwrap().to_rgba8()
}

fn scene_file(dir: &Path, name: &str, doc: &SceneDoc) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    marionette::document::scenes::write_scene(&path, doc).unwrap();
    path
}

/// The puppet alone, lit by the sun alone from `azimuth` (a dim fill), no floor.
fn puppet_lit_from(azimuth: f32) -> SceneDoc {
    let puppet = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "p");
    let stage = StageDoc {
        floor: false,
        shadows: false,
        sun: SunDoc { azimuth, elevation: 5.0, illuminance: 8000.0, color: [1.0; 3] },
        ambient: marionette::formats::scene::AmbientDoc { color: [1.0; 3], brightness: 20.0 },
        background: BackgroundDoc::Transparent,
        ..StageDoc::default()
    };
    SceneDoc { characters: vec![puppet], stage, ..SceneDoc::default() }
}

/// The columns and rows the opaque pixels span.
fn silhouette(picture: &image::RgbaImage) -> (u32, u32, u32, u32) {
    let opaque: Vec<(u32, u32)> = picture.enumerate_pixels().filter(|p| p.2.0[3] > 128).map(|p| (p.0, p.1)).collect();
    assert!(!opaque.is_empty(), "nothing drawn");
    let xs = opaque.iter().map(|p| p.0);
    let ys = opaque.iter().map(|p| p.1);
    (xs.clone().min().unwrap(), xs.max().unwrap(), ys.clone().min().unwrap(), ys.max().unwrap())
}

/// The mean brightness of the opaque pixels left and right of the silhouette's middle.
fn halves(picture: &image::RgbaImage) -> (f64, f64) {
    let (x0, x1, ..) = silhouette(picture);
    let middle = (x0 + x1) as f64 / 2.0;
    let (mut sums, mut counts) = ([0.0; 2], [0.0; 2]);
    for (x, _, p) in picture.enumerate_pixels().filter(|p| p.2.0[3] == 255) {
        let side = usize::from(x as f64 > middle);
        sums[side] += p.0[..3].iter().map(|&c| c as f64).sum::<f64>() / 3.0;
        counts[side] += 1.0;
    }
    (sums[0] / counts[0], sums[1] / counts[1])
}

#[test]
fn the_sun_from_the_left_lights_the_left_halves_and_from_the_right_the_right() {
    let dir = scratch("shot-sun");
    // The front view looks along -z at the puppet: the picture's left is -x.
    let left = render(&scene_file(&dir, "left.ron", &puppet_lit_from(-90.0)), &["--view", "front"], &dir.join("l.png"));
    let right =
        render(&scene_file(&dir, "right.ron", &puppet_lit_from(90.0)), &["--view", "front"], &dir.join("r.png"));
    let ((ll, lr), (rl, rr)) = (halves(&left), halves(&right));
    assert!(ll > lr * 1.3, "sun from the left: left half {ll:.1}, right half {lr:.1}");
    assert!(rr > rl * 1.3, "sun from the right: left half {rl:.1}, right half {rr:.1}");
}

#[test]
fn a_transparent_picture_is_clear_around_the_characters_and_opaque_on_them() {
    let dir = scratch("shot-transparent");
    let mut doc = puppet_lit_from(30.0);
    doc.stage = StageDoc::default();
    let picture = render(&scene_file(&dir, "p.ron", &doc), &["--transparent", "--samples", "2"], &dir.join("t.png"));
    let (w, h) = picture.dimensions();
    assert_eq!((w, h), (64, 96), "supersampled, then averaged to the size asked for");
    for (x, y) in [(0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)] {
        assert_eq!(picture.get_pixel(x, y).0[3], 0, "corner ({x}, {y})");
    }
    let (x0, x1, y0, y1) = silhouette(&picture);
    let opaque = picture.pixels().filter(|p| p.0[3] == 255).count();
    assert!(opaque > 200, "{opaque} opaque pixels");
    // The chest, at the middle of the silhouette's width, a third of the way down.
    assert_eq!(picture.get_pixel((x0 + x1) / 2, y0 + (y1 - y0) / 3).0[3], 255);
}

/// Edges are multisampled unless the shot or `--antialias` says otherwise: over nothing, the
/// puppet's edge pixels are partly covered when multisampled and never without smoothing;
/// FXAA blends the edges of the finished picture (another picture than the unsmoothed one);
/// a scene whose shot says `Off` draws what `--antialias off` draws.
#[test]
fn edges_are_smoothed_as_the_shot_or_the_flag_asks() {
    let dir = scratch("shot-antialias");
    let mut doc = puppet_lit_from(30.0);
    let scene = scene_file(&dir, "p.ron", &doc);
    let drawn = |flags: &[&str], name: &str| render(&scene, flags, &dir.join(name));
    let partly_covered = |p: &image::RgbaImage| p.pixels().filter(|p| p.0[3] > 0 && p.0[3] < 255).count();
    let multisampled = drawn(&[], "m.png");
    let unsmoothed = drawn(&["--antialias", "off"], "o.png");
    let fxaa = drawn(&["--antialias", "fxaa"], "f.png");
    assert!(partly_covered(&multisampled) > 20, "{} edge pixels partly covered", partly_covered(&multisampled));
    assert_eq!(partly_covered(&unsmoothed), 0);
    assert!(fxaa != unsmoothed && fxaa != multisampled);
    doc.shot.antialias = marionette::formats::scene::Antialias::Off;
    let said_off = render(&scene_file(&dir, "off.ron", &doc), &[], &dir.join("s.png"));
    assert!(said_off == unsmoothed);
}

/// Sharp shadows have narrower edges than soft ones: against the same scene without
/// shadows, a sharp shadow darkens fewer pixels part of the way (its edge) for each pixel
/// it darkens fully (its core) than a soft one.
#[test]
fn sharp_shadows_have_narrower_edges_than_soft_ones() {
    let dir = scratch("shot-shadow-edges");
    let mut doc = puppet_lit_from(30.0);
    (doc.stage.floor, doc.stage.shadows, doc.stage.sun.elevation) = (true, true, 35.0);
    doc.stage.background = BackgroundDoc::Color([0.0, 0.0, 1.0]);
    let drawn = |doc: &SceneDoc, name: &str| {
        render(
            &scene_file(&dir, &format!("{name}.ron"), doc),
            &["--antialias", "off"],
            &dir.join(format!("{name}.png")),
        )
    };
    let soft = drawn(&doc, "soft");
    doc.stage.soft_shadows = false;
    let sharp = drawn(&doc, "sharp");
    doc.stage.shadows = false;
    let unshadowed = drawn(&doc, "unshadowed");
    // How much darker each pixel is than without shadows: the edge (a fifth to four fifths
    // of the deepest) against the core (beyond four fifths).
    let edge_per_core = |shadowed: &image::RgbaImage| {
        let dark: Vec<i32> = shadowed
            .pixels()
            .zip(unshadowed.pixels())
            .map(|(s, u)| (0..3).map(|c| i32::from(u.0[c]) - i32::from(s.0[c])).sum::<i32>())
            .collect();
        let deepest = *dark.iter().max().unwrap();
        let edge = dark.iter().filter(|&&d| d * 5 > deepest && d * 5 <= deepest * 4).count();
        let core = dark.iter().filter(|&&d| d * 5 > deepest * 4).count();
        assert!(core > 0, "no shadow drawn");
        edge as f64 / core as f64
    };
    assert!(soft != sharp);
    let (soft_edge, sharp_edge) = (edge_per_core(&soft), edge_per_core(&sharp));
    assert!(sharp_edge < soft_edge * 0.7, "edge pixels a core pixel: soft {soft_edge:.2}, sharp {sharp_edge:.2}");
}

#[test]
fn a_gradient_background_fills_behind_the_characters() {
    let dir = scratch("shot-gradient");
    let mut doc = puppet_lit_from(30.0);
    doc.stage.background = BackgroundDoc::Gradient { top: [1.0, 0.0, 0.0], bottom: [0.0, 0.0, 1.0] };
    let picture = render(&scene_file(&dir, "g.ron", &doc), &[], &dir.join("g.png"));
    let (top, bottom) = (picture.get_pixel(0, 0).0, picture.get_pixel(0, 95).0);
    assert_eq!((top[0], top[2], top[3]), (255, 0, 255), "red at the top");
    assert_eq!((bottom[0], bottom[2]), (0, 255), "blue at the bottom");
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn an_orthographic_front_view_draws_model1_at_one_size_whatever_the_distance() {
    let data = crate::common::data_dir();
    let dir = scratch("shot-ortho");
    let model = CharacterDoc::new(SourceDoc::File(data.join("mit6837/Model1.skel")), "m");
    let stage = StageDoc { floor: false, background: BackgroundDoc::Transparent, ..StageDoc::default() };
    let height_at = |distance: f32, ortho: Option<f32>| {
        let camera =
            CameraDoc { focus: glam::Vec3::ZERO, yaw: 0.0, pitch: 0.0, distance, ortho, ..CameraDoc::default() };
        let doc = SceneDoc {
            characters: vec![model.clone()],
            camera: Some(camera),
            stage: stage.clone(),
            ..SceneDoc::default()
        };
        let name = format!("{distance}-{}", ortho.is_some());
        let picture = render(&scene_file(&dir, &format!("{name}.ron"), &doc), &[], &dir.join(format!("{name}.png")));
        let (.., y0, y1) = silhouette(&picture);
        y1 - y0
    };
    let (near, far) = (height_at(4.0, Some(2.5)), height_at(8.0, Some(2.5)));
    assert_eq!(near, far, "orthographic: the same pixel height at 4 m and 8 m");
    let (near, far) = (height_at(4.0, None), height_at(8.0, None));
    assert!(near > far + far / 2, "perspective: nearer is larger ({near} against {far} pixels)");
}

#[test]
fn a_contact_sheet_shows_every_kept_pose_in_a_grid() {
    use marionette::formats::scene::LibraryPoseDoc;
    use marionette::rig::JointRotation;
    let dir = scratch("shot-sheet");
    let mut doc = puppet_lit_from(30.0);
    doc.camera =
        Some(CameraDoc { focus: glam::Vec3::new(0.0, 0.6, 0.0), pitch: 0.0, distance: 2.6, ..CameraDoc::default() });
    for (name, angle) in [("a raised", -2.2), ("b level", -1.4), ("c lowered", 0.0)] {
        let joints = [("r_shoulder".to_string(), JointRotation::euler_xyz(0.0, 0.0, angle))].into_iter().collect();
        doc.poses.insert(name.into(), LibraryPoseDoc { joints, thumbnail: Vec::new(), rig: None });
    }
    let scene = scene_file(&dir, "poses.ron", &doc);
    let sheet = render(&scene, &["--poses"], &dir.join("sheet.png"));
    assert_eq!(sheet.dimensions(), (128, 192), "three 64×96 cells in a 2×2 grid");
    let cell = |k: u32| image::imageops::crop_imm(&sheet, (k % 2) * 64, (k / 2) * 96, 64, 96).to_image();
    let differing =
        |a: &image::RgbaImage, b: &image::RgbaImage| a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
    for (a, b) in [(0, 1), (1, 2), (0, 2)] {
        assert!(differing(&cell(a), &cell(b)) > 20, "cells {a} and {b} differ");
    }
    assert!(cell(3).pixels().all(|p| p.0[3] == 0), "the fourth cell is empty");
    assert!(cell(0).pixels().any(|p| p.0[3] == 255), "a cell shows the puppet");
}

/// Each character's colours reach the picture from the skin materials' buffer, at its own
/// place (the vertex buffer holds positions only): a puppet tinted red beside one tinted
/// blue (skinned on the GPU, both in the one plain material), in the default light: red outweighs green and blue twice over in the left
/// one's pixels, blue outweighs red and green in the right one's. (Reading the wrong word
/// of the buffer for the colour fails it.)
#[test]
fn each_characters_colours_reach_the_picture_from_its_own_buffer() {
    use bevy::math::Vec3;
    use marionette::formats::scene::PlacementDoc;
    let dir = scratch("shot-tints");
    let mut doc = puppet_lit_from(30.0);
    doc.stage = StageDoc::default();
    let mut red = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "red");
    red.view.tint = [1.0, 0.0, 0.0];
    red.placement = PlacementDoc::new(Vec3::new(-0.7, 0.0, 0.0), 0.0, 1.0);
    let mut blue = CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "blue");
    blue.view.tint = [0.0, 0.0, 1.0];
    blue.placement = PlacementDoc::new(Vec3::new(0.7, 0.0, 0.0), 0.0, 1.0);
    blue.gpu_skinning = true;
    doc.characters = vec![red, blue];
    let flags = ["--transparent", "--view", "front"];
    let picture = render(&scene_file(&dir, "tints.ron", &doc), &flags, &dir.join("tints.png"));
    let (x0, x1, ..) = silhouette(&picture);
    let middle = (x0 + x1) / 2;
    let mut sums = [[0u64; 3]; 2];
    for (x, _, p) in picture.enumerate_pixels().filter(|p| p.2.0[3] == 255) {
        let side = usize::from(x > middle);
        (0..3).for_each(|c| sums[side][c] += u64::from(p.0[c]));
    }
    let [[r, g, b], [r2, g2, b2]] = sums;
    assert!(r > 2 * g.max(b), "the left puppet is red: {:?}", sums[0]);
    assert!(b2 > 2 * r2.max(g2), "the right puppet is blue: {:?}", sums[1]);
}

/// A reference picture behind the scene: filling the frame (its middle kept) or fitted
/// inside it with the sky around; the scene file keeps its path relative to its folder.
#[test]
fn a_reference_picture_fills_or_fits_behind_the_characters() {
    let dir = scratch("shot-reference");
    std::fs::create_dir_all(dir.join("refs")).unwrap();
    // Left half red, right half blue, square.
    let reference =
        image::RgbImage::from_fn(30, 30, |x, _| if x < 15 { image::Rgb([255, 0, 0]) } else { image::Rgb([0, 0, 255]) });
    reference.save(dir.join("refs/ref.png")).unwrap();
    let mut doc = puppet_lit_from(30.0);
    // Far away: a speck in the middle, the edges all background.
    doc.camera = Some(CameraDoc { focus: glam::Vec3::new(0.0, 0.5, 0.0), distance: 60.0, ..CameraDoc::default() });
    let near = |p: [u8; 4], want: [u8; 3]| p[..3].iter().zip(want).all(|(&a, b)| a.abs_diff(b) <= 2);
    let sky = marionette::formats::stage::SKY.map(|c| (c * 255.0).round() as u8);
    for fill in [true, false] {
        doc.stage.background = BackgroundDoc::Image { path: dir.join("refs/ref.png"), fill };
        let scene = scene_file(&dir, "r.ron", &doc);
        assert!(std::fs::read_to_string(&scene).unwrap().contains("\"refs/ref.png\""), "kept relative");
        let picture = render(&scene, &[], &dir.join(format!("r{fill}.png")));
        // 64×96: filled, the square is 96 high and its middle 64 columns show; fitted,
        // it is 64 square from row 16, the sky above and below.
        let (left, right) = (picture.get_pixel(1, 40).0, picture.get_pixel(62, 40).0);
        assert!(near(left, [255, 0, 0]) && near(right, [0, 0, 255]), "fill {fill}: {left:?} {right:?}");
        let top = picture.get_pixel(1, 4).0;
        assert!(near(top, if fill { [255, 0, 0] } else { sky }), "fill {fill}: the top {top:?}");
    }
    doc.stage.background = BackgroundDoc::Image { path: dir.join("refs/missing.png"), fill: false };
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["render", "--width", "64", "--height", "96", "--out"])
        .arg(dir.join("missing.png"))
        .arg(scene_file(&dir, "missing.ron", &doc))
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success() && said.contains("missing.png"), "{said}");
}
