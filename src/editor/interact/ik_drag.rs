//! Posing by dragging: grab a joint in the viewport and move it in the plane facing the
//! camera; FABRIK moves its chain every frame (for a non-leaf joint this turns its parent
//! towards the cursor). Pinned joints (P) hold their place meanwhile. Each frame's solve is
//! an ordinary pose `Edit`, applied in `Animate`; the whole drag is one undo step.

use crate::editor::edits::kinds;
use bevy::prelude::*;

use crate::editor::edits::edit::EditQueue;
use crate::editor::interact::picking::{CLICK_SLOP_PX, JointPicker, PICK_RADIUS_PX};
use crate::editor::interact::pointer::{PointerOwner, ViewportHasPointer};
use crate::editor::present::draw::SkeletonGizmos;
use crate::editor::scene_doc::document::SceneCharacter;
use crate::editor::state::Pins;
use crate::editor::state::{Drag, JointDrag, Selection};
use crate::rig::ik::{IK_ROUNDS, IK_TOLERANCE};
use crate::rig::ik::{IkGoal, solve_ik};
use crate::scene::{Character, CurrentJointToWorld, JointPose, Placement};

pub struct IkDragPlugin;

impl Plugin for IkDragPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<JointDrag>()
            .init_resource::<Pins>()
            .add_systems(
                Update,
                (toggle_pins, start_drag, drag_joint).chain().in_set(crate::editor::order::EditorSystems::Drag),
            )
            .add_systems(
                PostUpdate,
                (draw_handles, draw_dragged_chain).in_set(crate::editor::order::EditorSystems::Present),
            );
    }
}

/// P pins or unpins the selected joints (reads keys, `Selection`; writes `Pins`).
fn toggle_pins(
    keys: Res<ButtonInput<KeyCode>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    mut pins: ResMut<Pins>,
) {
    if !keys.just_pressed(KeyCode::KeyP) || wants.is_some_and(|w| w.wants_any_keyboard_input()) {
        return;
    }
    let Some(id) = selection.character else { return };
    let list = pins.0.entry(id).or_default();
    for &j in &selection.joints {
        match list.iter().position(|&p| p == j) {
            Some(k) => {
                list.remove(k);
            }
            None => list.push(j),
        }
    }
}

/// On a left press near a joint, starts dragging it (reads input, joints; writes
/// `JointDrag`).
pub fn start_drag(
    buttons: Res<ButtonInput<MouseButton>>,
    picker: JointPicker,
    pointer: Res<ViewportHasPointer>,
    pins: Res<Pins>,
    owner: Res<PointerOwner>,
    mut drag: ResMut<JointDrag>,
) {
    if !buttons.just_pressed(MouseButton::Left) || !pointer.0 || owner.gizmo_holds_pointer {
        return;
    }
    let (Some(cursor), Some((_, camera_transform))) = (picker.cursor(), picker.camera()) else { return };
    let Some(hit) = picker.joint_at(cursor, PICK_RADIUS_PX * 0.5) else { return };
    let (id, joint, at) = (hit.id, hit.joint, hit.position);
    let Ok((_, _, character, placement, _)) = picker.characters.get(hit.entity) else { return };
    if character.asset.skeleton.parent(joint).is_none() {
        return;
    }
    let pins = pins.0.get(&id).map_or(Vec::new(), |list| {
        list.iter()
            .filter(|&&p| p != joint)
            .filter_map(|&p| Some((p, picker.joints.get(*character.joints.get(p)?).ok()?.world_position(placement))))
            .collect()
    });
    drag.active = Some(Drag {
        character: id,
        joint,
        plane_point: at,
        plane_normal: camera_transform.forward().as_vec3(),
        pins,
        pressed_at: cursor,
        moved: false,
    });
}

