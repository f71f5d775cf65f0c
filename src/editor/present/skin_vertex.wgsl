// The skin's vertex shader, for the main pass and the prepasses (shadows): the mesh's
// vertex buffer holds positions only (12 bytes a vertex, all the CPU hands on when a
// character moves), or positions and normals for a normal-mapped skin; texture
// coordinates and colours come from the one buffer of every skin's attributes, written
// only when they change. A mesh's surface starts there at its
// tag (MeshTag); its vertex k is the mesh's k-th: the draw's vertex index less the mesh's
// first in the vertex buffer.
#import bevy_pbr::{
    mesh_bindings::mesh,
    mesh_functions,
    view_transformations::position_world_to_clip,
}
#ifdef PREPASS_PIPELINE
#import bevy_pbr::prepass_io::VertexOutput
#else
#import bevy_pbr::forward_io::VertexOutput
#endif

// Every skin surface's attributes, per vertex three words: u and v (float bits; zero
// where the skin has none), then the colour (unorm8x4, red in the low byte).
@group(#{MATERIAL_BIND_GROUP}) @binding(101) var<storage, read> attributes: array<u32>;

struct Vertex {
    @builtin(instance_index) instance_index: u32,
    @builtin(vertex_index) index: u32,
    @location(0) position: vec3<f32>,
#ifdef VERTEX_NORMALS
#ifdef PREPASS_PIPELINE
    @location(3) normal: vec3<f32>,
#else
    @location(1) normal: vec3<f32>,
#endif
#endif
};

// The vertex's skinned normal in the world (zero where it has none: lit flat); zero for a
// mesh without normals, whose triangles are lit with their own.
fn skinned_world_normal(vertex: Vertex) -> vec3<f32> {
#ifdef VERTEX_NORMALS
    return mesh_functions::mesh_normal_local_to_world(vertex.normal, vertex.instance_index);
#else
    return vec3(0.0);
#endif
}

@vertex
fn vertex(vertex: Vertex) -> VertexOutput {
    var out: VertexOutput;
    let world_from_local = mesh_functions::get_world_from_local(vertex.instance_index);
    out.world_position = mesh_functions::mesh_position_local_to_world(world_from_local, vec4(vertex.position, 1.0));
    out.position = position_world_to_clip(out.world_position.xyz);
    let instance = mesh[vertex.instance_index];
    let k = 3u * (instance.tag + vertex.index - instance.first_vertex_index);
#ifdef VERTEX_UVS_A
    out.uv = vec2(bitcast<f32>(attributes[k]), bitcast<f32>(attributes[k + 1u]));
#endif
#ifdef VERTEX_COLORS
    out.color = unpack4x8unorm(attributes[k + 2u]);
#endif
#ifdef PREPASS_PIPELINE
#ifdef UNCLIPPED_DEPTH_ORTHO_EMULATION
    out.unclipped_depth = out.position.z;
    out.position.z = min(out.position.z, 1.0);
#endif
#ifdef NORMAL_PREPASS_OR_DEFERRED_PREPASS
    out.world_normal = skinned_world_normal(vertex);
#endif
#ifdef MOTION_VECTOR_PREPASS
    // Last frame's skinned position is not kept: the mesh's own motion only.
    out.previous_world_position = mesh_functions::mesh_position_local_to_world(
        mesh_functions::get_previous_world_from_local(vertex.instance_index),
        vec4(vertex.position, 1.0),
    );
#endif
#else
    out.world_normal = skinned_world_normal(vertex);
#endif
#ifdef VERTEX_OUTPUT_INSTANCE_INDEX
    out.instance_index = vertex.instance_index;
#endif
#ifdef VISIBILITY_RANGE_DITHER
    out.visibility_range_dither =
        mesh_functions::get_visibility_range_dither_level(vertex.instance_index, world_from_local[3]);
#endif
    return out;
}
