//! Engine-ready environment maps from one probe, in one call ([`prefilter`]): the GGX specular
//! mip chain (cube and/or lat-long), the diffuse irradiance cube and the split-sum DFG table,
//! what Filament's cmgen, cmft and the Khronos glTF-IBL-Sampler make (their spherical harmonics
//! are `ibl-sh`'s; `ibl-pipeline::prefilter` adds them and writes the files).
//!
//! - **Specular** ([`crate::specular`]): level `m` of the chain has faces of `S / 2^m` and holds
//!   the radiance prefiltered at the roughness the chosen [`EngineTarget`] reads at that level;
//!   level 0 (roughness 0) is the source itself, resampled energy-conservingly to the cube.
//! - **Irradiance cube**: each texel is the exact irradiance at its centre direction divided by
//!   pi, `E(n) / pi` (CONVENTIONS section 4; [`ibl_core::irradiance_exact`]), which is the
//!   radiance of a white Lambertian surface: what engines multiply by the diffuse colour.
//! - **DFG** ([`crate::dfg`]).
//!
//! Everything is in memory; writing files is the caller's (`ibl-pipeline` writes KTX2/DDS
//! through `ibl-io`). The job reports progress as `(steps done, steps total)`, one step per output level
//! or table.

use ibl_core::{Image, Rgb};

use crate::cube::face_dir;
use crate::dfg::{Dfg, DfgLayout};
use crate::error::MappingError;
use crate::ggx::EngineTarget;
use crate::mapping::{CubeLayout, Mapping};
use crate::specular::{prefilter_cube, prefilter_latlong};
use crate::specular_source::SpecularSource;
use crate::{resample, split_cube_faces};

/// Largest specular face size (a 4096 chain is 400 M texels of f32 RGB in memory).
pub const MAX_FACE_SIZE: usize = 4096;
/// Largest lat-long chain width.
pub const MAX_LATLONG_WIDTH: usize = 8192;
/// Largest irradiance face size and DFG table size.
pub const MAX_TABLE_SIZE: usize = 1024;
/// Most GGX samples per texel.
pub const MAX_SAMPLES: usize = 1 << 16;

/// The specular chain to make.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularOptions {
    /// Face size of level 0 (a power of two).
    pub face_size: usize,
    /// Whose roughness-per-level convention (and level count) to follow.
    pub target: EngineTarget,
    /// GGX samples per texel.
    pub samples: usize,
    /// Also a lat-long chain with this level-0 width (`None`: cube only).
    pub latlong_width: Option<usize>,
}

/// The DFG table to make.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DfgOptions {
    /// Width and height in texels.
    pub size: usize,
    /// GGX samples per texel.
    pub samples: usize,
    /// Channel layout.
    pub layout: DfgLayout,
}

/// What [`prefilter`] makes; every part is optional.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PrefilterOptions {
    /// The specular chain.
    pub specular: Option<SpecularOptions>,
    /// Face size of the irradiance cube.
    pub irradiance_face: Option<usize>,
    /// The DFG table.
    pub dfg: Option<DfgOptions>,
}

/// A specular chain: per level, the roughness and the maps.
#[derive(Clone, Debug)]
pub struct SpecularChain {
    /// The roughness convention followed.
    pub target: EngineTarget,
    /// Perceptual roughness of each level.
    pub roughness: Vec<f64>,
    /// Six faces per level (GL orientation), level 0 first.
    pub cube: Vec<[Image<Rgb>; 6]>,
    /// Lat-long maps per level (empty unless asked for).
    pub latlong: Vec<Image<Rgb>>,
}

/// Everything [`prefilter`] made.
#[derive(Clone, Debug, Default)]
pub struct Prefiltered {
    /// The specular chain.
    pub specular: Option<SpecularChain>,
    /// The irradiance cube `E / pi` (six faces, GL orientation).
    pub irradiance: Option<[Image<Rgb>; 6]>,
    /// The DFG table.
    pub dfg: Option<Dfg>,
}

