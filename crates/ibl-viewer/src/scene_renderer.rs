//! One frame of the scene viewer, the same code in the window and headless: what is redrawn and
//! what is kept (see `shadow_atlas.rs`), the passes in order, and their timings.
//!
//! Per frame: the object transforms and the frame uniform are written; the real shadow atlas is
//! drawn when the lights changed or the objects left its region; the virtual atlas when the
//! lights changed or an object moved; then the scene pass and the display transform.

use glam::{Affine3A, Vec3};
use ibl_core::tonemap::Display;
use ibl_core::{Image, Rgb};
use ibl_scene::Background;
use ibl_scene::description::CompositeRule;

use crate::ViewerError;
use crate::display_pass::DisplayPass;
use crate::environment_maps::EnvironmentMaps;
use crate::frame_targets::FrameTargets;
use crate::gpu::GpuContext;
use crate::gpu_scene::{FrameUniform, GpuLight, GpuObject, GpuScene, mat3_columns, vec4};
use crate::lighting::SceneLighting;
use crate::scene_model::SceneModel;
use crate::scene_pass::{SceneBindGroups, ScenePass, ScenePassInputs, ShaderVariant};
use crate::shadow_atlas::{CasterPlacement, ShadowAtlases, ShadowDrawing};
use crate::textures::{HdrTexture, black_texture, upload_hdr};
use crate::timing::{PassTimer, PassTimes, SCENE_PASSES};
use crate::view_camera::OutputCamera;

/// Where the glossy lobe's light comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlossySource {
    /// The directional lights, with their shadows (as `ibl render` lights glossy surfaces).
    #[default]
    Lights,
    /// The probe prefiltered through the Phong mip chain (unshadowed reflections; the lights then
    /// light only the diffuse part).
    Environment,
}

/// How to draw a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneFrameSettings {
    /// The camera at the output size.
    pub camera: OutputCamera,
    /// Exposure and tone curve.
    pub display: Display,
    /// Glossy reflections.
    pub glossy: GlossySource,
    /// Background rays per pixel axis where the probe is minified or at a pole (elsewhere the
    /// pixel's area share of its texels, as `ibl render`); 1: the centre's texel alone.
    pub background_rays: u32,
    /// Shadow map side per light, texels (shrunk when the atlas would be too large).
    pub shadow_tile: u32,
    /// The selected object (tinted in the overlay).
    pub selected: Option<usize>,
    /// Real surfaces take only their screen tile's lights (`light_tiles.rs`; the same frame,
    /// faster); false tests every light on every real pixel (for checking the culling).
    pub light_culling: bool,
    /// Closed virtual objects draw only their light-facing triangles into the shadow maps
    /// (`shadow_atlas.rs`; the same atlas, faster); false draws every triangle (for checking).
    pub shadow_culling: bool,
    /// Virtual objects draw coarser copies of themselves into shadow maps whose texels are much
    /// larger than the difference (`shadow_lod.rs`; within half a texel, faster); false
    /// draws the full meshes (for checking).
    pub shadow_levels: bool,
}

/// What a frame did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameReport {
    /// Seconds of CPU work to record and submit the frame.
    pub cpu_seconds: f64,
    /// Whether the real atlas was drawn.
    pub drew_real_shadows: bool,
    /// Whether the virtual atlas was drawn.
    pub drew_virtual_shadows: bool,
}

