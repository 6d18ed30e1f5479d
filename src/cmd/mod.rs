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

/// Prints `summary` as pretty JSON on stdout when `json` is set (`--json`); whether it did.
pub fn print_json(json: bool, summary: &impl serde::Serialize) -> anyhow::Result<bool> {
    if json {
        println!("{}", serde_json::to_string_pretty(summary)?);
    }
    Ok(json)
}
