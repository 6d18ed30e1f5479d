// The scene pass (scene_pass.rs); prepended by gpu_scene.wgsl and shadow_lookup.wgsl.
//
// Deferred, in two passes, so that every pixel is shaded once: lavapipe shades whole 4 x 4
// blocks per triangle, and a mesh of triangles a few pixels wide (the bunny's are about 6)
// paid for its shading several times over in a forward pass (BENCHMARKS.md, "Viewer").
//
// 1. The geometry pass (`vs_geometry`, `fs_gbuffer`), 4x multisampled with a depth test,
//    writes per sample what shading needs: the view depth of the surface at the pixel centre,
//    the surface's material and layer, and its shading and geometric normals (both already
//    turned to face the viewer). A triangle's fragment is evaluated once per pixel, at the
//    pixel centre, and stored in the samples it covers, as a forward pass would shade it.
// 2. The shading pass (`vs_fullscreen`, `fs_shade`), one full-screen triangle: each pixel
//    groups its samples into surfaces (samples of the same material and layer whose points
//    and normals agree: one surface across the shared edge of two triangles of a smooth
//    mesh), shades each surface once and the sky once, and writes the samples' mean.
//
// Every surface gets the final composite of differential rendering (Debevec 1998; Grosch 2005
// section 4.1), the same per-sample rule as ibl-render's `render`:
//
// - virtual object: its own radiance, lit by the lights (each with its shadow from the real and
//   the virtual atlas), the hybrid ambient, mirrors and optionally glossy lobes reflecting the
//   probe;
// - real surface: the background B at that point plus the change the objects make,
//   `B + (with - without)` (difference) or `B with / without` (ratio, falling back to the
//   difference where `without` is 0), where with and without light the real surface's albedo
//   with and without the virtual casters, and only `with` has the goniometric point lights
//   (new lights: their pool, and the shadows in it, join the background);
// - sky: the background B.
//
// B along a pixel is, as in ibl-render's `background`, the mean of an n x n grid of sub-pixel
// rays each reading its nearest probe texel (panorama), or the photo's pixel (photo). On real
// surfaces the rays run from the probe's centre to where the camera's sub-pixel rays meet the
// surface's plane (Grosch 2005 section 4.4: the probe projected on the geometry), which equals
// the camera's rays when the camera is at the probe's centre. Coverage (location 1) is the
// fraction of the pixel's samples on virtual objects: the object's alpha, the CPU renderer's
// `object_coverage`.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lights: array<Light, MAX_SHADOWED_LIGHTS>;
@group(0) @binding(2) var<storage, read> objects: array<Object>;
@group(0) @binding(3) var<storage, read> materials: array<Material>;
@group(0) @binding(4) var probe: texture_2d<f32>;
@group(0) @binding(5) var glossy: texture_2d<f32>;
@group(0) @binding(6) var probe_sampler: sampler;
@group(0) @binding(7) var ambient: texture_2d<f32>;
@group(0) @binding(8) var photo: texture_2d<f32>;
@group(0) @binding(9) var real_atlas: texture_depth_2d;
@group(0) @binding(10) var virtual_atlas: texture_depth_2d;
@group(0) @binding(11) var shadow_sampler: sampler_comparison;
// Goniometric point lights and the strip of their intensity maps (point_lights.wgsl).
@group(0) @binding(12) var<uniform> point_lights: array<PointLight, MAX_POINT_LIGHTS>;
@group(0) @binding(13) var intensity_maps: texture_2d<f32>;
// The geometry pass's samples (frame_targets.rs): view depth (0 where no geometry was drawn),
// surface id (material + 1, negated on virtual objects; 0 where no geometry was drawn) and the
// octahedral shading and geometric normals.
@group(1) @binding(0) var gbuffer_depth: texture_multisampled_2d<f32>;
@group(1) @binding(1) var gbuffer_id: texture_multisampled_2d<f32>;
@group(1) @binding(2) var gbuffer_normals: texture_multisampled_2d<f32>;
// Per screen tile, the lights that can change the tile's real surfaces (light_tiles.wgsl; the
// layout is gpu_scene.wgsl's `light_mask_base`).
@group(1) @binding(3) var<storage, read> light_masks: array<u32>;

const PI: f32 = 3.14159265358979;

