//! Skeleton view: a sphere at each joint and a box along each bone (a unit box scaled to
//! the bone's length, its z axis along the bone); CSE169 skeletons draw their own
//! `boxmin`/`boxmax` boxes. The selected joints are highlighted.

use bevy::prelude::*;

use crate::editor::scene_doc::document::SceneCharacter;
use crate::editor::state::Selection;
use crate::formats::scene::DisplayDoc;
use crate::rig::character::SkinKind;
use crate::scene::{Character, CharacterView, CurrentJointToWorld, Placement};

/// Skeleton gizmos draw over the meshes (they would be hidden inside them).
#[derive(Default, Reflect, GizmoConfigGroup)]
pub struct SkeletonGizmos;

/// Registers the skeleton gizmo group, drawn on top.
pub fn setup_skeleton_gizmos(app: &mut App) {
    app.init_gizmo_group::<SkeletonGizmos>();
    let mut store = app.world_mut().resource_mut::<GizmoConfigStore>();
    let (config, _) = store.config_mut::<SkeletonGizmos>();
    config.depth_bias = -1.0;
    config.line.width = 2.5;
}

const JOINT_COLOR: Color = Color::srgb(1.0, 0.85, 0.2);
const BONE_COLOR: Color = Color::srgb(0.92, 0.94, 1.0);
const SELECTED_COLOR: Color = Color::srgb(1.0, 0.15, 0.3);
const HOVER_COLOR: Color = Color::srgb(0.3, 1.0, 1.0);

/// Draws skeletons of characters in skeleton or both view, and the selected joints of
/// any character (reads joint matrices, `Selection`; draws gizmos).
pub fn draw_skeletons(
    characters: Query<(&Character, &CharacterView, &Placement, Option<&SceneCharacter>, &InheritedVisibility)>,
    joints: Query<&CurrentJointToWorld>,
    selection: Res<Selection>,
    hovered: Option<Res<crate::editor::state::HoveredJoint>>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    if let Some(hit) = hovered.as_ref().and_then(|h| h.0)
        && let Ok((character, _, placement, ..)) = characters.get(hit.entity)
    {
        let radius = (character_size(character) * placement.scale * 0.012).max(0.003);
        gizmos.sphere(Isometry3d::from_translation(hit.position), radius * 3.0, HOVER_COLOR);
    }
    for (character, view, placement, sc, visible) in &characters {
        if !visible.get() {
            continue;
        }
        let selected: &[usize] =
            if sc.is_some_and(|s| Some(s.id) == selection.character) { &selection.joints } else { &[] };
        let size = character_size(character) * placement.scale;
        let radius = (size * 0.012).max(0.003);
        let model_to_world = placement.to_mat4();
        let world = |j: usize| {
            model_to_world * character.joints.get(j).and_then(|&e| joints.get(e).ok()).map_or(Mat4::IDENTITY, |c| c.0)
        };
        for &j in selected {
            gizmos.sphere(Isometry3d::from_translation(world(j).w_axis.truncate()), radius * 2.2, SELECTED_COLOR);
        }
        if view.display == DisplayDoc::Mesh {
            continue;
        }
        let skeleton = &character.asset.skeleton;
        for j in 0..skeleton.len() {
            let m = world(j);
            let p = m.w_axis.truncate();
            gizmos.sphere(Isometry3d::from_translation(p), radius, JOINT_COLOR);
            if character.asset.skin_kind == SkinKind::BoneBoxes
                && let Some(b) = skeleton.joint(j).bone_box
            {
                let local = Mat4::from_scale_rotation_translation(
                    (b.max - b.min).max(Vec3::splat(1e-4)),
                    Quat::IDENTITY,
                    (b.min + b.max) / 2.0,
                );
                gizmos.cube(Transform::from_matrix(m * local), BONE_COLOR);
            } else if let Some(parent) = skeleton.parent(j) {
                let from = world(parent).w_axis.truncate();
                let length = from.distance(p);
                if length > 1e-6 {
                    // The classic recipe: a unit box in the bone's frame [u v w c], scaled to
                    // the bone's length along w.
                    let up = skeleton.parent(parent).map(|g| from - world(g).w_axis.truncate());
                    let frame = crate::rig::bind::bone_frame(from, p, up);
                    let thickness = (length * 0.12).min(radius * 1.5);
                    let scale = Mat4::from_scale(Vec3::new(thickness, thickness, length));
                    gizmos.cube(Transform::from_matrix(frame * scale), BONE_COLOR);
                }
            }
        }
    }
}

/// The diagonal of a character's bind mesh (model units).
pub fn character_size(character: &Character) -> f32 {
    let (lo, hi) = character.asset.bounds();
    (hi - lo).length().max(0.1)
}
