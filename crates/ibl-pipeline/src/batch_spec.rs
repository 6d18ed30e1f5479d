//! The batch spec: which probes a batch runs over and which per-probe steps it runs on each
//! (issue 19). One TOML file, read by `ibl batch SPEC.toml` and by `python -m iblkit.batch
//! SPEC.toml` alike, so both front ends run the same job ([`crate::batch`]).
//!
//! ```toml
//! [input]
//! folder = "probes"            # or glob = "probes/**/*.exr", list = "list.txt", files = [...]
//! extensions = ["exr", "hdr"]  # folder only (default: every image format iblkit reads)
//! mapping = "latlong"          # optional; default: each probe's mapping from its shape
//!
//! [output]
//! folder = "out"               # one sub-folder per probe, and the rows
//! rows = "results.jsonl"       # default
//!
//! [steps.info]
//! [steps.lights]
//! n = 16
//! [steps.sh]
//! [steps.preview]
//! ```
//!
//! Every path is relative to the spec file's folder. Unknown tables and keys are refused with
//! their name and line (serde's `deny_unknown_fields`); every name (method, format, curve) is
//! checked when the spec is read, so a typo fails before the first probe, not on each one.

use std::path::{Path, PathBuf};

use ibl_core::tonemap::ToneCurve;
use ibl_io::{ShFileFormat, ShQuantity, TexelFormat};
use ibl_light::Method;
use ibl_mapping::EngineTarget;
use ibl_sh::Window;
use serde::{Deserialize, Serialize};

use crate::envmap_files::EnvMapping;
use crate::error::{PipelineError, Result};

/// Largest spec file read, bytes.
const MAX_SPEC_BYTES: u64 = 1 << 20;

/// Where the probes come from (exactly one of the four).
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct InputTable {
    folder: Option<String>,
    glob: Option<String>,
    list: Option<String>,
    files: Option<Vec<String>>,
    extensions: Option<Vec<String>>,
    mapping: Option<String>,
}

#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
struct OutputTable {
    folder: String,
    rows: Option<String>,
}

/// The spec file as written.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecFile {
    input: InputTable,
    output: OutputTable,
    #[serde(default)]
    steps: Steps,
}

/// The per-probe steps; a step runs when its table is present. The same struct, serialised,
/// is hashed into every row ([`BatchSpec::steps_sha256`]), so a row made by other settings is
/// not taken as done.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Steps {
    /// `ibl info`: statistics (size, range, power, brightest pixel).
    pub info: Option<InfoStep>,
    /// `ibl lights`: N lights by one method, written in the listed formats.
    pub lights: Option<LightsStep>,
    /// `ibl sh`: the coefficients in one tool's format.
    pub sh: Option<ShStep>,
    /// `ibl irradiance`: an irradiance map.
    pub irradiance: Option<IrradianceStep>,
    /// `ibl prefilter`: the GGX specular chain, the irradiance cube and the DFG-free SH.
    pub prefilter: Option<PrefilterStep>,
    /// `ibl preview`: a tone-mapped PNG.
    pub preview: Option<PreviewStep>,
    /// `ibl eval`: the methods' irradiance errors against the exact ground truth.
    pub eval: Option<EvalStep>,
}

/// `[steps.info]`: no settings.
#[derive(Clone, Debug, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct InfoStep {}

/// `[steps.lights]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightsStep {
    /// Number of lights.
    pub n: usize,
    /// Method name (`median-cut` by default).
    #[serde(default = "default_method")]
    pub method: String,
    /// Seed of the randomised methods.
    #[serde(default)]
    pub seed: u64,
    /// Output formats by extension: json, gltf, glb, xml, pbrt (`["json"]` by default).
    #[serde(default = "default_light_formats")]
    pub formats: Vec<String>,
    /// Hybrid lighting: an SH ambient of this many bands in the JSON file.
    pub ambient_sh: Option<usize>,
    /// Also draw the lights over the probe (`lights.png`).
    #[serde(default)]
    pub overlay: bool,
}

/// `[steps.sh]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ShStep {
    /// Bands (3 = SH9).
    #[serde(default = "default_bands")]
    pub bands: usize,
    /// Format name (`json` by default).
    #[serde(default = "default_sh_format")]
    pub format: String,
    /// Window against ringing: none, lanczos, hann.
    #[serde(default = "default_window")]
    pub window: String,
    /// Irradiance coefficients `A_l c_lm` instead of radiance (json only).
    #[serde(default)]
    pub irradiance: bool,
}

