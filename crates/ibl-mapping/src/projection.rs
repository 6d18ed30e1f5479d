//! A [`Mapping`] bound to an image size ([`Projection`]): the per-sample geometry used by
//! resampling, power, the renderer and the viewer, so that every consumer samples any mapping
//! the same way, and the `Mapping` methods that need it (`pixel_dir`, `dir_to_pixel`,
//! `texel_solid_angles`, `check_shape`).
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
use ibl_core::{Image, LatLong, Rgb};

use crate::cube::{self, CubeImage};
use crate::disc::{Disc, Profile};
use crate::error::MappingError;
use crate::fisheye::DualFisheye;
use crate::mapping::Mapping;
use crate::taps::Taps;

/// A mapping with a validated image size: every query is O(1) and allocation-free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection(pub(crate) Geometry);

/// The geometry of each kind of mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Geometry {
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
    pub fn new(mapping: Mapping, width: usize, height: usize) -> Result<Self, MappingError> {
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
                Ok(Projection(Geometry::Disc(Disc::new(
                    profile, 1.0, sz, 0, width, height,
                ))))
            } else {
                Err(shape(mapping, width, height, "needs a square image"))
            }
        };
        match mapping {
            Mapping::LatLong => Ok(Projection(Geometry::LatLong(LatLong::new(width, height)))),
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
                    Ok(Projection(Geometry::Dual(DualFisheye::new(
                        height,
                        f64::from(fov_deg).to_radians() / 2.0,
                    ))))
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
                Some(size) => Ok(Projection(Geometry::Cube(CubeImage::new(layout, size)))),
                None => Err(cube::shape_error(layout, width, height)),
            },
        }
    }

    /// Image width in pixels.
    pub fn width(&self) -> usize {
        match &self.0 {
            Geometry::LatLong(ll) => ll.width,
            Geometry::Disc(d) => d.cw,
            Geometry::Dual(d) => 2 * d.front.cw,
            Geometry::Cube(c) => c.layout.grid().0 * c.size,
        }
    }

    /// Image height in pixels.
    pub fn height(&self) -> usize {
        match &self.0 {
            Geometry::LatLong(ll) => ll.height,
            Geometry::Disc(d) => d.h,
            Geometry::Dual(d) => d.front.h,
            Geometry::Cube(c) => c.layout.grid().1 * c.size,
        }
    }

    fn inside_image(&self, x: f64, y: f64) -> bool {
        x >= 0.0 && y >= 0.0 && x <= self.width() as f64 && y <= self.height() as f64
    }

    /// Unit direction and solid-angle density (sr per unit pixel area) at continuous image
    /// coordinates; `None` outside the domain.
    pub fn pixel_dir(&self, x: f64, y: f64) -> Option<(DVec3, f64)> {
        if !self.inside_image(x, y) {
            return None;
        }
        match &self.0 {
            Geometry::LatLong(ll) => {
                let (w, h) = (ll.width as f64, ll.height as f64);
                let v = y / h;
                let density = (PI * v).sin() * (TAU / w) * (PI / h);
                Some((LatLong::uv_to_dir64(x / w, v), density))
            }
            Geometry::Disc(d) => {
                let (a, b) = d.disc_coords(x, y);
                d.dir_density(a, b)
            }
            Geometry::Dual(dual) => {
                let lens = dual.lens_at(x);
                let (a, b) = lens.disc_coords(x, y);
                lens.dir_density(a, b)
            }
            Geometry::Cube(c) => c.dir_density(x, y),
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
        let lens = match &self.0 {
            Geometry::Disc(d) => d,
            Geometry::Dual(dual) => dual.lens_at(x),
            _ => return self.pixel_dir(x, y).map(|(d, _)| d),
        };
        if !lens.texel_in_disc(i - lens.x0, j) {
            return None;
        }
        let (a, b) = lens.disc_coords(x, y);
        lens.clamped_dir(a, b)
    }

    /// Continuous image coordinates of a unit direction; `None` where the mapping does not see it.
    pub fn dir_to_pixel(&self, d: DVec3) -> Option<(f64, f64)> {
        match &self.0 {
            Geometry::LatLong(ll) => {
                let (u, v) = LatLong::dir_to_uv(d);
                Some((u * ll.width as f64, v * ll.height as f64))
            }
            Geometry::Disc(disc) => disc.pixel_of_dir(d),
            Geometry::Dual(dual) => dual.pixel_of_dir(d),
            Geometry::Cube(c) => Some(c.pixel_of_dir(d)),
        }
    }

    /// A texel's solid angle near unit direction `d` (an estimate of the local resolution, used
    /// to choose the supersampling rate); 0 where the mapping does not see `d`.
    pub(crate) fn texel_solid_angle_near(&self, d: DVec3) -> f64 {
        match &self.0 {
            Geometry::LatLong(ll) => {
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
    pub fn taps(&self, d: DVec3) -> Taps {
        match &self.0 {
            Geometry::LatLong(ll) => latlong_taps(ll, d),
            Geometry::Disc(disc) => match disc.pixel_of_dir(d) {
                Some((x, y)) => disc.taps(disc.cw, x, y),
                None => Taps::default(),
            },
            Geometry::Dual(dual) => dual.taps(2 * dual.front.cw, d),
            Geometry::Cube(c) => c.taps(d),
        }
    }

    /// Exact solid angle of pixel `(i, j)` (see [`Mapping::texel_solid_angles`]).
    pub fn texel_solid_angle(&self, i: usize, j: usize) -> f64 {
        match &self.0 {
            Geometry::LatLong(ll) => ll.row_solid_angle(j),
            Geometry::Disc(d) => d.texel_solid_angle(i, j),
            Geometry::Dual(dual) => dual.texel_solid_angle(i, j),
            Geometry::Cube(c) => c.texel_solid_angle(i, j),
        }
    }

    /// Bilinear radiance of `image` (this projection's size; black otherwise) towards unit
    /// direction `d`: the [`Projection::taps`] gathered. Black where the mapping does not see
    /// `d`.
    pub fn sample(&self, image: &Image<Rgb>, d: DVec3) -> Rgb {
        if (image.width(), image.height()) != (self.width(), self.height()) {
            return Rgb::ZERO;
        }
        self.taps(d).gather(image.pixels())
    }

    /// Exact solid angles of every pixel, rows in parallel; disc images compute one quadrant and
    /// mirror it (the disc is symmetric about both axes of the cell). Cost O(W H).
    pub fn texel_solid_angles(&self) -> Image<f64> {
        let (w, h) = (self.width(), self.height());
        match &self.0 {
            Geometry::Disc(_) | Geometry::Dual(_) => {
                // Mirror within the cell: column i of a cell of width cw equals column cw-1-i.
                let cw = if let Geometry::Dual(d) = &self.0 {
                    d.front.cw
                } else {
                    w
                };
                // Each cell's top-left quadrant once (a quarter of the exact integrals), then
                // every texel read from it.
                let (qw, qh) = (cw.div_ceil(2), h.div_ceil(2));
                let cells = w / cw.max(1);
                let quadrants = Image::from_fn_par(qw * cells, qh, |qi, j| {
                    let (cell, li) = (qi / qw, qi % qw);
                    self.texel_solid_angle(cell * cw + li, j)
                });
                Image::from_fn_par(w, h, |i, j| {
                    let (cell, li) = (i / cw, i % cw);
                    let li = li.min(cw - 1 - li);
                    let lj = j.min(h - 1 - j);
                    *quadrants.get(cell * qw + li, lj)
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

/// The largest all-zero image [`Mapping::texel_solid_angles`] returns for an invalid shape.
const MAX_ZERO_PIXELS: usize = 1 << 28;

impl Mapping {
    /// Whether a `width` x `height` image can hold this mapping (and its parameters are valid).
    pub fn check_shape(&self, width: usize, height: usize) -> Result<(), MappingError> {
        Projection::new(*self, width, height).map(|_| ())
    }

    /// The unit direction shown at continuous image coordinates `(x, y)` of a `width x height`
    /// image (pixel (i, j)'s centre is `(i + 0.5, j + 0.5)`). `None` outside the valid domain:
    /// outside the image, outside the disc, in an unused cross cell, or when the shape or
    /// parameters are invalid.
    pub fn pixel_dir(&self, width: usize, height: usize, x: f64, y: f64) -> Option<DVec3> {
        let p = Projection::new(*self, width, height).ok()?;
        p.pixel_dir(x, y).map(|(d, _)| d)
    }

    /// The continuous image coordinates showing direction `d` (need not be unit length); the
    /// inverse of [`Mapping::pixel_dir`]. `None` for a zero or non-finite `d`, a direction a
    /// fisheye does not see, or an invalid shape. For dual fisheye the lens with the larger
    /// blend weight is chosen (the front lens on a tie).
    pub fn dir_to_pixel(&self, width: usize, height: usize, d: DVec3) -> Option<(f64, f64)> {
        let p = Projection::new(*self, width, height).ok()?;
        if !d.is_finite() || d.length_squared() == 0.0 {
            return None;
        }
        p.dir_to_pixel(d.normalize())
    }

    /// The solid angle (sr) of every pixel, 0 outside the domain. Exact closed forms: lat-long
    /// rows (CONVENTIONS section 4), cube texels (`atan2(xy, sqrt(x^2 + y^2 + 1))` at the
    /// corners), and disc texels clipped to the disc by Green's theorem (see [`crate::disc`]).
    /// The total is 4 pi for every mapping that covers the sphere (to about 1e-12), `2 pi (1 -
    /// cos(fov/2))` for a fisheye under 360 degrees. Dual fisheye counts every direction once:
    /// each pixel's solid angle is weighted by its lens' blend weight (the same feathered weights
    /// used when converting from dual fisheye), so the overlap of two lenses wider than 180
    /// degrees is not counted twice. An invalid shape gives an all-zero image of the requested
    /// size (0 x 0 beyond 2^28 pixels). Cost O(W H).
    pub fn texel_solid_angles(&self, width: usize, height: usize) -> Image<f64> {
        match Projection::new(*self, width, height) {
            Ok(p) => p.texel_solid_angles(),
            Err(_) => match width.checked_mul(height).filter(|&n| n <= MAX_ZERO_PIXELS) {
                Some(n) => Image::from_vec(width, height, vec![0.0; n])
                    .unwrap_or_else(|_| Image::from_fn_par(0, 0, |_, _| 0.0)),
                None => Image::from_fn_par(0, 0, |_, _| 0.0),
            },
        }
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
            (Mapping::Cube(CubeLayout::VerticalStrip), 16, 96),
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
