//! A [`Mapping`] bound to an image size: the per-sample geometry used by resampling, power and
//! the public `Mapping` methods.
//!
//! Building a `Projection` validates the shape and parameters once (so no per-sample code can
//! meet a zero size, a bad field of view or a cube layout that does not fit), then every query is
//! O(1) and allocation-free:
//!
//! * `pixel_dir(x, y)`: unit direction at continuous image coordinates and the solid-angle
//!   density `dOmega / (dx dy)` there (the Jacobian used to weight sub-samples);
//! * `dir_to_pixel(d)`: the inverse;
//! * `taps(d)`: the source pixels and weights of a bilinear look-up in direction `d` that wraps
//!   horizontally on lat-long (and clamps at the poles), stays inside a cube face, inside the
//!   disc, or blends the two lenses of a dual fisheye (as taps so that resampling can both gather
//!   radiance and measure how much weight each source pixel receives);
//! * `texel_solid_angle(i, j)`: exact pixel solid angles (lat-long rows from `ibl_core::LatLong`,
//!   cube and disc closed forms from [`crate::cube`] and [`crate::disc`]).
//!
//! Lat-long geometry is CONVENTIONS section 2 through `ibl_core::LatLong`: `u = x / W`,
//! `v = y / H`, and the density is `sin(pi v) (2 pi / W) (pi / H)`.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use ibl_core::{Image, LatLong};

use crate::cube::{self, CubeImage};
use crate::disc::{Disc, Profile};
use crate::fisheye::DualFisheye;
use crate::mapping::{Mapping, MappingError};

/// A mapping with a validated image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Projection {
    /// Equirectangular, any size.
    LatLong(LatLong),
    /// A single disc filling a square image (angular, mirror ball, fisheye).
    Disc(Disc),
    /// Two fisheye discs side by side.
    Dual(DualFisheye),
    /// A cube layout.
    Cube(CubeImage),
}

fn shape(mapping: Mapping, width: usize, height: usize, reason: &str) -> MappingError {
    MappingError::Shape {
        mapping: mapping.name(),
        width,
        height,
        reason: reason.into(),
    }
}

impl Projection {
    /// Validates `mapping` for a `width x height` image.
    pub(crate) fn new(mapping: Mapping, width: usize, height: usize) -> Result<Self, MappingError> {
        mapping.validate()?;
        if width == 0 || height == 0 {
            return Err(shape(mapping, width, height, "the image is empty"));
        }
        if width
            .checked_mul(height)
            .is_none_or(|n| n > isize::MAX as usize / 16)
        {
            return Err(shape(mapping, width, height, "the image is too large"));
        }
        let square = |profile: Profile, sz: f64| {
            if width == height {
                Ok(Projection::Disc(Disc::new(
                    profile, 1.0, sz, 0, width, height,
                )))
            } else {
                Err(shape(mapping, width, height, "needs a square image"))
            }
        };
        match mapping {
            Mapping::LatLong => Ok(Projection::LatLong(LatLong::new(width, height))),
            Mapping::Angular => square(Profile::Angular, -1.0),
            // The ball's centre looks at the camera (+Z).
            Mapping::MirrorBall => square(Profile::MirrorBall, 1.0),
            Mapping::Fisheye { fov_deg } => square(
                Profile::Equidistant {
                    half_fov: f64::from(fov_deg).to_radians() / 2.0,
                },
                -1.0,
            ),
            Mapping::DualFisheye { fov_deg } => {
                if width == 2 * height {
                    Ok(Projection::Dual(DualFisheye::new(
                        height,
                        f64::from(fov_deg).to_radians() / 2.0,
                    )))
                } else {
                    Err(shape(
                        mapping,
                        width,
                        height,
                        "needs a 2:1 image (two square halves)",
                    ))
                }
            }
            Mapping::Cube(layout) => match layout.face_size(width, height) {
                Some(size) => Ok(Projection::Cube(CubeImage::new(layout, size))),
                None => Err(cube::shape_error(layout, width, height)),
            },
        }
    }

