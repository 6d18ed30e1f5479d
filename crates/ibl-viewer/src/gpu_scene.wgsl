// The scene's GPU data (gpu_scene.rs holds the Rust twins; keep both in step): every struct is
// made of 16-byte columns so that the WGSL and Rust layouts agree without padding rules.

struct Frame {
    // Clip space from world (reversed depth, far plane at infinity: view_camera.rs).
    clip_from_world: mat4x4<f32>,
    // Columns: camera right, up, back in world coordinates.
    world_from_camera: mat4x4<f32>,
    // xyz: the eye.
    camera_position: vec4<f32>,
    // fx, fy, cx, cy in output pixels.
    intrinsics: vec4<f32>,
    // Rotation from world to the probe frame (columns).
    probe_from_world: mat4x4<f32>,
    // xyz: the probe's centre; w: radiance = probe texel x w.
    probe_position: vec4<f32>,
    // width, height, 1 / width, 1 / height.
    viewport: vec4<f32>,
    // x: the light count; y, z, w: 0. The scene's other choices (composite rule, shadows,
    // background, glossy source, ambient, background rays) are pipeline constants
    // (scene_pass.rs, ShaderVariant).
    counts: vec4<u32>,
    // glossy chain: exponent of level 1, levels; photo scale; ambient scale.
    environment: vec4<f32>,
    // real atlas width, height; virtual atlas width, height (texels).
    atlas: vec4<f32>,
    // The flat real layer's plane (n, d), n . p + d = 0; zero when the real layer is not flat.
    real_plane: vec4<f32>,
    // The virtual objects as one sphere of their mean cross-section (centre, radius) and their
    // mean diffuse albedo (rgb): the occlusion gather on real surfaces (scene_pass.wgsl's
    // `occluder_change`); zero when the scene has none.
    occluder: vec4<f32>,
    occluder_albedo: vec4<f32>,
};

// Lights a frame draws (gpu_scene.rs's MAX_SHADOWED_LIGHTS): a uniform array of this many.
const MAX_SHADOWED_LIGHTS: u32 = 256u;

struct Light {
    // xyz: unit direction towards the light; w: tan of the half-angle of its cone.
    direction: vec4<f32>,
    // rgb: I = L A, the irradiance on a surface facing the light.
    irradiance: vec4<f32>,
    // World to (x, y, depth) of this light's tile in the real-geometry atlas.
    real_map: mat4x4<f32>,
    // The tile in atlas texture coordinates: u0, v0, du, dv.
    real_tile: vec4<f32>,
    // half extent and depth range of the tile (world units), world size of a texel, 0.
    real_extent: vec4<f32>,
    virtual_map: mat4x4<f32>,
    virtual_tile: vec4<f32>,
    virtual_extent: vec4<f32>,
};

// Goniometric point lights a frame draws (point_lights.rs's MAX_POINT_LIGHTS; a scene's
// [[luminaire]] entries, ibl_scene's MAX_LUMINAIRES).
const MAX_POINT_LIGHTS: u32 = 64u;

// A goniometric point light (Grosch 2005 section 4.2) and its omnidirectional shadow: six cube
// faces per atlas, each a 90-degree perspective view from the light along +-x, +-y, +-z
// (`face_coords`), drawn into its own atlas tile, and only where casters can be seen.
struct PointLight {
    // xyz: the light's world position; w: the faces' near plane distance (world units).
    position: vec4<f32>,
    // x: the faces' far plane distance; y: the face tile's side in texels; z, w: 0.
    shadow: vec4<f32>,
    // Columns: rotation from world to the light's photometric frame (ibl-light's
    // `light_from_world`).
    light_from_world: mat4x4<f32>,
    // Its intensity map's rows in the strip of maps (texture v0, dv); the strip's scale to
    // intensity (probe units per sr); 0.
    map: vec4<f32>,
    // The six faces' tiles in each atlas (u0, v0, du, dv); du = 0 where the face sees no caster.
    real_faces: array<vec4<f32>, 6>,
    virtual_faces: array<vec4<f32>, 6>,
    // The cone from the light holding every vertex of the virtual objects (point_lights.rs's
    // shadow_cone): xyz its axis times the nearest vertex's distance, w the cosine of its
    // half-angle; w = -2 where there is none (every direction: light_tiles.wgsl keeps the
    // light everywhere), w = 2 where there are no objects (nowhere).
    shadow_cone: vec4<f32>,
};

