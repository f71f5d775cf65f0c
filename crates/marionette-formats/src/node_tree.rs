//! A file's node tree as a character's skeleton: the one conversion glTF and FBX share.
//! The nodes a mesh depends on become joints, depth first (under a common root when they
//! have several roots); each skin's bindings become the joints' bind matrices, and a node
//! that two skins bind differently gets a fixed child joint carrying the second binding.

use glam::{Mat4, Quat, Vec3};
use marionette_rig::{JointRotation, RawJoint, Skeleton};

use super::checks::{is_invertible, is_normalisable};

/// A node as the file gives it: its name and its transform in its parent's frame.
pub struct TreeNode {
    pub name: String,
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

/// A skin: the nodes it binds, each with its inverse bind matrix (world to joint at bind
/// time). `label` names the skin in a joint its binding adds (`"skin 2"`, `"cluster Arm"`);
/// `at` is where its matrices are reported (`at $.skins[2].inverseBindMatrices`).
pub struct Binding {
    pub label: String,
    pub at: String,
    pub joints: Vec<(usize, Mat4)>,
}

/// The skeleton of a node tree.
pub struct TreeSkeleton {
    pub skeleton: Skeleton,
    /// Each joint's inverse bind matrix: its skins' (the first skin's where several bind
    /// it alike), else the inverse of its world matrix at rest.
    pub bind: Vec<Mat4>,
    /// Each node's joint, none for the nodes left out.
    pub joint_of_node: Vec<Option<usize>>,
    /// For each binding, the joint each of its nodes' influences go to.
    pub skin_joints: Vec<Vec<usize>>,
}

/// Where the tree's nodes come from.
pub struct Tree<'a> {
    /// The name of the common root the tree gets when it has several roots.
    pub name: &'a str,
    /// How many nodes the file has (node indices are below it).
    pub node_count: usize,
    /// The roots of the nodes kept, in order.
    pub roots: &'a [usize],
    /// Where a failure to build the skeleton is reported (`at $.nodes (the tree of node 0)`).
    pub at: &'a str,
}

/// The skeleton of `tree`: `node` gives a node's name and transform, `children` its kept
/// children in order. Every number is checked here, the nodes' before the skins': a finite
/// translation, a finite scale not zero on any axis, a rotation that can be normalised, and
/// bind matrices that can be inverted.
pub fn tree_skeleton(
    tree: &Tree,
    mut node: impl FnMut(usize) -> Result<TreeNode, String>,
    children: impl Fn(usize) -> Vec<usize>,
    skins: &[Binding],
) -> Result<TreeSkeleton, String> {
    let mut raw = Vec::new();
    let mut raw_of_node = vec![None; tree.node_count];
    let mut todo: Vec<(usize, Option<usize>)> = match tree.roots {
        [root] => vec![(*root, None)],
        roots => {
            raw.push(RawJoint::new(tree.name, None, Vec3::ZERO));
            roots.iter().rev().map(|&r| (r, Some(0))).collect()
        }
    };
    while let Some((index, parent)) = todo.pop() {
        raw_of_node[index] = Some(raw.len());
        let me = raw.len();
        raw.push(raw_joint(node(index)?, parent)?);
        todo.extend(children(index).into_iter().rev().map(|c| (c, Some(me))));
    }
    let (slots, bound) = skin_slots(skins, &raw_of_node, &mut raw)?;
    let (skeleton, new_index) = Skeleton::build_reordered(raw).map_err(|e| format!("{}: {e}", tree.at))?;
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    marionette_rig::fk::forward_kinematics(&skeleton, &skeleton.initial_pose(), Mat4::IDENTITY, &mut rest);
    let mut bind = vec![Mat4::IDENTITY; skeleton.len()];
    for (r, b) in bound.iter().enumerate() {
        bind[new_index[r]] = b.unwrap_or_else(|| rest[new_index[r]].inverse());
    }
    Ok(TreeSkeleton {
        skeleton,
        bind,
        joint_of_node: raw_of_node.iter().map(|r| r.map(|r| new_index[r])).collect(),
        skin_joints: slots.iter().map(|s| s.iter().map(|&r| new_index[r]).collect()).collect(),
    })
}

/// A node as a raw joint under `parent`, its transform checked.
fn raw_joint(node: TreeNode, parent: Option<usize>) -> Result<RawJoint, String> {
    let TreeNode { name, translation, rotation, scale } = node;
    if !translation.is_finite() || !scale.is_finite() || scale.min_element().abs() < 1e-12 {
        return Err(format!(
            "node `{name}`: expected a finite translation and a finite, non-zero scale, found {translation} and {scale}"
        ));
    }
    if !is_normalisable(rotation) {
        return Err(format!("node `{name}`: expected a rotation that can be normalised, found {rotation}"));
    }
    let mut joint = RawJoint::new(name, parent, translation);
    joint.initial_rotation = JointRotation::Quat(rotation.normalize());
    if (scale - Vec3::ONE).abs().max_element() > 1e-6 {
        joint.rest_scale = scale;
    }
    Ok(joint)
}