/// The GPU state of a scene.
pub struct SceneRenderer {
    gpu_scene: GpuScene,
    environment: EnvironmentMaps,
    scene_pass: ScenePass,
    display: DisplayPass,
    shadows: ShadowAtlases,
    ambient: HdrTexture,
    photo: HdrTexture,
    /// The point lights' intensity maps (`point_lights::intensity_strip`).
    intensity: HdrTexture,
    targets: FrameTargets,
    bind_groups: SceneBindGroups,
    lighting: Option<SceneLighting>,
    gpu_lights: Vec<GpuLight>,
    /// Placements the virtual atlas was drawn with.
    drawn_placements: Option<Vec<Affine3A>>,
    /// Whether the lights changed since the atlases were drawn.
    lights_changed: bool,
    timer: Option<PassTimer>,
    /// The real geometry's plane when it is flat (`SceneGeometry::real_plane`; real geometry
    /// never changes after load, so it is found once).
    real_plane: Option<(Vec3, f32)>,
    /// The radius of the sphere of the objects' mean cross-section as a fraction of their
    /// bounding sphere's ([`occluding_fraction`]; found once, at load).
    occluding_fraction: f32,
    /// Pass times of the latest frame whose timestamps were read.
    pub last_pass_times: Option<PassTimes>,
    /// The photo background set by [`SceneRenderer::set_photo`] (a sequence's frame), at its
    /// own size, kept to be resampled again when the output size changes.
    photo_source: Option<Image<Rgb>>,
}

fn photo_texture(
    gpu: &GpuContext,
    model: &SceneModel,
    source: Option<&Image<Rgb>>,
    width: u32,
    height: u32,
) -> HdrTexture {
    let image = match (source, &model.scene.background) {
        (Some(photo), _) => resized(photo, width, height),
        (None, Background::Photo(_)) => {
            ibl_render::background::background_image(&model.scene, width, height)
        }
        (None, Background::Panorama) => {
            return black_texture(&gpu.device, &gpu.queue, "no photo");
        }
    };
    upload_hdr(
        &gpu.device,
        &gpu.queue,
        &image,
        "background photo",
        1,
        wgpu::TextureUsages::empty(),
    )
}

/// `photo` at `width x height` (area-weighted, as `ibl render` resamples a photo background).
fn resized(photo: &Image<Rgb>, width: u32, height: u32) -> Image<Rgb> {
    let (w, h) = (width as usize, height as usize);
    if (photo.width(), photo.height()) == (w, h) {
        photo.clone()
    } else {
        ibl_render::background::area_resize(photo, w, h)
    }
}

impl SceneRenderer {
    /// Uploads a scene for frames of `width x height`.
    pub fn new(
        gpu: &GpuContext,
        model: &SceneModel,
        width: u32,
        height: u32,
        shadow_tile: u32,
    ) -> Result<SceneRenderer, ViewerError> {
        let targets = FrameTargets::new(gpu, width, height)?;
        let gpu_scene = GpuScene::new(gpu, &model.geometry);
        let environment = EnvironmentMaps::new(gpu, &model.scene.probe.radiance);
        let scene_pass = ScenePass::new(gpu);
        let shadows = ShadowAtlases::new(gpu, 1, shadow_tile, false);
        let ambient = black_texture(&gpu.device, &gpu.queue, "no ambient");
        let photo = photo_texture(gpu, model, None, width, height);
        let intensity = black_texture(&gpu.device, &gpu.queue, "no point lights");
        let bind_group = scene_pass.bind_group(
            gpu,
            &gpu_scene,
            &ScenePassInputs {
                environment: &environment,
                ambient: &ambient,
                photo: &photo,
                shadows: &shadows,
                intensity: &intensity,
            },
        );
        let (shading_targets, light_tiles) =
            scene_pass.target_bind_groups(gpu, &gpu_scene, &targets);
        gpu.take_errors()?;
        Ok(SceneRenderer {
            gpu_scene,
            environment,
            scene_pass,
            display: DisplayPass::new(gpu),
            shadows,
            ambient,
            photo,
            intensity,
            targets,
            bind_groups: SceneBindGroups {
                scene: bind_group,
                shading_targets,
                light_tiles,
            },
            lighting: None,
            gpu_lights: Vec::new(),
            drawn_placements: None,
            lights_changed: true,
            timer: PassTimer::new(gpu, &SCENE_PASSES),
            real_plane: model.geometry.real_plane(),
            occluding_fraction: occluding_fraction(model),
            last_pass_times: None,
            photo_source: None,
        })
    }

