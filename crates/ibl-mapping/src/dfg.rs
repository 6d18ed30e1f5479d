//! The split-sum DFG ("BRDF") look-up table (Karis 2013, "Real Shading in Unreal Engine 4",
//! eq. 8): the directional albedo of a GGX microfacet surface with Schlick's Fresnel split into
//! the part that scales `F0` and the part that does not,
//!
//! ```text
//! integral f(l, v) (n.l) dl = F0 A + B,   F = F0 + (1 - F0) Fc,   Fc = (1 - v.h)^5
//! A = integral D V (n.l) (1 - Fc) dl
//! B = integral D V (n.l) Fc dl
//! ```
//!
//! with `V` the height-correlated Smith visibility ([`crate::ggx::smith_ggx_correlated`], as
//! Filament and the Khronos glTF-IBL-Sampler use) and `D` GGX with `alpha = r^2`. Estimated with
//! GGX importance samples of `h` (Hammersley): per sample `4 V (n.l) (v.h) / (n.h)` times the
//! Fresnel factor.
//!
//! **Layout** ([`Dfg`]): texel `(i, j)` of an `N x N` table holds `n.v = (i + 0.5) / N` along x
//! and perceptual roughness `r = (j + 0.5) / N` along y; row 0 (r near 0) is the first row in
//! memory, so a shader reads it with `texture(dfg, vec2(NoV, roughness))` in GL, Vulkan or
//! D3D alike. Two channels:
//!
//! - [`DfgLayout::ScaleBias`] (Karis, glTF-Sample-Viewer, Bevy's table form): `R = A`, `G = B`;
//!   `specular = prefiltered * (F0 * R + G)`.
//! - [`DfgLayout::MultiScatter`] (Filament `cmgen --ibl-dfg-multiscatter`): `R = B`,
//!   `G = A + B`; `specular = prefiltered * mix(R, G, F0)`, and `G` (the single-scattering
//!   albedo `E`) gives the energy compensation `1 + F0 (1 / G - 1)` (Fdez-Aguera 2019).

use glam::DVec3;
use rayon::prelude::*;

use crate::ggx::{ggx_cos_theta, radical_inverse, smith_ggx_correlated};

/// Which quantities the two channels hold (see the module note).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DfgLayout {
    /// `R = A` (scale of F0), `G = B` (bias).
    ScaleBias,
    /// `R = B`, `G = A + B` (Filament's multiple-scattering layout).
    MultiScatter,
}

/// A DFG table: `size x size` texels of two f32 channels, row-major, row 0 = roughness near 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Dfg {
    /// Width and height in texels.
    pub size: usize,
    /// The channel layout.
    pub layout: DfgLayout,
    /// `[R, G]` per texel, row-major.
    pub texels: Vec<[f32; 2]>,
}

/// `(A, B)` of the split sum at `n.v` and perceptual roughness `r`, from `samples` GGX samples.
pub fn dfg_scale_bias(n_v: f64, roughness: f64, samples: usize) -> (f64, f64) {
    let alpha = roughness * roughness;
    let v = DVec3::new((1.0 - n_v * n_v).max(0.0).sqrt(), 0.0, n_v);
    let (mut a, mut b) = (0.0, 0.0);
    let n = samples.max(1);
    for i in 0..n {
        let phi = std::f64::consts::TAU * (i as f64 / n as f64);
        let cos_h = ggx_cos_theta(radical_inverse(i as u32), alpha);
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
        let v_h = v.dot(h);
        let l = 2.0 * v_h * h - v;
        let (n_l, n_h) = (l.z, h.z);
        if n_l <= 0.0 || v_h <= 0.0 || n_h <= 0.0 {
            continue;
        }
        let g = 4.0 * smith_ggx_correlated(n_v, n_l, alpha) * n_l * v_h / n_h;
        let fc = (1.0 - v_h).powi(5);
        a += (1.0 - fc) * g;
        b += fc * g;
    }
    (a / n as f64, b / n as f64)
}

impl DfgLayout {
    /// The layout by the name the command line and the bindings use: `scale-bias`, or
    /// `multi-scatter` (also spelled `multiscatter`).
    pub fn from_name(name: &str) -> Option<DfgLayout> {
        match name {
            "scale-bias" => Some(DfgLayout::ScaleBias),
            "multiscatter" | "multi-scatter" => Some(DfgLayout::MultiScatter),
            _ => None,
        }
    }
}