// Per-scene choices as pipeline constants (scene_pass.rs's `ShaderVariant`): a pipeline holds
// only the code its scene runs. On a software rasterizer (lavapipe) a branch on a uniform keeps
// both sides in the compiled shader and costs several times the side taken (BENCHMARKS.md,
// "Viewer"); a constant branch is compiled away.
// Composite by the ratio rule (else the difference rule).
override RATIO_RULE: bool = false;
// The background is a photograph (else the panorama).
override PHOTO_BACKGROUND: bool = false;
// Glossy lobes reflect the prefiltered probe (else the lights light them).
override GLOSSY_FROM_PROBE: bool = false;
// The hybrid ambient's irradiance map is bound.
override HAS_AMBIENT: bool = false;
// Background rays per pixel axis (1 to 8) where the probe is minified or at a pole (`background`).
override BACKGROUND_RAYS: u32 = 4u;
// Real surfaces take only their screen tile's lights (light_tiles.wgsl; else every light).
override TILED_LIGHTS: bool = false;
// Real surfaces lose the ambient light the objects hide (frame.occluder, `occluder_change`).
override OCCLUSION_GATHER: bool = false;

struct GeometryOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) material: u32,
    // 1 on virtual objects, 0 on real geometry (the object's layer, passed on so that the
    // fragment does not read the object's record again).
    @location(3) @interpolate(flat) layer: u32,
};

struct FragmentOut {
    @location(0) radiance: vec4<f32>,
    @location(1) coverage: vec4<f32>,
};

@vertex
fn vs_geometry(vertex: Vertex, @builtin(instance_index) object: u32) -> GeometryOut {
    let o = objects[object];
    let world = o.world_from_load * vec4<f32>(vertex.position, 1.0);
    var out: GeometryOut;
    out.clip = frame.clip_from_world * world;
    out.world = world.xyz;
    out.normal = (o.normal_from_load * vec4<f32>(vertex.normal, 0.0)).xyz;
    out.material = vertex.material;
    out.layer = o.flags.x;
    return out;
}

fn dir_to_uv(d: vec3<f32>) -> vec2<f32> {
    let theta = atan2(length(d.xz), d.y);
    return vec2<f32>(atan2(d.x, -d.z) / (2.0 * PI) + 0.5, theta / PI);
}

// Continuous texel coordinates (column, row; texel (i, j) spans [i, i + 1) x [j, j + 1)) of world
// direction d in the probe (CONVENTIONS section 2, as ibl_core::LatLong::dir_to_pixel before its
// rounding); the column wraps.
fn probe_coords(d: vec3<f32>, size: vec2<f32>) -> vec2<f32> {
    let local = (frame.probe_from_world * vec4<f32>(d, 0.0)).xyz;
    let uv = dir_to_uv(local);
    return vec2<f32>((uv.x - floor(uv.x)) * size.x, uv.y * size.y);
}

// Nearest probe texel along world direction d (the row clamps).
fn probe_nearest(d: vec3<f32>) -> vec3<f32> {
    let size = textureDimensions(probe, 0);
    let c = probe_coords(d, vec2<f32>(size));
    let texel = vec2<u32>(min(u32(c.x), size.x - 1u), min(u32(max(c.y, 0.0)), size.y - 1u));
    return textureLoad(probe, vec2<i32>(texel), 0).rgb * frame.probe_position.w;
}

// Filtered probe radiance along world direction d at a mip level of a chain.
fn probe_filtered(chain: texture_2d<f32>, d: vec3<f32>, level: f32) -> vec3<f32> {
    let local = (frame.probe_from_world * vec4<f32>(d, 0.0)).xyz;
    return textureSampleLevel(chain, probe_sampler, dir_to_uv(local), level).rgb * frame.probe_position.w;
}

// The camera ray through continuous pixel coordinates (view_camera.rs).
fn camera_ray(px: vec2<f32>) -> vec3<f32> {
    let k = frame.intrinsics;
    let d = vec3<f32>((px.x - k.z) / k.x, -(px.y - k.w) / k.y, -1.0);
    return normalize((frame.world_from_camera * vec4<f32>(d, 0.0)).xyz);
}

fn photo_pixel(pixel: vec2<f32>) -> vec3<f32> {
    return textureLoad(photo, vec2<i32>(pixel), 0).rgb * frame.environment.z;
}

