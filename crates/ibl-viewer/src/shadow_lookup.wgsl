// Shadow look-ups in the atlases (shadow_atlas.rs); prepended to scene_pass.wgsl after
// gpu_scene.wgsl. A light's visibility at a receiver is the product of its visibility in the
// real-geometry atlas and in the virtual-object atlas (the two sets of casters are drawn apart so
// that the real one, which never moves, is drawn only when the lights change).
//
// Hard shadows: one comparison tap with bilinear filtering (2 x 2 PCF), the receiver moved along
// its normal by 1.5 texels plus 2 sin(theta) texels and its depth lowered by 1 + 2 tan(theta)
// texels (at most 9), theta the angle between the receiver's normal and the light: normal-offset
// and slope-scaled depth bias against self-shadowing. A surface turning away from the light
// covers more depth per texel, so a constant bias leaves acne near the terminator.
// Soft shadows (PCSS, Fernando 2005): a directional light of cone half-angle a casts a penumbra
// `(d_receiver - d_blocker) tan a` wide; the mean blocker depth comes from 12 taps over the
// widest penumbra possible, the visibility from 16 comparison taps over that penumbra, rotated
// per pixel, both with a receiver-plane bias (below).

const POISSON: array<vec2<f32>, 16> = array<vec2<f32>, 16>(
    vec2<f32>(-0.94201624, -0.39906216), vec2<f32>(0.94558609, -0.76890725),
    vec2<f32>(-0.09418410, -0.92938870), vec2<f32>(0.34495938, 0.29387760),
    vec2<f32>(-0.91588581, 0.45771432), vec2<f32>(-0.81544232, -0.87912464),
    vec2<f32>(-0.38277543, 0.27676845), vec2<f32>(0.97484398, 0.75648379),
    vec2<f32>(0.44323325, -0.97511554), vec2<f32>(0.53742981, -0.47373420),
    vec2<f32>(-0.26496911, -0.41893023), vec2<f32>(0.79197514, 0.19090188),
    vec2<f32>(-0.24188840, 0.99706507), vec2<f32>(-0.81409955, 0.91437590),
    vec2<f32>(0.19984126, 0.78641367), vec2<f32>(0.14383161, -0.14100790)
);

// Tile coordinates (x, y in [-1, 1], +y up) to atlas texture coordinates.
fn tile_uv(tile: vec4<f32>, xy: vec2<f32>) -> vec2<f32> {
    return tile.xy + tile.zw * vec2<f32>(0.5 + 0.5 * xy.x, 0.5 - 0.5 * xy.y);
}

// Keeps a texture coordinate half a texel inside its tile.
fn clamp_to_tile(uv: vec2<f32>, tile: vec4<f32>, texel_uv: vec2<f32>) -> vec2<f32> {
    return clamp(uv, tile.xy + 0.5 * texel_uv, tile.xy + tile.zw - 0.5 * texel_uv);
}

// Visibility (0 shadowed, 1 lit) of a light in one atlas at world point `p` with unit normal
// `n` (on the lit side). `extent` = (half extent, depth range, texel size) in world units.
fn atlas_visibility(
    atlas: texture_depth_2d,
    map: mat4x4<f32>,
    tile: vec4<f32>,
    extent: vec4<f32>,
    atlas_size: vec2<f32>,
    tan_half: f32,
    soft: bool,
    p: vec3<f32>,
    n: vec3<f32>,
    cos_light: f32,
    noise: f32,
) -> f32 {
    let texel_world = extent.z;
    let cos_t = clamp(cos_light, 0.01, 1.0);
    let sin_t = sqrt(1.0 - cos_t * cos_t);
    let slope = min(sin_t / cos_t, 4.0);
    let q = map * vec4<f32>(p + n * ((1.5 + 2.0 * sin_t) * texel_world), 1.0);
    // Outside the tile (no caster projects there) or in front of every caster: lit.
    if abs(q.x) >= 1.0 || abs(q.y) >= 1.0 || q.z <= 0.0 {
        return 1.0;
    }
    let depth = min(q.z, 1.0) - (1.0 + 2.0 * slope) * texel_world / extent.y;
    let texel_uv = 1.0 / atlas_size;
    let uv = tile_uv(tile, q.xy);
    if !soft || tan_half <= 0.0 {
        return textureSampleCompareLevel(atlas, shadow_sampler, clamp_to_tile(uv, tile, texel_uv), depth);
    }
    // World units to texture coordinates across this tile.
    let uv_per_world = tile.zw / (2.0 * extent.x);
    let receiver = depth * extent.y;
    let search = clamp(receiver * tan_half, texel_world, 0.25 * extent.x);
    // Receiver-plane bias: a tap r world units from the centre meets the receiver's own plane up
    // to r tan(theta) deeper, which the blocker search and the filter must not count as a
    // blocker (without it the rotated taps print the noise pattern on surfaces turning away).
    let search_depth = depth - search * slope / extent.y;
    var blockers = 0.0;
    var blocker_sum = 0.0;
    let rotation = noise * 6.2831853;
    let c = cos(rotation);
    let s = sin(rotation);
    for (var k = 0u; k < 12u; k = k + 1u) {
        let o = POISSON[k];
        let r = vec2<f32>(c * o.x - s * o.y, s * o.x + c * o.y);
        let at = clamp_to_tile(uv + r * search * uv_per_world, tile, texel_uv);
        let z = textureLoad(atlas, vec2<i32>(at * atlas_size), 0);
        if z < search_depth {
            blockers = blockers + 1.0;
            blocker_sum = blocker_sum + z;
        }
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let blocker = blocker_sum / blockers * extent.y;
    let penumbra = clamp((receiver - blocker) * tan_half, texel_world, 0.5 * extent.x);
    let filter_depth = depth - penumbra * slope / extent.y;
    var lit = 0.0;
    for (var k = 0u; k < 16u; k = k + 1u) {
        let o = POISSON[k];
        let r = vec2<f32>(c * o.x - s * o.y, s * o.x + c * o.y);
        let at = clamp_to_tile(uv + r * penumbra * uv_per_world, tile, texel_uv);
        lit = lit + textureSampleCompareLevel(atlas, shadow_sampler, at, filter_depth);
    }
    return lit / 16.0;
}

fn real_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, noise: f32) -> f32 {
    let light = lights[i];
    return atlas_visibility(real_atlas, light.real_map, light.real_tile, light.real_extent,
        frame.atlas.xy, light.direction.w, frame.counts.z == 1u, p, n,
        dot(n, light.direction.xyz), noise);
}

fn virtual_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, noise: f32) -> f32 {
    let light = lights[i];
    return atlas_visibility(virtual_atlas, light.virtual_map, light.virtual_tile,
        light.virtual_extent, frame.atlas.zw, light.direction.w, frame.counts.z == 1u, p, n,
        dot(n, light.direction.xyz), noise);
}
