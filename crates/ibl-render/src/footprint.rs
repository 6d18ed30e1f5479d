//! The mean of a piecewise-constant lat-long probe over the footprint of one pinhole pixel: what
//! the camera sees through a pixel where it sees no geometry.
//!
//! A pinhole pixel `[x, x + 1) x [y, y + 1)` looks at the directions `d(x', y')` of its camera
//! rays; its value is the mean over the pixel's area of `L(d(x', y'))`, `L` the probe's radiance,
//! constant over each texel (the nearest-texel convention of [`crate::environment`]), so it is
//! `sum_texels L_texel * (the share of the pixel's area whose rays fall in the texel)`. The shares
//! are computed in the image plane, where the weighting is uniform: the unnormalised ray
//! direction `d = world_from_camera ((x' - cx) / fx, -(y' - cy) / fy, -1)` is an affine function
//! of the pixel coordinates, so the pixel is a parallelogram of such vectors (the plane
//! `d . forward = 1`, probe frame), and each texel is cut out of it by four constraints:
//!
//! - its two meridians `phi = phi_i`: the half-spaces `n_i . d >= 0` with
//!   `n_i = (cos phi_i, 0, sin phi_i)` (probe frame; valid within a half-turn of `phi_i`), linear in
//!   `d`, so clipping the parallelogram by them is exact (meridians are straight lines in a
//!   pinhole image);
//! - its two parallels `theta = theta_j`: `cos(theta_j) |d| - d_y >= 0`, a cone, whose trace on the
//!   image plane is a conic, cut along the chord between the points where it crosses the
//!   polygon's edges (found by linear interpolation of the constraint along each edge). Across one
//!   pixel the conic's sagitta is a few 1e-6 of the pixel away from the poles.
//!
//! Each piece is clipped with Sutherland and Hodgman's algorithm (1974) and measured by the
//! vector shoelace formula; the shares sum to 1 up to rounding. Longitudes are unwrapped next to
//! the pixel's first corner, so the seam at `u = 0` costs nothing. A pixel whose corners span more
//! than a quarter of the longitudes (it surrounds or nearly touches a pole, where meridians
//! converge) is split into four, up to [`MAX_DEPTH`] times; a cell still that wide takes the
//! radiance at its centre ray.
//!
//! Cost: O(texels covered) clips per pixel; one pixel covers a few texels at the example scenes'
//! sizes, and a pixel provably inside one texel takes it without clipping
//! (`PixelFootprint::parallels_bulge`). Each pixel corner's ray is computed once for the four
//! pixels that share it ([`PixelFootprint::image`]).

use glam::{DVec3, Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_scene::Camera;
use rayon::prelude::*;

/// Largest number of splits of a pixel around a pole (a pixel becomes at most `4^MAX_DEPTH`
/// cells there).
pub const MAX_DEPTH: u32 = 5;

/// The probe seen through the pixels of a pinhole camera.
pub struct PixelFootprint<'a> {
    probe: &'a Image<Rgb>,
    camera: &'a Camera,
    probe_from_world: Mat3,
    /// The camera's viewing direction, world frame (`d . forward = 1` is the image plane).
    forward: Vec3,
    size: (u32, u32),
    /// [`PixelFootprint::parallel_cos`] of rows `0..=H`, computed once.
    parallel_cos: Vec<f64>,
    /// [`PixelFootprint::meridian_normal`] of columns `-W - 2 .. 2 W + 3` (every column a
    /// footprint's unwrapped longitudes reach), computed once.
    meridian_normals: Vec<DVec3>,
}

/// The corner of a pixel (or cell): its ray direction on the image plane and its texel
/// coordinates.
#[derive(Clone, Copy)]
struct Corner {
    direction: DVec3,
    coords: (f64, f64),
}

/// Polygons a footprint's clipping reuses from pixel to pixel (no allocation per pixel).
#[derive(Default)]
struct Scratch {
    row: Vec<DVec3>,
    piece: Vec<DVec3>,
    clipped: Vec<DVec3>,
}

