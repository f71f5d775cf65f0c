//! Handing skinned vertices to the GPU without Bevy's whole-mesh path: the skinning system
//! packs each re-skinned character's vertices (position, texture coordinates where the
//! skin has them, colour: the skin mesh's own layout) into its [`SkinUpload`]; the render world takes the changed ones (an `Arc`, no
//! copy) and writes them straight into the mesh's slot of the vertex buffer. The skin mesh
//! asset itself is never modified after it is made, so Bevy neither clones it into the
//! render world nor re-packs it each frame, and indices stay as they were uploaded.

use std::collections::HashMap;
use std::sync::Arc;

use bevy::prelude::*;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::renderer::RenderQueue;
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};

use super::components::Character;

/// Bytes per skin vertex without texture coordinates: position (3 × f32) then colour
/// (4 × f32), the order in which Bevy packs the mesh's attributes. Texture coordinates
/// (2 × f32) go between them where a skin has them.
pub const SKIN_VERTEX_BYTES: usize = 7 * 4;

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

    /// The vertices as the bytes the GPU takes.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.vertices)
    }
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
        out.extend(positions.iter().zip(colors).flat_map(|(p, c)| [p.x, p.y, p.z, c[0], c[1], c[2], c[3]]));
        return 7;
    }
    assert_eq!(positions.len(), texcoords.len(), "texture coordinates for every vertex");
    out.extend(
        positions
            .iter()
            .zip(texcoords)
            .zip(colors)
            .flat_map(|((p, t), c)| [p.x, p.y, p.z, t.x, t.y, c[0], c[1], c[2], c[3]]),
    );
    9
}

/// Bytes handed to the GPU in the last frame (the packed uploads that changed, and the
/// palettes of characters skinned on the GPU), for benchmarks and readouts.
#[derive(Resource, Default, Debug)]
pub struct HandedOn(pub usize);

/// Counts the packed vertices that changed and, for characters skinned on the GPU, their
/// palettes (reads `SkinUpload`, `GpuSkinJob`; writes `HandedOn`).
fn count_handed_on(
    changed: Query<&SkinUpload, Changed<SkinUpload>>,
    gpu_jobs: Query<&super::gpu_skinning::GpuSkinJob, Changed<super::gpu_skinning::GpuSkinJob>>,
    mut handed: ResMut<HandedOn>,
) {
    let palettes: usize =
        gpu_jobs.iter().filter_map(|j| j.0.as_ref()).map(|j| std::mem::size_of_val(j.palette.as_slice())).sum();
    handed.0 = changed.iter().map(|u| u.bytes().len()).sum::<usize>() + palettes;
}

/// Uploads waiting in the render world: by mesh, the newest bytes (kept until the mesh has
/// its slot on the GPU), with the frames waited.
#[derive(Resource, Default)]
struct PendingUploads(HashMap<AssetId<Mesh>, (Arc<Vec<f32>>, usize, u32)>);

/// Frames an upload waits for its mesh's slot before it is dropped (the mesh is gone).
const MAX_WAIT_FRAMES: u32 = 600;

/// The render-world half: extraction of changed uploads and the buffer writes.
pub struct SkinUploadPlugin;

impl Plugin for SkinUploadPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<HandedOn>().add_systems(Last, count_handed_on);
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .init_resource::<PendingUploads>()
            .add_systems(ExtractSchedule, extract_skin_uploads)
            .add_systems(Render, write_skin_uploads.in_set(RenderSystems::PrepareMeshes));
    }
}

/// Takes the uploads that changed this frame (reads `SkinUpload`; writes `PendingUploads`).
fn extract_skin_uploads(
    skins: Extract<Query<(&Character, &SkinUpload), Changed<SkinUpload>>>,
    mut pending: ResMut<PendingUploads>,
) {
    for (character, upload) in &skins {
        if !upload.vertices.is_empty() {
            pending.0.insert(character.mesh.id(), (upload.vertices.clone(), upload.floats, 0));
        }
    }
}

/// Writes each pending upload into its mesh's slot of the vertex buffer, after Bevy has
/// allocated and filled the slots of new meshes (reads `MeshAllocator`; writes GPU buffers).
fn write_skin_uploads(
    mut pending: ResMut<PendingUploads>,
    allocator: Option<Res<MeshAllocator>>,
    queue: Res<RenderQueue>,
) {
    let Some(allocator) = allocator else { return };
    pending.0.retain(|id, (vertices, floats, waited)| {
        let Some(slice) = allocator.mesh_vertex_slice(id) else {
            *waited += 1;
            return *waited < MAX_WAIT_FRAMES;
        };
        if (slice.range.end - slice.range.start) as usize * *floats == vertices.len() {
            let offset = (slice.range.start as usize * *floats * 4) as u64;
            queue.write_buffer(slice.buffer, offset, bytemuck::cast_slice(vertices));
        }
        false
    });
}
