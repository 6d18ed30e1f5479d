//! Closed virtual objects draw only their light-facing triangles into the virtual shadow atlas
//! (`shadow_atlas.rs`, `away_facing`), and the atlas is the one every triangle draws: a ray from
//! the light meets a closed surface first through a triangle facing the light, rasterised the
//! same way either way, so a texel keeps its depth bit for bit; except where a triangle facing
//! away lies a rounding error in front of the facing one at a silhouette edge (measured: 7 to
//! 13 texels in a million on the full bunny, up to 160 in a million on the coarser copies the
//! room's cube faces take, whose larger triangles graze more; by 6e-8 to 4.5e-4 of the depth
//! range, under the look-up's smallest bias, about 1e-3 of it). So: no texel nearer the light
//! with the culling than without, at most 1e-3 of the covered texels changed, none by more
//! than 1e-3, and the frames the same. A wrong choice of the side to cull (the projection's
//! handedness, a cube face's, the mesh's winding) keeps the far side's depths instead, and
//! changes most texels the object covers. Checked on the
//! directional lights' tiles (bunny-sky, 16-bit atlas), on point lights' cube faces of both
//! handedness (the room's 32 patches about the bunny; the umbrella luminaire over the bunny),
//! with the bunny as loaded and turned and moved.

mod common;

use ibl_viewer::headless::{self, HeadlessOptions};
use ibl_viewer::lighting::SceneLighting;
use ibl_viewer::scene_geometry::Closure;
use ibl_viewer::scene_renderer::{GlossySource, SceneFrameSettings, SceneRenderer};
use ibl_viewer::{SceneModel, gpu::GpuContext};

const SIZE: (u32, u32) = (320, 240);

/// The virtual atlas after one frame, with or without the culling: its texels and the bytes
/// of one.
fn atlas(
    gpu: &GpuContext,
    model: &SceneModel,
    lighting: &SceneLighting,
    culling: bool,
) -> (Vec<u8>, usize) {
    let tile = HeadlessOptions::default().shadow_tile;
    let mut renderer = SceneRenderer::new(gpu, model, SIZE.0, SIZE.1, tile).expect("a renderer");
    renderer.set_lighting(gpu, lighting.clone());
    let settings = SceneFrameSettings {
        camera: headless::scene_camera(model, SIZE.0, SIZE.1),
        display: Default::default(),
        glossy: GlossySource::Lights,
        background_rays: 4,
        shadow_tile: tile,
        selected: None,
        light_culling: true,
        shadow_culling: culling,
        shadow_levels: true,
    };
    renderer.render(gpu, model, &settings);
    let (w, h, texels) = renderer.virtual_atlas_texels(gpu).expect("reads the atlas");
    let bytes = texels.len() / (w as usize * h as usize);
    (texels, bytes)
}

/// The atlases with and without the culling agree texel for texel, and the object covers some.
fn same_atlas(name: &str, gpu: &GpuContext, model: &SceneModel, lighting: &SceneLighting) {
    assert_eq!(
        Closure::of(&model.geometry.objects[0].vertices),
        Closure::Outward,
        "{name}: the bunny is closed"
    );
    let (culled, _) = atlas(gpu, model, lighting, true);
    let (every, bytes) = atlas(gpu, model, lighting, false);
    assert_eq!(culled.len(), every.len());
    let depth = |t: &[u8]| {
        if bytes == 2 {
            f32::from(u16::from_le_bytes([t[0], t[1]])) / 65535.0
        } else {
            f32::from_le_bytes([t[0], t[1], t[2], t[3]])
        }
    };
    let (mut covered, mut differ, mut nearer, mut largest) = (0usize, 0usize, 0usize, 0.0f32);
    for (a, b) in culled.chunks_exact(bytes).zip(every.chunks_exact(bytes)) {
        let (a, b) = (depth(a), depth(b));
        covered += usize::from(b < 1.0);
        if a != b {
            differ += 1;
            nearer += usize::from(a < b);
            largest = largest.max(a - b);
        }
    }
    eprintln!(
        "{name}: {covered} texels hold the object; {differ} differ with the culling, by at \
         most {largest:e}"
    );
    assert!(covered > 1000, "{name}: the object is in the atlas");
    assert_eq!(
        nearer, 0,
        "{name}: culling triangles brought {nearer} texels nearer"
    );
    assert!(
        differ as f64 <= 1e-3 * covered as f64,
        "{name}: the culled atlas differs on {differ} of {covered} texels"
    );
    assert!(largest <= 1e-3, "{name}: a texel moved by {largest}");
    // The frames.
    let frame = |shadow_culling| {
        let options = HeadlessOptions {
            size: SIZE,
            shadow_culling,
            ..Default::default()
        };
        common::radiance(gpu, model, lighting, &options)
    };
    let (with, without) = (frame(true), frame(false));
    let changed = with
        .pixels()
        .iter()
        .zip(without.pixels())
        .filter(|(a, b)| a != b)
        .count();
    eprintln!("{name}: {changed} pixels of the frame changed");
    assert_eq!(changed, 0, "{name}: the frame changed");
}

#[test]
fn directional_tiles_keep_their_depths() {
    let Some(gpu) = common::gpu_or_skip("directional_tiles_keep_their_depths") else {
        return;
    };
    let (mut model, lighting) = common::example_scene("bunny-sky");
    common::as_loaded_and_moved("bunny-sky", &mut model, |name, model| {
        same_atlas(name, &gpu, model, &lighting)
    });
}

#[test]
fn a_luminaires_cube_faces_keep_their_depths() {
    let Some(gpu) = common::gpu_or_skip("a_luminaires_cube_faces_keep_their_depths") else {
        return;
    };
    let (mut model, lighting) = common::example_scene("lamp/bunny-lamp");
    assert!(!lighting.luminaires.is_empty());
    common::as_loaded_and_moved("bunny-lamp", &mut model, |name, model| {
        same_atlas(name, &gpu, model, &lighting)
    });
}

#[test]
fn the_rooms_patch_faces_keep_their_depths() {
    let Some(gpu) = common::gpu_or_skip("the_rooms_patch_faces_keep_their_depths") else {
        return;
    };
    let mut live = common::room_with_bunny();
    assert!(live.lighting.luminaires.len() >= 32);
    let lighting = live.lighting.clone();
    common::as_loaded_and_moved("the room", &mut live.model, |name, model| {
        same_atlas(name, &gpu, model, &lighting)
    });
}
