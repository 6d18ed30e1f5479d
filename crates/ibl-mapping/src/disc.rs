//! Disc-shaped mappings: angular map, mirror ball and equidistant fisheye (CONVENTIONS section 3).
//!
//! A disc lives in a cell of the image (the whole square image, or one half of a dual fisheye)
//! with disc coordinates `a = 2 (x - x0) / cw - 1` (right +) and `b = 1 - 2 y / h` (up +), the
//! unit disc `r = sqrt(a^2 + b^2) <= 1` being the domain. Each mapping is radial: the polar angle
//! `alpha(r)` from the lens axis depends on `r` only and the azimuth is `atan2(b, a)`:
//!
//! ```text
//! angular map   alpha = pi r                   axis -Z   d = (sin a cos p, sin a sin p, -cos a)
//! mirror ball   cos alpha = 1 - 2 r^2          axis +Z   d = (2ca, 2cb, 2c^2 - 1), c = sqrt(1-r^2)
//! fisheye       alpha = (fov / 2) r            axis -Z (the back lens of a dual: +Z, x mirrored)
//! ```
//!
//! (The mirror-ball line is `d = i - 2 (i.n) n` with `n = (a, b, c)`, `i = (0, 0, -1)`.)
//!
//! Solid angle: with `H(r) = 1 - cos alpha(r)` (the cap of radius r is `2 pi H(r)`), the density
//! is `dOmega = H'(r) / r  da db`: angular `pi sin(pi r) / r`, fisheye `F sin(F r) / r` with
//! `F = fov / 2`, and the mirror ball exactly `4 da db` (it is an equal-area map: `H = 2 r^2`).
//! The solid angle of a pixel clipped to the disc is computed exactly by Green's theorem,
//! `Omega(R) = contour integral of H(r) dpsi` around the boundary of R = pixel square cap disc:
//! along a straight edge `P(t) = P0 + t D` the integrand is `K(|P|) (P0 x D) dt` with
//! `K(r) = H(r) / r^2` smooth (so 4-point Gauss-Legendre is exact to rounding on pixel-sized
//! edges), and along the circle it is `H(1) dpsi`. Rim pixels therefore get their exact clipped
//! solid angle and the total is `2 pi H(1)` (4 pi for angular and ball) to about 1e-12. The
//! same machinery takes any radial weight (the dual fisheye's blend weights) through `H`.
//!
//! Singular rims. The angular map's rim is the single direction +Z and the mirror ball's is -Z:
//! near it the map is extremely anisotropic (a ball pixel on the rim of a 1024-pixel ball spans
//! about 7 degrees radially and a sliver tangentially; everything within 1 degree of -Z lies in
//! the outer 0.02 pixel). Resampling adapts its rate per axis to this, up to its cap, but a bright
//! source within a degree or so of the ball's -Z (or the angular map's +Z) cannot be carried
//! faithfully: its power may be off by tens of per cent. A real mirror-ball photo does not see
//! -Z at all (the ball hides it), so this only matters for synthetic data.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use crate::taps::{Taps, bilinear_corners};

/// The radial law of a disc mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Profile {
    /// `alpha = pi r`.
    Angular,
    /// `cos alpha = 1 - 2 r^2` (orthographic mirror ball).
    MirrorBall,
    /// `alpha = half_fov r` (equidistant fisheye), `half_fov` in radians, in (0, pi].
    Equidistant {
        /// Half the field of view, radians.
        half_fov: f64,
    },
}

/// `sin(c r / 2) / r`, finite at r = 0.
fn half_sinc(c: f64, r: f64) -> f64 {
    if r < 1e-7 {
        0.5 * c
    } else {
        (0.5 * c * r).sin() / r
    }
}

impl Profile {
    /// `(sin alpha, cos alpha)` at disc radius `r` in [0, 1].
    pub(crate) fn angle(self, r: f64) -> (f64, f64) {
        match self {
            Profile::Angular => (PI * r).sin_cos(),
            Profile::MirrorBall => {
                let c = (1.0 - r * r).max(0.0).sqrt();
                (2.0 * r * c, 1.0 - 2.0 * r * r)
            }
            Profile::Equidistant { half_fov } => (half_fov * r).sin_cos(),
        }
    }

