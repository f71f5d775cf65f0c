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

pub use super::handoff::{SKIN_VERTEX_BYTES, SkinUpload, pack_vertices};

/// Bytes handed to the GPU in the last frame (the packed uploads that changed, and the
/// palettes of characters skinned on the GPU), for benchmarks and readouts.
#[derive(Resource, Default, Debug)]
pub struct HandedOn(pub usize);

/// Counts the packed vertices that changed and, for characters skinned on the GPU, their
/// palettes (reads `SkinUpload`, `GpuSkinJob`; writes `HandedOn`).
fn count_handed_on(
    changed: Query<&SkinUpload, Changed<SkinUpload>>,
    gpu_jobs: Query<&super::handoff::GpuSkinJob, Changed<super::handoff::GpuSkinJob>>,
    mut handed: ResMut<HandedOn>,
) {
    let palettes: usize =
        gpu_jobs.iter().filter_map(|j| j.0.as_ref()).map(|j| std::mem::size_of_val(j.palette.as_slice())).sum();
    handed.0 = changed.iter().map(|u| u.bytes().len()).sum::<usize>() + palettes;
}

/// An upload waiting for its mesh's slot: the character's packed vertices, the floats per
/// vertex, the range of vertices that mesh shows, and the frames waited.
struct Pending {
    vertices: Arc<Vec<f32>>,
    floats: usize,
    range: std::ops::Range<u32>,
    waited: u32,
}

/// Uploads waiting in the render world: by mesh, the newest bytes (kept until the mesh has
/// its slot on the GPU).
#[derive(Resource, Default)]
struct PendingUploads(HashMap<AssetId<Mesh>, Pending>);

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
        if upload.vertices.is_empty() {
            continue;
        }
        for part in &character.skins {
            let (vertices, floats, range) = (upload.vertices.clone(), upload.floats, part.vertices.clone());
            pending.0.insert(part.mesh.id(), Pending { vertices, floats, range, waited: 0 });
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
    pending.0.retain(|id, upload| {
        let Some(slice) = allocator.mesh_vertex_slice(id) else {
            upload.waited += 1;
            return upload.waited < MAX_WAIT_FRAMES;
        };
        let floats = upload.floats;
        let part = upload.vertices.get(upload.range.start as usize * floats..upload.range.end as usize * floats);
        if let Some(part) = part.filter(|p| (slice.range.end - slice.range.start) as usize * floats == p.len()) {
            let offset = (slice.range.start as usize * floats * 4) as u64;
            queue.write_buffer(slice.buffer, offset, bytemuck::cast_slice(part));
        }
        false
    });
}
