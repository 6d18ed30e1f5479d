//! Irradiance volumes (Greger, Shirley, Hubbard & Greenberg 1998, "The irradiance volume"): a
//! regular grid of key points in the scene, each holding the irradiance a surface there would
//! receive as SH L2 RGB coefficients (9 per channel, CONVENTIONS section 6, world frame), looked
//! up between points by trilinear interpolation.
//!
//! Jensen, Andersen & Madsen 2006 (section 3.3) refresh such a volume every frame from the
//! relit environment map; Grosch 2005 keeps two layers per key point, all light and the light of
//! the "unimportant" patches, so a volume holds one or two [`VolumeLayer`]s.
//!
//! **Key points.** [`KeyPointVolume`] is generic over what a key point holds (any
//! [`KeyPointIrradiance`]: a linear, normal-dependent irradiance that can be weighted and summed);
//! [`IrradianceVolume`] is the L2 volume both pipelines use, and other representations (the
//! room's ambient cube, `ibl-room`) share the grid, the validity and the interpolation.
//!
//! **Grid**: key point `(ix, iy, iz)` sits at `origin + (ix, iy, iz) * spacing` (metres, world
//! frame), index `ix + nx (iy + ny iz)`. A point can be **invalid** (inside a wall, below the
//! ground): it is never interpolated from.
//!
//! **Interpolation with leak control.** For a position `p` the cell's eight corners get the
//! trilinear weights `prod (f or 1 - f)` (positions outside the grid clamp to its faces). With
//! [`LeakControl::ValidOnly`] invalid corners get weight 0; with [`LeakControl::Facing`] each
//! corner's weight is also multiplied by `max(0.05, (1 + n . u) / 2)^2`, `u` the unit vector from
//! `p` to the corner and `n` the surface normal, so key points behind the surface (often on the
//! far side of a thin wall, where the light is different) count little (the "backface" weight
//! of Majercik et al. 2019, DDGI). [`KeyPointVolume::sample_visible`] also gives weight 0 to
//! every corner a caller's visibility test rejects (a wall or a box face between the position and
//! the key point, which only the caller's geometry can tell). The weights are renormalised; if
//! all vanish the look-up fails. Cost O(1) per look-up (eight corners, 27 coefficients each for
//! L2), plus the caller's visibility tests.

use ibl_core::glam::{DVec3, Vec3};

use crate::ShError;
use crate::basis::eval_basis;
use crate::coefficients::IrradianceSh;

/// The key-point grid, metres, world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeGrid {
    /// Position of key point `(0, 0, 0)`.
    pub origin: DVec3,
    /// Distance between neighbouring key points along x, y, z (each > 0).
    pub spacing: DVec3,
    /// Key points along x, y, z (each >= 1).
    pub counts: [usize; 3],
}

/// Most key points a volume may hold (2^24).
pub const MAX_KEY_POINTS: usize = 1 << 24;

impl VolumeGrid {
    /// A grid; an error for a non-finite origin, a spacing that is not positive and finite, a
    /// zero count or more than [`MAX_KEY_POINTS`] points.
    pub fn new(origin: DVec3, spacing: DVec3, counts: [usize; 3]) -> Result<VolumeGrid, ShError> {
        if !origin.is_finite() || !spacing.is_finite() || spacing.min_element() <= 0.0 {
            return Err(ShError::Parameter(format!(
                "volume grid: origin {origin} must be finite and spacing {spacing} positive"
            )));
        }
        let total = counts
            .iter()
            .try_fold(1usize, |a, &c| a.checked_mul(c))
            .unwrap_or(usize::MAX);
        if counts.contains(&0) || total > MAX_KEY_POINTS {
            return Err(ShError::Parameter(format!(
                "volume grid: {counts:?} key points (each count at least 1, at most {MAX_KEY_POINTS} in all)"
            )));
        }
        Ok(VolumeGrid {
            origin,
            spacing,
            counts,
        })
    }

