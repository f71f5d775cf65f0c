//! The rotation gizmo on the selected joint: a ring per DOF axis (the same x/y/z as its
//! sliders, drawn about the axes those angles turn about; a locked axis has none, a limited
//! one shows its range as an arc and the bone's place in it as a tick) and, where no axis
//! is locked, a trackball inside them. Drag a ring to turn about it, the angle shown;
//! Esc or a right click cancels; a drag is one undo step. R, then X/Y/Z and a number of
//! degrees, then Enter turns by typing (Esc cancels). While a ring or the trackball is
//! dragged, the joints that move are drawn in the chain colour.
//!
//! The turning itself is [`crate::rig::turn`]; this module finds what the pointer grabs,
//! follows it and pushes each frame's rotation as an ordinary pose [`Edit`].

use crate::editor::edits::kinds;
use bevy::input::mouse::AccumulatedMouseMotion;
use bevy::prelude::*;

use crate::editor::edits::edit::{EditQueue, GestureHold};
use crate::editor::interact::picking::{JointPicker, PICK_RADIUS_PX};
use crate::editor::interact::pointer::ViewportHasPointer;
use crate::editor::present::draw::SkeletonGizmos;
use crate::editor::state::{JointDrag, Selection};
use crate::formats::scene::CharacterId;
use crate::rig::turn::{dof_angles, dof_axes, turn_dof, turn_freely, wrap_angle};
use crate::rig::{DofLimits, JointRotation};
use crate::scene::{Character, JointPose};

/// The rings' radius on screen (pixels), and how near (pixels) the pointer must be to grab one.
pub const RING_RADIUS_PX: f32 = 80.0;
const RING_GRAB_PX: f32 = 8.0;
/// Points per ring when drawn and hit-tested.
const RING_SEGMENTS: usize = 96;
const AXIS_COLORS: [Color; 3] =
    [Color::srgb(0.95, 0.25, 0.3), Color::srgb(0.45, 0.9, 0.2), Color::srgb(0.25, 0.5, 1.0)];
const ACTIVE_COLOR: Color = Color::srgb(1.0, 0.9, 0.2);
const TRACKBALL_COLOR: Color = Color::srgba(1.0, 1.0, 1.0, 0.5);
const AXIS_NAMES: [&str; 3] = ["X", "Y", "Z"];

/// A turn of one joint under way, by a ring, the trackball or typing. Holds where it
/// started, so cancelling restores the pose exactly.
#[derive(Debug, Clone, PartialEq)]
pub struct Turn {
    pub character: CharacterId,
    pub joint: usize,
    pub start: JointRotation,
    pub limits: DofLimits,
    pub grip: Grip,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Grip {
    /// A ring of DOF `axis`, whose plane (world: its normal, and where its angles count
    /// from) is kept from the press; the cursor's angle on it last frame and how far it
    /// has turned since the press (radians, not wrapped, so several turns add up).
    Ring { axis: usize, normal: Vec3, across: Vec3, last: f32, turned: f32 },
    /// The trackball: the turn so far, in the joint's parent frame.
    Trackball { turned: Quat },
    /// R then an axis key and a number of degrees.
    Typed { axis: Option<usize>, text: String },
}

impl Turn {
    /// The joint's rotation for the turn so far.
    pub fn rotation(&self) -> JointRotation {
        match &self.grip {
            Grip::Ring { axis, turned, .. } => turn_dof(&self.start, &self.limits, *axis, *turned),
            Grip::Trackball { turned } => turn_freely(&self.start, &self.limits, *turned),
            Grip::Typed { axis: Some(axis), text } => match text.parse::<f32>() {
                Ok(degrees) => turn_dof(&self.start, &self.limits, *axis, degrees.to_radians()),
                Err(_) => self.start,
            },
            Grip::Typed { axis: None, .. } => self.start,
        }
    }

    /// The cursor is now at `angle` (radians) on the ring: adds the wrapped change since
    /// last frame. Nothing for other grips.
    pub fn ring_to(&mut self, angle: f32) {
        if let Grip::Ring { last, turned, .. } = &mut self.grip {
            *turned += wrap_angle(angle - *last);
            *last = angle;
        }
    }

