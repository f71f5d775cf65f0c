//! Hand presets: the fingers of the humanoid map curled and spread by name (`fist`,
//! `open`, `point`, …), each hand on its own. A finger curls toward the palm: about the
//! axis square to the finger and to the palm's normal, the palm facing down at rest (the
//! T- and A-poses rigs are made in).

use glam::{Mat4, Quat, Vec3};

use crate::fk::forward_kinematics;
use crate::humanoid::{HumanBone, HumanoidMap};
use crate::{JointRotation, Skeleton};

/// The presets: each finger's curl (radians per phalanx, thumb first) and the spread
/// (radians between neighbouring fingers, added to the rest).
pub const PRESETS: [(&str, [f32; 5], f32); 9] = [
    ("relaxed", [0.25, 0.35, 0.4, 0.45, 0.5], 0.0),
    ("fist", [0.7, 1.35, 1.35, 1.35, 1.35], 0.0),
    ("open", [0.0, 0.0, 0.0, 0.0, 0.0], 0.0),
    ("spread", [0.0, 0.0, 0.0, 0.0, 0.0], 0.2),
    ("point", [0.7, 0.0, 1.35, 1.35, 1.35], 0.0),
    ("pinch", [0.6, 0.7, 0.3, 0.3, 0.3], 0.0),
    ("grip", [0.5, 0.9, 0.9, 0.9, 0.9], 0.0),
    ("peace", [0.7, 0.0, 0.0, 1.35, 1.35], 0.15),
    ("thumbs-up", [0.0, 1.35, 1.35, 1.35, 1.35], 0.0),
];

/// The preset of that name.
pub fn preset(name: &str) -> Option<([f32; 5], f32)> {
    PRESETS.iter().find(|(n, ..)| *n == name).map(|&(_, curl, spread)| (curl, spread))
}

/// Puts a hand preset on `pose`: each mapped phalanx of the `left` (else right) hand aimed
/// along the bone that leads into it, turned by its finger's curl toward the palm (the
/// proximal ones fanned by `spread` about the palm's normal from the middle finger), the
/// smallest rotation in the joint's own type, clamped to its limits. Returns whether some
/// rotation was clamped, or `None` when the hand has no mapped finger.
pub fn apply_hand(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    pose: &mut [JointRotation],
    left: bool,
    curl: [f32; 5],
    spread: f32,
) -> Option<bool> {
    apply_hand_shape(skeleton, map, pose, left, HandShape::of_preset(curl, spread))
}

/// A hand's shape: each finger's curl (radians per phalanx, thumb first) and its fan away
/// from the middle finger (radians, toward the thumb's side positive; the thumb's and the
/// middle's turn their proximal phalanx the same way).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HandShape {
    pub curl: [f32; 5],
    pub fan: [f32; 5],
}

impl HandShape {
    /// A preset's shape: `spread` between neighbouring fingers, fanned from the middle.
    pub fn of_preset(curl: [f32; 5], spread: f32) -> HandShape {
        let fan = std::array::from_fn(|f| if f == 0 { 0.0 } else { spread * (2.0 - f as f32) });
        HandShape { curl, fan }
    }

    /// The shape of the preset of that name.
    pub fn preset(name: &str) -> Option<HandShape> {
        preset(name).map(|(curl, spread)| HandShape::of_preset(curl, spread))
    }
}

/// Puts `shape` on the `left` (else right) hand, as [`apply_hand`] does a preset.
pub fn apply_hand_shape(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    pose: &mut [JointRotation],
    left: bool,
    shape: HandShape,
) -> Option<bool> {
    let HandShape { curl, fan } = shape;
    let hand = *map.get(if left { &HumanBone::LeftHand } else { &HumanBone::RightHand })?;
    let phalanx = |f: usize, p: usize| map.get(&HumanBone::finger(left, f, p)).copied();
    (0..5).any(|f| phalanx(f, 0).is_some()).then_some(())?;
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut world);
    let palm_in_hand = palm_in_hand(skeleton, &world, hand, &phalanx);
    let mut limited = false;
    for (f, &bend) in curl.iter().enumerate() {
        for p in 0..3 {
            let Some(j) = phalanx(f, p) else { continue };
            let Some(&child) = skeleton.children(j).first() else { continue };
            forward_kinematics(skeleton, pose, Mat4::IDENTITY, &mut world);
            let at = |k: usize| world[k].w_axis.truncate();
            let palm = crate::ik::rotation_of(world[hand]) * palm_in_hand;
            let incoming = skeleton.parent(j).map_or(Vec3::ZERO, |q| at(j) - at(q));
            let now = at(child) - at(j);
            let incoming =
                if incoming.length_squared() > 1e-12 { incoming.normalize() } else { now.normalize_or(Vec3::X) };
            let axis = incoming.cross(palm).normalize_or(Vec3::Z);
            let mut wanted = Quat::from_axis_angle(axis, bend) * incoming;
            if p == 0 && fan[f] != 0.0 {
                let turn = -fan[f] * if left { 1.0 } else { -1.0 };
                wanted = Quat::from_axis_angle(palm, turn) * wanted;
            }
            if now.length_squared() < 1e-12 {
                continue;
            }
            let turn = Quat::from_rotation_arc(now.normalize(), wanted.normalize());
            let parent_world = skeleton.parent(j).map_or(Mat4::IDENTITY, |q| world[q]);
            limited |= crate::ik::turn_joint(skeleton, pose, j, parent_world, turn);
        }
    }
    Some(limited)
}

/// The palm's normal in the hand's frame: at rest the palm faces down, square to the hand's
/// direction (from the hand to its fingers' roots).
fn palm_in_hand(
    skeleton: &Skeleton,
    rest: &[Mat4],
    hand: usize,
    phalanx: &impl Fn(usize, usize) -> Option<usize>,
) -> Vec3 {
    let at = |k: usize| rest[k].w_axis.truncate();
    let roots: Vec<Vec3> = (1..5).filter_map(|f| phalanx(f, 0)).map(at).collect();
    let roots = if roots.is_empty() { vec![at(skeleton.children(hand)[0])] } else { roots };
    let along = (roots.iter().sum::<Vec3>() / roots.len() as f32 - at(hand)).normalize_or(Vec3::X);
    let palm = (Vec3::NEG_Y - along * Vec3::NEG_Y.dot(along)).normalize_or(Vec3::NEG_Z);
    crate::ik::rotation_of(rest[hand]).inverse() * palm
}
