//! The viewer's sequence mode (Jensen, Andersen & Madsen 2006): a scene file with an `[outdoor]`
//! table is played frame by frame. Each frame goes through the library's per-frame loop
//! (`ibl_pipeline::outdoor_sequence`, `ibl_outdoor::OutdoorSystem::process`: the SPA sun, the
//! robust fit of `P_d` and `P_a` from the marked diffuse surfaces, the relit environment map,
//! the volume refresh), exactly as `ibl outdoor` runs it, and becomes what the scene renderer
//! draws:
//!
//! - the **background**: the frame itself (the scene's photo background);
//! - the **sun**: one shadowed directional light of irradiance `pi P_d` from the SPA direction, a
//!   cone of the sun's disc (`ibl_outdoor::composite::sun_light`, the CPU composite's light);
//! - the **ambient**: the world-frame irradiance `E(n)` the objects receive from everything but
//!   the sun. With an irradiance volume (`[outdoor] volume_spacing_m`) it is the volume refreshed
//!   this frame, interpolated at the centre of the objects' bounding sphere (the paper's
//!   design: the volume holds the sky as the buildings let it through and the light they
//!   reflect); without one it is the tracked sky shape times `P_a` in SH, as the CPU composite's
//!   ambient (`ibl_outdoor::composite::sky_ambient`), there seen through occlusion rays and here
//!   unoccluded; or, on request ([`SequencePlayer::sky_lights`]), the sky split by median cut
//!   into N lights, each with its own shadow map (Madsen & Laursen 2006's lights applied to
//!   the estimated sky): the objects' sky shadow on the ground and on themselves, which the
//!   unshadowed ambient leaves out;
//! - the **environment** mirrors and glossy lobes reflect: the relit map (the sun left out).
//!
//! Shadows both ways come from the scene pass's differential composite with the model as the
//! real layer: a real surface the buildings already shade has no sun in either pass, so the
//! object casts no second sun shadow there (the paper's rule, by construction).
//!
//! What the viewer leaves out that the CPU composite has: with the ambient, the objects'
//! occlusion of it (their sky shadow on the ground and on themselves; the sky lights bring it
//! back as N shadows), and the sun's penumbra beyond the shadow map's filter. `tests/sequence.rs` measures the difference on the bundled courtyard.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{DMat3, Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_extract::{ExtractOptions, ModelSpec, build_model};
use ibl_light::Method;
use ibl_outdoor::composite::{sky_ambient, sun_light};
use ibl_outdoor::{CompositeSettings, FrameResult, OutdoorSystem};
use ibl_pipeline::outdoor_sequence::OutdoorSequence;
use ibl_render::lighting::LightList;
use ibl_scene::ShadowKind;
use ibl_sh::{LeakControl, VolumeLayer};
use serde::Serialize;

use crate::ViewerError;
use crate::gpu::GpuContext;
use crate::lighting::{IRRADIANCE_MAP_WIDTH, SceneLighting, irradiance_map};
use crate::point_lights::PointLightRole;
use crate::scene_model::SceneModel;
use crate::scene_renderer::SceneRenderer;

/// Lat-long size the sky is split into lights from (median cut needs no more: each light is a
/// region of it).
const SKY_MAP_SIZE: (usize, usize) = (128, 64);

/// One played frame: which it was and what was estimated.
#[derive(Clone, Debug, Serialize)]
pub struct PlayedFrame {
    /// Index in the sequence.
    pub index: usize,
    /// Its name (the file's stem, or `frame_NNNNN` of a video).
    pub name: String,
    /// Local time `YYYY-MM-DDTHH:MM:SS`.
    pub local_time: String,
    /// Local time of day, hours.
    pub hour: f64,
    /// The estimate, the sun light and the sky condition (`ibl outdoor`'s per-frame result).
    pub result: FrameResult,
    /// Seconds reading the frame.
    pub read_seconds: f64,
    /// Seconds of estimation, relighting and volume refresh.
    pub estimate_seconds: f64,
    /// Seconds making the renderer's lights and ambient from the estimate.
    pub lighting_seconds: f64,
}

/// What one step gives the renderer.
pub struct SequenceStep {
    /// The frame played.
    pub frame: PlayedFrame,
    /// Its image (the background).
    pub image: Image<Rgb>,
    /// The sun and the ambient.
    pub lighting: SceneLighting,
}

