//! Texture for the holes a moved camera sees, beyond Grosch 2005: its section 5 proposes to
//! improve the hole filling "by analyzing the texture in visible regions and modulating the
//! radiance estimate with the texture in the hidden regions" (after Loscos et al. 1999). The
//! fill of section 4.4 is the patch's estimate `rho E / pi`, flat over each patch; this module
//! gives it the texture of the part of the same face the probe saw.
//!
//! **The texture.** Each surface face is cut into square texels in its own `(u, v)` metres
//! (`geometry::Face`), of side `d pi / H`: the probe's pixel pitch (`pi / H` rad, `H` its rows,
//! the same in azimuth at the equator) at the distance `d` from the probe to the centre of the
//! face's bounding rectangle, so a texel holds about one probe pixel. A texel whose centre `x`
//! the probe saw (the depth test of [`RoomRadiance`]) has the **reflectance texture**
//!
//! ```text
//! t(x) = pi L(x) / (rho_g E_p)        per channel
//! ```
//!
//! `L(x)` the probe's radiance there, `E_p` the estimated irradiance of its patch `p` and `rho_g`
//! its group's reflectance. `pi L = rho(x) E(x)`, so `t = (rho(x) / rho_g) (E(x) / E_p)`: the
//! point's reflectance relative to the group's, the lighting removed down to the patch's scale.
//! Its `E`-weighted mean over the group's seen patches is 1 (`rho_g = sum w B / sum w E`,
//! `reflectance`; exactly so up to how the texels sample the pixels the patches' `B` came from),
//! which is the mean normalisation: a filled point keeps its patch's estimate on average.
//! Dividing by the group's `rho_g` rather than the patch's own `B / E` keeps texture coarser than
//! a patch (tiles as large as patches) that a per-patch ratio would flatten.
//!
//! **Where a hidden texel takes its texture.** A texture that repeats can be copied in phase: the
//! normalised autocorrelation of `Y(t)` (luminance) over pairs of seen texels `k` texels apart
//! along `u`, and along `v` (from at least [`MIN_PAIRS`] pairs), is computed for `k` up to
//! [`FillTextureSettings::max_period_m`] (and half the face); the **period** of an axis is the
//! first local maximum, after the correlation has gone negative, of at least
//! [`FillTextureSettings::min_correlation`], refined to a fraction of a texel by a parabola
//! through it and its neighbours. A hidden texel takes `t` from the
//! nearest seen texel among the shifts `(m S_u, n S_v)`, `S` the period, or, along an axis
//! without one, the lag where the correlation first goes negative (a source that much away is
//! uncorrelated with the hidden texel's neighbourhood, so the copy does not smear an edge into
//! a streak). The fill is then `t rho E / pi` of the hidden point's patch.
//!
//! **When copying helps.** For a stationary texture of variance `s^2` and correlation `r` at the
//! shift, a copy errs by `2 s^2 (1 - r)` in mean square, the flat fill by `s^2`: the copy wins
//! exactly when `r > 1 / 2`, the default `min_correlation` (probe noise of variance `n^2` lowers
//! the measured `r` by `s^2 / (s^2 + n^2)`, and the break-even stays at `r = 1 / 2`). With a
//! period that is met by construction; without one the shift is uncorrelated (`r ~ 0`), the
//! copy doubles the texture's share of the error and gives the look of the surface only. So a
//! face **is modulated only when it has a period** along an axis, unless
//! [`FillTextureSettings::aperiodic`] asks for the look. A face of which the probe sees no
//! texel, and a hidden texel with no seen source among its [`MAX_SHIFTS`] nearest shifts, keep
//! the flat fill (modulation 1). The period search assumes the texture's lattice lies along the
//! face's axes, as tiles and planks do in a room whose walls are its axes.
//!
//! World frame and metres as `docs/CONVENTIONS.md`; `t` is dimensionless. Cost: one short ray
//! and one depth test per texel, `O(K N)` for the autocorrelation (`K` lags, `N` texels) and up
//! to [`MAX_SHIFTS`] look-ups per hidden texel; faces in parallel, identical for any thread count.

use glam::{Vec2, Vec3};
use ibl_core::{Image, Rgb};
use rayon::prelude::*;

use crate::depth_map::ProbeDepthMap;
use crate::description::GroupKind;
use crate::geometry::{Face, FaceShape};
use crate::reflectance::Estimate;
use crate::room_radiance::RoomRadiance;
use crate::{Room, RoomError};