// The direction the background is read along for the camera ray through image point `at`: the
// ray itself on the sky; on a real surface (`on_plane`), from the probe's centre to where the
// ray meets the surface's plane (through p, camera-facing normal ng, `height` = (p - eye) . ng).
fn background_direction(at: vec2<f32>, on_plane: bool, p: vec3<f32>, ng: vec3<f32>, height: f32) -> vec3<f32> {
    let d = camera_ray(at);
    if !on_plane {
        return d;
    }
    let cos_d = dot(d, ng);
    // A ray (nearly) parallel to the plane keeps the pixel centre's point.
    var q = p;
    if cos_d < -1e-4 {
        q = frame.camera_position.xyz + d * (height / cos_d);
    }
    return normalize(q - frame.probe_position.xyz);
}

// The share of a pixel's footprint lying past a line `x` texels from its centre, along one texel
// axis. The footprint (linearised) is the parallelogram `centre + s e_x + t e_y`, s and t uniform
// in [-1/2, 1/2]; along the axis its coordinate is the sum of two uniform spreads of half-widths
// `a` and `b` (the axis components of e_x / 2 and e_y / 2), whose distribution is a trapezoid:
// rising as a square over `[-(p + q), -(p - q)]`, flat over `|x| <= p - q`, falling as a square
// to `p + q` (p >= q the larger and smaller half-width). Exact where one texel boundary crosses
// the footprint; where a texel corner lies inside it, the two axes' shares are multiplied.
fn share_past(x: f32, a: f32, b: f32) -> f32 {
    let p = max(max(a, b), 1e-6);
    let q = min(a, b);
    let ramp = max(8.0 * p * q, 1e-30);
    let rising = (x + p + q) * (x + p + q) / ramp;
    let flat = (x + p) / (2.0 * p);
    let falling = 1.0 - (p + q - x) * (p + q - x) / ramp;
    let below = select(select(select(1.0, falling, x < p + q), flat, x <= p - q), rising, x < q - p);
    return 1.0 - select(below, 0.0, x <= -(p + q));
}

// B seen through the pixel at `pixel` (its top-left corner is floor(pixel)): the mean of the
// nearest-texel probe over the pixel's area, as ibl render's footprint (ibl-render footprint.rs)
// takes it exactly. Where the probe is magnified (the pixel's footprint, linearised from its
// centre's ray and its two neighbours', has a bounding box at most one texel across: the bundled
// scenes' whole view but for the poles), the footprint's shares of its at most 2 x 2 texels
// (share_past) weigh them: 3 rays and 4 reads in place of BACKGROUND_RAYS^2 of each (on lavapipe
// the 16 rays were a sixth of a frame). Elsewhere (a minified probe, a pole) a BACKGROUND_RAYS x BACKGROUND_RAYS grid
// of nearest-texel rays; one ray per pixel is the centre's texel.
fn background(pixel: vec2<f32>, on_plane: bool, p: vec3<f32>, ng: vec3<f32>) -> vec3<f32> {
    if PHOTO_BACKGROUND {
        return photo_pixel(pixel);
    }
    let height = dot(p - frame.camera_position.xyz, ng);
    let corner = floor(pixel);
    let n = BACKGROUND_RAYS;
    let dims = textureDimensions(probe, 0);
    let size = vec2<f32>(dims);
    let centre = corner + 0.5;
    if n == 1u {
        return probe_nearest(background_direction(centre, on_plane, p, ng, height));
    }
    let c = probe_coords(background_direction(centre, on_plane, p, ng, height), size);
    var dx = probe_coords(background_direction(centre + vec2<f32>(1.0, 0.0), on_plane, p, ng, height), size) - c;
    var dy = probe_coords(background_direction(centre + vec2<f32>(0.0, 1.0), on_plane, p, ng, height), size) - c;
    // Columns wrap: a step across the seam is the short way round.
    dx.x = dx.x - size.x * round(dx.x / size.x);
    dy.x = dy.x - size.x * round(dy.x / size.x);
    let half_box = 0.5 * (abs(dx) + abs(dy));
    // A loop of 0 or 1 trips rather than an `if`: lavapipe runs a branch's body for a whole block
    // of pixels under a mask, but skips a loop no pixel of the block enters (shadow_lookup.wgsl).
    let magnified = all(half_box <= vec2<f32>(0.5));
    var sum = vec3<f32>(0.0);
    for (var once = select(0u, 1u, magnified); once > 0u; once = once - 1u) {
        let first = floor(c - half_box);
        // The share of the footprint past the boundary between the first texel and the next.
        let boundary = first + 1.0 - c;
        let share = vec2<f32>(
            share_past(boundary.x, 0.5 * abs(dx.x), 0.5 * abs(dy.x)),
            share_past(boundary.y, 0.5 * abs(dx.y), 0.5 * abs(dy.y)),
        );
        let w = i32(dims.x);
        let h = i32(dims.y);
        let i0 = ((i32(first.x) % w) + w) % w;
        let i1 = (i0 + 1) % w;
        let j0 = clamp(i32(first.y), 0, h - 1);
        let j1 = clamp(i32(first.y) + 1, 0, h - 1);
        let top = mix(textureLoad(probe, vec2<i32>(i0, j0), 0).rgb, textureLoad(probe, vec2<i32>(i1, j0), 0).rgb, share.x);
        let bottom = mix(textureLoad(probe, vec2<i32>(i0, j1), 0).rgb, textureLoad(probe, vec2<i32>(i1, j1), 0).rgb, share.x);
        sum = mix(top, bottom, share.y) * frame.probe_position.w;
    }
    let rays = select(n, 0u, magnified);
    for (var sy = 0u; sy < rays; sy = sy + 1u) {
        for (var sx = 0u; sx < rays; sx = sx + 1u) {
            let at = corner + (vec2<f32>(f32(sx), f32(sy)) + 0.5) / f32(n);
            sum = sum + probe_nearest(background_direction(at, on_plane, p, ng, height)) / f32(n * n);
        }
    }
    return sum;
}

