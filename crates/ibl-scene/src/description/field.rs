//! What every table's validation shares: the error that names the field at fault by its path
//! (`object[0].rotate_deg`), and the checks on numbers and reflectances. A leaf module: the
//! tables import it, it imports none of them.

/// A problem in a scene description, with the path of the field at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct DescriptionError {
    /// Path of the field, e.g. `object[1].scale` (or `toml` for a syntax error).
    pub field: String,
    /// What is wrong.
    pub problem: String,
}

pub(crate) fn invalid(field: impl Into<String>, problem: impl Into<String>) -> DescriptionError {
    DescriptionError {
        field: field.into(),
        problem: problem.into(),
    }
}

pub(crate) fn finite3(field: &str, v: [f32; 3]) -> Result<(), DescriptionError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, format!("{v:?} is not finite")))
    }
}

/// `v` (an `f32` or `f64` field) finite and > 0, or an error at `field`.
pub(crate) fn positive<T: Into<f64> + Copy + std::fmt::Display>(
    field: &str,
    v: T,
) -> Result<(), DescriptionError> {
    let x: f64 = v.into();
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v} is not a positive finite number"),
        ))
    }
}

pub(crate) fn nonzero(field: &str, v: f32) -> Result<(), DescriptionError> {
    if v.is_finite() && v != 0.0 {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v} is not a non-zero finite number"),
        ))
    }
}

pub(crate) fn reflectance(field: &str, v: [f32; 3]) -> Result<(), DescriptionError> {
    if v.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)) {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("{v:?} is not a reflectance in [0, 1]"),
        ))
    }
}

impl DescriptionError {
    /// Always true: a description error is about the scene file's content.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}
