//! A picture of a light set over its probe, as in Figure 3 of Madsen & Laursen 2006: the
//! tone-mapped lat-long probe, each light's region outlined, and each light's direction marked by
//! a disc whose size grows with the light's share of the set's power.
//!
//! - **Background**: the probe through the preview transform of `ibl preview` (automatic exposure
//!   mapping the log-average luminance to 0.18, Reinhard curve, sRGB), enlarged by a whole factor
//!   `s` (nearest neighbour) to at least [`OverlayOptions::min_width`] pixels, so that markers stay
//!   legible on small probes; pixel `(i, j)` of the probe becomes the block `[s i, s i + s) x
//!   [s j, s j + s)`.
//! - **Regions** ([`ibl_light::PixelRegion`], region methods only): the inner border of each
//!   block of probe pixels, `max(1, s / 2)` pixels thick, in [`REGION_COLOR`]; neighbouring
//!   regions therefore show a double line between them.
//! - **Markers**: a light with direction `w` (world frame, CONVENTIONS section 1) sits at lat-long
//!   `(u, v)` (CONVENTIONS section 2), the point `(u W', v H')` of the `W' x H'` picture. Its share
//!   of the power is `q = Y(I) / sum Y(I)` (Rec. 709 luminance of `I = L A`); the disc radius is
//!   `r = k clamp(10 + 3 log10 q, 1.5, 10)` pixels with `k = max(1, H' / 256)`: on a 1024 x 512
//!   picture 20 pixels for the whole power, 14 for a tenth, 8 for a hundredth, and the 3-pixel
//!   minimum from about 1.5e-3 down, so ten times the power reads as 6 pixels more radius. Discs
//!   are [`MARKER_COLOR`] inside a dark ring and wrap across the azimuth seam (u = 0 = 1); the
//!   strongest are drawn first so that weak lights stay visible on top of them.
//!
//! Pure computation: the caller encodes the result (e.g. `ibl_io::ldr::encode_png`).

use ibl_core::rgb::Rgb64;
use ibl_core::tonemap::{Display, ToneCurve};
use ibl_core::{Image, LatLong, Rgb};
use ibl_light::{LightSet, PixelRegion};

/// Colour of region outlines (8-bit sRGB).
pub const REGION_COLOR: [u8; 3] = [255, 214, 0];
/// Fill colour of light markers (8-bit sRGB).
pub const MARKER_COLOR: [u8; 3] = [255, 40, 40];
/// Colour of the ring around each marker (8-bit sRGB).
pub const RING_COLOR: [u8; 3] = [0, 0, 0];

/// Largest picture drawn, in pixels: the enlargement factor is lowered to stay below it.
const MAX_PIXELS: usize = 1 << 26;

/// How the overlay is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverlayOptions {
    /// Probes narrower than this many pixels are enlarged by the smallest whole factor reaching
    /// it (within a 2^26-pixel picture).
    pub min_width: usize,
}

impl Default for OverlayOptions {
    fn default() -> Self {
        OverlayOptions { min_width: 1024 }
    }
}

/// The whole enlargement factor for a `width` x `height` probe: the smallest reaching
/// `min_width`, at least 1, lowered while the picture would exceed 2^26 pixels.
pub fn scale_factor(width: usize, height: usize, min_width: usize) -> usize {
    if width == 0 || height == 0 {
        return 1;
    }
    let wanted = min_width.div_ceil(width).max(1);
    let area = width.saturating_mul(height);
    // Largest s with area * s^2 <= MAX_PIXELS.
    let limit = ((MAX_PIXELS / area.max(1)) as f64).sqrt().floor() as usize;
    wanted.min(limit).max(1)
}