/// `[steps.irradiance]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct IrradianceStep {
    /// exact, fast or sh.
    #[serde(default = "default_irradiance_method")]
    pub method: String,
    /// Width of the map, pixels.
    #[serde(default = "default_irradiance_width")]
    pub width: usize,
    /// Mapping of the map.
    #[serde(default = "default_latlong")]
    pub mapping: String,
    /// File extension of the map (exr, hdr, pfm).
    #[serde(default = "default_exr")]
    pub extension: String,
    /// SH bands (method sh only).
    #[serde(default = "default_bands")]
    pub bands: usize,
}

/// `[steps.prefilter]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PrefilterStep {
    /// Roughness convention: filament, khronos, ...
    #[serde(default = "default_target")]
    pub target: String,
    /// Face size of level 0 (a power of two).
    #[serde(default = "default_face_size")]
    pub face_size: usize,
    /// GGX samples per texel.
    #[serde(default = "default_samples")]
    pub samples: usize,
    /// Texel format: rgba16f, rgba32f, rgb9e5.
    #[serde(default = "default_texel")]
    pub texel: String,
    /// Container: ktx2 or dds.
    #[serde(default = "default_ktx2")]
    pub extension: String,
    /// Also the irradiance cube of this face size.
    pub irradiance_size: Option<usize>,
}

/// `[steps.preview]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PreviewStep {
    /// Exposure in stops (automatic when absent).
    pub exposure: Option<f32>,
    /// Tone curve: clamp, reinhard, aces.
    #[serde(default = "default_curve")]
    pub curve: String,
}

/// `[steps.eval]`.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct EvalStep {
    /// `all` or comma-separated method names.
    #[serde(default = "default_method")]
    pub methods: String,
    /// Light counts.
    #[serde(default = "default_eval_counts")]
    pub n: Vec<usize>,
    /// Scoring normals.
    #[serde(default = "default_normals")]
    pub normals: usize,
    /// Seed of the randomised methods.
    #[serde(default)]
    pub seed: u64,
}

fn default_method() -> String {
    Method::MedianCut.name().to_string()
}
fn default_light_formats() -> Vec<String> {
    vec!["json".to_string()]
}
fn default_bands() -> usize {
    3
}
fn default_sh_format() -> String {
    ShFileFormat::Json.name().to_string()
}
fn default_window() -> String {
    Window::None.name().to_string()
}
fn default_irradiance_method() -> String {
    "exact".to_string()
}
fn default_irradiance_width() -> usize {
    64
}
fn default_latlong() -> String {
    "latlong".to_string()
}
fn default_exr() -> String {
    "exr".to_string()
}
fn default_target() -> String {
    EngineTarget::Filament.name().to_string()
}
fn default_face_size() -> usize {
    64
}
fn default_samples() -> usize {
    64
}
fn default_texel() -> String {
    TexelFormat::Rgba16Float.name().to_string()
}
fn default_ktx2() -> String {
    "ktx2".to_string()
}
fn default_curve() -> String {
    "aces".to_string()
}
fn default_eval_counts() -> Vec<usize> {
    vec![16]
}
fn default_normals() -> usize {
    2000
}

/// Where the probes come from, paths resolved against the spec's folder.
#[derive(Clone, Debug, PartialEq)]
pub enum InputSource {
    /// Every file in a folder (not recursive) whose extension is listed.
    Folder {
        /// The folder.
        folder: PathBuf,
        /// Extensions, lower case, without the dot.
        extensions: Vec<String>,
    },
    /// A glob pattern (`*`, `?`, `[...]`, `**`).
    Glob(String),
    /// A text file: one path per line (relative to the list's folder), `#` comments.
    List(PathBuf),
    /// Paths given in the spec.
    Files(Vec<PathBuf>),
}

/// A checked spec.
#[derive(Clone, Debug, PartialEq)]
pub struct BatchSpec {
    /// The spec file.
    pub path: PathBuf,
    /// Where the probes come from.
    pub input: InputSource,
    /// Mapping of every probe (`None`: each from its shape).
    pub mapping: Option<EnvMapping>,
    /// Output folder.
    pub out: PathBuf,
    /// The rows file (JSON Lines), in `out`.
    pub rows: PathBuf,
    /// The steps as written (names checked).
    pub steps: Steps,
    /// The steps' typed settings.
    pub typed: TypedSteps,
}

