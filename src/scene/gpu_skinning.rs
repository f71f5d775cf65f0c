//! GPU skinning (the 6.837 assignment's "accelerate SSD using shaders"): a compute shader
//! (`gpu_skinning.wgsl`) takes the same palette and bind data as the CPU kernels and writes
//! the skinned positions, which are copied into the mesh's slot of the vertex buffer (the
//! positions are the whole of it: the material reads the other attributes). Chosen per
//! character ([`SkinOnGpu`](super::SkinOnGpu), the inspector, the scene file); the CPU path
//! stays the default.
//!
//! The main world hands over each re-posed character's palette ([`GpuSkinJob`]); the render
//! world keeps, per character, the bind positions and influences on the GPU (uploaded once
//! per asset), and dispatches one invocation per vertex.
//!
//! Flat normals need no pass: the skin material lights each triangle with its own normal.
//! Culling is off for these skins ([`NoFrustumCulling`]): the main world has no skinned
//! vertices to bound them by (its bounds are the influence boxes' hull, see
//! [`influence_hull_bounds`](crate::rig::skinning::influence_hull_bounds), which holds every
//! linear-blend vertex but not every dual-quaternion one).

use std::collections::HashMap;
use std::sync::Arc;

use bevy::camera::visibility::NoFrustumCulling;
use bevy::prelude::*;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_resource::{
    BindGroup, BindGroupEntry, BindGroupLayout, BindGroupLayoutEntry, BindingType, Buffer, BufferBindingType,
    BufferDescriptor, BufferUsages, CommandEncoderDescriptor, ComputePassDescriptor, ComputePipeline, MapMode,
    PipelineCompilationOptions, PipelineLayoutDescriptor, PollType, RawComputePipelineDescriptor,
    ShaderModuleDescriptor, ShaderSource, ShaderStages,
};
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};

use super::components::{Character, SkinOnGpu, SkinScratch};
use crate::rig::CharacterAsset;
use crate::rig::dqs::{self, SkinningMethod};

pub use super::handoff::{GpuSkinInput, GpuSkinJob};

/// Hands over the character's palette (from `scratch`, as `method` takes it) in its job.
pub fn hand_over(job: &mut GpuSkinJob, character: &Character, method: SkinningMethod, scratch: &mut SkinScratch) {
    let palette = if method.is_linear() {
        scratch.palette.clone()
    } else {
        dqs::dual_quaternion_palette(&scratch.palette, &mut scratch.dual_quaternions);
        scratch.dual_quaternions.iter().map(|q| Mat4::from_cols(q.real, q.dual, Vec4::ZERO, Vec4::ZERO)).collect()
    };
    job.0 = Some(GpuSkinInput { asset: character.asset.clone(), palette: Arc::new(palette), method });
}

/// The compute path: culling off for GPU-skinned skins, extraction of the jobs, the
/// dispatches.
pub struct GpuSkinningPlugin;

impl Plugin for GpuSkinningPlugin {
    fn build(&self, app: &mut App) {
        // In `Draw`, not `Skin`: its commands would end the skin phase with a sync point of
        // its own (0.05–0.13 ms a frame at 64 SMPL bodies), and `Draw` holds one already.
        app.add_systems(PostUpdate, cull_only_cpu_skins.in_set(super::MarionetteSystems::Draw));
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
            return;
        };
        render_app
            .init_resource::<GpuSkins>()
            .add_systems(ExtractSchedule, extract_gpu_skin_jobs)
            .add_systems(Render, dispatch_gpu_skinning.in_set(RenderSystems::PrepareMeshes));
    }
}

/// Turns frustum culling off for skins skinned on the GPU and back on for the others
/// (reads `SkinOnGpu`; writes `NoFrustumCulling` on skin entities).
fn cull_only_cpu_skins(mut commands: Commands, characters: Query<(&Character, &SkinOnGpu), Changed<SkinOnGpu>>) {
    for (character, on_gpu) in &characters {
        for part in &character.skins {
            let Ok(mut skin) = commands.get_entity(part.entity) else { continue };
            if on_gpu.0 && character.skins.len() == 1 {
                skin.insert(NoFrustumCulling);
            } else {
                skin.remove::<NoFrustumCulling>();
            }
        }
    }
}

