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
//! - a first sample that differs from the mean of its (up to eight) neighbours' by more than
//!   `c (value + mean)` in any channel of the radiance with the objects or without them: a
//!   penumbra (a shadow ray open in one sample and blocked in its neighbour's), a shading edge,
//!   a change of material.
//!
//! The test is Mitchell's with the neighbourhood's mean in place of its extremes: a pixel on a
//! smooth gradient (a floor lit at a slant, the bunny's flank) equals the mean of its
//! neighbours and keeps one sample, where `(max - min) / (max + min)` over the neighbourhood
//! refined it for a change spread over three pixels. Mitchell's thresholds were 0.4, 0.3 and
//! 0.6 for 8-bit display values; the renders here are linear HDR composited into a photograph,
//! so the default is far stricter (0.02, `[lighting] adaptive_contrast`). The decision depends
//! only on first samples, which depend on the seed only, so the image stays independent of the
//! thread count. The reference mode is never adaptive: it is the unbiased judge of the others.
//!
//! A refined pixel's later samples trace only the shadow rays that can change (Whitted 1980
//! section 4 on adaptive supersampling, where only the rays between differing samples are
//! cast; here per light): where all the first samples around that met one kind of surface found
//! a light's shadow ray blocked the same way (open, blocked by the real layer, or by the objects
//! only), the later samples take that answer for that light ([`KnownVisibility`]) and trace the
//! others: the lights whose shadow edge passes through the neighbourhood. Each kind of surface
//! lends its own answers (across a silhouette too), and only for a light that at least six of
//! its samples traced (a cone point below the surface traces nothing and says nothing). A
//! shadow edge thinner than the first samples' spacing is what this can miss. A pixel left at
//! one sample is its own sample 0, which for a smooth neighbourhood differs from the pixel's
//! mean by less than the deviation the test allows.
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
/// kind of primary hit, or its own `with` or `without` deviates from its neighbours' mean by
/// more than `contrast (value + mean)` in a channel.
/// `Some` with what its later samples may take instead of tracing (per kind of surface, from
/// the neighbours of that kind), `None` when its first sample is enough.
pub fn needs_refinement(
    first: &[FirstSample],
    width: usize,
    height: usize,
    x: usize,
    y: usize,
    contrast: f32,
) -> Option<KnownVisibility> {
    let neighbourhood = || {
        (y.saturating_sub(1)..(y + 2).min(height))
            .flat_map(move |ny| (x.saturating_sub(1)..(x + 2).min(width)).map(move |nx| (nx, ny)))
    };
    let centre = first[y * width + x];
    let (mut with, mut without, mut others) = (Rgb::ZERO, Rgb::ZERO, 0u32);
    let mut silhouette = false;
    for (nx, ny) in neighbourhood() {
        let s = &first[ny * width + nx];
        silhouette |= s.primary != centre.primary;
        if (nx, ny) != (x, y) {
            with += s.with;
            without += s.without;
            others += 1;
        }
    }
    let n = others.max(1) as f32;
    if !silhouette
        && !deviates(centre.with, with / n, contrast)
        && !deviates(centre.without, without / n, contrast)
    {
        return None;
    }
    // Only a pixel that is refined needs what its neighbours agree on.
    let mut agreement = Agreement::EMPTY;
    for (nx, ny) in neighbourhood() {
        agreement.add(first[ny * width + nx]);
    }
    Some(agreement.known())
}

/// Whether `value` differs from `mean` by more than `contrast (value + mean)` in a channel.
fn deviates(value: Rgb, mean: Rgb, contrast: f32) -> bool {
    let over = |v: f32, m: f32| (v - m).abs() > contrast * (v + m);
    over(value.r, mean.r) || over(value.g, mean.g) || over(value.b, mean.b)
}

/// The first pass's coarse grid: pixels with even `x` and `y` trace every light; the others
/// take, for each light, the answer that all coarse pixels within `REACH` pixels in `x` and
/// in `y` (3 x 3 to 4 x 4 of them) that met the same kind of surface found
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
        let mut agreement = Agreement::EMPTY;
        for j in j0..=j1 {
            for i in i0..=i1 {
                agreement.add(coarse[j * self.width + i]);
            }
        }
        agreement.known()
    }
}

/// How far, in image pixels, [`CoarseGrid::known`] looks for coarse pixels.
const REACH: usize = 3;

/// What a set of first samples agree on: per kind of surface, per light, whether each sample
/// of that kind traced it and found it blocked the same way.
struct Agreement {
    /// Real surfaces, virtual objects.
    kinds: [KindAgreement; 2],
}

