//! Side by side by bounds, and matching heights: boxes never overlap, heights end equal.

use bevy::prelude::*;
use marionette::editor::ScenePlugin;
use marionette::editor::scene_doc::arrange::{ArrangeWhenSkinned, beside, side_by_side, world_box};
use marionette::editor::scene_doc::document::{PendingScene, SceneCharacter};
use marionette::formats::scene::{CharacterDoc, PlacementDoc, SceneDoc, SourceDoc};
use marionette::scene::{Placement, SkinScratch};

use crate::editor::doc_with;

/// Boxes of different sizes and offsets (not centred on their origins), with scales.
fn boxes() -> (Vec<(Vec3, Vec3)>, Vec<f32>) {
    let boxes = vec![
        (Vec3::new(-0.4, 0.0, -0.2), Vec3::new(0.5, 1.8, 0.3)),
        (Vec3::new(2.0, -1.0, 5.0), Vec3::new(2.3, -0.1, 5.2)),
        (Vec3::new(-8.0, 3.0, -1.0), Vec3::new(9.0, 20.0, 4.0)),
        (Vec3::new(-0.05, 0.0, 0.0), Vec3::new(0.05, 0.1, 0.02)),
    ];
    (boxes, vec![1.0, 3.0, 0.1, 12.0])
}

fn disjoint_in_x(a: (Vec3, Vec3), b: (Vec3, Vec3)) -> bool {
    a.1.x < b.0.x || b.1.x < a.0.x
}

fn placed(boxes: &[(Vec3, Vec3)], scales: &[f32], translations: &[Vec3]) -> Vec<(Vec3, Vec3)> {
    boxes
        .iter()
        .zip(scales)
        .zip(translations)
        .map(|(((lo, hi), &scale), &translation)| world_box(*lo, *hi, &PlacementDoc::new(translation, 0.0, scale)))
        .collect()
}

#[test]
fn characters_side_by_side_never_overlap_and_stand_on_the_floor() {
    let (boxes, scales) = boxes();
    let world = placed(&boxes, &scales, &side_by_side(&boxes, &scales));
    for (i, a) in world.iter().enumerate() {
        assert!(a.0.y.abs() < 1e-5, "standing on the floor: {a:?}");
        assert!((a.0.z + a.1.z).abs() < 1e-4, "centred in z: {a:?}");
        for b in &world[i + 1..] {
            assert!(a.1.x < b.0.x, "in order, a gap apart: {a:?} {b:?}");
        }
    }
    let (left, right) = (world[0].0.x, world.last().unwrap().1.x);
    assert!((left + right).abs() < 1e-3, "centred on the origin: {left} .. {right}");
}

#[test]
fn an_added_character_stands_beside_every_other_even_turned_ones() {
    let (boxes, scales) = boxes();
    let mut world: Vec<(Vec3, Vec3)> = boxes
        .iter()
        .zip(&scales)
        .enumerate()
        .map(|(i, ((lo, hi), &scale))| {
            let placement = PlacementDoc::new(Vec3::new(i as f32 * 0.7, 0.0, 0.0), 0.4 * i as f32, scale);
            world_box(*lo, *hi, &placement)
        })
        .collect();
    for (k, ((lo, hi), &scale)) in boxes.iter().zip(&scales).enumerate() {
        let translation = beside(&world, *lo, *hi, scale);
        let new = world_box(*lo, *hi, &PlacementDoc::new(translation, 0.0, scale));
        assert!(world.iter().all(|&w| disjoint_in_x(w, new)), "added {k} overlaps");
        assert!(new.0.y.abs() < 1e-5);
        world.push(new);
    }
    let first = beside(&[], boxes[0].0, boxes[0].1, 1.0);
    let alone = world_box(boxes[0].0, boxes[0].1, &PlacementDoc::new(first, 0.0, 1.0));
    assert!((alone.0.x + alone.1.x).abs() < 1e-5, "the first stands at the origin");
}

