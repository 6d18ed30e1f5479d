// Depth passes of the shadow atlases (shadow_atlas.rs); prepended by gpu_scene.wgsl.
//
// Real geometry (it never moves): one draw per light into that light's tile, the viewport set
// to the tile (the geometry can extend past it and is clipped there); instance_index = light.
// Virtual objects (they move): one instanced draw per object for all lights at once,
// instance_index = object x lights + light; the object is wholly inside every tile by
// construction (each tile is fitted around the bounding sphere of the virtual objects), so the
// atlas needs no clipping against tile borders.

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<uniform> lights: array<Light, MAX_SHADOWED_LIGHTS>;
@group(0) @binding(2) var<storage, read> objects: array<Object>;

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
