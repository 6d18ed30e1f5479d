//! A seamless mip pyramid of a cube map, for filtered importance sampling (Krivanek & Colbert,
//! "Real-time shading with filtered importance sampling", EGSR 2008; GPU Gems 3 ch. 20).
//!
//! Level 0 holds the six faces (GL/KTX orientation, [`crate::cube`]); level `l + 1` halves the
//! face size, each texel the **solid-angle-weighted** mean of its 2 x 2 children,
//!
//! ```text
//! L_parent = sum_c L_c dOmega_c / sum_c dOmega_c
//! ```
//!
//! so every level carries the same power `sum L dOmega` as level 0 (to f32 rounding): a plain
//! 2 x 2 average would brighten the face corners, whose texels subtend less solid angle.
//!
//! **Seamless look-ups.** Each face is stored with a one-texel border filled from the
//! neighbouring faces (the border texel's centre direction, looked up on the face that owns it),
//! so a bilinear look-up near an edge blends texels of both faces, as GPUs do with seamless cube
//! filtering. A look-up is trilinear: bilinear in the two levels around a fractional `lod`,
//! blended linearly. Radiance is f32 (the prefiltered sums are f32 too).

use glam::{DVec3, Vec3};
use ibl_core::{Image, Rgb};

use crate::cube::{CubeImage, dir_face, face_dir};
use crate::error::MappingError;
use crate::mapping::CubeLayout;

/// One level: six bordered faces of `(size + 2)^2` texels, face-major then row-major.
#[derive(Clone, Debug)]
struct Level {
    size: usize,
    texels: Vec<[f32; 3]>,
}

impl Level {
    fn stride(&self) -> usize {
        self.size + 2
    }

    /// Index of face texel `(i, j)` in bordered coordinates (`-1..=size`, shifted by one).
    fn index(&self, face: usize, bi: usize, bj: usize) -> usize {
        let st = self.stride();
        face * st * st + bj * st + bi
    }

    /// Fills the border of every face from the neighbouring faces.
    fn fill_borders(&mut self) {
        let s = self.size;
        let st = self.stride();
        let sf = s as f64;
        for face in 0..6 {
            for bj in 0..st {
                for bi in 0..st {
                    if bi != 0 && bj != 0 && bi != st - 1 && bj != st - 1 {
                        continue;
                    }
                    // Border texel centre in face coordinates, just outside [-1, 1].
                    let sc = 2.0 * (bi as f64 - 0.5) / sf - 1.0;
                    let tc = 2.0 * (bj as f64 - 0.5) / sf - 1.0;
                    let (f2, sc2, tc2) = dir_face(face_dir(face, sc, tc));
                    let to_texel = |c: f64| (((c + 1.0) * 0.5 * sf) as usize).min(s - 1);
                    let src = self.index(f2, to_texel(sc2) + 1, to_texel(tc2) + 1);
                    let dst = self.index(face, bi, bj);
                    self.texels[dst] = self.texels[src];
                }
            }
        }
    }

    /// Bilinear radiance at face coordinates `(sc, tc)` in [-1, 1] of `face`.
    #[inline]
    fn bilinear(&self, face: usize, sc: f32, tc: f32) -> Vec3 {
        let s = self.size as f32;
        // Bordered continuous coordinates: texel centres at integers 1..=size.
        let x = ((sc + 1.0) * 0.5 * s + 0.5).clamp(0.0, s + 1.0);
        let y = ((tc + 1.0) * 0.5 * s + 0.5).clamp(0.0, s + 1.0);
        let (x0, y0) = (x.floor(), y.floor());
        let (tx, ty) = (x - x0, y - y0);
        let st = self.stride();
        let i0 = (x0 as usize).min(st - 2);
        let j0 = (y0 as usize).min(st - 2);
        let base = face * st * st + j0 * st + i0;
        let t = &self.texels;
        let v = |k: usize| Vec3::from_array(t[k]);
        let top = v(base).lerp(v(base + 1), tx);
        let bottom = v(base + st).lerp(v(base + st + 1), tx);
        top.lerp(bottom, ty)
    }
}

/// Face-texel solid angles of a face of size `s` (the same on every face), row-major.
fn face_solid_angles(s: usize) -> Vec<f64> {
    let cube = CubeImage::new(CubeLayout::HorizontalStrip, s);
    (0..s * s)
        .map(|k| cube.texel_solid_angle(k % s, k / s))
        .collect()
}

/// The mip pyramid of a cube map with one-texel borders (see the module note).
#[derive(Clone, Debug)]
pub struct CubePyramid {
    levels: Vec<Level>,
}

