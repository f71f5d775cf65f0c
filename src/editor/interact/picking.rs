//! Clicking a joint (or the mesh near it) in the viewport selects that joint.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;
use bevy::window::PrimaryWindow;

use crate::editor::interact::pointer::{PointerOwner, ViewportHasPointer};
use crate::editor::scene_doc::document::SceneCharacter;
use crate::editor::state::Selection;
use crate::editor::state::camera::OrbitCamera;
use crate::editor::state::{HoveredJoint, JointHit};
use crate::formats::scene::CharacterId;
use crate::scene::{Character, CurrentJointToWorld, Placement};

/// Where the left button went down, to tell a click from a drag.
#[derive(Resource, Default)]
pub struct PointerPress(pub Option<Vec2>);

/// What every pick in the viewport reads: the window's cursor, the orbit camera and the
/// joints that can be picked.
#[derive(SystemParam)]
pub struct JointPicker<'w, 's> {
    windows: Query<'w, 's, &'static Window, With<PrimaryWindow>>,
    cameras: Query<'w, 's, (&'static Camera, &'static GlobalTransform), With<OrbitCamera>>,
    pub characters: PickableCharacters<'w, 's>,
    pub joints: Query<'w, 's, &'static CurrentJointToWorld>,
    skins: Query<'w, 's, &'static crate::scene::SkinScratch>,
}

impl JointPicker<'_, '_> {
    /// The cursor in window pixels, when it is over the window.
    pub fn cursor(&self) -> Option<Vec2> {
        self.windows.single().ok()?.cursor_position()
    }

    /// The orbit camera.
    pub fn camera(&self) -> Option<(&Camera, &GlobalTransform)> {
        self.cameras.single().ok()
    }

    /// The visible character (or prop) whose skin is nearest the camera under `cursor`.
    pub fn character_at(&self, cursor: Vec2) -> Option<CharacterId> {
        let (camera, camera_transform) = self.camera()?;
        let ray = camera.viewport_to_world(camera_transform, cursor).ok()?;
        self.characters
            .iter()
            .filter(|c| c.4.get())
            .filter_map(|(entity, sc, character, placement, _)| {
                // The ray in model space keeps its parameter: t there is t in the world.
                let to_model = placement.to_mat4().inverse();
                let (origin, direction) =
                    (to_model.transform_point3(ray.origin), to_model.transform_vector3(*ray.direction));
                let skin = self.skins.get(entity).ok()?;
                let t = crate::rig::triangle_tree::first_hit(
                    &skin.positions,
                    &character.asset.skin.triangles,
                    origin,
                    direction,
                )?;
                Some((t, sc.id))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, id)| id)
    }

    /// The visible joint nearest to `cursor` on screen, within `radius` pixels.
    pub fn joint_at(&self, cursor: Vec2, radius: f32) -> Option<JointHit> {
        let (camera, camera_transform) = self.camera()?;
        nearest_joint_on_screen(camera, camera_transform, cursor, radius, &self.characters, &self.joints)
    }
}

/// Finds the joint under the cursor while nothing is held or dragged (reads input, joint
/// matrices; writes `HoveredJoint`).
pub fn hover_joint(
    buttons: Res<ButtonInput<MouseButton>>,
    picker: JointPicker,
    pointer: Res<ViewportHasPointer>,
    drag: Res<crate::editor::state::JointDrag>,
    mut hovered: ResMut<HoveredJoint>,
) {
    let hit = (pointer.0 && drag.active.is_none() && buttons.get_pressed().next().is_none())
        .then(|| picker.joint_at(picker.cursor()?, PICK_RADIUS_PX * 0.5))
        .flatten();
    let changed = match (&hovered.0, &hit) {
        (Some(a), Some(b)) => a.entity != b.entity || a.joint != b.joint || a.position != b.position,
        (None, None) => false,
        _ => true,
    };
    if changed {
        hovered.0 = hit;
    }
}

/// Screen distance (pixels) within which a click picks a joint.
pub const PICK_RADIUS_PX: f32 = 40.0;

/// How far (pixels) the cursor may move between press and release for a click; a drag
/// starts beyond it.
pub const CLICK_SLOP_PX: f32 = 4.0;

/// On a left click (press and release within a few pixels) in the viewport, selects the
/// visible joint nearest to the cursor on screen, else the character whose skin is under
/// it (none: nothing selected); Shift or Ctrl adds joints to the selection (reads input,
/// joint matrices, skins; writes `Selection`).
pub fn pick_joint_on_click(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    picker: JointPicker,
    pointer: Res<ViewportHasPointer>,
    owner: Res<PointerOwner>,
    mut press: ResMut<PointerPress>,
    mut selection: ResMut<Selection>,
) {
    let cursor = picker.cursor();
    if owner.gizmo_holds_pointer || owner.gizmo_typing {
        // The press turns the joint (or applies a typed turn): no pick.
        press.0 = None;
        return;
    }
    if buttons.just_pressed(MouseButton::Left) {
        press.0 = cursor.filter(|_| pointer.0);
    }
    if !buttons.just_released(MouseButton::Left) {
        return;
    }
    let (Some(start), Some(cursor)) = (press.0.take(), cursor) else {
        return;
    };
    if start.distance(cursor) > CLICK_SLOP_PX {
        return;
    }
    let best = picker.joint_at(cursor, PICK_RADIUS_PX);
    let additive =
        keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight, KeyCode::ControlLeft, KeyCode::ControlRight]);
    match best {
        Some(hit) => select_joint(&mut selection, hit.id, hit.joint, additive),
        // A click on a character's (or prop's) skin selects it, without joints: its move gizmo.
        None if !additive => *selection = Selection { character: picker.character_at(cursor), joints: Vec::new() },
        None => {}
    }
}

/// The characters whose joints can be picked: with their placement (joint matrices are
/// in model space) and whether they are shown.
pub type PickableCharacters<'w, 's> = Query<
    'w,
    's,
    (Entity, &'static SceneCharacter, &'static Character, &'static Placement, &'static InheritedVisibility),
>;

/// The visible joint nearest to `cursor` on screen, within `radius` pixels; deeper joints
/// win ties (zero-length bones stack joints on one point).
pub fn nearest_joint_on_screen(
    camera: &Camera,
    camera_transform: &GlobalTransform,
    cursor: Vec2,
    radius: f32,
    characters: &PickableCharacters,
    joints: &Query<&CurrentJointToWorld>,
) -> Option<JointHit> {
    let mut best: Option<(f32, JointHit)> = None;
    for (entity, sc, character, placement, visible) in characters {
        if !visible.get() {
            continue;
        }
        for (j, &e) in character.joints.iter().enumerate() {
            let Ok(m) = joints.get(e) else { continue };
            let position = m.world_position(placement);
            let Ok(screen) = camera.world_to_viewport(camera_transform, position) else { continue };
            let d = screen.distance(cursor);
            if d < radius && best.is_none_or(|b| d < b.0 - 0.5) {
                best = Some((d, JointHit { entity, id: sc.id, joint: j, position }));
            }
        }
    }
    best.map(|b| b.1)
}

/// Selects joint `j` of character `id`; `additive` toggles it within the selection.
pub fn select_joint(selection: &mut Selection, id: CharacterId, j: usize, additive: bool) {
    if selection.character != Some(id) || !additive {
        selection.character = Some(id);
        selection.joints = vec![j];
    } else if let Some(k) = selection.joints.iter().position(|&x| x == j) {
        selection.joints.remove(k);
    } else {
        selection.joints.push(j);
    }
}
