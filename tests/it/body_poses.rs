//! The built-in body poses on every kind of humanoid: the puppet, the Blender-made rig
//! families, a VRM avatar, and with the data the 6.837 Model1, an SMPL body and CesiumMan.
//! Each pose through the command line's path (`--preset`, the document layer), checked by
//! forward kinematics and the posed skin: every aimed bone within 5° of the definition
//! unless its joint's limits were reported, every rotation within its limits, the feet on
//! the floor (1 % of the leg); t-pose, a-pose and sit-chair against their definitions in
//! words, measured in a facing frame the test works out from the hips itself.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};
use marionette::document::AssetLibrary;
use marionette::document::options::{PoseOptions, PoseSpecs, apply_options};
use marionette::document::posing::{BodyPoseSpec, posed_positions};
use marionette::document::retarget::humanoid_map;
use marionette::formats::scene::{CharacterDoc, SceneDoc, SourceDoc};
use marionette::rig::body_poses::{POSES, aim_end, aim_start, body_pose};
use marionette::rig::fk::forward_kinematics;
use marionette::rig::humanoid::{HumanBone, HumanoidMap};
use marionette::rig::{CharacterAsset, JointRotation};

use HumanBone::*;

fn fixture(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/rigs").join(file)
}

/// A character posed by `--preset` as every command poses it: its asset, map, pose, placement.
struct Posed {
    asset: std::sync::Arc<CharacterAsset>,
    map: HumanoidMap,
    pose: Vec<JointRotation>,
    placement: Mat4,
    notes: Vec<String>,
}

fn posed(library: &mut AssetLibrary, doc: &CharacterDoc, spec: &str) -> Posed {
    let mut scene = SceneDoc { characters: vec![doc.clone()], ..SceneDoc::default() };
    let specs = PoseSpecs { preset: Some(spec.parse().unwrap()), ..PoseSpecs::default() };
    let notes = apply_options(&mut scene, &PoseOptions { specs, ..PoseOptions::default() }, library).unwrap();
    let c = &scene.characters[0];
    let asset = library.shaped(c).unwrap();
    let (pose, _) = marionette::document::scenes::pose_from_doc(&asset, c);
    let map = humanoid_map(&asset, &c.humanoid);
    Posed { asset, map, pose, placement: c.placement.to_mat4(), notes }
}

/// The facing frame worked out here: x the character's left (from its right thigh's root
/// to its left's, level), y up, z ahead; from the rest pose, in the model's space.
fn facing(asset: &CharacterAsset, map: &HumanoidMap) -> glam::Mat3 {
    let rest = world(asset, &asset.skeleton.initial_pose(), Mat4::IDENTITY);
    let (l, r) = (rest[map[&LeftUpperLeg]], rest[map[&RightUpperLeg]]);
    let left = Vec3::new(l.x - r.x, 0.0, l.z - r.z).normalize();
    glam::Mat3::from_cols(left, Vec3::Y, left.cross(Vec3::Y))
}

fn rotations(asset: &CharacterAsset, pose: &[JointRotation]) -> Vec<glam::Quat> {
    let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
    forward_kinematics(&asset.skeleton, pose, Mat4::IDENTITY, &mut world);
    world.iter().map(|&m| marionette::rig::ik::rotation_of(m)).collect()
}

fn world(asset: &CharacterAsset, pose: &[JointRotation], placement: Mat4) -> Vec<Vec3> {
    let mut world = vec![Mat4::IDENTITY; asset.skeleton.len()];
    forward_kinematics(&asset.skeleton, pose, placement, &mut world);
    world.iter().map(|m| m.w_axis.truncate()).collect()
}

/// A bone's direction in the facing frame (the placement only turns about up and scales).
fn direction(p: &Posed, frame: glam::Mat3, from: usize, to: usize) -> Vec3 {
    let at = world(&p.asset, &p.pose, Mat4::IDENTITY);
    frame.transpose() * (at[to] - at[from]).normalize()
}

fn leg_length(asset: &CharacterAsset, map: &HumanoidMap) -> f32 {
    let rest = world(asset, &asset.skeleton.initial_pose(), Mat4::IDENTITY);
    rest[map[&LeftUpperLeg]].distance(rest[map[&LeftLowerLeg]])
        + rest[map[&LeftLowerLeg]].distance(rest[map[&LeftFoot]])
}

