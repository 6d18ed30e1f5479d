//! What a photometric file states about its flux: the figure the table's exact integral
//! (`ibl_light::CandelaTable::flux`) is checked against (`docs/PHOTOMETRY.md`, section 5).

/// What a file states about its luminous flux, the figure its table's integral is checked against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StatedFlux {
    /// Absolute photometry (IES lumens per lamp = -1): no lumens stated.
    Absolute,
    /// Relative photometry stating only the lamps' lumens, lm: the table integrates to that
    /// times the luminaire's light output ratio, which the file does not give.
    Lamps {
        /// Lamps times lumens per lamp (times the ballast factors), lm.
        lamp_lumens: f64,
    },
    /// The lamps' lumens and the luminaire's light output ratio: the table should integrate to
    /// their product.
    LampsAndLor {
        /// The lamps' lumens, lm.
        lamp_lumens: f64,
        /// The light output ratio, a fraction (EULUMDAT's `LORL / 100`).
        light_output_ratio: f64,
    },
}

impl StatedFlux {
    /// The lamps' lumens, if stated.
    pub fn lamp_lumens(&self) -> Option<f64> {
        match *self {
            StatedFlux::Absolute => None,
            StatedFlux::Lamps { lamp_lumens } | StatedFlux::LampsAndLor { lamp_lumens, .. } => {
                Some(lamp_lumens)
            }
        }
    }

    /// The luminaire's lumens (what the table should integrate to), if the file states them.
    pub fn luminaire_lumens(&self) -> Option<f64> {
        match *self {
            StatedFlux::LampsAndLor {
                lamp_lumens,
                light_output_ratio,
            } => Some(lamp_lumens * light_output_ratio),
            _ => None,
        }
    }
}
