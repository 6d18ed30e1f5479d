//! Adaptive antialiasing of the `lights` and `hybrid` modes (Mitchell 1987, "Generating
//! antialiased images at low sampling densities", SIGGRAPH '87, section 3: a first pass at a low
//! density, then more samples only where the first pass shows contrast).
//!
//! Those modes are deterministic direct light: a pixel sample is a camera ray and one shadow ray
//! per light, so the samples of a pixel differ only by where they land in the pixel (edges) and by
//! the points they draw in the lights' cones (penumbrae). Where neither changes anything, one
//! sample gives what all of them would, and the rest of `spp` is wasted. So every pixel first takes
//! its sample 0; a pixel then takes samples `1..spp` as well when its 3 x 3 neighbourhood of first
//! samples ([`FirstSample`]) shows
//!
//! - a change of what the camera met (background, real surface, virtual object): a silhouette;
//! - a contrast `(max - min) / (max + min)` above the threshold `c` in any channel of the radiance
//!   with the objects or without them: a penumbra (a shadow ray open in one sample and blocked
//!   in its neighbour's), a shading edge, a change of material.
//!
//! A refined pixel's later samples trace only the shadow rays that can change (Whitted 1980
//! section 4 on adaptive supersampling, where only the rays between differing samples are
//! cast; here per light): where all nine first samples met one kind of surface and found a
//! light's shadow ray blocked the same way (open, blocked by the real layer, or by the objects
//! only), the later samples take that answer for that light ([`KnownVisibility`]) and trace the
//! others: the lights whose shadow edge passes through the neighbourhood. A shadow edge thinner
//! than the first samples' spacing, or a later sample meeting another kind of surface (which
//! then traces everything), is what this can miss. A pixel left at one sample is its own
//! sample 0, which for a smooth neighbourhood differs from the pixel's mean by less than the
//! contrast the test allows.
//! Mitchell's per-channel thresholds were 0.4, 0.3 and 0.6 for 8-bit display values; the renders
//! here are linear HDR composited into a photograph, so the default is far stricter (0.04,
//! `[lighting] adaptive_contrast`). The decision depends only on first samples, which depend on
//! the seed only, so the image stays independent of the thread count. The reference mode is
//! never adaptive: it is the unbiased judge of the others.
//!
//! The first pass itself runs on a coarse grid first ([`CoarseGrid`]): pixels with even `x` and
//! `y` trace every light, and the others take the answers of the lights their coarse neighbours
//! all found alike, tracing only the others.
//!
//! Cost: one pass of one sample per pixel (every light traced at a quarter of them), O(9)
//! comparisons per pixel, then `spp - 1` samples per refined pixel.

use ibl_core::Rgb;

use crate::tracer::{KnownVisibility, LightVisibility, PrimaryHit};

/// What a pixel's first sample saw: the test's input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstSample {
    /// What the camera ray met.
    pub primary: PrimaryHit,
    /// Radiance with the objects (0 for the background, which the composite takes from the
    /// background image).
    pub with: Rgb,
    /// Radiance without the objects (likewise).
    pub without: Rgb,
    /// What blocked each light's shadow ray at the camera ray's hit.
    pub visibility: LightVisibility,
}

/// Whether the pixel at `(x, y)` of a `width x height` grid of first samples (row-major) needs
/// all its samples: its 3 x 3 neighbourhood (clipped at the image's border) holds more than one
/// kind of primary hit, or a contrast above `contrast` in a channel of `with` or `without`.
/// `Some` with what its later samples may take instead of tracing (nothing across a
/// silhouette), `None` when its first sample is enough.
pub fn needs_refinement(
    first: &[FirstSample],
    width: usize,
    height: usize,
    x: usize,
    y: usize,
    contrast: f32,
) -> Option<KnownVisibility> {
    let mut agreement = Agreement::new(first[y * width + x]);
    for ny in y.saturating_sub(1)..(y + 2).min(height) {
        for nx in x.saturating_sub(1)..(x + 2).min(width) {
            agreement.add(first[ny * width + nx]);
        }
    }
    if agreement.silhouette {
        return Some(KnownVisibility::NONE);
    }
    if !(agreement.with.exceeds(contrast) || agreement.without.exceeds(contrast)) {
        return None;
    }
    Some(agreement.known())
}

/// The first pass's coarse grid: pixels with even `x` and `y` trace every light; the others
/// take, for each light, the answer that all coarse pixels within [`REACH`] pixels in `x` and
/// in `y` found (3 x 3 to 4 x 4 of them), when those all met one kind of surface
/// ([`KnownVisibility`]), and trace the rest. Nine or more agreeing samples keep a soft
/// shadow's random first samples from agreeing by chance (with two, a cone half hidden agrees
/// a quarter of the time); shadow edges are traced at full resolution, and only a shadow
/// narrower than the coarse grid's spacing and wholly between its pixels goes unseen.
pub struct CoarseGrid {
    /// Width of the coarse grid, `(width + 1) / 2`.
    width: usize,
    /// Height of the coarse grid.
    height: usize,
}