/// Most texels over all faces (`16 M`, 256 MiB of texture).
pub const MAX_TEXELS: usize = 1 << 24;

/// Lattice shifts tried per hidden texel, nearest first, at most [`MAX_SHIFT_STEPS`] spacings
/// along either axis: as many as a 64 x 64 block, which bounds the search on a face with a short
/// spacing.
pub const MAX_SHIFTS: usize = 64 * 64;

/// Most spacings a shift goes along one axis: 64 covers a 4 m face at a 6.25 cm spacing.
pub const MAX_SHIFT_STEPS: i64 = 64;

/// Fewest pairs of seen texels a lag's autocorrelation is computed from (0 below): for
/// uncorrelated texels its standard error is `1 / sqrt(N)`, 0.05 here, so a period's 0.5 stands
/// ten standard errors above chance even where neighbouring texels share a probe pixel and the
/// independent pairs are fewer.
pub const MIN_PAIRS: usize = 400;

/// How far in front of a face the ray that finds a texel's patch starts, metres (well above f32
/// rounding at room scale, well below any gap between two surfaces of a room model).
const TEXEL_PROBE_OFFSET_M: f32 = 1e-3;

/// Settings of the texture analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FillTextureSettings {
    /// Longest period looked for, metres: 1 m covers floor tiles, planks and wallpaper repeats;
    /// a longer one needs over 2 m of seen surface to show twice.
    pub max_period_m: f32,
    /// Autocorrelation a period must reach: 1/2, where a copy starts to beat the flat fill in
    /// mean square (module doc).
    pub min_correlation: f32,
    /// Modulate faces without a period too (the look of the surface, at a higher error).
    pub aperiodic: bool,
}

impl Default for FillTextureSettings {
    fn default() -> Self {
        FillTextureSettings {
            max_period_m: 1.0,
            min_correlation: 0.5,
            aperiodic: false,
        }
    }
}

/// What the analysis found on one face.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceTextureAnalysis {
    /// The face (room order).
    pub face: u32,
    /// Texel side, metres.
    pub texel_m: f32,
    /// Texels on the face whose centre the probe saw.
    pub seen_texels: usize,
    /// Texels on the face whose centre the probe did not see.
    pub hidden_texels: usize,
    /// Hidden texels that found a seen source (0 when the face is not modulated).
    pub sourced_texels: usize,
    /// The period along `u` and `v`, metres, where one was found.
    pub period_m: [Option<f32>; 2],
    /// The autocorrelation at each period (0 where there is none).
    pub correlation: [f32; 2],
    /// The lattice spacing of the shifts along `u` and `v`, metres.
    pub spacing_m: [f32; 2],
    /// Whether the fill of this face is modulated.
    pub modulated: bool,
}

/// One modulated face's texture.
#[derive(Clone, Debug)]
struct FaceTexture {
    origin: Vec3,
    u_axis: Vec3,
    v_axis: Vec3,
    /// `(u, v)` of the grid's corner, metres.
    corner: Vec2,
    texel_m: f32,
    /// Per texel, `t` (own where seen, copied where hidden), `None` where the flat fill stays.
    values: Image<Option<Rgb>>,
}

/// The state of a texel during the analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Texel {
    /// Its centre is off the face (a hole, outside a polygon).
    Outside,
    /// The probe did not see its centre.
    Hidden,
    /// The probe saw it: its reflectance texture `t`.
    Seen(Rgb),
}

/// The reflectance texture of every face, for modulating the fill of a moved camera.
#[derive(Clone, Debug)]
pub struct FillTexture {
    /// Per face, its texture when modulated.
    faces: Vec<Option<FaceTexture>>,
    /// Per surface face the probe saw any of, what the analysis found (room order).
    pub analysis: Vec<FaceTextureAnalysis>,
}