impl SequenceStep {
    /// Hands the step to `renderer` (module notes): its image as the photo background, its sun
    /// and ambient as the lights, and `relit` (the relit map after it) as the environment when
    /// an object of `model` reflects it; returns the frame played.
    pub fn show(
        self,
        gpu: &GpuContext,
        model: &SceneModel,
        renderer: &mut SceneRenderer,
        relit: &Image<Rgb>,
    ) -> PlayedFrame {
        renderer.set_photo(gpu, model, self.image);
        renderer.set_lighting(gpu, self.lighting);
        if model.reflects_environment() {
            renderer.set_environment(gpu, relit);
        }
        self.frame
    }
}

/// An outdoor sequence being played (see the module notes).
pub struct SequencePlayer {
    sequence: OutdoorSequence,
    system: OutdoorSystem,
    /// Where the ambient is read from the volume: the objects' bounding-sphere centre.
    ambient_point: Option<Vec3>,
    ambient_bands: usize,
    /// The sky as this many shadowed lights (median cut of the sky, Madsen & Laursen 2006)
    /// instead of the unshadowed ambient: the objects' sky shadow on the ground and on
    /// themselves, at the cost of a shadow map per light; 0 keeps the ambient.
    pub sky_lights: usize,
    /// Seconds the offline step took.
    pub setup_seconds: f64,
    /// Frames in the sequence (`None` for a video).
    pub frame_count: Option<usize>,
}

/// A sequence opened and checked, before its offline step.
pub struct PreparedSequence {
    sequence: OutdoorSequence,
    objects_centre: Option<Vec3>,
}

impl PreparedSequence {
    /// Frames in the sequence (`None` for a video).
    pub fn frame_count(&self) -> Option<usize> {
        self.sequence.frame_count()
    }

    /// The offline step (Jensen, Andersen & Madsen 2006 section 4; about a second and a half
    /// for the bundled courtyard): the player, ready for its first frame.
    pub fn start(self) -> Result<SequencePlayer, ViewerError> {
        let started = Instant::now();
        let system = self.sequence.system()?;
        Ok(SequencePlayer {
            frame_count: self.sequence.frame_count(),
            setup_seconds: started.elapsed().as_secs_f64(),
            ambient_point: self.objects_centre,
            ambient_bands: CompositeSettings::default().ambient_bands,
            sky_lights: 0,
            sequence: self.sequence,
            system,
        })
    }
}

impl SequencePlayer {
    /// Opens a scene's sequence and runs the offline step (seconds): [`SequencePlayer::prepare`]
    /// then [`PreparedSequence::start`].
    pub fn open(
        scene: &Path,
        objects_centre: Option<Vec3>,
        outputs: &[&Path],
    ) -> Result<SequencePlayer, ViewerError> {
        SequencePlayer::prepare(scene, objects_centre, outputs)?.start()
    }

    /// Opens a scene's sequence and checks it (the scene, the mask, the frames and their
    /// times), without the offline step; `objects_centre` is where the ambient is read from the
    /// volume; `outputs` (the files the caller will write) are refused when one is an input of
    /// the sequence.
    pub fn prepare(
        scene: &Path,
        objects_centre: Option<Vec3>,
        outputs: &[&Path],
    ) -> Result<PreparedSequence, ViewerError> {
        let sequence = OutdoorSequence::open(scene, None)?;
        let inputs = sequence.inputs();
        let inputs: Vec<&Path> = inputs.iter().map(PathBuf::as_path).collect();
        for output in outputs {
            ibl_io::ensure_output_is_not_input(output, &inputs)?;
        }
        Ok(PreparedSequence {
            sequence,
            objects_centre,
        })
    }

    /// Whether `scene`'s description has an `[outdoor]` table (it is played as a sequence).
    pub fn is_sequence(description: &ibl_scene::SceneDescription) -> bool {
        description.outdoor.is_some()
    }

    /// The relit environment map of the last frame (probe frame, lat-long, the sun left out).
    pub fn relit_map(&self) -> &Image<Rgb> {
        self.system.relit_map()
    }