impl CoarseGrid {
    /// The coarse grid of a `width x height` image.
    pub fn new(width: usize, height: usize) -> CoarseGrid {
        CoarseGrid {
            width: width.div_ceil(2),
            height: height.div_ceil(2),
        }
    }

    /// Its size, coarse pixels across and down.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Whether `(x, y)` of the image is a coarse pixel.
    pub fn is_coarse(x: usize, y: usize) -> bool {
        x.is_multiple_of(2) && y.is_multiple_of(2)
    }

    /// What image pixel `(x, y)` (not a coarse one) may take from `coarse`, the coarse pixels'
    /// first samples (row-major, [`CoarseGrid::size`]).
    pub fn known(&self, coarse: &[FirstSample], x: usize, y: usize) -> KnownVisibility {
        let (i0, i1) = (
            x.saturating_sub(REACH).div_ceil(2),
            ((x + REACH) / 2).min(self.width - 1),
        );
        let (j0, j1) = (
            y.saturating_sub(REACH).div_ceil(2),
            ((y + REACH) / 2).min(self.height - 1),
        );
        let mut agreement = Agreement::new(coarse[j0 * self.width + i0]);
        for j in j0..=j1 {
            for i in i0..=i1 {
                agreement.add(coarse[j * self.width + i]);
            }
        }
        if agreement.silhouette {
            KnownVisibility::NONE
        } else {
            agreement.known()
        }
    }
}

/// How far, in image pixels, [`CoarseGrid::known`] looks for coarse pixels.
const REACH: usize = 3;

/// What a set of first samples agree on: one kind of primary hit or not, the range of their
/// light, and per light whether each traced it and found it blocked the same way.
struct Agreement {
    primary: PrimaryHit,
    silhouette: bool,
    with: Range,
    without: Range,
    /// Traced by every sample.
    tested: u64,
    /// Blocked by the real layer in every sample, in some sample.
    all_real: u64,
    any_real: u64,
    /// Blocked by the objects only in every sample, in some sample.
    all_virtual: u64,
    any_virtual: u64,
}

impl Agreement {
    fn new(first: FirstSample) -> Agreement {
        let v = first.visibility;
        Agreement {
            primary: first.primary,
            silhouette: false,
            with: Range::new(first.with),
            without: Range::new(first.without),
            tested: v.tested,
            all_real: v.real,
            any_real: v.real,
            all_virtual: v.virtual_only,
            any_virtual: v.virtual_only,
        }
    }

    fn add(&mut self, s: FirstSample) {
        self.silhouette |= s.primary != self.primary;
        self.with.grow(s.with);
        self.without.grow(s.without);
        let v = s.visibility;
        self.tested &= v.tested;
        self.all_real &= v.real;
        self.any_real |= v.real;
        self.all_virtual &= v.virtual_only;
        self.any_virtual |= v.virtual_only;
    }

    /// The lights every sample traced and found blocked alike, with those answers.
    fn known(&self) -> KnownVisibility {
        let uniform =
            self.tested & !(self.all_real ^ self.any_real) & !(self.all_virtual ^ self.any_virtual);
        KnownVisibility {
            primary: self.primary,
            lights: LightVisibility {
                tested: uniform,
                real: self.all_real & uniform,
                virtual_only: self.all_virtual & uniform,
            },
        }
    }
}

/// The per-channel minimum and maximum of a set of colours.
struct Range {
    min: Rgb,
    max: Rgb,
}

impl Range {
    fn new(c: Rgb) -> Range {
        Range { min: c, max: c }
    }

    fn grow(&mut self, c: Rgb) {
        self.min = Rgb::new(
            self.min.r.min(c.r),
            self.min.g.min(c.g),
            self.min.b.min(c.b),
        );
        self.max = Rgb::new(
            self.max.r.max(c.r),
            self.max.g.max(c.g),
            self.max.b.max(c.b),
        );
    }