    /// `(sin alpha, cos alpha, density)` at radius `r` with one `sin_cos` (the hot path of
    /// [`Disc::dir_density`]).
    pub(crate) fn angle_density(self, r: f64) -> (f64, f64, f64) {
        let scaled = |c: f64| {
            let (s, co) = (c * r).sin_cos();
            let dens = if r > 1e-7 { c * s / r } else { c * c };
            (s, co, dens)
        };
        match self {
            Profile::Angular => scaled(PI),
            Profile::MirrorBall => {
                let (s, c) = self.angle(r);
                (s, c, 4.0)
            }
            Profile::Equidistant { half_fov } => scaled(half_fov),
        }
    }

    /// Disc radius of polar angle `alpha` in [0, pi]; `None` beyond a fisheye's rim.
    pub(crate) fn radius(self, alpha: f64) -> Option<f64> {
        match self {
            Profile::Angular => Some((alpha / PI).min(1.0)),
            Profile::MirrorBall => Some((0.5 * alpha).sin().min(1.0)),
            Profile::Equidistant { half_fov } => {
                let r = alpha / half_fov;
                if r <= 1.0 + 1e-12 {
                    Some(r.min(1.0))
                } else {
                    None
                }
            }
        }
    }

    /// Solid-angle density `dOmega / (da db)` at radius `r` (finite at r = 0).
    #[cfg(test)]
    pub(crate) fn density(self, r: f64) -> f64 {
        match self {
            Profile::Angular => PI * half_sinc(TAU, r),
            Profile::MirrorBall => 4.0,
            Profile::Equidistant { half_fov } => half_fov * half_sinc(2.0 * half_fov, r),
        }
    }

    /// `H(r) = 1 - cos alpha(r)`.
    pub(crate) fn cap(self, r: f64) -> f64 {
        self.cap_over_r2(r) * r * r
    }

    /// `K(r) = H(r) / r^2`, smooth and finite at r = 0.
    pub(crate) fn cap_over_r2(self, r: f64) -> f64 {
        match self {
            Profile::Angular => 2.0 * half_sinc(PI, r).powi(2),
            Profile::MirrorBall => 2.0,
            Profile::Equidistant { half_fov } => 2.0 * half_sinc(half_fov, r).powi(2),
        }
    }
}

/// A disc mapping placed in an image cell: profile, orientation and cell geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Disc {
    /// The radial law.
    pub profile: Profile,
    /// Sign of world x for disc right (+1, or -1 for the backward lens of a dual fisheye).
    pub sx: f64,
    /// World z of the lens axis (the disc centre's direction): -1 forward, +1 backward.
    pub sz: f64,
    /// First column of the cell.
    pub x0: usize,
    /// Cell width in pixels.
    pub cw: usize,
    /// Cell (image) height in pixels.
    pub h: usize,
    /// `2 / cw`: disc units per pixel across.
    sa: f64,
    /// `2 / h`: disc units per pixel down.
    sb: f64,
}

impl Disc {
    /// A disc of `profile` in the `cw x h` cell starting at column `x0`; `sx` and `sz` orient it
    /// (see the fields).
    pub(crate) fn new(profile: Profile, sx: f64, sz: f64, x0: usize, cw: usize, h: usize) -> Self {
        Disc {
            profile,
            sx,
            sz,
            x0,
            cw,
            h,
            sa: 2.0 / cw as f64,
            sb: 2.0 / h as f64,
        }
    }