    /// Turns the trackball further by `turn` (in the joint's parent frame).
    pub fn roll(&mut self, turn: Quat) {
        if let Grip::Trackball { turned } = &mut self.grip {
            *turned = (turn * *turned).normalize();
        }
    }

    /// What the turn does, for the readout: the joint, the angle and how far it turned.
    pub fn describe(&self, joint_name: &str) -> String {
        let (angles, _) = dof_angles(&self.rotation());
        let (start, _) = dof_angles(&self.start);
        let dof = |axis: usize| {
            format!(
                "{joint_name} {} = {:.3} rad ({:.1}°), turned {:+.1}°",
                AXIS_NAMES[axis],
                angles[axis],
                angles[axis].to_degrees(),
                (angles[axis] - start[axis]).to_degrees()
            )
        };
        match &self.grip {
            Grip::Ring { axis, .. } => dof(*axis),
            Grip::Trackball { .. } => format!(
                "{joint_name} = ({:.1}°, {:.1}°, {:.1}°)",
                angles.x.to_degrees(),
                angles.y.to_degrees(),
                angles.z.to_degrees()
            ),
            Grip::Typed { axis: None, .. } => format!("Rotate {joint_name}: press X, Y or Z, type degrees, Enter"),
            Grip::Typed { axis: Some(axis), text } => {
                format!("Rotate {joint_name} about {}: {text}_° (Enter applies, Esc cancels)", AXIS_NAMES[*axis])
            }
        }
    }
}

/// The turn under way, and whether the pointer is the gizmo's (from the press on a ring
/// or the trackball until release, a cancelled drag too, so it neither orbits nor picks).
#[derive(Resource, Default, Debug)]
pub struct RotateGizmo {
    pub turn: Option<Turn>,
    pub holds_pointer: bool,
    /// What the turn under way does, shown over the viewport.
    pub readout: Option<String>,
}

impl RotateGizmo {
    /// Whether a typed rotation is under way (its gesture goes on between key presses).
    pub fn is_typing(&self) -> bool {
        matches!(self.turn, Some(Turn { grip: Grip::Typed { .. }, .. }))
    }
}

/// Tells the camera, picking and IK drags whether the gizmo has the pointer (reads
/// `RotateGizmo`; writes `PointerOwner`; the move gizmo adds its own after).
fn publish_pointer_owner(gizmo: Res<RotateGizmo>, mut owner: ResMut<crate::editor::interact::pointer::PointerOwner>) {
    let now = crate::editor::interact::pointer::PointerOwner {
        gizmo_holds_pointer: gizmo.holds_pointer,
        gizmo_turning: gizmo.turn.is_some(),
        gizmo_typing: gizmo.is_typing(),
    };
    owner.set_if_neq(now);
}

pub struct RotateGizmoPlugin;

impl Plugin for RotateGizmoPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<RotateGizmo>()
            .init_resource::<crate::editor::interact::pointer::PointerOwner>()
            .add_systems(
                Update,
                (grab_gizmo, follow_gizmo, type_rotation, publish_pointer_owner)
                    .chain()
                    .in_set(crate::editor::order::EditorSystems::Gizmo),
            )
            .add_systems(
                PostUpdate,
                draw_rotate_gizmo
                    .in_set(crate::editor::order::EditorSystems::Present)
                    .after(crate::editor::present::stage::apply_stage_settings),
            );
    }
}

/// The gizmo of the selected joint as the camera sees it.
struct GizmoView {
    character: CharacterId,
    joint: usize,
    name: String,
    rotation: JointRotation,
    limits: DofLimits,
    /// Where the joint is, and the rings' radius (world).
    center: Vec3,
    radius: f32,
    /// Rotation of the joint's parent frame in the world.
    frame: Quat,
    /// DOF axes in the world, and for each a unit vector across it: towards the first
    /// child where it has one (the tick of where the bone is).
    axes: [Vec3; 3],
    across: [Vec3; 3],
    /// Which axes have a ring (not locked), and whether the trackball is there (none locked).
    rings: [bool; 3],
    trackball: bool,
    center_px: Vec2,
}