/// The agreement of the samples of one kind of surface.
#[derive(Clone, Copy)]
struct KindAgreement {
    /// Per light, how many samples traced it (a cone point below the surface traces none), as
    /// a bit-sliced counter: bit `i` of plane `k` is bit `k` of light `i`'s count (up to 31; a
    /// neighbourhood holds at most 16 samples). All 64 lights count in a few word operations.
    tested: [u64; 5],
    /// Blocked by the real layer in every sample that traced it, in some sample.
    all_real: u64,
    any_real: u64,
    /// Blocked by the objects only in every sample that traced it, in some sample.
    all_virtual: u64,
    any_virtual: u64,
}

/// Fewest samples that must have traced a light, all alike, before their answer is lent: a soft
/// shadow's random first samples rarely agree by chance across this many (a cone half hidden,
/// one time in 2^(n-1)). [`KindAgreement::known`] reads `count >= 6` off the counter's planes.
const MIN_AGREEING: u8 = 6;

impl KindAgreement {
    const EMPTY: KindAgreement = KindAgreement {
        tested: [0; 5],
        all_real: u64::MAX,
        any_real: 0,
        all_virtual: u64::MAX,
        any_virtual: 0,
    };

    fn add(&mut self, v: LightVisibility) {
        // One added to the count of every light in `v.tested`: a ripple-carry add per plane.
        let mut carry = v.tested;
        for plane in &mut self.tested {
            let next = *plane & carry;
            *plane ^= carry;
            carry = next;
        }
        // A sample that did not trace a light says nothing about it: neutral in the "every".
        self.all_real &= v.real | !v.tested;
        self.any_real |= v.real;
        self.all_virtual &= v.virtual_only | !v.tested;
        self.any_virtual |= v.virtual_only;
    }

    /// The lights that at least [`MIN_AGREEING`] samples traced, every one of them finding it
    /// blocked alike, with those answers.
    fn known(&self) -> LightVisibility {
        const { assert!(MIN_AGREEING == 6) };
        // count >= 6: 8 or more (plane 3 or 4), or 6 and 7 (planes 1 and 2).
        let [_, p1, p2, p3, p4] = self.tested;
        let enough = p4 | p3 | (p2 & p1);
        let uniform =
            enough & !(self.all_real ^ self.any_real) & !(self.all_virtual ^ self.any_virtual);
        LightVisibility {
            tested: uniform,
            real: self.all_real & uniform,
            virtual_only: self.all_virtual & uniform,
        }
    }
}

impl Agreement {
    const EMPTY: Agreement = Agreement {
        kinds: [KindAgreement::EMPTY; 2],
    };

    fn add(&mut self, s: FirstSample) {
        match s.primary {
            PrimaryHit::Real => self.kinds[0].add(s.visibility),
            PrimaryHit::Virtual => self.kinds[1].add(s.visibility),
            PrimaryHit::Background => {}
        }
    }

