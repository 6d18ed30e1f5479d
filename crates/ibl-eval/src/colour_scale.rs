//! False colour: the viridis colour map (matplotlib's, perceptually uniform and readable in grey
//! and by colour-blind readers) and error maps drawn on it. Used by the sphere figures and by
//! `ibl compare`'s error images.

use ibl_core::Image;

/// The viridis colour map (matplotlib), nine stops from 0 to 1, sRGB.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Viridis at `t` in `[0, 1]` (clamped; NaN is the top colour), linear between stops in sRGB.
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let k = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    std::array::from_fn(|c| {
        (f64::from(a[c]) + f * (f64::from(b[c]) - f64::from(a[c]))).round() as u8
    })
}

/// Colour of the pixels outside the mask in [`false_colour`] (sRGB mid grey).
pub const MASKED_OUT_COLOUR: [u8; 3] = [128, 128, 128];

/// An error map on the viridis scale (8-bit sRGB): 0 is dark purple, `top` and above yellow;
/// pixels outside `mask` (when it has the map's size) are [`MASKED_OUT_COLOUR`]. A `top` that is
/// not positive draws every pixel at the bottom colour. O(W H).
pub fn false_colour(map: &Image<f32>, top: f64, mask: Option<&Image<bool>>) -> Image<[u8; 3]> {
    let mask = mask.filter(|m| (m.width(), m.height()) == (map.width(), map.height()));
    Image::from_fn_par(map.width(), map.height(), |x, y| {
        if mask.is_some_and(|m| !*m.get(x, y)) {
            return MASKED_OUT_COLOUR;
        }
        let t = if top > 0.0 {
            f64::from(*map.get(x, y)) / top
        } else {
            0.0
        };
        viridis(t)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(7.0), VIRIDIS[8]);
        assert_eq!(viridis(-1.0), VIRIDIS[0]);
        assert_eq!(viridis(0.5), VIRIDIS[4]);
    }

    #[test]
    fn masked_pixels_are_grey() {
        let map = Image::from_fn_par(8, 2, |x, _| if x < 4 { 1.0 } else { 0.0 });
        let right = Image::from_fn_par(8, 2, |x, _| x >= 4);
        let colours = false_colour(&map, 1.0, Some(&right));
        assert_eq!(*colours.get(0, 0), MASKED_OUT_COLOUR);
        assert_eq!(*colours.get(7, 1), viridis(0.0));
        assert_eq!(*false_colour(&map, 1.0, None).get(0, 0), viridis(1.0));
    }
}