    /// Image width in pixels.
    pub(crate) fn width(&self) -> usize {
        match self {
            Projection::LatLong(ll) => ll.width,
            Projection::Disc(d) => d.cw,
            Projection::Dual(d) => 2 * d.front.cw,
            Projection::Cube(c) => c.layout.grid().0 * c.size,
        }
    }

    /// Image height in pixels.
    pub(crate) fn height(&self) -> usize {
        match self {
            Projection::LatLong(ll) => ll.height,
            Projection::Disc(d) => d.h,
            Projection::Dual(d) => d.front.h,
            Projection::Cube(c) => c.layout.grid().1 * c.size,
        }
    }

    fn inside_image(&self, x: f64, y: f64) -> bool {
        x >= 0.0 && y >= 0.0 && x <= self.width() as f64 && y <= self.height() as f64
    }

    /// Unit direction and solid-angle density (sr per unit pixel area) at continuous image
    /// coordinates; `None` outside the domain.
    pub(crate) fn pixel_dir(&self, x: f64, y: f64) -> Option<(DVec3, f64)> {
        if !self.inside_image(x, y) {
            return None;
        }
        match self {
            Projection::LatLong(ll) => {
                let (w, h) = (ll.width as f64, ll.height as f64);
                let v = y / h;
                let density = (PI * v).sin() * (TAU / w) * (PI / h);
                Some((LatLong::uv_to_dir64(x / w, v), density))
            }
            Projection::Disc(d) => {
                let (a, b) = d.disc_coords(x, y);
                d.dir_density(a, b)
            }
            Projection::Dual(dual) => {
                let lens = dual.lens_at(x);
                let (a, b) = lens.disc_coords(x, y);
                lens.dir_density(a, b)
            }
            Projection::Cube(c) => c.dir_density(x, y),
        }
    }

    /// For pixel `(i, j)` whose centre is outside the domain but which still overlaps it (a rim
    /// pixel of a disc), the direction at its centre moved just inside the rim; `None` for pixels
    /// entirely outside the domain. Lat-long and cube pixels: the direction at the centre.
    pub(crate) fn rim_dir(&self, i: usize, j: usize) -> Option<DVec3> {
        let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
        if !self.inside_image(x, y) {
            return None;
        }
        let lens = match self {
            Projection::Disc(d) => d,
            Projection::Dual(dual) => dual.lens_at(x),
            _ => return self.pixel_dir(x, y).map(|(d, _)| d),
        };
        if !lens.texel_in_disc(i - lens.x0, j) {
            return None;
        }
        let (a, b) = lens.disc_coords(x, y);
        lens.clamped_dir(a, b)
    }

    /// Continuous image coordinates of a unit direction; `None` where the mapping does not see it.
    pub(crate) fn dir_to_pixel(&self, d: DVec3) -> Option<(f64, f64)> {
        match self {
            Projection::LatLong(ll) => {
                let (u, v) = LatLong::dir_to_uv(d);
                Some((u * ll.width as f64, v * ll.height as f64))
            }
            Projection::Disc(disc) => disc.pixel_of_dir(d),
            Projection::Dual(dual) => dual.pixel_of_dir(d),
            Projection::Cube(c) => Some(c.pixel_of_dir(d)),
        }
    }

    /// A texel's solid angle near unit direction `d` (an estimate of the local resolution, used
    /// to choose the supersampling rate); 0 where the mapping does not see `d`.
    pub(crate) fn texel_solid_angle_near(&self, d: DVec3) -> f64 {
        match self {
            Projection::LatLong(ll) => {
                let (_, v) = LatLong::dir_to_uv(d);
                let row = ((v * ll.height as f64) as usize).min(ll.height - 1);
                ll.row_solid_angle(row)
            }
            _ => match self.dir_to_pixel(d) {
                Some((x, y)) => self.pixel_dir(x, y).map_or(0.0, |(_, density)| density),
                None => 0.0,
            },
        }
    }