    /// Per kind of surface, the lights its samples all traced and found blocked alike.
    fn known(&self) -> KnownVisibility {
        KnownVisibility {
            real: self.kinds[0].known(),
            virtual_object: self.kinds[1].known(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bit_sliced_counts_agree_with_counting_each_light() {
        // Up to 16 samples (the coarse grid's 4 x 4), random lights traced and blocked.
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            state = crate::sampling::splitmix64(state);
            state
        };
        for samples in 0..=16 {
            for _ in 0..50 {
                // Lights in `shared` are blocked alike in every sample that traces them.
                let (shared, real_shared, virtual_shared) = (next() | next(), next(), next());
                let visibilities: Vec<LightVisibility> = (0..samples)
                    .map(|_| {
                        let tested = next() | next();
                        let real = ((real_shared & shared) | (next() & !shared)) & tested;
                        let virtual_only =
                            ((virtual_shared & shared) | (next() & !shared)) & tested & !real;
                        LightVisibility {
                            tested,
                            real,
                            virtual_only,
                        }
                    })
                    .collect();
                let mut agreement = KindAgreement::EMPTY;
                visibilities.iter().for_each(|&v| agreement.add(v));
                let known = agreement.known();
                for light in 0..64 {
                    let bit = 1u64 << light;
                    let traced: Vec<_> = visibilities
                        .iter()
                        .filter(|v| v.tested & bit != 0)
                        .collect();
                    let alike = |f: fn(&LightVisibility) -> u64| {
                        traced.iter().all(|v| f(v) & bit != 0)
                            || traced.iter().all(|v| f(v) & bit == 0)
                    };
                    let lent = traced.len() >= usize::from(MIN_AGREEING)
                        && alike(|v| v.real)
                        && alike(|v| v.virtual_only);
                    assert_eq!(
                        known.tested & bit != 0,
                        lent,
                        "{samples} samples, light {light}"
                    );
                    if lent {
                        assert_eq!(known.real & bit != 0, traced[0].real & bit != 0);
                        let virtual_only = traced[0].virtual_only & bit != 0;
                        assert_eq!(known.virtual_only & bit != 0, virtual_only);
                    }
                }
            }
        }
    }

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
    fn the_deviation_from_the_neighbours_is_measured_against_the_threshold() {
        // The centre 1.1 against neighbours of 1.0: 0.1 / 2.1 = 0.048.
        let mut v = [1.0; 9];
        v[4] = 1.1;
        let g = grid(&v, PrimaryHit::Real);
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.05).is_none());
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.04).is_some());
        // (0, 0) sees 1.1 among three neighbours: mean 1.033, 0.033 / 2.033 = 0.016.
        assert!(needs_refinement(&g, 3, 3, 0, 0, 0.02).is_none());
        assert!(needs_refinement(&g, 3, 3, 0, 0, 0.01).is_some());
    }

    #[test]
    fn a_smooth_gradient_keeps_one_sample() {
        // A ramp of 10 % a pixel: the centre is its neighbours' mean.
        let v = [1.0, 1.1, 1.2, 1.0, 1.1, 1.2, 1.0, 1.1, 1.2];
        let g = grid(&v, PrimaryHit::Real);
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.02).is_none());
    }

    #[test]
    fn a_change_of_primary_hit_refines_its_neighbours_only() {
        let mut g = grid(&[1.0; 9], PrimaryHit::Real);
        g[2] = sample(PrimaryHit::Virtual, 1.0);
        // Across a silhouette each kind lends what enough of its samples agree on: eight real
        // samples around (1, 1), one virtual (too few).
        let known = needs_refinement(&g, 3, 3, 1, 1, 0.04).expect("refined");
        assert_eq!(known.real.tested, 0b111);
        assert_eq!(known.virtual_object, LightVisibility::NONE);
        // (2, 0) sees three real samples and one virtual: nothing is lent.
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
        assert!(needs_refinement(&g, 3, 3, 1, 1, 0.04).is_some());
        assert!(needs_refinement(&g, 3, 3, 0, 0, 0.04).is_some());
    }

    #[test]
    fn later_samples_know_the_lights_blocked_alike_everywhere() {
        // Light 0 open everywhere, light 1 blocked by the real layer everywhere, light 2 blocked
        // by the objects in one pixel only, light 3 traced (open) in all but one pixel: the
        // eight that traced it lend their answer.
        let mut g = grid(&[1.0; 9], PrimaryHit::Real);
        for s in &mut g {
            s.visibility.tested = 0b1111;
        }
        g[5].visibility.virtual_only = 0b100;
        g[4].with = Rgb::splat(0.5);
        g[7].visibility.tested = 0b0111;
        let known = needs_refinement(&g, 3, 3, 1, 1, 0.04).expect("refined");
        assert_eq!(known.virtual_object, LightVisibility::NONE);
        assert_eq!(
            known.real,
            LightVisibility {
                tested: 0b1011,
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
            assert_eq!(k.real.tested & 0b11, 0b01, "({x}, {y})");
        }
        // A larger image: (9, 9) is farther than 3 from image (2, 2).
        let grid = CoarseGrid::new(11, 11);
        let mut coarse = grid_of(36, PrimaryHit::Real);
        coarse[7].visibility.virtual_only = 0b10;
        assert_eq!(grid.known(&coarse, 9, 9).real.tested & 0b11, 0b11);
        assert_eq!(grid.known(&coarse, 5, 5).real.tested & 0b11, 0b01);
        // Another kind of surface among the neighbours lends nothing to the first kind's rays,
        // and fewer than six of a kind lend nothing to theirs: (3, 3) sees 4 x 4 coarse pixels,
        // one of them virtual.
        let mut coarse = grid_of(36, PrimaryHit::Real);
        coarse[0].primary = PrimaryHit::Virtual;
        coarse[0].visibility.real = 0b111;
        let k = grid.known(&coarse, 3, 3);
        assert_eq!(k.real.tested & 0b111, 0b111);
        assert_eq!(k.real.real & 0b111, 0b010);
        assert_eq!(k.virtual_object, LightVisibility::NONE);
        assert!(CoarseGrid::is_coarse(2, 4) && !CoarseGrid::is_coarse(1, 2));
    }

    fn grid_of(n: usize, primary: PrimaryHit) -> Vec<FirstSample> {
        (0..n).map(|_| sample(primary, 1.0)).collect()
    }
}
