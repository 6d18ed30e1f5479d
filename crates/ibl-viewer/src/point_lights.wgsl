// Goniometric point lights in the scene pass (point_lights.rs); prepended to scene_pass.wgsl
// after shadow_lookup.wgsl. A point light's direct light at a surface point is Grosch 2005
// EQ5 times the BSDF, `f cos(theta_i) I(-w_i) / d^2` (ibl-render's `luminaires`), with a hard
// shadow from each layer: a point source casts no penumbra, and the CPU renderer traces one
// shadow ray to it.
//
// The shadow look-up is hard_visibility's, in the cube face the receiver falls in: one
// bilinear comparison tap, the receiver moved along its normal by 1.5 + 2 sin(theta) texels and
// its distance along the face's axis lowered by 1 + 2 tan(theta) texels, a texel being
// `2 z / tile` world units at distance z (a 90-degree face). The bias is applied to the
// distance and the result mapped through face_depth, so it is linear in world units although
// the stored depth is not.

// The scene has point lights (frame.counts.y of them): a pipeline constant.
override POINT_LIGHTS: bool = false;

// Visibility of point light k (at `light`) through one atlas's face tiles, for a receiver at
// p with unit normal n (lit side) and cos_light = n . (unit direction to the light).
fn point_atlas_visibility(atlas: texture_depth_2d, atlas_size: vec2<f32>, k: u32, real: bool,
                          light: vec3<f32>, p: vec3<f32>, n: vec3<f32>, cos_light: f32) -> f32 {
    let near = point_lights[k].position.w;
    let far = point_lights[k].shadow.x;
    let texels = point_lights[k].shadow.y;
    let cos_t = clamp(cos_light, 0.01, 1.0);
    let sin_t = sqrt(1.0 - cos_t * cos_t);
    let slope = min(sin_t / cos_t, 4.0);
    let v0 = p - light;
    let z0 = max(abs(v0.x), max(abs(v0.y), abs(v0.z)));
    let texel_world = 2.0 * z0 / texels;
    let v = v0 + n * ((1.5 + 2.0 * sin_t) * texel_world);
    let face = face_of(v);
    var tile = point_lights[k].virtual_faces[face];
    if real {
        tile = point_lights[k].real_faces[face];
    }
    if tile.z == 0.0 {
        // No caster in this face.
        return 1.0;
    }
    let q = face_coords(v, face);
    let z = q.z - (1.0 + 2.0 * slope) * texel_world;
    if z <= near {
        // Nearer the light than any caster.
        return 1.0;
    }
    let depth = min(face_depth(z, near, far), 1.0);
    let uv = clamp_to_tile(tile_uv(tile, q.xy / q.z), tile, 1.0 / atlas_size);
    return textureSampleCompareLevel(atlas, shadow_sampler, uv, depth);
}

// Visibility of point light k through the real geometry.
fn point_real_visibility(k: u32, light: vec3<f32>, p: vec3<f32>, n: vec3<f32>, cos_light: f32) -> f32 {
    if FLAT_REAL_LAYER {
        // A point on the light's side of the plane (or on it) sees the light past the plane:
        // no look-up (real_visibility's rule; the margin is two texels at this distance).
        let plane = frame.real_plane;
        let margin = 4.0 * length(p - light) / point_lights[k].shadow.y;
        let side = (dot(plane.xyz, p) + plane.w) * sign(dot(plane.xyz, light) + plane.w);
        if side >= -margin {
            return 1.0;
        }
    }
    return point_atlas_visibility(real_atlas, frame.atlas.xy, k, true, light, p, n, cos_light);
}

// The intensity of point light k towards world direction `travel` (from the light outwards),
// probe units per sr: its table's map (point_lights.rs), bilinear in the photometric angles
// (gamma from the nadir -y, C from +x towards -z, ibl-light's `angles_of_direction`).
fn point_intensity(k: u32, travel: vec3<f32>) -> vec3<f32> {
    let d = (point_lights[k].light_from_world * vec4<f32>(travel, 0.0)).xyz;
    let gamma = atan2(length(d.xz), -d.y);
    var c = atan2(-d.z, d.x) / (2.0 * PI);
    c = c - floor(c);
    let map = point_lights[k].map;
    let half_row = 0.5 / f32(textureDimensions(intensity_maps).y);
    let v = map.x + clamp(gamma / PI * map.y, half_row, map.y - half_row);
    return textureSampleLevel(intensity_maps, probe_sampler, vec2<f32>(c, v), 0.0).rgb * map.z;
}

// What point light k gives a surface point with BSDF term `fc` (f cos theta_i) from distance
// squared d2 along wi: I(-wi) fc / max(d2, its near-field bound map.w), unshadowed.
fn point_light_term(k: u32, fc: vec3<f32>, wi: vec3<f32>, d2: f32) -> vec3<f32> {
    return fc * point_intensity(k, -wi) / max(d2, point_lights[k].map.w);
}

