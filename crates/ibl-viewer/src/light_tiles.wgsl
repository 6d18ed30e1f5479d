// Which lights can change the real surfaces of each screen tile (light_tiles.rs); prepended by
// gpu_scene.wgsl.
//
// On a real surface the scene pass needs only the lights whose shadow the virtual objects can
// cast there (difference and ratio rules alike: the change `with - without` is 0 elsewhere).
// A light is kept for a tile when the bounding sphere of the tile's real samples can see a
// caster through the shadow look-up (`reaches`). Conservative, so the composite is unchanged; the
// shading pass then loops over a tile's own lights, the same count for every pixel of the tile,
// instead of testing every light per pixel.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lights: array<Light, MAX_SHADOWED_LIGHTS>;
@group(0) @binding(2) var gbuffer_depth: texture_multisampled_2d<f32>;
@group(0) @binding(3) var gbuffer_id: texture_multisampled_2d<f32>;
@group(0) @binding(4) var<storage, read_write> masks: array<u32>;

// Whether light i's virtual-object shadow can reach the sphere (b, s). The tile is fitted
// around the objects' bounding sphere (radius half its depth range, light_space.rs's
// `around_sphere`), so a caster lies within that radius of the tile's axis; a receiver sees
// one through its hard tap within the look-up's normal offset (at most 3.5 texels: tile_hit)
// and through PCSS's blocker search within the search radius, `receiver depth x tan(half
// angle)`, at most a quarter of the tile's half extent (soft_visibility). Without a blocker
// found the filter does not run, so no wider penumbra can reach further.
fn reaches(i: u32, b: vec3<f32>, s: f32) -> bool {
    let q = lights[i].virtual_map * vec4<f32>(b, 1.0);
    let e = lights[i].virtual_extent;
    let margin = s + 4.0 * e.z;
    let caster = 0.5 * e.y;
    let behind = max(q.z * e.y, 0.0) + s;
    let search = min(behind * lights[i].direction.w, 0.25 * e.x);
    let across = length(q.xy) * e.x;
    return across < caster + search + margin && q.z * e.y > -margin;
}

@compute @workgroup_size(8, 8)
fn cs_light_tiles(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gbuffer_depth);
    let tiles = (size + vec2<u32>(LIGHT_TILE - 1u)) / LIGHT_TILE;
    if id.x >= tiles.x || id.y >= tiles.y {
        return;
    }
    var lo = vec3<f32>(3.0e38);
    var hi = vec3<f32>(-3.0e38);
    var real = false;
    for (var y = 0u; y < LIGHT_TILE; y = y + 1u) {
        for (var x = 0u; x < LIGHT_TILE; x = x + 1u) {
            let texel = id.xy * LIGHT_TILE + vec2<u32>(x, y);
            if any(texel >= size) {
                continue;
            }
            let pixel = vec2<f32>(texel) + 0.5;
            for (var s = 0u; s < GBUFFER_SAMPLES; s = s + 1u) {
                if textureLoad(gbuffer_id, texel, s).x > 0.0 {
                    let p = point_at_depth(pixel, textureLoad(gbuffer_depth, texel, s).x);
                    lo = min(lo, p);
                    hi = max(hi, p);
                    real = true;
                }
            }
        }
    }
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * length(hi - lo);
    let count = frame.counts.x;
    let base = light_mask_base(id.xy, size.x);
    for (var w = 0u; w < LIGHT_WORDS; w = w + 1u) {
        var bits = 0u;
        for (var k = 0u; k < 32u; k = k + 1u) {
            let i = w * 32u + k;
            if real && i < count && reaches(i, centre, radius) {
                bits = bits | (1u << k);
            }
        }
        masks[base + w] = bits;
    }
}
