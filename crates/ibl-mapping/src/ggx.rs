//! The GGX (Trowbridge-Reitz) microfacet distribution as engines use it for image-based
//! lighting, its importance sampling, and the roughness each engine expects at each mip level.
//!
//! **Distribution** (Walter et al. 2007, eq. 33), with `alpha = r^2` for perceptual roughness
//! `r` (the glTF / Disney / Filament convention):
//!
//! ```text
//! D(h) = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)
//! ```
//!
//! **Sampling** (Karis 2013, "Real Shading in Unreal Engine 4"): Hammersley points
//! `(i / N, radical_inverse_2(i))` give `phi = 2 pi u`,
//! `cos theta_h = sqrt((1 - v) / (1 + (alpha^2 - 1) v))`, i.e. `h` with density `D(h) (n.h)`.
//! With the split-sum assumption `n = v = r` the light direction is `l = 2 (n.h) h - n`, of
//! density `D(h) / 4` per steradian of `l`.
//!
//! **Roughness per mip** ([`EngineTarget`]): each engine samples its prefiltered cube at a level
//! computed from the material's perceptual roughness with its own formula; the chain must be
//! filtered with the inverse, level by level. Sources are named on each variant and in
//! `docs/PREFILTER.md`.

use std::f64::consts::PI;

/// GGX `D(h)` for `cos_h = n.h` and `alpha = r^2` (1/sr).
pub fn ggx_d(cos_h: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let f = cos_h * cos_h * (a2 - 1.0) + 1.0;
    a2 / (PI * f * f)
}

/// Van der Corput radical inverse in base 2 of `i` (the second Hammersley coordinate).
pub fn radical_inverse(i: u32) -> f64 {
    f64::from(i.reverse_bits()) * (1.0 / 4_294_967_296.0)
}

/// `cos theta_h` of the GGX sample for the uniform variate `v` in [0, 1).
pub fn ggx_cos_theta(v: f64, alpha: f64) -> f64 {
    ((1.0 - v) / (1.0 + (alpha * alpha - 1.0) * v))
        .max(0.0)
        .sqrt()
}

/// Smith-GGX height-correlated visibility `V = G2 / (4 (n.l)(n.v))` (Heitz 2014, eq. 99; the
/// form of Filament and the Khronos glTF-IBL-Sampler).
pub fn smith_ggx_correlated(n_v: f64, n_l: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let gv = n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt();
    let gl = n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt();
    0.5 / (gv + gl)
}

/// The engine whose roughness-per-mip convention a prefiltered chain follows (`r` = perceptual
/// roughness, `m` = mip level, `L` = number of levels).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EngineTarget {
    /// Filament (cmgen, `IndirectLight`): `m / (L - 1) = r (2 - r)`, so
    /// `r = 1 - sqrt(1 - m / (L - 1))`; levels down to 16 px faces (cmgen
    /// `--ibl-min-lod-size`, default 16). Source: filament
    /// `libs/iblprefilter/src/IBLPrefilterContext.cpp` (`lodToPerceptualRoughness`) and its
    /// inverse in the shaders (`perceptualRoughnessToLod`).
    Filament,
    /// Khronos glTF-IBL-Sampler and glTF-Sample-Viewer: `r = m / (L - 1)`, `L = log2(S)` (the
    /// smallest level is 2 x 2). Source: glTF-IBL-Sampler `lib/source/lib.cpp`
    /// (`values.roughness = currentMipLevel / (outputMipLevels - 1)`,
    /// `_mipmapCount = floor(log2(resolution))`).
    Khronos,
    /// Bevy (`EnvironmentMapLight`): `m = r (L - 1)` with `L` the levels in the file
    /// (`crates/bevy_pbr/src/light_probe/environment_map.wgsl`:
    /// `perceptual_roughness * f32(textureNumLevels(...) - 1)`);
    /// the chain is the full one down to 1 x 1. Bevy samples the cube at `(x, y, -z)`.
    Bevy,
    /// Unity (built-in and SRP): `m = 6 r (1.7 - 0.7 r)` (`UNITY_SPECCUBE_LOD_STEPS = 6`,
    /// seven levels), so `r = (1.7 - sqrt(2.89 - 2.8 m / 6)) / 1.4`. Source: Unity SRP core
    /// `ShaderLibrary/ImageBasedLighting.hlsl` (`PerceptualRoughnessToMipmapLevel`,
    /// `MipmapLevelToPerceptualRoughness`).
    Unity,
    /// three.js PMREM (`cube_uv_reflection_fragment.glsl.js`, `roughnessToMip`): a level of face
    /// size `2^k` holds `r = 2^(-k/2) / 1.16` where that is under 0.21, else the piecewise-linear
    /// inverse (k = 4: 0.21, 3: 0.305, 2: 0.4); levels down to 16 px. three.js filters its own
    /// chain when it loads a map; this target reproduces the roughness it gives each face size.
    Threejs,
}

