//! One module per subcommand.

pub mod convert;
pub mod demo;
pub mod eval;
pub mod info;
pub mod irradiance;
pub mod lights;
pub mod preview;
pub mod sh;
