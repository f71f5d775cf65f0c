//! The runtime skeleton: a validated tree of named joints stored flat, parents before
//! children (the ozz-animation layout). Built once from a [`RawSkeleton`].

use glam::Vec3;

use super::RigError;
use super::pose::{DofLimits, JointRotation};

/// An axis-aligned box in a joint's local space (CSE169 `boxmin`/`boxmax`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneBox {
    pub min: Vec3,
    pub max: Vec3,
}

/// One joint as a file describes it, before validation.
#[derive(Debug, Clone, PartialEq)]
pub struct RawJoint {
    pub name: String,
    /// Index of the parent in the raw list; `None` for a root.
    pub parent: Option<usize>,
    /// Translation from the parent's frame to this joint's frame, in the parent's local
    /// space (model units). For the root: its place in the character's model space.
    pub rest_offset: Vec3,
    /// Per-axis rotation limits in radians (unlimited by default).
    pub limits: DofLimits,
    /// Optional box drawn for a skeleton without skin.
    pub bone_box: Option<BoneBox>,
    /// The pose the file gives (already clamped to `limits` by [`Skeleton::build`]).
    pub initial_rotation: JointRotation,
    /// Scale of the joint's frame after its rotation (glTF node scale; 1 for the course
    /// rigs).
    pub rest_scale: Vec3,
}

impl RawJoint {
    /// A joint with only a name, a parent and an offset; everything else default.
    pub fn new(name: impl Into<String>, parent: Option<usize>, rest_offset: Vec3) -> Self {
        Self {
            name: name.into(),
            parent,
            rest_offset,
            limits: DofLimits::UNLIMITED,
            bone_box: None,
            initial_rotation: JointRotation::IDENTITY,
            rest_scale: Vec3::ONE,
        }
    }
}

/// A joint of a validated skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDef {
    pub name: String,
    /// Parent index, always smaller than this joint's index; `None` for the root.
    pub parent: Option<usize>,
    /// Translation relative to the parent, in the parent's local space.
    pub rest_offset: Vec3,
    pub limits: DofLimits,
    pub bone_box: Option<BoneBox>,
    /// The file's pose, clamped to `limits`.
    pub initial_rotation: JointRotation,
    /// Scale of the joint's frame after its rotation (1 for the course rigs).
    pub rest_scale: Vec3,
}

impl JointDef {
    /// The joint's transform in its parent's frame at `pose` with rest offset `offset`:
    /// `T(offset) · R(pose) · S(rest_scale)`, glTF's order.
    pub fn local_transform(&self, pose: &JointRotation, offset: Vec3) -> glam::Mat4 {
        let m = pose.local_transform(offset);
        if self.rest_scale == Vec3::ONE { m } else { m * glam::Mat4::from_scale(self.rest_scale) }
    }
}

/// A validated joint tree: exactly one root (index 0), parents before children.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    joints: Vec<JointDef>,
    /// `children[j]`: indices of j's children, in index order.
    children: Vec<Vec<usize>>,
}

impl Skeleton {
    /// Validates a raw joint list and reorders it so that parents come before children
    /// (depth-first, children in file order). Returns the skeleton and, for each raw index,
    /// its new index.
    pub fn build_reordered(raw: Vec<RawJoint>) -> Result<(Self, Vec<usize>), RigError> {
        let order = depth_first_order(&raw)?;
        let mut new_index = vec![0; raw.len()];
        for (new, &old) in order.iter().enumerate() {
            new_index[old] = new;
        }
        let mut raw: Vec<Option<RawJoint>> = raw.into_iter().map(Some).collect();
        let joints = order
            .iter()
            .map(|&old| {
                let j = raw[old].take().expect("each joint is visited once");
                joint_def(j, |p| new_index[p])
            })
            .collect();
        Ok((Self::from_ordered(joints), new_index))
    }

    /// Validates a raw joint list whose parents already precede their children and keeps
    /// its order (file indices stay joint indices, as weight files expect).
    pub fn build(raw: Vec<RawJoint>) -> Result<Self, RigError> {
        // Roots, ranges and cycles first, so a forward reference on a cycle says "cycle".
        depth_first_order(&raw)?;
        if let Some((i, j)) = raw.iter().enumerate().find(|(i, j)| j.parent.is_some_and(|p| p >= *i)) {
            let parent = j.parent.expect("found by its parent");
            return Err(RigError::NotParentFirst { joint: j.name.clone(), index: i, parent });
        }
        Ok(Self::from_ordered(raw.into_iter().map(|j| joint_def(j, |p| p)).collect()))
    }