impl SpecularChain {
    /// Every cube level resampled (energy-conservingly) to a horizontal cross of `face`-pixel
    /// faces, left to right, level 0 first: a picture of the whole chain at one scale.
    pub fn contact_sheet(&self, face: usize) -> Result<Image<Rgb>, MappingError> {
        let cross = Mapping::Cube(CubeLayout::HorizontalCross);
        let (cw, ch) = (4 * face.max(1), 3 * face.max(1));
        let mut sheet = Image::filled(cw * self.cube.len().max(1), ch, Rgb::ZERO);
        for (m, faces) in self.cube.iter().enumerate() {
            let strip = crate::join_cube_faces(faces, CubeLayout::HorizontalStrip)?;
            let strip_mapping = Mapping::Cube(CubeLayout::HorizontalStrip);
            let cell = resample(
                &strip,
                strip_mapping,
                cross,
                cw,
                ch,
                glam::Mat3::IDENTITY,
                &|_, _| {},
            )?;
            for y in 0..ch {
                for (x, p) in cell.row(y).iter().enumerate() {
                    *sheet.get_mut(m * cw + x, y) = *p;
                }
            }
        }
        Ok(sheet)
    }
}

fn parameter(msg: String) -> MappingError {
    MappingError::Parameter(msg)
}

/// Checks options against the limits before any work.
pub fn check_options(options: &PrefilterOptions) -> Result<(), MappingError> {
    if let Some(s) = &options.specular {
        if !s.face_size.is_power_of_two() || s.face_size > MAX_FACE_SIZE {
            return Err(parameter(format!(
                "the face size must be a power of two up to {MAX_FACE_SIZE}, got {}",
                s.face_size
            )));
        }
        if s.samples == 0 || s.samples > MAX_SAMPLES {
            return Err(parameter(format!(
                "the sample count must be between 1 and {MAX_SAMPLES}, got {}",
                s.samples
            )));
        }
        if let Some(w) = s.latlong_width
            && !(2..=MAX_LATLONG_WIDTH).contains(&w)
        {
            return Err(parameter(format!(
                "the lat-long width must be between 2 and {MAX_LATLONG_WIDTH}, got {w}"
            )));
        }
    }
    if let Some(f) = options.irradiance_face
        && !(1..=MAX_TABLE_SIZE).contains(&f)
    {
        return Err(parameter(format!(
            "the irradiance face size must be between 1 and {MAX_TABLE_SIZE}, got {f}"
        )));
    }
    if let Some(d) = &options.dfg
        && (!(1..=MAX_TABLE_SIZE).contains(&d.size) || d.samples == 0 || d.samples > MAX_SAMPLES)
    {
        return Err(parameter(format!(
            "the DFG table must be 1 to {MAX_TABLE_SIZE} texels with 1 to {MAX_SAMPLES} samples, \
             got {} texels, {} samples",
            d.size, d.samples
        )));
    }
    Ok(())
}

/// The six faces of size `size` of any probe: split directly when it already is such a cube,
/// else resampled energy-conservingly.
fn cube_faces(
    probe: &Image<Rgb>,
    mapping: Mapping,
    size: usize,
) -> Result<[Image<Rgb>; 6], MappingError> {
    if let Mapping::Cube(layout) = mapping
        && layout.face_size(probe.width(), probe.height()) == Some(size)
    {
        return split_cube_faces(probe, layout);
    }
    let strip = Mapping::Cube(CubeLayout::HorizontalStrip);
    let img = resample(
        probe,
        mapping,
        strip,
        6 * size,
        size,
        glam::Mat3::IDENTITY,
        &|_, _| {},
    )?;
    split_cube_faces(&img, CubeLayout::HorizontalStrip)
}

/// The probe as a lat-long map (itself when it is one; otherwise resampled at the width that
/// keeps its resolution).
fn latlong_of(probe: &Image<Rgb>, mapping: Mapping) -> Result<Image<Rgb>, MappingError> {
    if mapping == Mapping::LatLong {
        return Ok(probe.clone());
    }
    let (w, h) = Mapping::LatLong.default_size_for(mapping, probe.width(), probe.height());
    resample(
        probe,
        mapping,
        Mapping::LatLong,
        w,
        h,
        glam::Mat3::IDENTITY,
        &|_, _| {},
    )
}