    /// The grid from `min` to `max` (inclusive corners) with at most `spacing` between points.
    pub fn covering(min: DVec3, max: DVec3, spacing: f64) -> Result<VolumeGrid, ShError> {
        if spacing.is_nan()
            || spacing <= 0.0
            || !min.is_finite()
            || !max.is_finite()
            || max.cmplt(min).any()
        {
            return Err(ShError::Parameter(format!(
                "volume grid: box {min} to {max} with spacing {spacing}"
            )));
        }
        let extent = max - min;
        let counts = [extent.x, extent.y, extent.z]
            .map(|e| ((e / spacing).ceil() as usize).saturating_add(1).max(1));
        let step = |e: f64, n: usize| if n > 1 { e / (n - 1) as f64 } else { spacing };
        let spacing = DVec3::new(
            step(extent.x, counts[0]),
            step(extent.y, counts[1]),
            step(extent.z, counts[2]),
        );
        VolumeGrid::new(min, spacing, counts)
    }

    /// Number of key points.
    pub fn len(&self) -> usize {
        self.counts[0] * self.counts[1] * self.counts[2]
    }

    /// Whether the grid is empty (never, for a grid made by [`Self::new`]).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Index of key point `(ix, iy, iz)`.
    pub fn index(&self, ix: usize, iy: usize, iz: usize) -> usize {
        ix + self.counts[0] * (iy + self.counts[1] * iz)
    }

    /// `(ix, iy, iz)` of an index.
    pub fn coordinates(&self, index: usize) -> [usize; 3] {
        let [nx, ny, _] = self.counts;
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    /// World position of key point `index`.
    pub fn position(&self, index: usize) -> DVec3 {
        let [x, y, z] = self.coordinates(index);
        self.origin + DVec3::new(x as f64, y as f64, z as f64) * self.spacing
    }
}

/// Irradiance of one key point: 3 bands of SH, RGB, `coefficients[sh_index(l, m)]`; irradiance
/// on a surface of unit normal `n` is `sum_k coefficients[k] Y_k(n)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct IrradianceL2 {
    /// Coefficients per channel.
    pub coefficients: [[f32; 3]; 9],
}

impl IrradianceL2 {
    /// All zero.
    pub const ZERO: IrradianceL2 = IrradianceL2 {
        coefficients: [[0.0; 3]; 9],
    };

    /// The first 3 bands of an irradiance expansion (missing bands are zero).
    pub fn from_sh(sh: &IrradianceSh) -> IrradianceL2 {
        let mut out = IrradianceL2::ZERO;
        for (o, c) in out.coefficients.iter_mut().zip(sh.coefficients()) {
            *o = c.map(|v| v as f32);
        }
        out
    }

    /// The irradiance on a surface with unit normal `n`, per channel (not clamped).
    pub fn irradiance(&self, n: Vec3) -> [f32; 3] {
        let mut y = [0.0f64; 9];
        eval_basis(n.as_dvec3(), 3, &mut y);
        let mut out = [0.0f32; 3];
        for (k, c) in self.coefficients.iter().enumerate() {
            for ch in 0..3 {
                out[ch] += y[k] as f32 * c[ch];
            }
        }
        out
    }

    /// `self += weight * other`.
    pub fn add_scaled(&mut self, other: &IrradianceL2, weight: f32) {
        for (a, b) in self.coefficients.iter_mut().zip(&other.coefficients) {
            for ch in 0..3 {
                a[ch] += weight * b[ch];
            }
        }
    }
}

/// What a key point of a [`KeyPointVolume`] holds: an irradiance that depends on the surface
/// normal and is linear in the light, so interpolation is a weighted sum of key points.
pub trait KeyPointIrradiance: Copy + std::fmt::Debug + PartialEq + Send + Sync {
    /// No light.
    const ZERO: Self;
    /// `self += weight * other`.
    fn add_scaled(&mut self, other: &Self, weight: f32);
    /// The irradiance on a surface with unit normal `n` (world frame), per channel.
    fn irradiance(&self, n: Vec3) -> [f32; 3];
}

impl KeyPointIrradiance for IrradianceL2 {
    const ZERO: IrradianceL2 = IrradianceL2::ZERO;

    fn add_scaled(&mut self, other: &IrradianceL2, weight: f32) {
        IrradianceL2::add_scaled(self, other, weight);
    }

    fn irradiance(&self, n: Vec3) -> [f32; 3] {
        IrradianceL2::irradiance(self, n)
    }
}

