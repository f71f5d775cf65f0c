//! Limb handles in the viewport: for each arm and leg of a humanoid, a target its wrist or
//! ankle reaches and a pole its elbow or knee bends toward (two-bone IK), and a point the
//! head looks at. Drag one in the plane facing the camera: its limb is solved again (an
//! ordinary pose edit; the drag is one undo step). Handles not dragged stay where they
//! are, so the limbs they hold stay put when another is moved.

use bevy::prelude::*;

use crate::editor::edits::edit::EditQueue;
use crate::editor::edits::kinds;
use crate::editor::interact::picking::{JointPicker, PICK_RADIUS_PX};
use crate::editor::interact::pointer::{PointerOwner, ViewportHasPointer};
use crate::editor::present::draw::SkeletonGizmos;
use crate::editor::scene_doc::document::{HumanoidMapOf, SceneCharacter};
use crate::editor::state::{LimbHandle, LimbHandles};
use crate::formats::scene::CharacterId;
use crate::rig::humanoid::{HumanBone, HumanoidMap};
use crate::rig::{JointRotation, Skeleton};
use crate::scene::{Character, CurrentJointToWorld, JointPose, Placement};

pub struct LimbHandlesPlugin;

impl Plugin for LimbHandlesPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<LimbHandles>()
            .add_systems(
                Update,
                (grab_handle, drag_handle, solve_moved_handles)
                    .chain()
                    .before(crate::editor::interact::ik_drag::start_drag)
                    .in_set(crate::editor::order::EditorSystems::Drag),
            )
            .add_systems(PostUpdate, draw_limb_handles.in_set(crate::editor::order::EditorSystems::Present));
    }
}

/// The handles for a character as it stands: each limb's target at its wrist or ankle and
/// pole out from its elbow or knee (the way it bends, or ahead for a straight limb), and a
/// point a metre-and-a-half ahead of the head. `at` gives a joint's world position.
pub fn handles_of(
    id: CharacterId,
    skeleton: &Skeleton,
    map: &HumanoidMap,
    ahead: Vec3,
    at: impl Fn(usize) -> Vec3,
) -> Vec<LimbHandle> {
    let mut handles = Vec::new();
    for end in [HumanBone::LeftHand, HumanBone::RightHand, HumanBone::LeftFoot, HumanBone::RightFoot] {
        let Some(&end) = map.get(&end) else { continue };
        let Some(mid) = skeleton.parent(end) else { continue };
        let Some(root) = skeleton.parent(mid) else { continue };
        let (a, b, c) = (at(root), at(mid), at(end));
        let length = a.distance(b) + b.distance(c);
        let off_line = b - (a + c) / 2.0;
        let out = if off_line.length() > 1e-3 * length { off_line.normalize() } else { ahead };
        handles.push(LimbHandle::TwoBone { character: id, end, target: c, pole: b + out * length });
    }
    if let Some(&head) = map.get(&HumanBone::Head) {
        handles.push(LimbHandle::LookAt { character: id, head, target: at(head) + ahead * 1.5 });
    }
    handles
}

impl LimbHandle {
    pub fn character(&self) -> CharacterId {
        match self {
            LimbHandle::TwoBone { character, .. } | LimbHandle::LookAt { character, .. } => *character,
        }
    }

    /// Its points: the target, then the pole.
    fn points(&self) -> Vec<Vec3> {
        match self {
            LimbHandle::TwoBone { target, pole, .. } => vec![*target, *pole],
            LimbHandle::LookAt { target, .. } => vec![*target],
        }
    }

    fn point_mut(&mut self, k: usize) -> &mut Vec3 {
        match self {
            LimbHandle::TwoBone { target, pole, .. } => {
                if k == 0 {
                    target
                } else {
                    pole
                }
            }
            LimbHandle::LookAt { target, .. } => target,
        }
    }

    /// Poses its limb (or head) on `pose`: the limb's end at the target bending toward the
    /// pole, or the face toward the point. Returns the note on what the solve did.
    pub fn solve(
        &self,
        skeleton: &Skeleton,
        map: &HumanoidMap,
        pose: &mut [JointRotation],
        placement: Mat4,
    ) -> Option<String> {
        use crate::document::posing;
        match self {
            LimbHandle::TwoBone { end, target, pole, .. } => {
                let spec = posing::TwoBoneSpec {
                    joint: skeleton.joint(*end).name.clone(),
                    target: *target,
                    pole: Some(*pole),
                };
                let report = posing::apply_two_bone_specs(skeleton, pose, placement, &[spec]).ok()?.pop()?;
                Some(posing::describe_two_bone(skeleton, &report))
            }
            LimbHandle::LookAt { head, target, .. } => {
                let spec = posing::LookAtSpec { joint: skeleton.joint(*head).name.clone(), target: *target };
                let report = posing::apply_look_at_specs(skeleton, map, pose, placement, &[spec]).ok()?.pop()?;
                Some(posing::describe_look_at(skeleton, &report))
            }
        }
    }
}

/// Index of the handle point (handle, point) nearest `cursor` on the screen, within the
/// pick radius.
fn handle_at(handles: &LimbHandles, picker: &JointPicker, cursor: Vec2) -> Option<(usize, usize, Vec3)> {
    let (camera, transform) = picker.camera()?;
    handles
        .handles
        .iter()
        .enumerate()
        .flat_map(|(h, handle)| handle.points().into_iter().enumerate().map(move |(k, p)| (h, k, p)))
        .filter_map(|(h, k, p)| Some((h, k, p, camera.world_to_viewport(transform, p).ok()?.distance(cursor))))
        .filter(|&(.., d)| d <= PICK_RADIUS_PX)
        .min_by(|a, b| a.3.total_cmp(&b.3))
        .map(|(h, k, p, _)| (h, k, p))
}

