//! Symmetry expansion: both formats store only the planes a luminaire's symmetry does not
//! repeat; `expand` mirrors them into the full turn `C = 0 ..= 360` that
//! [`ibl_light::CandelaTable`] holds.
//!
//! | symmetry | stored planes | images of a stored plane at `C` | IES LM-63 type C | EULUMDAT |
//! |---|---|---|---|---|
//! | [`Symmetry::Axial`] | one | every `C` | one horizontal angle | `Isym = 1` |
//! | [`Symmetry::Quadrant`] | `0 ..= 90` | `C`, `180 - C`, `180 + C`, `360 - C` | 0 to 90 | `Isym = 4` |
//! | [`Symmetry::PlaneC0C180`] | `0 ..= 180` | `C`, `360 - C` | 0 to 180 | `Isym = 2` |
//! | [`Symmetry::PlaneC90C270`] | `90 ..= 270` | `C`, `180 - C` (mod 360) | 90 to 270 | `Isym = 3` |
//! | [`Symmetry::None`] | all | `C` | 0 to over 180 | `Isym = 0` |
//!
//! A full set that does not reach 360 (EULUMDAT lists `0 .. 360 - Dc`) or does not start at 0 is
//! closed periodically: the missing `C = 0` plane is interpolated linearly across the gap between
//! the last plane and the first one turned by 360 degrees, and `C = 360` repeats `C = 0`.

/// How a file's horizontal planes repeat (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symmetry {
    /// Rotationally symmetric about the vertical axis: one plane.
    Axial,
    /// Symmetric to both the C0-C180 and the C90-C270 planes: `0 ..= 90` stored.
    Quadrant,
    /// Symmetric to the C0-C180 plane: `0 ..= 180` stored.
    PlaneC0C180,
    /// Symmetric to the C90-C270 plane: `90 ..= 270` stored.
    PlaneC90C270,
    /// No symmetry: every plane stored.
    None,
}

/// Angles closer than this (degrees) are the same plane; the stated ends of a symmetric range
/// (0, 90, 180, 270, 360) are matched within it too.
pub(crate) const ANGLE_EPS: f64 = 1e-3;

/// Whether `a` is the angle `b` within [`ANGLE_EPS`].
pub(crate) fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= ANGLE_EPS
}

/// The full table's horizontal angles (degrees, `[0]` or `0 ..= 360`) and its values row-major by
/// horizontal angle, from `stored` planes at increasing `angles` (degrees, `0..=360`, checked by
/// the caller against the symmetry's range), each `vertical` values long, each value times
/// `scale`.
pub(crate) fn expand(
    symmetry: Symmetry,
    angles: &[f64],
    stored: &[f32],
    vertical: usize,
    scale: f64,
) -> (Vec<f32>, Vec<f32>) {
    let plane = |k: usize| &stored[k * vertical..(k + 1) * vertical];
    let scaled =
        |p: &[f32]| -> Vec<f32> { p.iter().map(|&c| (f64::from(c) * scale) as f32).collect() };
    if symmetry == Symmetry::Axial || angles.is_empty() {
        return (vec![0.0], scaled(plane(0)));
    }
    let mut images: Vec<(f64, usize)> = Vec::with_capacity(angles.len() * 4);
    for (k, &c) in angles.iter().enumerate() {
        let turned: &[f64] = match symmetry {
            Symmetry::Quadrant => &[c, 180.0 - c, 180.0 + c, 360.0 - c],
            Symmetry::PlaneC0C180 => &[c, 360.0 - c],
            Symmetry::PlaneC90C270 => &[c, (180.0 - c).rem_euclid(360.0)],
            Symmetry::None | Symmetry::Axial => &[c],
        };
        images.extend(turned.iter().map(|&a| (a, k)));
    }
    images.sort_by(|x, y| x.0.total_cmp(&y.0));
    images.dedup_by(|later, earlier| near(later.0, earlier.0));
    let mut columns: Vec<(f64, Vec<f32>)> = images
        .into_iter()
        .map(|(a, k)| (a, scaled(plane(k))))
        .collect();
    // Close the turn: a plane at exactly 0 and one at exactly 360.
    let (first, last) = (columns[0].0, columns[columns.len() - 1].0);
    if near(first, 0.0) {
        columns[0].0 = 0.0;
    } else {
        let gap = first - (last - 360.0);
        let w = ((360.0 - last) / gap) as f32;
        let (a, b) = (&columns[columns.len() - 1].1, &columns[0].1);
        let zero = a.iter().zip(b).map(|(&a, &b)| a + (b - a) * w).collect();
        columns.insert(0, (0.0, zero));
    }
    let n = columns.len();
    if near(columns[n - 1].0, 360.0) && n > 1 {
        columns[n - 1].0 = 360.0;
    } else {
        let zero = columns[0].1.clone();
        columns.push((360.0, zero));
    }
    let horizontal = columns.iter().map(|c| c.0 as f32).collect();
    let values = columns.into_iter().flat_map(|c| c.1).collect();
    (horizontal, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One value per plane (vertical = 1) equal to the plane's own angle, to see where each goes.
    fn expanded(symmetry: Symmetry, angles: &[f64]) -> Vec<(f32, f32)> {
        let stored: Vec<f32> = angles.iter().map(|&a| a as f32).collect();
        let (h, v) = expand(symmetry, angles, &stored, 1, 1.0);
        h.into_iter().zip(v).collect()
    }

    #[test]
    fn each_symmetry_mirrors_as_documented() {
        assert_eq!(expanded(Symmetry::Axial, &[0.0]), vec![(0.0, 0.0)]);
        assert_eq!(
            expanded(Symmetry::Quadrant, &[0.0, 45.0, 90.0]),
            vec![
                (0.0, 0.0),
                (45.0, 45.0),
                (90.0, 90.0),
                (135.0, 45.0),
                (180.0, 0.0),
                (225.0, 45.0),
                (270.0, 90.0),
                (315.0, 45.0),
                (360.0, 0.0)
            ]
        );
        assert_eq!(
            expanded(Symmetry::PlaneC0C180, &[0.0, 90.0, 180.0]),
            vec![
                (0.0, 0.0),
                (90.0, 90.0),
                (180.0, 180.0),
                (270.0, 90.0),
                (360.0, 0.0)
            ]
        );
        assert_eq!(
            expanded(Symmetry::PlaneC90C270, &[90.0, 180.0, 270.0]),
            vec![
                (0.0, 180.0),
                (90.0, 90.0),
                (180.0, 180.0),
                (270.0, 270.0),
                (360.0, 180.0)
            ]
        );
        assert_eq!(
            expanded(Symmetry::None, &[0.0, 120.0, 240.0]),
            vec![(0.0, 0.0), (120.0, 120.0), (240.0, 240.0), (360.0, 0.0)]
        );
    }

    #[test]
    fn an_open_turn_is_closed_across_the_gap() {
        // Planes at 10, 130, 250: C = 0 lies 110 / 120 of the way from 250 (= -110) to 10 (1e-3:
        // f32 rounding).
        let got = expanded(Symmetry::None, &[10.0, 130.0, 250.0]);
        assert_eq!(got[0].0, 0.0);
        assert!((got[0].1 - (250.0 + (10.0 - 250.0) * (110.0 / 120.0))).abs() < 1e-3);
        assert_eq!(got.last().unwrap(), &(360.0, got[0].1));
    }

    #[test]
    fn values_are_scaled() {
        let (_, v) = expand(Symmetry::Axial, &[0.0], &[2.0, 4.0], 2, 0.5);
        assert_eq!(v, vec![1.0, 2.0]);
    }
}
