// GPU skinning: one invocation per vertex. It takes the same palette and bind data as the
// CPU kernels (`rig::lbs`, `rig::dqs`) and writes the skinned position, which is then
// copied into the mesh's slot of the vertex buffer (positions only: the skin material reads
// texture coordinates and colours from a buffer of its own). Normals need no pass: the skin
// material lights each triangle with its own normal, from the screen-space derivatives of
// the position.

struct Params {
    vertex_count: u32,
    // 0: linear blend; 1: dual quaternion (palette holds real, dual per joint).
    method: u32,
    _pad: vec2<u32>,
}

@group(0) @binding(0) var<uniform> params: Params;
// Linear blend: one column-major matrix per joint. Dual quaternion: (real, dual, 0, 0).
@group(0) @binding(1) var<storage, read> palette: array<mat4x4<f32>>;
// Three floats per vertex.
@group(0) @binding(2) var<storage, read> bind_positions: array<f32>;
// The influences of vertex v are influences[offsets[v] .. offsets[v + 1]]: (joint, weight bits).
@group(0) @binding(3) var<storage, read> offsets: array<u32>;
@group(0) @binding(4) var<storage, read> influences: array<vec2<u32>>;
// Three floats per vertex.
@group(0) @binding(5) var<storage, read_write> positions: array<f32>;

fn linear_blend(first: u32, last: u32, p: vec3<f32>) -> vec3<f32> {
    var m = mat4x4<f32>(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
    for (var i = first; i < last; i++) {
        let influence = influences[i];
        m += palette[influence.x] * bitcast<f32>(influence.y);
    }
    return (m * vec4(p, 1.0)).xyz;
}

// Kavan et al.: blend in the hemisphere of the heaviest influence (the first of the
// heaviest, as the CPU kernels pick it), normalise, rotate and translate.
fn dual_quaternion(first: u32, last: u32, p: vec3<f32>) -> vec3<f32> {
    var heaviest = first;
    for (var i = first + 1u; i < last; i++) {
        if bitcast<f32>(influences[i].y) > bitcast<f32>(influences[heaviest].y) {
            heaviest = i;
        }
    }
    let pivot = palette[influences[heaviest].x][0];
    var real = vec4(0.0);
    var dual = vec4(0.0);
    for (var i = first; i < last; i++) {
        let influence = influences[i];
        let q = palette[influence.x];
        var w = bitcast<f32>(influence.y);
        if dot(q[0], pivot) < 0.0 {
            w = -w;
        }
        real += q[0] * w;
        dual += q[1] * w;
    }
    let inv = inverseSqrt(dot(real, real));
    real *= inv;
    dual *= inv;
    let r = real.xyz;
    let d = dual.xyz;
    let t = cross(r, p) + real.w * p;
    let rotated = p + 2.0 * cross(r, t);
    return rotated + 2.0 * (real.w * d - dual.w * r + cross(r, d));
}

@compute @workgroup_size(64)
fn skin(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let v = id.y * groups.x * 64u + id.x;
    if v >= params.vertex_count {
        return;
    }
    let p = vec3(bind_positions[3u * v], bind_positions[3u * v + 1u], bind_positions[3u * v + 2u]);
    let first = offsets[v];
    let last = offsets[v + 1u];
    var moved: vec3<f32>;
    if params.method == 0u {
        moved = linear_blend(first, last, p);
    } else {
        moved = dual_quaternion(first, last, p);
    }
    positions[3u * v] = moved.x;
    positions[3u * v + 1u] = moved.y;
    positions[3u * v + 2u] = moved.z;
}