/// While the button is held, moves the dragged joint to the cursor in its plane by IK;
/// ends the drag on release (reads input, poses; writes `EditQueue`, `JointDrag`).
fn drag_joint(
    buttons: Res<ButtonInput<MouseButton>>,
    picker: JointPicker,
    characters: Query<(&SceneCharacter, &Character, &Placement)>,
    poses: Query<&JointPose>,
    mut edits: ResMut<EditQueue>,
    mut drag: ResMut<JointDrag>,
    mut selection: ResMut<Selection>,
) {
    let Some(active) = drag.active.clone() else { return };
    if !buttons.pressed(MouseButton::Left) {
        drag.active = None;
        return;
    }
    let (Some(cursor), Some((camera, camera_transform))) = (picker.cursor(), picker.camera()) else { return };
    if !active.moved {
        if cursor.distance(active.pressed_at) <= CLICK_SLOP_PX {
            return;
        }
        if let Some(d) = drag.active.as_mut() {
            d.moved = true;
        }
    }
    let Ok(ray) = camera.viewport_to_world(camera_transform, cursor) else { return };
    let denom = ray.direction.dot(active.plane_normal);
    if denom.abs() < 1e-6 {
        return;
    }
    let t = (active.plane_point - ray.origin).dot(active.plane_normal) / denom;
    let target = ray.origin + *ray.direction * t;
    let Some((_, character, placement)) = characters.iter().find(|c| c.0.id == active.character) else { return };
    if selection.character != Some(active.character) || selection.joints.first() != Some(&active.joint) {
        *selection = Selection { character: Some(active.character), joints: vec![active.joint] };
    }
    let skeleton = &character.asset.skeleton;
    let before: Vec<_> = character.joints.iter().map(|&e| poses.get(e).map_or(Default::default(), |p| p.0)).collect();
    let mut pose = before.clone();
    let mut goals = vec![IkGoal { end: active.joint, target }];
    goals.extend(active.pins.iter().map(|&(end, target)| IkGoal { end, target }));
    let reports = solve_ik(skeleton, &mut pose, placement.to_mat4(), &goals, IK_TOLERANCE, IK_ROUNDS.min(8));
    drag.note = reports.first().map(|r| crate::document::posing::describe_ik(skeleton, r)).unwrap_or_default();
    if let Some(change) = kinds::Pose::change(active.character, &before, &pose) {
        edits.push(change);
    }
}

/// Handles on the leaf joints of the selected character, pins in orange, the dragged joint
/// in red (draws gizmos).
fn draw_handles(
    selection: Res<Selection>,
    pins: Res<Pins>,
    drag: Res<JointDrag>,
    characters: Query<(&SceneCharacter, &Character, &Placement)>,
    joints: Query<&CurrentJointToWorld>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    for (sc, character, placement) in &characters {
        let pinned = pins.0.get(&sc.id);
        let selected = selection.character == Some(sc.id);
        if !selected && pinned.is_none_or(|p| p.is_empty()) {
            continue;
        }
        let size = crate::editor::present::draw::character_size(character) * 0.02;
        let skeleton = &character.asset.skeleton;
        for j in 0..skeleton.len() {
            let is_pin = pinned.is_some_and(|p| p.contains(&j));
            let is_leaf = skeleton.children(j).is_empty();
            if !(is_pin || (selected && is_leaf)) {
                continue;
            }
            let Ok(m) = joints.get(character.joints[j]) else { continue };
            let dragged = drag.active.as_ref().is_some_and(|d| d.character == sc.id && d.joint == j);
            let color = if dragged {
                Color::srgb(1.0, 0.1, 0.1)
            } else if is_pin {
                Color::srgb(1.0, 0.55, 0.0)
            } else {
                Color::srgb(0.2, 0.9, 1.0)
            };
            gizmos.cube(Transform::from_translation(m.world_position(placement)).with_scale(Vec3::splat(size)), color);
        }
    }
}

/// While a joint is dragged, the chain IK moves (from the joint up to its sub-base) is
/// drawn in red, as the exercise plots it (draws gizmos).
fn draw_dragged_chain(
    drag: Res<JointDrag>,
    characters: Query<(&SceneCharacter, &Character, &Placement)>,
    joints: Query<&CurrentJointToWorld>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    let Some(active) = drag.active.as_ref().filter(|d| d.moved) else { return };
    let Some((_, character, placement)) = characters.iter().find(|c| c.0.id == active.character) else { return };
    let world = |j: usize| Some(joints.get(*character.joints.get(j)?).ok()?.world_position(placement));
    let chain: Vec<Vec3> = crate::rig::ik::chain_to_sub_base(&character.asset.skeleton, active.joint)
        .into_iter()
        .filter_map(world)
        .collect();
    let radius = crate::editor::present::draw::character_size(character) * placement.scale * 0.02;
    for pair in chain.windows(2) {
        gizmos.line(pair[0], pair[1], CHAIN_COLOR);
    }
    for &p in &chain {
        gizmos.sphere(Isometry3d::from_translation(p), radius, CHAIN_COLOR);
    }
}

/// The colour of the joints a drag moves (the IK chain, what a gizmo turns).
pub const CHAIN_COLOR: Color = Color::srgb(1.0, 0.1, 0.1);