/// The render world's GPU skinning state.
#[derive(Resource, Default)]
struct GpuSkins {
    pipeline: Option<SkinningPipeline>,
    /// By character entity (main world).
    skins: HashMap<Entity, SkinBuffers>,
    /// Jobs waiting for their dispatch (their mesh's slot), by character entity.
    pending: HashMap<Entity, (AssetId<Mesh>, GpuSkinInput, u32)>,
}

struct SkinningPipeline {
    layout: BindGroupLayout,
    pipeline: ComputePipeline,
}

/// One character's buffers on the GPU.
struct SkinBuffers {
    /// The asset they were made from.
    asset: Arc<CharacterAsset>,
    params: Buffer,
    /// What `params` holds (written when it changes: the method).
    written_params: Option<[u32; 4]>,
    palette: Buffer,
    vertices: Buffer,
    bind_group: BindGroup,
}

/// Takes the jobs that changed; forgets characters that are gone or went back to the CPU
/// (reads `GpuSkinJob`; writes `GpuSkins`).
fn extract_gpu_skin_jobs(jobs: Extract<Query<(Entity, &Character, Ref<GpuSkinJob>)>>, mut gpu: ResMut<GpuSkins>) {
    let gpu = &mut *gpu;
    gpu.skins.retain(|e, _| jobs.get(*e).is_ok_and(|(_, _, job)| job.0.is_some()));
    gpu.pending.retain(|e, _| jobs.get(*e).is_ok_and(|(_, _, job)| job.0.is_some()));
    for (entity, character, job) in &jobs {
        if let Some(input) = job.0.as_ref().filter(|_| job.is_changed()) {
            gpu.pending.insert(entity, (character.skins[0].mesh.id(), input.clone(), 0));
        }
    }
}

