//! What the main world hands the render world for each character's skin: its packed
//! vertices ([`SkinUpload`], skinned on the CPU) or its palette ([`GpuSkinJob`], skinned by
//! the compute shader). Plain data, required by [`Character`](super::Character); the
//! systems that fill and take them live in `systems`, `upload` and `gpu_skinning`.

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

/// A character's packed vertices (`floats` per vertex), replaced whenever it is re-skinned
/// or recoloured (its change tick is what the render world looks for).
#[derive(Component, Default, Debug)]
pub struct SkinUpload {
    pub vertices: Arc<Vec<f32>>,
    pub floats: usize,
}

impl SkinUpload {
    /// The buffer to pack into: the previous one when nothing else holds it any more (no
    /// allocation per frame), a new one otherwise.
    pub fn buffer(&mut self) -> &mut Vec<f32> {
        if Arc::get_mut(&mut self.vertices).is_none() {
            self.vertices = Arc::new(Vec::with_capacity(self.vertices.len()));
        }
        Arc::get_mut(&mut self.vertices).expect("the buffer is not shared")
    }

    /// Packs a skin's vertices into this upload (see [`pack_vertices`]).
    pub fn pack(&mut self, positions: &[Vec3], texcoords: &[Vec2], colors: &[[f32; 4]]) {
        self.floats = pack_vertices(positions, texcoords, colors, self.buffer());
    }

    /// Writes new positions over the packed ones, leaving texture coordinates and colours
    /// as they are, and returns their bounds (found in the same pass); none (nothing
    /// written) when the buffer is still held elsewhere, holds another number of vertices
    /// or another layout than [`pack_vertices`] makes, and must be packed whole.
    pub fn repack_positions(&mut self, positions: &[Vec3]) -> Option<(Vec3, Vec3)> {
        let floats = self.floats;
        let buffer = Arc::get_mut(&mut self.vertices)?;
        if buffer.len() != positions.len() * floats {
            return None;
        }
        match floats {
            4 => Some(write_positions::<4>(positions, buffer)),
            6 => Some(write_positions::<6>(positions, buffer)),
            _ => None,
        }
    }

    /// The vertices as the bytes the GPU takes.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.vertices)
    }
}

/// Writes `positions` over the first three floats of each `F`-float vertex of `buffer`
/// (a constant stride, so the copy is three plain stores) and returns their bounds.
fn write_positions<const F: usize>(positions: &[Vec3], buffer: &mut [f32]) -> (Vec3, Vec3) {
    let (slots, _) = buffer.as_chunks_mut::<F>();
    let written = positions.iter().zip(slots).map(|(p, slot)| {
        [slot[0], slot[1], slot[2]] = p.to_array();
        *p
    });
    crate::rig::skinning::bounds_of(written)
}

/// Packs positions, texture coordinates (none, or one per vertex) and colours as the skin
/// mesh's vertex buffer holds them; returns the floats per vertex.
///
/// # Panics
/// When the lengths differ.
pub fn pack_vertices(positions: &[Vec3], texcoords: &[Vec2], colors: &[[f32; 4]], out: &mut Vec<f32>) -> usize {
    assert_eq!(positions.len(), colors.len(), "one colour per vertex");
    out.clear();
    if texcoords.is_empty() {
        out.extend(positions.iter().zip(colors).flat_map(|(p, c)| [p.x, p.y, p.z, color_word(*c)]));
        return 4;
    }
    assert_eq!(positions.len(), texcoords.len(), "texture coordinates for every vertex");
    out.extend(
        positions.iter().zip(texcoords).zip(colors).flat_map(|((p, t), c)| [p.x, p.y, p.z, t.x, t.y, color_word(*c)]),
    );
    6
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