/// On a left press on a handle, starts dragging it (before a joint drag could start; reads
/// input, handles; writes `LimbHandles`, `PointerOwner`).
fn grab_handle(
    buttons: Res<ButtonInput<MouseButton>>,
    picker: JointPicker,
    pointer: Res<ViewportHasPointer>,
    mut owner: ResMut<PointerOwner>,
    mut handles: ResMut<LimbHandles>,
) {
    if !buttons.just_pressed(MouseButton::Left) || !pointer.0 || owner.gizmo_holds_pointer || handles.handles.is_empty()
    {
        return;
    }
    let (Some(cursor), Some((_, transform))) = (picker.cursor(), picker.camera()) else { return };
    let Some((h, k, at)) = handle_at(&handles, &picker, cursor) else { return };
    handles.dragged = Some((h * 2 + k, at, transform.forward().as_vec3()));
    // The press is the handle's: no joint drag, no orbit.
    owner.gizmo_holds_pointer = true;
}

/// While the button is held, moves the dragged handle to the cursor in its plane; lets go
/// on release (reads input; writes `LimbHandles`).
fn drag_handle(buttons: Res<ButtonInput<MouseButton>>, picker: JointPicker, mut handles: ResMut<LimbHandles>) {
    let Some((slot, point, normal)) = handles.dragged else { return };
    if !buttons.pressed(MouseButton::Left) {
        handles.dragged = None;
        return;
    }
    let (Some(cursor), Some((camera, transform))) = (picker.cursor(), picker.camera()) else { return };
    let Ok(ray) = camera.viewport_to_world(transform, cursor) else { return };
    let denom = ray.direction.dot(normal);
    if denom.abs() < 1e-6 {
        return;
    }
    let moved_to = ray.origin + *ray.direction * ((point - ray.origin).dot(normal) / denom);
    let (h, k) = (slot / 2, slot % 2);
    if let Some(handle) = handles.handles.get_mut(h) {
        *handle.point_mut(k) = moved_to;
        if !handles.moved.contains(&h) {
            handles.moved.push(h);
        }
    }
}

/// Solves the limbs whose handles moved, each a pose edit (reads the characters; writes
/// `EditQueue`, `LimbHandles`).
fn solve_moved_handles(
    mut handles: ResMut<LimbHandles>,
    characters: Query<(&SceneCharacter, &Character, &Placement, Option<&HumanoidMapOf>)>,
    poses: Query<&JointPose>,
    mut edits: ResMut<EditQueue>,
    mut messages: ResMut<crate::editor::state::Messages>,
) {
    let moved = std::mem::take(&mut handles.moved);
    for h in moved {
        let Some(handle) = handles.handles.get(h) else { continue };
        let Some((_, character, placement, map)) = characters.iter().find(|c| c.0.id == handle.character()) else {
            continue;
        };
        let before: Vec<_> =
            character.joints.iter().map(|&e| poses.get(e).map_or(Default::default(), |p| p.0)).collect();
        let mut pose = before.clone();
        let map = map.map(|m| m.0.clone()).unwrap_or_default();
        let note = handle.solve(&character.asset.skeleton, &map, &mut pose, placement.to_mat4());
        if let Some(note) = note.filter(|n| n.contains("not reached") || n.contains("limit")) {
            messages.push(note);
        }
        if let Some(change) = kinds::Pose::change(handle.character(), &before, &pose) {
            edits.push(change);
        }
    }
}

/// Targets in green, poles in yellow (a line to the elbow or knee), look-at points in
/// magenta (a line from the head); the dragged one in red (draws gizmos).
fn draw_limb_handles(
    handles: Res<LimbHandles>,
    characters: Query<(&SceneCharacter, &Character, &Placement)>,
    joints: Query<&CurrentJointToWorld>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    for (h, handle) in handles.handles.iter().enumerate() {
        let Some((_, character, placement)) = characters.iter().find(|c| c.0.id == handle.character()) else {
            continue;
        };
        let at = |j: usize| Some(joints.get(*character.joints.get(j)?).ok()?.world_position(placement));
        let size = crate::editor::present::draw::character_size(character) * placement.scale * 0.025;
        let dragged = |k: usize| handles.dragged.is_some_and(|(slot, ..)| slot == h * 2 + k);
        let color = |k: usize, c: Color| if dragged(k) { Color::srgb(1.0, 0.1, 0.1) } else { c };
        match handle {
            LimbHandle::TwoBone { end, target, pole, .. } => {
                gizmos.sphere(Isometry3d::from_translation(*target), size, color(0, Color::srgb(0.2, 1.0, 0.3)));
                gizmos.sphere(Isometry3d::from_translation(*pole), size * 0.8, color(1, Color::srgb(1.0, 0.9, 0.1)));
                if let Some(mid) = character.asset.skeleton.parent(*end).and_then(at) {
                    gizmos.line(mid, *pole, Color::srgba(1.0, 0.9, 0.1, 0.6));
                }
            }
            LimbHandle::LookAt { head, target, .. } => {
                gizmos.sphere(Isometry3d::from_translation(*target), size, color(0, Color::srgb(1.0, 0.2, 0.9)));
                if let Some(head) = at(*head) {
                    gizmos.line(head, *target, Color::srgba(1.0, 0.2, 0.9, 0.6));
                }
            }
        }
    }
}
