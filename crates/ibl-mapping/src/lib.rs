//! Environment-map mappings for iblkit: lat-long, angular map, mirror ball, cube maps (crosses
//! and strip), single and dual fisheye; their exact texel solid angles, total power, rotation and
//! energy-conserving resampling between any two of them.
//!
//! Frame and formulas follow `docs/CONVENTIONS.md` (sections 1-4): world +Y up, -Z forward, +X
//! right; images row 0 at the top; continuous image coordinates put pixel (i, j)'s centre at
//! `(i + 0.5, j + 0.5)`. Modules:
//!
//! * [`mapping`]: the [`Mapping`] enum, names, shapes, sizes.
//! * [`projection`]: a mapping bound to an image size ([`Projection`]): per-pixel directions and
//!   densities, their inverse, bilinear look-ups ([`Taps`], [`taps`]), exact texel solid angles;
//!   what the renderer and the viewer sample with.
//! * [`cube`]: GL/KTX cube faces, cross and strip layouts, split/join of faces.
//! * [`disc`]: angular map, mirror ball and the radial machinery (exact clipped solid angles).
//! * [`fisheye`]: equidistant single and dual fisheye, the dual's feathered blend.
//! * [`resample`](mod@resample): area-averaging resampling and rotation (rows in parallel,
//!   deterministic).
//! * [`power`](mod@power): `sum L dOmega` per channel.
//! * [`prefilter`](mod@prefilter): engine-ready maps in one call: the GGX specular chain
//!   ([`specular`] over a seamless [`cube_pyramid`] split by [`specular_source`], roughness per
//!   level from [`ggx`]), the
//!   irradiance cube, SH and the split-sum table ([`dfg`]).

pub mod cube;
pub mod cube_pyramid;
pub mod dfg;
pub mod disc;
mod error;
pub mod fisheye;
pub mod ggx;
pub mod mapping;
pub mod power;
pub mod prefilter;
pub mod projection;
pub mod resample;
pub mod specular;
pub mod specular_source;
pub mod taps;

pub use cube::{CUBE_FACE_NAMES, join_cube_faces, split_cube_faces};
pub use cube_pyramid::CubePyramid;
pub use dfg::{Dfg, DfgLayout};
pub use error::{MappingError, with_article};
pub use ggx::EngineTarget;
pub use mapping::{CubeLayout, MAPPING_NAMES, Mapping};
pub use power::{power, power_with_solid_angles, try_power};
pub use prefilter::{
    DfgOptions, PrefilterOptions, Prefiltered, SpecularChain, SpecularOptions, prefilter,
};
pub use projection::Projection;
pub use resample::{resample, rotate};
pub use specular_source::SpecularSource;
pub use taps::Taps;