impl EngineTarget {
    /// Every target.
    pub const ALL: [EngineTarget; 5] = [
        EngineTarget::Filament,
        EngineTarget::Khronos,
        EngineTarget::Bevy,
        EngineTarget::Unity,
        EngineTarget::Threejs,
    ];

    /// The target's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EngineTarget::Filament => "filament",
            EngineTarget::Khronos => "khronos",
            EngineTarget::Bevy => "bevy",
            EngineTarget::Unity => "unity",
            EngineTarget::Threejs => "threejs",
        }
    }

    /// Looks a target up by name (`gltf` is an alias of `khronos`).
    pub fn from_name(name: &str) -> Option<EngineTarget> {
        match name.to_ascii_lowercase().as_str() {
            "filament" | "cmgen" => Some(EngineTarget::Filament),
            "khronos" | "gltf" | "gltf-ibl-sampler" => Some(EngineTarget::Khronos),
            "bevy" => Some(EngineTarget::Bevy),
            "unity" => Some(EngineTarget::Unity),
            "threejs" | "three" | "three.js" => Some(EngineTarget::Threejs),
            _ => None,
        }
    }

    /// Number of mip levels of a chain whose level 0 has faces of `size` (a power of two).
    pub fn level_count(self, size: usize) -> usize {
        let full = size.max(1).trailing_zeros() as usize + 1; // down to 1 x 1
        match self {
            EngineTarget::Filament | EngineTarget::Threejs => full.saturating_sub(4).max(1),
            EngineTarget::Khronos => (full - 1).max(1),
            EngineTarget::Bevy => full,
            EngineTarget::Unity => full.min(7),
        }
    }

    /// Perceptual roughness of level `m` of a `levels`-level chain whose level 0 has faces of
    /// `size` (see each variant). Level 0 is always 0 (the mirror).
    pub fn roughness(self, m: usize, levels: usize, size: usize) -> f64 {
        if m == 0 || levels <= 1 {
            return 0.0;
        }
        let x = (m as f64 / (levels - 1) as f64).min(1.0);
        match self {
            EngineTarget::Filament => 1.0 - (1.0 - x).max(0.0).sqrt(),
            EngineTarget::Khronos | EngineTarget::Bevy => x,
            EngineTarget::Unity => {
                let t = (m as f64 / 6.0).min(1.0); // m / UNITY_SPECCUBE_LOD_STEPS
                ((1.7 - (2.89 - 2.8 * t).max(0.0).sqrt()) / 1.4).clamp(0.0, 1.0)
            }
            EngineTarget::Threejs => {
                let k = (size >> m).max(1).trailing_zeros() as f64; // log2 of the face size
                threejs_roughness(k)
            }
        }
    }
}

