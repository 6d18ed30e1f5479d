// Which lights can change the real surfaces of each screen tile (light_tiles.rs); prepended by
// gpu_scene.wgsl.
//
// On a real surface the scene pass needs only the lights whose shadow the virtual objects can
// cast there (difference and ratio rules alike: the change `with - without` is 0 elsewhere).
// A light is kept for a tile when the box of the tile's real samples can see a caster through
// the shadow look-up (`reaches`, against the light's caster cells). Conservative, so the
// composite is unchanged; the shading pass then loops over a tile's own lights, the same count
// for every pixel of the tile, instead of testing every light per pixel.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lights: array<Light, MAX_SHADOWED_LIGHTS>;
@group(0) @binding(2) var gbuffer_depth: texture_multisampled_2d<f32>;
@group(0) @binding(3) var gbuffer_id: texture_multisampled_2d<f32>;
@group(0) @binding(4) var<storage, read_write> masks: array<u32>;
@group(0) @binding(6) var gbuffer_normals: texture_multisampled_2d<f32>;

// The caster cells of every light (caster_cells.wgsl).
@group(0) @binding(5) var<storage, read> caster_cells: array<f32>;

// Whether light i's virtual-object shadow can reach a tile's real points, which lie in the box
// (lo, hi). A receiver sees a caster through its hard tap within the look-up's normal offset (at
// most 3.5 texels: tile_hit) and the tap's bilinear footprint (a texel) and clamp (half a
// texel), a margin of 6 texels, and through PCSS's blocker search within the search radius,
// `receiver depth x tan(half angle)` from the tile's near plane, at most a quarter of the tile's
// half extent (soft_visibility); without a blocker found the filter does not run, so no wider
// penumbra can reach further; only casters in front of the receiver block it. So the light is
// kept when a caster cell within that reach of the box's footprint in the light's tile (the
// rectangle around its corners' projections) holds a depth in front of the box's back. The
// cells are read at the pyramid level whose cells are at least a third of the region wide (at
// most 4 x 4 of them). A box wholly beside the tile or in front of every caster is lit.
fn reaches(i: u32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let e = lights[i].virtual_extent;
    var near = vec3<f32>(3.0e38);
    var far = vec3<f32>(-3.0e38);
    for (var k = 0u; k < 8u; k = k + 1u) {
        let corner = select(lo, hi, vec3<bool>((k & 1u) != 0u, (k & 2u) != 0u, (k & 4u) != 0u));
        let q = (lights[i].virtual_map * vec4<f32>(corner, 1.0)).xyz;
        near = min(near, q);
        far = max(far, q);
    }
    let margin = 6.0 * e.z;
    let deepest = far.z * e.y + margin;
    if deepest <= 0.0 {
        return false;
    }
    let search = min(min(deepest, e.y) * lights[i].direction.w, 0.25 * e.x);
    let reach = (margin + search) / e.x;
    return caster_within(i, near.xy - reach, far.xy + reach, deepest, 3.0);
}

// Whether some normal in the box (lo, hi) faces light i: the largest `n . w` over the box is
// positive (a real surface's light is 0 where its geometric normal faces away: reflection()).
fn faces(i: u32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let w = lights[i].direction.xyz;
    return dot(max(lo * w, hi * w), vec3<f32>(1.0)) > 0.0;
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
    // The box of the real samples' geometric normals: a light none of them faces lights none.
    var normals_lo = vec3<f32>(1.0);
    var normals_hi = vec3<f32>(-1.0);
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
                    let ng = oct_decode(textureLoad(gbuffer_normals, texel, s).zw);
                    normals_lo = min(normals_lo, ng);
                    normals_hi = max(normals_hi, ng);
                    real = true;
                }
            }
        }
    }
    let count = frame.counts.x;
    let base = light_mask_base(id.xy, size.x);
    for (var w = 0u; w < LIGHT_WORDS; w = w + 1u) {
        var bits = 0u;
        for (var k = 0u; k < 32u; k = k + 1u) {
            let i = w * 32u + k;
            if real && i < count && faces(i, normals_lo, normals_hi) && reaches(i, lo, hi) {
                bits = bits | (1u << k);
            }
        }
        masks[base + w] = bits;
    }
}