/// Which light a layer holds (Grosch 2005 keeps both per key point).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeLayer {
    /// All the light arriving at the key point (the outdoor case: all secondary light).
    AllLight,
    /// Only the light of the unimportant sources (Grosch's second layer).
    UnimportantLight,
}

/// Which layers a volume holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeLayers {
    /// [`VolumeLayer::AllLight`] only.
    AllLight,
    /// [`VolumeLayer::AllLight`] and [`VolumeLayer::UnimportantLight`].
    AllAndUnimportant,
}

impl VolumeLayers {
    fn count(self) -> usize {
        match self {
            VolumeLayers::AllLight => 1,
            VolumeLayers::AllAndUnimportant => 2,
        }
    }
}

/// How interpolation keeps light from leaking through walls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LeakControl {
    /// Plain trilinear weights (invalid points included as they are: zero).
    None,
    /// Invalid key points get weight 0.
    ValidOnly,
    /// Invalid points get weight 0 and points behind the surface of this unit normal count little.
    Facing(Vec3),
}

/// A grid of key points with validity and one or two layers of irradiance `P` per point.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyPointVolume<P> {
    grid: VolumeGrid,
    layers: VolumeLayers,
    valid: Vec<bool>,
    /// `layer * len + index`.
    data: Vec<P>,
}

/// The volume of L2 irradiance key points (both pipelines' volume).
pub type IrradianceVolume = KeyPointVolume<IrradianceL2>;

impl<P: KeyPointIrradiance> KeyPointVolume<P> {
    /// A volume of zero irradiance, every point valid.
    pub fn new(grid: VolumeGrid, layers: VolumeLayers) -> KeyPointVolume<P> {
        let n = grid.len();
        KeyPointVolume {
            grid,
            layers,
            valid: vec![true; n],
            data: vec![P::ZERO; n * layers.count()],
        }
    }

    /// The grid.
    pub fn grid(&self) -> &VolumeGrid {
        &self.grid
    }

    /// The layers held.
    pub fn layers(&self) -> VolumeLayers {
        self.layers
    }

    /// Whether key point `index` may be interpolated from.
    pub fn is_valid(&self, index: usize) -> bool {
        self.valid[index]
    }

    /// Marks key point `index` valid or not.
    pub fn set_valid(&mut self, index: usize, valid: bool) {
        self.valid[index] = valid;
    }

    fn offset(&self, layer: VolumeLayer) -> Result<usize, ShError> {
        match (layer, self.layers) {
            (VolumeLayer::AllLight, _) => Ok(0),
            (VolumeLayer::UnimportantLight, VolumeLayers::AllAndUnimportant) => Ok(self.grid.len()),
            (VolumeLayer::UnimportantLight, VolumeLayers::AllLight) => Err(ShError::Parameter(
                "this volume holds no unimportant-light layer".into(),
            )),
        }
    }

    /// One layer's key points, in index order.
    pub fn layer(&self, layer: VolumeLayer) -> Result<&[P], ShError> {
        let start = self.offset(layer)?;
        Ok(&self.data[start..start + self.grid.len()])
    }

    /// One layer's key points, to write.
    pub fn layer_mut(&mut self, layer: VolumeLayer) -> Result<&mut [P], ShError> {
        let start = self.offset(layer)?;
        let n = self.grid.len();
        Ok(&mut self.data[start..start + n])
    }

    /// The interpolated irradiance at `position` (see the module doc); `None` when every
    /// corner has weight 0.
    pub fn sample(
        &self,
        position: Vec3,
        layer: VolumeLayer,
        leak: LeakControl,
    ) -> Result<Option<P>, ShError> {
        self.sample_visible(position, layer, leak, |_| true)
    }

