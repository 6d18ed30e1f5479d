// Light markers over the tone-mapped picture (markers_pass.rs): one instanced quad per marker,
// a ring of the given radius (a light; its size grows with the light's share of the power) or a
// ring with a cross (the dominant light). Premultiplied alpha over the display target.

struct Marker {
    // centre x, y and radius in output pixels; style (0 ring, 1 ring with cross).
    shape: vec4<f32>,
    // premultiplied colour.
    colour: vec4<f32>,
};

struct Screen {
    // width, height, line half-width (pixels), 0.
    size: vec4<f32>,
};

@group(0) @binding(0) var<uniform> screen: Screen;
@group(0) @binding(1) var<storage, read> markers: array<Marker>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) offset: vec2<f32>,
    @location(1) @interpolate(flat) marker: u32,
};

@vertex
fn vs_marker(@builtin(vertex_index) index: u32, @builtin(instance_index) marker: u32) -> VertexOut {
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0)
    );
    let m = markers[marker];
    let extent = 1.6 * m.shape.z + 2.0 * screen.size.z + 1.0;
    let offset = corners[index] * extent;
    let pixel = m.shape.xy + offset;
    var out: VertexOut;
    out.position = vec4<f32>(2.0 * pixel.x / screen.size.x - 1.0, 1.0 - 2.0 * pixel.y / screen.size.y, 0.0, 1.0);
    out.offset = offset;
    out.marker = marker;
    return out;
}

@fragment
fn fs_marker(in: VertexOut) -> @location(0) vec4<f32> {
    let m = markers[in.marker];
    let half_width = screen.size.z;
    let d = length(in.offset);
    var coverage = 1.0 - smoothstep(half_width - 0.5, half_width + 0.5, abs(d - m.shape.z));
    if m.shape.w == 1.0 {
        let cross = min(abs(in.offset.x), abs(in.offset.y));
        let arm = 1.0 - smoothstep(half_width - 0.5, half_width + 0.5, cross);
        coverage = max(coverage, arm * f32(d < m.shape.z * 1.6));
    }
    if coverage <= 0.0 {
        discard;
    }
    return m.colour * coverage;
}