/// Skins each pending character on the GPU into its mesh's slot of the vertex buffer, after
/// Bevy has allocated the slots of new meshes (reads `MeshAllocator`; writes GPU buffers):
/// its palette written, every character dispatched in one compute pass, then each one's
/// positions copied into its slot. (A pass and a parameter write a character, each frame,
/// cost 256 bodies 4.8 ms of the upload on llvmpipe.)
fn dispatch_gpu_skinning(
    mut gpu: ResMut<GpuSkins>,
    allocator: Option<Res<MeshAllocator>>,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
) {
    let Some(allocator) = allocator else { return };
    if gpu.pending.is_empty() {
        return;
    }
    let gpu = &mut *gpu;
    let pipeline = gpu.pipeline.get_or_insert_with(|| SkinningPipeline::new(&device));
    // Each ready character's entity, its slot's buffer and byte offset, and vertex count.
    let mut ready = Vec::new();
    gpu.pending.retain(|entity, (mesh, input, waited)| {
        let Some(slice) = allocator.mesh_vertex_slice(mesh) else {
            *waited += 1;
            return *waited < super::handoff::MAX_WAIT_FRAMES;
        };
        let vertex_count = input.asset.vertex_count();
        if (slice.range.end - slice.range.start) as usize != vertex_count {
            return false;
        }
        let skin = match gpu.skins.get_mut(entity) {
            Some(skin) if Arc::ptr_eq(&skin.asset, &input.asset) => skin,
            _ => gpu.skins.entry(*entity).insert_entry(SkinBuffers::new(&device, pipeline, input)).into_mut(),
        };
        let params = [vertex_count as u32, u32::from(!input.method.is_linear()), 0, 0];
        if skin.written_params != Some(params) {
            queue.write_buffer(&skin.params, 0, bytemuck::cast_slice(&params));
            skin.written_params = Some(params);
        }
        queue.write_buffer(&skin.palette, 0, bytemuck::cast_slice(input.palette.as_slice()));
        ready.push((*entity, slice.buffer.clone(), u64::from(slice.range.start) * VERTEX_BYTES, vertex_count));
        false
    });
    let mut encoder =
        device.create_command_encoder(&CommandEncoderDescriptor { label: Some("marionette gpu skinning") });
    {
        let mut pass =
            encoder.begin_compute_pass(&ComputePassDescriptor { label: Some("skin"), timestamp_writes: None });
        pass.set_pipeline(&pipeline.pipeline);
        for (entity, _, _, vertex_count) in &ready {
            pass.set_bind_group(0, &*gpu.skins[entity].bind_group, &[]);
            let (x, y) = workgroups(*vertex_count);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
    for (entity, slot, offset, vertex_count) in &ready {
        encoder.copy_buffer_to_buffer(
            &gpu.skins[entity].vertices,
            0,
            slot,
            *offset,
            *vertex_count as u64 * VERTEX_BYTES,
        );
    }
    queue.submit([encoder.finish()]);
}

/// Bytes of a skin vertex in the vertex buffer (its position).
const VERTEX_BYTES: u64 = super::handoff::SKIN_VERTEX_BYTES as u64;

/// Vertices per workgroup (the shader's `@workgroup_size`).
const WORKGROUP: usize = 64;

/// Workgroups in x and y for `vertex_count` vertices (x at most 65,535, the least limit).
fn workgroups(vertex_count: usize) -> (u32, u32) {
    let groups = vertex_count.div_ceil(WORKGROUP).max(1);
    let x = groups.min(65_535);
    (x as u32, groups.div_ceil(x) as u32)
}

impl SkinningPipeline {
    fn new(device: &RenderDevice) -> Self {
        let storage = |binding: u32, read_only: bool| BindGroupLayoutEntry {
            binding,
            visibility: ShaderStages::COMPUTE,
            ty: BindingType::Buffer {
                ty: BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let params = BindGroupLayoutEntry {
            binding: 0,
            visibility: ShaderStages::COMPUTE,
            ty: BindingType::Buffer {
                ty: BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let entries =
            [params, storage(1, true), storage(2, true), storage(3, true), storage(4, true), storage(5, false)];
        let layout = device.create_bind_group_layout("marionette gpu skinning", &entries);
        let module = device.create_and_validate_shader_module(ShaderModuleDescriptor {
            label: Some("gpu_skinning.wgsl"),
            source: ShaderSource::Wgsl(include_str!("gpu_skinning.wgsl").into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&PipelineLayoutDescriptor {
            label: Some("marionette gpu skinning"),
            bind_group_layouts: &[Some(&*layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&RawComputePipelineDescriptor {
            label: Some("marionette gpu skinning"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("skin"),
            compilation_options: PipelineCompilationOptions::default(),
            cache: None,
        });
        Self { layout, pipeline }
    }
}

impl SkinBuffers {
    /// The asset's bind positions and influences on the GPU, and room for the palette and
    /// the skinned positions.
    fn new(device: &RenderDevice, pipeline: &SkinningPipeline, input: &GpuSkinInput) -> Self {
        let skin = &input.asset.skin;
        // A skin without vertices still gets buffers a binding accepts (not empty ones).
        let with_data = |label: &str, contents: &[u8]| {
            let mut padded = contents.to_vec();
            padded.resize(contents.len().max(16), 0);
            device.create_buffer_with_data(&bevy::render::render_resource::BufferInitDescriptor {
                label: Some(label),
                contents: &padded,
                usage: BufferUsages::STORAGE,
            })
        };
        let empty = |label: &str, size: usize, usage: BufferUsages| {
            device.create_buffer(&BufferDescriptor {
                label: Some(label),
                size: size.max(16) as u64,
                usage: usage | BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let positions: Vec<f32> = skin.bind_positions.iter().flat_map(|p| p.to_array()).collect();
        let influences: Vec<[u32; 2]> =
            skin.weights.influences().iter().map(|i| [u32::from(i.joint), i.weight.to_bits()]).collect();
        let bind = with_data("bind positions", bytemuck::cast_slice(&positions));
        let offsets = with_data("influence offsets", bytemuck::cast_slice(skin.weights.offsets()));
        let influences = with_data("influences", bytemuck::cast_slice(&influences));
        let params = empty("skinning params", 16, BufferUsages::UNIFORM);
        let palette = empty("palette", input.palette.len() * 64, BufferUsages::STORAGE);
        let vertices = empty(
            "skinned positions",
            input.asset.vertex_count() * VERTEX_BYTES as usize,
            BufferUsages::STORAGE | BufferUsages::COPY_SRC,
        );
        let entries = [&params, &palette, &bind, &offsets, &influences, &vertices]
            .into_iter()
            .enumerate()
            .map(|(binding, buffer)| BindGroupEntry { binding: binding as u32, resource: buffer.as_entire_binding() })
            .collect::<Vec<_>>();
        let bind_group = device.create_bind_group("marionette gpu skinning", &pipeline.layout, &entries);
        Self { asset: input.asset.clone(), params, written_params: None, palette, vertices, bind_group }
    }
}

/// Reads back a mesh's positions from its slot of the vertex buffer (render world; blocks
/// until the GPU has finished). For tests that compare the GPU path with the CPU.
pub fn read_back_mesh_positions(render_world: &World, mesh: AssetId<Mesh>) -> Option<Vec<Vec3>> {
    read_back_mesh_vertices(render_world, mesh, VERTEX_BYTES)
}

/// Reads back a skin mesh with normals: its positions and its normals.
pub fn read_back_mesh_positions_and_normals(
    render_world: &World,
    mesh: AssetId<Mesh>,
) -> Option<(Vec<Vec3>, Vec<Vec3>)> {
    let both = read_back_mesh_vertices(render_world, mesh, 2 * VERTEX_BYTES)?;
    Some(both.chunks_exact(2).map(|v| (v[0], v[1])).unzip())
}

/// A mesh's slot of `vertex_bytes` a vertex, as three floats at a time.
fn read_back_mesh_vertices(render_world: &World, mesh: AssetId<Mesh>, vertex_bytes: u64) -> Option<Vec<Vec3>> {
    let slice = render_world.get_resource::<MeshAllocator>()?.mesh_vertex_slice(&mesh)?;
    let bytes = u64::from(slice.range.end - slice.range.start) * vertex_bytes;
    let read = read_back_buffer(render_world, slice.buffer, u64::from(slice.range.start) * vertex_bytes, bytes)?;
    Some(bytemuck::cast_slice::<u8, Vec3>(&read).to_vec())
}

/// Reads back `bytes` of a GPU buffer from byte `at` (render world; blocks until the GPU
/// has finished). For tests.
pub fn read_back_buffer(render_world: &World, buffer: &Buffer, at: u64, bytes: u64) -> Option<Vec<u8>> {
    let device = render_world.get_resource::<RenderDevice>()?;
    let queue = render_world.get_resource::<RenderQueue>()?;
    let staging = device.create_buffer(&BufferDescriptor {
        label: Some("read back"),
        size: bytes,
        usage: BufferUsages::MAP_READ | BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&CommandEncoderDescriptor { label: Some("read back") });
    encoder.copy_buffer_to_buffer(buffer, at, &staging, 0, bytes);
    queue.submit([encoder.finish()]);
    let (sender, receiver) = std::sync::mpsc::channel();
    staging.slice(..).map_async(MapMode::Read, move |result| {
        let _ = sender.send(result);
    });
    device.poll(PollType::wait_indefinitely()).ok()?;
    receiver.recv().ok()?.ok()?;
    let read = staging.slice(..).get_mapped_range().to_vec();
    Some(read)
}
