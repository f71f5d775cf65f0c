//! Handing skinned vertices to the GPU without Bevy's whole-mesh path: the skinning system
//! skins each re-posed character's positions into its `SkinScratch` and marks its
//! [`SkinUpload`] changed; the render world takes the changed ones (an `Arc`, no copy) and
//! copies them straight into the staging memory of the mesh's slot of the vertex buffer,
//! which holds positions only (12 bytes a vertex; a normal-mapped skin's normal after each
//! position, 24): texture coordinates and colours are in
//! the skin materials' buffer ([`SkinAttributes`](super::handoff::SkinAttributes)), written
//! only when they change. The skin mesh asset itself is never modified after it is made,
//! so Bevy neither clones it into the render world nor re-packs it each frame, and indices
//! stay as they were uploaded.

use std::collections::HashMap;
use std::sync::Arc;

use bevy::prelude::*;
use bevy::render::mesh::allocator::{MeshAllocator, MeshBufferSlice};
use bevy::render::render_resource::BufferSize;
use bevy::render::renderer::RenderQueue;
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};

use super::components::{Character, SkinScratch};

pub use super::handoff::{SKIN_VERTEX_BYTES, SKIN_VERTEX_WITH_NORMAL_BYTES, SkinAttributes, SkinUpload};

/// Bytes handed to the GPU in the last frame (the positions of the uploads that changed,
/// the attributes that changed, and the palettes of characters skinned on the GPU), for
/// benchmarks and readouts.
#[derive(Resource, Default, Debug)]
pub struct HandedOn(pub usize);

/// Counts the positions and attributes that changed and, for characters skinned on the
/// GPU, their palettes (reads `SkinUpload`, `SkinAttributes`, `GpuSkinJob`; writes
/// `HandedOn`).
fn count_handed_on(
    changed: Query<&SkinUpload, Changed<SkinUpload>>,
    recolored: Query<&SkinAttributes, Changed<SkinAttributes>>,
    gpu_jobs: Query<&super::handoff::GpuSkinJob, Changed<super::handoff::GpuSkinJob>>,
    mut handed: ResMut<HandedOn>,
) {
    let palettes: usize =
        gpu_jobs.iter().filter_map(|j| j.0.as_ref()).map(|j| std::mem::size_of_val(j.palette.as_slice())).sum();
    let attributes: usize = recolored.iter().map(|a| std::mem::size_of_val(a.0.as_slice())).sum();
    handed.0 = changed.iter().map(SkinUpload::byte_len).sum::<usize>() + attributes + palettes;
}

/// An upload waiting for its mesh's slot: the character's skinned positions (and normals,
/// where it has them), the range of them that mesh shows, and the frames waited.
struct Pending {
    positions: Arc<Vec<Vec3>>,
    normals: Option<Arc<Vec<Vec3>>>,
    range: std::ops::Range<u32>,
    waited: u32,
}

impl Pending {
    /// The positions of this part's vertices; none when they do not hold all of them.
    fn part(&self) -> Option<&[Vec3]> {
        self.positions.get(self.range.start as usize..self.range.end as usize)
    }

    /// The normals of this part's vertices: none when the skin has none, or they do not
    /// hold all of them.
    fn part_normals(&self) -> Option<&[Vec3]> {
        self.normals.as_ref()?.get(self.range.start as usize..self.range.end as usize)
    }
}

/// Uploads waiting in the render world: by mesh, the newest bytes (kept until the mesh has
/// its slot on the GPU).
#[derive(Resource, Default)]
struct PendingUploads(HashMap<AssetId<Mesh>, Pending>);

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

/// Takes the uploads that changed this frame (reads `SkinUpload`, `SkinScratch`; writes
/// `PendingUploads`).
fn extract_skin_uploads(
    skins: Extract<Query<(&Character, &SkinUpload, &SkinScratch), Changed<SkinUpload>>>,
    mut pending: ResMut<PendingUploads>,
) {
    for (character, upload, scratch) in &skins {
        if upload.vertex_count == 0 {
            continue;
        }
        for part in &character.skins {
            let (positions, range) = (scratch.positions.clone(), part.vertices.clone());
            let normals = upload.with_normals.then(|| scratch.normals.clone());
            pending.0.insert(part.mesh.id(), Pending { positions, normals, range, waited: 0 });
        }
    }
}

/// Copies each pending upload into its mesh's slot of the vertex buffer, through the
/// staging memory the queue copies from, after Bevy has allocated and filled the slots
/// of new meshes (reads `MeshAllocator`; writes GPU buffers). Slots that follow one another
/// in a buffer (a crowd's meshes, allocated in turn) are written through one staging
/// allocation: each allocation costs about as much as filling a body's slot.
fn write_skin_uploads(
    mut pending: ResMut<PendingUploads>,
    allocator: Option<Res<MeshAllocator>>,
    queue: Res<RenderQueue>,
) {
    let Some(allocator) = allocator else { return };
    let (ready, waiting): (Vec<_>, Vec<_>) =
        pending.0.drain().partition(|(id, _)| allocator.mesh_vertex_slice(id).is_some());
    pending.0.extend(waiting.into_iter().filter_map(|(id, mut upload)| {
        upload.waited += 1;
        (upload.waited < super::handoff::MAX_WAIT_FRAMES).then_some((id, upload))
    }));
    let mut writes: Vec<SlotWrite> =
        ready.iter().filter_map(|(id, upload)| SlotWrite::of(allocator.mesh_vertex_slice(id)?, upload)).collect();
    writes.sort_by_key(|w| (w.buffer.id(), w.offset));
    for run in writes.chunk_by(|a, b| a.buffer.id() == b.buffer.id() && a.end() == b.offset) {
        write_run(&queue, run);
    }
}