impl GizmoView {
    /// The selected joint's gizmo: the first selected joint of the selected character, when
    /// one of its axes can turn and it is in front of the camera.
    fn of_selection(selection: &Selection, picker: &JointPicker, poses: &Query<&JointPose>) -> Option<Self> {
        let id = selection.character?;
        let &joint = selection.joints.first()?;
        let (_, _, character, placement, visible) = picker.characters.iter().find(|c| c.1.id == id)?;
        if !visible.get() {
            return None;
        }
        let def = character.asset.skeleton.joints().get(joint)?;
        let rings = [0, 1, 2].map(|axis| !def.limits.is_locked(axis));
        if !rings.contains(&true) {
            return None;
        }
        let rotation = poses.get(*character.joints.get(joint)?).ok()?.0;
        let world = |j: usize| Some(picker.joints.get(*character.joints.get(j)?).ok()?.world(placement));
        let (_, joint_rotation, center) = world(joint)?.to_scale_rotation_translation();
        let frame = (joint_rotation * rotation.to_quat().inverse()).normalize();
        let bone = character
            .asset
            .skeleton
            .children(joint)
            .first()
            .and_then(|&c| world(c))
            .map(|m| m.w_axis.truncate() - center);
        let (camera, camera_transform) = picker.camera()?;
        let center_px = camera.world_to_viewport(camera_transform, center).ok()?;
        let step = camera_transform.right().as_vec3() * character_scale(character, placement.scale);
        let step_px = camera.world_to_viewport(camera_transform, center + step).ok()?.distance(center_px);
        let radius = RING_RADIUS_PX * step.length() / step_px.max(1e-3);
        let axes = dof_axes(&rotation).map(|a| frame * a);
        let across = axes.map(|axis| {
            let b = bone.unwrap_or(Vec3::ZERO);
            let off = b - axis * b.dot(axis);
            if off.length() > 1e-4 * radius { off.normalize() } else { axis.any_orthonormal_vector() }
        });
        Some(Self {
            character: id,
            joint,
            name: def.name.clone(),
            rotation,
            limits: def.limits,
            center,
            radius,
            frame,
            axes,
            across,
            rings,
            trackball: !rings.contains(&false),
            center_px,
        })
    }

    /// Points of ring `axis` from angle `from` to `to` (radians from its `across` vector).
    fn arc(&self, axis: usize, from: f32, to: f32, radius: f32) -> impl Iterator<Item = Vec3> + '_ {
        let (u, v) = (self.across[axis], self.axes[axis].cross(self.across[axis]));
        let steps = ((to - from).abs() / std::f32::consts::TAU * RING_SEGMENTS as f32).ceil().max(2.0) as usize;
        (0..=steps).map(move |i| {
            let a = from + (to - from) * i as f32 / steps as f32;
            self.center + radius * (u * a.cos() + v * a.sin())
        })
    }

    /// The ring within grabbing distance of `cursor`, nearest first.
    fn ring_at(&self, cursor: Vec2, camera: &Camera, camera_transform: &GlobalTransform) -> Option<usize> {
        let mut best: Option<(f32, usize)> = None;
        for axis in (0..3).filter(|&a| self.rings[a]) {
            let screen: Vec<Vec2> = self
                .arc(axis, 0.0, std::f32::consts::TAU, self.radius)
                .filter_map(|p| camera.world_to_viewport(camera_transform, p).ok())
                .collect();
            let d = screen.windows(2).map(|s| distance_to_segment(cursor, s[0], s[1])).fold(f32::INFINITY, f32::min);
            if d < RING_GRAB_PX && best.is_none_or(|b| d < b.0) {
                best = Some((d, axis));
            }
        }
        best.map(|b| b.1)
    }
}

/// The angle (radians from `across`, right-handed about `normal`) at which `ray` meets the
/// plane through `center` facing `normal`; none when the ray runs along the plane.
pub fn angle_on_ring(center: Vec3, normal: Vec3, across: Vec3, ray: Ray3d) -> Option<f32> {
    let denom = ray.direction.dot(normal);
    if denom.abs() < 1e-4 {
        return None;
    }
    let t = (center - ray.origin).dot(normal) / denom;
    let p = ray.origin + *ray.direction * t - center;
    Some(p.dot(normal.cross(across)).atan2(p.dot(across)))
}

/// A character's size in the world (its bind mesh's diagonal times its scale).
fn character_scale(character: &Character, scale: f32) -> f32 {
    crate::editor::present::draw::character_size(character) * scale
}

