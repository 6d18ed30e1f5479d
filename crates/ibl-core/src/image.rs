//! A dense 2-D image of any pixel type, stored row-major with **row 0 at the top** (as every
//! iblkit file format is presented, whatever its on-disk order).
//!
//! Pixel (x, y) is column x, row y. Sizes are `usize`; constructors check `width * height` for
//! overflow so that a size taken from an untrusted header can never wrap.

use rayon::prelude::*;

/// A width x height grid of pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    width: usize,
    height: usize,
    data: Vec<T>,
}

/// Why an image could not be built from the given parts.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ImageError {
    /// `width * height` overflows `usize`.
    #[error("image size {width} x {height} overflows")]
    SizeOverflow {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
    },
    /// The pixel vector has the wrong length.
    #[error("image of {width} x {height} needs {expected} pixels, got {actual}")]
    LengthMismatch {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
        /// `width * height`.
        expected: usize,
        /// Length of the data given.
        actual: usize,
    },
}

impl ImageError {
    /// Always true: the sizes and data come from the caller.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

impl<T: Clone> Image<T> {
    /// An image filled with `value`.
    ///
    /// # Panics
    /// If `width * height` overflows; sizes from files must go through [`Image::from_vec`].
    pub fn filled(width: usize, height: usize, value: T) -> Self {
        let n = width
            .checked_mul(height)
            .expect("image size overflows usize");
        Image {
            width,
            height,
            data: vec![value; n],
        }
    }
}

impl<T> Image<T> {
    /// Wraps a row-major pixel vector (row 0 first).
    pub fn from_vec(width: usize, height: usize, data: Vec<T>) -> Result<Self, ImageError> {
        let expected = width
            .checked_mul(height)
            .ok_or(ImageError::SizeOverflow { width, height })?;
        if data.len() != expected {
            return Err(ImageError::LengthMismatch {
                width,
                height,
                expected,
                actual: data.len(),
            });
        }
        Ok(Image {
            width,
            height,
            data,
        })
    }

    /// Builds an image by calling `f(x, y)` for every pixel, in parallel over rows.
    pub fn from_fn_par(width: usize, height: usize, f: impl Fn(usize, usize) -> T + Sync) -> Self
    where
        T: Send,
    {
        let data: Vec<T> = (0..height)
            .into_par_iter()
            .flat_map_iter(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Image {
            width,
            height,
            data,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Whether the image has no pixels.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If the coordinates are outside the image.
    pub fn get(&self, x: usize, y: usize) -> &T {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside image"
        );
        &self.data[y * self.width + x]
    }

    /// Mutable access to the pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If the coordinates are outside the image.
    pub fn get_mut(&mut self, x: usize, y: usize) -> &mut T {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside image"
        );
        &mut self.data[y * self.width + x]
    }

    /// Row `y` as a slice (left to right).
    pub fn row(&self, y: usize) -> &[T] {
        &self.data[y * self.width..(y + 1) * self.width]
    }

    /// All pixels, row-major, row 0 first.
    pub fn pixels(&self) -> &[T] {
        &self.data
    }

    /// All pixels, mutable, row-major, row 0 first.
    pub fn pixels_mut(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// Rows as mutable slices, for parallel processing with `par_chunks_mut`-style loops.
    pub fn rows_mut(&mut self) -> std::slice::ChunksExactMut<'_, T> {
        self.data.chunks_exact_mut(self.width.max(1))
    }

    /// Consumes the image and returns its pixels (row-major, row 0 first).
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }

    /// A new image of the same size with `f` applied to every pixel.
    pub fn map<U>(&self, f: impl Fn(&T) -> U) -> Image<U> {
        Image {
            width: self.width,
            height: self.height,
            data: self.data.iter().map(f).collect(),
        }
    }

    /// The image flipped top to bottom (for formats stored bottom-up).
    pub fn flipped_vertically(mut self) -> Self {
        let w = self.width;
        let h = self.height;
        for y in 0..h / 2 {
            let (top, bottom) = self.data.split_at_mut((h - 1 - y) * w);
            top[y * w..(y + 1) * w].swap_with_slice(&mut bottom[..w]);
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_vec_checks_length_and_overflow() {
        assert!(Image::from_vec(2, 2, vec![0u8; 4]).is_ok());
        assert!(matches!(
            Image::from_vec(2, 2, vec![0u8; 3]),
            Err(ImageError::LengthMismatch { .. })
        ));
        assert!(matches!(
            Image::<u8>::from_vec(usize::MAX, 2, vec![]),
            Err(ImageError::SizeOverflow { .. })
        ));
    }

    #[test]
    fn flip_reverses_rows() {
        let img = Image::from_vec(2, 3, vec![0, 1, 2, 3, 4, 5]).unwrap();
        assert_eq!(img.flipped_vertically().into_vec(), vec![4, 5, 2, 3, 0, 1]);
    }

    #[test]
    fn from_fn_par_is_row_major() {
        let img = Image::from_fn_par(3, 2, |x, y| 10 * y + x);
        assert_eq!(img.pixels(), &[0, 1, 2, 10, 11, 12]);
        assert_eq!(*img.get(2, 1), 12);
    }
}
