//! The demo (`ibl demo`): the main job on a folder of probes and one of scenes, with no other
//! input needed.
//!
//! It describes every probe, writes a tone-mapped preview, shows each probe in every mapping (EXR
//! plus preview), converts each back to lat-long and reports how much power the round trip kept,
//! and writes its irradiance map exact and as SH9 with SH9's error and the probe's dominant light
//! ([`crate::demo_probe`]). Then it runs the comparison of [`crate::eval`] on the same probes
//! (every extraction method, SH9 alone and LightGen lights with an SH9 ambient, N = 1 to 128,
//! 20000 scoring normals) into `eval/`, and renders the example scenes (`renders/`,
//! [`crate::demo_render`]) and estimates the worked example's room (Grosch 2005: reflectance per
//! group, the report, the important patches; `room/`, [`crate::demo_room`]) and runs the bundled
//! outdoor sequence (Jensen et al. 2006: sun and sky per frame, composites; `outdoor/`,
//! [`crate::demo_outdoor`]). Everything lands in one folder with an `index.html` to look at and
//! a `summary.json` for scripts ([`crate::demo_page`]).

use std::path::{Path, PathBuf};

use ibl_extract::ModelSpec;
use ibl_light::{LightSource, Method};

use crate::demo_outdoor::demo_outdoor;
use crate::demo_paths::EVAL_DIR;
use crate::demo_probe::{ProbeResult, demo_mappings, demo_probe};
use crate::demo_render::{SceneResult, demo_renders};
use crate::demo_room::{RoomResult, demo_room};
use crate::demo_section::{DemoSection, PageSection};
use crate::error::{Context, PipelineError, Result};
use crate::eval::{EvalSettings, evaluate};
use crate::progress::Progress;

/// What the demo runs on.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoOptions {
    /// Folder for all outputs (created if missing).
    pub out: PathBuf,
    /// Folder of lat-long probes.
    pub probes: PathBuf,
    /// Folder of scene files to render.
    pub scenes: PathBuf,
    /// Room file of the room section (the bundled `assets/rooms/apartment/room.toml`); none
    /// leaves the section out.
    pub room: Option<PathBuf>,
    /// Scene file of the outdoor section (the bundled `assets/outdoor/courtyard/scene.toml`);
    /// none leaves the section out.
    pub outdoor: Option<PathBuf>,
}

/// What the demo made.
#[derive(Clone, Debug)]
pub struct Demo {
    /// Per probe.
    pub probes: Vec<ProbeResult>,
    /// The comparison.
    pub report: ibl_eval::Report,
    /// Per scene.
    pub renders: Vec<SceneResult>,
    /// The reconstructed room.
    pub room: Option<RoomResult>,
    /// The front ends' sections.
    pub sections: Vec<PageSection>,
}

/// Light counts of the demo's comparison: the powers of two 1 to 128. `ibl eval` also sweeps 256 by
/// default; the demo leaves it out because irradiance optimisation alone needs about 35 s per
/// probe there (release build, 2 cores), three minutes for the five bundled probes, against about
/// 15 s per probe for all of 1 to 128.
pub const DEMO_EVAL_COUNTS: [usize; 8] = [1, 2, 4, 8, 16, 32, 64, 128];

/// The demo's comparison: every light method, SH9 alone and LightGen lights with an SH9 ambient.
pub fn demo_methods() -> Vec<ModelSpec> {
    let mut methods: Vec<ModelSpec> = Method::ALL.map(ModelSpec::from).to_vec();
    methods.push(ModelSpec::Sh { bands: 3 });
    methods.push(ModelSpec::Hybrid {
        lights: LightSource::Method(Method::LightGen),
        bands: 3,
    });
    methods
}

/// Lat-long probes in a folder: `.exr` files (or `.hdr` where no `.exr` of that name exists).
pub fn list_probes(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files = ibl_io::list_dir(dir)?;
    files.retain(|p| {
        matches!(
            ibl_io::ImageFormat::from_path(p),
            Some(ibl_io::ImageFormat::Exr | ibl_io::ImageFormat::Hdr)
        )
    });
    let exr_stems: Vec<PathBuf> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")))
        .map(|p| p.with_extension(""))
        .collect();
    files.retain(|p| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            || !exr_stems.contains(&p.with_extension(""))
    });
    if files.is_empty() {
        return Err(PipelineError::parameter(format!(
            "{}: no .exr or .hdr probes found",
            dir.display()
        )));
    }
    Ok(files)
}

/// Runs the demo (see the module doc); each of `front_ends` adds a section to the page after the
/// renders, the room and the outdoor sequence.
pub fn demo(
    o: &DemoOptions,
    progress: &dyn Progress,
    front_ends: &[&dyn DemoSection],
) -> Result<Demo> {
    let probes = list_probes(&o.probes)?;
    crate::output_paths::check_output_folder(&o.out)?;
    ibl_io::create_dir_all(&o.out)?;
    let mappings = demo_mappings();
    // Per probe: the preview, each mapping, the irradiance maps.
    let total = (probes.len() * (mappings.len() + 2)) as u64;
    progress.begin("demo", total);
    let mut done = 0u64;
    let mut results = Vec::new();
    for path in &probes {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        progress.update(done, total, Some(&name));
        let result = demo_probe(path, &name, &o.out, &mappings, &mut || {
            done += 1;
            progress.update(done, total, Some(&name));
        })
        .context(format!("demo on {}", path.display()));
        match result {
            Ok(r) => results.push(r),
            Err(e) => {
                progress.end();
                return Err(e);
            }
        }
    }
    progress.end();
    let settings = EvalSettings::new(
        demo_methods(),
        DEMO_EVAL_COUNTS.to_vec(),
        ibl_core::fibonacci::DEFAULT_NORMAL_COUNT,
        ibl_extract::ExtractOptions::default().seed,
        None,
    )?;
    let report = evaluate(&probes, &settings, &o.out.join(EVAL_DIR), progress)
        .context("comparing the light extraction methods")?;
    let renders = demo_renders(&o.scenes, &o.out, progress)?;
    let room = match &o.room {
        Some(path) => Some(demo_room(path, &o.out, progress)?),
        None => None,
    };
    let mut sections: Vec<PageSection> = Vec::new();
    if let Some(scene) = &o.outdoor {
        sections.push(demo_outdoor(scene, &o.out, progress)?);
    }
    sections.extend(
        front_ends
            .iter()
            .map(|f| f.section(&o.scenes, o.outdoor.as_deref(), &o.out, progress)),
    );
    crate::demo_page::write_summary(
        &o.out,
        &results,
        &report,
        &renders,
        room.as_ref(),
        &sections,
    )?;
    Ok(Demo {
        probes: results,
        report,
        renders,
        room,
        sections,
    })
}
