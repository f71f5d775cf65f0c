//! What the main world hands the render world for each character's skin: its skinned
//! positions with their packed attributes ([`SkinUpload`], skinned on the CPU) or its
//! palette ([`GpuSkinJob`], skinned by the compute shader). Plain data, required by
//! [`Character`](super::Character); the systems that fill and take them live in
//! `systems`, `upload` and `gpu_skinning`.

use std::sync::Arc;

use bevy::prelude::*;

use crate::rig::CharacterAsset;
use crate::rig::dqs::SkinningMethod;

/// Bytes per skin vertex without texture coordinates: position (3 × f32) then colour
/// (4 × u8, [`SKIN_COLOR`]), the order in which Bevy packs the mesh's attributes. Texture
/// coordinates (2 × f32) go between them where a skin has them.
pub const SKIN_VERTEX_BYTES: usize = 4 * 4;

/// The skin mesh's vertex colour: Bevy's own attribute (its id, so the PBR shader takes it
/// at its location as a `vec4<f32>`) in four bytes (unorm8x4) instead of four floats: 16
/// bytes a vertex handed on instead of 28.
pub const SKIN_COLOR: bevy::mesh::MeshVertexAttribute =
    bevy::mesh::MeshVertexAttribute::new("Vertex_Color", 5, bevy::render::render_resource::VertexFormat::Unorm8x4);

/// A colour as [`SKIN_COLOR`] holds it: each channel clamped to 0–1, to the nearest of 255
/// steps.
pub fn color_bytes(c: [f32; 4]) -> [u8; 4] {
    c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// Packed colour bytes in the slot of one float of the upload.
fn color_word(c: [f32; 4]) -> f32 {
    f32::from_bits(u32::from_le_bytes(color_bytes(c)))
}

/// What follows each skinned position in the skin mesh's vertex layout (texture
/// coordinates where the skin has them, then the colour word), packed once and again only
/// when the colours change. The render world interleaves them with the skinned positions
/// (`SkinScratch::positions`) as it writes them into the mesh's slot, so a pose change
/// copies nothing on the main world's side. Marked changed whenever either changed: its
/// change tick is what the render world looks for.
#[derive(Component, Default, Debug)]
pub struct SkinUpload {
    /// `floats - 3` per vertex.
    pub attributes: Arc<Vec<f32>>,
    /// Floats per vertex in the mesh's layout: the position's three, then the attributes.
    pub floats: usize,
}

impl SkinUpload {
    /// Packs a skin's texture coordinates and colours (see [`pack_attributes`]).
    pub fn pack_attributes(&mut self, texcoords: &[Vec2], colors: &[[f32; 4]]) {
        self.floats = pack_attributes(texcoords, colors, reclaimed(&mut self.attributes));
    }

    /// The vertices the attributes are packed for.
    pub fn vertex_count(&self) -> usize {
        self.attributes.len().checked_div(self.floats.saturating_sub(3)).unwrap_or(0)
    }

    /// Bytes of the mesh's vertex buffer these attributes and their positions fill.
    pub fn byte_len(&self) -> usize {
        self.vertex_count() * self.floats * 4
    }
}

/// The vector behind `shared`, to overwrite: the same one when nothing else holds it any
/// more (no allocation per frame; the render world drops its copy once written), a new
/// empty one otherwise.
pub fn reclaimed<T>(shared: &mut Arc<Vec<T>>) -> &mut Vec<T> {
    if Arc::get_mut(shared).is_none() {
        *shared = Arc::new(Vec::with_capacity(shared.len()));
    }
    Arc::get_mut(shared).expect("a vector of its own")
}

/// Packs the attributes that follow each position in the skin mesh's layout: texture
/// coordinates (none, or one per vertex), then the colour ([`SKIN_COLOR`]) in the slot of
/// one float; returns the floats per vertex of the whole layout (4 or 6).
///
/// # Panics
/// When there are texture coordinates, but not one per colour.
pub fn pack_attributes(texcoords: &[Vec2], colors: &[[f32; 4]], out: &mut Vec<f32>) -> usize {
    out.clear();
    if texcoords.is_empty() {
        out.extend(colors.iter().map(|c| color_word(*c)));
        return 4;
    }
    assert_eq!(colors.len(), texcoords.len(), "texture coordinates for every vertex");
    out.extend(texcoords.iter().zip(colors).flat_map(|(t, c)| [t.x, t.y, color_word(*c)]));
    6
}

/// Each vertex in the skin mesh's layout of `F` floats: its position, then its `F - 3`
/// packed attributes (as [`pack_attributes`] makes them). Stops at the shorter input.
pub fn interleaved<'a, const F: usize>(
    positions: &'a [Vec3],
    attributes: &'a [f32],
) -> impl Iterator<Item = [f32; F]> + 'a {
    positions
        .iter()
        .zip(attributes.chunks_exact(F - 3))
        .map(|(p, rest)| std::array::from_fn(|k| if k < 3 { p[k] } else { rest[k - 3] }))
}

/// Packs positions, texture coordinates (none, or one per vertex) and colours as the skin
/// mesh's vertex buffer holds them; returns the floats per vertex.
///
/// # Panics
/// When the lengths differ.
pub fn pack_vertices(positions: &[Vec3], texcoords: &[Vec2], colors: &[[f32; 4]], out: &mut Vec<f32>) -> usize {
    assert_eq!(positions.len(), colors.len(), "one colour per vertex");
    let mut attributes = Vec::new();
    let floats = pack_attributes(texcoords, colors, &mut attributes);
    out.clear();
    match floats {
        4 => out.extend(interleaved::<4>(positions, &attributes).flatten()),
        _ => out.extend(interleaved::<6>(positions, &attributes).flatten()),
    }
    floats
}

/// What the render world needs to skin a character on the GPU (`None`: it is skinned on
/// the CPU). Replaced whenever the character is re-posed or recoloured.
#[derive(Component, Default)]
pub struct GpuSkinJob(pub Option<GpuSkinInput>);

/// One character's input to the compute shader.
#[derive(Clone)]
pub struct GpuSkinInput {
    /// The asset whose bind positions and influences are skinned.
    pub asset: Arc<CharacterAsset>,
    /// Linear blend: the palette matrices. Dual quaternion: columns (real, dual, 0, 0).
    pub palette: Arc<Vec<Mat4>>,
    pub method: SkinningMethod,
    /// The packed vertices at the bind pose (positions, texture coordinates, colours);
    /// the shader overwrites the positions.
    pub template: Arc<Vec<f32>>,
    /// Floats per packed vertex.
    pub floats: usize,
}