impl FillTexture {
    /// Analyses `room` seen in `probe` (lat-long radiance) through `depth` (same size), with the
    /// estimate's irradiance and reflectances.
    pub fn new(
        room: &Room,
        depth: &ProbeDepthMap,
        probe: &Image<Rgb>,
        estimate: &Estimate,
        settings: &FillTextureSettings,
    ) -> Result<FillTexture, RoomError> {
        let period_ok = settings.max_period_m > 0.0 && settings.max_period_m.is_finite();
        let correlation_ok = settings.min_correlation > 0.0 && settings.min_correlation <= 1.0;
        if !(period_ok && correlation_ok) {
            return Err(RoomError::Parameter(format!(
                "max_period_m {} must be positive and min_correlation {} in (0, 1]",
                settings.max_period_m, settings.min_correlation
            )));
        }
        let radiance = RoomRadiance::new(room, depth, probe, estimate)?;
        let pitch_rad = std::f32::consts::PI / probe.height() as f32;
        let grids: Vec<Option<Grid>> = room
            .faces
            .iter()
            .map(|face| {
                let reflectance = estimate.groups[face.group as usize].reflectance;
                match (room.groups[face.group as usize].kind, reflectance) {
                    (GroupKind::Surface, Some(rho)) => {
                        Grid::of(face, room.probe_position, pitch_rad, Rgb::from_array(rho))
                    }
                    _ => None,
                }
            })
            .collect();
        let texels: usize = grids.iter().flatten().map(|g| g.size[0] * g.size[1]).sum();
        if texels > MAX_TEXELS {
            return Err(RoomError::Limits(format!(
                "the fill texture would take {texels} texels, more than {MAX_TEXELS}"
            )));
        }
        let analysed: Vec<Option<(FaceTextureAnalysis, Option<FaceTexture>)>> = grids
            .into_par_iter()
            .enumerate()
            .map(|(f, grid)| {
                let grid = grid?;
                let texels = grid.sample(room, f, &radiance, estimate);
                analyse(room, f, &grid, &texels, settings)
            })
            .collect();
        let mut faces = Vec::with_capacity(analysed.len());
        let mut analysis = Vec::new();
        for a in analysed {
            match a {
                Some((record, texture)) => {
                    analysis.push(record);
                    faces.push(texture);
                }
                None => faces.push(None),
            }
        }
        Ok(FillTexture { faces, analysis })
    }

    /// The modulation `t` of the fill at world point `point` of face `face`: the texel's
    /// reflectance texture, 1 where the face is not modulated or the texel found no source.
    pub fn modulation(&self, face: usize, point: Vec3) -> Rgb {
        let Some(Some(tex)) = self.faces.get(face) else {
            return Rgb::ONE;
        };
        let rel = point - tex.origin;
        let st = Vec2::new(rel.dot(tex.u_axis), rel.dot(tex.v_axis));
        tex.at(st).unwrap_or(Rgb::ONE)
    }
}

impl FaceTexture {
    /// The value of the texel holding face coordinates `st` (clamped to the grid).
    fn at(&self, st: Vec2) -> Option<Rgb> {
        let (w, h) = (self.values.width(), self.values.height());
        let a = ((st - self.corner) / self.texel_m).floor();
        let i = (a.x.max(0.0) as usize).min(w - 1);
        let j = (a.y.max(0.0) as usize).min(h - 1);
        *self.values.get(i, j)
    }
}

/// A face's texel grid before sampling.
#[derive(Clone, Copy, Debug)]
struct Grid {
    corner: Vec2,
    texel_m: f32,
    size: [usize; 2],
    rho: Rgb,
}