/// The lowest point of the skin bound mostly to each foot (or what hangs below it).
fn lowest_foot(p: &Posed) -> f32 {
    let skeleton = &p.asset.skeleton;
    let below = |j: usize, foot: usize| {
        let mut k = Some(j);
        while let Some(n) = k {
            if n == foot {
                return true;
            }
            k = skeleton.parent(n);
        }
        false
    };
    let skin = posed_positions(&p.asset, &p.pose, p.placement);
    let feet = [LeftFoot, RightFoot].map(|f| p.map[&f]);
    let weights = &p.asset.skin.weights;
    let lowest = (0..skin.len())
        .filter(|&v| {
            let top = weights.of_vertex(v).iter().max_by(|a, b| a.weight.total_cmp(&b.weight));
            top.is_some_and(|i| feet.iter().any(|&f| below(i.joint as usize, f)))
        })
        .map(|v| skin[v].y)
        .fold(f32::INFINITY, f32::min);
    if lowest.is_finite() {
        lowest
    } else {
        // A skeleton without skin on its feet: the feet's joints.
        let at = world(&p.asset, &p.pose, p.placement);
        feet.iter().map(|&f| at[f].y).fold(f32::INFINITY, f32::min)
    }
}

/// Every pose, plain and mirrored, on `doc`: the figures and the failures.
fn check_every_pose(library: &mut AssetLibrary, doc: &CharacterDoc, failures: &mut Vec<String>) {
    let name = &doc.name;
    let mut worst = (0.0f32, 0.0f32, 0usize);
    for body in &POSES {
        for mirrored in [false, true] {
            let spec = if mirrored { format!("{}:mirrored", body.name) } else { body.name.to_string() };
            let p = posed(library, doc, &spec);
            let skeleton = &p.asset.skeleton;
            let frame = facing(&p.asset, &p.map);
            let held: Vec<&str> = p
                .notes
                .iter()
                .filter_map(|n| n.split_once("held short by the limits of ").map(|(_, list)| list))
                .flat_map(|list| list.split(", "))
                .collect();
            let limited: Vec<usize> =
                (0..skeleton.len()).filter(|&j| held.contains(&skeleton.joint(j).name.as_str())).collect();
            worst.2 += limited.len();
            // Every rotation the pose turned within its limits.
            let rest = skeleton.initial_pose();
            for (j, r) in p.pose.iter().enumerate().filter(|&(j, r)| *r != rest[j]) {
                let clamped = r.clamped(&skeleton.joint(j).limits);
                let off = 1.0 - clamped.to_quat().dot(r.to_quat()).abs();
                if off > 1e-6 {
                    failures.push(format!(
                        "{name} {spec}: joint {} {off}° outside its limits {r:?} {clamped:?}",
                        skeleton.joint(j).name
                    ));
                }
            }
            // Every aimed bone along the definition (the look turns the chest and neck).
            let spec_parsed: BodyPoseSpec = spec.parse().unwrap();
            let definition = body_pose(&spec_parsed.name).unwrap().directions(mirrored);
            for (bone, wanted) in definition {
                if body.look.is_some() && matches!(bone, Chest | Neck) {
                    continue;
                }
                let (Some(joint), Some(end)) = (aim_start(&p.map, bone), aim_end(&p.map, bone)) else { continue };
                let off = direction(&p, frame, joint, end).angle_between(wanted).to_degrees();
                if !limited.contains(&joint) {
                    worst.0 = worst.0.max(off);
                    if off > 5.0 {
                        failures.push(format!("{name} {spec}: {bone:?} {off:.2}° off"));
                    }
                }
            }
            // The feet on the floor where a shin stands near upright; the skin on the floor always.
            let skin_lowest =
                posed_positions(&p.asset, &p.pose, p.placement).iter().map(|v| v.y).fold(f32::INFINITY, f32::min);
            let leg = leg_length(&p.asset, &p.map) * p.placement.x_axis.length();
            if skin_lowest.is_finite() && skin_lowest.abs() > 1e-4 * leg {
                failures.push(format!("{name} {spec}: the skin's lowest point at {skin_lowest}"));
            }
            let upright_shin = [LeftLowerLeg, RightLowerLeg].iter().any(|&s| {
                let d = direction(&p, frame, p.map[&s], p.map[&if s == LeftLowerLeg { LeftFoot } else { RightFoot }]);
                d.dot(Vec3::NEG_Y) > std::f32::consts::FRAC_1_SQRT_2
            });
            if upright_shin {
                let foot = lowest_foot(&p) / leg;
                worst.1 = worst.1.max(foot.abs());
                if foot.abs() > 0.01 {
                    failures.push(format!("{name} {spec}: the lowest foot {:.4} of the leg off the floor", foot));
                }
            }
        }
    }
    eprintln!(
        "{name}: worst bone {:.3}° off its direction, feet within {:.5} of the leg of the floor; {} joints held by limits",
        worst.0, worst.1, worst.2
    );
}