// f(wo, wi) cos(theta_i) of a material (ibl-render's Bsdf::eval times the cosine): zero unless
// wo and wi are above the geometric surface and wi above the shading surface.
fn reflection(m: Material, ns: vec3<f32>, ng: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>, with_lobe: bool) -> vec3<f32> {
    let cos_i = dot(wi, ns);
    if dot(wo, ng) <= 0.0 || dot(wi, ng) <= 0.0 || cos_i <= 0.0 {
        return vec3<f32>(0.0);
    }
    let kind = u32(m.albedo_kind.w);
    if kind == 2u {
        return vec3<f32>(0.0);
    }
    var f = m.albedo_kind.rgb / PI;
    if kind == 1u && with_lobe {
        let r = 2.0 * dot(wo, ns) * ns - wo;
        let cos_a = dot(wi, r);
        if cos_a > 0.0 {
            let e = m.specular_exponent.w;
            f = f + m.specular_exponent.rgb * ((e + 2.0) / (2.0 * PI) * pow(cos_a, e));
        }
    }
    return f * cos_i;
}

// E(n) of the hybrid ambient (world-frame lat-long map).
fn ambient_irradiance(n: vec3<f32>) -> vec3<f32> {
    if !HAS_AMBIENT {
        return vec3<f32>(0.0);
    }
    return textureSampleLevel(ambient, probe_sampler, dir_to_uv(n), 0.0).rgb * frame.environment.w;
}

fn noise(pixel: vec2<f32>) -> f32 {
    // Interleaved gradient noise (Jimenez 2014): decorrelates the PCSS rotations of neighbours.
    return fract(52.9829189 * fract(dot(pixel, vec2<f32>(0.06711056, 0.00583715))));
}

// Shading normal and camera-facing geometric normal, as ibl_scene's `surface_point`: both
// flipped to face the viewer (two-sided), the shading normal bent back to the geometric side.
struct SurfaceFrame {
    ns: vec3<f32>,
    ng: vec3<f32>,
};

fn facing(in_normal: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, wo: vec3<f32>, front: bool) -> SurfaceFrame {
    var ng = normalize(cross(dx, dy));
    if dot(ng, wo) < 0.0 {
        ng = -ng;
    }
    var ns = ng;
    if dot(in_normal, in_normal) > 1e-20 {
        ns = normalize(in_normal);
        if !front {
            ns = -ns;
        }
    }
    if dot(ns, ng) <= 0.0 {
        ns = ng;
    }
    var out: SurfaceFrame;
    out.ns = ns;
    out.ng = ng;
    return out;
}

// What the lights give a surface point: on a virtual object its direct light (each light's
// shadow from both layers), on a real surface the change the virtual objects make,
// `with - without` over the lights they block.
struct LightSums {
    direct: vec3<f32>,
    change: vec3<f32>,
    affected: bool,
};