    /// Disc coordinates `(a, b)` of continuous image coordinates.
    pub(crate) fn disc_coords(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.x0 as f64) * self.sa - 1.0, 1.0 - y * self.sb)
    }

    /// Direction and solid-angle density per unit pixel area at disc coordinates `(a, b)`;
    /// `None` outside the unit disc.
    pub(crate) fn dir_density(&self, a: f64, b: f64) -> Option<(DVec3, f64)> {
        let r = (a * a + b * b).sqrt();
        if r.is_nan() || r > 1.0 {
            return None;
        }
        let (s, c, density) = self.profile.angle_density(r);
        let (cp, sp) = if r > 0.0 { (a / r, b / r) } else { (1.0, 0.0) };
        let d = DVec3::new(self.sx * s * cp, s * sp, self.sz * c);
        Some((d, density * self.sa * self.sb))
    }

    /// Direction nearest to `(a, b)` inside the disc (radius clamped just inside the rim).
    pub(crate) fn clamped_dir(&self, a: f64, b: f64) -> Option<DVec3> {
        let r = (a * a + b * b).sqrt();
        let scale = if r > 1.0 - 1e-9 {
            (1.0 - 1e-9) / r
        } else {
            1.0
        };
        self.dir_density(a * scale, b * scale).map(|(d, _)| d)
    }

    /// Polar angle of a unit direction from this lens' axis, and disc coordinates of it
    /// (`None` if the profile does not reach that angle).
    pub(crate) fn disc_of_dir(&self, d: DVec3) -> Option<(f64, f64)> {
        let lx = self.sx * d.x;
        let ly = d.y;
        let lz = self.sz * d.z;
        if self.profile == Profile::MirrorBall && lz > 0.0 {
            // r = sin(alpha / 2) and (a, b) = r (lx, ly) / rho = (lx, ly) / sqrt(2 (1 + z)).
            let k = 1.0 / (2.0 * (1.0 + lz)).sqrt();
            return Some((lx * k, ly * k));
        }
        let rho = (lx * lx + ly * ly).sqrt();
        let alpha = rho.atan2(lz);
        let r = self.profile.radius(alpha)?;
        if rho > 0.0 {
            Some((r * lx / rho, r * ly / rho))
        } else {
            Some((r, 0.0))
        }
    }

    /// Continuous image coordinates of a unit direction.
    pub(crate) fn pixel_of_dir(&self, d: DVec3) -> Option<(f64, f64)> {
        let (a, b) = self.disc_of_dir(d)?;
        Some((
            self.x0 as f64 + 0.5 * (a + 1.0) * self.cw as f64,
            0.5 * (1.0 - b) * self.h as f64,
        ))
    }

    /// Disc-coordinate bounds `(a0, a1, b0, b1)` of cell pixel `(i, j)` (i relative to the cell).
    pub(crate) fn texel_bounds(&self, i: usize, j: usize) -> (f64, f64, f64, f64) {
        let a0 = i as f64 * self.sa - 1.0;
        let a1 = (i + 1) as f64 * self.sa - 1.0;
        let b0 = 1.0 - (j + 1) as f64 * self.sb;
        let b1 = 1.0 - j as f64 * self.sb;
        (a0, a1, b0, b1)
    }

    /// Whether cell pixel `(i, j)` overlaps the open unit disc (has a positive solid angle).
    pub(crate) fn texel_in_disc(&self, i: usize, j: usize) -> bool {
        let (a0, a1, b0, b1) = self.texel_bounds(i, j);
        let a = 0.0_f64.clamp(a0, a1);
        let b = 0.0_f64.clamp(b0, b1);
        a * a + b * b < 1.0
    }

    /// Exact solid angle of cell pixel `(i, j)` clipped to the disc, for the radial law's own
    /// cap function.
    pub(crate) fn texel_solid_angle(&self, i: usize, j: usize) -> f64 {
        let p = self.profile;
        let constant = (p == Profile::MirrorBall).then_some(2.0);
        clipped_solid_angle(
            self.texel_bounds(i, j),
            |r| p.cap(r),
            |r| p.cap_over_r2(r),
            constant,
        )
    }

    /// Bilinear taps at continuous image coordinates `(x, y)` using only the cell's pixels that
    /// overlap the disc (weights renormalised to sum to 1), so nothing outside the disc or in
    /// the other cell bleeds in. Indices are into the whole image with `stride` pixels per row.
    pub(crate) fn taps(&self, stride: usize, x: f64, y: f64) -> Taps {
        let mut taps = Taps::default();
        for (i, j, w) in bilinear_corners(x - self.x0 as f64 - 0.5, y - 0.5, self.cw, self.h) {
            if w > 0.0 && self.texel_in_disc(i, j) {
                taps.push(j * stride + self.x0 + i, w);
            }
        }
        if taps.is_empty() {
            let i = (x - self.x0 as f64)
                .floor()
                .clamp(0.0, (self.cw - 1) as f64) as usize;
            let j = y.floor().clamp(0.0, (self.h - 1) as f64) as usize;
            taps.push(j * stride + self.x0 + i, 1.0);
        }
        taps.normalised()
    }
}