/// The three poses defined in words, measured in the test's own facing frame.
fn check_definitions(library: &mut AssetLibrary, doc: &CharacterDoc, failures: &mut Vec<String>) {
    let name = &doc.name;
    let mut check = |what: String, degrees: f32, want: f32| {
        if (degrees - want).abs() > 5.0 {
            failures.push(format!("{name}: {what} {degrees:.2}°, want {want}°"));
        }
    };
    let elevation = |d: Vec3| d.y.asin().to_degrees();
    let p = posed(library, doc, "t-pose");
    let frame = facing(&p.asset, &p.map);
    for (upper, lower, hand, side) in
        [(LeftUpperArm, LeftLowerArm, LeftHand, 1.0), (RightUpperArm, RightLowerArm, RightHand, -1.0)]
    {
        for (from, to) in [(upper, lower), (lower, hand)] {
            // An arm whose lower bone ends in no joint (6.837's) has no hand to aim it at.
            let Some(&end) = p.map.get(&to) else { continue };
            let d = direction(&p, frame, p.map[&from], end);
            check(format!("t-pose {from:?} from level"), elevation(d), 0.0);
            check(format!("t-pose {from:?} from straight out"), d.angle_between(Vec3::X * side).to_degrees(), 0.0);
        }
    }
    for (thigh, shin, foot) in [(LeftUpperLeg, LeftLowerLeg, LeftFoot), (RightUpperLeg, RightLowerLeg, RightFoot)] {
        for (from, to) in [(thigh, shin), (shin, foot)] {
            let d = direction(&p, frame, p.map[&from], p.map[&to]);
            check(format!("t-pose {from:?} from straight down"), d.angle_between(Vec3::NEG_Y).to_degrees(), 0.0);
        }
    }
    let p = posed(library, doc, "a-pose");
    for (upper, lower, side) in [(LeftUpperArm, LeftLowerArm, 1.0f32), (RightUpperArm, RightLowerArm, -1.0)] {
        let d = direction(&p, frame, p.map[&upper], p.map[&lower]);
        check(format!("a-pose {upper:?} below level"), -elevation(d), 45.0);
        check(format!("a-pose {upper:?} ahead of sideways"), d.z.atan2(d.x * side).to_degrees(), 0.0);
    }
    let p = posed(library, doc, "sit-chair");
    for (thigh, shin, foot) in [(LeftUpperLeg, LeftLowerLeg, LeftFoot), (RightUpperLeg, RightLowerLeg, RightFoot)] {
        check(
            format!("sit-chair {thigh:?} from level"),
            elevation(direction(&p, frame, p.map[&thigh], p.map[&shin])),
            0.0,
        );
        let d = direction(&p, frame, p.map[&shin], p.map[&foot]);
        check(format!("sit-chair {shin:?} from straight down"), d.angle_between(Vec3::NEG_Y).to_degrees(), 0.0);
    }
    let top = [Neck, Head].iter().find_map(|b| p.map.get(b)).copied().unwrap();
    let spine = direction(&p, frame, p.map[&Hips], top);
    check("sit-chair spine from upright".into(), spine.angle_between(Vec3::Y).to_degrees(), 0.0);
}

fn doc_of(library: &mut AssetLibrary, path: &Path) -> CharacterDoc {
    let source = SourceDoc::File(path.to_path_buf());
    let asset = library.load(&source).unwrap();
    library.new_character_doc(source, &asset)
}

