//! The move gizmo on the selected character or prop (selected without a joint): an arrow
//! per world axis, a square for the ground plane and a ring to turn it about the vertical.
//! Drag an arrow, the square or the ring; hold Ctrl to snap to the grid (0.1 m, 15°), Shift
//! to stand it on the floor. G moves it in the ground plane with the cursor (X/Y/Z and a
//! number of metres: exactly that far), R turns it (a number of degrees); Enter or a click
//! applies, Esc or a right click cancels. One drag or one typed move is one undo step.
//!
//! The moving itself ([`Move`]) is plain math on rays, tested without a window; the
//! systems find what the pointer grabs and push each frame's placement as an ordinary
//! [`Edit::Place`].

use crate::editor::edits::kinds;
use bevy::math::Ray3d;
use bevy::prelude::*;

use crate::editor::edits::edit::{EditQueue, GestureHold};
use crate::editor::interact::picking::JointPicker;
use crate::editor::interact::pointer::ViewportHasPointer;
use crate::editor::interact::rotate_gizmo::{distance_to_segment, read_typing};
use crate::editor::present::draw::SkeletonGizmos;
use crate::editor::state::{JointDrag, Selection};
use crate::formats::scene::{CharacterId, PlacementDoc};

/// The arrows' length on screen (pixels), and how near the pointer must be to grab one.
const ARROW_PX: f32 = 90.0;
const GRAB_PX: f32 = 9.0;
/// The grid a Ctrl drag snaps to (metres, and degrees for turns).
pub const GRID_STEP: f32 = 0.1;
pub const TURN_STEP_DEGREES: f32 = 15.0;
const AXIS_COLORS: [Color; 3] =
    [Color::srgb(0.95, 0.25, 0.3), Color::srgb(0.45, 0.9, 0.2), Color::srgb(0.25, 0.5, 1.0)];
const ACTIVE_COLOR: Color = Color::srgb(1.0, 0.9, 0.2);
const RING_COLOR: Color = Color::srgb(0.95, 0.75, 0.3);

/// How a move goes.
#[derive(Debug, Clone, PartialEq)]
pub enum MoveGrip {
    /// Along world axis `axis` (0 x, 1 y, 2 z), from where the press met it.
    Axis { axis: usize, from: f32 },
    /// In the horizontal plane at `height`, from where the press met it.
    Plane { height: f32, from: Vec3 },
    /// About the vertical through the start: the cursor's angle last frame.
    Turn { last: f32 },
    /// G (a move) or R (a turn), then for a move an axis key, and a number.
    Typed { turn: bool, axis: Option<usize>, text: String },
}

/// Snapping while moving: to the grid, and the feet to the floor.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Snap {
    pub grid: bool,
    /// The floor's height and the character's lowest point in its model space (unscaled).
    pub floor: Option<(f32, f32)>,
}

/// A move of one character under way. Holds where it started, so cancelling restores the
/// placement exactly.
#[derive(Debug, Clone, PartialEq)]
pub struct Move {
    pub character: CharacterId,
    pub start: PlacementDoc,
    pub grip: MoveGrip,
    /// How far it has moved (world) and turned (radians) so far.
    pub moved: Vec3,
    pub turned: f32,
}

impl Move {
    pub fn new(character: CharacterId, start: PlacementDoc, grip: MoveGrip) -> Self {
        Self { character, start, grip, moved: Vec3::ZERO, turned: 0.0 }
    }

    /// Follows the cursor's ray: the point on the axis nearest it, where it meets the
    /// plane, or its angle about the vertical. A typed move follows the plane until an axis
    /// is typed; nothing when the ray runs along the plane or the axis.
    pub fn follow(&mut self, ray: Ray3d) {
        let origin = self.start.translation;
        match &mut self.grip {
            MoveGrip::Axis { axis, from } => {
                let direction = Vec3::AXES[*axis];
                if let Some(s) = along_axis(origin, direction, ray) {
                    self.moved = direction * (s - *from);
                }
            }
            MoveGrip::Plane { height, from } => {
                if let Some(p) = on_ground(*height, ray) {
                    self.moved = p - *from;
                }
            }
            MoveGrip::Turn { last } => {
                if let Some(angle) = on_ground(origin.y, ray).and_then(|p| angle_about_vertical(origin, p)) {
                    self.turned += crate::rig::turn::wrap_angle(angle - *last);
                    *last = angle;
                }
            }
            MoveGrip::Typed { .. } => {}
        }
    }