/// Draws `set` over the lat-long `probe` (see the module documentation). The picture is
/// `s W x s H` with `s` from [`scale_factor`].
pub fn draw_overlay(
    probe: &Image<Rgb>,
    set: &LightSet,
    options: &OverlayOptions,
) -> Image<[u8; 3]> {
    let display = Display {
        exposure_stops: ibl_core::tonemap::auto_exposure_stops(probe),
        curve: ToneCurve::Reinhard,
    };
    let base = ibl_core::tonemap::to_srgb8(probe, &display);
    let (w, h) = (probe.width(), probe.height());
    if w == 0 || h == 0 {
        return base;
    }
    let s = scale_factor(w, h, options.min_width);
    let mut canvas = if s == 1 {
        base
    } else {
        Image::from_fn_par(w * s, h * s, |x, y| *base.get(x / s, y / s))
    };
    for region in set.lights.iter().filter_map(|l| l.region) {
        outline(&mut canvas, &region, s, (s / 2).max(1));
    }

    let lum = |i: [f64; 3]| {
        Rgb64 {
            r: i[0],
            g: i[1],
            b: i[2],
        }
        .luminance()
        .max(0.0)
    };
    let total: f64 = set
        .lights
        .iter()
        .map(|l| lum(l.irradiance.to_array()))
        .sum();
    let n = set.lights.len().max(1) as f64;
    let unit = (canvas.height() as f64 / 256.0).max(1.0);
    let mut markers: Vec<(f64, f64, f64)> = set
        .lights
        .iter()
        .map(|l| {
            let share = if total > 0.0 {
                lum(l.irradiance.to_array()) / total
            } else {
                1.0 / n
            };
            let (u, v) = LatLong::dir_to_uv(l.direction);
            let steps = (10.0 + 3.0 * share.max(1e-300).log10()).clamp(1.5, 10.0);
            (
                u * canvas.width() as f64,
                v * canvas.height() as f64,
                unit * steps,
            )
        })
        .collect();
    markers.sort_by(|a, b| b.2.total_cmp(&a.2));
    for (cx, cy, r) in markers {
        let ring = (r / 5.0).max(1.0);
        disc(&mut canvas, cx, cy, r + ring, RING_COLOR);
        disc(&mut canvas, cx, cy, r, MARKER_COLOR);
    }
    canvas
}

/// Paints the inner border (`thickness` pixels) of a probe region enlarged `s` times.
fn outline(canvas: &mut Image<[u8; 3]>, region: &PixelRegion, s: usize, thickness: usize) {
    let (w, h) = (canvas.width(), canvas.height());
    let (x0, x1) = ((region.x0 * s).min(w), (region.x1 * s).min(w));
    let (y0, y1) = ((region.y0 * s).min(h), (region.y1 * s).min(h));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let t = thickness.min(x1 - x0).min(y1 - y0);
    for y in y0..y1 {
        let edge_row = y < y0 + t || y >= y1 - t;
        for x in x0..x1 {
            if edge_row || x < x0 + t || x >= x1 - t {
                *canvas.get_mut(x, y) = REGION_COLOR;
            }
        }
    }
}