    /// Plays the next daylight frame, from the first again after the last (night frames are
    /// passed over).
    pub fn step(&mut self) -> Result<SequenceStep, ViewerError> {
        let mut rewound = false;
        loop {
            let started = Instant::now();
            let Some(next) = self.sequence.next_frame()? else {
                if rewound {
                    return Err(ViewerError::Parameter(format!(
                        "{}: no frame in daylight",
                        self.sequence.source.display()
                    )));
                }
                self.sequence.rewind()?;
                rewound = true;
                continue;
            };
            let Some(image) = next.image else {
                continue;
            };
            let read_seconds = started.elapsed().as_secs_f64();
            let started = Instant::now();
            let result = self
                .system
                .process(next.time, &image)
                .map_err(|e| ViewerError::Parameter(format!("{}: {e}", next.file.display())))?;
            let estimate_seconds = started.elapsed().as_secs_f64();
            let started = Instant::now();
            let lighting = self.lighting(&result)?;
            return Ok(SequenceStep {
                frame: PlayedFrame {
                    index: next.index,
                    name: next.name,
                    local_time: next.local_time,
                    hour: next.hour,
                    result,
                    read_seconds,
                    estimate_seconds,
                    lighting_seconds: started.elapsed().as_secs_f64(),
                },
                image,
                lighting,
            });
        }
    }

    /// The renderer's lights for a frame's result (module notes).
    fn lighting(&self, result: &FrameResult) -> Result<SceneLighting, ViewerError> {
        let numerical = |e: String| ViewerError::Lighting(e);
        let mut lights: Vec<_> = sun_light(&result.sun).into_iter().collect();
        let sun = if lights.is_empty() { "no sun" } else { "sun" };
        let sky = format!("{:?}", result.sky_condition).to_lowercase();
        if self.sky_lights > 0 {
            let set = self.sky_light_set(result)?;
            let list = LightList::from_set(&set, DMat3::IDENTITY, ShadowKind::Soft);
            lights.extend(list.lights);
            return Ok(SceneLighting {
                lights,
                luminaires: Vec::new(),
                luminaire_role: PointLightRole::NEW,
                luminaire_near_field_m2: Vec::new(),
                occlusion_gather: false,
                ambient: None,
                summary: format!(
                    "{sun} + the sky as {} shadowed median-cut lights, {sky} sky",
                    self.sky_lights
                ),
            });
        }
        let volume_ambient = match (self.system.volume(), self.ambient_point) {
            (Some(volume), Some(point)) => volume
                .sample(point, VolumeLayer::AllLight, LeakControl::ValidOnly)
                .map_err(|e| numerical(e.to_string()))?,
            _ => None,
        };
        let (ambient, source) = match volume_ambient {
            Some(key) => {
                let (w, h) = (IRRADIANCE_MAP_WIDTH, IRRADIANCE_MAP_WIDTH / 2);
                let grid = LatLong::new(w, h);
                let map = Image::from_fn_par(w, h, |i, j| {
                    let e = key.irradiance(grid.pixel_dir64(i, j).as_vec3());
                    Rgb::new(e[0].max(0.0), e[1].max(0.0), e[2].max(0.0))
                });
                (map, "volume ambient".to_string())
            }
            None => {
                let lighting = self
                    .system
                    .frame_lighting(result)
                    .map_err(|e| numerical(e.to_string()))?;
                let sh = sky_ambient(lighting.sky_shape, lighting.sky, self.ambient_bands)
                    .map_err(|e| numerical(e.to_string()))?;
                let irradiance = sh.irradiance(ibl_sh::Window::None);
                (
                    irradiance_map(&irradiance, IRRADIANCE_MAP_WIDTH),
                    format!("SH{} sky ambient", self.ambient_bands * self.ambient_bands),
                )
            }
        };
        Ok(SceneLighting {
            lights,
            luminaires: Vec::new(),
            luminaire_role: PointLightRole::NEW,
            luminaire_near_field_m2: Vec::new(),
            occlusion_gather: false,
            ambient: Some(ambient),
            summary: format!("{sun} + {source}, {sky} sky"),
        })
    }

    /// The frame's sky (the tracked shape times `P_a`, world frame, the sun left out) as
    /// [`SequencePlayer::sky_lights`] median-cut lights (their irradiance sums to the sky's).
    fn sky_light_set(&self, result: &FrameResult) -> Result<ibl_light::LightSet, ViewerError> {
        let lighting = self
            .system
            .frame_lighting(result)
            .map_err(|e| ViewerError::Lighting(e.to_string()))?;
        let (w, h) = SKY_MAP_SIZE;
        let mut map = lighting.sky_shape.latlong(w, h, Mat3::IDENTITY);
        for px in map.pixels_mut() {
            *px = *px * lighting.sky;
        }
        let spec = ModelSpec::from(Method::MedianCut);
        let (model, _) = build_model(&map, spec, self.sky_lights, &ExtractOptions::default())
            .map_err(|e| ViewerError::Parameter(format!("sky lights: {e}")))?;
        model
            .lights()
            .cloned()
            .ok_or_else(|| ViewerError::Lighting("median cut made no sky lights".into()))
    }
}