/// Each binding's raw joints, and each raw joint's bind matrix. A node an earlier binding
/// binds differently gets a fixed child joint (added to `raw`) carrying this one.
type Slots = (Vec<Vec<usize>>, Vec<Option<Mat4>>);

fn skin_slots(skins: &[Binding], raw_of_node: &[Option<usize>], raw: &mut Vec<RawJoint>) -> Result<Slots, String> {
    let mut bound: Vec<Option<Mat4>> = vec![None; raw.len()];
    let mut slots = Vec::with_capacity(skins.len());
    for skin in skins {
        let mut joints = Vec::with_capacity(skin.joints.len());
        for (k, &(node, bind)) in skin.joints.iter().enumerate() {
            let r = raw_of_node
                .get(node)
                .copied()
                .flatten()
                .ok_or_else(|| format!("{}: binds node {node}, which is not in the tree", skin.at))?;
            if !is_invertible(&bind) {
                let what = if bind.is_finite() { "a singular matrix" } else { "numbers that are not finite" };
                let name = &raw[r].name;
                return Err(format!(
                    "{}: expected an invertible matrix for joint {k} (`{name}`), found {what}",
                    skin.at
                ));
            }
            let slot = match bound[r] {
                None => {
                    bound[r] = Some(bind);
                    r
                }
                Some(first) if same_binding(first, bind) => r,
                Some(_) => {
                    raw.push(RawJoint::new(format!("{} ({})", raw[r].name, skin.label), Some(r), Vec3::ZERO));
                    bound.push(Some(bind));
                    raw.len() - 1
                }
            };
            joints.push(slot);
        }
        slots.push(joints);
    }
    Ok((slots, bound))
}

/// Whether two inverse bind matrices are the same binding (within 1e-6 of their size).
fn same_binding(a: Mat4, b: Mat4) -> bool {
    let size = a.to_cols_array().iter().fold(1.0f32, |m, x| m.max(x.abs()));
    a.abs_diff_eq(b, 1e-6 * size)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain 0 → 1 → 2 and a lone node 3, each one unit above its parent.
    fn node(i: usize) -> Result<TreeNode, String> {
        Ok(TreeNode { name: format!("n{i}"), translation: Vec3::Y, rotation: Quat::IDENTITY, scale: Vec3::ONE })
    }

    fn children(i: usize) -> Vec<usize> {
        if i < 2 { vec![i + 1] } else { vec![] }
    }

    fn tree<'a>(roots: &'a [usize]) -> Tree<'a> {
        Tree { name: "file", node_count: 4, roots, at: "the tree" }
    }

    #[test]
    fn unbound_joints_bind_at_rest_and_several_roots_get_a_common_one() {
        let t = tree_skeleton(&tree(&[0, 3]), node, children, &[]).unwrap();
        assert_eq!(t.skeleton.joint(0).name, "file");
        assert_eq!(t.joint_of_node, vec![Some(1), Some(2), Some(3), Some(4)]);
        // Node 2 stands 3 units up: its inverse bind takes it back down.
        assert!(t.bind[3].abs_diff_eq(Mat4::from_translation(-3.0 * Vec3::Y), 1e-6));
    }

    #[test]
    fn a_node_bound_twice_differently_gets_a_child_for_the_second_binding() {
        let a = Mat4::from_translation(Vec3::X);
        let skins = [
            Binding { label: "skin 0".into(), at: "skins[0]".into(), joints: vec![(1, a), (2, a)] },
            Binding { label: "skin 1".into(), at: "skins[1]".into(), joints: vec![(1, a), (2, Mat4::IDENTITY)] },
        ];
        let t = tree_skeleton(&tree(&[0]), node, children, &skins).unwrap();
        assert_eq!(t.skeleton.len(), 4);
        let extra = t.skin_joints[1][1];
        assert_eq!(t.skeleton.joint(extra).name, "n2 (skin 1)");
        assert_eq!(t.skin_joints[0], vec![1, 2]);
        assert_eq!(t.skin_joints[1][0], 1, "the same binding shares the joint");
        assert_eq!(t.bind[extra], Mat4::IDENTITY);
        assert_eq!(t.bind[2], a);
    }

    #[test]
    fn transforms_that_make_no_joint_are_refused_by_name() {
        let zero_scale = |i| node(i).map(|n| TreeNode { scale: Vec3::new(1.0, 0.0, 1.0), ..n });
        let e = tree_skeleton(&tree(&[0]), zero_scale, children, &[]).err().unwrap();
        assert!(e.starts_with("node `n0`: expected a finite translation and a finite, non-zero scale"), "{e}");
        let zero_rotation = |i| node(i).map(|n| TreeNode { rotation: Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), ..n });
        let e = tree_skeleton(&tree(&[0]), zero_rotation, children, &[]).err().unwrap();
        assert!(e.starts_with("node `n0`: expected a rotation that can be normalised"), "{e}");
        let singular = Binding { label: "skin 0".into(), at: "skins[0]".into(), joints: vec![(0, Mat4::ZERO)] };
        let e = tree_skeleton(&tree(&[0]), node, children, &[singular]).err().unwrap();
        assert_eq!(e, "skins[0]: expected an invertible matrix for joint 0 (`n0`), found a singular matrix");
    }
}
