//! What the main world hands the render world for each character's skin: its skinned
//! positions ([`SkinUpload`], skinned on the CPU) or its palette ([`GpuSkinJob`], skinned
//! by the compute shader), and, only when they change, the attributes the skin material
//! reads beside the positions ([`SkinAttributes`]). Plain data, required by
//! [`Character`](super::Character); the systems that fill and take them live in
//! `systems`, `upload`, `gpu_skinning` and the editor's skin material.

use std::sync::Arc;

use bevy::prelude::*;

use crate::rig::CharacterAsset;
use crate::rig::dqs::SkinningMethod;

/// Frames something handed to the render world (an upload, a GPU skinning job, a write of
/// the skins' attributes) waits for the GPU resource it goes into before it is dropped
/// (the resource is gone).
pub const MAX_WAIT_FRAMES: u32 = 600;

/// Bytes per skin vertex handed to the GPU when a character moves: its position (3 × f32),
/// the whole of the skin mesh's vertex buffer. Texture coordinates and colours live in
/// [`SkinAttributes`], handed on only when they change.
pub const SKIN_VERTEX_BYTES: usize = 3 * 4;

/// The same for a skin with normals (a normal-mapped glTF skin): position and normal.
pub const SKIN_VERTEX_WITH_NORMAL_BYTES: usize = 2 * SKIN_VERTEX_BYTES;

/// A colour as the skin's attributes hold it: each channel clamped to 0–1, to the nearest
/// of 255 steps (the shader unpacks it with `unpack4x8unorm`).
pub fn color_bytes(c: [f32; 4]) -> [u8; 4] {
    c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// Marks a character skinned on the CPU whose positions (`SkinScratch::positions`) go to
/// the GPU: changed whenever they moved, which is what the render world looks for.
#[derive(Component, Default, Debug)]
pub struct SkinUpload {
    /// The vertices skinned (the positions the render world takes).
    pub vertex_count: usize,
    /// Whether their normals go with them.
    pub with_normals: bool,
}

impl SkinUpload {
    /// Bytes of the mesh's vertex buffer the positions (and normals) fill.
    pub fn byte_len(&self) -> usize {
        self.vertex_count * if self.with_normals { SKIN_VERTEX_WITH_NORMAL_BYTES } else { SKIN_VERTEX_BYTES }
    }
}

/// What the skin material reads for each vertex besides its position: texture coordinates
/// (u and v as float bits; zero where the skin has none) and the colour
/// ([`color_bytes`] as one little-endian word). Packed when the colours change, and only
/// then: its change tick is what the material's buffer follows.
#[derive(Component, Default, Debug)]
pub struct SkinAttributes(pub Vec<[u32; 3]>);

impl SkinAttributes {
    /// Packs a skin's texture coordinates (none, or one per colour) and colours.
    ///
    /// # Panics
    /// When there are texture coordinates, but not one per colour.
    pub fn pack(&mut self, texcoords: &[Vec2], colors: &[[f32; 4]]) {
        assert!(texcoords.is_empty() || texcoords.len() == colors.len(), "texture coordinates for every vertex");
        self.0.clear();
        self.0.extend(colors.iter().enumerate().map(|(k, c)| {
            let [u, v] = texcoords.get(k).map_or([0, 0], |t| [t.x.to_bits(), t.y.to_bits()]);
            [u, v, u32::from_le_bytes(color_bytes(*c))]
        }));
    }

    /// The colour of vertex `k` (each channel in 0–1, as the shader unpacks it).
    pub fn color(&self, k: usize) -> Option<[f32; 4]> {
        Some(self.0.get(k)?[2].to_le_bytes().map(|b| f32::from(b) / 255.0))
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

/// What the render world needs to skin a character on the GPU (`None`: it is skinned on
/// the CPU). Replaced whenever the character is re-posed.
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
}
