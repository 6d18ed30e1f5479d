// Display transform (ibl-io's `tonemap`, on the GPU): radiance x 2^exposure, a tone curve,
// the sRGB encoding; then the overlay (premultiplied colour) on top. One full-screen triangle.

struct Display {
    // 2^exposure_stops.
    scale: f32,
    // 0 clamp, 1 Reinhard, 2 ACES filmic (Narkowicz).
    curve: u32,
    _pad0: u32,
    _pad1: u32,
};

@group(0) @binding(0) var<uniform> display: Display;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var overlay: texture_2d<f32>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
};

@vertex
fn vs_fullscreen(@builtin(vertex_index) index: u32) -> VertexOut {
    // A triangle covering the viewport: (-1, -1), (3, -1), (-1, 3).
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    var out: VertexOut;
    out.position = vec4<f32>(x, y, 0.0, 1.0);
    return out;
}

fn tone(x: f32) -> f32 {
    if display.curve == 0u {
        return min(x, 1.0);
    }
    if display.curve == 1u {
        return x / (1.0 + x);
    }
    let y = min(x, 1.0e4);
    return clamp((y * (2.51 * y + 0.03)) / (y * (2.43 * y + 0.59) + 0.14), 0.0, 1.0);
}

fn srgb(x: f32) -> f32 {
    if x <= 0.0031308 {
        return 12.92 * max(x, 0.0);
    }
    return 1.055 * pow(min(x, 1.0), 1.0 / 2.4) - 0.055;
}

fn encode(v: f32) -> f32 {
    // Negative and NaN display as black (`v > 0` is false for NaN), +Inf as white.
    var x = 0.0;
    if v > 0.0 {
        x = v * display.scale;
    }
    return srgb(tone(x));
}

@fragment
fn fs_display(in: VertexOut) -> @location(0) vec4<f32> {
    let pixel = vec2<i32>(in.position.xy);
    let l = textureLoad(radiance, pixel, 0).rgb;
    let picture = vec3<f32>(encode(l.r), encode(l.g), encode(l.b));
    let o = textureLoad(overlay, pixel, 0);
    return vec4<f32>(picture * (1.0 - o.a) + o.rgb, 1.0);
}
