//! Why a room operation failed, split by cause; [`RoomError::is_bad_input`] tells a front end
//! whether the input is at fault (exit status 2) or something went wrong inside (exit status 1).

use ibl_scene::description::DescriptionError;

/// Why a room operation failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RoomError {
    /// A field of a room or marks file is invalid; `field` is its path (`room.box[2].min`).
    #[error("{field}: {problem}")]
    Invalid {
        /// Path of the field at fault (`toml` or `json` for a syntax error).
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A setting is out of its range (`rays_per_patch = 0`).
    #[error("{0}")]
    Parameter(String),
    /// The input would need more memory or time than the limits allow (too many patches).
    #[error("{0}")]
    Limits(String),
    /// The probe does not show what the method needs (a light group it never sees, too few
    /// marked lines for a vanishing point).
    #[error("{0}")]
    Unobservable(String),
    /// An internal numerical failure (a degenerate system that valid input cannot produce).
    #[error("numerical failure: {0}")]
    Numerical(String),
}

/// A scene format error (the `[room]` table's checks, a room file parsed as a scene): the same
/// field and message, bad input.
impl From<DescriptionError> for RoomError {
    fn from(e: DescriptionError) -> RoomError {
        RoomError::Invalid {
            field: e.field,
            problem: e.problem,
        }
    }
}

impl RoomError {
    /// Whether the input (a file, a setting, the probe) is at fault rather than this library.
    pub fn is_bad_input(&self) -> bool {
        !matches!(self, RoomError::Numerical(_))
    }

    /// An [`RoomError::Invalid`] for `field`.
    pub fn invalid(field: impl Into<String>, problem: impl Into<String>) -> RoomError {
        RoomError::Invalid {
            field: field.into(),
            problem: problem.into(),
        }
    }
}
