//! The sizes a photometric file may announce, checked by both readers before they allocate.

/// Sizes a photometric file may announce, checked before anything is allocated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PhotometryLimits {
    /// The largest file, bytes.
    pub max_bytes: u64,
    /// The most angles on one axis (and TILT pairs).
    pub max_angles: usize,
    /// The most stored candela values (vertical x horizontal angles); symmetry expansion makes
    /// the table at most about 4 times as large.
    pub max_values: usize,
}

impl Default for PhotometryLimits {
    /// 16 MiB, 3601 angles (0.1 degree steps over a full turn), 2^22 values (16 MiB of f32).
    fn default() -> Self {
        PhotometryLimits {
            max_bytes: 16 << 20,
            max_angles: 3601,
            max_values: 1 << 22,
        }
    }
}
