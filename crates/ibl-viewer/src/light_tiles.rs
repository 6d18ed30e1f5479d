//! Light culling per screen tile for the real layer (`light_tiles.wgsl`): between the scene's
//! geometry and shading passes, a compute pass marks, for each 8 x 8 pixel tile, the lights
//! whose virtual-object shadow can reach the tile's real surfaces (a directional light against
//! its caster cells, `caster_cells.rs`; a point light against its cone about the objects'
//! vertices, `point_lights::shadow_cone`), and the new point lights that can light them. A real surface is
//! changed only by those lights (the composite's `with - without`, and a new light's whole
//! light), so the shading pass loops over them alone; a virtual object still takes every
//! light. The test is conservative: the frame is the same as with every light tested per
//! pixel (`tests/light_culling.rs` compares the two; the GPU-against-CPU checks in
//! `tests/against_cpu.rs` run through it).

use crate::gpu::GpuContext;
use crate::gpu_scene::{GpuScene, MAX_POINT_LIGHTS, MAX_SHADOWED_LIGHTS};

/// Screen tile side, pixels (`gpu_scene.wgsl`'s `LIGHT_TILE`).
pub const TILE: u32 = 8;
/// Mask words per tile for the directional lights: one bit per light (`gpu_scene.wgsl`'s
/// `LIGHT_WORDS`).
pub const WORDS: u32 = (MAX_SHADOWED_LIGHTS as u32).div_ceil(32);
/// Mask words per tile for the point lights, after the directional ones (`POINT_LIGHT_WORDS`).
pub const POINT_WORDS: u32 = (MAX_POINT_LIGHTS as u32).div_ceil(32);
/// Invocations per workgroup side (`@workgroup_size`), one per tile.
const GROUP: u32 = 8;
/// Fewest lights of either kind for which the culling runs: it costs about 13 ms a 640 x 480
/// frame on lavapipe, and one light tested per pixel costs less (the courtyard's sun,
/// BENCHMARKS.md).
pub const MIN_TILED_LIGHTS: u32 = 2;

/// Tiles across and down a frame of `size` pixels.
pub fn tile_counts(size: (u32, u32)) -> (u32, u32) {
    (size.0.div_ceil(TILE), size.1.div_ceil(TILE))
}

/// Bytes of the mask buffer of a frame of `size` pixels.
pub fn mask_bytes(size: (u32, u32)) -> u64 {
    let (x, y) = tile_counts(size);
    u64::from(x) * u64::from(y) * u64::from(WORDS + POINT_WORDS) * 4
}

/// The culling pipeline.
#[derive(Debug)]
pub struct LightTiles {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
}

impl LightTiles {
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext) -> LightTiles {
        let device = &gpu.device;
        let source = format!(
            "{}\n{}\n{}",
            include_str!("gpu_scene.wgsl"),
            include_str!("caster_cells.wgsl"),
            include_str!("light_tiles.wgsl")
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("light_tiles.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: compute,
            ty: wgpu::BindingType::Buffer {
                ty,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let samples = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: compute,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: true,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("light tiles"),
            entries: &[
                buffer(0, wgpu::BufferBindingType::Uniform),
                buffer(1, wgpu::BufferBindingType::Uniform),
                samples(2),
                samples(3),
                buffer(4, wgpu::BufferBindingType::Storage { read_only: false }),
                buffer(5, wgpu::BufferBindingType::Storage { read_only: true }),
                samples(6),
                buffer(7, wgpu::BufferBindingType::Uniform),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("light tiles"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("light tiles"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("cs_light_tiles"),
            compilation_options: Default::default(),
            cache: None,
        });
        LightTiles { pipeline, layout }
    }

    /// The bind group of a scene's lights and caster cells, the geometry pass's samples
    /// (`FrameTargets::gbuffer`) and the mask buffer (`FrameTargets::light_masks`).
    pub fn bind_group(
        &self,
        gpu: &GpuContext,
        scene: &GpuScene,
        gbuffer: &[wgpu::TextureView; 3],
        masks: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let view = wgpu::BindingResource::TextureView;
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("light tiles"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: scene.frame.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: scene.lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: view(&gbuffer[0]),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: view(&gbuffer[1]),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: masks.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: scene.caster_cells.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: view(&gbuffer[2]),
                },
                wgpu::BindGroupEntry {
                    binding: 7,
                    resource: scene.point_lights.as_entire_binding(),
                },
            ],
        })
    }

    /// Records the culling of a frame of `size` pixels.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        size: (u32, u32),
    ) {
        let (x, y) = tile_counts(size);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("light tiles"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(x.div_ceil(GROUP), y.div_ceil(GROUP), 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shader_constants_match() {
        // gpu_scene.wgsl, prepended to both the culling and the scene pass, declares them once.
        let shared = include_str!("gpu_scene.wgsl");
        assert!(shared.contains(&format!("const LIGHT_TILE: u32 = {TILE}u;")));
        assert!(shared.contains(&format!("const LIGHT_WORDS: u32 = {WORDS}u;")));
        assert!(shared.contains(&format!("const POINT_LIGHT_WORDS: u32 = {POINT_WORDS}u;")));
        let samples = crate::frame_targets::MSAA_SAMPLES;
        assert!(shared.contains(&format!("const GBUFFER_SAMPLES: u32 = {samples}u;")));
        let source = include_str!("light_tiles.wgsl");
        assert!(source.contains(&format!("@workgroup_size({GROUP}, {GROUP})")));
        assert_eq!(tile_counts((640, 480)), (80, 60));
        assert_eq!(tile_counts((641, 1)), (81, 1));
        assert_eq!(mask_bytes((8, 8)), u64::from(WORDS + POINT_WORDS) * 4);
    }
}