/// The distance (pixels) from `p` to the segment `a`–`b` on screen.
pub fn distance_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// On a left press on a ring, or inside them away from any joint, starts turning the
/// selected joint (reads input, the selection, joints; writes `RotateGizmo`).
#[allow(clippy::too_many_arguments)]
fn grab_gizmo(
    buttons: Res<ButtonInput<MouseButton>>,
    pointer: Res<ViewportHasPointer>,
    selection: Res<Selection>,
    picker: JointPicker,
    poses: Query<&JointPose>,
    ik: Res<JointDrag>,
    mut gizmo: ResMut<RotateGizmo>,
) {
    if !buttons.just_pressed(MouseButton::Left) || !pointer.0 || gizmo.turn.is_some() || ik.active.is_some() {
        return;
    }
    let (Some(cursor), Some((camera, camera_transform))) = (picker.cursor(), picker.camera()) else { return };
    let Some(view) = GizmoView::of_selection(&selection, &picker, &poses) else { return };
    let grip = if let Some(axis) = view.ring_at(cursor, camera, camera_transform) {
        let Ok(ray) = camera.viewport_to_world(camera_transform, cursor) else { return };
        let (normal, across) = (view.axes[axis], view.across[axis]);
        let Some(angle) = angle_on_ring(view.center, normal, across, ray) else { return };
        Grip::Ring { axis, normal, across, last: angle, turned: 0.0 }
    } else if view.trackball
        && cursor.distance(view.center_px) < RING_RADIUS_PX
        && picker.joint_at(cursor, PICK_RADIUS_PX * 0.5).is_none()
    {
        Grip::Trackball { turned: Quat::IDENTITY }
    } else {
        return;
    };
    gizmo.turn =
        Some(Turn { character: view.character, joint: view.joint, start: view.rotation, limits: view.limits, grip });
    gizmo.holds_pointer = true;
}

/// While a ring or the trackball is held, turns the joint with the cursor; Esc or a right
/// click puts it back; release ends the drag (reads input, joints; writes `EditQueue`,
/// `RotateGizmo`).
#[allow(clippy::too_many_arguments)]
fn follow_gizmo(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    motion: Res<AccumulatedMouseMotion>,
    selection: Res<Selection>,
    picker: JointPicker,
    poses: Query<&JointPose>,
    mut edits: ResMut<EditQueue>,
    mut gizmo: ResMut<RotateGizmo>,
) {
    if !buttons.pressed(MouseButton::Left) {
        gizmo.holds_pointer = false;
    }
    let Some(mut turn) = gizmo.turn.clone().filter(|t| !matches!(t.grip, Grip::Typed { .. })) else { return };
    if keys.just_pressed(KeyCode::Escape) || buttons.just_pressed(MouseButton::Right) {
        edits.push(kinds::Pose { character: turn.character, joints: vec![(turn.joint, turn.start)] });
        gizmo.turn = None;
        gizmo.readout = None;
        return;
    }
    if !buttons.pressed(MouseButton::Left) {
        gizmo.turn = None;
        gizmo.readout = None;
        return;
    }
    let (Some(cursor), Some((camera, camera_transform))) = (picker.cursor(), picker.camera()) else { return };
    let Some(view) = GizmoView::of_selection(&selection, &picker, &poses).filter(|v| v.joint == turn.joint) else {
        return;
    };
    match turn.grip {
        Grip::Ring { normal, across, .. } => {
            let Ok(ray) = camera.viewport_to_world(camera_transform, cursor) else { return };
            if let Some(angle) = angle_on_ring(view.center, normal, across, ray) {
                turn.ring_to(angle);
            }
        }
        Grip::Trackball { .. } if motion.delta != Vec2::ZERO => {
            // Drag right turns the front of the ball right (about the camera's up), drag down
            // turns it down (about its right); a drag across the ring's radius is a radian.
            let d = motion.delta;
            let world_axis = camera_transform.up().as_vec3() * d.x + camera_transform.right().as_vec3() * d.y;
            let local = view.frame.inverse() * world_axis.normalize();
            turn.roll(Quat::from_axis_angle(local, d.length() / RING_RADIUS_PX));
        }
        _ => {}
    }
    push_turn(&mut edits, &turn, &view.rotation);
    gizmo.readout = Some(turn.describe(&view.name));
    gizmo.turn = Some(turn);
}

