//! The probe's pixels nearest each light: its **cell**, the region of the sphere (a cell of the
//! spherical Voronoi diagram of the light directions) whose radiance the light stands for, and
//! the source that sizes its soft shadow.
//!
//! A fitted light (irradiance optimisation) has a direction and a power but no pixels: the fit
//! works on irradiance, and the paper gives every light the same small disc `A` (Madsen &
//! Laursen 2006, section 4.4). Shadowed by that disc, 256 fitted lights render an indoor probe's
//! broad windows as 256 hard shadows. Given its cell, a fitted light is sized as a LightGen
//! cluster is (a cluster is the pixels nearest its centre, the same kind of cell): its source
//! solid angle is the cell's, its spread ([`ibl_light::spread`]) is the half-energy cone of the
//! cell's power about the light's direction, and its core fraction fits the cell's power to a
//! core and a halo ([`WIDEST_CORE_IN_A_CLUSTER`]). The light's power `I` is the fit's; its
//! radiance becomes `I / Omega_cell`.
//!
//! # Cores at their centroids
//! A fitted light stands where its cosine lobe helps the unshadowed irradiance, which need not be
//! where its source is. On the sky probe, 256 fitted lights split the sun between two lights 1
//! degree apart (the sun's pixels hold half their energy within 0.43 degrees of their centroid),
//! each with a 0.4-degree core about its own direction: two discs side by side, a penumbra twice
//! as long one way as the sun's. Irradiance cannot tell, a shadow can: 256 such lights scored
//! 1.18x the reference's noise floor on bunny-sky where median cut's scored 1.03x, the
//! difference all in the sun's shadow (8 x 8 block maps). So [`aim_cores_at_their_centroids`]
//! moves each light with a core and a halo (`core_fraction < 1`: a concentrated source in its
//! cell) to the energy centroid of its core's pixels, its cell's pixels within its core's cone
//! (not its whole cell's: at 16 lights the sun's cell holds 0.8 sr of sky, whose centroid lies
//! degrees off the sun, and moving there took bunny-sky's 16 lights from 2.5x to 2.9x). The
//! moves are small (0.1 to 0.2 degrees for the two sun lights at 256, 0.08 degrees for the sun's
//! at 16, up to 3.7 degrees for broad lights with a halo at 16), the cells are sized again, and
//! the powers are solved for the lights where they stand (`hemispheres`). Converged, bunny-sky at
//! 256 lights: 1.18x -> 1.05x (median cut 1.03x); at 16 / 32 / 64 on both scenes every figure
//! as good or better (BENCHMARKS.md, "Cores at their centroids").
//!
//! # Cost
//! The nearest light of each pixel is found exactly without testing every light: the probe is cut
//! into tiles of [`TILE`] x [`TILE`] pixels, each with a centre direction `c` and the largest angle
//! `r` from `c` to one of its pixel centres. With `a` the angle from `c` to its nearest light, a
//! pixel's nearest light is within `a + 2 r` of `c` (triangle inequality: the pixel is within `r`
//! of `c`, its nearest light within `a + r` of the pixel), so only those lights are tested. Cost
//! O(W H k + T N) for `k` candidates a tile and `T` tiles; the tiles are taken a row of tiles at
//! a time in parallel and their histograms merged in row order, so the result does not depend on
//! the thread count. Ties go to the lower light index, as a scan of every light would give.

use glam::DVec3;
use ibl_core::{Image, Rgb};
use ibl_light::Light;
use ibl_light::spread::{SpreadHistogram, WIDEST_CORE_IN_A_CLUSTER};
use rayon::prelude::*;

use crate::region_stats::{Grid, core_fraction, each_pixel, light};

/// Side of a tile, pixels.
const TILE: usize = 16;

/// Margin added to the candidate angle, radians: it covers the rounding of the dot products and
/// of `acos`, at most about 2e-8 rad (near an angle of 0, where `acos` is steepest: a dot product
/// off by 2e-16 moves `acos(1 - e)` by up to 2e-8).
const MARGIN_RAD: f64 = 1e-7;

/// One light's share of the probe: its cell's solid angle (sr) and its power's histogram about
/// the light's direction.
#[derive(Clone, Debug, Default)]
struct Cell {
    solid_angle_sr: f64,
    histogram: SpreadHistogram,
}