    /// [`Self::sample`] where a corner key point also gets weight 0 when `visible(key_point)`
    /// (its world position, metres) is false: a wall between `position` and the key point.
    /// `visible` is asked only about corners that still have weight after `leak`, at most eight.
    pub fn sample_visible(
        &self,
        position: Vec3,
        layer: VolumeLayer,
        leak: LeakControl,
        visible: impl Fn(Vec3) -> bool,
    ) -> Result<Option<P>, ShError> {
        let data = self.layer(layer)?;
        let g = &self.grid;
        let t = (position.as_dvec3() - g.origin) / g.spacing;
        let mut base = [0usize; 3];
        let mut frac = [0f64; 3];
        for a in 0..3 {
            let n = g.counts[a];
            let ta = t[a].clamp(0.0, (n - 1) as f64);
            let i0 = (ta.floor() as usize).min(n.saturating_sub(2));
            base[a] = i0;
            frac[a] = if n > 1 { ta - i0 as f64 } else { 0.0 };
        }
        let mut corners = [(0usize, 0.0f64); 8];
        let mut used = 0;
        let mut total = 0.0f64;
        for corner in 0..8 {
            let mut idx = [0usize; 3];
            let mut w = 1.0f64;
            for a in 0..3 {
                let up = (corner >> a) & 1 == 1;
                idx[a] = (base[a] + usize::from(up)).min(g.counts[a] - 1);
                w *= if up { frac[a] } else { 1.0 - frac[a] };
            }
            if w == 0.0 {
                continue;
            }
            let index = g.index(idx[0], idx[1], idx[2]);
            match leak {
                LeakControl::None => {}
                LeakControl::ValidOnly | LeakControl::Facing(_) if !self.valid[index] => continue,
                LeakControl::ValidOnly => {}
                LeakControl::Facing(n) => {
                    let u = (g.position(index) - position.as_dvec3()).normalize_or_zero();
                    if u != DVec3::ZERO {
                        let f = (0.5 * (1.0 + n.as_dvec3().dot(u))).max(0.05);
                        w *= f * f;
                    }
                }
            }
            if !visible(g.position(index).as_vec3()) {
                continue;
            }
            corners[used] = (index, w);
            used += 1;
            total += w;
        }
        if total.is_nan() || total <= 0.0 {
            return Ok(None);
        }
        let mut out = P::ZERO;
        for &(index, w) in &corners[..used] {
            out.add_scaled(&data[index], (w / total) as f32);
        }
        Ok(Some(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(e: f32) -> IrradianceL2 {
        // A constant irradiance e: c_00 = e / Y_00 = 2 sqrt(pi) e.
        let mut s = IrradianceL2::ZERO;
        s.coefficients[0] = [e * 2.0 * std::f32::consts::PI.sqrt(); 3];
        s
    }

    fn volume() -> IrradianceVolume {
        let grid =
            VolumeGrid::new(DVec3::new(-1.0, 0.0, -1.0), DVec3::splat(1.0), [3, 2, 3]).unwrap();
        let mut v = IrradianceVolume::new(grid, VolumeLayers::AllAndUnimportant);
        for i in 0..grid.len() {
            let p = grid.position(i);
            // A linear field 1 + x + 2y + 3z (trilinear interpolation reproduces it exactly).
            v.layer_mut(VolumeLayer::AllLight).unwrap()[i] =
                constant((1.0 + p.x + 2.0 * p.y + 3.0 * p.z + 10.0) as f32);
            v.layer_mut(VolumeLayer::UnimportantLight).unwrap()[i] = constant(1.0);
        }
        v
    }

    #[test]
    fn grid_geometry_round_trips() {
        let g = VolumeGrid::covering(DVec3::ZERO, DVec3::new(10.0, 3.0, 4.5), 1.5).unwrap();
        assert_eq!(g.counts, [8, 3, 4]);
        for i in 0..g.len() {
            let [x, y, z] = g.coordinates(i);
            assert_eq!(g.index(x, y, z), i);
        }
        assert!((g.position(g.len() - 1) - DVec3::new(10.0, 3.0, 4.5)).length() < 1e-12);
        assert!(VolumeGrid::new(DVec3::ZERO, DVec3::ONE, [0, 1, 1]).is_err());
        assert!(VolumeGrid::new(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0), [1, 1, 1]).is_err());
        assert!(VolumeGrid::new(DVec3::ZERO, DVec3::ONE, [1 << 12, 1 << 12, 2]).is_err());
    }

    #[test]
    fn trilinear_reproduces_a_linear_field_and_clamps_outside() {
        let v = volume();
        for p in [
            Vec3::new(0.3, 0.7, -0.2),
            Vec3::new(-1.0, 0.0, -1.0),
            Vec3::new(0.99, 0.5, 0.5),
        ] {
            let s = v
                .sample(p, VolumeLayer::AllLight, LeakControl::None)
                .unwrap()
                .unwrap();
            let e = s.irradiance(Vec3::Y)[0];
            let want = 1.0 + p.x + 2.0 * p.y + 3.0 * p.z + 10.0;
            // f32 sums of eight terms: 1e-5 relative.
            assert!((e - want).abs() < 1e-5 * want, "{p}: {e} vs {want}");
        }
        // Beyond the last point the face value holds: y = 5 reads y = 1.
        let s = v
            .sample(
                Vec3::new(0.0, 5.0, 0.0),
                VolumeLayer::AllLight,
                LeakControl::None,
            )
            .unwrap()
            .unwrap();
        assert!((s.irradiance(Vec3::Y)[0] - 13.0).abs() < 1e-4);
        let u = v
            .sample(Vec3::ZERO, VolumeLayer::UnimportantLight, LeakControl::None)
            .unwrap()
            .unwrap();
        assert!((u.irradiance(Vec3::X)[1] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn invalid_and_hidden_points_do_not_leak() {
        let mut v = volume();
        let g = *v.grid();
        // Invalidate the x = 1 plane: a point at x = 0.5 then reads only the x = 0 points.
        for i in 0..g.len() {
            if g.coordinates(i)[0] == 2 {
                v.set_valid(i, false);
            }
        }
        let p = Vec3::new(0.5, 0.0, 0.0);
        let s = v
            .sample(p, VolumeLayer::AllLight, LeakControl::ValidOnly)
            .unwrap()
            .unwrap();
        assert!((s.irradiance(Vec3::Y)[0] - 11.0).abs() < 1e-5);
        // Facing: a surface at x = 0.5 facing -x weights the x = 0 corners (in front) far more
        // than the x = 1 corners (behind) once they are valid again.
        for i in 0..g.len() {
            v.set_valid(i, true);
        }
        let facing = v
            .sample(p, VolumeLayer::AllLight, LeakControl::Facing(Vec3::NEG_X))
            .unwrap()
            .unwrap()
            .irradiance(Vec3::Y)[0];
        let plain = v
            .sample(p, VolumeLayer::AllLight, LeakControl::None)
            .unwrap()
            .unwrap()
            .irradiance(Vec3::Y)[0];
        assert!(
            (plain - 11.5).abs() < 1e-5 && facing < 11.1,
            "{facing} {plain}"
        );
        // All corners invalid: no answer.
        for i in 0..g.len() {
            v.set_valid(i, false);
        }
        assert!(
            v.sample(p, VolumeLayer::AllLight, LeakControl::ValidOnly)
                .unwrap()
                .is_none()
        );
        let single = IrradianceVolume::new(g, VolumeLayers::AllLight);
        assert!(single.layer(VolumeLayer::UnimportantLight).is_err());
    }

    #[test]
    fn corners_behind_a_wall_do_not_leak() {
        let v = volume();
        // A wall at x = 0.25 seen from x = 0.5: the x = 0 corners are hidden, so the look-up
        // reads the x = 1 plane only (the linear field at x = 1, y = 0, z = 0: 12).
        let p = Vec3::new(0.5, 0.0, 0.0);
        let s = v
            .sample_visible(p, VolumeLayer::AllLight, LeakControl::ValidOnly, |k| {
                k.x > 0.25
            })
            .unwrap()
            .unwrap();
        assert!((s.irradiance(Vec3::Y)[0] - 12.0).abs() < 1e-5);
        // Everything hidden: no answer; nothing hidden: the plain look-up.
        assert!(
            v.sample_visible(p, VolumeLayer::AllLight, LeakControl::ValidOnly, |_| false)
                .unwrap()
                .is_none()
        );
        assert_eq!(
            v.sample_visible(p, VolumeLayer::AllLight, LeakControl::None, |_| true),
            v.sample(p, VolumeLayer::AllLight, LeakControl::None)
        );
    }
}
