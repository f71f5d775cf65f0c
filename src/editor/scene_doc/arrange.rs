//! Arranging the scene's characters once they are skinned (their boxes as they stand):
//! side by side and of one height, by the document layer's layout.

use bevy::math::Vec3;
use bevy::prelude::*;

pub use crate::document::layout::{
    GAP_SHARE, beside, gltf_file, one_file_groups, rescaled_keeping_feet, side_by_side, union, world_box,
};
use crate::editor::scene_doc::document::SceneCharacter;
use crate::formats::scene::PlacementDoc;
use crate::scene::{Placement, PoseDirty, SkinScratch};

/// What `--match-height` and a scene opened from character files ask of the characters
/// once they are skinned (their boxes are then known as they stand).
#[derive(Resource, Default, Clone, Copy, Debug)]
pub struct ArrangeWhenSkinned {
    /// Stand them side by side by their skinned boxes.
    pub side_by_side: bool,
    /// First scale every character to the first one's height.
    pub match_height: bool,
}

/// Once every character is skinned, scales them to the first one's height (when asked)
/// and stands them side by side by their boxes as they stand (when asked; otherwise each
/// keeps its place, feet where they stood) (reads `SkinScratch`; writes `Placement`).
/// Runs once per scene opened.
pub fn arrange_when_skinned(
    mut arrange: ResMut<ArrangeWhenSkinned>,
    mut characters: Query<(&SceneCharacter, &mut Placement, &SkinScratch, &PoseDirty)>,
) {
    let ArrangeWhenSkinned { side_by_side: in_a_row, match_height } = *arrange;
    if !(in_a_row || match_height) || characters.iter().any(|c| *c.3 != PoseDirty::default()) {
        return;
    }
    *arrange = ArrangeWhenSkinned::default();
    let mut characters: Vec<_> =
        characters.iter_mut().map(|(sc, p, s, _)| ((sc.id, sc.source.clone()), p, s.bounds)).collect();
    // Ids follow the document's order.
    characters.sort_by_key(|c| c.0.0);
    let height = |(lo, hi): (Vec3, Vec3)| hi.y - lo.y;
    let target = characters.first().map(|c| height(c.2) * c.1.scale);
    let scales: Vec<f32> = characters
        .iter()
        .map(|(_, placement, bounds)| match target {
            Some(t) if match_height && height(*bounds) > 0.0 => t / height(*bounds),
            _ => placement.scale,
        })
        .collect();
    // The characters of one glTF file move together, keeping the file's layout.
    let files: Vec<Option<&std::path::Path>> = characters.iter().map(|c| gltf_file(&c.0.1)).collect();
    let groups = one_file_groups(&files);
    let boxes: Vec<(Vec3, Vec3)> = groups.iter().map(|g| union(g.iter().map(|&i| characters[i].2))).collect();
    let group_scales: Vec<f32> = groups.iter().map(|g| scales[g[0]]).collect();
    let mut translations = vec![Vec3::ZERO; characters.len()];
    for (group, t) in groups.iter().zip(side_by_side(&boxes, &group_scales)) {
        group.iter().for_each(|&i| translations[i] = t);
    }
    let scales: Vec<f32> = (0..characters.len())
        .map(|i| groups.iter().find(|g| g.contains(&i)).map_or(scales[i], |g| scales[g[0]]))
        .collect();
    for (((_, placement, bounds), scale), translation) in characters.iter_mut().zip(scales).zip(translations) {
        placement.0 = if in_a_row {
            PlacementDoc::new(translation, 0.0, scale)
        } else {
            rescaled_keeping_feet(&placement.0, bounds.0.y, scale)
        };
    }
}