/// Fills the pixels whose centres lie within `r` of `(cx, cy)` (picture pixel units), wrapping
/// columns across the azimuth seam and clipping rows.
fn disc(canvas: &mut Image<[u8; 3]>, cx: f64, cy: f64, r: f64, color: [u8; 3]) {
    let (w, h) = (canvas.width() as i64, canvas.height() as i64);
    if w == 0 || h == 0 || !(cx.is_finite() && cy.is_finite() && r.is_finite()) {
        return;
    }
    let r = r.min(w as f64 / 2.0);
    let (px0, px1) = ((cx - r).floor() as i64, (cx + r).ceil() as i64);
    let (py0, py1) = (
        ((cy - r).floor() as i64).max(0),
        ((cy + r).ceil() as i64).min(h - 1),
    );
    for py in py0..=py1 {
        let dy = py as f64 + 0.5 - cy;
        for px in px0..=px1 {
            let dx = px as f64 + 0.5 - cx;
            if dx * dx + dy * dy <= r * r {
                // Both fit in usize: rem_euclid is in [0, w) and py in [0, h).
                *canvas.get_mut(px.rem_euclid(w) as usize, py as usize) = color;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::glam::DVec3;
    use ibl_core::rgb::Rgb64;
    use ibl_light::{Extraction, Light, Provenance};

    fn light(direction: [f64; 3], irradiance: f64, region: Option<PixelRegion>) -> Light {
        Light {
            direction: DVec3::from_array(direction),
            radiance: Rgb::splat(1.0),
            solid_angle_sr: 1.0,
            irradiance: Rgb64::new(irradiance, irradiance, irradiance),
            region,
            spread_sr: None,
            core_fraction: None,
            side: None,
        }
    }

    fn test_provenance() -> Provenance {
        Provenance::extracted(Extraction::Unknown {
            name: "test".into(),
        })
    }

    fn grey_probe(w: usize, h: usize) -> Image<Rgb> {
        Image::filled(w, h, Rgb::splat(0.5))
    }

    #[test]
    fn markers_sit_on_the_lights_pixels() {
        let probe = grey_probe(64, 32);
        let dirs = [[0.0, 0.0, -1.0], [0.6, 0.64, 0.48], [-0.8, -0.36, 0.48]];
        let set = LightSet {
            provenance: test_provenance(),
            lights: dirs.iter().map(|d| light(*d, 1.0, None)).collect(),
        };
        let img = draw_overlay(&probe, &set, &OverlayOptions::default());
        assert_eq!((img.width(), img.height()), (1024, 512));
        let ll = LatLong::new(img.width(), img.height());
        for d in dirs {
            let (i, j) = ll.dir_to_pixel(ibl_core::glam::DVec3::from_array(d));
            assert_eq!(*img.get(i, j), MARKER_COLOR, "{d:?} at ({i}, {j})");
        }
        // Far from every light the picture is the tone-mapped probe.
        let grey = *img.get(100, 20);
        assert_ne!(grey, MARKER_COLOR);
        assert_eq!(grey[0], grey[1]);
    }

    #[test]
    fn brighter_lights_get_bigger_markers() {
        let probe = grey_probe(128, 64);
        let set = LightSet {
            provenance: test_provenance(),
            lights: vec![
                light([0.0, 0.0, -1.0], 100.0, None),
                light([0.0, 0.0, 1.0], 0.01, None),
            ],
        };
        let img = draw_overlay(&probe, &set, &OverlayOptions::default());
        let count = |x0: usize, x1: usize| {
            (0..img.height())
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .filter(|&(x, y)| *img.get(x, y) == MARKER_COLOR)
                .count()
        };
        // The strong light is at the centre; the weak one straddles the seam (both edges).
        let strong = count(256, 768);
        let weak = count(0, 256) + count(768, 1024);
        assert!(strong > 4 * weak && weak > 0, "{strong} vs {weak}");
        assert!(
            count(0, 16) > 0 && count(1008, 1024) > 0,
            "wraps across the seam"
        );
    }

    #[test]
    fn region_outlines_are_drawn_on_their_borders() {
        let probe = grey_probe(128, 64);
        let region = PixelRegion {
            x0: 16,
            y0: 8,
            x1: 48,
            y1: 36,
        };
        // The light sits at the nadir, far below the region, so its marker covers no outline.
        let set = LightSet {
            provenance: test_provenance(),
            lights: vec![light([0.0, -1.0, 0.0], 1.0, Some(region))],
        };
        let img = draw_overlay(&probe, &set, &OverlayOptions { min_width: 0 });
        assert_eq!((img.width(), img.height()), (128, 64));
        for x in 16..48 {
            assert_eq!(*img.get(x, 8), REGION_COLOR);
            assert_eq!(*img.get(x, 35), REGION_COLOR);
            assert_ne!(*img.get(x, 7), REGION_COLOR);
            assert_ne!(*img.get(x, 36), REGION_COLOR);
        }
        for y in 8..36 {
            assert_eq!(*img.get(16, y), REGION_COLOR);
            assert_eq!(*img.get(47, y), REGION_COLOR);
            assert_ne!(*img.get(15, y), REGION_COLOR);
            assert_ne!(*img.get(48, y), REGION_COLOR);
        }
        assert_ne!(*img.get(30, 20), REGION_COLOR);

        // Enlarged 4 times: the inner border of the enlarged block, 2 pixels thick.
        let big = draw_overlay(&probe, &set, &OverlayOptions { min_width: 512 });
        assert_eq!((big.width(), big.height()), (512, 256));
        for (x, y, on) in [
            (64, 80, true),
            (65, 80, true),
            (66, 80, false),
            (63, 80, false),
            (191, 80, true),
            (192, 80, false),
            (120, 143, true),
            (120, 142, true),
            (120, 141, false),
            (120, 144, false),
            (120, 32, true),
            (120, 31, false),
        ] {
            assert_eq!(*big.get(x, y) == REGION_COLOR, on, "({x}, {y})");
        }
    }

    #[test]
    fn scale_factor_reaches_the_minimum_width_within_the_pixel_cap() {
        assert_eq!(scale_factor(512, 256, 1024), 2);
        assert_eq!(scale_factor(1000, 500, 1024), 2);
        assert_eq!(scale_factor(2048, 1024, 1024), 1);
        assert_eq!(scale_factor(8, 4, 1024), 128);
        assert_eq!(scale_factor(0, 0, 1024), 1);
        let s = scale_factor(4, 60_000, 1024);
        assert!(s >= 1 && 4 * s * 60_000 * s <= MAX_PIXELS, "{s}");
    }

    #[test]
    fn empty_sets_and_probes_do_not_panic() {
        let set = LightSet {
            provenance: test_provenance(),
            lights: vec![],
        };
        let img = draw_overlay(&grey_probe(16, 8), &set, &OverlayOptions::default());
        assert_eq!(img.width(), 1024);
        let empty = draw_overlay(
            &Image::filled(0, 0, Rgb::ZERO),
            &set,
            &OverlayOptions::default(),
        );
        assert!(empty.is_empty());
    }
}