// The lights of mask word `word` (32 a word) of `count` that a surface takes: every one on a
// virtual object, on a real surface those its screen tile's mask names, whose words start at
// `first` (light_tiles.wgsl).
fn word_lights(count: u32, word: u32, on_virtual: bool, first: u32) -> u32 {
    var bits = 0xffffffffu;
    if TILED_LIGHTS && !on_virtual {
        bits = light_masks[first + word];
    }
    let left = count - 32u * word;
    if left < 32u {
        bits = bits & ((1u << left) - 1u);
    }
    return bits;
}

// One loop over the lights for both layers, so that the shadow look-ups are compiled once
// (on lavapipe the size of the shader costs as much as the work it does: BENCHMARKS.md). A
// virtual object takes every light; a real surface only those its screen tile's mask names
// (light_tiles.wgsl), the same for every pixel of the tile, starting at word `mask_base`.
fn light_sums(m: Material, p: vec3<f32>, f: SurfaceFrame, wo: vec3<f32>, on_virtual: bool, pixel_noise: f32, mask_base: u32) -> LightSums {
    var sums = LightSums(vec3<f32>(0.0), vec3<f32>(0.0), false);
    // Real surfaces take their glossy lobe from the lights (ibl-render's rule).
    let with_lobe = !on_virtual || !GLOSSY_FROM_PROBE;
    let count = frame.counts.x;
    let words = (count + 31u) / 32u;
    for (var word = 0u; word < words; word = word + 1u) {
        var bits = word_lights(count, word, on_virtual, mask_base);
        loop {
            if bits == 0u {
                break;
            }
            let i = 32u * word + firstTrailingBit(bits);
            bits = bits & (bits - 1u);
            let wi = lights[i].direction.xyz;
            let fc = reflection(m, f.ns, f.ng, wo, wi, with_lobe);
            if all(fc <= vec3<f32>(0.0)) {
                continue;
            }
            let vv = virtual_visibility(i, p, f.ng, pixel_noise);
            if on_virtual || vv < 1.0 {
                let e = fc * lights[i].irradiance.rgb * real_visibility(i, p, f.ng, pixel_noise);
                if on_virtual {
                    sums.direct = sums.direct + e * vv;
                } else {
                    sums.affected = true;
                    sums.change = sums.change + e * (vv - 1.0);
                }
            }
        }
    }
    return sums;
}

// A virtual object's radiance from its lights' sums (mirrors reflect the probe instead).
fn shade_virtual(m: Material, f: SurfaceFrame, wo: vec3<f32>, sums: LightSums) -> vec3<f32> {
    let kind = u32(m.albedo_kind.w);
    let ns = f.ns;
    if kind == 2u {
        // A perfect mirror reflects the probe (level 0 of the chain).
        let r = 2.0 * dot(wo, ns) * ns - wo;
        return m.specular_exponent.rgb * probe_filtered(probe, r, 0.0);
    }
    var radiance = sums.direct + m.albedo_kind.rgb / PI * ambient_irradiance(ns);
    if kind == 1u && GLOSSY_FROM_PROBE {
        // The glossy lobe reflecting the prefiltered probe (environment_maps.rs).
        let r = 2.0 * dot(wo, ns) * ns - wo;
        let e = m.specular_exponent.w;
        let level = clamp(1.0 + 0.5 * log2(frame.environment.x / max(e, 1e-6)), 0.0,
                          frame.environment.y - 1.0);
        radiance = radiance + m.specular_exponent.rgb * probe_filtered(glossy, r, level);
    }
    return radiance;
}

// The change in a real surface point's radiance from the ambient light the virtual objects
// hide from it, the improved display's differential gather (docs/ROOMS.md section 13) with the
// objects taken as one sphere of their mean cross-section (frame.occluder): the sphere covers
// a cone of half-angle a (sin a = r / d) towards its centre c, whose cosine-weighted solid angle
// is pi sin^2(a) (n . c) while it stands above the horizon. Through it the point no longer sees
// the room beyond, radiance E(c) / pi (the ambient map at the objects: the light arriving there
// from beyond them), but the objects' own ambient-lit side, rho_o E(-c) / pi, so
// `dE = sin^2(a) (n . c) (rho_o E(-c) - E(c))` and the radiance changes by `rho dE / pi`.
fn occluder_change(m: Material, p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let o = frame.occluder;
    let to_centre = o.xyz - p;
    let d2 = dot(to_centre, to_centre);
    if o.w <= 0.0 || d2 <= 0.0 {
        return vec3<f32>(0.0);
    }
    let c = to_centre * inverseSqrt(d2);
    let cos_n = dot(n, c);
    if cos_n <= 0.0 {
        return vec3<f32>(0.0);
    }
    let cover = min(o.w * o.w / d2, 1.0);
    let hidden = ambient_irradiance(c);
    let seen = frame.occluder_albedo.rgb * ambient_irradiance(-c);
    return m.albedo_kind.rgb / PI * (cover * cos_n) * (seen - hidden);
}