    fn rebind(&mut self, gpu: &GpuContext) {
        self.bind_groups.scene = self.scene_pass.bind_group(
            gpu,
            &self.gpu_scene,
            &ScenePassInputs {
                environment: &self.environment,
                ambient: &self.ambient,
                photo: &self.photo,
                shadows: &self.shadows,
                intensity: &self.intensity,
            },
        );
    }

    /// The frame's textures.
    pub fn targets(&self) -> &FrameTargets {
        &self.targets
    }

    /// The lighting drawn now.
    pub fn lighting(&self) -> Option<&SceneLighting> {
        self.lighting.as_ref()
    }

    /// Shadow map side per light now, texels.
    pub fn shadow_tile(&self) -> u32 {
        self.shadows.tile()
    }

    /// Changes the output size (no-op when equal).
    pub fn resize(
        &mut self,
        gpu: &GpuContext,
        model: &SceneModel,
        width: u32,
        height: u32,
    ) -> Result<(), ViewerError> {
        if self.targets.size == (width, height) {
            return Ok(());
        }
        self.targets = FrameTargets::new(gpu, width, height)?;
        let (shading_targets, light_tiles) =
            self.scene_pass
                .target_bind_groups(gpu, &self.gpu_scene, &self.targets);
        self.bind_groups.shading_targets = shading_targets;
        self.bind_groups.light_tiles = light_tiles;
        self.photo = photo_texture(gpu, model, self.photo_source.as_ref(), width, height);
        self.rebind(gpu);
        Ok(())
    }

    /// Replaces the photo background by `photo` (a sequence's frame, linear radiance, any size
    /// of the camera's aspect: resampled to the output size). The scene's background must be a
    /// photo for the scene pass to show it.
    pub fn set_photo(&mut self, gpu: &GpuContext, model: &SceneModel, photo: Image<Rgb>) {
        let (w, h) = self.targets.size;
        self.photo = photo_texture(gpu, model, Some(&photo), w, h);
        self.photo_source = Some(photo);
        self.rebind(gpu);
    }

    /// Replaces the environment mirrors and glossy lobes reflect (a sequence's relit map,
    /// lat-long in the probe's frame) and rebuilds its mip chains.
    pub fn set_environment(&mut self, gpu: &GpuContext, probe: &Image<Rgb>) {
        self.environment = EnvironmentMaps::new(gpu, probe);
        self.rebind(gpu);
    }

    /// Replaces the lights (from the lighting worker).
    pub fn set_lighting(&mut self, gpu: &GpuContext, lighting: SceneLighting) {
        self.ambient = match &lighting.ambient {
            Some(map) => upload_hdr(
                &gpu.device,
                &gpu.queue,
                map,
                "ambient irradiance",
                1,
                wgpu::TextureUsages::empty(),
            ),
            None => black_texture(&gpu.device, &gpu.queue, "no ambient"),
        };
        self.intensity = if lighting.luminaires.is_empty() {
            black_texture(&gpu.device, &gpu.queue, "no point lights")
        } else {
            upload_hdr(
                &gpu.device,
                &gpu.queue,
                &crate::point_lights::intensity_strip(&lighting.luminaires),
                "point light intensities",
                1,
                wgpu::TextureUsages::empty(),
            )
        };
        self.lighting = Some(lighting);
        self.lights_changed = true;
        self.rebind(gpu);
    }

    /// Rewrites the materials (after an edit).
    pub fn update_materials(&self, gpu: &GpuContext, model: &SceneModel) {
        self.gpu_scene.write_materials(gpu, &model.materials());
    }