impl Dfg {
    /// Computes a `size x size` table with `samples` GGX samples per texel (rows in parallel).
    pub fn new(size: usize, samples: usize, layout: DfgLayout) -> Dfg {
        let size = size.max(1);
        let rows: Vec<Vec<[f32; 2]>> = (0..size)
            .into_par_iter()
            .map(|j| {
                let r = (j as f64 + 0.5) / size as f64;
                (0..size)
                    .map(|i| {
                        let n_v = (i as f64 + 0.5) / size as f64;
                        let (a, b) = dfg_scale_bias(n_v, r, samples);
                        match layout {
                            DfgLayout::ScaleBias => [a as f32, b as f32],
                            DfgLayout::MultiScatter => [b as f32, (a + b) as f32],
                        }
                    })
                    .collect()
            })
            .collect();
        Dfg {
            size,
            layout,
            texels: rows.concat(),
        }
    }

    /// The texel at `(i, j)` (`n.v` column, roughness row).
    pub fn get(&self, i: usize, j: usize) -> [f32; 2] {
        self.texels[j * self.size + i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(A, B)` by a midpoint rule over the hemisphere of `l` (no importance sampling): an
    /// independent path to the same integral.
    fn brute(n_v: f64, r: f64) -> (f64, f64) {
        let alpha = r * r;
        let v = DVec3::new((1.0 - n_v * n_v).sqrt(), 0.0, n_v);
        let (nt, np) = (1200, 600);
        let (mut a, mut b) = (0.0, 0.0);
        for it in 0..nt {
            // Uniform in cos(theta_l) so that dOmega = dcos dphi.
            let c = (it as f64 + 0.5) / nt as f64;
            let s = (1.0 - c * c).sqrt();
            for ip in 0..np {
                let phi = std::f64::consts::TAU * (ip as f64 + 0.5) / np as f64;
                let l = DVec3::new(s * phi.cos(), s * phi.sin(), c);
                let h = (l + v).normalize();
                let v_h = v.dot(h);
                let d = crate::ggx::ggx_d(h.z, alpha);
                let f = d * smith_ggx_correlated(n_v, c, alpha) * c;
                let w = f * std::f64::consts::TAU / (nt * np) as f64;
                let fc = (1.0 - v_h).powi(5);
                a += (1.0 - fc) * w;
                b += fc * w;
            }
        }
        (a, b)
    }

    #[test]
    fn importance_sampling_matches_a_hemisphere_quadrature() {
        for &(n_v, r) in &[(0.9, 0.5), (0.5, 0.7), (0.2, 0.9), (0.7, 0.35)] {
            let (a, b) = dfg_scale_bias(n_v, r, 4096);
            let (ea, eb) = brute(n_v, r);
            // Quasi-Monte Carlo error of 4096 Hammersley samples against a 1200 x 600 midpoint
            // grid: measured under 3e-3 absolute; 1e-2 is the margin.
            assert!(
                (a - ea).abs() < 1e-2 && (b - eb).abs() < 1e-2,
                "{n_v} {r}: {a} {b} vs {ea} {eb}"
            );
        }
    }

    #[test]
    fn a_mirror_reflects_schlick_fresnel() {
        // r -> 0: h = n, so A = 1 - (1 - n.v)^5 and B = (1 - n.v)^5 exactly (closed form).
        for n_v in [0.1, 0.5, 0.95] {
            let (a, b) = dfg_scale_bias(n_v, 1e-4, 64);
            let fc = (1.0 - n_v).powi(5);
            assert!(
                (a - (1.0 - fc)).abs() < 1e-6 && (b - fc).abs() < 1e-6,
                "{n_v} {a} {b}"
            );
        }
    }

    #[test]
    fn albedo_never_exceeds_one_and_falls_with_roughness() {
        let t = Dfg::new(16, 512, DfgLayout::MultiScatter);
        for j in 0..16 {
            for i in 0..16 {
                let [b, e] = t.get(i, j);
                assert!(e <= 1.0 + 1e-3 && b >= 0.0 && b <= e, "{i} {j} {b} {e}");
            }
        }
        // Single scattering loses energy at high roughness (Kulla & Conty 2017, fig. 1), and a
        // nearly smooth surface keeps it all.
        assert!(t.get(15, 15)[1] < 0.8 && t.get(15, 0)[1] > 0.99);
        let s = Dfg::new(16, 512, DfgLayout::ScaleBias);
        let [a, b] = s.get(7, 9);
        let [b2, e] = t.get(7, 9);
        assert!((b - b2).abs() < 1e-6 && (a + b - e).abs() < 1e-6);
    }
}