    /// The placement for the move so far: typed numbers are exact; with `snap.grid` the
    /// moved coordinates land on the grid (turns on steps of 15°); with `snap.floor` the
    /// lowest point stands on the floor.
    pub fn placement(&self, snap: Snap) -> PlacementDoc {
        let mut p = self.start;
        let (moved, turned) = match &self.grip {
            MoveGrip::Typed { turn, axis, text } => match (text.parse::<f32>(), turn, axis) {
                (Ok(v), true, _) => (Vec3::ZERO, v.to_radians()),
                (Ok(v), false, Some(axis)) => (Vec3::AXES[*axis] * v, 0.0),
                _ if *turn => (Vec3::ZERO, 0.0),
                _ => (self.moved, 0.0),
            },
            _ => (self.moved, self.turned),
        };
        p.translation += moved;
        p.yaw += turned;
        if snap.grid && !matches!(self.grip, MoveGrip::Typed { .. }) {
            let on_grid = |v: f32| (v / GRID_STEP).round() * GRID_STEP;
            for k in (0..3).filter(|&k| moved[k] != 0.0) {
                p.translation[k] = on_grid(p.translation[k]);
            }
            if turned != 0.0 {
                let step = TURN_STEP_DEGREES.to_radians();
                p.yaw = (p.yaw / step).round() * step;
            }
        }
        if let Some((floor, lowest)) = snap.floor {
            p.translation.y = floor - lowest * p.scale;
        }
        p
    }

    /// What the move does, for the readout.
    pub fn describe(&self, name: &str, snap: Snap) -> String {
        let p = self.placement(snap);
        let d = p.translation - self.start.translation;
        match &self.grip {
            MoveGrip::Typed { turn: true, text, .. } => format!("Turn {name}: {text}_° (Enter applies, Esc cancels)"),
            MoveGrip::Typed { axis: None, .. } => {
                format!("Move {name} ({:+.3}, {:+.3}, {:+.3}) m: X/Y/Z and metres, Enter, Esc", d.x, d.y, d.z)
            }
            MoveGrip::Typed { axis: Some(a), text, .. } => {
                format!("Move {name} along {}: {text}_ m (Enter applies, Esc cancels)", ["X", "Y", "Z"][*a])
            }
            MoveGrip::Turn { .. } => {
                format!("Turn {name} to {:.1}° ({:+.1}°)", p.yaw.to_degrees(), (p.yaw - self.start.yaw).to_degrees())
            }
            _ => format!(
                "Move {name} by ({:+.3}, {:+.3}, {:+.3}) m to ({:.3}, {:.3}, {:.3})",
                d.x, d.y, d.z, p.translation.x, p.translation.y, p.translation.z
            ),
        }
    }
}

/// The parameter `s` of the point `origin + s·axis` (axis a unit vector) nearest `ray`;
/// none when they run (nearly) parallel.
pub fn along_axis(origin: Vec3, axis: Vec3, ray: Ray3d) -> Option<f32> {
    let d = *ray.direction;
    let w = origin - ray.origin;
    let b = axis.dot(d);
    let denom = 1.0 - b * b;
    (denom > 1e-6).then(|| (b * d.dot(w) - axis.dot(w)) / denom)
}

/// Where `ray` meets the horizontal plane at `height` (ahead of its origin).
pub fn on_ground(height: f32, ray: Ray3d) -> Option<Vec3> {
    let dy = ray.direction.y;
    if dy.abs() < 1e-6 {
        return None;
    }
    let t = (height - ray.origin.y) / dy;
    (t > 0.0).then(|| ray.origin + *ray.direction * t)
}

/// The angle of `p` about the vertical through `center` (radians, 0 towards +z, as the yaw).
fn angle_about_vertical(center: Vec3, p: Vec3) -> Option<f32> {
    let d = p - center;
    (d.x.hypot(d.z) > 1e-6).then(|| d.x.atan2(d.z))
}

/// The move under way, and whether the pointer is the gizmo's.
#[derive(Resource, Default, Debug)]
pub struct MoveGizmo {
    pub active: Option<Move>,
    pub holds_pointer: bool,
    pub readout: Option<String>,
    /// Where the cursor met the ground when G was pressed.
    typed_from: Option<Vec3>,
}

impl MoveGizmo {
    pub fn is_typing(&self) -> bool {
        matches!(self.active, Some(Move { grip: MoveGrip::Typed { .. }, .. }))
    }
}