    fn frame_uniform(
        &self,
        model: &SceneModel,
        settings: &SceneFrameSettings,
        lights: u32,
        points: u32,
        occluder: Option<(Vec3, f32)>,
    ) -> FrameUniform {
        let c = &settings.camera;
        let (w, h) = self.targets.size;
        let probe = &model.scene.probe;
        let atlas = |a: &crate::shadow_atlas::Atlas| a.size();
        let (rw, rh) = atlas(&self.shadows.real);
        let (vw, vh) = atlas(&self.shadows.virtual_objects);
        FrameUniform {
            clip_from_world: c.clip_from_world().to_cols_array_2d(),
            world_from_camera: mat3_columns(c.world_from_camera),
            camera_position: vec4(c.position, 1.0),
            intrinsics: [
                c.focal_px.x,
                c.focal_px.y,
                c.principal_px.x,
                c.principal_px.y,
            ],
            probe_from_world: mat3_columns(probe.world_from_probe.transpose()),
            probe_position: vec4(probe.position, self.environment.scale),
            viewport: [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32],
            counts: [lights, points, 0, 0],
            environment: [
                self.environment.first_exponent,
                self.environment.levels as f32,
                self.photo.scale,
                self.ambient.scale,
            ],
            atlas: [rw as f32, rh as f32, vw as f32, vh as f32],
            real_plane: self
                .real_plane
                .map_or([0.0; 4], |(n, d)| [n.x, n.y, n.z, d]),
            occluder: occluder.map_or([0.0; 4], |(c, r)| [c.x, c.y, c.z, r]),
            occluder_albedo: match occluder {
                Some(_) => {
                    let a = objects_albedo(model);
                    [a.r, a.g, a.b, 0.0]
                }
                None => [0.0; 4],
            },
        }
    }

    /// The pipeline constants of a frame of `model` drawn with `settings`.
    fn shader_variant(
        &self,
        model: &SceneModel,
        settings: &SceneFrameSettings,
        lights: u32,
        points: u32,
        occlusion_gather: bool,
    ) -> ShaderVariant {
        ShaderVariant {
            tiled_lights: settings.light_culling
                && (lights >= crate::light_tiles::MIN_TILED_LIGHTS
                    || points >= crate::light_tiles::MIN_TILED_LIGHTS),
            soft_shadows: model.description.lighting.shadows == ibl_scene::ShadowKind::Soft,
            ratio_rule: model.description.render.composite == CompositeRule::Ratio,
            photo_background: matches!(model.scene.background, Background::Photo(_)),
            glossy_from_probe: settings.glossy == GlossySource::Environment,
            has_ambient: self.lighting.as_ref().is_some_and(|l| l.ambient.is_some()),
            background_rays: settings.background_rays.clamp(1, 8),
            flat_real_layer: self.real_plane.is_some(),
            point_lights: points > 0,
            occlusion_gather,
        }
    }

    /// The objects' occluding sphere now (centre, radius), when the lighting asks for the
    /// occlusion gather.
    fn occluder(&self, model: &SceneModel) -> Option<(Vec3, f32)> {
        if !self.lighting.as_ref().is_some_and(|l| l.occlusion_gather) {
            return None;
        }
        model
            .objects_sphere()
            .map(|(c, r)| (c, r * self.occluding_fraction))
    }