/// Makes the maps `options` asks for from `probe` (an image of `mapping`); see the module note.
/// Errors on options over the limits ([`check_options`]) or a probe that does not fit its
/// mapping. Deterministic whatever the thread count.
pub fn prefilter(
    probe: &Image<Rgb>,
    mapping: Mapping,
    options: &PrefilterOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Prefiltered, MappingError> {
    check_options(options)?;
    mapping.check_shape(probe.width(), probe.height())?;
    let levels = options
        .specular
        .map_or(0, |s| s.target.level_count(s.face_size));
    let latlong_levels = options
        .specular
        .and_then(|s| s.latlong_width)
        .map_or(0, |_| levels);
    let total = levels
        + latlong_levels
        + usize::from(options.irradiance_face.is_some())
        + usize::from(options.dfg.is_some());
    let mut done = 0;
    let mut step = || {
        done += 1;
        progress(done, total);
    };
    let needs_latlong = options.irradiance_face.is_some()
        || options.specular.is_some_and(|s| s.latlong_width.is_some());
    let latlong = needs_latlong
        .then(|| latlong_of(probe, mapping))
        .transpose()?;
    let mut out = Prefiltered::default();

    if let Some(s) = options.specular {
        let source = SpecularSource::new(&cube_faces(probe, mapping, s.face_size)?)?;
        let roughness: Vec<f64> = (0..levels)
            .map(|m| s.target.roughness(m, levels, s.face_size))
            .collect();
        let mut cube = Vec::with_capacity(levels);
        for (m, &r) in roughness.iter().enumerate() {
            cube.push(prefilter_cube(&source, s.face_size >> m, r, s.samples));
            step();
        }
        let mut ll_levels = Vec::new();
        if let (Some(w0), Some(ll)) = (s.latlong_width, &latlong) {
            for (m, &r) in roughness.iter().enumerate() {
                let w = (w0 >> m).max(2);
                ll_levels.push(if r <= 0.0 {
                    latlong_level0(ll, w)?
                } else {
                    prefilter_latlong(&source, w, r, s.samples)
                });
                step();
            }
        }
        out.specular = Some(SpecularChain {
            target: s.target,
            roughness,
            cube,
            latlong: ll_levels,
        });
    }
    if let (Some(f), Some(ll)) = (options.irradiance_face, &latlong) {
        out.irradiance = Some(irradiance_cube(ll, f));
        step();
    }
    if let Some(d) = options.dfg {
        out.dfg = Some(Dfg::new(d.size, d.samples, d.layout));
        step();
    }
    Ok(out)
}

/// Level 0 of a lat-long chain: the source itself when the width matches, else resampled.
fn latlong_level0(latlong: &Image<Rgb>, width: usize) -> Result<Image<Rgb>, MappingError> {
    if latlong.width() == width && latlong.height() == width / 2 {
        return Ok(latlong.clone());
    }
    let ll = Mapping::LatLong;
    resample(
        latlong,
        ll,
        ll,
        width,
        (width / 2).max(1),
        glam::Mat3::IDENTITY,
        &|_, _| {},
    )
}

/// The irradiance cube `E(n) / pi` of a lat-long probe, exact at every texel centre.
pub fn irradiance_cube(latlong: &Image<Rgb>, size: usize) -> [Image<Rgb>; 6] {
    let dirs: Vec<glam::DVec3> = (0..6 * size * size)
        .map(|k| {
            let (face, t) = (k / (size * size), k % (size * size));
            let sc = 2.0 * ((t % size) as f64 + 0.5) / size as f64 - 1.0;
            let tc = 2.0 * ((t / size) as f64 + 0.5) / size as f64 - 1.0;
            face_dir(face, sc, tc).normalize()
        })
        .collect();
    let e = ibl_core::irradiance_exact(latlong, &dirs);
    let inv_pi = 1.0 / std::f64::consts::PI;
    std::array::from_fn(|face| {
        let base = face * size * size;
        Image::from_fn_par(size, size, |i, j| {
            let v = e[base + j * size + i];
            Rgb::new(
                (v[0] * inv_pi) as f32,
                (v[1] * inv_pi) as f32,
                (v[2] * inv_pi) as f32,
            )
        })
    })
}
