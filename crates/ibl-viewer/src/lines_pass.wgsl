// Antialiased line segments over the tone-mapped picture (lines_pass.rs): one instanced quad per
// segment, a capsule of the given half-width around it (a segment of length 0 is a disc), its
// coverage the pixel centre's distance to the segment. Where a segment joins the next one of its
// polyline it stops at the line through the joint across their mean tangent (the other takes
// the pixels beyond), so joined segments never cover a pixel twice. Premultiplied alpha over
// the display target, so a pixel whose centre lies within half-width - 0.5 of the segment is
// exactly the segment's colour.

struct Segment {
    // from x, y and to x, y in output pixels (continuous, row 0 at the top).
    ends: vec4<f32>,
    // half-width in pixels, then unused.
    style: vec4<f32>,
    // premultiplied colour.
    colour: vec4<f32>,
    // unit mean tangents at the joints at from (xy) and to (zw); zero: a round end.
    cuts: vec4<f32>,
};

struct Screen {
    // width, height (pixels), 0, 0.
    size: vec4<f32>,
};

@group(0) @binding(0) var<uniform> screen: Screen;
@group(0) @binding(1) var<storage, read> segments: array<Segment>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) @interpolate(flat) segment: u32,
};

@vertex
fn vs_line(@builtin(vertex_index) index: u32, @builtin(instance_index) segment: u32) -> VertexOut {
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0)
    );
    let s = segments[segment];
    let a = s.ends.xy;
    let b = s.ends.zw;
    let ab = b - a;
    let len = length(ab);
    var along = vec2<f32>(1.0, 0.0);
    if len > 1e-6 {
        along = ab / len;
    }
    let across = vec2<f32>(-along.y, along.x);
    // One pixel beyond the half-width holds the antialiased fringe.
    let reach = s.style.x + 1.0;
    let c = corners[index];
    let pixel = 0.5 * (a + b) + along * c.x * (0.5 * len + reach) + across * c.y * reach;
    var out: VertexOut;
    out.position = vec4<f32>(2.0 * pixel.x / screen.size.x - 1.0, 1.0 - 2.0 * pixel.y / screen.size.y, 0.0, 1.0);
    out.segment = segment;
    return out;
}

@fragment
fn fs_line(in: VertexOut) -> @location(0) vec4<f32> {
    let s = segments[in.segment];
    // The fragment's position is its pixel centre (i + 0.5, j + 0.5).
    let p = in.position.xy;
    let a = s.ends.xy;
    let ab = s.ends.zw - a;
    let l2 = dot(ab, ab);
    var h = 0.0;
    if l2 > 1e-12 {
        h = clamp(dot(p - a, ab) / l2, 0.0, 1.0);
    }
    if dot(s.cuts.xy, s.cuts.xy) > 0.0 && dot(p - a, s.cuts.xy) < 0.0 {
        discard;
    }
    if dot(s.cuts.zw, s.cuts.zw) > 0.0 && dot(p - s.ends.zw, s.cuts.zw) >= 0.0 {
        discard;
    }
    let d = length(p - a - ab * h);
    let coverage = clamp(s.style.x + 0.5 - d, 0.0, 1.0);
    if coverage <= 0.0 {
        discard;
    }
    return s.colour * coverage;
}