/// 4-point Gauss-Legendre nodes and weights on [-1, 1].
const GAUSS4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// Roots `r0 <= r1` of `|P0 + t D| = 1` (the line's crossings of the unit circle), if the line
/// passes through the open disc.
fn circle_roots(p0: (f64, f64), d: (f64, f64)) -> Option<(f64, f64)> {
    let qa = d.0 * d.0 + d.1 * d.1;
    let qb = 2.0 * (p0.0 * d.0 + p0.1 * d.1);
    let qc = p0.0 * p0.0 + p0.1 * p0.1 - 1.0;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa <= 0.0 || disc <= 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // Numerically stable roots.
    let q = -0.5 * (qb + if qb < 0.0 { -sq } else { sq });
    let (r0, r1) = if q != 0.0 {
        (q / qa, qc / q)
    } else {
        (-sq / (2.0 * qa), sq / (2.0 * qa))
    };
    Some((r0.min(r1), r0.max(r1)))
}

/// Solid angle of the rectangle `(a0, a1, b0, b1)` clipped to the unit disc, for a radial
/// density whose cap function is `cap(r) = H(r)` with `cap_over_r2(r) = H(r) / r^2` (or the
/// constant `constant_k` if `H / r^2` is constant, as for the mirror ball):
/// `Omega = contour integral of H dpsi` (Green's theorem; see the module note). Cost O(1).
pub(crate) fn clipped_solid_angle(
    rect: (f64, f64, f64, f64),
    cap: impl Fn(f64) -> f64,
    cap_over_r2: impl Fn(f64) -> f64,
    constant_k: Option<f64>,
) -> f64 {
    let (a0, a1, b0, b1) = rect;
    // Counter-clockwise in (a, b) (b up).
    let corners = [(a0, b0), (a1, b0), (a1, b1), (a0, b1)];
    let mut total = 0.0;
    let mut crossings = [0.0_f64; 8];
    let mut n_cross = 0;
    for k in 0..4 {
        let p0 = corners[k];
        let p1 = corners[(k + 1) % 4];
        let d = (p1.0 - p0.0, p1.1 - p0.1);
        let Some((r0, r1)) = circle_roots(p0, d) else {
            continue;
        };
        // A (nearly) tangent line only grazes the disc: its chord has no area, and its two
        // crossings are too ill-conditioned (error ~ sqrt(eps)) to delimit arcs.
        if (r1 - r0) * (d.0 * d.0 + d.1 * d.1).sqrt() < 1e-6 {
            continue;
        }
        for t in [r0, r1] {
            if (-1e-12..=1.0 + 1e-12).contains(&t) && n_cross < crossings.len() {
                crossings[n_cross] = (p0.1 + t * d.1).atan2(p0.0 + t * d.0);
                n_cross += 1;
            }
        }
        let (t0, t1) = (r0.max(0.0), r1.min(1.0));
        let cross = p0.0 * d.1 - p0.1 * d.0;
        if t1 <= t0 || cross == 0.0 {
            continue;
        }
        if let Some(k) = constant_k {
            total += cross * k * (t1 - t0);
            continue;
        }
        // Split long edges so the 4-point rule stays accurate on tiny images.
        let len = (t1 - t0) * (d.0 * d.0 + d.1 * d.1).sqrt();
        let pieces = (len / 0.05).ceil().clamp(1.0, 64.0) as usize;
        let step = (t1 - t0) / pieces as f64;
        let mut integral = 0.0;
        for p in 0..pieces {
            let mid = t0 + (p as f64 + 0.5) * step;
            for (node, w) in GAUSS4 {
                let t = mid + 0.5 * step * node;
                let (x, y) = (p0.0 + t * d.0, p0.1 + t * d.1);
                integral += w * 0.5 * step * cap_over_r2((x * x + y * y).sqrt());
            }
        }
        total += cross * integral;
    }
    // Arcs of the unit circle inside the rectangle, traversed counter-clockwise.
    let inside = |x: f64, y: f64| x >= a0 && x <= a1 && y >= b0 && y <= b1;
    let crossings = &mut crossings[..n_cross];
    let arc = if crossings.is_empty() {
        if inside(1.0, 0.0) && inside(-1.0, 0.0) && inside(0.0, 1.0) && inside(0.0, -1.0) {
            TAU
        } else {
            0.0
        }
    } else {
        crossings.sort_by(f64::total_cmp);
        let n = crossings.len();
        let mut sum = 0.0;
        for k in 0..n {
            let start = crossings[k];
            let end = if k + 1 < n {
                crossings[k + 1]
            } else {
                crossings[0] + TAU
            };
            let mid = 0.5 * (start + end);
            if end > start && inside(mid.cos(), mid.sin()) {
                sum += end - start;
            }
        }
        sum
    };
    // Pixels that only touch the rim can round to -1e-17.
    (total + cap(1.0) * arc).max(0.0)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;

    fn disc(profile: Profile, n: usize) -> Disc {
        Disc::new(profile, 1.0, -1.0, 0, n, n)
    }

    #[test]
    fn profiles_invert() {
        for profile in [
            Profile::Angular,
            Profile::MirrorBall,
            Profile::Equidistant { half_fov: 1.7 },
        ] {
            let dsc = disc(profile, 64);
            for &(a, b) in &[(0.0, 0.0), (0.3, -0.2), (-0.7, 0.6), (0.05, 0.99)] {
                let (d, _) = dsc.dir_density(a, b).unwrap();
                assert!((d.length() - 1.0).abs() < 1e-12);
                let (a2, b2) = dsc.disc_of_dir(d).unwrap();
                assert!(
                    (a - a2).abs() < 1e-9 && (b - b2).abs() < 1e-9,
                    "{profile:?} {a} {b}"
                );
            }
        }
    }

    #[test]
    fn density_matches_cap_derivative() {
        for profile in [
            Profile::Angular,
            Profile::MirrorBall,
            Profile::Equidistant { half_fov: 1.2 },
        ] {
            for r in [0.1, 0.5, 0.9] {
                let h = 1e-6;
                let deriv = (profile.cap(r + h) - profile.cap(r - h)) / (2.0 * h);
                assert!(
                    (deriv / r - profile.density(r)).abs() < 1e-6,
                    "{profile:?} {r}"
                );
                let (_, c) = profile.angle(r);
                assert!((profile.cap(r) - (1.0 - c)).abs() < 1e-12);
                let (s2, c2, dens) = profile.angle_density(r);
                assert!((s2, c2) == profile.angle(r) || (dens - profile.density(r)).abs() < 1e-12);
                assert!((dens - profile.density(r)).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn clipped_areas_of_a_uniform_density() {
        // H = r^2 / 2 is density 1: plain areas.
        let cap = |r: f64| 0.5 * r * r;
        let k = |_r: f64| 0.5;
        let whole = clipped_solid_angle((-1.0, 1.0, -1.0, 1.0), cap, k, None);
        assert!((whole - PI).abs() < 1e-12);
        let quarter = clipped_solid_angle((0.0, 1.0, 0.0, 1.0), cap, k, None);
        assert!((quarter - PI / 4.0).abs() < 1e-12);
        let inner = clipped_solid_angle((0.1, 0.2, -0.3, -0.2), cap, k, None);
        assert!((inner - 0.01).abs() < 1e-15);
        let outside = clipped_solid_angle((1.0, 2.0, 1.0, 2.0), cap, k, None);
        assert_eq!(outside, 0.0);
        let big = clipped_solid_angle((-3.0, 3.0, -2.0, 2.0), cap, k, None);
        assert!((big - PI).abs() < 1e-12);
        // A rectangle straddling the rim: [0.5, 1] x [0, 0.5] minus the corner outside.
        let straddle = clipped_solid_angle((0.5, 1.0, 0.0, 0.5), cap, k, None);
        let g = |u: f64| 0.5 * (u * (1.0 - u * u).sqrt() + u.asin());
        let x0 = 0.75_f64.sqrt();
        let exact = 0.5 * (x0 - 0.5) + (g(1.0) - g(x0));
        assert!((straddle - exact).abs() < 1e-12, "{straddle} {exact}");
    }
}