/// three.js `roughnessToMip` inverted: the roughness whose mip is `k` (piecewise linear above
/// r = 0.21, `-2 log2(1.16 r)` below).
fn threejs_roughness(k: f64) -> f64 {
    // (roughness, mip) knots of cube_uv_reflection_fragment.glsl.
    const KNOTS: [(f64, f64); 5] = [
        (1.0, -2.0),
        (0.8, -1.0),
        (0.4, 2.0),
        (0.305, 3.0),
        (0.21, 4.0),
    ];
    let log_part = 2f64.powf(-k / 2.0) / 1.16;
    if log_part < KNOTS[4].0 {
        return log_part;
    }
    for w in KNOTS.windows(2) {
        let ((r0, m0), (r1, m1)) = (w[0], w[1]);
        if k <= m1 {
            return r0 + (k - m0) / (m1 - m0) * (r1 - r0);
        }
    }
    KNOTS[4].0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution_is_normalised_over_projected_area() {
        // integral D(h) (n.h) dOmega = 1 (midpoint rule in cos theta, 400000 steps).
        for alpha in [0.05, 0.3, 1.0] {
            let n = 400_000;
            let s: f64 = (0..n)
                .map(|k| {
                    let c = (k as f64 + 0.5) / n as f64;
                    ggx_d(c, alpha) * c * 2.0 * PI / n as f64
                })
                .sum();
            // Midpoint rule on a peak of width alpha^2 = 0.0025: 1.3e-4 at 20000 steps, about
            // 3e-7 at 400000 (error falls as the square of the step).
            assert!((s - 1.0).abs() < 1e-4, "{alpha} {s}");
        }
    }

    #[test]
    fn sampling_inverts_the_cdf() {
        // P(cos theta_h > c(v)) = v for the density D (n.h): the CDF in closed form.
        for alpha in [0.1f64, 0.5, 0.9] {
            for v in [0.1, 0.5, 0.9] {
                let c = ggx_cos_theta(v, alpha);
                let a2 = alpha * alpha;
                let cdf_above = (1.0 - c * c) / (1.0 + (a2 - 1.0) * c * c);
                assert!((cdf_above - v).abs() < 1e-12, "{alpha} {v}");
            }
        }
        assert_eq!(radical_inverse(1), 0.5);
        assert_eq!(radical_inverse(2), 0.25);
        assert_eq!(radical_inverse(3), 0.75);
    }

    #[test]
    fn roughness_schedules_match_each_engines_forward_formula() {
        let size = 256;
        for target in EngineTarget::ALL {
            assert_eq!(EngineTarget::from_name(target.name()), Some(target));
            let levels = target.level_count(size);
            for m in 0..levels {
                let r = target.roughness(m, levels, size);
                // The engine's own level-from-roughness formula must give m back.
                let back = match target {
                    EngineTarget::Filament => (levels - 1) as f64 * r * (2.0 - r),
                    EngineTarget::Khronos | EngineTarget::Bevy => r * (levels - 1) as f64,
                    EngineTarget::Unity => 6.0 * r * (1.7 - 0.7 * r),
                    EngineTarget::Threejs if m == 0 => continue, // level 0 is the mirror
                    EngineTarget::Threejs => {
                        let k = (size >> m).trailing_zeros() as f64;
                        let mip = if r < 0.21 {
                            -2.0 * (1.16 * r).log2()
                        } else if r < 0.305 {
                            (0.305 - r) / (0.305 - 0.21) + 3.0
                        } else {
                            (0.4 - r) / (0.4 - 0.305) + 2.0
                        };
                        assert!((mip - k).abs() < 1e-9, "{m} {r} {mip} {k}");
                        continue;
                    }
                };
                assert!((back - m as f64).abs() < 1e-9, "{target:?} {m} {r} {back}");
            }
        }
        assert_eq!(EngineTarget::Filament.level_count(256), 5);
        assert_eq!(EngineTarget::Khronos.level_count(256), 8);
        assert_eq!(EngineTarget::Bevy.level_count(256), 9);
        assert_eq!(EngineTarget::Unity.level_count(256), 7);
        assert_eq!(EngineTarget::Threejs.level_count(256), 5);
    }
}
