//! One module per subcommand.

pub mod batch;
pub mod capture;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod eval;
pub mod info;
pub mod irradiance;
pub mod lights;
pub mod outdoor;
pub mod prefilter;
pub mod preview;
pub mod render;
pub mod room;
pub mod sh;
pub mod view;
