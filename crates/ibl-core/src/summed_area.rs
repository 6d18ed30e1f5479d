//! Summed-area tables (Crow 1984) over a scalar image, in f64, so that the sum over any axis-aligned
//! rectangle costs four look-ups. Median cut (Debevec 2005) uses one over luminance x solid angle.
//!
//! The table has `(W + 1) x (H + 1)` entries with a zero first row and column; `S(x, y)` is the
//! sum of all values with column < x and row < y. Building costs O(W H).

/// A summed-area table of an f64 image.
#[derive(Clone, Debug)]
pub struct SummedAreaTable {
    width: usize,
    height: usize,
    table: Vec<f64>,
}

impl SummedAreaTable {
    /// Builds the table from `value(x, y)` for every pixel of a `width` x `height` image.
    pub fn new(width: usize, height: usize, value: impl Fn(usize, usize) -> f64) -> Self {
        let stride = width + 1;
        let mut table = vec![0.0; stride * (height + 1)];
        for y in 0..height {
            let mut row_sum = 0.0;
            for x in 0..width {
                row_sum += value(x, y);
                table[(y + 1) * stride + x + 1] = table[y * stride + x + 1] + row_sum;
            }
        }
        SummedAreaTable {
            width,
            height,
            table,
        }
    }

    /// Width of the summed image.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height of the summed image.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Sum over columns `x0..x1` and rows `y0..y1` (half-open; bounds are clamped to the image).
    pub fn sum(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> f64 {
        let x1 = x1.min(self.width);
        let y1 = y1.min(self.height);
        if x0 >= x1 || y0 >= y1 {
            return 0.0;
        }
        let s = self.width + 1;
        self.table[y1 * s + x1] - self.table[y0 * s + x1] - self.table[y1 * s + x0]
            + self.table[y0 * s + x0]
    }

    /// Sum of the whole image.
    pub fn total(&self) -> f64 {
        self.sum(0, 0, self.width, self.height)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rectangle_sums_match_brute_force() {
        let f = |x: usize, y: usize| (x * 7 + y * 3) as f64 % 5.0 + 0.25;
        let sat = SummedAreaTable::new(9, 6, f);
        for (x0, y0, x1, y1) in [(0, 0, 9, 6), (2, 1, 5, 4), (8, 5, 9, 6), (3, 3, 3, 5)] {
            let brute: f64 = (y0..y1).flat_map(|y| (x0..x1).map(move |x| f(x, y))).sum();
            assert!((sat.sum(x0, y0, x1, y1) - brute).abs() < 1e-9);
        }
    }
}
