//! Props held by joints: an attached character follows its holder's joint, keeping the
//! offset it had when it was attached (the scene file's own `AttachDoc`).

use bevy::prelude::*;

pub use crate::editor::scene_doc::document::Attached;
use crate::editor::scene_doc::document::CharacterIndex;
use crate::formats::scene::joint_of_pose_key;
use crate::scene::{Character, CurrentJointToWorld, Placement};

/// The world transform of `holder`'s joint `key` (a pose key), as the matrix stack last
/// left it.
pub fn holding_joint_world(
    holder: (&Character, &Placement),
    key: &str,
    joints: &Query<&CurrentJointToWorld>,
) -> Option<Mat4> {
    let (character, placement) = holder;
    let joint = joint_of_pose_key(&character.asset.skeleton, key)?;
    Some(joints.get(*character.joints.get(joint)?).ok()?.world(placement))
}

/// Places every attached character where its holder's joint carries it (reads
/// `CurrentJointToWorld`, the holder's `Placement`; writes `Placement` and `Transform`).
/// A holder that is gone leaves it where it stands.
pub fn follow_holders(
    index: Res<CharacterIndex>,
    held: Query<(Entity, &Attached)>,
    mut characters: Query<(&Character, &mut Placement, &mut Transform)>,
    joints: Query<&CurrentJointToWorld>,
) {
    for (entity, attached) in &held {
        let Some(holder) = index.get(attached.to).filter(|&h| h != entity) else { continue };
        let Ok((character, placement, _)) = characters.get(holder) else { continue };
        let Some(joint_world) = holding_joint_world((character, placement), &attached.joint, &joints) else {
            continue;
        };
        if let Ok((_, mut placement, mut transform)) = characters.get_mut(entity) {
            placement.set_if_neq(Placement(attached.placement(joint_world)));
            transform.set_if_neq(placement.to_transform());
        }
    }
}