/// The cells of one row of tiles: per light touched, its slot in `cells`.
struct RowCells {
    slot: Vec<u32>,
    cells: Vec<(usize, Cell)>,
}

impl RowCells {
    fn new(lights: usize) -> RowCells {
        RowCells {
            slot: vec![u32::MAX; lights],
            cells: Vec::new(),
        }
    }

    fn cell(&mut self, light: usize) -> &mut Cell {
        if self.slot[light] == u32::MAX {
            self.slot[light] = self.cells.len() as u32;
            self.cells.push((light, Cell::default()));
        }
        &mut self.cells[self.slot[light] as usize].1
    }
}

/// Sizes each of `lights` by its cell of `probe` (lat-long, world frame; see the module doc):
/// sets its `solid_angle_sr` to the cell's, its radiance to `I / Omega_cell`, its spread and its
/// core fraction. A light whose cell holds no pixel, or no energy, keeps its solid angle and gets
/// no spread. Directions need not be unit (they are normalised for the search; a zero or
/// non-finite direction gets no cell). `grid` is `probe`'s ([`Grid::new`]). Cost: module doc.
pub(crate) fn size_by_cells(probe: &Image<Rgb>, grid: &Grid, lights: &mut [Light]) {
    let dirs: Vec<Option<DVec3>> = lights.iter().map(|l| l.direction.try_normalize()).collect();
    if dirs.iter().all(Option::is_none) {
        return;
    }
    let tile_rows: Vec<RowCells> = (0..grid.h.div_ceil(TILE))
        .into_par_iter()
        .map(|t| tile_row(probe, grid, &dirs, t))
        .collect();
    let mut cells = vec![Cell::default(); lights.len()];
    for row in &tile_rows {
        for (k, c) in &row.cells {
            cells[*k].solid_angle_sr += c.solid_angle_sr;
            cells[*k].histogram.merge(&c.histogram);
        }
    }
    for (l, c) in lights.iter_mut().zip(&cells) {
        let spread = c.histogram.spread_sr();
        if c.solid_angle_sr > 0.0 && spread.is_some() {
            let side = l.side;
            *l = light(
                l.direction,
                l.irradiance.to_array(),
                c.solid_angle_sr,
                spread,
                l.region,
            );
            l.core_fraction = core_fraction(&c.histogram, l, WIDEST_CORE_IN_A_CLUSTER);
            l.side = side;
        }
    }
}

/// Aims each of `lights` that has a core and a halo (a concentrated source inside its cell, such
/// as a sun: `core_fraction < 1`, sized by [`size_by_cells`]) at the energy centroid of its
/// core, the pixels of its cell within its core's cone (luminance times pixel solid angle as
/// weights), kept on its side of the horizon where it has one (a centroid across it is
/// projected onto it). A fitted light stands where it helps the irradiance, which need not be
/// where its source is: on the sky probe, 256 fitted lights split the sun between two lights 1
/// degree apart, each with a 0.4-degree core, so the sun's shadow was two discs side by side
/// (module doc, "Cores at their centroids"). Returns whether any light moved; the caller sizes
/// the cells again. Directions need not be unit; `grid` is `probe`'s. Only the rows within the core's angle of the
/// light are read, O(W (rows in reach) N) for the core's pixels' nearest-light test; lights in
/// parallel, each summed in pixel order (results do not depend on the thread count).
pub(crate) fn aim_cores_at_their_centroids(
    probe: &Image<Rgb>,
    grid: &Grid,
    lights: &mut [Light],
) -> bool {
    let dirs: Vec<Option<DVec3>> = lights.iter().map(|l| l.direction.try_normalize()).collect();
    let aims: Vec<Option<DVec3>> = lights
        .par_iter()
        .enumerate()
        .map(|(k, l)| {
            let d = dirs[k]?;
            let spread = l.spread_sr?;
            if !(l.core_fraction? < 1.0 && spread > 0.0) {
                return None;
            }
            let core = core_centroid(probe, grid, &dirs, k, d, spread)?;
            let aim = match l.side {
                Some(side) if core.dot(side.up()) < 0.0 => {
                    (core - core.dot(side.up()) * side.up()).try_normalize()?
                }
                _ => core,
            };
            (aim != d).then_some(aim)
        })
        .collect();
    let mut moved = false;
    for (l, aim) in lights.iter_mut().zip(aims) {
        if let Some(aim) = aim {
            l.direction = aim;
            moved = true;
        }
    }
    moved
}