    /// Draws a frame of `model` and submits it.
    pub fn render(
        &mut self,
        gpu: &GpuContext,
        model: &SceneModel,
        settings: &SceneFrameSettings,
    ) -> FrameReport {
        let started = std::time::Instant::now();
        let count = self.lighting.as_ref().map_or(0, |l| l.lights.len()) as u32;
        let points = self.lighting.as_ref().map_or(0, |l| {
            l.luminaires.len().min(crate::gpu_scene::MAX_POINT_LIGHTS)
        }) as u32;
        // Atlases sized for the lights and the requested tile.
        let tiles = ShadowAtlases::tiles_for(count as usize, points as usize);
        let wanted = crate::light_space::AtlasLayout::new(
            tiles,
            settings.shadow_tile,
            gpu.max_texture_side(),
        );
        if wanted != self.shadows.real.layout
            || ShadowAtlases::virtual_format(points > 0) != self.shadows.virtual_objects.format
        {
            self.shadows = ShadowAtlases::new(gpu, tiles, settings.shadow_tile, points > 0);
            self.lights_changed = true;
            self.rebind(gpu);
        }
        let placements: Vec<Affine3A> = (0..model.object_count())
            .map(|i| model.world_from_load(i))
            .collect();
        let sphere = model
            .objects_sphere()
            .or_else(|| {
                model
                    .geometry
                    .real_bounds()
                    .map(|(lo, hi)| crate::light_space::bounding_sphere(lo, hi))
            })
            .unwrap_or((Vec3::ZERO, 1.0));
        let moved = self.drawn_placements.as_ref() != Some(&placements);
        let mut draw_real = self.lights_changed;
        if moved || self.lights_changed {
            let lights = self.lighting.as_ref().map_or(&[][..], |l| &l.lights[..]);
            let points = self
                .lighting
                .as_ref()
                .map_or(crate::point_lights::PointLightInputs::NONE, |l| {
                    l.point_light_inputs(self.intensity.scale)
                });
            // The objects' vertices now, for the point lights' shadow cones.
            let caster_points = if points.lights.is_empty() {
                Vec::new()
            } else {
                model.caster_points()
            };
            let (gpu_lights, region_moved) = self.shadows.fit(
                lights,
                &points,
                model.description.lighting.shadows,
                sphere,
                &caster_points,
                model.geometry.real_bounds(),
            );
            draw_real |= region_moved;
            self.gpu_scene.write_lights(gpu, &gpu_lights);
            self.gpu_scene
                .write_caster_cells(gpu, &gpu_lights, &placements);
            self.gpu_scene
                .write_point_lights(gpu, self.shadows.point_lights());
            self.gpu_lights = gpu_lights;
        }
        let mut objects = vec![GpuObject::new(Affine3A::IDENTITY, false, false)];
        objects.extend(
            placements
                .iter()
                .enumerate()
                .map(|(i, &m)| GpuObject::new(m, true, settings.selected == Some(i))),
        );
        self.gpu_scene.write_transforms(gpu, &objects);
        let occluder = self.occluder(model);
        let uniform = self.frame_uniform(model, settings, count, points, occluder);
        self.gpu_scene.write_frame(gpu, &uniform);
        let variant = self.shader_variant(model, settings, count, points, occluder.is_some());
        self.scene_pass.prepare(gpu, variant);

        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("scene frame"),
            });
        let draw_virtual = moved || self.lights_changed;
        let any_lights = count + points > 0;
        if draw_real && any_lights {
            let t = self.timer.as_mut().and_then(|t| t.writes(0));
            self.shadows
                .draw_real(gpu, &mut encoder, &self.gpu_scene, count, t);
        }
        if draw_virtual && any_lights {
            let t = self.timer.as_mut().and_then(|t| t.writes(1));
            let drawing = ShadowDrawing {
                culling: settings.shadow_culling,
                levels: settings.shadow_levels,
            };
            // The directional tiles' finest texel at the objects.
            let texel = self
                .gpu_lights
                .iter()
                .map(|l| l.virtual_extent[2])
                .fold(f32::INFINITY, f32::min);
            self.shadows.draw_virtual(
                gpu,
                &mut encoder,
                &self.gpu_scene,
                count,
                &caster_placements(model),
                drawing,
                texel,
                t,
            );
        }
        {
            let t = self.timer.as_mut().and_then(|t| t.split_writes(2));
            self.scene_pass.record(
                variant,
                &mut encoder,
                &self.targets,
                &self.gpu_scene,
                &self.bind_groups,
                t,
            );
        }
        clear_overlay(&mut encoder, &self.targets);
        {
            let t = self.timer.as_mut().and_then(|t| t.writes(3));
            self.display
                .record(gpu, &mut encoder, &self.targets, &settings.display, t);
        }
        if let Some(timer) = self.timer.as_mut() {
            timer.resolve(&mut encoder);
        }
        gpu.queue.submit([encoder.finish()]);
        if let Some(timer) = self.timer.as_mut() {
            timer.after_submit();
        }
        self.lights_changed = false;
        self.drawn_placements = Some(placements);
        FrameReport {
            cpu_seconds: started.elapsed().as_secs_f64(),
            drew_real_shadows: draw_real && any_lights,
            drew_virtual_shadows: draw_virtual && any_lights,
        }
    }

    /// The virtual objects' shadow atlas as last drawn, for checks: its width, height and
    /// texels, rows packed, in its format (`ShadowAtlases::virtual_format`: 2 bytes a texel at
    /// `Depth16Unorm`, 4 at `Depth32Float`).
    pub fn virtual_atlas_texels(
        &self,
        gpu: &GpuContext,
    ) -> Result<(u32, u32, Vec<u8>), ViewerError> {
        let atlas = &self.shadows.virtual_objects;
        let bytes = atlas.format.block_copy_size(None).unwrap_or(4);
        let texels = crate::frame_targets::read_texture(gpu, &atlas.texture, bytes)?;
        let (w, h) = atlas.size();
        Ok((w, h, texels))
    }

    /// Reads the pass times of the last frame (waiting for them with `wait`).
    pub fn read_pass_times(&mut self, gpu: &GpuContext, wait: bool) -> Option<PassTimes> {
        let times = self.timer.as_mut()?.read(gpu, wait)?;
        self.last_pass_times = Some(times.clone());
        Some(times)
    }
}

