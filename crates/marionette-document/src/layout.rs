//! Characters side by side by their bounds, and of one height: where characters opened
//! together stand, where an added one goes, and `--match-height`. Boxes are axis-aligned,
//! `(min, max)`; a character's own box is in its model space, as it stands (skinned).

use glam::Vec3;

use marionette_formats::scene::PlacementDoc;

/// The gap between neighbours, as a share of the widest character's width.
pub const GAP_SHARE: f32 = 0.15;

/// The world box of a model box `lo..hi` placed by `placement` (its eight corners moved).
pub fn world_box(lo: Vec3, hi: Vec3, placement: &PlacementDoc) -> (Vec3, Vec3) {
    let m = placement.to_mat4();
    (0..8)
        .map(|i| Vec3::new(corner(i, 0, lo, hi), corner(i, 1, lo, hi), corner(i, 2, lo, hi)))
        .map(|c| m.transform_point3(c))
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)))
}

fn corner(i: usize, axis: usize, lo: Vec3, hi: Vec3) -> f32 {
    if i >> axis & 1 == 0 { lo[axis] } else { hi[axis] }
}

/// The gap between characters whose widest is `widest` wide.
fn gap(widest: f32) -> f32 {
    GAP_SHARE * widest.max(1e-3)
}

/// Translations that stand characters (model boxes `boxes`, scaled by `scales`, not
/// turned) side by side along x in order, a gap apart, centred on the origin, on the
/// floor (y = 0) and centred in z.
pub fn side_by_side(boxes: &[(Vec3, Vec3)], scales: &[f32]) -> Vec<Vec3> {
    let widths: Vec<f32> = boxes.iter().zip(scales).map(|((lo, hi), s)| (hi.x - lo.x) * s).collect();
    let gap = gap(widths.iter().copied().fold(0.0, f32::max));
    let total = widths.iter().sum::<f32>() + gap * boxes.len().saturating_sub(1) as f32;
    let mut left = -total / 2.0;
    boxes
        .iter()
        .zip(scales)
        .zip(&widths)
        .map(|(((lo, hi), &s), &w)| {
            let at = stand_left_at(*lo, *hi, s, left);
            left += w + gap;
            at
        })
        .collect()
}

/// Characters that stand as one: the characters of one glTF file keep the layout the file
/// gives them (each `Some(file)`), every other character stands alone. Returns groups of
/// indices, in order of their first member.
pub fn one_file_groups(files: &[Option<&std::path::Path>]) -> Vec<Vec<usize>> {
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, file) in files.iter().enumerate() {
        match file.and_then(|f| groups.iter_mut().find(|g| files[g[0]] == Some(f))) {
            Some(group) => group.push(i),
            None => groups.push(vec![i]),
        }
    }
    groups
}

/// The box around boxes.
pub fn union(boxes: impl IntoIterator<Item = (Vec3, Vec3)>) -> (Vec3, Vec3) {
    boxes.into_iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), (lo, hi)| (a.min(lo), b.max(hi)))
}

/// The glTF file a source is one character of (none for any other source).
pub fn gltf_file(source: &marionette_formats::scene::SourceDoc) -> Option<&std::path::Path> {
    source.path().filter(|p| marionette_formats::has_parts(p))
}

/// The translation that puts a model box's left side at x = `left`, on the floor,
/// centred in z.
fn stand_left_at(lo: Vec3, hi: Vec3, scale: f32, left: f32) -> Vec3 {
    Vec3::new(left - lo.x * scale, -lo.y * scale, -(lo.z + hi.z) / 2.0 * scale)
}

/// Where a character (model box `lo..hi` at `scale`) goes beside those already in the
/// world (their world boxes): right of all of them, a gap beyond, on the floor; at the
/// origin when there are none.
pub fn beside(world: &[(Vec3, Vec3)], lo: Vec3, hi: Vec3, scale: f32) -> Vec3 {
    let Some(right) = world.iter().map(|b| b.1.x).reduce(f32::max) else {
        return side_by_side(&[(lo, hi)], &[scale])[0];
    };
    let widest = world.iter().map(|(a, b)| b.x - a.x).fold((hi.x - lo.x) * scale, f32::max);
    stand_left_at(lo, hi, scale, right + gap(widest))
}

/// `placement` scaled to `scale` with the feet (the model box's lowest point, `lowest`)
/// kept where they stood.
pub fn rescaled_keeping_feet(placement: &PlacementDoc, lowest: f32, scale: f32) -> PlacementDoc {
    let mut translation = placement.translation;
    translation.y += lowest * (placement.scale - scale);
    PlacementDoc { translation, scale, ..*placement }
}
