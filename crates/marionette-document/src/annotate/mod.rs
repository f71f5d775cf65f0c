//! Pictures that carry data: what the renderer knows exactly about a picture, written
//! beside it. The scene's triangles rasterised through the picture's pinhole camera give
//! depth, normals, instance and body-part masks ([`raster`]); the humanoid map gives the
//! keypoints, seen or hidden by the depth pass; COCO's and OpenPose's files carry them with
//! the camera ([`coco`], [`openpose`]); [`write`] puts the files on disk.

pub mod camera;
pub mod canny;
pub mod coco;
pub mod controlnet;
pub mod openpose;
pub mod raster;
pub mod write;

use std::collections::BTreeMap;

use glam::Vec3;
use marionette_rig::humanoid::{HumanBone, HumanoidMap};
use marionette_rig::{CharacterAsset, Skeleton};

pub use camera::Pinhole;
pub use raster::{Passes, Surface, rasterize};

/// The body parts of the parts mask, by id (0: nothing, the floor or the background).
pub const PARTS: [&str; 17] = [
    "none",
    "head",
    "torso",
    "left_upper_arm",
    "right_upper_arm",
    "left_lower_arm",
    "right_lower_arm",
    "left_hand",
    "right_hand",
    "left_upper_leg",
    "right_upper_leg",
    "left_lower_leg",
    "right_lower_leg",
    "left_foot",
    "right_foot",
    "unmapped",
    "prop",
];

/// The part of a character's joint no mapped bone is above.
pub const UNMAPPED: u8 = 15;
/// The part of every vertex of a character without a humanoid map.
pub const PROP: u8 = 16;

/// The body part a standard bone's joint moves.
pub fn part_of_bone(bone: HumanBone) -> u8 {
    use HumanBone::*;
    match bone {
        Neck | Head => 1,
        Hips | Spine | Chest | LeftShoulder | RightShoulder => 2,
        LeftUpperArm => 3,
        RightUpperArm => 4,
        LeftLowerArm => 5,
        RightLowerArm => 6,
        LeftUpperLeg => 9,
        RightUpperLeg => 10,
        LeftLowerLeg => 11,
        RightLowerLeg => 12,
        LeftFoot | LeftToes => 13,
        RightFoot | RightToes => 14,
        LeftHand => 7,
        RightHand => 8,
        finger if HumanBone::ALL[HumanBone::BODY_COUNT..][..15].contains(&finger) => 7,
        _ => 8,
    }
}

/// Each joint's body part: its nearest mapped ancestor's (itself included), [`UNMAPPED`]
/// where none is; [`PROP`] for every joint of a character without a map.
pub fn joint_parts(skeleton: &Skeleton, map: Option<&HumanoidMap>) -> Vec<u8> {
    let Some(map) = map else { return vec![PROP; skeleton.len()] };
    let mut bone_of: Vec<Option<u8>> = vec![None; skeleton.len()];
    for (&bone, &j) in map {
        if j < bone_of.len() {
            bone_of[j] = Some(part_of_bone(bone));
        }
    }
    let mut parts = vec![UNMAPPED; skeleton.len()];
    // Parents come before their children.
    for j in 0..skeleton.len() {
        parts[j] = bone_of[j].unwrap_or_else(|| skeleton.parent(j).map_or(UNMAPPED, |p| parts[p]));
    }
    parts
}

/// Each vertex's body part: its most weighted joint's.
pub fn vertex_parts(asset: &CharacterAsset, joint_parts: &[u8]) -> Vec<u8> {
    let weights = &asset.skin.weights;
    (0..weights.vertex_count())
        .map(|v| {
            let top = weights.of_vertex(v).iter().max_by(|a, b| a.weight.total_cmp(&b.weight));
            top.and_then(|i| joint_parts.get(i.joint as usize)).copied().unwrap_or(UNMAPPED)
        })
        .collect()
}

/// How a keypoint is judged seen or hidden by the depth pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PointKind {
    /// A point on the surface (a vertex landmark) or just under it (an eye's joint): seen
    /// where the nearest surface at its pixel is within [`SURFACE_TOLERANCE`] of it.
    Surface,
    /// A joint inside the body: seen where its pixel shows these body parts of its own
    /// character within [`JOINT_TOLERANCE`] in front of it, or no surface in front of it
    /// by more than [`SURFACE_TOLERANCE`].
    Joint([u8; 2]),
}

/// Metres a surface point may lie behind the surface seen at its pixel and be seen.
pub const SURFACE_TOLERANCE: f32 = 0.03;
/// Metres a joint may lie behind its own limb's surface seen at its pixel and be seen.
pub const JOINT_TOLERANCE: f32 = 0.25;

/// A keypoint of a character in world metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    pub at: Vec3,
    pub kind: PointKind,
}