/// Every virtual object of `model` as the shadow passes see it now: the sign of its placement's
/// determinant, its largest stretch and its world box.
fn caster_placements(model: &SceneModel) -> Vec<CasterPlacement> {
    (0..model.object_count())
        .map(|i| {
            let m = model.world_from_load(i).matrix3;
            let (lo, hi) = model.object_box(i).unwrap_or((Vec3::ZERO, Vec3::ZERO));
            CasterPlacement {
                mirror: if m.determinant() < 0.0 { -1.0 } else { 1.0 },
                scale: m
                    .x_axis
                    .length()
                    .max(m.y_axis.length())
                    .max(m.z_axis.length()),
                bounds: (lo, hi),
            }
        })
        .collect()
}

/// Clears the overlay target (nothing is drawn over a scene frame yet).
fn clear_overlay(encoder: &mut wgpu::CommandEncoder, targets: &FrameTargets) {
    let _pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("overlay clear"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &targets.overlay_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
}

/// The radius of the sphere whose cross-section is the virtual objects' mean one, as a fraction
/// of their bounding sphere's radius at load: by Cauchy's formula a convex body's shadow,
/// averaged over all directions, is a quarter of its surface area `S`, so the sphere of radius
/// `sqrt(S / (4 pi))` casts the same mean shadow (a concave body's is somewhat smaller).
fn occluding_fraction(model: &SceneModel) -> f32 {
    let Some((_, radius)) = model.objects_sphere() else {
        return 0.0;
    };
    let area: f32 = model
        .geometry
        .objects
        .iter()
        .flat_map(|o| o.vertices.chunks_exact(3))
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|v| Vec3::from(v.position));
            0.5 * (b - a).cross(c - a).length()
        })
        .sum();
    ((area / (4.0 * std::f32::consts::PI)).sqrt() / radius).min(1.0)
}

/// The virtual objects' mean diffuse albedo over their materials (as edited).
fn objects_albedo(model: &SceneModel) -> Rgb {
    let materials = model.materials();
    let slots: Vec<Rgb> = model
        .geometry
        .objects
        .iter()
        .flat_map(|o| o.materials.clone())
        .map(|slot| materials[slot as usize].diffuse_albedo())
        .collect();
    if slots.is_empty() {
        return Rgb::ZERO;
    }
    slots.iter().fold(Rgb::ZERO, |a, &b| a + b) / slots.len() as f32
}
