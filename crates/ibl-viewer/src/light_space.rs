//! Orthographic shadow projections for directional lights, and the atlas that packs one shadow
//! map per light into a single depth texture.
//!
//! A directional light arriving from unit direction `w` (towards the light, world frame) sees the
//! scene along `-w`. Its light frame has axes `u`, `v` (perpendicular to `w`) and `w`. A
//! projection covers a disc of world radius `half_extent` about a centre `c` across the light and
//! a slab of depths along it: for a world point `P`,
//!
//! ```text
//! x = (P - c) . u / half_extent,   y = (P - c) . v / half_extent         (in [-1, 1] on the map)
//! depth = ((c - P) . w + toward_light) / (toward_light + away_from_light) (0 nearest the light)
//! ```
//!
//! so depth grows with distance from the light and is linear in world units (an orthographic
//! projection: no perspective, one texel is `2 half_extent / tile` world units everywhere).
//! `toward_light` and `away_from_light` bound the casters along `w` (distances from `c`).
//! Receivers beyond the slab are clamped to depth 1 when they are looked up, so everything behind
//! the casters is compared against them and a texel no caster covered (cleared to 1) reads as
//! lit.
//!
//! The atlas is a grid of square tiles, one per light, in a texture at most the device's largest
//! 2-D side and at most [`MAX_ATLAS_TEXELS`] texels: when N lights do not fit at the requested
//! tile size the tiles shrink (every light keeps a shadow). Tile `i` is at column `i % columns`,
//! row `i / columns`.

use glam::{Mat4, Vec3, Vec4};

/// Largest atlas, texels (a 4096 x 4096 depth texture: 64 MiB of f32).
pub const MAX_ATLAS_TEXELS: u64 = 4096 * 4096;

/// Smallest tile, texels.
pub const MIN_TILE: u32 = 64;

/// An orthonormal frame `(u, v, w)` about a light direction `w`.
pub fn light_frame(w: Vec3) -> (Vec3, Vec3, Vec3) {
    let w = w.normalize();
    // The helper axis least aligned with w, so the cross product is well conditioned.
    let helper = if w.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let u = helper.cross(w).normalize();
    let v = w.cross(u);
    (u, v, w)
}

/// One light's orthographic shadow projection (see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowProjection {
    /// World point to `(x, y, depth, 1)`.
    pub map_from_world: Mat4,
    /// World radius covered across the light.
    pub half_extent: f32,
    /// World length of the depth slab (`toward_light + away_from_light`).
    pub depth_range: f32,
}

impl ShadowProjection {
    /// The projection for light direction `w` covering `half_extent` about `centre` across the
    /// light and casters from `toward_light` in front of `centre` to `away_from_light` behind it.
    /// Extents are kept positive (at least 1e-6 world units).
    pub fn new(
        w: Vec3,
        centre: Vec3,
        half_extent: f32,
        toward_light: f32,
        away_from_light: f32,
    ) -> ShadowProjection {
        let (u, v, w) = light_frame(w);
        let half_extent = half_extent.max(1e-6);
        let depth_range = (toward_light + away_from_light).max(1e-6);
        let sx = 1.0 / half_extent;
        let sz = -1.0 / depth_range;
        // Rows of the affine map; glam matrices are column-major, so build the transpose.
        let row_x = Vec4::new(u.x * sx, u.y * sx, u.z * sx, -centre.dot(u) * sx);
        let row_y = Vec4::new(v.x * sx, v.y * sx, v.z * sx, -centre.dot(v) * sx);
        let row_z = Vec4::new(
            w.x * sz,
            w.y * sz,
            w.z * sz,
            (toward_light + centre.dot(w)) / depth_range,
        );
        let map_from_world = Mat4::from_cols(row_x, row_y, row_z, Vec4::W).transpose();
        ShadowProjection {
            map_from_world,
            half_extent,
            depth_range,
        }
    }

    /// The projection covering a sphere (`centre`, `radius`) across and along the light, with
    /// `across` times the radius across it (1 for hard shadows; more leaves room for penumbrae).
    pub fn around_sphere(w: Vec3, centre: Vec3, radius: f32, across: f32) -> ShadowProjection {
        ShadowProjection::new(w, centre, radius * across.max(1.0), radius, radius)
    }

    /// `(x, y, depth)` of a world point.
    pub fn project(&self, p: Vec3) -> Vec3 {
        self.map_from_world.transform_point3(p)
    }
}

/// The sphere `(centre, radius)` enclosing a box.
pub fn bounding_sphere(lo: Vec3, hi: Vec3) -> (Vec3, f32) {
    ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-4))
}

/// The eight corners of the box `(lo, hi)`.
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Extents along `w` of the box `(lo, hi)` about `centre`: `(toward_light, away_from_light)`, the
/// largest distances of its corners in front of and behind `centre` along `w` (at least 0).
pub fn box_depths(w: Vec3, centre: Vec3, lo: Vec3, hi: Vec3) -> (f32, f32) {
    let w = w.normalize();
    let mut toward = 0.0f32;
    let mut away = 0.0f32;
    for corner in box_corners(lo, hi) {
        let d = (corner - centre).dot(w);
        toward = toward.max(d);
        away = away.max(-d);
    }
    (toward, away)
}