    fn from_ordered(joints: Vec<JointDef>) -> Self {
        let mut children = vec![Vec::new(); joints.len()];
        for (i, j) in joints.iter().enumerate() {
            if let Some(p) = j.parent {
                children[p].push(i);
            }
        }
        Self { joints, children }
    }

    pub fn len(&self) -> usize {
        self.joints.len()
    }

    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    pub fn joints(&self) -> &[JointDef] {
        &self.joints
    }

    pub fn joint(&self, index: usize) -> &JointDef {
        &self.joints[index]
    }

    pub fn children(&self, index: usize) -> &[usize] {
        &self.children[index]
    }

    pub fn parent(&self, index: usize) -> Option<usize> {
        self.joints[index].parent
    }

    /// Whether joint `j` lies below `ancestor` (not `ancestor` itself).
    pub fn is_below(&self, mut j: usize, ancestor: usize) -> bool {
        while let Some(p) = self.parent(j) {
            if p == ancestor {
                return true;
            }
            j = p;
        }
        false
    }

    /// First joint with this name (names are not unique in every file).
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// A joint by name, or by index written as a number.
    pub fn resolve(&self, name_or_index: &str) -> Option<usize> {
        self.find(name_or_index).or_else(|| name_or_index.parse::<usize>().ok().filter(|&i| i < self.len()))
    }

    /// The initial pose the file gave (clamped).
    pub fn initial_pose(&self) -> Vec<JointRotation> {
        self.joints.iter().map(|j| j.initial_rotation).collect()
    }

    /// The rest pose: every joint at identity rotation.
    pub fn rest_pose(&self) -> Vec<JointRotation> {
        vec![JointRotation::IDENTITY; self.len()]
    }

    /// Replaces rest offsets (a reshaped skeleton keeps its topology).
    pub fn set_rest_offsets(&mut self, offsets: &[Vec3]) {
        for (j, &o) in self.joints.iter_mut().zip(offsets) {
            j.rest_offset = o;
        }
    }
}

/// A validated joint, its parent index mapped by `parent_index`; the pose clamped.
fn joint_def(j: RawJoint, parent_index: impl Fn(usize) -> usize) -> JointDef {
    JointDef {
        initial_rotation: j.initial_rotation.clamped(&j.limits),
        name: j.name,
        parent: j.parent.map(parent_index),
        rest_offset: j.rest_offset,
        limits: j.limits,
        bone_box: j.bone_box,
        rest_scale: j.rest_scale,
    }
}

/// Checks a raw tree (joints present, parents in range, one root, no cycles) and returns
/// its depth-first order from the root, children in file order.
fn depth_first_order(raw: &[RawJoint]) -> Result<Vec<usize>, RigError> {
    let n = raw.len();
    if n == 0 {
        return Err(RigError::EmptySkeleton);
    }
    if n > super::MAX_JOINTS {
        return Err(RigError::TooManyJoints { count: n });
    }
    for (i, j) in raw.iter().enumerate() {
        if let Some(p) = j.parent {
            if p >= n {
                return Err(RigError::ParentOutOfRange { joint: i, parent: p, count: n });
            }
            if p == i {
                return Err(RigError::Cycle { joint: j.name.clone() });
            }
        }
    }
    let roots: Vec<usize> = (0..n).filter(|&i| raw[i].parent.is_none()).collect();
    match roots.len() {
        0 => return Err(RigError::Cycle { joint: raw[0].name.clone() }),
        1 => {}
        _ => return Err(RigError::SeveralRoots { roots: roots.iter().map(|&r| raw[r].name.clone()).collect() }),
    }
    let mut children = vec![Vec::new(); n];
    for (i, j) in raw.iter().enumerate() {
        if let Some(p) = j.parent {
            children[p].push(i);
        }
    }
    // Joints never reached from the root sit on a cycle.
    let mut order = Vec::with_capacity(n);
    let mut todo = vec![roots[0]];
    while let Some(j) = todo.pop() {
        order.push(j);
        todo.extend(children[j].iter().rev());
    }
    if order.len() != n {
        let mut reached = vec![false; n];
        order.iter().for_each(|&j| reached[j] = true);
        let lost = (0..n).find(|&j| !reached[j]).unwrap_or(0);
        return Err(RigError::Cycle { joint: raw[lost].name.clone() });
    }
    Ok(order)
}
