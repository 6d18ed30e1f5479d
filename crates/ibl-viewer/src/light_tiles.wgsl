// Which lights can change the real surfaces of each screen tile (light_tiles.rs); prepended by
// gpu_scene.wgsl.
//
// On a real surface the scene pass needs only the lights whose shadow the virtual objects can
// cast there (difference and ratio rules alike: the change `with - without` is 0 elsewhere),
// and the new point lights (their whole light is a change). A directional light is kept for a
// tile when the box of the tile's real samples can see a caster through the shadow look-up
// (`reaches`, against the light's caster cells), a point light already in the background when
// the box's bounding sphere meets the light's cone about the objects' vertices
// (`point_shadow_reaches`). Conservative, so the
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
// The goniometric point lights (point_lights.wgsl).
@group(0) @binding(7) var<uniform> point_lights: array<PointLight, MAX_POINT_LIGHTS>;

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

// Whether a sphere (centre, radius) can hold a point that point light k's virtual faces
// shadow (point_lights.wgsl's `point_atlas_visibility`). The faces hold only the virtual
// objects, whose vertices, and so triangles, lie in the light's shadow cone (point_lights.rs's
// `shadow_cone`, fitted on the CPU whenever an object or a light moves): a texel holds a caster
// only where its centre's direction lies in that cone, and only behind its nearest vertex. A
// look-up's direction strays from the receiver's by its normal offset (at most 3.5 texels at
// the receiver's distance along the face's axis, a texel being 2 / texels of the face's tangent
// plane: 7 / texels radians), the texel centres its bilinear tap reads lie within a texel on
// each axis of it (2 sqrt(2) / texels) and its clamp to the tile moves it by at most half a
// texel (1 / texels): under 11 / texels radians in all, taken as 12 (`reach`), and 12 / texels
// of the distance besides. The sphere reaches the cone when the angle between the two axes is
// within the two half-angles and that margin, compared as cosines (the sum of the three
// angles by the addition formulas; past pi, always); and always when the light is inside the
// sphere or the cone is a half-space or wider.
fn point_shadow_reaches(k: u32, centre: vec3<f32>, radius: f32, reach: vec3<f32>) -> bool {
    let cone = point_lights[k].shadow_cone;
    if cone.w > 1.5 {
        // No objects: nothing in the virtual faces.
        return false;
    }
    let light = point_lights[k].position.xyz;
    let to_sphere = centre - light;
    let d_sphere = length(to_sphere);
    if cone.w < -1.5 || d_sphere <= radius {
        return true;
    }
    let nearest = length(cone.xyz);
    if (d_sphere + radius) * (1.0 + reach.x) < nearest {
        // The whole sphere is nearer the light than any caster.
        return false;
    }
    let cos_cone = cone.w;
    let sin_cone = sqrt(max(1.0 - cos_cone * cos_cone, 0.0));
    let sin_spread = radius / d_sphere;
    let cos_spread = sqrt(max(1.0 - sin_spread * sin_spread, 0.0));
    let cos_both = cos_cone * cos_spread - sin_cone * sin_spread;
    let sin_both = sin_cone * cos_spread + cos_cone * sin_spread;
    let cos_all = cos_both * reach.y - sin_both * reach.z;
    let sin_all = sin_both * reach.y + cos_both * reach.z;
    return sin_all < 0.0 || dot(cone.xyz, to_sphere) >= cos_all * nearest * d_sphere;
}

// The point lights' angular margin (12 texels of a face: `point_shadow_reaches`), its cosine and
// sine.
fn point_reach() -> vec3<f32> {
    let margin = 12.0 / point_lights[0].shadow.y;
    return vec3<f32>(margin, cos(margin), sin(margin));
}

// Whether some normal in the box (normals_lo, normals_hi) faces point light k from some point
// in the box (lo, hi): the largest `n . (light - p)` over both boxes, a sum of per-axis products
// whose largest is at a corner of the two intervals, is positive (reflection() is 0 elsewhere).
fn faces_point(k: u32, lo: vec3<f32>, hi: vec3<f32>, normals_lo: vec3<f32>, normals_hi: vec3<f32>) -> bool {
    let light = point_lights[k].position.xyz;
    let near = light - hi;
    let far = light - lo;
    let most = max(max(normals_lo * near, normals_lo * far), max(normals_hi * near, normals_hi * far));
    return most.x + most.y + most.z > 0.0;
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
    let base = light_mask_base(id.xy, size.x);
    // Each word's loop runs over the lights it holds, and none in a tile without real samples:
    // on lavapipe a light tested under a condition that differs between tiles costs its whole
    // test even where the condition fails, while a loop stops at the last trip any tile takes.
    let count = select(0u, frame.counts.x, real);
    for (var w = 0u; w < LIGHT_WORDS; w = w + 1u) {
        var bits = 0u;
        let first = w * 32u;
        let n = min(count - min(count, first), 32u);
        for (var k = 0u; k < n; k = k + 1u) {
            if faces(first + k, normals_lo, normals_hi) && reaches(first + k, lo, hi) {
                bits = bits | (1u << k);
            }
        }
        masks[base + w] = bits;
    }
    // A point light already in the background changes a real surface only by the objects'
    // shadow; a new one by all its light.
    let points = select(0u, frame.counts.y, real);
    let centre = 0.5 * (lo + hi);
    let radius = 0.5 * length(hi - lo);
    let reach = point_reach();
    for (var w = 0u; w < POINT_LIGHT_WORDS; w = w + 1u) {
        var bits = 0u;
        let first = w * 32u;
        let n = min(points - min(points, first), 32u);
        for (var b = 0u; b < n; b = b + 1u) {
            let k = first + b;
            if faces_point(k, lo, hi, normals_lo, normals_hi)
                && (point_lights[k].shadow.z < 0.5 || point_shadow_reaches(k, centre, radius, reach)) {
                bits = bits | (1u << b);
            }
        }
        masks[base + LIGHT_WORDS + w] = bits;
    }
}