/// The tiles of a shadow atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasLayout {
    /// Number of tiles (lights).
    pub tiles: u32,
    /// Side of one tile, texels.
    pub tile: u32,
    /// Tiles per row.
    pub columns: u32,
    /// Rows of tiles.
    pub rows: u32,
}

impl AtlasLayout {
    /// A layout for `lights` tiles of `requested_tile` texels, shrunk (halving) until the atlas
    /// fits `max_side` and [`MAX_ATLAS_TEXELS`]; at least one tile of [`MIN_TILE`].
    pub fn new(lights: u32, requested_tile: u32, max_side: u32) -> AtlasLayout {
        let tiles = lights.max(1);
        let columns = (tiles as f64).sqrt().ceil() as u32;
        let rows = tiles.div_ceil(columns);
        let mut tile = requested_tile.clamp(MIN_TILE, max_side.max(MIN_TILE));
        while tile > MIN_TILE
            && (columns.max(rows) * tile > max_side
                || u64::from(columns * tile) * u64::from(rows * tile) > MAX_ATLAS_TEXELS)
        {
            tile /= 2;
        }
        AtlasLayout {
            tiles,
            tile,
            columns,
            rows,
        }
    }

    /// Width and height of the atlas, texels.
    pub fn size(&self) -> (u32, u32) {
        (self.columns * self.tile, self.rows * self.tile)
    }

    /// Top-left texel of tile `i`.
    pub fn origin(&self, i: u32) -> (u32, u32) {
        (
            (i % self.columns) * self.tile,
            (i / self.columns) * self.tile,
        )
    }

    /// Tile `i` in atlas texture coordinates: `(u0, v0, du, dv)` (top left and size).
    pub fn uv_rect(&self, i: u32) -> Vec4 {
        let (w, h) = self.size();
        let (x, y) = self.origin(i);
        Vec4::new(
            x as f32 / w as f32,
            y as f32 / h as f32,
            self.tile as f32 / w as f32,
            self.tile as f32 / h as f32,
        )
    }

    /// Tile `i` in the atlas's normalised device coordinates: `(centre x, centre y, half width,
    /// half height)`, +y up (a point at tile coordinates `(x, y)` in `[-1, 1]` lands at
    /// `centre + half * (x, y)`).
    pub fn ndc_rect(&self, i: u32) -> Vec4 {
        let r = self.uv_rect(i);
        let cx = (r.x + 0.5 * r.z) * 2.0 - 1.0;
        let cy = 1.0 - (r.y + 0.5 * r.w) * 2.0;
        Vec4::new(cx, cy, r.z, r.w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frame_is_orthonormal_and_right_handed() {
        for w in [Vec3::Y, Vec3::NEG_Y, Vec3::new(0.3, 0.5, -0.8), Vec3::X] {
            let (u, v, w) = light_frame(w);
            // f32 rounding of a normalised cross product: a few ulps.
            assert!((u.length() - 1.0).abs() < 1e-6 && (v.length() - 1.0).abs() < 1e-6);
            assert!(u.dot(v).abs() < 1e-6 && u.dot(w).abs() < 1e-6 && v.dot(w).abs() < 1e-6);
            assert!((u.cross(v) - w).length() < 1e-5);
        }
    }

    #[test]
    fn depth_grows_away_from_the_light() {
        let w = Vec3::new(0.2, 0.9, 0.1).normalize();
        let c = Vec3::new(1.0, -0.5, 2.0);
        let p = ShadowProjection::new(w, c, 2.0, 3.0, 5.0);
        // Exact in real arithmetic; f32 matrix products: 1e-6 relative, margin 10x.
        let tol = 1e-5;
        assert!((p.project(c + w * 3.0).z - 0.0).abs() < tol);
        assert!((p.project(c - w * 5.0).z - 1.0).abs() < tol);
        assert!((p.project(c).z - 3.0 / 8.0).abs() < tol);
        let (u, v, _) = light_frame(w);
        let q = p.project(c + u * 2.0 - v * 1.0);
        assert!((q.x - 1.0).abs() < tol && (q.y + 0.5).abs() < tol);
    }

    #[test]
    fn box_depths_bound_every_corner() {
        let (t, a) = box_depths(
            Vec3::Y,
            Vec3::ZERO,
            Vec3::splat(-1.0),
            Vec3::new(1.0, 2.0, 1.0),
        );
        assert_eq!((t, a), (2.0, 1.0));
    }

    #[test]
    fn atlas_tiles_shrink_to_fit() {
        let a = AtlasLayout::new(16, 1024, 16384);
        assert_eq!((a.columns, a.rows, a.tile), (4, 4, 1024));
        assert_eq!(a.size(), (4096, 4096));
        let b = AtlasLayout::new(64, 1024, 16384);
        assert_eq!((b.columns, b.rows), (8, 8));
        assert_eq!(
            b.tile, 512,
            "64 tiles of 1024 exceed the 4096^2 texel budget"
        );
        let c = AtlasLayout::new(3, 2048, 2048);
        assert_eq!((c.columns, c.rows, c.tile), (2, 2, 1024));
        assert_eq!(c.origin(3), (1024, 1024));
        let r = c.ndc_rect(0);
        assert_eq!(r, Vec4::new(-0.5, 0.5, 0.5, 0.5));
    }
}