/// Puppets of three scales, opened as `--match-height` opens character files: once
/// skinned, every one is as tall as the first (to 1e-5), and none overlaps another.
#[test]
fn match_height_makes_heights_equal_and_the_row_does_not_overlap() {
    let mut app = crate::ecs::app();
    app.add_plugins(ScenePlugin);
    let one = doc_with(SourceDoc::Embedded("puppet".into()), &[]).characters[0].clone();
    let characters = [0.7f32, 2.5, 0.2]
        .iter()
        .map(|&scale| CharacterDoc { placement: PlacementDoc::new(Vec3::ZERO, 0.3, scale), ..one.clone() })
        .collect();
    let doc = SceneDoc { characters, ..SceneDoc::default() };
    *app.world_mut().resource_mut::<PendingScene>() = PendingScene { doc: Some(doc), frame: false };
    *app.world_mut().resource_mut::<ArrangeWhenSkinned>() =
        ArrangeWhenSkinned { side_by_side: true, match_height: true };
    for _ in 0..3 {
        app.update();
    }
    let mut stood: Vec<_> = app
        .world_mut()
        .query::<(&SceneCharacter, &Placement, &SkinScratch)>()
        .iter(app.world())
        .map(|(sc, p, s)| (sc.id, world_box(s.bounds.0, s.bounds.1, &p.0)))
        .collect();
    stood.sort_by_key(|s| s.0);
    let heights: Vec<f32> = stood.iter().map(|(_, b)| b.1.y - b.0.y).collect();
    assert_eq!(heights.len(), 3);
    for h in &heights {
        assert!((h - heights[0]).abs() < 1e-5 * heights[0].max(1.0), "{heights:?}");
    }
    for (i, a) in stood.iter().enumerate() {
        for b in &stood[i + 1..] {
            assert!(disjoint_in_x(a.1, b.1), "{a:?} overlaps {b:?}");
        }
    }
    assert!(!app.world().resource::<ArrangeWhenSkinned>().match_height, "done once");
}

/// Framing a box with Bevy's default perspective (45° vertically) at several aspects:
/// every corner is in the picture, and the box covers at least 60 % of the picture's width
/// or of its height.
#[test]
fn framing_sees_every_corner_and_fills_most_of_the_picture() {
    use bevy::camera::CameraProjection;
    use marionette::editor::state::camera::OrbitCamera;
    let boxes = [
        (Vec3::new(-0.5, 0.0, -0.3), Vec3::new(0.5, 1.8, 0.3)),
        (Vec3::new(-8.0, 0.0, -2.0), Vec3::new(8.0, 1.0, 2.0)),
        (Vec3::new(3.0, -1.0, 4.0), Vec3::new(3.2, 9.0, 4.1)),
    ];
    for (lo, hi) in boxes {
        for aspect in [0.6f32, 1.0, 16.0 / 9.0, 3.0] {
            let orbit = OrbitCamera::framing(lo, hi, aspect);
            let view = orbit.transform().to_matrix().inverse();
            let projection = PerspectiveProjection { aspect_ratio: aspect, ..Default::default() };
            let clip = projection.get_clip_from_view() * view;
            let ndc: Vec<Vec3> = (0..8)
                .map(|i| {
                    let pick = |bit: usize, a: f32, b: f32| if i >> bit & 1 == 0 { a } else { b };
                    Vec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z))
                })
                .map(|c| clip.project_point3(c))
                .collect();
            for p in &ndc {
                assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{lo} {hi} at {aspect}: a corner at {p} is outside");
            }
            let span = |f: fn(&Vec3) -> f32| {
                ndc.iter().map(f).fold(f32::NEG_INFINITY, f32::max) - ndc.iter().map(f).fold(f32::INFINITY, f32::min)
            };
            // NDC spans 2 across: the share of the picture's width and of its height the box
            // covers; its larger side must cover at least 60 % of the picture that way.
            let fill = (span(|p| p.x) / 2.0).max(span(|p| p.y) / 2.0);
            assert!(fill >= 0.6, "{lo} {hi} at {aspect}: fills {fill:.2}");
        }
    }
}

/// The characters of one glTF file stand as one (keeping the file's layout); every other
/// character stands alone, even one from the same non-glTF file.
#[test]
fn characters_of_one_gltf_file_are_placed_together() {
    use marionette::editor::scene_doc::arrange::{gltf_file, one_file_groups};
    use marionette::formats::scene::SourceDoc;
    let glb = std::path::PathBuf::from("pair.glb");
    let sources = [
        SourceDoc::File(glb.clone()),
        SourceDoc::Embedded("puppet".into()),
        SourceDoc::Part(glb.clone(), 1),
        SourceDoc::File("Model1.skel".into()),
        SourceDoc::File("Model1.skel".into()),
        SourceDoc::Part(glb, 2),
    ];
    let files: Vec<_> = sources.iter().map(gltf_file).collect();
    assert_eq!(one_file_groups(&files), vec![vec![0, 2, 5], vec![1], vec![3], vec![4]]);
}