    /// The source pixels and weights (summing to 1) that interpolate unit direction `d` (see
    /// the module note); empty where the mapping does not see `d`.
    pub(crate) fn taps(&self, d: DVec3) -> Taps {
        match self {
            Projection::LatLong(ll) => latlong_taps(ll, d),
            Projection::Disc(disc) => match disc.pixel_of_dir(d) {
                Some((x, y)) => disc.taps(disc.cw, x, y),
                None => Taps::default(),
            },
            Projection::Dual(dual) => dual.taps(2 * dual.front.cw, d),
            Projection::Cube(c) => c.taps(d),
        }
    }

    /// Exact solid angle of pixel `(i, j)` (see [`Mapping::texel_solid_angles`]).
    pub(crate) fn texel_solid_angle(&self, i: usize, j: usize) -> f64 {
        match self {
            Projection::LatLong(ll) => ll.row_solid_angle(j),
            Projection::Disc(d) => d.texel_solid_angle(i, j),
            Projection::Dual(dual) => dual.texel_solid_angle(i, j),
            Projection::Cube(c) => c.texel_solid_angle(i, j),
        }
    }

    /// Exact solid angles of every pixel, rows in parallel; disc images compute one quadrant and
    /// mirror it (the disc is symmetric about both axes of the cell). Cost O(W H).
    pub(crate) fn texel_solid_angles(&self) -> Image<f64> {
        let (w, h) = (self.width(), self.height());
        match self {
            Projection::Disc(_) | Projection::Dual(_) => {
                // Mirror within the cell: column i of a cell of width cw equals column cw-1-i.
                let cw = if let Projection::Dual(d) = self {
                    d.front.cw
                } else {
                    w
                };
                Image::from_fn_par(w, h, |i, j| {
                    let (x0, li) = (i - i % cw, i % cw);
                    let li = li.min(cw - 1 - li);
                    let lj = j.min(h - 1 - j);
                    self.texel_solid_angle(x0 + li, lj)
                })
            }
            _ => Image::from_fn_par(w, h, |i, j| self.texel_solid_angle(i, j)),
        }
    }
}

/// Bilinear taps in a lat-long map: columns wrap, rows clamp at the poles.
fn latlong_taps(ll: &LatLong, d: DVec3) -> Taps {
    let (w, h) = (ll.width, ll.height);
    let (u, v) = LatLong::dir_to_uv(d);
    let fx = u * w as f64 - 0.5;
    let fy = (v * h as f64 - 0.5).clamp(0.0, (h - 1) as f64);
    let x0 = fx.floor();
    let tx = fx - x0;
    let i0 = if x0 < 0.0 {
        w - 1
    } else {
        (x0 as usize).min(w - 1)
    };
    let i1 = if i0 + 1 == w { 0 } else { i0 + 1 };
    let j0 = fy.floor() as usize;
    let ty = fy - j0 as f64;
    let j1 = (j0 + 1).min(h - 1);
    let mut taps = Taps::default();
    taps.push(j0 * w + i0, (1.0 - tx) * (1.0 - ty));
    taps.push(j0 * w + i1, tx * (1.0 - ty));
    taps.push(j1 * w + i0, (1.0 - tx) * ty);
    taps.push(j1 * w + i1, tx * ty);
    taps
}

/// The four bilinear corners `(column, row, weight)` of continuous texel coordinates `(fx, fy)`
/// (texel centres at integers), clamped to a `width` x `height` grid.
pub(crate) fn bilinear_corners(
    fx: f64,
    fy: f64,
    width: usize,
    height: usize,
) -> [(usize, usize, f64); 4] {
    let fx = fx.clamp(0.0, width.saturating_sub(1) as f64);
    let fy = fy.clamp(0.0, height.saturating_sub(1) as f64);
    let (i0, j0) = (fx.floor() as usize, fy.floor() as usize);
    let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
    let i1 = (i0 + 1).min(width.saturating_sub(1));
    let j1 = (j0 + 1).min(height.saturating_sub(1));
    [
        (i0, j0, (1.0 - tx) * (1.0 - ty)),
        (i1, j0, tx * (1.0 - ty)),
        (i0, j1, (1.0 - tx) * ty),
        (i1, j1, tx * ty),
    ]
}