// Cube face `face` (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z) of vector v from a point light:
// (x, y, z) with z the distance along the face's axis, x and y across it (both written and
// read by this function only, so any fixed choice of axes works).
fn face_coords(v: vec3<f32>, face: u32) -> vec3<f32> {
    let axis = face / 2u;
    let s = select(1.0, -1.0, (face & 1u) == 1u);
    if axis == 0u {
        return vec3<f32>(v.y, v.z, s * v.x);
    }
    if axis == 1u {
        return vec3<f32>(v.z, v.x, s * v.y);
    }
    return vec3<f32>(v.x, v.y, s * v.z);
}

// The cube face a vector from a point light falls in: its largest component.
fn face_of(v: vec3<f32>) -> u32 {
    let a = abs(v);
    if a.x >= a.y && a.x >= a.z {
        return select(0u, 1u, v.x < 0.0);
    }
    if a.y >= a.z {
        return select(2u, 3u, v.y < 0.0);
    }
    return select(4u, 5u, v.z < 0.0);
}

// The depth a face stores for a point at distance z along its axis: the perspective projection's
// far (z - near) / ((far - near) z), 0 at the near plane and 1 at the far one.
fn face_depth(z: f32, near: f32, far: f32) -> f32 {
    return far * (z - near) / ((far - near) * z);
}

struct Object {
    // World from the frame the vertices were loaded in (identity for real geometry).
    world_from_load: mat4x4<f32>,
    // Inverse transpose of its upper 3 x 3 (normals).
    normal_from_load: mat4x4<f32>,
    // layer (0 real, 1 virtual), selected (0 or 1), 0, 0.
    flags: vec4<u32>,
};

struct Material {
    // rgb: diffuse albedo; w: kind (0 diffuse, 1 glossy, 2 mirror).
    albedo_kind: vec4<f32>,
    // rgb: specular (glossy) or mirror reflectance; w: Phong exponent.
    specular_exponent: vec4<f32>,
};

struct Vertex {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) material: u32,
};

// The world point at view depth `depth` (distance in front of the camera along its axis) seen
// through continuous pixel coordinates `pixel`: camera_ray's unnormalised direction, whose
// component along the axis is 1, times the depth (the scene pass's geometry pass stores it).
fn point_at_depth(pixel: vec2<f32>, depth: f32) -> vec3<f32> {
    let k = frame.intrinsics;
    let d = vec3<f32>((pixel.x - k.z) / k.x, -(pixel.y - k.w) / k.y, -1.0);
    return frame.camera_position.xyz + (frame.world_from_camera * vec4<f32>(d, 0.0)).xyz * depth;
}

// The inverse of scene_pass.wgsl's oct_encode: a unit vector from its octahedral code (the
// geometry pass's normals).
fn oct_decode(e: vec2<f32>) -> vec3<f32> {
    var n = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if n.z < 0.0 {
        n = vec3<f32>((1.0 - abs(n.yx)) * select(vec2<f32>(-1.0), vec2<f32>(1.0), n.xy >= vec2<f32>(0.0)), n.z);
    }
    return normalize(n);
}

// Samples per pixel of the scene's geometry pass (frame_targets.rs's MSAA_SAMPLES).
const GBUFFER_SAMPLES: u32 = 4u;

// The light masks of light_tiles.wgsl: per LIGHT_TILE x LIGHT_TILE pixel tile, LIGHT_WORDS
// words of one bit per directional light, then POINT_LIGHT_WORDS of one bit per point light
// (light_tiles.rs's TILE, WORDS and POINT_WORDS).
const LIGHT_TILE: u32 = 8u;
const LIGHT_WORDS: u32 = 8u;
const POINT_LIGHT_WORDS: u32 = 2u;

// The first mask word of screen tile `tile` in a frame `width` pixels wide.
fn light_mask_base(tile: vec2<u32>, width: u32) -> u32 {
    let tiles_x = (width + LIGHT_TILE - 1u) / LIGHT_TILE;
    return (tile.y * tiles_x + tile.x) * (LIGHT_WORDS + POINT_LIGHT_WORDS);
}