/// The names of the spec resolved to the library's types.
#[derive(Clone, Debug, PartialEq)]
pub struct TypedSteps {
    /// Lights method.
    pub method: Method,
    /// Light file formats' extensions.
    pub light_formats: Vec<String>,
    /// SH format, window and quantity.
    pub sh: (ShFileFormat, Window, ShQuantity),
    /// Irradiance map: method and mapping.
    pub irradiance: (crate::irradiance::IrradianceMethod, EnvMapping),
    /// Prefilter target and texel format.
    pub prefilter: (EngineTarget, TexelFormat),
    /// Preview curve.
    pub curve: ToneCurve,
    /// Eval methods.
    pub eval_methods: Vec<ibl_extract::ModelSpec>,
}

/// Image formats a folder input takes by default.
pub const DEFAULT_EXTENSIONS: [&str; 4] = ["exr", "hdr", "pfm", "png"];

impl BatchSpec {
    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<BatchSpec> {
        let text = ibl_io::read_text(path, MAX_SPEC_BYTES)?;
        BatchSpec::parse(&text, path)
    }

    /// Parses `text` as the spec file `path` (paths resolve against its folder).
    pub fn parse(text: &str, path: &Path) -> Result<BatchSpec> {
        let shown = path.display();
        let bad = |m: String| PipelineError::parameter(format!("{shown}: {m}"));
        let file: SpecFile = toml::from_str(text).map_err(|e| bad(e.to_string()))?;
        let base = path.parent().unwrap_or(Path::new(""));
        let input = resolve_input(&file.input, base).map_err(bad)?;
        let mapping = match &file.input.mapping {
            Some(name) => Some(
                EnvMapping::parse(name, 180.0).map_err(|e| bad(format!("[input] mapping: {e}")))?,
            ),
            None => None,
        };
        let out = join_lexically(base, &file.output.folder);
        let rows_name = file.output.rows.as_deref().unwrap_or("results.jsonl");
        if rows_name.is_empty() || Path::new(rows_name).components().count() != 1 {
            return Err(bad(format!(
                "[output] rows `{rows_name}`: a file name in the output folder"
            )));
        }
        let steps = file.steps;
        let typed = typed_steps(&steps).map_err(bad)?;
        if steps == Steps::default() {
            return Err(bad(
                "no [steps.*] table: name at least one of info, lights, sh, irradiance, \
                 prefilter, preview, eval"
                    .to_string(),
            ));
        }
        Ok(BatchSpec {
            path: path.to_path_buf(),
            input,
            mapping,
            rows: out.join(rows_name),
            out,
            steps,
            typed,
        })
    }

    /// SHA-256 of the steps' settings, written into every row: a row whose hash differs was made
    /// by other settings and is done again.
    pub fn steps_sha256(&self) -> String {
        let json = serde_json::to_string(&self.steps).unwrap_or_default();
        ibl_io::light_file::sha256_hex(json.as_bytes())
    }
}

/// `base` joined with `relative`, `.` and `..` folded lexically (`assets/batch/../probes` is
/// `assets/probes`), so rows and messages show the path a user would type. A `..` that would
/// climb above a relative base's start is kept.
pub fn join_lexically(base: &Path, relative: &str) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in base.join(relative).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                let last = out.components().next_back();
                if matches!(last, Some(Component::Normal(_))) {
                    out.pop();
                } else if !matches!(last, Some(Component::RootDir | Component::Prefix(_))) {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    if out.as_os_str().is_empty() {
        out.push(".");
    }
    out
}