impl CubePyramid {
    /// Builds the pyramid of six `S x S` faces (order `+X -X +Y -Y +Z -Z`, GL orientation) down
    /// to 1 x 1. `S` must be a power of two. Cost O(S^2).
    pub fn new(faces: &[Image<Rgb>; 6]) -> Result<Self, MappingError> {
        let s = faces[0].width();
        if !s.is_power_of_two() || faces.iter().any(|f| f.width() != s || f.height() != s) {
            return Err(MappingError::Parameter(format!(
                "a cube pyramid needs six square faces of one power-of-two size (face 0 is {} x {})",
                faces[0].width(),
                faces[0].height()
            )));
        }
        let mut level = Level {
            size: s,
            texels: vec![[0.0; 3]; 6 * (s + 2) * (s + 2)],
        };
        for (f, img) in faces.iter().enumerate() {
            for j in 0..s {
                for (i, p) in img.row(j).iter().enumerate() {
                    let k = level.index(f, i + 1, j + 1);
                    level.texels[k] = [p.r, p.g, p.b];
                }
            }
        }
        level.fill_borders();
        let mut levels = vec![level];
        while levels[levels.len() - 1].size > 1 {
            let child = &levels[levels.len() - 1];
            let cs = child.size;
            let omega = face_solid_angles(cs);
            let ps = cs / 2;
            let mut parent = Level {
                size: ps,
                texels: vec![[0.0; 3]; 6 * (ps + 2) * (ps + 2)],
            };
            for f in 0..6 {
                for j in 0..ps {
                    for i in 0..ps {
                        let mut sum = DVec3::ZERO;
                        let mut weight = 0.0;
                        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                            let (ci, cj) = (2 * i + di, 2 * j + dj);
                            let w = omega[cj * cs + ci];
                            let t = child.texels[child.index(f, ci + 1, cj + 1)];
                            sum += DVec3::new(t[0].into(), t[1].into(), t[2].into()) * w;
                            weight += w;
                        }
                        let mean = (sum / weight).as_vec3();
                        let k = parent.index(f, i + 1, j + 1);
                        parent.texels[k] = mean.to_array();
                    }
                }
            }
            parent.fill_borders();
            levels.push(parent);
        }
        Ok(CubePyramid { levels })
    }

    /// Face size of level 0.
    pub fn size(&self) -> usize {
        self.levels[0].size
    }

    /// Number of levels (`log2(S) + 1`).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Mean texel solid angle of level 0, `4 pi / (6 S^2)` (sr).
    pub fn texel_solid_angle(&self) -> f64 {
        let s = self.size() as f64;
        4.0 * std::f64::consts::PI / (6.0 * s * s)
    }

    /// Trilinear radiance towards a non-zero direction `d` at fractional level `lod` (clamped
    /// to the pyramid).
    #[inline]
    pub fn sample(&self, d: Vec3, lod: f32) -> Vec3 {
        let a = d.abs();
        let (face, sc, tc) = if a.x >= a.y && a.x >= a.z {
            let m = 1.0 / a.x;
            if d.x >= 0.0 {
                (0, -d.z * m, -d.y * m)
            } else {
                (1, d.z * m, -d.y * m)
            }
        } else if a.y >= a.z {
            let m = 1.0 / a.y;
            if d.y >= 0.0 {
                (2, d.x * m, d.z * m)
            } else {
                (3, d.x * m, -d.z * m)
            }
        } else {
            let m = 1.0 / a.z;
            if d.z >= 0.0 {
                (4, d.x * m, -d.y * m)
            } else {
                (5, -d.x * m, -d.y * m)
            }
        };
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let l0 = lod.floor();
        let t = lod - l0;
        let l0 = l0 as usize;
        let v0 = self.levels[l0].bilinear(face, sc, tc);
        if t == 0.0 {
            v0
        } else {
            v0.lerp(self.levels[l0 + 1].bilinear(face, sc, tc), t)
        }
    }

    /// Face size of `level` (clamped to the pyramid).
    pub fn level_size(&self, level: usize) -> usize {
        self.levels[level.min(self.levels.len() - 1)].size
    }

    /// Every texel of `level` as `(unit centre direction, exact solid angle in sr, radiance)`,
    /// faces in order, rows top to bottom.
    pub fn texels(&self, level: usize) -> Vec<(Vec3, f32, Vec3)> {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let s = l.size;
        let omega = face_solid_angles(s);
        let mut out = Vec::with_capacity(6 * s * s);
        for f in 0..6 {
            for j in 0..s {
                for i in 0..s {
                    let sc = 2.0 * (i as f64 + 0.5) / s as f64 - 1.0;
                    let tc = 2.0 * (j as f64 + 0.5) / s as f64 - 1.0;
                    let d = face_dir(f, sc, tc).normalize().as_vec3();
                    let t = l.texels[l.index(f, i + 1, j + 1)];
                    out.push((d, omega[j * s + i] as f32, Vec3::from_array(t)));
                }
            }
        }
        out
    }

    /// The faces of `level` without their borders (GL orientation), for tests and previews.
    pub fn faces(&self, level: usize) -> [Image<Rgb>; 6] {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let s = l.size;
        std::array::from_fn(|f| {
            Image::from_fn_par(s, s, |i, j| {
                let t = l.texels[l.index(f, i + 1, j + 1)];
                Rgb::new(t[0], t[1], t[2])
            })
        })
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;

    fn faces_from(f: impl Fn(DVec3) -> Rgb + Sync, s: usize) -> [Image<Rgb>; 6] {
        std::array::from_fn(|face| {
            Image::from_fn_par(s, s, |i, j| {
                let sc = 2.0 * (i as f64 + 0.5) / s as f64 - 1.0;
                let tc = 2.0 * (j as f64 + 0.5) / s as f64 - 1.0;
                f(face_dir(face, sc, tc).normalize())
            })
        })
    }

    #[test]
    fn every_level_keeps_the_power() {
        let p = CubePyramid::new(&faces_from(
            |d| {
                Rgb::new(
                    (d.x + 1.2) as f32,
                    (d.y * d.y) as f32,
                    (3.0 * d.z).exp() as f32,
                )
            },
            32,
        ))
        .unwrap();
        assert_eq!(p.level_count(), 6);
        let power = |level: usize| {
            let faces = p.faces(level);
            let s = faces[0].width();
            let omega = face_solid_angles(s);
            let mut sum = [0.0f64; 3];
            for f in &faces {
                for (k, px) in f.pixels().iter().enumerate() {
                    for c in 0..3 {
                        sum[c] += f64::from(px[c]) * omega[k];
                    }
                }
            }
            sum
        };
        let top = power(0);
        for level in 1..p.level_count() {
            let e = power(level);
            for c in 0..3 {
                // f32 texels re-rounded once per level: measured under 1e-7 relative.
                assert!(
                    (e[c] / top[c] - 1.0).abs() < 1e-6,
                    "level {level} {e:?} {top:?}"
                );
            }
        }
    }

    #[test]
    fn lookups_are_continuous_across_edges_and_exact_at_texel_centres() {
        let f = |d: DVec3| Rgb::new((2.0 * d.x + 3.0) as f32, (d.y + 2.0) as f32, 1.0);
        let p = CubePyramid::new(&faces_from(f, 16)).unwrap();
        // Texel centres return the texel.
        for (face, img) in p.faces(0).iter().enumerate() {
            for &(i, j) in &[(0, 0), (5, 9), (15, 15)] {
                let sc = 2.0 * (i as f64 + 0.5) / 16.0 - 1.0;
                let tc = 2.0 * (j as f64 + 0.5) / 16.0 - 1.0;
                let d = face_dir(face, sc, tc).as_vec3();
                let v = p.sample(d, 0.0);
                let t = img.get(i, j);
                assert!((v - Vec3::new(t.r, t.g, t.b)).abs().max_element() < 1e-5);
            }
        }
        // Just either side of every edge the look-ups agree to the field's variation over a
        // texel (the field changes by at most 2 per radian; a texel is about 0.1 rad).
        for face in 0..6 {
            for k in 0..64 {
                let t = -1.0 + (k as f64 + 0.5) / 32.0;
                for (sc, tc) in [(1.0, t), (-1.0, t), (t, 1.0), (t, -1.0)] {
                    let edge = face_dir(face, sc, tc).normalize();
                    let inward = face_dir(face, 0.0, 0.0).normalize();
                    let a = p.sample((edge + inward * 1e-4).as_vec3(), 0.0);
                    let b = p.sample((edge - inward * 1e-4).as_vec3(), 0.0);
                    assert!(
                        (a - b).abs().max_element() < 0.2,
                        "{face} {sc} {tc} {a} {b}"
                    );
                }
            }
        }
    }

    #[test]
    fn refuses_non_power_of_two_faces() {
        let faces = std::array::from_fn(|_| Image::filled(3, 3, Rgb::ZERO));
        assert!(CubePyramid::new(&faces).is_err());
    }
}
