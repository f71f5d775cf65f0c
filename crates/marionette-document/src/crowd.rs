//! Crowds as scene documents: SMPL bodies with their own β, clip and blend, all playing
//! (or puppets), on a square grid. Used by `marionette bench`, the editor's "Add crowd"
//! and the shipped crowd scene.

use std::path::Path;

use glam::Vec3;

use marionette_formats::scene::{CharacterDoc, PlacementDoc, SceneDoc, SmplDoc, SourceDoc};

/// Where the `i`-th of `n` characters stands: a square grid `spacing` apart, centred.
fn grid(i: usize, n: usize, spacing: f32) -> Vec3 {
    let side = (n as f32).sqrt().ceil().max(1.0) as usize;
    let (row, col) = (i / side, i % side);
    let half = (side - 1) as f32 / 2.0;
    Vec3::new((col as f32 - half) * spacing, 0.0, (row as f32 - half) * spacing)
}

fn crowd_member(i: usize, n: usize, source: SourceDoc, spacing: f32, lift: f32, smpl: Option<SmplDoc>) -> CharacterDoc {
    CharacterDoc {
        placement: PlacementDoc::new(grid(i, n, spacing) + Vec3::Y * lift, 0.0, 1.0),
        smpl,
        ..CharacterDoc::new(source, format!("crowd {i}"))
    }
}

/// `n` SMPL bodies, each with its own β and clip (every third blends a second clip), all
/// playing from different times.
/// A folder without SMPL clips to play.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: expected SMPL clips (smpl_quaternions_*.txt), found none", .0.display())]
pub struct NoClips(pub std::path::PathBuf);

pub fn smpl_crowd(dir: &Path, n: usize) -> Result<SceneDoc, NoClips> {
    let clips: Vec<String> = marionette_formats::smpl::clip_paths(dir)
        .iter()
        .filter_map(|p| Some(p.file_name()?.to_string_lossy().into_owned()))
        .collect();
    if clips.is_empty() {
        return Err(NoClips(dir.to_owned()));
    }
    let characters = (0..n)
        .map(|i| {
            let state = SmplDoc {
                betas: (0..10).map(|k| (((i * 7 + k * 3) % 11) as f32 - 5.0) * 0.3).collect(),
                clip: Some(clips[i % clips.len()].clone()),
                time: crate::motion::smpl_frame_time(i * 13 % 60),
                playing: true,
                blend_clip: (i % 3 == 0).then(|| clips[(i + 1) % clips.len()].clone()),
                blend: if i % 3 == 0 { 0.5 } else { 0.0 },
                ..SmplDoc::default()
            };
            crowd_member(i, n, SourceDoc::File(dir.to_path_buf()), 1.2, 1.2, Some(state))
        })
        .collect();
    Ok(SceneDoc { characters, ..SceneDoc::default() })
}

/// The crowd scene shipped in `assets/crowd_scene.ron`: 64 puppets (open it with
/// `marionette edit assets/crowd_scene.ron`; "Add crowd" with an SMPL folder makes playing ones).
pub fn shipped_crowd() -> SceneDoc {
    let mut doc = puppet_crowd(64);
    doc.camera = Some(marionette_formats::scene::CameraDoc {
        fov: 45.0,
        ortho: None,
        focus: Vec3::new(0.0, 0.4, 0.0),
        yaw: 0.6,
        pitch: -0.45,
        distance: 9.0,
    });
    doc
}

/// `n` puppets on a grid, each turned, tinted and posed a little differently.
pub fn puppet_crowd(n: usize) -> SceneDoc {
    use marionette_rig::JointRotation;
    let characters = (0..n)
        .map(|i| {
            let mut c = crowd_member(i, n, SourceDoc::Embedded("puppet".into()), 0.8, 0.0, None);
            let k = |m: usize| (i % m) as f32;
            c.placement.yaw = (k(7) - 3.0) * 0.25;
            c.view.tint = [0.55 + 0.08 * k(5), 0.5 + 0.06 * k(4), 0.45 + 0.1 * k(3)];
            c.pose = [
                ("head", JointRotation::euler_xyz(0.1, (k(5) - 2.0) * 0.2, 0.0)),
                ("l_shoulder", JointRotation::euler_xyz(0.0, 0.0, -0.3 - 0.25 * k(5))),
                ("r_shoulder", JointRotation::euler_xyz(0.0, 0.0, -0.2 - 0.2 * k(4))),
                ("l_elbow", JointRotation::euler_xyz(0.0, -0.2 * k(3), 0.0)),
                ("r_elbow", JointRotation::euler_xyz(0.0, 0.0, -0.3 * k(4))),
                ("l_hip", JointRotation::euler_xyz(-0.1 * k(3), 0.0, 0.05)),
                ("l_knee", JointRotation::euler_xyz(0.15 * k(3), 0.0, 0.0)),
            ]
            .into_iter()
            .map(|(joint, rotation)| (joint.to_string(), rotation))
            .collect();
            c
        })
        .collect();
    SceneDoc { characters, ..SceneDoc::default() }
}
