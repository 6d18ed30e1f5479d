// Depth passes of the shadow atlases (shadow_atlas.rs); prepended by gpu_scene.wgsl.
//
// Real geometry (it never moves): one draw per light into that light's tile, the viewport set
// to the tile (the geometry can extend past it and is clipped there); instance_index = light.
// Virtual objects (they move): one instanced draw per object for all lights at once,
// instance_index = object x lights + light; the object is wholly inside every tile by
// construction (each tile is fitted around the bounding sphere of the virtual objects), so the
// atlas needs no clipping against tile borders.
// Point lights' cube faces: one draw per face that sees casters, the viewport set to the face's
// tile (casters straddle faces, so the tile clips them), instance_index = (object x
// MAX_POINT_LIGHTS + light) x 6 + face, object 0 being the real geometry.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lights: array<Light, MAX_SHADOWED_LIGHTS>;
@group(0) @binding(2) var<storage, read> objects: array<Object>;
@group(0) @binding(3) var<uniform> point_lights: array<PointLight, MAX_POINT_LIGHTS>;

@vertex
fn vs_real_tile(vertex: Vertex, @builtin(instance_index) light: u32) -> @builtin(position) vec4<f32> {
    let p = lights[light].real_map * vec4<f32>(vertex.position, 1.0);
    // Receivers past the slab still need their casters: keep depth within [0, 1].
    return vec4<f32>(p.xy, clamp(p.z, 0.0, 1.0), 1.0);
}

@vertex
fn vs_virtual_atlas(vertex: Vertex, @builtin(instance_index) instance: u32) -> @builtin(position) vec4<f32> {
    let count = frame.counts.x;
    let light = instance % count;
    let object = instance / count;
    let world = objects[object].world_from_load * vec4<f32>(vertex.position, 1.0);
    let p = lights[light].virtual_map * world;
    let tile = lights[light].virtual_tile;
    let centre = vec2<f32>((tile.x + 0.5 * tile.z) * 2.0 - 1.0, 1.0 - (tile.y + 0.5 * tile.w) * 2.0);
    return vec4<f32>(centre + p.xy * tile.zw, clamp(p.z, 0.0, 1.0), 1.0);
}

@vertex
fn vs_point_face(vertex: Vertex, @builtin(instance_index) instance: u32) -> @builtin(position) vec4<f32> {
    let face = instance % 6u;
    let light = (instance / 6u) % MAX_POINT_LIGHTS;
    let object = instance / (6u * MAX_POINT_LIGHTS);
    let world = objects[object].world_from_load * vec4<f32>(vertex.position, 1.0);
    let l = point_lights[light];
    let q = face_coords(world.xyz - l.position.xyz, face);
    // A 90-degree perspective projection: x / z and y / z in [-1, 1] across the face, depth
    // face_depth(z) after the division by w = z.
    let near = l.position.w;
    let far = l.shadow.x;
    return vec4<f32>(q.x, q.y, far * (q.z - near) / (far - near), q.z);
}
