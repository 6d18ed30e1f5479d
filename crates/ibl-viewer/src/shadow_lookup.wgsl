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
// widest penumbra possible, the visibility from 16 comparison taps over that penumbra, both on
// a Vogel disk (golden-angle spiral) rotated per pixel, with a receiver-plane bias (below).
//
// Written for software rasterizers as much as for GPUs: lavapipe runs this code on the CPU,
// where a constant array indexed in a loop becomes a per-pixel copy in memory and a function
// that holds both the hard and the soft look-up costs the hard one 3 to 5 times its own time
// (measured, BENCHMARKS.md "Viewer"). So the taps are generated, not read from a table, the
// hard look-up is its own function, each light's fields are read one by one, not copied, and
// work that most pixels skip sits in loops whose trip count is 0 there (soft_visibility).

// Soft (PCSS) or hard shadows: a pipeline constant (scene_pass.rs), so each pipeline holds
// only the look-up it runs.
override SOFT_SHADOWS: bool = false;

// The golden angle's rotation, (cos, sin) of pi (3 - sqrt 5).
const GOLDEN: vec2<f32> = vec2<f32>(-0.7373688, 0.6754903);

// Tile coordinates (x, y in [-1, 1], +y up) to atlas texture coordinates.
fn tile_uv(tile: vec4<f32>, xy: vec2<f32>) -> vec2<f32> {
    return tile.xy + tile.zw * vec2<f32>(0.5 + 0.5 * xy.x, 0.5 - 0.5 * xy.y);
}

// Keeps a texture coordinate half a texel inside its tile.
fn clamp_to_tile(uv: vec2<f32>, tile: vec4<f32>, texel_uv: vec2<f32>) -> vec2<f32> {
    return clamp(uv, tile.xy + 0.5 * texel_uv, tile.xy + tile.zw - 0.5 * texel_uv);
}

// Where a receiver at world point `p` with unit normal `n` (lit side) falls in a light's tile:
// xy in [-1, 1] inside it, z its depth in [0, 1]; `extent` = (half extent, depth range, texel
// size) in world units. Normal offset and slope-scaled depth bias against self-shadowing.
struct TileHit {
    inside: bool,
    uv: vec2<f32>,
    depth: f32,
    slope: f32,
};

fn tile_hit(map: mat4x4<f32>, tile: vec4<f32>, extent: vec4<f32>, p: vec3<f32>, n: vec3<f32>, cos_light: f32) -> TileHit {
    let texel_world = extent.z;
    let cos_t = clamp(cos_light, 0.01, 1.0);
    let sin_t = sqrt(1.0 - cos_t * cos_t);
    var hit: TileHit;
    hit.slope = min(sin_t / cos_t, 4.0);
    let q = map * vec4<f32>(p + n * ((1.5 + 2.0 * sin_t) * texel_world), 1.0);
    // Outside the tile (no caster projects there) or in front of every caster: lit.
    hit.inside = abs(q.x) < 1.0 && abs(q.y) < 1.0 && q.z > 0.0;
    hit.depth = min(q.z, 1.0) - (1.0 + 2.0 * hit.slope) * texel_world / extent.y;
    hit.uv = tile_uv(tile, q.xy);
    return hit;
}

// Hard visibility (0 shadowed, 1 lit): one bilinear comparison tap.
fn hard_visibility(atlas: texture_depth_2d, map: mat4x4<f32>, tile: vec4<f32>, extent: vec4<f32>,
                   atlas_size: vec2<f32>, p: vec3<f32>, n: vec3<f32>, cos_light: f32) -> f32 {
    let hit = tile_hit(map, tile, extent, p, n, cos_light);
    if !hit.inside {
        return 1.0;
    }
    return textureSampleCompareLevel(atlas, shadow_sampler, clamp_to_tile(hit.uv, tile, 1.0 / atlas_size), hit.depth);
}