/// Pushes the turn's rotation as a pose edit when it differs from the joint's now.
fn push_turn(edits: &mut EditQueue, turn: &Turn, now: &JointRotation) {
    let rotation = turn.rotation();
    if rotation != *now {
        edits.push(kinds::Pose { character: turn.character, joints: vec![(turn.joint, rotation)] });
    }
}

/// The keys of a typed rotation: R starts it on the selected joint, X/Y/Z pick the axis,
/// digits, '-' and '.' type degrees (Backspace deletes), Enter or a left click applies,
/// Esc or a right click cancels. The pose follows the typing (reads keys, the selection;
/// writes `EditQueue`, `RotateGizmo`, `GestureHold`).
#[allow(clippy::too_many_arguments)]
fn type_rotation(
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    picker: JointPicker,
    poses: Query<&JointPose>,
    mut edits: ResMut<EditQueue>,
    mut gizmo: ResMut<RotateGizmo>,
    mut hold: ResMut<GestureHold>,
) {
    if wants.is_some_and(|w| w.wants_any_keyboard_input()) {
        return;
    }
    let starts = !gizmo.is_typing()
        && keys.just_pressed(KeyCode::KeyR)
        && gizmo.turn.is_none()
        && !keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight, KeyCode::SuperLeft, KeyCode::SuperRight]);
    if !gizmo.is_typing() && !starts {
        // Nothing typed and no R: no view of the gizmo to work out this frame.
        return;
    }
    let view = GizmoView::of_selection(&selection, &picker, &poses);
    if starts {
        if let Some(view) = &view {
            let grip = Grip::Typed { axis: None, text: String::new() };
            gizmo.turn = Some(Turn {
                character: view.character,
                joint: view.joint,
                start: view.rotation,
                limits: view.limits,
                grip,
            });
            hold.typing = true;
        } else {
            return;
        }
    }
    let Some(mut turn) = gizmo.turn.clone() else { return };
    let Some(view) = view.filter(|v| v.joint == turn.joint && v.character == turn.character) else {
        // The selection moved away: keep what was typed.
        finish_typing(&mut gizmo, &mut hold);
        return;
    };
    if keys.just_pressed(KeyCode::Escape) || buttons.just_pressed(MouseButton::Right) {
        edits.push(kinds::Pose { character: turn.character, joints: vec![(turn.joint, turn.start)] });
        finish_typing(&mut gizmo, &mut hold);
        return;
    }
    if keys.any_just_pressed([KeyCode::Enter, KeyCode::NumpadEnter]) || buttons.just_pressed(MouseButton::Left) {
        // A click that applies is only that: the pointer stays the gizmo's until released.
        gizmo.holds_pointer = buttons.just_pressed(MouseButton::Left);
        finish_typing(&mut gizmo, &mut hold);
        return;
    }
    if let Grip::Typed { axis, text } = &mut turn.grip {
        read_typing(&keys, axis, text, |a| view.rings[a]);
    }
    push_turn(&mut edits, &turn, &view.rotation);
    gizmo.readout = Some(turn.describe(&view.name));
    gizmo.turn = Some(turn);
}

fn finish_typing(gizmo: &mut RotateGizmo, hold: &mut GestureHold) {
    gizmo.turn = None;
    gizmo.readout = None;
    hold.typing = false;
}

/// This frame's keys of a typed number: X/Y/Z pick the axis (where `allowed`), digits,
/// '-' and '.' type, Backspace deletes.
pub fn read_typing(
    keys: &ButtonInput<KeyCode>,
    axis: &mut Option<usize>,
    text: &mut String,
    allowed: impl Fn(usize) -> bool,
) {
    for (key, a) in [(KeyCode::KeyX, 0), (KeyCode::KeyY, 1), (KeyCode::KeyZ, 2)] {
        if keys.just_pressed(key) && allowed(a) {
            *axis = Some(a);
        }
    }
    for key in keys.get_just_pressed() {
        match typed_char(*key) {
            Some(c) => text.push(c),
            None if *key == KeyCode::Backspace => {
                text.pop();
            }
            None => {}
        }
    }
}

