// The probe's mip chains (environment_maps.rs): a box-filtered chain (each level the bilinear
// average of the level above at the texel centre, i.e. the mean of its 2 x 2 texels), and the
// Phong-prefiltered chain whose level k >= 1 holds, at each direction r,
//
//   P_e(r) = integral L(w) (e + 1) / (2 pi) cos^e(angle(w, r)) dw,   e = e_k,
//
// the radiance a normalised Phong lobe of exponent e about r gathers. It is estimated with 64
// lobe samples (Hammersley points), each read from the box chain at the level whose texel solid
// angle matches the sample's share of the lobe (filtered importance sampling, Krivanek & Colbert
// 2008, GPU Gems 3 ch. 20), which keeps the estimate smooth with few samples.

struct Prefilter {
    // Exponent of this level's lobe.
    exponent: f32,
    // Solid angle of one texel of the source's level 0, sr.
    texel_solid_angle: f32,
    // Mip levels of the source.
    levels: f32,
    _pad: f32,
};

@group(0) @binding(0) var<uniform> prefilter: Prefilter;
@group(0) @binding(1) var source: texture_2d<f32>;
@group(0) @binding(2) var linear_sampler: sampler;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> VertexOut {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: VertexOut;
    out.position = vec4<f32>(x, y, 0.0, 1.0);
    out.uv = vec2<f32>(0.5 * x + 0.5, 0.5 - 0.5 * y);
    return out;
}

const PI: f32 = 3.14159265358979;

// CONVENTIONS section 2: theta from +Y, phi = 0 forward (-Z), +pi/2 right (+X).
fn uv_to_dir(uv: vec2<f32>) -> vec3<f32> {
    let theta = PI * uv.y;
    let phi = 2.0 * PI * (uv.x - 0.5);
    return vec3<f32>(sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi));
}

fn dir_to_uv(d: vec3<f32>) -> vec2<f32> {
    let theta = atan2(length(d.xz), d.y);
    let phi = atan2(d.x, -d.z);
    return vec2<f32>(phi / (2.0 * PI) + 0.5, theta / PI);
}

// The previous level at this texel's centre: bound as a single-level view, so this is level 0 of
// the view; with an exact 2:1 reduction the bilinear tap is the mean of the 2 x 2 texels.
@fragment
fn fs_downsample(in: VertexOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSampleLevel(source, linear_sampler, in.uv, 0.0).rgb, 1.0);
}

fn radical_inverse(bits_in: u32) -> f32 {
    var bits = bits_in;
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return f32(bits) * 2.3283064365386963e-10;
}

const SAMPLES: u32 = 64u;

@fragment
fn fs_prefilter(in: VertexOut) -> @location(0) vec4<f32> {
    let r = uv_to_dir(in.uv);
    // A basis about r.
    var helper = vec3<f32>(0.0, 1.0, 0.0);
    if abs(r.y) > 0.9 {
        helper = vec3<f32>(1.0, 0.0, 0.0);
    }
    let t = normalize(cross(helper, r));
    let b = cross(r, t);
    let e = prefilter.exponent;
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < SAMPLES; i = i + 1u) {
        let u1 = (f32(i) + 0.5) / f32(SAMPLES);
        let u2 = radical_inverse(i);
        // Phong lobe sampling: cos(alpha) = u^(1 / (e + 1)), density (e + 1) / (2 pi) cos^e.
        let cos_a = pow(u1, 1.0 / (e + 1.0));
        let sin_a = sqrt(max(0.0, 1.0 - cos_a * cos_a));
        let phi = 2.0 * PI * u2;
        let w = normalize(t * (sin_a * cos(phi)) + b * (sin_a * sin(phi)) + r * cos_a);
        let pdf = (e + 1.0) / (2.0 * PI) * pow(cos_a, e);
        let sample_solid_angle = 1.0 / (f32(SAMPLES) * max(pdf, 1e-8));
        let lod = clamp(0.5 * log2(sample_solid_angle / prefilter.texel_solid_angle) + 1.0, 0.0,
                        prefilter.levels - 1.0);
        sum = sum + textureSampleLevel(source, linear_sampler, dir_to_uv(w), lod).rgb;
    }
    return vec4<f32>(sum / f32(SAMPLES), 1.0);
}