/// One mesh's slot and what goes in it.
struct SlotWrite<'a> {
    buffer: &'a bevy::render::render_resource::Buffer,
    /// Bytes into the buffer.
    offset: u64,
    positions: &'a [Vec3],
    /// The normals after each position, where the mesh has them.
    normals: Option<&'a [Vec3]>,
}

impl<'a> SlotWrite<'a> {
    /// The write of `upload` into `slice`; none when its vertices do not fill the slot
    /// exactly.
    fn of(slice: MeshBufferSlice<'a>, upload: &'a Pending) -> Option<Self> {
        let (positions, normals) = (upload.part()?, upload.part_normals());
        let write = Self { buffer: slice.buffer, offset: 0, positions, normals };
        (positions.len() == (slice.range.end - slice.range.start) as usize)
            .then(|| Self { offset: u64::from(slice.range.start) * write.vertex_bytes(), ..write })
    }

    /// Bytes a vertex takes in the slot.
    fn vertex_bytes(&self) -> u64 {
        (if self.normals.is_some() { SKIN_VERTEX_WITH_NORMAL_BYTES } else { SKIN_VERTEX_BYTES }) as u64
    }

    /// The byte after the slot.
    fn end(&self) -> u64 {
        self.offset + self.positions.len() as u64 * self.vertex_bytes()
    }

    /// Fills the slot's staging bytes: the positions as they are, or each followed by its
    /// normal (interleaved through a small buffer on the stack).
    fn fill(&self, mut slot: wgpu_types::WriteOnly<[u8]>) {
        let Some(normals) = self.normals else {
            slot.copy_from_slice(bytemuck::cast_slice(self.positions));
            return;
        };
        const STEP: usize = 256;
        let mut vertices = [[Vec3::ZERO; 2]; STEP];
        for (k, (positions, normals)) in self.positions.chunks(STEP).zip(normals.chunks(STEP)).enumerate() {
            let vertices = &mut vertices[..positions.len()];
            vertices.iter_mut().zip(positions.iter().zip(normals)).for_each(|(v, (&p, &n))| *v = [p, n]);
            let at = k * STEP * SKIN_VERTEX_WITH_NORMAL_BYTES;
            let bytes: &[u8] = bytemuck::cast_slice(vertices);
            slot.slice(at..at + bytes.len()).copy_from_slice(bytes);
        }
    }
}

/// Writes slots that follow one another in one buffer through one staging allocation,
/// several slots at once on the compute task pool: filling the staging memory is most of
/// the write's time (64 SMPL bodies, 5.3 MB: 0.72 ms on one thread, 0.46 ms on two).
fn write_run(queue: &RenderQueue, run: &[SlotWrite]) {
    let (Some(first), Some(last)) = (run.first(), run.last()) else { return };
    let Some(mut view) = BufferSize::new(last.end() - first.offset)
        .and_then(|size| queue.write_buffer_with(first.buffer, first.offset, size))
    else {
        return;
    };
    // The run's slots follow one another with no gap: the view splits into them in order.
    let mut rest = view.slice(..);
    let mut slots = Vec::with_capacity(run.len());
    for write in run {
        let (slot, tail) = rest.split_at((write.end() - write.offset) as usize);
        slots.push((write, SlotBytes(slot)));
        rest = tail;
    }
    let pool = bevy::tasks::ComputeTaskPool::get();
    let per_task = slots.len().div_ceil(pool.thread_num().max(1) * SLOT_TASKS_PER_THREAD);
    pool.scope(|scope| {
        let mut slots = slots.into_iter().peekable();
        while slots.peek().is_some() {
            let batch: Vec<_> = slots.by_ref().take(per_task).collect();
            scope.spawn(async move {
                for (write, SlotBytes(slot)) in batch {
                    write.fill(slot);
                }
            });
        }
    });
}

/// One slot's bytes of the staging memory, to fill on another thread. (wgpu's `WriteOnly`
/// is `Send` only for sized `T`; its own reasoning — exclusive access, like `&mut T`, needs
/// only `T: Send` — holds for `[u8]` as well.)
struct SlotBytes<'a>(wgpu_types::WriteOnly<'a, [u8]>);

// SAFETY: a `WriteOnly<[u8]>` is exclusive access to bytes, as `&mut [u8]` is (which is
// `Send`); wgpu's own impl leaves out unsized `T` only by its implicit `Sized` bound.
unsafe impl Send for SlotBytes<'_> {}

/// Tasks a thread of the pool gets when slots are filled at once (a few, so that a thread
/// held up elsewhere leaves its share to the others).
const SLOT_TASKS_PER_THREAD: usize = 4;