impl<'a> PixelFootprint<'a> {
    /// The integrator for `probe` (lat-long, probe frame) seen through `camera` at a
    /// `width x height` output, `world_from_probe` the probe's orientation. The forward direction
    /// of a panorama camera is taken as its ray through the image centre (it is not a pinhole:
    /// use [`crate::background::area_resize`] there).
    pub fn new(
        probe: &'a Image<Rgb>,
        camera: &'a Camera,
        world_from_probe: Mat3,
        width: u32,
        height: u32,
    ) -> Self {
        let forward = match *camera {
            Camera::Pinhole {
                world_from_camera, ..
            } => -world_from_camera.z_axis,
            Camera::Panorama { .. } => {
                camera
                    .ray(0.5 * width as f32, 0.5 * height as f32, width, height)
                    .direction
            }
        };
        let (w, h) = (probe.width() as i64, probe.height() as i64);
        PixelFootprint {
            probe,
            camera,
            probe_from_world: world_from_probe.transpose(),
            forward,
            size: (width, height),
            parallel_cos: (0..=h).map(|j| parallel_cos(j, h)).collect(),
            meridian_normals: (-w - 2..2 * w + 3).map(|i| meridian_normal(i, w)).collect(),
        }
    }

    /// The mean radiance over every pixel, row by row in parallel: each pixel corner's ray is
    /// computed once (shared by four pixels), the clipping polygons reused along a row.
    pub fn image(&self) -> Image<Rgb> {
        let (w, h) = (self.size.0 as usize, self.size.1 as usize);
        // Corners of row `y` of the grid of (w + 1) x (h + 1) pixel corners.
        let corner_row = |y: usize| -> Vec<Corner> {
            (0..=w).map(|x| self.corner(x as f64, y as f64)).collect()
        };
        let grid: Vec<Vec<Corner>> = (0..=h).into_par_iter().map(corner_row).collect();
        let data: Vec<Rgb> = (0..h)
            .into_par_iter()
            .flat_map_iter(|y| {
                let mut scratch = Scratch::default();
                let (top, bottom) = (&grid[y], &grid[y + 1]);
                (0..w)
                    .map(|x| {
                        let corners = [top[x], top[x + 1], bottom[x + 1], bottom[x]];
                        let sum = self.cell_of(corners, x as f64, y as f64, 1.0, 0, &mut scratch);
                        Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        Image::from_vec(w, h, data).expect("one value per pixel")
    }

    /// The ray direction through continuous output pixel coordinates `(x, y)`, probe frame,
    /// scaled onto the image plane `d . forward = 1` (affine in `(x, y)`).
    fn direction(&self, x: f64, y: f64) -> DVec3 {
        let d = self
            .camera
            .ray(x as f32, y as f32, self.size.0, self.size.1)
            .direction;
        let scaled = d.as_dvec3() / f64::from(d.dot(self.forward)).max(1e-12);
        (self.probe_from_world.as_dmat3()) * scaled
    }

    /// Continuous texel coordinates `(s, t)` of a direction (`s` in `[0, W)`, `t` in `[0, H]`).
    fn texel_coords(&self, d: DVec3) -> (f64, f64) {
        let (u, v) = LatLong::dir_to_uv(d);
        (
            u * self.probe.width() as f64,
            v * self.probe.height() as f64,
        )
    }

    /// A cell corner at continuous output pixel coordinates `(x, y)`.
    fn corner(&self, x: f64, y: f64) -> Corner {
        let direction = self.direction(x, y);
        Corner {
            direction,
            coords: self.texel_coords(direction),
        }
    }

    /// The mean over the square cell `[x, x + size) x [y, y + size)` (output pixel coordinates).
    fn cell(&self, x: f64, y: f64, size: f64, depth: u32, scratch: &mut Scratch) -> [f64; 3] {
        let corners = [
            self.corner(x, y),
            self.corner(x + size, y),
            self.corner(x + size, y + size),
            self.corner(x, y + size),
        ];
        self.cell_of(corners, x, y, size, depth, scratch)
    }

    /// [`PixelFootprint::cell`] with its `corners` (clockwise from `(x, y)`) given.
    fn cell_of(
        &self,
        corners: [Corner; 4],
        x: f64,
        y: f64,
        size: f64,
        depth: u32,
        scratch: &mut Scratch,
    ) -> [f64; 3] {
        let (w, h) = (self.probe.width() as f64, self.probe.height() as f64);
        let coords = corners.map(|c| c.coords);
        let corners = corners.map(|c| c.direction);
        let s0 = coords[0].0;
        let unwrapped = coords.map(|(s, t)| {
            let mut ds = s - s0;
            ds -= w * (ds / w).round();
            (s0 + ds, t)
        });
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for (s, t) in unwrapped {
            lo = (lo.0.min(s), lo.1.min(t));
            hi = (hi.0.max(s), hi.1.max(t));
        }
        if hi.0 - lo.0 > 0.25 * w {
            if depth < MAX_DEPTH {
                let half = 0.5 * size;
                let mut sum = [0.0f64; 3];
                for (dx, dy) in [(0.0, 0.0), (half, 0.0), (0.0, half), (half, half)] {
                    let part = self.cell(x + dx, y + dy, half, depth + 1, scratch);
                    for k in 0..3 {
                        sum[k] += 0.25 * part[k];
                    }
                }
                return sum;
            }
            // Around a pole: the radiance seen through the cell's centre.
            let (s, t) = self.texel_coords(self.direction(x + 0.5 * size, y + 0.5 * size));
            return self.texel(s.floor() as i64, t.floor() as i64);
        }
        let total = area(&corners);
        if total.is_nan() || total <= 0.0 {
            return self.texel(s0.floor() as i64, coords[0].1.floor() as i64);
        }
        // Meridians are straight lines in the image and a cell that holds no pole spans the
        // columns of its corners; the parallels are conics, whose chords may bulge past the
        // corners' rows by up to `bulge` rows (one row of margin where it is not known).
        let bulge = self.parallels_bulge(&corners, lo, hi);
        let margin = |distance: f64| match bulge {
            Some(bulge) if distance > bulge => 0,
            _ => 1,
        };
        let (i0, i1) = (lo.0.floor() as i64, hi.0.floor() as i64);
        let (j0, j1) = (
            (lo.1.floor() as i64 - margin(lo.1 - lo.1.floor())).max(0),
            (hi.1.floor() as i64 + margin(hi.1.floor() + 1.0 - hi.1)).min(h as i64 - 1),
        );
        if i0 == i1 && j0 == j1 {
            // One texel holds the whole cell (most pixels of a view finer than the probe).
            return self.texel(i0, j0);
        }
        let mut sum = [0.0f64; 3];
        let Scratch {
            row,
            piece,
            clipped,
        } = scratch;
        for j in j0..=j1 {
            let (c0, c1) = (
                self.parallel_cos[j as usize],
                self.parallel_cos[j as usize + 1],
            );
            // theta >= theta_j (c0 |d| - d_y >= 0) and theta <= theta_(j+1).
            clip(&corners, |d| c0 * d.length() - d.y, clipped);
            clip(clipped, |d| d.y - c1 * d.length(), row);
            if row.len() < 3 {
                continue;
            }
            for i in i0..=i1 {
                let (n0, n1) = (self.meridian(i), self.meridian(i + 1));
                clip(row, |d| n0.dot(d), clipped);
                clip(clipped, |d| -n1.dot(d), piece);
                if piece.len() < 3 {
                    continue;
                }
                let share = area(piece) / total;
                let l = self.texel(i, j);
                for k in 0..3 {
                    sum[k] += share * l[k];
                }
            }
        }
        sum
    }

    /// How far, in texel rows, the parallels' chords between a cell's `corners` (unwrapped
    /// texel coordinates spanning `lo..hi`) can stray past the corners' rows: twice the bulge
    /// `l^2 |cot theta| / 8` of a great-circle edge of length `l` (radians) next to the parallel
    /// at polar angle `theta` (its geodesic curvature is `cot theta`), at the parallel nearest a
    /// pole that the cell's rows touch. `None` (not known: a row of margin) for rows at a pole
    /// and for edges over 0.1 radians.
    fn parallels_bulge(&self, corners: &[DVec3; 4], lo: (f64, f64), hi: (f64, f64)) -> Option<f64> {
        use std::f64::consts::PI;
        let h = self.probe.height() as f64;
        let (top, bottom) = (lo.1.floor(), hi.1.floor() + 1.0);
        if top < 1.0 || bottom + 1.0 > h {
            return None;
        }
        let unit = corners.map(|d| d.normalize());
        let chord = (0..4)
            .map(|k| (unit[k] - unit[(k + 1) % 4]).length())
            .fold(0.0f64, f64::max);
        // An arc's angle is 2 asin(c / 2) <= 1.001 c for chords c below 0.1.
        if chord.is_nan() || chord >= 0.1 {
            return None;
        }
        let length = 1.001 * chord;
        let cot = |row: f64| {
            let c = self.parallel_cos[row as usize];
            (c / (1.0 - c * c).sqrt()).abs()
        };
        let bulge_rows = 2.0 * length * length * cot(top).max(cot(bottom)) / 8.0 * h / PI;
        Some(bulge_rows + 1e-9)
    }

    /// The meridian normal of column `i`: from the table where it covers `i`, else computed
    /// (the same value either way).
    fn meridian(&self, i: i64) -> DVec3 {
        let w = self.probe.width() as i64;
        usize::try_from(i + w + 2)
            .ok()
            .and_then(|k| self.meridian_normals.get(k).copied())
            .unwrap_or_else(|| meridian_normal(i, w))
    }

    /// The radiance of texel `(i, j)`, column wrapped, row clamped, in f64.
    fn texel(&self, i: i64, j: i64) -> [f64; 3] {
        let (w, h) = (self.probe.width() as i64, self.probe.height() as i64);
        let l = self
            .probe
            .get(i.rem_euclid(w) as usize, j.clamp(0, h - 1) as usize);
        [f64::from(l.r), f64::from(l.g), f64::from(l.b)]
    }
}

/// `cos(theta_j)`, `theta_j = pi j / H` the polar angle of the top of texel row `j` of a probe
/// `H` texels high.
fn parallel_cos(j: i64, height: i64) -> f64 {
    (std::f64::consts::PI * j as f64 / height as f64).cos()
}

/// The normal `(cos phi_i, 0, sin phi_i)` of the meridian plane at the left edge of column `i`
/// (any integer: columns repeat every `W`) of a probe `W` texels wide, pointing towards
/// increasing `phi`.
fn meridian_normal(i: i64, width: i64) -> DVec3 {
    let phi = std::f64::consts::TAU * (i as f64 / width as f64 - 0.5);
    DVec3::new(phi.cos(), 0.0, phi.sin())
}

/// Area of a planar polygon of 3-D points (half the length of the vector shoelace sum).
fn area(p: &[DVec3]) -> f64 {
    let mut sum = DVec3::ZERO;
    for k in 0..p.len() {
        sum += p[k].cross(p[(k + 1) % p.len()]);
    }
    0.5 * sum.length()
}

/// The part of `poly` where `inside(p) >= 0`, into `out` (one Sutherland-Hodgman step; the
/// crossing point on an edge by linear interpolation of `inside`, exact for a linear `inside`).
fn clip(poly: &[DVec3], inside: impl Fn(DVec3) -> f64, out: &mut Vec<DVec3>) {
    out.clear();
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (fa, fb) = (inside(a), inside(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn the_image_is_each_pixel_alone_bit_for_bit() {
        // Shared corners, tables and reused polygons change nothing: every pixel as `cell` computes
        // it alone, for a view across the seam and one around the north pole (split cells).
        let probe = Image::from_fn_par(64, 32, |x, y| {
            Rgb::new(
                x as f32 + 0.25,
                y as f32 * 1.5,
                ((x * 7 + y * 3) % 11) as f32,
            )
        });
        let (w, h) = (24u32, 18u32);
        for target in [Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.01, 1.0, 0.02)] {
            let up = if target.y > 0.5 { Vec3::Z } else { Vec3::Y };
            let camera = Camera::look_at(
                Vec3::ZERO,
                target,
                up,
                Vec2::splat(14.0),
                Vec2::new(12.0, 9.0),
                (w, h),
            );
            let footprint = PixelFootprint::new(&probe, &camera, Mat3::IDENTITY, w, h);
            let image = footprint.image();
            for y in 0..h {
                for x in 0..w {
                    let sum =
                        footprint.cell(f64::from(x), f64::from(y), 1.0, 0, &mut Scratch::default());
                    let alone = Rgb::new(sum[0] as f32, sum[1] as f32, sum[2] as f32);
                    assert_eq!(
                        *image.get(x as usize, y as usize),
                        alone,
                        "pixel ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn clipping_a_square_into_strips_keeps_its_area() {
        let square = [
            DVec3::new(0.5, 0.25, 1.0),
            DVec3::new(2.5, 0.25, 1.0),
            DVec3::new(2.5, 1.75, 1.0),
            DVec3::new(0.5, 1.75, 1.0),
        ];
        let (mut strip, mut scratch) = (Vec::new(), Vec::new());
        let mut total = 0.0;
        for i in 0..3 {
            let lo = f64::from(i);
            clip(&square, |d| d.x - lo, &mut scratch);
            clip(&scratch, |d| lo + 1.0 - d.x, &mut strip);
            total += area(&strip);
        }
        assert!((area(&square) - 3.0).abs() < 1e-12);
        assert!((total - 3.0).abs() < 1e-12);
    }
}