    /// Whether a channel's contrast `(max - min) / (max + min)` exceeds `contrast` (written
    /// without the division; a channel that is 0 throughout has none). The radiance of a
    /// vertex is clamped at 0, so `max + min >= 0`.
    fn exceeds(&self, contrast: f32) -> bool {
        let over = |lo: f32, hi: f32| hi - lo > contrast * (hi + lo);
        over(self.min.r, self.max.r) || over(self.min.g, self.max.g) || over(self.min.b, self.max.b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(primary: PrimaryHit, v: f32) -> FirstSample {
        FirstSample {
            primary,
            with: Rgb::splat(v),
            without: Rgb::splat(v),
            visibility: LightVisibility {
                tested: 0b111,
                real: 0b010,
                virtual_only: 0,
            },
        }
    }

    fn grid(values: &[f32; 9], primary: PrimaryHit) -> Vec<FirstSample> {
        values.iter().map(|&v| sample(primary, v)).collect()
    }

    #[test]
    fn a_flat_neighbourhood_keeps_one_sample() {
        let g = grid(&[1.0; 9], PrimaryHit::Real);
        for (x, y) in [(0, 0), (1, 1), (2, 2), (2, 0)] {
            assert!(needs_refinement(&g, 3, 3, x, y, 0.04).is_none());
        }
        let black = grid(&[0.0; 9], PrimaryHit::Background);
        assert!(needs_refinement(&black, 3, 3, 1, 1, 0.04).is_none());
    }

    #[test]
    fn contrast_is_measured_against_the_threshold() {
        // max 1.05, min 1.0: contrast 0.05 / 2.05 = 0.0244.
        let mut v = [1.0; 9];
        v[8] = 1.05;
        let g = grid(&v, PrimaryHit::Real);
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.04).is_none());
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.02).is_some());
        // The corner (2, 2) is outside (0, 0)'s neighbourhood.
        assert!(needs_refinement(&g, 3, 3, 0, 0, 0.02).is_none());
    }

    #[test]
    fn a_change_of_primary_hit_refines_its_neighbours_only() {
        let mut g = grid(&[1.0; 9], PrimaryHit::Real);
        g[2] = sample(PrimaryHit::Virtual, 1.0);
        // Across a silhouette nothing is known: every ray is traced.
        assert_eq!(
            needs_refinement(&g, 3, 3, 1, 1, 0.04),
            Some(KnownVisibility::NONE)
        );
        assert_eq!(
            needs_refinement(&g, 3, 3, 2, 0, 0.04),
            Some(KnownVisibility::NONE)
        );
        assert!(needs_refinement(&g, 3, 3, 0, 2, 0.04).is_none());
    }

    #[test]
    fn a_shadow_in_one_layer_only_refines() {
        // The layer without the objects is flat; the one with them has a shadowed sample.
        let mut g = grid(&[1.0; 9], PrimaryHit::Real);
        g[4].with = Rgb::new(1.0, 0.5, 1.0);
        assert!(needs_refinement(&g, 3, 3, 0, 0, 0.04).is_some());
    }

    #[test]
    fn later_samples_know_the_lights_blocked_alike_everywhere() {
        // Light 0 open everywhere, light 1 blocked by the real layer everywhere, light 2 blocked
        // by the objects in one pixel only, light 3 traced in all but one pixel.
        let mut g = grid(&[1.0; 9], PrimaryHit::Real);
        for s in &mut g {
            s.visibility.tested = 0b1111;
        }
        g[5].visibility.virtual_only = 0b100;
        g[5].with = Rgb::splat(0.5);
        g[7].visibility.tested = 0b0111;
        let known = needs_refinement(&g, 3, 3, 1, 1, 0.04).expect("refined");
        assert_eq!(known.primary, PrimaryHit::Real);
        assert_eq!(
            known.lights,
            LightVisibility {
                tested: 0b0011,
                real: 0b0010,
                virtual_only: 0,
            }
        );
    }

    #[test]
    fn the_coarse_grid_lends_its_agreed_answers_to_the_pixels_between() {
        // A 5 x 5 image: coarse pixels at x, y in {0, 2, 4}, a 3 x 3 coarse grid. Light 0 is
        // open everywhere; light 1 is blocked by the objects at coarse pixel (1, 1) (image
        // (2, 2)) only.
        let grid = CoarseGrid::new(5, 5);
        assert_eq!(grid.size(), (3, 3));
        let mut coarse = grid_of(9, PrimaryHit::Real);
        coarse[4].visibility.virtual_only = 0b10;
        // Every pixel within 3 of image (2, 2) sees the disagreeing coarse pixel: light 1 is
        // traced there, light 0 taken from the grid.
        for (x, y) in [(1, 0), (1, 1), (3, 3), (4, 1), (0, 1)] {
            let k = grid.known(&coarse, x, y);
            assert_eq!(k.lights.tested & 0b11, 0b01, "({x}, {y})");
        }
        // A larger image: (9, 9) is farther than 3 from image (2, 2).
        let grid = CoarseGrid::new(11, 11);
        let mut coarse = grid_of(36, PrimaryHit::Real);
        coarse[7].visibility.virtual_only = 0b10;
        assert_eq!(grid.known(&coarse, 9, 9).lights.tested & 0b11, 0b11);
        assert_eq!(grid.known(&coarse, 5, 5).lights.tested & 0b11, 0b01);
        let grid = CoarseGrid::new(5, 5);
        let mut coarse = grid_of(9, PrimaryHit::Real);
        // Another kind of surface among the neighbours: nothing is lent.
        coarse[0].primary = PrimaryHit::Virtual;
        assert_eq!(grid.known(&coarse, 1, 0), KnownVisibility::NONE);
        assert!(CoarseGrid::is_coarse(2, 4) && !CoarseGrid::is_coarse(1, 2));
    }

    fn grid_of(n: usize, primary: PrimaryHit) -> Vec<FirstSample> {
        (0..n).map(|_| sample(primary, 1.0)).collect()
    }
}
