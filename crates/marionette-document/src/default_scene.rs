//! The default scene, as generated into `assets/default_scene.ron` by
//! `marionette gen-assets`: two of the project's puppets greeting each other, and a third
//! shown as a skeleton with weight colours.

use std::collections::BTreeMap;

use marionette_formats::scene::{
    CameraDoc, CharacterDoc, DisplayDoc, PlacementDoc, SceneDoc, SourceDoc, StageDoc, ViewDoc,
};
use marionette_rig::JointRotation;

fn pose(specs: &[(&str, [f32; 3])]) -> BTreeMap<String, JointRotation> {
    specs.iter().map(|(j, [x, y, z])| (j.to_string(), JointRotation::euler_xyz(*x, *y, *z))).collect()
}

fn puppet(
    name: &str,
    translation: glam::Vec3,
    yaw: f32,
    pose: BTreeMap<String, JointRotation>,
    view: ViewDoc,
) -> CharacterDoc {
    CharacterDoc {
        placement: PlacementDoc::new(translation, yaw, 1.0),
        pose,
        view,
        ..CharacterDoc::new(SourceDoc::Embedded("puppet".into()), name)
    }
}

/// The default scene document.
pub fn generate() -> SceneDoc {
    // Left: waves with the right hand, weight on one leg.
    let waving = pose(&[
        ("l_shoulder", [0.0, 0.0, -1.25]),
        ("l_elbow", [0.0, -0.3, 0.0]),
        ("r_shoulder", [0.0, 0.0, -0.9]),
        ("r_elbow", [0.0, 0.0, -1.1]),
        ("head", [0.1, 0.3, 0.0]),
        ("l_hip", [-0.15, 0.0, 0.05]),
        ("l_knee", [0.3, 0.0, 0.0]),
    ]);
    // Right: reaches out a hand, stepping forward.
    let reaching = pose(&[
        ("l_shoulder", [0.0, 0.9, -0.5]),
        ("l_elbow", [0.0, 0.5, 0.0]),
        ("r_shoulder", [0.0, 0.0, 1.2]),
        ("r_elbow", [0.0, 0.3, 0.0]),
        ("spine", [0.1, 0.0, 0.0]),
        ("r_hip", [-0.5, 0.0, 0.0]),
        ("r_knee", [0.6, 0.0, 0.0]),
        ("r_ankle", [-0.1, 0.0, 0.0]),
        ("l_hip", [0.25, 0.0, 0.0]),
        ("head", [-0.1, -0.2, 0.0]),
    ]);
    // Behind: sits on the floor, hands on knees, in weight colours.
    let sitting = pose(&[
        ("pelvis", [0.0, 0.0, 0.0]),
        ("l_hip", [-1.45, 0.0, -0.15]),
        ("r_hip", [-1.45, 0.0, 0.15]),
        ("l_knee", [1.5, 0.0, 0.0]),
        ("r_knee", [1.5, 0.0, 0.0]),
        ("l_shoulder", [-0.6, 0.0, -1.1]),
        ("r_shoulder", [-0.6, 0.0, 1.1]),
        ("l_elbow", [0.0, -0.8, 0.0]),
        ("r_elbow", [0.0, 0.8, 0.0]),
        ("spine", [-0.15, 0.0, 0.0]),
    ]);
    let weights = ViewDoc { weight_colors: true, display: DisplayDoc::Both, ..ViewDoc::default() };
    let blue = ViewDoc { tint: [0.45, 0.6, 0.8], ..ViewDoc::default() };
    SceneDoc {
        characters: vec![
            puppet("Ada", glam::Vec3::new(-0.4, 0.0, 0.0), 0.9, waving, ViewDoc::default()),
            puppet("Bo", glam::Vec3::new(0.4, 0.0, 0.05), -0.9, reaching, blue),
            puppet("Cy", glam::Vec3::new(0.0, -0.29, -0.95), 0.0, sitting, weights),
        ],
        camera: Some(CameraDoc {
            focus: glam::Vec3::new(0.0, 0.42, -0.3),
            yaw: 0.0,
            pitch: -0.32,
            distance: 2.9,
            ..CameraDoc::default()
        }),
        stage: StageDoc::default(),
        poses: Default::default(),
        ..SceneDoc::default()
    }
}
