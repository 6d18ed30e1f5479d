//! What every comparison of two images checks first: equal, non-empty sizes and a mask of the same
//! size that selects some pixel, and the error that says which check failed. A leaf module, so
//! the metrics (`image_difference`, `flip`) share it without importing each other.

use std::fmt;

use ibl_core::{Image, Rgb};

/// Why two images (or an image and its mask) cannot be compared.
#[derive(Clone, Debug, PartialEq)]
pub enum DifferenceError {
    /// The test and reference images differ in size.
    SizeMismatch {
        /// Test image `[width, height]`.
        test: [usize; 2],
        /// Reference image `[width, height]`.
        reference: [usize; 2],
    },
    /// The mask differs in size from the images.
    MaskSizeMismatch {
        /// Mask `[width, height]`.
        mask: [usize; 2],
        /// Images `[width, height]`.
        image: [usize; 2],
    },
    /// Nothing to compare: an empty image, or a mask that selects no pixel.
    NoPixels,
    /// A viewing condition outside the supported range (FLIP's pixels per degree).
    PixelsPerDegree {
        /// The value given.
        value: f64,
        /// Smallest accepted.
        min: f64,
        /// Largest accepted.
        max: f64,
    },
}

impl fmt::Display for DifferenceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DifferenceError::SizeMismatch { test, reference } => write!(
                f,
                "the test image is {} x {} but the reference is {} x {}",
                test[0], test[1], reference[0], reference[1]
            ),
            DifferenceError::MaskSizeMismatch { mask, image } => write!(
                f,
                "the mask is {} x {} but the images are {} x {}",
                mask[0], mask[1], image[0], image[1]
            ),
            DifferenceError::NoPixels => {
                write!(f, "no pixels to compare (empty image or empty mask)")
            }
            DifferenceError::PixelsPerDegree { value, min, max } => write!(
                f,
                "pixels per degree must be between {min} and {max}, got {value}"
            ),
        }
    }
}

impl std::error::Error for DifferenceError {}

impl DifferenceError {
    /// Always true: every variant is about the images or options the caller gave.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

/// `[width, height]` of an image.
fn size_of<T>(image: &Image<T>) -> [usize; 2] {
    [image.width(), image.height()]
}

/// Checks that `test` and `reference` have the same, non-zero size.
pub(crate) fn check_sizes(
    test: &Image<Rgb>,
    reference: &Image<Rgb>,
) -> Result<(), DifferenceError> {
    if size_of(test) != size_of(reference) {
        return Err(DifferenceError::SizeMismatch {
            test: size_of(test),
            reference: size_of(reference),
        });
    }
    if reference.is_empty() {
        return Err(DifferenceError::NoPixels);
    }
    Ok(())
}

/// Checks that a mask, if any, has the size of `image` and selects at least one pixel.
pub(crate) fn check_mask<T>(
    image: &Image<T>,
    mask: Option<&Image<bool>>,
) -> Result<(), DifferenceError> {
    if let Some(m) = mask {
        if size_of(m) != size_of(image) {
            return Err(DifferenceError::MaskSizeMismatch {
                mask: size_of(m),
                image: size_of(image),
            });
        }
        if !m.pixels().iter().any(|&b| b) {
            return Err(DifferenceError::NoPixels);
        }
    }
    if image.is_empty() {
        return Err(DifferenceError::NoPixels);
    }
    Ok(())
}

/// Whether pixel `i` (row-major index) is compared.
pub(crate) fn selected(mask: Option<&Image<bool>>, i: usize) -> bool {
    mask.is_none_or(|m| m.pixels()[i])
}
