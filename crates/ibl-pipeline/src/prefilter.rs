//! Engine-ready environment maps (`ibl prefilter`; what Filament's cmgen, cmft and the Khronos
//! glTF-IBL-Sampler make): the GGX-prefiltered specular mip chain as a KTX2 or DDS cube map (and
//! optionally a lat-long chain), the irradiance cube `E / pi`, spherical harmonics in any tool's
//! convention, and the split-sum DFG table. Every output path is checked before any work; the
//! maps are made in memory by [`ibl_mapping::prefilter()`], the SH by [`ibl_sh::project_latlong`],
//! and each file is written atomically through `ibl-io`. `docs/PREFILTER.md` has the
//! conventions and the roughness each engine expects at each level.

use std::path::{Path, PathBuf};
use std::time::Instant;

use ibl_core::tonemap::{Display, ToneCurve, auto_exposure_stops};
use ibl_core::{Image, Rgb};
use ibl_io::sh_file::{SH_CONVENTION, SH_FORMAT};
use ibl_io::{ImageFormat, ShFile, ShFileFormat, ShQuantity, TexelFormat, Texture, WriteOptions};
use ibl_light::ProbeRef;
use ibl_mapping::{CubeLayout, DfgOptions, Mapping, PrefilterOptions, SpecularOptions};
/// The choices a front end parses: the roughness convention and the DFG channel layout.
pub use ibl_mapping::{DfgLayout, EngineTarget};
use serde::Serialize;

use crate::envmap_files::{self, EnvMapping};
use crate::error::{Context, PipelineError, Result};
use crate::progress::{self, Progress};

/// DFG samples per texel (1024, as Filament's cmgen; the error is under 3e-3).
pub const DFG_SAMPLES: usize = 1024;

/// What to make and where to write it; every output is optional, at least one is needed.
#[derive(Clone, Debug, PartialEq)]
pub struct PrefilterJob {
    /// The probe (any mapping; a KTX2/DDS cube is a cube map). Not needed for the DFG alone.
    pub probe: Option<PathBuf>,
    /// Mapping of the probe (`None`: from its shape).
    pub mapping: Option<EnvMapping>,
    /// Whose roughness-per-level convention (and level count) to follow.
    pub target: EngineTarget,
    /// Face size of level 0 (a power of two).
    pub face_size: usize,
    /// GGX samples per texel.
    pub samples: usize,
    /// Texel format of the KTX2/DDS outputs (3 channels: rgba16f, rgba32f, rgb9e5).
    pub texel: TexelFormat,
    /// The specular chain as a cube map (`.ktx2`/`.dds`).
    pub output: Option<PathBuf>,
    /// The specular chain as a lat-long 2D texture with mips (`.ktx2`/`.dds`).
    pub latlong: Option<PathBuf>,
    /// Width of the lat-long chain's level 0 (`None`: 4 x the face size).
    pub latlong_width: Option<usize>,
    /// The irradiance cube `E / pi` (a texture cube, or an image file as a horizontal cross).
    pub irradiance: Option<PathBuf>,
    /// Face size of the irradiance cube.
    pub irradiance_size: usize,
    /// Spherical harmonics of the probe, in `sh_format`.
    pub sh: Option<PathBuf>,
    /// SH convention of the SH file.
    pub sh_format: ShFileFormat,
    /// SH bands (3 for every format but json).
    pub bands: usize,
    /// The split-sum DFG table (texture as RG; EXR/PFM/HDR/PNG as RGB with blue 0).
    pub dfg: Option<PathBuf>,
    /// DFG table size in texels.
    pub dfg_size: usize,
    /// DFG channel layout.
    pub dfg_layout: DfgLayout,
    /// A tone-mapped PNG of the whole specular chain, one cube cross per level.
    pub preview: Option<PathBuf>,
}

/// What a run did (the JSON of `ibl prefilter --json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PrefilterSummary {
    /// The probe, as given.
    pub probe: Option<String>,
    /// The roughness convention (when a specular chain was made).
    pub target: Option<&'static str>,
    /// Face size of level 0 (specular chain only).
    pub face_size: Option<usize>,
    /// GGX samples per texel (specular chain only).
    pub samples: Option<usize>,
    /// Texel format of the textures.
    pub format: &'static str,
    /// Perceptual roughness of each level.
    pub roughness: Vec<f64>,
    /// Seconds to read, compute and write.
    pub seconds: f64,
    /// Files written.
    pub outputs: Vec<String>,
}

const TEXTURES: [ImageFormat; 2] = [ImageFormat::Ktx2, ImageFormat::Dds];
const IMAGES: [ImageFormat; 6] = [
    ImageFormat::Ktx2,
    ImageFormat::Dds,
    ImageFormat::Exr,
    ImageFormat::Hdr,
    ImageFormat::Pfm,
    ImageFormat::Png,
];