pub struct MoveGizmoPlugin;

impl Plugin for MoveGizmoPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<MoveGizmo>()
            .add_systems(
                Update,
                (grab_move_gizmo, follow_move, type_move, add_to_pointer_owner)
                    .chain()
                    .in_set(crate::editor::order::EditorSystems::MoveGizmo),
            )
            .add_systems(
                PostUpdate,
                draw_move_gizmo
                    .in_set(crate::editor::order::EditorSystems::Present)
                    .after(crate::editor::present::stage::apply_stage_settings),
            );
    }
}

/// Adds the move to what the rotation gizmo told the camera, picking and IK drags (reads
/// `MoveGizmo`; writes `PointerOwner`).
fn add_to_pointer_owner(gizmo: Res<MoveGizmo>, mut owner: ResMut<crate::editor::interact::pointer::PointerOwner>) {
    if gizmo.holds_pointer || gizmo.active.is_some() {
        owner.gizmo_holds_pointer |= gizmo.holds_pointer;
        owner.gizmo_turning |= gizmo.active.is_some();
        owner.gizmo_typing |= gizmo.is_typing();
    }
}

/// What a move needs of the characters besides the picker's: their skins' boxes, and
/// which are held by a joint (those follow it and have no gizmo).
#[derive(bevy::ecs::system::SystemParam)]
pub struct MoveTargets<'w, 's> {
    skins: Query<'w, 's, &'static crate::scene::SkinScratch>,
    held: Query<'w, 's, (), With<crate::editor::scene_doc::document::Attached>>,
}

/// The selected character's gizmo as the camera sees it.
struct MoveView {
    character: CharacterId,
    name: String,
    placement: PlacementDoc,
    /// The arrows' length (world), and the character's lowest point (model space).
    length: f32,
    lowest: f32,
}

impl MoveView {
    /// The selected character's, when it is selected without a joint, not held by another's
    /// joint, and in front of the camera.
    fn of_selection(selection: &Selection, picker: &JointPicker, skins: &MoveTargets) -> Option<Self> {
        let id = selection.character?;
        if !selection.joints.is_empty() {
            return None;
        }
        let (entity, sc, _, placement, visible) = picker.characters.iter().find(|c| c.1.id == id)?;
        if !visible.get() || skins.held.contains(entity) {
            return None;
        }
        let (camera, camera_transform) = picker.camera()?;
        let center = placement.translation;
        let center_px = camera.world_to_viewport(camera_transform, center).ok()?;
        let step = camera_transform.right().as_vec3() * 0.1;
        let step_px = camera.world_to_viewport(camera_transform, center + step).ok()?.distance(center_px);
        let lowest = skins.skins.get(entity).map_or(0.0, |s| s.bounds.0.y);
        Some(Self {
            character: id,
            name: sc.name.clone(),
            placement: placement.0,
            length: ARROW_PX * 0.1 / step_px.max(1e-3),
            lowest,
        })
    }

    fn center(&self) -> Vec3 {
        self.placement.translation
    }

    /// The ground square's corners (world).
    fn square(&self) -> [Vec3; 4] {
        let (a, b) = (0.25 * self.length, 0.5 * self.length);
        [(a, a), (b, a), (b, b), (a, b)].map(|(x, z)| self.center() + Vec3::new(x, 0.0, z))
    }

    fn ring_radius(&self) -> f32 {
        1.25 * self.length
    }

    /// What a press at `cursor` grabs.
    fn grip_at(&self, cursor: Vec2, ray: Ray3d, camera: &Camera, at: &GlobalTransform) -> Option<MoveGrip> {
        let screen = |p: Vec3| camera.world_to_viewport(at, p).ok();
        let center_px = screen(self.center())?;
        for axis in 0..3 {
            let end = screen(self.center() + Vec3::AXES[axis] * self.length)?;
            if distance_to_segment(cursor, center_px, end) < GRAB_PX {
                let from = along_axis(self.center(), Vec3::AXES[axis], ray)?;
                return Some(MoveGrip::Axis { axis, from });
            }
        }
        let hit = on_ground(self.center().y, ray)?;
        let local = hit - self.center();
        let [lo, .., hi] = self.square();
        if (lo.x - self.center().x..=hi.x - self.center().x).contains(&local.x)
            && (lo.z - self.center().z..=hi.z - self.center().z).contains(&local.z)
        {
            return Some(MoveGrip::Plane { height: self.center().y, from: hit });
        }
        let ring = self.center() + Vec3::new(local.x, 0.0, local.z).normalize_or_zero() * self.ring_radius();
        if screen(ring)?.distance(cursor) < GRAB_PX {
            return Some(MoveGrip::Turn { last: angle_about_vertical(self.center(), hit)? });
        }
        None
    }
}