// Point light k seen from a surface point p: its position, the unit direction wi to it, the
// squared distance d2 and the BSDF term fc = f cos(theta_i) along wi (zero when the light is
// behind the surface or at the point itself).
struct PointArrival {
    light: vec3<f32>,
    wi: vec3<f32>,
    d2: f32,
    fc: vec3<f32>,
};

fn point_arrival(k: u32, m: Material, p: vec3<f32>, f: SurfaceFrame, wo: vec3<f32>) -> PointArrival {
    var a: PointArrival;
    a.light = point_lights[k].position.xyz;
    let to_light = a.light - p;
    a.d2 = dot(to_light, to_light);
    a.fc = vec3<f32>(0.0);
    if a.d2 > 0.0 {
        a.wi = to_light * inverseSqrt(a.d2);
        // A point light lights glossy lobes too: the probe's reflection does not hold it.
        a.fc = reflection(m, f.ns, f.ng, wo, a.wi, true);
    }
    return a;
}

// Adds the point lights to a surface's sums. A new light (Grosch 2005 section 4.2: the scene
// without the objects, which the background shows, has none of its light) gives a real
// surface its whole light as a change; a light already in the background (a room's important
// patch, shadow.z = 1) gives it only the objects' shadow, `with - without` as for the
// directional lights (Grosch's `dL_i = rho E_i / pi` where the objects block it). A virtual
// object takes the light unless shadow.w = 0 (Grosch's fast display).
//
// On lavapipe a light skipped per pixel still costs its whole body (a branch that differs
// between pixels runs both sides), while a loop costs only the trips some pixel of the block
// takes. So a real surface loops only over the point lights its screen tile's mask names
// (light_tiles.wgsl's point words, from word `mask_base + LIGHT_WORDS`), and in two passes: the
// first finds the lights that change the pixel (a new light where it shines; one already in the
// background only where the objects' shadow falls: one virtual-atlas look-up), the second
// shades those alone. A light the tile keeps but whose shadow misses the pixel costs the
// look-up, not the intensity and the real shadow too. (Testing the pixel against the shadow's
// cone, as the tile is, in place of the look-up kept more lights and was slower.)
fn add_point_lights(m: Material, p: vec3<f32>, f: SurfaceFrame, wo: vec3<f32>, on_virtual: bool, sums_in: LightSums, mask_base: u32) -> LightSums {
    var sums = sums_in;
    let count = frame.counts.y;
    let words = (count + 31u) / 32u;
    for (var word = 0u; word < words; word = word + 1u) {
        var bits = word_lights(count, word, on_virtual, mask_base + LIGHT_WORDS);
        // The lights of this word that change the pixel.
        var changing = 0u;
        loop {
            if bits == 0u {
                break;
            }
            let b = firstTrailingBit(bits);
            bits = bits & (bits - 1u);
            let k = 32u * word + b;
            if on_virtual && point_lights[k].shadow.w < 0.5 {
                continue;
            }
            let a = point_arrival(k, m, p, f, wo);
            if all(a.fc <= vec3<f32>(0.0)) {
                continue;
            }
            if !on_virtual && point_lights[k].shadow.z > 0.5 {
                let cos_light = dot(f.ng, a.wi);
                let vv = point_atlas_visibility(virtual_atlas, frame.atlas.zw, k, false, a.light, p, f.ng, cos_light);
                if vv >= 1.0 {
                    // Not shadowed by the objects: with and without agree.
                    continue;
                }
            }
            changing = changing | (1u << b);
        }
        loop {
            if changing == 0u {
                break;
            }
            let k = 32u * word + firstTrailingBit(changing);
            changing = changing & (changing - 1u);
            let a = point_arrival(k, m, p, f, wo);
            let cos_light = dot(f.ng, a.wi);
            let vv = point_atlas_visibility(virtual_atlas, frame.atlas.zw, k, false, a.light, p, f.ng, cos_light);
            let lit = point_light_term(k, a.fc, a.wi, a.d2) * point_real_visibility(k, a.light, p, f.ng, cos_light);
            if on_virtual {
                sums.direct = sums.direct + lit * vv;
            } else if point_lights[k].shadow.z > 0.5 {
                sums.affected = true;
                sums.change = sums.change + lit * (vv - 1.0);
            } else {
                sums.affected = true;
                sums.change = sums.change + lit * vv;
            }
        }
    }
    return sums;
}

// The ratio rule's `without` on a real surface from the point lights already in the
// background: their light with the real layer's shadows only.
fn point_lights_without(m: Material, p: vec3<f32>, f: SurfaceFrame, wo: vec3<f32>) -> vec3<f32> {
    var without = vec3<f32>(0.0);
    let count = frame.counts.y;
    for (var k = 0u; k < count; k = k + 1u) {
        if point_lights[k].shadow.z < 0.5 {
            continue;
        }
        let a = point_arrival(k, m, p, f, wo);
        if all(a.fc <= vec3<f32>(0.0)) {
            continue;
        }
        without = without + point_light_term(k, a.fc, a.wi, a.d2)
            * point_real_visibility(k, a.light, p, f.ng, dot(f.ng, a.wi));
    }
    return without;
}
