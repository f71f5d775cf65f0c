// The skin's fragment shader: StandardMaterial lighting with each triangle's own normal,
// taken from the screen-space derivatives of the world position (flat shading without a
// normal attribute: the CPU writes only shared vertex positions), or, for a skin with
// normals (a normal-mapped one), with its skinned normal; bent by the material's normal
// map where it has one.
#import bevy_pbr::{
    pbr_fragment::pbr_input_from_standard_material,
    pbr_functions::alpha_discard,
}

#ifdef PREPASS_PIPELINE
#import bevy_pbr::{
    prepass_io::{VertexOutput, FragmentOutput},
    pbr_deferred_functions::deferred_output,
}
#else
#import bevy_pbr::{
    forward_io::{VertexOutput, FragmentOutput},
    pbr_functions::{apply_pbr_lighting, main_pass_post_lighting_processing},
}
#endif

// glTF's normalTexture.scale in x.
@group(#{MATERIAL_BIND_GROUP}) @binding(100) var<uniform> normal_scale: vec4<f32>;

@fragment
fn fragment(
    in: VertexOutput,
    @builtin(front_facing) is_front: bool,
) -> FragmentOutput {
    var pbr_input = pbr_input_from_standard_material(in, is_front);
    // Screen x runs along dpdx, screen y (downwards) along dpdy: their cross product
    // in this order faces the camera on a front face.
    let p = in.world_position.xyz;
    let flat = normalize(cross(dpdy(p), dpdx(p)));
    var base = flat;
#ifdef VERTEX_NORMALS
    // The interpolated skinned normal, turned towards the viewer on a (double-sided)
    // back face as the flat one is; zero where the file had none (and in dual quaternion
    // skinning, which skins positions only): flat there.
    if dot(in.world_normal, in.world_normal) > 1e-12 {
        base = normalize(in.world_normal) * select(-1.0, 1.0, is_front);
    }
#endif
    pbr_input.world_normal = base;
    var n = base;
#ifdef STANDARD_MATERIAL_NORMAL_MAP
#ifdef VERTEX_UVS_A
#ifndef BINDLESS
    // A normal map without tangents: the tangent frame from the derivatives of the
    // position and the texture coordinates (a cotangent frame). glTF's maps point +y
    // towards decreasing v (up the image), so the bitangent is -dp/dv.
    let uv = (pbr_input.material.uv_transform * vec3(in.uv, 1.0)).xy;
    let dp1 = dpdx(p);
    let dp2 = dpdy(p);
    let duv1 = dpdx(uv);
    let duv2 = dpdy(uv);
    let dp2perp = cross(dp2, base);
    let dp1perp = cross(base, dp1);
    let t = dp2perp * duv1.x + dp1perp * duv2.x;
    let b = dp2perp * duv1.y + dp1perp * duv2.y;
    let scale = inverseSqrt(max(max(dot(t, t), dot(b, b)), 1e-20));
    let sampled = textureSample(bevy_pbr::pbr_bindings::normal_map_texture, bevy_pbr::pbr_bindings::normal_map_sampler, uv).rgb;
    // glTF: scaledNormal = normalize((sampled * 2 - 1) * vec3(scale, scale, 1)).
    let tangent_space = (sampled * 2.0 - 1.0) * vec3(normal_scale.x, normal_scale.x, 1.0);
    n = normalize(tangent_space.x * t * scale - tangent_space.y * b * scale + tangent_space.z * base);
#endif
#endif
#endif
    pbr_input.N = n;
    pbr_input.material.base_color = alpha_discard(pbr_input.material, pbr_input.material.base_color);

#ifdef PREPASS_PIPELINE
    let out = deferred_output(in, pbr_input);
#else
    var out: FragmentOutput;
    out.color = apply_pbr_lighting(pbr_input);
    out.color = main_pass_post_lighting_processing(pbr_input, out.color);
#endif
    return out;
}