/// The snapping the modifier keys ask for.
fn snap_of(keys: &ButtonInput<KeyCode>, floor: f32, lowest: f32) -> Snap {
    Snap {
        grid: keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight]),
        floor: keys.any_pressed([KeyCode::ShiftLeft, KeyCode::ShiftRight]).then_some((floor, lowest)),
    }
}

/// On a left press on an arrow, the square or the ring, starts moving the selected
/// character (reads input, the selection; writes `MoveGizmo`).
#[allow(clippy::too_many_arguments)]
fn grab_move_gizmo(
    buttons: Res<ButtonInput<MouseButton>>,
    pointer: Res<ViewportHasPointer>,
    selection: Res<Selection>,
    picker: JointPicker,
    skins: MoveTargets,
    ik: Res<JointDrag>,
    mut gizmo: ResMut<MoveGizmo>,
) {
    if !buttons.just_pressed(MouseButton::Left) || !pointer.0 || gizmo.active.is_some() || ik.active.is_some() {
        return;
    }
    let (Some(cursor), Some((camera, at))) = (picker.cursor(), picker.camera()) else { return };
    let Some(view) = MoveView::of_selection(&selection, &picker, &skins) else { return };
    let Ok(ray) = camera.viewport_to_world(at, cursor) else { return };
    if let Some(grip) = view.grip_at(cursor, ray, camera, at) {
        gizmo.active = Some(Move::new(view.character, view.placement, grip));
        gizmo.holds_pointer = true;
    }
}

/// While a handle is held (or a typed move follows the cursor), moves the character with
/// it; Esc or a right click puts it back; release ends a drag (reads input; writes
/// `EditQueue`, `MoveGizmo`).
#[allow(clippy::too_many_arguments)]
fn follow_move(
    buttons: Res<ButtonInput<MouseButton>>,
    keys: Res<ButtonInput<KeyCode>>,
    selection: Res<Selection>,
    picker: JointPicker,
    skins: MoveTargets,
    stage: Res<crate::editor::state::StageSettings>,
    mut edits: ResMut<EditQueue>,
    mut gizmo: ResMut<MoveGizmo>,
) {
    if !buttons.pressed(MouseButton::Left) {
        gizmo.holds_pointer = false;
    }
    let Some(mut active) = gizmo.active.clone() else { return };
    let typed = matches!(active.grip, MoveGrip::Typed { .. });
    if !typed && (keys.just_pressed(KeyCode::Escape) || buttons.just_pressed(MouseButton::Right)) {
        edits.push(kinds::Place { character: active.character, placement: active.start });
        (gizmo.active, gizmo.readout) = (None, None);
        return;
    }
    if !typed && !buttons.pressed(MouseButton::Left) {
        (gizmo.active, gizmo.readout) = (None, None);
        return;
    }
    let Some(view) = MoveView::of_selection(&selection, &picker, &skins).filter(|v| v.character == active.character)
    else {
        return;
    };
    if let (Some(cursor), Some((camera, at))) = (picker.cursor(), picker.camera())
        && let Ok(ray) = camera.viewport_to_world(at, cursor)
    {
        active.follow(ray);
    }
    let snap = snap_of(&keys, stage.floor_height, view.lowest);
    let placement = active.placement(snap);
    if placement != view.placement {
        edits.push(kinds::Place { character: active.character, placement });
    }
    gizmo.readout = Some(active.describe(&view.name, snap));
    gizmo.active = Some(active);
}