// The composite on a real surface (module notes).
fn composite_real(m: Material, p: vec3<f32>, f: SurfaceFrame, wo: vec3<f32>, b: vec3<f32>, sums: LightSums, pixel_noise: f32) -> vec3<f32> {
    let change = sums.change;
    if !sums.affected {
        return b;
    }
    if !RATIO_RULE {
        return max(b + change, vec3<f32>(0.0));
    }
    var without = m.albedo_kind.rgb / PI * ambient_irradiance(f.ns);
    let count = frame.counts.x;
    for (var i = 0u; i < count; i = i + 1u) {
        let wi = lights[i].direction.xyz;
        let fc = reflection(m, f.ns, f.ng, wo, wi, true);
        if all(fc <= vec3<f32>(0.0)) {
            continue;
        }
        without = without + fc * lights[i].irradiance.rgb * real_visibility(i, p, f.ng, pixel_noise);
    }
    if POINT_LIGHTS {
        without = without + point_lights_without(m, p, f, wo);
    }
    let lit = without + change;
    var out = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c = c + 1u) {
        if change[c] == 0.0 {
            out[c] = b[c];
        } else if without[c] > 0.0 {
            out[c] = b[c] * (lit[c] / without[c]);
        } else {
            out[c] = b[c] + change[c];
        }
    }
    return max(out, vec3<f32>(0.0));
}

// Octahedral encoding of a unit vector (Meyer et al. 2010), in [-1, 1]^2.
fn oct_encode(n: vec3<f32>) -> vec2<f32> {
    let q = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return q;
    }
    return (1.0 - abs(q.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), q >= vec2<f32>(0.0));
}

struct GBufferOut {
    @location(0) depth: vec4<f32>,
    @location(1) id: vec4<f32>,
    @location(2) normals: vec4<f32>,
};

@fragment
fn fs_gbuffer(in: GeometryOut, @builtin(front_facing) front: bool) -> GBufferOut {
    let dx = dpdx(in.world);
    let dy = dpdy(in.world);
    let eye = frame.camera_position.xyz;
    let wo = normalize(eye - in.world);
    let f = facing(in.normal, dx, dy, wo, front);
    var out: GBufferOut;
    // The distance in front of the camera (point_at_depth).
    out.depth = vec4<f32>(dot(eye - in.world, frame.world_from_camera[2].xyz), 0.0, 0.0, 0.0);
    let id = f32(in.material + 1u);
    out.id = vec4<f32>(select(id, -id, in.layer == 1u), 0.0, 0.0, 0.0);
    out.normals = vec4<f32>(oct_encode(f.ns), oct_encode(f.ng));
    return out;
}

// A sample of the geometry pass.
struct Surface {
    // World point at the pixel centre.
    p: vec3<f32>,
    // Material + 1, negated on virtual objects; 0 for the sky.
    id: f32,
    ns: vec3<f32>,
    ng: vec3<f32>,
};

fn surface_at(texel: vec2<i32>, pixel: vec2<f32>, s: i32) -> Surface {
    var out: Surface;
    out.id = textureLoad(gbuffer_id, texel, s).x;
    out.p = point_at_depth(pixel, textureLoad(gbuffer_depth, texel, s).x);
    let e = textureLoad(gbuffer_normals, texel, s);
    out.ns = oct_decode(e.xy);
    out.ng = oct_decode(e.zw);
    return out;
}

// Whether two samples lie on one surface: the same material and layer, normals within about
// 8 degrees and points within two pixel footprints (two triangles of a smooth mesh sharing the
// pixel; an object's silhouette over itself or the ground parts by depth).
fn same_surface(a: Surface, b: Surface, footprint: f32) -> bool {
    return a.id == b.id && dot(a.ns, b.ns) > 0.99 && distance(a.p, b.p) < footprint;
}

