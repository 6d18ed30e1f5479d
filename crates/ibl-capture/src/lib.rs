//! HDR light probes from a camera (Debevec & Malik 1997; Ward 2003; Madsen & Laursen 2006,
//! section 1): bracketed exposures merged into one HDR image, mirror-ball photographs unwrapped
//! to lat-long, and fisheye pairs stitched into one panorama.
//!
//! This crate does no I/O: `ibl-io` reads the photographs, the CLI (`ibl capture`) ties it up.

pub mod align;
pub mod ball;
pub mod error;
pub mod fisheye;
pub mod ghost;
pub mod merge;
pub mod response;

pub use error::CaptureError;