/// G and R on a character selected without a joint: a typed move or turn. X/Y/Z pick the
/// axis of a move, digits, '-' and '.' type the number (Backspace deletes), Enter or a
/// left click applies, Esc or a right click cancels (reads keys, the selection; writes
/// `EditQueue`, `MoveGizmo`, `GestureHold`).
#[allow(clippy::too_many_arguments)]
fn type_move(
    keys: Res<ButtonInput<KeyCode>>,
    buttons: Res<ButtonInput<MouseButton>>,
    wants: Option<Res<bevy_egui::input::EguiWantsInput>>,
    selection: Res<Selection>,
    picker: JointPicker,
    skins: MoveTargets,
    mut edits: ResMut<EditQueue>,
    mut gizmo: ResMut<MoveGizmo>,
    mut hold: ResMut<GestureHold>,
) {
    if wants.is_some_and(|w| w.wants_any_keyboard_input()) {
        return;
    }
    let ctrl = keys.any_pressed([KeyCode::ControlLeft, KeyCode::ControlRight, KeyCode::SuperLeft, KeyCode::SuperRight]);
    if !gizmo.is_typing() {
        let turn = keys.just_pressed(KeyCode::KeyR);
        if ctrl || gizmo.active.is_some() || !(turn || keys.just_pressed(KeyCode::KeyG)) {
            return;
        }
        let Some(view) = MoveView::of_selection(&selection, &picker, &skins) else { return };
        let Some(from) = picker
            .cursor()
            .zip(picker.camera())
            .and_then(|(cursor, (camera, at))| camera.viewport_to_world(at, cursor).ok())
            .and_then(|ray| on_ground(view.center().y, ray))
        else {
            return;
        };
        let grip = MoveGrip::Typed { turn, axis: None, text: String::new() };
        gizmo.active = Some(Move::new(view.character, view.placement, grip));
        gizmo.typed_from = Some(from);
        hold.typing = true;
        return;
    }
    let Some(mut active) = gizmo.active.clone() else { return };
    if keys.just_pressed(KeyCode::Escape) || buttons.just_pressed(MouseButton::Right) {
        edits.push(kinds::Place { character: active.character, placement: active.start });
        finish(&mut gizmo, &mut hold);
        return;
    }
    if keys.any_just_pressed([KeyCode::Enter, KeyCode::NumpadEnter]) || buttons.just_pressed(MouseButton::Left) {
        gizmo.holds_pointer = buttons.just_pressed(MouseButton::Left);
        finish(&mut gizmo, &mut hold);
        return;
    }
    if let MoveGrip::Typed { turn, axis, text } = &mut active.grip {
        let turn = *turn;
        read_typing(&keys, axis, text, |_| !turn);
    }
    // Until an axis is typed, the cursor moves it in the ground plane.
    if let (MoveGrip::Typed { turn: false, axis: None, .. }, Some(from)) = (&active.grip, gizmo.typed_from)
        && let (Some(cursor), Some((camera, at))) = (picker.cursor(), picker.camera())
        && let Ok(ray) = camera.viewport_to_world(at, cursor)
        && let Some(p) = on_ground(from.y, ray)
    {
        active.moved = Vec3::new(p.x - from.x, 0.0, p.z - from.z);
    }
    let placement = active.placement(Snap::default());
    edits.push(kinds::Place { character: active.character, placement });
    let name = MoveView::of_selection(&selection, &picker, &skins).map_or_else(String::new, |v| v.name);
    gizmo.readout = Some(active.describe(&name, Snap::default()));
    gizmo.active = Some(active);
}

fn finish(gizmo: &mut MoveGizmo, hold: &mut GestureHold) {
    (gizmo.active, gizmo.readout, gizmo.typed_from) = (None, None, None);
    hold.typing = false;
}

/// Draws the arrows, the square and the ring of the selected character (the held one
/// highlighted) (draws gizmos).
fn draw_move_gizmo(
    selection: Res<Selection>,
    picker: JointPicker,
    skins: MoveTargets,
    gizmo: Res<MoveGizmo>,
    mut gizmos: Gizmos<SkeletonGizmos>,
) {
    let Some(view) = MoveView::of_selection(&selection, &picker, &skins) else { return };
    let held = gizmo.active.as_ref().map(|m| &m.grip);
    let c = view.center();
    for (axis, (direction, color)) in Vec3::AXES.into_iter().zip(AXIS_COLORS).enumerate() {
        let active = matches!(held, Some(MoveGrip::Axis { axis: a, .. }) if *a == axis);
        gizmos.arrow(c, c + direction * view.length, if active { ACTIVE_COLOR } else { color });
    }
    let square = view.square();
    let plane = if matches!(held, Some(MoveGrip::Plane { .. })) { ACTIVE_COLOR } else { Color::srgb(0.9, 0.9, 0.9) };
    gizmos.linestrip(square.iter().chain(&square[..1]).copied(), plane);
    let ring = if matches!(held, Some(MoveGrip::Turn { .. })) { ACTIVE_COLOR } else { RING_COLOR };
    gizmos.circle(Isometry3d::new(c, Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)), view.ring_radius(), ring);
}