/// The unit energy centroid of the pixels of light `k`'s cell (nearest light `k` among `dirs`,
/// ties to the lower index) within the cone of solid angle `core_sr` about its unit direction
/// `d`; `None` where they hold no energy.
fn core_centroid(
    probe: &Image<Rgb>,
    grid: &Grid,
    dirs: &[Option<DVec3>],
    k: usize,
    d: DVec3,
    core_sr: f64,
) -> Option<DVec3> {
    let least_cos = 1.0 - (core_sr / std::f64::consts::TAU).min(2.0);
    // Rows whose polar angle lies within the core's half-angle of the light's, with a pixel's
    // height of margin either side.
    let half = least_cos.clamp(-1.0, 1.0).acos();
    let polar = d.y.clamp(-1.0, 1.0).acos();
    let row_height = std::f64::consts::PI / grid.h as f64;
    let row_of = |t: f64| ((t / row_height).floor().max(0.0) as usize).min(grid.h - 1);
    let rows = row_of(polar - half - row_height)..=row_of(polar + half + row_height);
    let mut sum = DVec3::ZERO;
    for j in rows {
        let sr = grid.row_sr[j];
        each_pixel(probe.row(j), grid.clean[j], 0..grid.w, |i, _, y| {
            let p = grid.dir(i, j);
            let own = p.dot(d);
            if own < least_cos || y <= 0.0 || !y.is_finite() {
                return;
            }
            let nearer = dirs.iter().enumerate().any(|(m, other)| {
                other.is_some_and(|o| {
                    let c = p.dot(o);
                    c > own || (c == own && m < k)
                })
            });
            if !nearer {
                sum += y * sr * p;
            }
        });
    }
    sum.try_normalize()
}