/// Up to eight (pixel index, weight) pairs: a bilinear look-up, or two blended ones.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Taps {
    idx: [usize; 8],
    w: [f64; 8],
    n: usize,
}

impl Taps {
    /// Adds a tap (ignored beyond eight).
    pub(crate) fn push(&mut self, idx: usize, w: f64) {
        if self.n < 8 {
            self.idx[self.n] = idx;
            self.w[self.n] = w;
            self.n += 1;
        }
    }

    /// Whether there are no taps.
    pub(crate) fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The taps with weights scaled to sum to 1 (unchanged if they sum to 0).
    pub(crate) fn normalised(mut self) -> Self {
        let sum: f64 = self.w[..self.n].iter().sum();
        if sum > 0.0 {
            for w in &mut self.w[..self.n] {
                *w /= sum;
            }
        }
        self
    }

    /// The `(index, weight)` pairs.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.idx[..self.n]
            .iter()
            .copied()
            .zip(self.w[..self.n].iter().copied())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;
    use crate::mapping::CubeLayout;

    fn all_mappings() -> Vec<(Mapping, usize, usize)> {
        vec![
            (Mapping::LatLong, 64, 32),
            (Mapping::Angular, 48, 48),
            (Mapping::MirrorBall, 47, 47),
            (Mapping::Cube(CubeLayout::HorizontalCross), 64, 48),
            (Mapping::Cube(CubeLayout::VerticalCross), 48, 64),
            (Mapping::Cube(CubeLayout::HorizontalStrip), 96, 16),
            (Mapping::Fisheye { fov_deg: 360.0 }, 40, 40),
            (Mapping::DualFisheye { fov_deg: 195.0 }, 80, 40),
        ]
    }

    #[test]
    fn pixel_dir_and_inverse_agree() {
        for (m, w, h) in all_mappings() {
            let p = Projection::new(m, w, h).unwrap();
            let mut checked = 0;
            for j in 0..h {
                for i in 0..w {
                    let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
                    let Some((d, density)) = p.pixel_dir(x, y) else {
                        continue;
                    };
                    assert!((d.length() - 1.0).abs() < 1e-12 && density > 0.0);
                    let (x2, y2) = p.dir_to_pixel(d).unwrap();
                    let (d2, _) = p.pixel_dir(x2, y2).unwrap();
                    assert!(
                        d.dot(d2) > 1.0 - 1e-12,
                        "{m:?} ({i}, {j}) {d} {d2} {x2} {y2}"
                    );
                    checked += 1;
                }
            }
            assert!(checked >= w * h / 2, "{m:?}");
        }
    }

    #[test]
    fn densities_integrate_to_texel_solid_angles() {
        for (m, w, h) in all_mappings() {
            if matches!(m, Mapping::DualFisheye { .. }) {
                continue; // its texel solid angles carry blend weights
            }
            let p = Projection::new(m, w, h).unwrap();
            let omega = p.texel_solid_angles();
            let n = 16;
            for &(i, j) in &[(w / 2, h / 2), (w / 3, h / 5), (1, h / 2)] {
                let mut sum = 0.0;
                for q in 0..n {
                    for s in 0..n {
                        let x = i as f64 + (s as f64 + 0.5) / n as f64;
                        let y = j as f64 + (q as f64 + 0.5) / n as f64;
                        sum += p.pixel_dir(x, y).map_or(0.0, |(_, dens)| dens);
                    }
                }
                sum /= (n * n) as f64;
                let exact = *omega.get(i, j);
                assert!(
                    (sum - exact).abs() <= 2e-3 * exact + 1e-9,
                    "{m:?} ({i},{j}) {sum} {exact}"
                );
            }
        }
    }
}
