//! Photometric files: the goniometric lights of Grosch 2005, section 4.2, read from IES LM-63
//! ([`ies`]) and EULUMDAT ([`ldt`]) files into an [`ibl_light::CandelaTable`] (cd, the light frame
//! of [`ibl_light::goniometric`], every symmetry expanded to the full turn by [`symmetry`]).
//!
//! Why our own readers and not the `eulumdat` crate (0.7, which reads both formats): it is
//! licensed AGPL-3.0-or-later, which this MIT OR Apache-2.0 workspace cannot take on as a
//! dependency of every binary; it turns IES files into its EULUMDAT model (its own symmetry and
//! unit conventions) where we need the LM-63 fields as written (the ballast factors, `TILT`, the
//! edition); and its 15,000 lines are mostly diagrams, ratings and street-lighting calculations.
//! The two formats are small, and owning them lets every count in a header be checked against
//! [`PhotometryLimits`] and against what the rest of the file holds before anything is allocated,
//! and every error name its line and field, as this crate's image readers do.
//!
//! Units and scale: tables are in candela. Absolute photometry (IES lumens per lamp = -1) is the
//! file's values times its multiplier; relative photometry (IES lumens per lamp, EULUMDAT's cd per
//! 1000 lamp lumens) is scaled to the lamps' stated lumens, so a table is always absolute cd of
//! the luminaire as measured. [`StatedFlux`] says what flux the file claims; the light's scale to
//! a probe's radiance unit is [`ibl_light::intensity_per_candela_for`].

pub mod ies;
pub mod ldt;
pub mod limits;
pub mod stated;
pub mod symmetry;
mod text;

use std::path::Path;

use ibl_light::CandelaTable;

use crate::error::{DecodeError, IoError};

pub use ies::IesFile;
pub use ldt::LdtFile;
pub use limits::PhotometryLimits;
pub use stated::StatedFlux;
pub use symmetry::Symmetry;

/// A photometric file of either format.
#[derive(Clone, Debug, PartialEq)]
pub enum PhotometricFile {
    /// IES LM-63 (`.ies`).
    Ies(IesFile),
    /// EULUMDAT (`.ldt`).
    Ldt(LdtFile),
}

impl PhotometricFile {
    /// The expanded candela table.
    pub fn table(&self) -> &CandelaTable {
        match self {
            PhotometricFile::Ies(f) => &f.table,
            PhotometricFile::Ldt(f) => &f.table,
        }
    }

    /// What the file states about its flux.
    pub fn stated_flux(&self) -> StatedFlux {
        match self {
            PhotometricFile::Ies(f) => f.stated_flux(),
            PhotometricFile::Ldt(f) => f.stated_flux(),
        }
    }

    /// The luminaire's name as the file gives it.
    pub fn name(&self) -> &str {
        match self {
            PhotometricFile::Ies(f) => f.name(),
            PhotometricFile::Ldt(f) => &f.luminaire_name,
        }
    }

    /// The format, e.g. `"IES LM-63-2002"` or `"EULUMDAT"`.
    pub fn format(&self) -> String {
        match self {
            PhotometricFile::Ies(f) => format!("IES {}", f.version.name()),
            PhotometricFile::Ldt(_) => "EULUMDAT".to_string(),
        }
    }
}

/// Reads an `.ies` or `.ldt` file (by extension, any case) with the default limits.
pub fn read_photometry(path: &Path) -> Result<PhotometricFile, IoError> {
    read_photometry_with_limits(path, &PhotometryLimits::default())
}

/// Reads an `.ies` or `.ldt` file (by extension, any case); sizes are checked against `limits`
/// before allocating, and every error names the file, and inside it the line and the field.
pub fn read_photometry_with_limits(
    path: &Path,
    limits: &PhotometryLimits,
) -> Result<PhotometricFile, IoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let decode: fn(&[u8], &PhotometryLimits) -> Result<PhotometricFile, DecodeError> =
        match ext.as_deref() {
            Some("ies") => |b, l| ies::decode(b, l).map(PhotometricFile::Ies),
            Some("ldt") => |b, l| ldt::decode(b, l).map(PhotometricFile::Ldt),
            _ => {
                return Err(IoError::Unsupported {
                    path: path.to_path_buf(),
                    what: "file extension (expected .ies or .ldt)".into(),
                });
            }
        };
    let bytes = crate::read_bounded(path, limits.max_bytes)?;
    decode(&bytes, limits).map_err(|e| e.with_path(path))
}