// Soft visibility by PCSS over a cone of half-angle tangent `tan_half`; `noise` in [0, 1)
// rotates the taps per pixel.
fn soft_visibility(atlas: texture_depth_2d, map: mat4x4<f32>, tile: vec4<f32>, extent: vec4<f32>,
                   atlas_size: vec2<f32>, tan_half: f32, p: vec3<f32>, n: vec3<f32>,
                   cos_light: f32, noise: f32) -> f32 {
    let hit = tile_hit(map, tile, extent, p, n, cos_light);
    let texel_uv = 1.0 / atlas_size;
    let texel_world = extent.z;
    let depth = hit.depth;
    let slope = hit.slope;
    let uv = hit.uv;
    // World units to texture coordinates across this tile.
    let uv_per_world = tile.zw / (2.0 * extent.x);
    let receiver = depth * extent.y;
    let search = clamp(receiver * tan_half, texel_world, 0.25 * extent.x);
    // Receiver-plane bias: a tap r world units from the centre meets the receiver's own plane up
    // to r tan(theta) deeper, which the blocker search and the filter must not count as a
    // blocker (without it the rotated taps print the noise pattern on surfaces turning away).
    let search_depth = depth - search * slope / extent.y;
    let rotation = noise * 6.2831853;
    let start = vec2<f32>(cos(rotation), sin(rotation));
    // Vogel disk: tap k at radius sqrt((k + 0.5) / K), turned by the golden angle each step.
    var dir = start;
    var blockers = 0.0;
    var blocker_sum = 0.0;
    // Outside the tile no tap is taken: the loops' trip counts are 0 there rather than an early
    // return. On lavapipe (llvmpipe) an `if` or a `return` runs the rest for a whole block of
    // pixels under a mask even where no pixel of it continues, but a loop stops as soon as no
    // pixel of the block has trips left (BENCHMARKS.md, "Viewer": the courtyard's soft sun
    // shadow from 261 to 122 ms a frame, bunny-sky's 16 soft lights from 2.3 to 0.87 s).
    let search_taps = select(0u, 12u, hit.inside);
    for (var k = 0u; k < search_taps; k = k + 1u) {
        let r = sqrt((f32(k) + 0.5) / 12.0);
        let at = clamp_to_tile(uv + dir * (r * search) * uv_per_world, tile, texel_uv);
        let z = textureLoad(atlas, vec2<i32>(at * atlas_size), 0);
        if z < search_depth {
            blockers = blockers + 1.0;
            blocker_sum = blocker_sum + z;
        }
        dir = vec2<f32>(dir.x * GOLDEN.x - dir.y * GOLDEN.y, dir.x * GOLDEN.y + dir.y * GOLDEN.x);
    }
    if blockers == 0.0 {
        return 1.0;
    }
    let blocker = blocker_sum / blockers * extent.y;
    let penumbra = clamp((receiver - blocker) * tan_half, texel_world, 0.5 * extent.x);
    let filter_depth = depth - penumbra * slope / extent.y;
    dir = start;
    var lit = 0.0;
    let filter_taps = select(0u, 16u, blockers > 0.0);
    for (var k = 0u; k < filter_taps; k = k + 1u) {
        let r = sqrt((f32(k) + 0.5) / 16.0);
        let at = clamp_to_tile(uv + dir * (r * penumbra) * uv_per_world, tile, texel_uv);
        lit = lit + textureSampleCompareLevel(atlas, shadow_sampler, at, filter_depth);
        dir = vec2<f32>(dir.x * GOLDEN.x - dir.y * GOLDEN.y, dir.x * GOLDEN.y + dir.y * GOLDEN.x);
    }
    return lit / 16.0;
}

// Visibility of light i in one atlas (its tile's map, rectangle and extent): PCSS when the
// pipeline draws soft shadows and the light has a cone, else one hard tap.
fn atlas_visibility(i: u32, atlas: texture_depth_2d, map: mat4x4<f32>, tile: vec4<f32>,
                    extent: vec4<f32>, atlas_size: vec2<f32>, p: vec3<f32>, n: vec3<f32>,
                    noise: f32) -> f32 {
    let cos_light = dot(n, lights[i].direction.xyz);
    if SOFT_SHADOWS && lights[i].direction.w > 0.0 {
        return soft_visibility(atlas, map, tile, extent, atlas_size, lights[i].direction.w, p, n,
            cos_light, noise);
    }
    return hard_visibility(atlas, map, tile, extent, atlas_size, p, n, cos_light);
}

// The real geometry lies in one plane (frame.real_plane): a pipeline constant.
override FLAT_REAL_LAYER: bool = false;

// Visibility of light i in the real-geometry atlas.
fn real_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, noise: f32) -> f32 {
    if FLAT_REAL_LAYER {
        // A ray leaving a point on the light's side of a plane (or on it) moves away from it:
        // the flat real layer cannot block it, so no look-up (exact; on lavapipe the soft
        // look-ups of the ground were half a frame). The margin is the atlas's own bias scale.
        let plane = frame.real_plane;
        let side = (dot(plane.xyz, p) + plane.w) * sign(dot(plane.xyz, lights[i].direction.xyz));
        if side >= -2.0 * lights[i].real_extent.z {
            return 1.0;
        }
        // Behind the plane: its shadow edge is the plane's border, far from what is seen;
        // one hard tap.
        return hard_visibility(real_atlas, lights[i].real_map, lights[i].real_tile,
            lights[i].real_extent, frame.atlas.xy, p, n, dot(n, lights[i].direction.xyz));
    }
    return atlas_visibility(i, real_atlas, lights[i].real_map, lights[i].real_tile,
        lights[i].real_extent, frame.atlas.xy, p, n, noise);
}

// Visibility of light i in the virtual-object atlas.
fn virtual_visibility(i: u32, p: vec3<f32>, n: vec3<f32>, noise: f32) -> f32 {
    return atlas_visibility(i, virtual_atlas, lights[i].virtual_map, lights[i].virtual_tile,
        lights[i].virtual_extent, frame.atlas.zw, p, n, noise);
}