/// A character (or prop) as the data pictures see it.
pub struct Figure {
    /// Its name in the scene.
    pub name: String,
    /// 1 for the first character of the scene, 2 for the next…; kept across a sequence.
    pub instance: u16,
    /// The skinned vertices, world metres.
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub parts: Vec<u8>,
    /// Keypoints by name (COCO's and OpenPose's: `left_wrist`, `neck`, `left_hand_4`…).
    pub points: BTreeMap<String, Point>,
    /// Every mapped standard bone's joint, world metres.
    pub bones: BTreeMap<HumanBone, Vec3>,
}

impl Figure {
    /// The character `asset` as drawn: its skinned vertices and joints in the world
    /// (`positions`, `joint_world`), its humanoid map where it has one (else a prop without
    /// keypoints), and whether it is an SMPL body (its face and feet from the mesh).
    pub fn new(
        name: &str,
        instance: u16,
        asset: &CharacterAsset,
        map: Option<&HumanoidMap>,
        positions: Vec<Vec3>,
        joint_world: &[Vec3],
        smpl: bool,
    ) -> Self {
        let joint_parts = joint_parts(&asset.skeleton, map);
        let parts = vertex_parts(asset, &joint_parts);
        let (points, bones) = match map {
            Some(map) if joint_world.len() == asset.skeleton.len() => (
                keypoints(&asset.skeleton, map, joint_world, &joint_parts, &positions, smpl),
                map.iter().filter_map(|(&bone, &j)| Some((bone, *joint_world.get(j)?))).collect(),
            ),
            _ => Default::default(),
        };
        Figure {
            name: name.to_string(),
            instance,
            positions,
            triangles: asset.skin.triangles.clone(),
            parts,
            points,
            bones,
        }
    }

    /// Its triangles for the rasteriser.
    pub fn surface(&self) -> Surface<'_> {
        Surface { instance: self.instance, positions: &self.positions, triangles: &self.triangles, parts: &self.parts }
    }

    /// Whether it is a person (it has a humanoid map), not a prop.
    pub fn is_person(&self) -> bool {
        !self.bones.is_empty()
    }
}

/// The SMPL mesh's standard landmark vertices (the SMPL-X project's `vertex_ids` for the
/// SMPL topology): nose, eyes, ears, big and small toes, heels.
pub const SMPL_LANDMARKS: [(&str, usize); 11] = [
    ("nose", 332),
    ("right_eye", 6260),
    ("left_eye", 2800),
    ("right_ear", 4071),
    ("left_ear", 583),
    ("left_big_toe", 3216),
    ("left_small_toe", 3226),
    ("left_heel", 3387),
    ("right_big_toe", 6617),
    ("right_small_toe", 6624),
    ("right_heel", 6787),
];

/// The vertex count of SMPL's mesh, which [`SMPL_LANDMARKS`] index.
pub const SMPL_VERTICES: usize = 6890;

/// A character's keypoints: the joints of its humanoid map (`joint_world`: each joint's
/// world position), the fingers' tips past their last joints, and the face's points from
/// joints named for them (`LeftEye`, `nose`…) or, on an SMPL body (`smpl`), from its
/// landmark vertices (`positions`).
pub fn keypoints(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    joint_world: &[Vec3],
    joint_parts: &[u8],
    positions: &[Vec3],
    smpl: bool,
) -> BTreeMap<String, Point> {
    use HumanBone::*;
    let mut points = BTreeMap::new();
    let own_parts = |j: usize| [joint_parts[j], skeleton.parent(j).map_or(joint_parts[j], |p| joint_parts[p])];
    let joint = |bone: HumanBone| map.get(&bone).copied().filter(|&j| j < joint_world.len());
    let add_bone = |points: &mut BTreeMap<String, Point>, name: &str, bone: HumanBone| {
        if let Some(j) = joint(bone) {
            points.insert(name.to_string(), Point { at: joint_world[j], kind: PointKind::Joint(own_parts(j)) });
        }
    };
    for (name, bone) in [
        ("left_shoulder", LeftUpperArm),
        ("right_shoulder", RightUpperArm),
        ("left_elbow", LeftLowerArm),
        ("right_elbow", RightLowerArm),
        ("left_wrist", LeftHand),
        ("right_wrist", RightHand),
        ("left_hip", LeftUpperLeg),
        ("right_hip", RightUpperLeg),
        ("left_knee", LeftLowerLeg),
        ("right_knee", RightLowerLeg),
        ("left_ankle", LeftFoot),
        ("right_ankle", RightFoot),
    ] {
        add_bone(&mut points, name, bone);
    }
    // OpenPose's neck and mid-hip: between the shoulders, between the hips.
    for (name, a, b) in [("neck", "left_shoulder", "right_shoulder"), ("mid_hip", "left_hip", "right_hip")] {
        if let (Some(a), Some(b)) = (points.get(a), points.get(b)) {
            let at = (a.at + b.at) / 2.0;
            let parts = if name == "neck" { [2, 1] } else { [2, 2] };
            points.insert(name.to_string(), Point { at, kind: PointKind::Joint(parts) });
        }
    }
    for left in [true, false] {
        let side = if left { "left" } else { "right" };
        if let Some(j) = joint(if left { LeftHand } else { RightHand }) {
            let hand = points_of_hand(skeleton, map, joint_world, left, j);
            for (k, at) in hand.into_iter().enumerate() {
                if let Some(at) = at {
                    points.insert(
                        format!("{side}_hand_{k}"),
                        Point { at, kind: PointKind::Joint([7 + u8::from(!left); 2]) },
                    );
                }
            }
        }
    }
    if smpl && positions.len() == SMPL_VERTICES {
        for (name, v) in SMPL_LANDMARKS {
            points.insert(name.to_string(), Point { at: positions[v], kind: PointKind::Surface });
        }
    } else {
        for (name, j) in face_joints(skeleton) {
            points.insert(name.to_string(), Point { at: joint_world[j], kind: PointKind::Surface });
        }
    }
    points
}