/// The cells of tile row `t`: every pixel of rows `t TILE .. (t + 1) TILE` given to its nearest
/// light.
fn tile_row(probe: &Image<Rgb>, grid: &Grid, dirs: &[Option<DVec3>], t: usize) -> RowCells {
    let mut out = RowCells::new(dirs.len());
    let rows = t * TILE..((t + 1) * TILE).min(grid.h);
    let mut candidates: Vec<(usize, DVec3)> = Vec::with_capacity(dirs.len());
    let mut dots: Vec<f64> = Vec::with_capacity(dirs.len());
    for x0 in (0..grid.w).step_by(TILE) {
        let cols = x0..(x0 + TILE).min(grid.w);
        let centre = grid.dir(
            (cols.start + cols.end - 1) / 2,
            (rows.start + rows.end - 1) / 2,
        );
        let mut min_cos: f64 = 1.0;
        for j in rows.clone() {
            for i in cols.clone() {
                min_cos = min_cos.min(centre.dot(grid.dir(i, j)));
            }
        }
        let r = min_cos.clamp(-1.0, 1.0).acos();
        // The centre's cosine to each light (-inf for a light without a direction).
        dots.clear();
        dots.extend(
            dirs.iter()
                .map(|d| d.map_or(f64::NEG_INFINITY, |d| centre.dot(d))),
        );
        let nearest = dots.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let reach = nearest.clamp(-1.0, 1.0).acos() + 2.0 * r + MARGIN_RAD;
        let least_cos = if reach >= std::f64::consts::PI {
            f64::NEG_INFINITY
        } else {
            reach.cos()
        };
        candidates.clear();
        candidates.extend(
            dirs.iter()
                .zip(&dots)
                .enumerate()
                .filter(|(_, (_, c))| **c >= least_cos)
                .filter_map(|(k, (d, _))| d.map(|d| (k, d))),
        );
        for j in rows.clone() {
            let sr = grid.row_sr[j];
            let row = &probe.row(j)[cols.clone()];
            each_pixel(row, grid.clean[j], cols.clone(), |i, _, y| {
                let p = grid.dir(i, j);
                let (mut best, mut best_cos) = (candidates[0].0, f64::NEG_INFINITY);
                for &(k, d) in &candidates {
                    let c = p.dot(d);
                    if c > best_cos {
                        (best, best_cos) = (k, c);
                    }
                }
                let cell = out.cell(best);
                cell.solid_angle_sr += sr;
                cell.histogram.add(1.0 - best_cos, y * sr, sr);
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::rgb::Rgb64;

    fn light(direction: DVec3) -> Light {
        Light {
            direction,
            radiance: Rgb::new(1.0, 1.0, 1.0),
            solid_angle_sr: 2.392e-4,
            irradiance: Rgb64::from_array([2.392e-4; 3]),
            region: None,
            spread_sr: None,
            core_fraction: None,
            side: None,
        }
    }

    fn probe(w: usize, h: usize, f: impl Fn(usize, usize) -> f32 + Sync) -> Image<Rgb> {
        Image::from_fn_par(w, h, |i, j| {
            let v = f(i, j);
            Rgb::new(v, v, v)
        })
    }

    /// The nearest light of every pixel by testing every light (lowest index on ties).
    fn brute_force(grid: &Grid, dirs: &[DVec3]) -> Vec<f64> {
        let mut sr = vec![0.0; dirs.len()];
        for j in 0..grid.h {
            for i in 0..grid.w {
                let p = grid.dir(i, j);
                let mut best = (0, f64::NEG_INFINITY);
                for (k, d) in dirs.iter().enumerate() {
                    if p.dot(*d) > best.1 {
                        best = (k, p.dot(*d));
                    }
                }
                sr[best.0] += grid.row_sr[j];
            }
        }
        sr
    }

    #[test]
    fn the_tiles_find_every_pixels_nearest_light() {
        // 300 lights (Fibonacci, so some lie near tile edges and poles) on a probe whose size is
        // not a multiple of the tile: each cell's solid angle equals the brute-force one's, and
        // the cells cover the sphere (4 pi to rounding).
        let img = probe(200, 100, |_, _| 1.0);
        let dirs = ibl_core::fibonacci_normals(300);
        let mut lights: Vec<Light> = dirs.iter().map(|d| light(*d)).collect();
        let grid = Grid::new(&img).unwrap();
        size_by_cells(&img, &grid, &mut lights);
        let expected = brute_force(&grid, &dirs);
        let mut total = 0.0;
        for (l, e) in lights.iter().zip(&expected) {
            // Summation order differs (tile rows merged): equal to 1e-12 relative.
            assert!(
                (l.solid_angle_sr - e).abs() <= 1e-12 * e,
                "{} vs {e}",
                l.solid_angle_sr
            );
            total += l.solid_angle_sr;
        }
        assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9, "{total}");
    }

    #[test]
    fn a_uniform_probe_gives_each_light_its_cell() {
        // Two opposite lights on a uniform probe: each holds a hemisphere (2 pi sr), radiance
        // I / 2 pi, and a spread of the hemisphere's half-energy cone (1 - cos t_h = 1/2: 2 pi)
        // plus the pixels' mean extent, to the histogram's 9 % (spread module doc).
        let img = probe(64, 32, |_, _| 1.0);
        let mut lights = vec![light(DVec3::Y), light(-DVec3::Y)];
        size_by_cells(&img, &Grid::new(&img).unwrap(), &mut lights);
        for l in &lights {
            let two_pi = 2.0 * std::f64::consts::PI;
            assert!((l.solid_angle_sr - two_pi).abs() < 1e-9);
            assert!((f64::from(l.radiance.g) - 2.392e-4 / two_pi).abs() < 1e-9);
            let s = l.spread_sr.unwrap();
            assert!((s - two_pi).abs() < 0.09 * two_pi, "{s}");
            assert_eq!(l.core_fraction, Some(1.0));
        }
    }

    #[test]
    fn a_sun_in_a_dim_sky_keeps_a_narrow_core_and_a_halo() {
        // One light at a bright 3 x 3 pixel patch of a dim probe: its cell is the whole sphere,
        // its core the patch's extent, and most of the power is in the core.
        let img = probe(128, 64, |i, j| {
            if (63..66).contains(&i) && (20..23).contains(&j) {
                1.0e4
            } else {
                0.1
            }
        });
        let grid = Grid::new(&img).unwrap();
        let mut lights = vec![light(grid.dir(64, 21))];
        size_by_cells(&img, &grid, &mut lights);
        let l = &lights[0];
        assert!((l.solid_angle_sr - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        let patch = 9.0 * grid.row_sr[21];
        assert!(l.spread_sr.unwrap() < 4.0 * patch, "{:?}", l.spread_sr);
        let f = l.core_fraction.unwrap();
        assert!(f > 0.8 && f < 1.0, "{f}");
    }

    #[test]
    fn a_light_without_pixels_or_direction_is_left_as_it_was() {
        // Two lights in one direction: the first takes every pixel (ties to the lower index);
        // the second, and one without a direction, keep the disc they had.
        let img = probe(32, 16, |_, _| 1.0);
        let mut lights = vec![light(DVec3::X), light(DVec3::X), light(DVec3::ZERO)];
        let before = lights.clone();
        size_by_cells(&img, &Grid::new(&img).unwrap(), &mut lights);
        assert!((lights[0].solid_angle_sr - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        assert_eq!(lights[1], before[1]);
        assert_eq!(lights[2], before[2]);
    }

    #[test]
    fn a_light_with_a_core_is_aimed_at_its_cores_centroid() {
        // A 2 x 2-pixel sun (1e4) on a dim sky (0.1), 256 x 128: a light aimed 1.5 degrees off
        // the sun, with the sun inside its core (0.01 sr, half-angle 3.2 degrees) and a halo,
        // is moved onto the sun's centroid (its four pixel centres' energy-weighted mean, the
        // core's sky pixels pull it by 0.0001 degrees, measured: bound 0.05). A light without a
        // halo stays. A light marked as above the horizon whose core's centroid lies below it is
        // moved onto the horizon. Cells are its pixels only: the other light is far away.
        let (w, h) = (256, 128);
        let sun = |i: usize, j: usize| (i == 160 || i == 161) && (j == 40 || j == 41);
        let img = probe(w, h, |i, j| if sun(i, j) { 1e4 } else { 0.1 });
        let grid = Grid::new(&img).unwrap();
        let centre = [(160, 40), (161, 40), (160, 41), (161, 41)]
            .iter()
            .map(|&(i, j)| grid.row_sr[j] * grid.dir(i, j))
            .sum::<DVec3>()
            .normalize();
        let off = (centre + 0.026 * centre.any_orthonormal_vector()).normalize();
        let cored = |d: DVec3, f: Option<f64>| Light {
            spread_sr: Some(0.01),
            core_fraction: f,
            solid_angle_sr: 0.05,
            ..light(d)
        };
        let far = light(-centre);
        let mut lights = vec![cored(off, Some(0.9)), cored(off, None), far];
        assert!(aim_cores_at_their_centroids(
            &img,
            &Grid::new(&img).unwrap(),
            &mut lights
        ));
        let moved = lights[0]
            .direction
            .dot(centre)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees();
        println!(
            "off {:.3} deg, after {moved:.4} deg",
            off.dot(centre).acos().to_degrees()
        );
        assert!(moved < 0.05, "{moved}");
        assert_eq!(lights[1].direction, off);
        assert_eq!(lights[2].direction, -centre);
        // Above the horizon, a core whose light lies below it: mirrored sun below the horizon.
        let img = probe(w, h, |i, j| if sun(i, h - 1 - j) { 1e4 } else { 0.1 });
        let below = DVec3::new(centre.x, -centre.y, centre.z);
        let start = DVec3::new(below.x, 0.01, below.z).normalize();
        let mut lights = vec![Light {
            side: Some(ibl_light::HorizonSide::Above),
            spread_sr: Some(4.0),
            ..cored(start, Some(0.5))
        }];
        aim_cores_at_their_centroids(&img, &Grid::new(&img).unwrap(), &mut lights);
        let d = lights[0].direction;
        assert!(d.y.abs() < 1e-12 && (d.length() - 1.0).abs() < 1e-12, "{d}");
    }
}