/// Refuses an output whose folder does not exist, that is an input, or whose extension is not
/// one of `allowed` (`None`: any, e.g. an SH text file).
fn check_output(path: &Path, inputs: &[&Path], allowed: Option<&[ImageFormat]>) -> Result<()> {
    if let Some(allowed) = allowed
        && !ImageFormat::from_path(path).is_some_and(|f| allowed.contains(&f))
    {
        let names: Vec<_> = allowed.iter().map(|f| format!(".{}", f.name())).collect();
        return Err(PipelineError::parameter(format!(
            "{}: unsupported output format here (use {})",
            path.display(),
            names.join(", ")
        )));
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(PipelineError::parameter(format!(
            "{}: the folder {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    ibl_io::ensure_output_is_not_input(path, inputs)?;
    Ok(())
}

impl PrefilterJob {
    fn wants_probe(&self) -> bool {
        self.output.is_some()
            || self.latlong.is_some()
            || self.irradiance.is_some()
            || self.sh.is_some()
            || self.preview.is_some()
    }

    /// The in-memory maps to make.
    fn options(&self) -> PrefilterOptions {
        let specular = self.output.is_some() || self.latlong.is_some() || self.preview.is_some();
        PrefilterOptions {
            specular: specular.then_some(SpecularOptions {
                face_size: self.face_size,
                target: self.target,
                samples: self.samples,
                latlong_width: self
                    .latlong
                    .as_ref()
                    .map(|_| self.latlong_width.unwrap_or(4 * self.face_size)),
            }),
            irradiance_face: self.irradiance.as_ref().map(|_| self.irradiance_size),
            dfg: self.dfg.as_ref().map(|_| DfgOptions {
                size: self.dfg_size,
                samples: DFG_SAMPLES,
                layout: self.dfg_layout,
            }),
        }
    }

    /// Every check that needs no work: outputs named, paths writable and distinct, options in
    /// range.
    fn check(&self) -> Result<()> {
        if self.texel.channels() != 3 {
            return Err(PipelineError::parameter(format!(
                "--format {}: the maps need an RGB format (rgba16f, rgba32f, rgb9e5)",
                self.texel.name()
            )));
        }
        if self.sh.is_some() && self.sh_format != ShFileFormat::Json && self.bands != 3 {
            return Err(PipelineError::parameter(format!(
                "--sh-format {} holds 3 bands; use --bands 3 or --sh-format json",
                self.sh_format.name()
            )));
        }
        if self.sh.is_some() && !(1..=ibl_sh::MAX_BANDS).contains(&self.bands) {
            return Err(PipelineError::parameter(format!(
                "--bands must be between 1 and {}",
                ibl_sh::MAX_BANDS
            )));
        }
        if !self.wants_probe() && self.dfg.is_none() {
            return Err(PipelineError::parameter(
                "say what to write: -o FILE (specular cube), --latlong, --irradiance, --sh, --dfg \
                 or --preview",
            ));
        }
        if self.wants_probe() && self.probe.is_none() {
            return Err(PipelineError::parameter(
                "these outputs need a probe: ibl prefilter PROBE ...",
            ));
        }
        if self.latlong_width.is_some() && self.latlong.is_none() {
            return Err(PipelineError::parameter(
                "--latlong-width needs --latlong FILE",
            ));
        }
        let inputs: Vec<&Path> = self.probe.iter().map(PathBuf::as_path).collect();
        let mut named: Vec<&Path> = Vec::new();
        for (path, allowed) in [
            (&self.output, Some(&TEXTURES[..])),
            (&self.latlong, Some(&TEXTURES[..])),
            (&self.irradiance, Some(&IMAGES[..])),
            (&self.dfg, Some(&IMAGES[..])),
            (&self.preview, Some(&[ImageFormat::Png][..])),
            (&self.sh, None),
        ] {
            if let Some(p) = path {
                check_output(p, &inputs, allowed)?;
                if named.contains(&p.as_path()) {
                    return Err(PipelineError::parameter(format!(
                        "{} is named twice",
                        p.display()
                    )));
                }
                named.push(p);
            }
        }
        ibl_mapping::prefilter::check_options(&self.options())?;
        Ok(())
    }
}

/// Runs the job: checks everything first, reads the probe, makes the maps, writes the files.
pub fn prefilter(job: &PrefilterJob, progress: &dyn Progress) -> Result<PrefilterSummary> {
    job.check()?;
    let start = Instant::now();
    let options = job.options();
    let (image, mapping) = match &job.probe {
        Some(path) if job.wants_probe() => {
            let env = envmap_files::load(path, job.mapping)?;
            envmap_files::note_clamped(&env, progress);
            (env.image, env.mapping)
        }
        // Only the DFG table: no probe is read.
        _ => (Image::filled(2, 1, Rgb::ZERO), Mapping::LatLong),
    };
    let label = job
        .probe
        .as_ref()
        .map_or("prefilter".to_string(), |p| p.display().to_string());
    progress.begin("prefiltering", 0);
    let maps = ibl_mapping::prefilter(&image, mapping, &options, &progress::rows(progress));
    progress.end();
    let maps = maps.context(label.clone())?;

    let mut outputs = Vec::new();
    let mut roughness = Vec::new();
    let inputs: Vec<&Path> = job.probe.iter().map(PathBuf::as_path).collect();
    if let Some(chain) = &maps.specular {
        roughness.clone_from(&chain.roughness);
        if let Some(out) = &job.output {
            ibl_io::write_texture(out, &Texture::from_cube_levels(&chain.cube), job.texel)?;
            outputs.push(out.display().to_string());
        }
        if let Some(out) = &job.latlong {
            ibl_io::write_texture(out, &Texture::from_image_levels(&chain.latlong), job.texel)?;
            outputs.push(out.display().to_string());
        }
        if let Some(out) = &job.preview {
            let sheet = chain.contact_sheet(64)?;
            let opts = WriteOptions {
                display: Display {
                    exposure_stops: auto_exposure_stops(&sheet),
                    curve: ToneCurve::AcesFilmic,
                },
                ..WriteOptions::default()
            };
            ibl_io::write_image(out, &sheet, &opts)?;
            outputs.push(out.display().to_string());
        }
    }
    if let (Some(out), Some(faces)) = (&job.irradiance, &maps.irradiance) {
        if ImageFormat::from_path(out).is_some_and(ImageFormat::is_texture) {
            let texture = Texture::from_cube_levels(std::slice::from_ref(faces));
            ibl_io::write_texture(out, &texture, job.texel)?;
        } else {
            let cross = ibl_mapping::join_cube_faces(faces, CubeLayout::HorizontalCross)?;
            envmap_files::save(
                out,
                &cross,
                EnvMapping::Single(Mapping::Cube(CubeLayout::HorizontalCross)),
                &WriteOptions::default(),
                &inputs,
            )?;
        }
        outputs.push(out.display().to_string());
    }
    if let (Some(out), Some(probe)) = (&job.sh, &job.probe) {
        write_sh(job, out, probe, &image, mapping)?;
        outputs.push(out.display().to_string());
    }
    if let (Some(out), Some(dfg)) = (&job.dfg, &maps.dfg) {
        if ImageFormat::from_path(out).is_some_and(ImageFormat::is_texture) {
            let rg = if job.texel == TexelFormat::Rgba32Float {
                TexelFormat::Rg32Float
            } else {
                TexelFormat::Rg16Float
            };
            ibl_io::write_texture(out, &Texture::from_rg(dfg.size, dfg.size, &dfg.texels), rg)?;
        } else {
            let img = Image::from_fn_par(dfg.size, dfg.size, |i, j| {
                let [r, g] = dfg.get(i, j);
                Rgb::new(r, g, 0.0)
            });
            // A picture of the table (PNG is sRGB-encoded, 8-bit): use KTX2, DDS or EXR for data.
            let opts = WriteOptions {
                display: Display {
                    exposure_stops: 0.0,
                    curve: ToneCurve::Clamp,
                },
                ..WriteOptions::default()
            };
            ibl_io::write_image(out, &img, &opts)?;
        }
        outputs.push(out.display().to_string());
    }
    for o in &outputs {
        progress.note(&format!("wrote {o}"));
    }
    let specular = maps.specular.is_some();
    Ok(PrefilterSummary {
        probe: job.probe.as_ref().map(|p| p.display().to_string()),
        target: specular.then_some(job.target.name()),
        face_size: specular.then_some(job.face_size),
        samples: specular.then_some(job.samples),
        format: job.texel.name(),
        roughness,
        seconds: start.elapsed().as_secs_f64(),
        outputs,
    })
}

/// Projects the probe (as a lat-long map) on SH and writes it in the job's SH format.
fn write_sh(
    job: &PrefilterJob,
    out: &Path,
    probe: &Path,
    image: &Image<Rgb>,
    mapping: Mapping,
) -> Result<()> {
    let latlong = if mapping == Mapping::LatLong {
        image.clone()
    } else {
        let (w, h) = Mapping::LatLong.default_size_for(mapping, image.width(), image.height());
        ibl_mapping::resample(
            image,
            mapping,
            Mapping::LatLong,
            w,
            h,
            ibl_core::glam::Mat3::IDENTITY,
            &|_, _| {},
        )?
    };
    let sh = ibl_sh::project_latlong(&latlong, job.bands).context(probe.display().to_string())?;
    let file = ShFile {
        format: SH_FORMAT.to_string(),
        convention: SH_CONVENTION.to_string(),
        frame: "gltf".to_string(),
        quantity: ShQuantity::Radiance,
        bands: sh.bands(),
        window: "none".to_string(),
        probe: Some(ProbeRef {
            path: probe.display().to_string(),
            width: image.width(),
            height: image.height(),
            sha256: ibl_io::light_file::sha256_file(probe)?,
        }),
        coefficients: sh.coefficients().to_vec(),
    };
    ibl_io::write_sh_file(out, job.sh_format, &file)?;
    Ok(())
}
