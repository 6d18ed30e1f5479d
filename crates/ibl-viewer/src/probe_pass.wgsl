// The probe viewer (probe_pass.rs): the lat-long probe seen from its centre through a pinhole
// camera (look around) or laid out flat, with optional Laplacian sharpening (Grosch 2005
// section 3: a high-resolution look needs a "laplacian-enhanced image" of the map), or its SH
// irradiance E / pi instead of its radiance; region borders go to the overlay target.

struct ProbeView {
    // Columns: camera right, up, back (look around).
    world_from_camera: mat4x4<f32>,
    // fx, fy, cx, cy in output pixels.
    intrinsics: vec4<f32>,
    // output width, height; probe width, height.
    viewport: vec4<f32>,
    // World to probe frame.
    probe_from_world: mat4x4<f32>,
    // radiance scale of the probe texture, sharpening strength, scale of the irradiance
    // texture, mip level for minification.
    params: vec4<f32>,
    // projection (0 look around, 1 lat-long), layer (0 radiance, 1 SH irradiance),
    // region borders shown (0, 1), 0.
    modes: vec4<u32>,
};

@group(0) @binding(0) var<uniform> view: ProbeView;
@group(0) @binding(1) var probe: texture_2d<f32>;
@group(0) @binding(2) var probe_sampler: sampler;
@group(0) @binding(3) var irradiance: texture_2d<f32>;
@group(0) @binding(4) var regions: texture_2d<f32>;

const PI: f32 = 3.14159265358979;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
};

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> VertexOut {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: VertexOut;
    out.position = vec4<f32>(x, y, 0.0, 1.0);
    return out;
}

struct ProbeOut {
    @location(0) radiance: vec4<f32>,
    @location(1) overlay: vec4<f32>,
};

fn dir_to_uv(d: vec3<f32>) -> vec2<f32> {
    let theta = atan2(length(d.xz), d.y);
    return vec2<f32>(atan2(d.x, -d.z) / (2.0 * PI) + 0.5, theta / PI);
}

fn sample(uv: vec2<f32>, lod: f32) -> vec3<f32> {
    return textureSampleLevel(probe, probe_sampler, uv, lod).rgb;
}

@fragment
fn fs_probe(in: VertexOut) -> ProbeOut {
    let pixel = in.position.xy;
    var uv: vec2<f32>;
    if view.modes.x == 1u {
        uv = pixel / view.viewport.xy;
    } else {
        let k = view.intrinsics;
        let d = vec3<f32>((pixel.x - k.z) / k.x, -(pixel.y - k.w) / k.y, -1.0);
        let world = normalize((view.world_from_camera * vec4<f32>(d, 0.0)).xyz);
        uv = dir_to_uv((view.probe_from_world * vec4<f32>(world, 0.0)).xyz);
    }
    var out: ProbeOut;
    if view.modes.y == 1u {
        let e = textureSampleLevel(irradiance, probe_sampler, uv, 0.0).rgb * view.params.z;
        out.radiance = vec4<f32>(e, 1.0);
    } else {
        let lod = view.params.w;
        var l = sample(uv, lod);
        let strength = view.params.y;
        if strength > 0.0 {
            // Unsharp masking by the 4-neighbour Laplacian at the texel size of this level.
            let texel = exp2(lod) / view.viewport.zw;
            let mean = 0.25 * (sample(uv + vec2<f32>(texel.x, 0.0), lod)
                + sample(uv - vec2<f32>(texel.x, 0.0), lod)
                + sample(uv + vec2<f32>(0.0, texel.y), lod)
                + sample(uv - vec2<f32>(0.0, texel.y), lod));
            l = max(l + strength * (l - mean), vec3<f32>(0.0));
        }
        out.radiance = vec4<f32>(l * view.params.x, 1.0);
    }
    out.overlay = vec4<f32>(0.0);
    if view.modes.z == 1u {
        let size = vec2<f32>(textureDimensions(regions, 0));
        var t = uv;
        t.x = t.x - floor(t.x);
        let texel = vec2<i32>(min(t * size, size - 1.0));
        if textureLoad(regions, texel, 0).r > 0.5 {
            // Premultiplied: 60 % of a light cyan.
            out.overlay = vec4<f32>(0.3, 0.55, 0.6, 0.6);
        }
    }
    return out;
}
