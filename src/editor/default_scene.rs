//! The embedded default scene: two of the project's puppets greeting each other.

use std::sync::Arc;

use glam::Vec3;

use super::Placed;
use crate::posing::{PoseSpec, apply_pose_specs};
use crate::puppet::embedded_puppet;
use crate::scene::Placement;

/// The characters of the default scene, posed.
pub fn characters() -> Vec<Placed> {
    let puppet = Arc::new(embedded_puppet());
    let pose = |specs: &[(&str, [f32; 3])]| {
        let mut pose = puppet.skeleton.initial_pose();
        let specs: Vec<PoseSpec> = specs.iter().map(|(j, a)| PoseSpec { joint: j.to_string(), angles: Vec3::from(*a) }).collect();
        apply_pose_specs(&puppet.skeleton, &mut pose, &specs).expect("the default poses name puppet joints");
        pose
    };
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
    vec![
        (puppet.clone(), Placement { translation: Vec3::new(-0.4, 0.0, 0.0), yaw: 0.9, scale: 1.0 }, waving),
        (puppet, Placement { translation: Vec3::new(0.4, 0.0, 0.05), yaw: -0.9, scale: 1.0 }, reaching),
    ]
}