fn resolve_input(t: &InputTable, base: &Path) -> std::result::Result<InputSource, String> {
    let given = [
        t.folder.is_some(),
        t.glob.is_some(),
        t.list.is_some(),
        t.files.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err("[input] needs exactly one of folder, glob, list, files".to_string());
    }
    if t.extensions.is_some() && t.folder.is_none() {
        return Err("[input] extensions only applies to folder".to_string());
    }
    if let Some(folder) = &t.folder {
        let extensions = match &t.extensions {
            Some(list) if list.is_empty() => {
                return Err("[input] extensions is empty".to_string());
            }
            Some(list) => list
                .iter()
                .map(|e| e.trim_start_matches('.').to_ascii_lowercase())
                .collect(),
            None => DEFAULT_EXTENSIONS.map(String::from).to_vec(),
        };
        return Ok(InputSource::Folder {
            folder: join_lexically(base, folder),
            extensions,
        });
    }
    if let Some(pattern) = &t.glob {
        let joined = join_lexically(base, pattern);
        return Ok(InputSource::Glob(joined.to_string_lossy().into_owned()));
    }
    if let Some(list) = &t.list {
        return Ok(InputSource::List(join_lexically(base, list)));
    }
    let files = t.files.as_deref().unwrap_or_default();
    if files.is_empty() {
        return Err("[input] files is empty".to_string());
    }
    Ok(InputSource::Files(
        files.iter().map(|f| join_lexically(base, f)).collect(),
    ))
}

fn typed_steps(s: &Steps) -> std::result::Result<TypedSteps, String> {
    let method = match &s.lights {
        Some(l) => l
            .method
            .parse::<Method>()
            .map_err(|e| format!("[steps.lights] method: {e}"))?,
        None => Method::MedianCut,
    };
    let light_formats = match &s.lights {
        Some(l) => {
            if l.formats.is_empty() {
                return Err("[steps.lights] formats is empty".to_string());
            }
            for f in &l.formats {
                let probe = PathBuf::from(format!("lights.{f}"));
                ibl_io::LightFormat::from_path(&probe).ok_or_else(|| {
                    format!("[steps.lights] formats: `{f}` (json, gltf, glb, xml, pbrt)")
                })?;
            }
            l.formats.clone()
        }
        None => Vec::new(),
    };
    let sh = match &s.sh {
        Some(sh) => (
            ShFileFormat::from_name(&sh.format)
                .ok_or_else(|| format!("[steps.sh] format: unknown `{}`", sh.format))?,
            sh.window
                .parse::<Window>()
                .map_err(|e| format!("[steps.sh] window: {e}"))?,
            if sh.irradiance {
                ShQuantity::Irradiance
            } else {
                ShQuantity::Radiance
            },
        ),
        None => (ShFileFormat::Json, Window::None, ShQuantity::Radiance),
    };
    let irradiance = match &s.irradiance {
        Some(i) => {
            let method =
                crate::irradiance::IrradianceMethod::from_name(&i.method).ok_or_else(|| {
                    format!(
                        "[steps.irradiance] method: `{}` (exact, fast, sh)",
                        i.method
                    )
                })?;
            let mapping = EnvMapping::parse(&i.mapping, 180.0)
                .map_err(|e| format!("[steps.irradiance] mapping: {e}"))?;
            if mapping == EnvMapping::CubeFaces {
                return Err(
                    "[steps.irradiance] mapping: cube-faces writes six files; use \
                            a single-image mapping"
                        .to_string(),
                );
            }
            (method, mapping)
        }
        None => (
            crate::irradiance::IrradianceMethod::Exact,
            EnvMapping::Single(ibl_mapping::Mapping::LatLong),
        ),
    };
    let prefilter = match &s.prefilter {
        Some(p) => (
            EngineTarget::from_name(&p.target)
                .ok_or_else(|| format!("[steps.prefilter] target: unknown `{}`", p.target))?,
            TexelFormat::from_name(&p.texel)
                .ok_or_else(|| format!("[steps.prefilter] texel: unknown `{}`", p.texel))?,
        ),
        None => (EngineTarget::Filament, TexelFormat::Rgba16Float),
    };
    let curve = match &s.preview {
        Some(p) => ToneCurve::from_name(&p.curve).ok_or_else(|| {
            format!(
                "[steps.preview] curve: `{}` (clamp, reinhard, aces)",
                p.curve
            )
        })?,
        None => ToneCurve::AcesFilmic,
    };
    let eval_methods = match &s.eval {
        Some(e) => crate::eval::parse_methods(&e.methods)
            .map_err(|err| format!("[steps.eval] methods: {err}"))?,
        None => Vec::new(),
    };
    Ok(TypedSteps {
        method,
        light_formats,
        sh,
        irradiance,
        prefilter,
        curve,
        eval_methods,
    })
}