/// A hand's 21 OpenPose points: the wrist, then for the thumb and each finger its three
/// joints and its tip (the last joint's child, else as far past it as the joint before);
/// none where the finger is not mapped.
fn points_of_hand(
    skeleton: &Skeleton,
    map: &HumanoidMap,
    world: &[Vec3],
    left: bool,
    wrist: usize,
) -> Vec<Option<Vec3>> {
    let mut out = vec![Some(world[wrist])];
    for finger in 0..5 {
        let joints: Vec<Option<usize>> =
            (0..3).map(|p| map.get(&HumanBone::finger(left, finger, p)).copied()).collect();
        let [Some(a), Some(b), Some(c)] = joints[..] else {
            out.extend([None; 4]);
            continue;
        };
        let tip = skeleton.children(c).first().map_or(world[c] + (world[c] - world[b]), |&t| world[t]);
        out.extend([Some(world[a]), Some(world[b]), Some(world[c]), Some(tip)]);
    }
    out
}

/// Joints named for the face's points: `nose`, `left_eye`, `right_eye`, `left_ear`,
/// `right_ear` (a name's words, any case, with a side as a word or prefix: `LeftEye`,
/// `eye.L`, `R_Ear`).
fn face_joints(skeleton: &Skeleton) -> Vec<(&'static str, usize)> {
    let mut found = Vec::new();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let words = words(&joint.name);
        let has = |w: &str| words.iter().any(|x| x == w);
        let side = if has("left") || has("l") {
            Some("left")
        } else if has("right") || has("r") {
            Some("right")
        } else {
            None
        };
        let name = match (has("nose"), has("eye"), has("ear"), side) {
            (true, _, _, _) => "nose",
            (_, true, _, Some("left")) => "left_eye",
            (_, true, _, Some("right")) => "right_eye",
            (_, _, true, Some("left")) => "left_ear",
            (_, _, true, Some("right")) => "right_ear",
            _ => continue,
        };
        if !found.iter().any(|&(n, _)| n == name) {
            found.push((name, j));
        }
    }
    found
}

/// A joint name's words, lower case: split at non-letters and where a capital follows a
/// small letter (`LeftEye_end` → left, eye, end).
fn words(name: &str) -> Vec<String> {
    let mut words = vec![String::new()];
    let mut previous_lower = false;
    for c in name.chars() {
        if !c.is_alphabetic() {
            words.push(String::new());
            previous_lower = false;
            continue;
        }
        if c.is_uppercase() && previous_lower {
            words.push(String::new());
        }
        previous_lower = c.is_lowercase();
        words.last_mut().expect("a word").extend(c.to_lowercase());
    }
    words.retain(|w| !w.is_empty());
    words
}

/// A keypoint in the picture: its pixel position and COCO's visibility (2 seen, 1 inside
/// the picture but hidden, 0 outside it or behind the camera: then at (0, 0)).
pub fn seen(camera: &Pinhole, passes: &Passes, instance: u16, point: &Point) -> (f32, f32, u8) {
    let Some((x, y, z)) = camera.project(point.at) else { return (0.0, 0.0, 0) };
    if !camera.inside(x, y) {
        return (0.0, 0.0, 0);
    }
    let i = passes.at(x as u32, y as u32);
    let (depth, shown) = (passes.depth[i], passes.instance[i]);
    let hidden = match point.kind {
        PointKind::Surface => depth < z - SURFACE_TOLERANCE,
        PointKind::Joint(parts) => {
            let own_limb = shown == instance && parts.contains(&passes.part[i]) && depth >= z - JOINT_TOLERANCE;
            !own_limb && depth < z - SURFACE_TOLERANCE
        }
    };
    (x, y, if hidden { 1 } else { 2 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_split_into_words_find_the_face() {
        assert_eq!(words("LeftEye_end"), ["left", "eye", "end"]);
        assert_eq!(words("eye.L"), ["eye", "l"]);
        assert!(words("LeftForeArm").iter().all(|w| w != "ear"), "a forearm is no ear");
    }

    #[test]
    fn fingers_belong_to_their_own_sides_hand() {
        assert_eq!(part_of_bone(HumanBone::finger(true, 4, 2)), 7);
        assert_eq!(part_of_bone(HumanBone::finger(false, 0, 0)), 8);
        assert_eq!(PARTS[part_of_bone(HumanBone::LeftLowerLeg) as usize], "left_lower_leg");
    }
}