/// The character a key types into a number of degrees.
fn typed_char(key: KeyCode) -> Option<char> {
    use KeyCode::*;
    let digits = [Digit0, Digit1, Digit2, Digit3, Digit4, Digit5, Digit6, Digit7, Digit8, Digit9];
    let numpad = [Numpad0, Numpad1, Numpad2, Numpad3, Numpad4, Numpad5, Numpad6, Numpad7, Numpad8, Numpad9];
    if let Some(d) = digits.iter().chain(&numpad).position(|&k| k == key) {
        return char::from_digit((d % 10) as u32, 10);
    }
    match key {
        Minus | NumpadSubtract => Some('-'),
        Period | NumpadDecimal | Comma | NumpadComma => Some('.'),
        _ => None,
    }
}

/// Draws the selected joint's rings (the one held highlighted), limit arcs with a tick at
/// the bone, the trackball's outline, and while a turn is under way the joints it moves
/// (draws gizmos).
fn draw_rotate_gizmo(
    selection: Res<Selection>,
    picker: JointPicker,
    poses: Query<&JointPose>,
    gizmo: Res<RotateGizmo>,
    ik: Res<JointDrag>,
    cameras: Query<&GlobalTransform, With<crate::editor::state::camera::OrbitCamera>>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    if ik.active.is_some() {
        return;
    }
    let Some(view) = GizmoView::of_selection(&selection, &picker, &poses) else { return };
    let held = gizmo.turn.as_ref().filter(|t| t.joint == view.joint && t.character == view.character);
    let held_axis = held.and_then(|t| match t.grip {
        Grip::Ring { axis, .. } | Grip::Typed { axis: Some(axis), .. } => Some(axis),
        _ => None,
    });
    let (angles, _) = dof_angles(&view.rotation);
    for axis in (0..3).filter(|&a| view.rings[a]) {
        let color = if held_axis == Some(axis) { ACTIVE_COLOR } else { AXIS_COLORS[axis] };
        if held_axis.is_some_and(|h| h != axis) {
            continue;
        }
        gizmos.linestrip(view.arc(axis, 0.0, std::f32::consts::TAU, view.radius), color);
        let (lo, hi) = (view.limits.min[axis], view.limits.max[axis]);
        if lo > -std::f32::consts::PI || hi < std::f32::consts::PI {
            // The range, seen from where the bone is now (angle 0 along `across`).
            let arc: Vec<Vec3> = view.arc(axis, lo - angles[axis], hi - angles[axis], view.radius * 0.85).collect();
            gizmos.linestrip(arc.iter().copied(), color.with_alpha(0.6));
            // Shaded by spokes every few degrees; a solid spoke where the bone is.
            for &p in arc.iter().step_by(2) {
                gizmos.line(view.center, p, color.with_alpha(0.3));
            }
            gizmos.line(view.center, view.center + view.across[axis] * view.radius, color);
        }
    }
    if view.trackball
        && held_axis.is_none()
        && let Ok(camera) = cameras.single()
    {
        let facing = Quat::from_rotation_arc(Vec3::Z, camera.back().as_vec3());
        gizmos.circle(Isometry3d::new(view.center, facing), view.radius, TRACKBALL_COLOR);
    }
    if held.is_some() {
        draw_moving_joints(&picker, &view, &mut gizmos);
    }
}

/// The joint being turned and every joint below it, in the chain colour.
fn draw_moving_joints(picker: &JointPicker, view: &GizmoView, gizmos: &mut Gizmos<SkeletonGizmos>) {
    let Some((_, _, character, placement, _)) = picker.characters.iter().find(|c| c.1.id == view.character) else {
        return;
    };
    let skeleton = &character.asset.skeleton;
    let world = |j: usize| Some(picker.joints.get(*character.joints.get(j)?).ok()?.world_position(placement));
    let radius = character_scale(character, placement.scale) * 0.015;
    let mut todo = vec![view.joint];
    while let Some(j) = todo.pop() {
        let Some(p) = world(j) else { continue };
        gizmos.sphere(Isometry3d::from_translation(p), radius, crate::editor::interact::ik_drag::CHAIN_COLOR);
        for &c in skeleton.children(j) {
            if let Some(q) = world(c) {
                gizmos.line(p, q, crate::editor::interact::ik_drag::CHAIN_COLOR);
            }
            todo.push(c);
        }
    }
}