impl Grid {
    /// The grid over `face`'s bounding rectangle, texels of the probe's pixel footprint at its
    /// centre (module doc); `None` for an empty face.
    fn of(face: &Face, probe: Vec3, pitch_rad: f32, rho: Rgb) -> Option<Grid> {
        let (lo, hi) = match &face.shape {
            FaceShape::Rectangle { size, .. } => (Vec2::ZERO, Vec2::new(size[0], size[1])),
            FaceShape::Polygon { points } => points.iter().fold(
                (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            ),
        };
        let extent = hi - lo;
        let centre = lo + extent * 0.5;
        let distance = (face.point(centre.x, centre.y) - probe).length();
        // A face through the probe centre would get zero-sized texels: one millimetre at least.
        let texel_m = (distance * pitch_rad).max(TEXEL_PROBE_OFFSET_M);
        let size = [
            (extent.x / texel_m).ceil() as usize,
            (extent.y / texel_m).ceil() as usize,
        ];
        (size[0] > 0 && size[1] > 0 && extent.is_finite()).then_some(Grid {
            corner: lo,
            texel_m,
            size,
            rho,
        })
    }

    /// Face coordinates of texel `(i, j)`'s centre, metres.
    fn centre(&self, i: usize, j: usize) -> Vec2 {
        self.corner + (Vec2::new(i as f32, j as f32) + 0.5) * self.texel_m
    }

    /// Every texel of face `f`: off the face, hidden, or seen with its `t`.
    fn sample(
        &self,
        room: &Room,
        f: usize,
        radiance: &RoomRadiance,
        estimate: &Estimate,
    ) -> Image<Texel> {
        let face = &room.faces[f];
        Image::from_fn_par(self.size[0], self.size[1], |i, j| {
            let st = self.centre(i, j);
            let point = face.point(st.x, st.y);
            let Some(hit) = room.hit(
                point + face.normal * TEXEL_PROBE_OFFSET_M,
                -face.normal,
                0.0,
                2.0 * TEXEL_PROBE_OFFSET_M,
            ) else {
                return Texel::Outside;
            };
            let patch = hit.patch as usize;
            if !hit.front || room.patches[patch].face as usize != f {
                return Texel::Outside;
            }
            let (l, seen) = radiance.at(point, patch);
            let lit = self.rho * estimate.patches[patch].irradiance;
            // A channel without estimated light (or NaN) gives no texture.
            if !seen || !(0..3).all(|c| lit[c] > 0.0) {
                return Texel::Hidden;
            }
            let t = l * std::f32::consts::PI;
            Texel::Seen(Rgb::new(t.r / lit.r, t.g / lit.g, t.b / lit.b))
        })
    }
}

/// The normalised autocorrelation of the seen texels' luminance for lags `1..=max_lag` along
/// `axis` (0 = u, 1 = v); entry `k - 1` is lag `k`, 0 where there are fewer than [`MIN_PAIRS`]
/// pairs or no variance.
fn autocorrelation(texels: &Image<Texel>, axis: usize, max_lag: usize) -> Vec<f32> {
    let (w, h) = (texels.width(), texels.height());
    let lum = |i: usize, j: usize| match *texels.get(i, j) {
        Texel::Seen(t) => Some(f64::from(t.luminance())),
        _ => None,
    };
    let (mut sum, mut count) = (0.0f64, 0usize);
    for j in 0..h {
        for i in 0..w {
            if let Some(y) = lum(i, j) {
                sum += y;
                count += 1;
            }
        }
    }
    let mean = sum / count.max(1) as f64;
    (1..=max_lag)
        .into_par_iter()
        .map(|k| {
            let (mut ab, mut aa, mut bb, mut pairs) = (0.0f64, 0.0f64, 0.0f64, 0usize);
            let (di, dj) = if axis == 0 { (k, 0) } else { (0, k) };
            for j in 0..h.saturating_sub(dj) {
                for i in 0..w.saturating_sub(di) {
                    if let (Some(a), Some(b)) = (lum(i, j), lum(i + di, j + dj)) {
                        let (a, b) = (a - mean, b - mean);
                        ab += a * b;
                        aa += a * a;
                        bb += b * b;
                        pairs += 1;
                    }
                }
            }
            if pairs >= MIN_PAIRS && aa > 0.0 && bb > 0.0 {
                (ab / (aa * bb).sqrt()) as f32
            } else {
                0.0
            }
        })
        .collect()
}

/// The period (texels, refined) and its correlation, and the first lag at which the correlation
/// is negative, of an autocorrelation `r` (entry `k - 1` for lag `k`).
fn period(r: &[f32], min_correlation: f32) -> (Option<(f32, f32)>, Option<usize>) {
    let Some(first_negative) = r.iter().position(|&x| x < 0.0) else {
        return (None, None);
    };
    let peak = (first_negative + 1..r.len().saturating_sub(1))
        .find(|&k| r[k] >= min_correlation && r[k] >= r[k - 1] && r[k] >= r[k + 1])
        .map(|k| {
            let (a, b, c) = (r[k - 1], r[k], r[k + 1]);
            let curvature = a - 2.0 * b + c;
            let offset = if curvature < 0.0 {
                (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
            } else {
                0.0
            };
            // Entry k is lag k + 1.
            ((k + 1) as f32 + offset, b)
        });
    (peak, Some(first_negative + 1))
}

/// The analysis of face `f` from its sampled texels, and its texture when modulated; `None` when
/// the probe saw none of it.
fn analyse(
    room: &Room,
    f: usize,
    grid: &Grid,
    texels: &Image<Texel>,
    settings: &FillTextureSettings,
) -> Option<(FaceTextureAnalysis, Option<FaceTexture>)> {
    let seen = texels
        .pixels()
        .iter()
        .filter(|t| matches!(t, Texel::Seen(_)))
        .count();
    if seen == 0 {
        return None;
    }
    let hidden = texels
        .pixels()
        .iter()
        .filter(|t| matches!(t, Texel::Hidden))
        .count();
    let longest_lag = (settings.max_period_m / grid.texel_m).floor() as usize;
    let mut period_m = [None; 2];
    let mut correlation = [0.0; 2];
    let mut spacing_m = [0.0; 2];
    for axis in 0..2 {
        let max_lag = longest_lag.min(grid.size[axis] / 2);
        let r = autocorrelation(texels, axis, max_lag);
        let (peak, decorrelated) = period(&r, settings.min_correlation);
        if let Some((lag, rho)) = peak {
            period_m[axis] = Some(lag * grid.texel_m);
            correlation[axis] = rho;
        }
        let lag = peak.map_or(decorrelated.unwrap_or(max_lag).max(1) as f32, |p| p.0);
        spacing_m[axis] = lag * grid.texel_m;
    }
    let modulated = period_m.iter().any(Option::is_some) || settings.aperiodic;
    let mut record = FaceTextureAnalysis {
        face: f as u32,
        texel_m: grid.texel_m,
        seen_texels: seen,
        hidden_texels: hidden,
        sourced_texels: 0,
        period_m,
        correlation,
        spacing_m,
        modulated,
    };
    if !modulated {
        return Some((record, None));
    }
    let shifts = shifts(grid, spacing_m);
    let own = |st: Vec2| -> Option<Rgb> {
        let a = ((st - grid.corner) / grid.texel_m).floor();
        if a.x < 0.0 || a.y < 0.0 {
            return None;
        }
        let (i, j) = (a.x as usize, a.y as usize);
        if i >= grid.size[0] || j >= grid.size[1] {
            return None;
        }
        match *texels.get(i, j) {
            Texel::Seen(t) => Some(t),
            _ => None,
        }
    };
    let values = Image::from_fn_par(grid.size[0], grid.size[1], |i, j| match *texels.get(i, j) {
        Texel::Seen(t) => Some(t),
        Texel::Outside => None,
        Texel::Hidden => {
            let st = grid.centre(i, j);
            shifts.iter().find_map(|&d| own(st + d))
        }
    });
    record.sourced_texels = values
        .pixels()
        .iter()
        .zip(texels.pixels())
        .filter(|(v, t)| v.is_some() && matches!(t, Texel::Hidden))
        .count();
    let face = &room.faces[f];
    Some((
        record,
        Some(FaceTexture {
            origin: face.origin,
            u_axis: face.u_axis,
            v_axis: face.v_axis,
            corner: grid.corner,
            texel_m: grid.texel_m,
            values,
        }),
    ))
}

/// The lattice shifts `(m S_u, n S_v)` that stay within the face and [`MAX_SHIFT_STEPS`], nearest
/// first, at most [`MAX_SHIFTS`], `(0, 0)` left out.
fn shifts(grid: &Grid, spacing_m: [f32; 2]) -> Vec<Vec2> {
    let reach = |axis: usize| -> i64 {
        let extent = grid.size[axis] as f32 * grid.texel_m;
        ((extent / spacing_m[axis]).ceil() as i64).min(MAX_SHIFT_STEPS)
    };
    let (mu, mv) = (reach(0), reach(1));
    let mut all: Vec<(i64, i64)> = (-mu..=mu)
        .flat_map(|m| (-mv..=mv).map(move |n| (m, n)))
        .filter(|&s| s != (0, 0))
        .collect();
    let vector = |(m, n): (i64, i64)| Vec2::new(m as f32 * spacing_m[0], n as f32 * spacing_m[1]);
    // Nearest first; ties in a fixed order (by m, then n) so the result never depends on the sort.
    all.sort_by(|&a, &b| {
        vector(a)
            .length_squared()
            .total_cmp(&vector(b).length_squared())
            .then(a.cmp(&b))
    });
    all.truncate(MAX_SHIFTS);
    all.into_iter().map(vector).collect()
}
