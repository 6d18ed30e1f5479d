//! Light types as data, low in the crate graph so that every producer (`ibl-extract`, and later
//! `ibl-room` and `ibl-outdoor`), the file formats (`ibl-io`) and every consumer (`ibl-render`,
//! the viewer, the Python bindings) share one definition:
//!
//! - [`directional`]: directional light sets (Madsen & Laursen 2006): per light a direction, a
//!   radiance, a solid angle and `I = L A`, with the [`Provenance`] of the set;
//! - [`method`]: the extraction methods by name ([`Method`], [`LightSource`]), what a scene file or
//!   a command line asks for;
//! - [`provenance`]: what made a set: the method with its parameters ([`Extraction`]) and the
//!   source probe ([`ProbeRef`]);
//! - [`patch`]: area patches of a room (Grosch 2005): position, normal, area, radiance;
//! - [`goniometric`]: point lights with a candela table and an orientation (IES / EULUMDAT), with
//!   the light's own evaluation (Grosch 2005, section 4.2): the bilinear interpolant, its exact
//!   luminous flux, the equal-area look-up map and EQ5's irradiance, defined once here for the
//!   renderer, the viewer and the file readers' checks;
//! - [`daylight`]: the sun (direction, irradiance) and the sky (Jensen, Andersen & Madsen 2006).
//!
//! Every colour is a linear Rec. 709 triple ([`ibl_core::Rgb`], or [`ibl_core::rgb::Rgb64`] where
//! sums must conserve power) named for the quantity it holds, with its unit in the field's doc.
//! Directions are unit vectors in the world frame (CONVENTIONS section 1) unless a field says
//! otherwise. No I/O here, and no algorithms beyond that evaluation of the goniometric light: the serde form of [`LightSet`]'s lights is the
//! interchange schema of CONVENTIONS section 7, written and read by `ibl-io`.

pub mod daylight;
pub mod directional;
mod encoding;
pub mod goniometric;
pub mod method;
pub mod patch;
pub mod provenance;
pub mod soft_points;
pub mod spread;

pub use daylight::{Sky, Sun};
pub use directional::{HorizonSide, Light, LightSet, PixelRegion, ShadowCones};
pub use goniometric::equal_area::EqualAreaMap;
pub use goniometric::{CandelaTable, GoniometricLight, PhotometryError, intensity_per_candela_for};
pub use method::{LightSource, MAX_MEDIAN_CUT_SPLITS, Method, MethodError};
pub use patch::AreaPatch;
pub use provenance::{Extraction, FitReport, ParameterError, ProbeRef, Provenance};
pub use spread::SpreadHistogram;