// The composite radiance of one surface seen through `pixel`.
fn shade_surface(s: Surface, pixel: vec2<f32>, pixel_noise: f32, mask_base: u32) -> vec3<f32> {
    let m = materials[u32(abs(s.id)) - 1u];
    let on_virtual = s.id < 0.0;
    let wo = normalize(frame.camera_position.xyz - s.p);
    var f: SurfaceFrame;
    f.ns = s.ns;
    f.ng = s.ng;
    var sums = light_sums(m, s.p, f, wo, on_virtual, pixel_noise, mask_base);
    if POINT_LIGHTS {
        sums = add_point_lights(m, s.p, f, wo, on_virtual, sums, mask_base);
    }
    if OCCLUSION_GATHER && !on_virtual {
        let gathered = occluder_change(m, s.p, f.ns);
        if any(gathered != vec3<f32>(0.0)) {
            sums.affected = true;
            sums.change = sums.change + gathered;
        }
    }
    if on_virtual {
        return shade_virtual(m, f, wo, sums);
    }
    let b = background(pixel, true, s.p, f.ng);
    return composite_real(m, s.p, f, wo, b, sums, pixel_noise);
}

struct FullscreenOut {
    @builtin(position) clip: vec4<f32>,
};

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> FullscreenOut {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: FullscreenOut;
    out.clip = vec4<f32>(x, y, 0.0, 1.0);
    return out;
}

@fragment
fn fs_shade(in: FullscreenOut) -> FragmentOut {
    let pixel = in.clip.xy;
    let texel = vec2<i32>(floor(pixel));
    let pixel_noise = noise(floor(pixel));
    let mask_base = light_mask_base(vec2<u32>(texel) / LIGHT_TILE, u32(frame.viewport.x));
    // Most pixels lie inside one triangle (or the sky): their samples hold the same fragment,
    // so sample 0 stands for all of them and the rest are not decoded.
    let id0 = textureLoad(gbuffer_id, texel, 0).x;
    let depth0 = textureLoad(gbuffer_depth, texel, 0).x;
    var one_fragment = true;
    for (var s = 1u; s < GBUFFER_SAMPLES; s = s + 1u) {
        one_fragment = one_fragment && textureLoad(gbuffer_id, texel, s).x == id0
            && textureLoad(gbuffer_depth, texel, s).x == depth0;
    }
    let read = select(GBUFFER_SAMPLES, 1u, one_fragment);
    let share = f32(GBUFFER_SAMPLES / read);
    // Group the samples into surfaces: `surfaces[g]` is the first sample of group g, `weights[g]`
    // how many samples it stands for.
    var surfaces: array<Surface, GBUFFER_SAMPLES>;
    var weights = array<f32, GBUFFER_SAMPLES>(0.0, 0.0, 0.0, 0.0);
    var groups = 0u;
    var sky = 0.0;
    var covered = 0.0;
    for (var s = 0u; s < read; s = s + 1u) {
        let a = surface_at(texel, pixel, i32(s));
        if a.id == 0.0 {
            sky = sky + share;
            continue;
        }
        if a.id < 0.0 {
            covered = covered + share;
        }
        // Two pixel footprints at this distance (intrinsics.y: focal length in pixels).
        let footprint = 2.0 * distance(a.p, frame.camera_position.xyz) / frame.intrinsics.y;
        var joined = false;
        for (var g = 0u; g < groups; g = g + 1u) {
            if !joined && same_surface(surfaces[g], a, footprint) {
                weights[g] = weights[g] + share;
                joined = true;
            }
        }
        if !joined {
            surfaces[groups] = a;
            weights[groups] = share;
            groups = groups + 1u;
        }
    }
    var sum = vec3<f32>(0.0);
    if sky > 0.0 {
        sum = sky * background(pixel, false, vec3<f32>(0.0), vec3<f32>(0.0, 0.0, 1.0));
    }
    for (var g = 0u; g < groups; g = g + 1u) {
        sum = sum + weights[g] * shade_surface(surfaces[g], pixel, pixel_noise, mask_base);
    }
    var out: FragmentOut;
    out.radiance = vec4<f32>(sum / f32(GBUFFER_SAMPLES), 1.0);
    out.coverage = vec4<f32>(covered / f32(GBUFFER_SAMPLES), 0.0, 0.0, 1.0);
    return out;
}