fn characters_here(library: &mut AssetLibrary) -> Vec<CharacterDoc> {
    let mut docs = vec![CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet")];
    for file in ["mixamo.glb", "unreal.glb", "rigify.glb", "daz.glb", "humanik.glb", "vroid.glb", "biped.glb"] {
        docs.push(doc_of(library, &fixture(file)));
    }
    docs.push(doc_of(library, &crate::wild::vrm_avatar(1)));
    docs
}

#[test]
fn every_body_pose_fits_the_puppet_the_rig_families_and_a_vrm_avatar() {
    let mut library = AssetLibrary::default();
    let mut failures = Vec::new();
    for doc in characters_here(&mut library) {
        check_every_pose(&mut library, &doc, &mut failures);
        check_definitions(&mut library, &doc, &mut failures);
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
}

#[test]
#[cfg_attr(not(marionette_data), ignore)]
fn every_body_pose_fits_model1_an_smpl_body_and_cesium_man() {
    let data = crate::common::data_dir();
    let mut library = AssetLibrary::default();
    let mut failures = Vec::new();
    for file in ["mit6837/Model1.skel", "smpl", "khronos/CesiumMan.glb"] {
        let doc = doc_of(&mut library, &data.join(file));
        check_every_pose(&mut library, &doc, &mut failures);
        check_definitions(&mut library, &doc, &mut failures);
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
}

/// Flipping a pose through the humanoid map: twice is the pose itself (1e-4 per joint), and
/// a body pose flipped puts every aimed bone where the mirrored body pose does (0.5°); one
/// joint's twin under symmetry is the flipped pose's (1e-4).
#[test]
fn a_flipped_pose_is_the_mirrored_pose_and_flips_back() {
    use marionette::rig::body_poses::{apply_body_pose, facing_frame};
    use marionette::rig::mirror::{counterparts, flipped_pose, mirrored_joint};
    let mut library = AssetLibrary::default();
    let mut failures = Vec::new();
    for doc in characters_here(&mut library) {
        let asset = library.shaped(&doc).unwrap();
        let skeleton = &asset.skeleton;
        let map = humanoid_map(&asset, &doc.humanoid);
        let twin = counterparts(skeleton, &map);
        let left = facing_frame(skeleton, &map).unwrap() * Vec3::X;
        for body in &POSES {
            let mut pose = skeleton.initial_pose();
            apply_body_pose(skeleton, &map, &mut pose, body, false).unwrap();
            let flipped = flipped_pose(skeleton, &twin, &pose, left);
            let back = flipped_pose(skeleton, &twin, &flipped, left);
            let worst =
                pose.iter().zip(&back).map(|(a, b)| 1.0 - a.to_quat().dot(b.to_quat()).abs()).fold(0.0, f32::max);
            if worst > 1e-4 {
                failures.push(format!("{} {}: flipped twice, {worst} from itself", doc.name, body.name));
            }
            let mut mirrored = skeleton.initial_pose();
            apply_body_pose(skeleton, &map, &mut mirrored, body, true).unwrap();
            let (a, b) = (world(&asset, &flipped, Mat4::IDENTITY), world(&asset, &mirrored, Mat4::IDENTITY));
            for (bone, _) in body.directions(false) {
                let (Some(start), Some(end)) = (aim_start(&map, bone), aim_end(&map, bone)) else { continue };
                let off = (a[end] - a[start]).angle_between(b[end] - b[start]).to_degrees();
                if off > 0.5 {
                    failures.push(format!("{} {}: {bone:?} flipped {off:.2}° from mirrored", doc.name, body.name));
                }
            }
            // Symmetry: each arm and leg joint's twin, set by `mirrored_joint`, turns from
            // rest in the model as the joint does, reflected.
            let turn = |pose: &[marionette::rig::JointRotation], j: usize| {
                let (now, rest) = (rotations(&asset, pose), rotations(&asset, &skeleton.initial_pose()));
                now[j] * rest[j].inverse()
            };
            for bone in [LeftUpperArm, LeftLowerArm, LeftUpperLeg, LeftLowerLeg] {
                let j = map[&bone];
                let mut both = pose.clone();
                let (k, rotation) = mirrored_joint(skeleton, &twin, &pose, j, left).unwrap();
                both[k] = rotation;
                let want = marionette::rig::mirror::reflected(turn(&both, j), left);
                let off = 1.0 - turn(&both, k).dot(want).abs();
                if k != twin[j] || off > 1e-5 {
                    failures.push(format!("{} {}: {bone:?}'s twin {off}", doc.name, body.name));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures.join("\n"));
}
