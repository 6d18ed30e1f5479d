//! Cube maps: six square faces `+X, -X, +Y, -Y, +Z, -Z` in the OpenGL / KTX orientation, and the
//! single-image layouts that hold them.
//!
//! **Faces.** The standard GL cube-map table (OpenGL 4.6 table 8.19) applied to our world
//! direction `d = (x, y, z)`: pick the major axis `ma`, then
//!
//! ```text
//! face  sc    tc    ma         face  sc    tc    ma
//! +X    -z    -y    x          -X    +z    -y    x
//! +Y    +x    +z    y          -Y    +x    -z    y
//! +Z    +x    -y    z          -Z    -x    -y    z
//! s = (sc / |ma| + 1) / 2,  t = (tc / |ma| + 1) / 2
//! ```
//!
//! and face pixel `(i, j)` covers `s in [i, i+1) / S`, `t in [j, j+1) / S`, row 0 (t = 0) at the
//! top of the face image, as KTX, DDS and every GL tool store them. This table is left-handed
//! (RenderMan style): seen from the *inside* of the cube in our right-handed frame each face is
//! mirrored left-right (e.g. +Z, which is behind us, shows +X on its right); renderers in
//! right-handed frames (three.js, glTF viewers) flip x when they sample such files. We keep the
//! file convention unchanged so that cube maps exchanged with other tools are right.
//!
//! **Layouts** (cells of S x S pixels, `(column, row)` from the top left):
//!
//! ```text
//! horizontal cross 4x3      vertical cross 3x4        horizontal strip 6x1
//!      .  +Y  .   .              .  +Y  .              +X -X +Y -Y +Z -Z
//!                                                      (vertical strip 1x6: the same, top down)
//!     -X  +Z  +X  -Z            -X  +Z  +X
//!      .  -Y  .   .              .  -Y  .
//!                                .  -Z* .   (* rotated 180 degrees)
//! ```
//!
//! +Y at (1,0), -X (0,1), +Z (1,1), +X (2,1), -Z (3,1), -Y (1,2) in the horizontal cross; the
//! vertical cross moves -Z to (1,3), rotated by 180 degrees so that its bottom edge meets the
//! bottom edge of -Y. These are the layouts of AMD CubeMapGen and cmft, and with the GL
//! faces every shared edge of the cross is continuous: folded with the pictures facing outwards
//! the cross puts each face on its own axis of our frame (+Z towards the viewer, +X to the right,
//! +Y on top). Unused cells are black and outside the domain.
//!
//! **Solid angle.** A face texel spanning `[x0, x1] x [y0, y1]` on the plane at distance 1 (face
//! coordinates in [-1, 1]) subtends exactly `A(x1, y1) - A(x0, y1) - A(x1, y0) + A(x0, y0)` with
//! `A(x, y) = atan2(x y, sqrt(x^2 + y^2 + 1))`; the density is `dOmega = (1 + sc^2 + tc^2)^(-3/2)
//! dsc dtc`. Six faces sum to 4 pi to rounding.

use glam::DVec3;
use ibl_core::{Image, Rgb};

use crate::error::MappingError;
use crate::mapping::{CubeLayout, Mapping};
use crate::taps::{Taps, bilinear_corners};

/// File-name suffixes of the six faces, in face order `+X, -X, +Y, -Y, +Z, -Z`.
pub const CUBE_FACE_NAMES: [&str; 6] = ["px", "nx", "py", "ny", "pz", "nz"];

impl CubeLayout {
    /// The cell `(column, row)` of `face` (0..6 in the order `+X, -X, +Y, -Y, +Z, -Z`) and whether
    /// it is stored rotated by 180 degrees.
    pub fn cell(self, face: usize) -> (usize, usize, bool) {
        match self {
            CubeLayout::HorizontalCross => [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (3, 1, false),
            ][face % 6],
            CubeLayout::VerticalCross => [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (1, 3, true),
            ][face % 6],
            CubeLayout::HorizontalStrip => (face % 6, 0, false),
            CubeLayout::VerticalStrip => (0, face % 6, false),
        }
    }

    /// The face size of a `width x height` image of this layout, `None` if it does not fit.
    pub fn face_size(self, width: usize, height: usize) -> Option<usize> {
        let (cols, rows) = self.grid();
        let s = width / cols;
        (s > 0 && width == cols * s && s.checked_mul(rows) == Some(height)).then_some(s)
    }
}

/// Direction (not normalised) of face coordinates `sc, tc` in [-1, 1] on `face`.
pub(crate) fn face_dir(face: usize, sc: f64, tc: f64) -> DVec3 {
    match face {
        0 => DVec3::new(1.0, -tc, -sc),
        1 => DVec3::new(-1.0, -tc, sc),
        2 => DVec3::new(sc, 1.0, tc),
        3 => DVec3::new(sc, -1.0, -tc),
        4 => DVec3::new(sc, -tc, 1.0),
        _ => DVec3::new(-sc, -tc, -1.0),
    }
}

/// Face and face coordinates `(sc, tc)` in [-1, 1] of a non-zero direction (GL table; ties go to
/// x, then y).
pub(crate) fn dir_face(d: DVec3) -> (usize, f64, f64) {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        let m = a.x;
        if d.x >= 0.0 {
            (0, -d.z / m, -d.y / m)
        } else {
            (1, d.z / m, -d.y / m)
        }
    } else if a.y >= a.z {
        let m = a.y;
        if d.y >= 0.0 {
            (2, d.x / m, d.z / m)
        } else {
            (3, d.x / m, -d.z / m)
        }
    } else {
        let m = a.z;
        if d.z >= 0.0 {
            (4, d.x / m, -d.y / m)
        } else {
            (5, -d.x / m, -d.y / m)
        }
    }
}

/// `A(x, y)`: solid angle of the face rectangle `[0, x] x [0, y]` (signed).
fn corner_area(x: f64, y: f64) -> f64 {
    (x * y).atan2((x * x + y * y + 1.0).sqrt())
}

/// The `cells` entry of an unused cell.
const NO_FACE: u8 = u8::MAX;

/// A cube layout bound to an image of face size `size`, with its cell tables precomputed (the
/// per-sample look-ups are then a few multiplications).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct CubeImage {
    /// The layout.
    pub layout: CubeLayout,
    /// Face size S in pixels.
    pub size: usize,
    /// Grid columns and rows.
    cols: usize,
    rows: usize,
    /// Face of each cell, row-major; [`NO_FACE`] for unused cells.
    cells: [u8; 24],
    /// Whether each face's cell is stored rotated by 180 degrees.
    rotated: [bool; 6],
    /// Top-left pixel and rotation of each face's cell.
    origin: [(usize, usize); 6],
    /// `1 / size`.
    inv_size: f64,
}

impl CubeImage {
    /// The layout bound to face size `size` (at least 1).
    pub(crate) fn new(layout: CubeLayout, size: usize) -> Self {
        let (cols, rows) = layout.grid();
        let mut cells = [NO_FACE; 24];
        let mut rotated = [false; 6];
        let mut origin = [(0, 0); 6];
        for (f, o) in origin.iter_mut().enumerate() {
            let (c, r, rot) = layout.cell(f);
            cells[r * cols + c] = f as u8;
            rotated[f] = rot;
            *o = (c * size, r * size);
        }
        CubeImage {
            layout,
            size,
            cols,
            rows,
            cells,
            rotated,
            origin,
            inv_size: 1.0 / size.max(1) as f64,
        }
    }

    /// Face and rotation-corrected face-local coordinates in [0, S] of continuous image
    /// coordinates; `None` in unused cells or outside the image.
    fn locate(&self, x: f64, y: f64) -> Option<(usize, f64, f64)> {
        let s = self.size as f64;
        let inside = x >= 0.0 && y >= 0.0 && x <= self.cols as f64 * s && y <= self.rows as f64 * s;
        if !inside {
            return None;
        }
        let col = ((x * self.inv_size) as usize).min(self.cols - 1);
        let row = ((y * self.inv_size) as usize).min(self.rows - 1);
        let face = usize::from(self.cells[row * self.cols + col]);
        if face >= 6 {
            return None;
        }
        let rot = self.rotated[face];
        let (fx, fy) = (x - col as f64 * s, y - row as f64 * s);
        let (fx, fy) = if rot { (s - fx, s - fy) } else { (fx, fy) };
        Some((face, fx, fy))
    }

    /// Unit direction and solid-angle density per unit pixel area at continuous coordinates.
    pub(crate) fn dir_density(&self, x: f64, y: f64) -> Option<(DVec3, f64)> {
        let (face, fx, fy) = self.locate(x, y)?;
        let k = 2.0 * self.inv_size;
        let (sc, tc) = (k * fx - 1.0, k * fy - 1.0);
        let inv = 1.0 / (1.0 + sc * sc + tc * tc).sqrt();
        let density = k * k * inv * inv * inv;
        Some((face_dir(face, sc, tc) * inv, density))
    }

    /// Continuous image coordinates of a non-zero direction.
    pub(crate) fn pixel_of_dir(&self, d: DVec3) -> (f64, f64) {
        let (face, sc, tc) = dir_face(d);
        let s = self.size as f64;
        let (fx, fy) = ((sc + 1.0) * 0.5 * s, (tc + 1.0) * 0.5 * s);
        let ((x0, y0), rot) = (self.origin[face % 6], self.rotated[face % 6]);
        let (fx, fy) = if rot { (s - fx, s - fy) } else { (fx, fy) };
        (x0 as f64 + fx, y0 as f64 + fy)
    }

    /// Image pixel index of face texel `(i, j)` (face orientation).
    fn texel_index(&self, face: usize, i: usize, j: usize) -> usize {
        let s = self.size;
        let ((x0, y0), rot) = (self.origin[face % 6], self.rotated[face % 6]);
        let (i, j) = if rot { (s - 1 - i, s - 1 - j) } else { (i, j) };
        (y0 + j) * (self.cols * s) + x0 + i
    }

    /// Bilinear taps of a non-zero direction, clamped within its face (never reading a
    /// neighbouring cell).
    pub(crate) fn taps(&self, d: DVec3) -> Taps {
        let (face, sc, tc) = dir_face(d);
        let s = self.size as f64;
        let fx = (sc + 1.0) * 0.5 * s - 0.5;
        let fy = (tc + 1.0) * 0.5 * s - 0.5;
        let mut taps = Taps::default();
        for (i, j, w) in bilinear_corners(fx, fy, self.size, self.size) {
            taps.push(self.texel_index(face, i, j), w);
        }
        taps
    }

    /// Exact solid angle of image pixel `(i, j)` (0 in unused cells).
    pub(crate) fn texel_solid_angle(&self, i: usize, j: usize) -> f64 {
        let s = self.size;
        if self.cells[(j / s) * self.cols + i / s] == NO_FACE {
            return 0.0;
        }
        // Rotation does not change a texel's solid angle (the table is symmetric).
        let (fi, fj) = (i % s, j % s);
        let sf = s as f64;
        let x0 = 2.0 * fi as f64 / sf - 1.0;
        let x1 = 2.0 * (fi + 1) as f64 / sf - 1.0;
        let y0 = 2.0 * fj as f64 / sf - 1.0;
        let y1 = 2.0 * (fj + 1) as f64 / sf - 1.0;
        corner_area(x1, y1) - corner_area(x0, y1) - corner_area(x1, y0) + corner_area(x0, y0)
    }
}

/// Splits a single-image cube map into its six faces, in the order `+X, -X, +Y, -Y, +Z, -Z`
/// (names [`CUBE_FACE_NAMES`]), each `S x S` in the GL orientation (the vertical cross' -Z is
/// rotated back). Cost O(S^2).
pub fn split_cube_faces(
    image: &Image<Rgb>,
    layout: CubeLayout,
) -> Result<[Image<Rgb>; 6], MappingError> {
    let (w, h) = (image.width(), image.height());
    let size = layout
        .face_size(w, h)
        .ok_or_else(|| shape_error(layout, w, h))?;
    let cube = CubeImage::new(layout, size);
    let pixels = image.pixels();
    let face = |f: usize| {
        let data = (0..size * size)
            .map(|k| pixels[cube.texel_index(f, k % size, k / size)])
            .collect();
        Image::from_vec(size, size, data).map_err(|e| MappingError::Parameter(e.to_string()))
    };
    Ok([face(0)?, face(1)?, face(2)?, face(3)?, face(4)?, face(5)?])
}

/// Joins six `S x S` faces (order `+X, -X, +Y, -Y, +Z, -Z`, GL orientation) into one image of
/// `layout`; unused cells are black. Errors if the faces are empty, not square or differ in size.
/// Cost O(S^2).
pub fn join_cube_faces(
    faces: &[Image<Rgb>; 6],
    layout: CubeLayout,
) -> Result<Image<Rgb>, MappingError> {
    let size = faces[0].width();
    for (f, img) in faces.iter().enumerate() {
        if size == 0 || img.width() != size || img.height() != size {
            return Err(MappingError::Parameter(format!(
                "cube face {} is {} x {}: faces must be equal non-empty squares ({size} x {size})",
                CUBE_FACE_NAMES[f],
                img.width(),
                img.height()
            )));
        }
    }
    let (cols, rows) = layout.grid();
    let (w, h) = match (cols.checked_mul(size), rows.checked_mul(size)) {
        (Some(w), Some(h)) if w.checked_mul(h).is_some() => (w, h),
        _ => {
            return Err(MappingError::Parameter(format!(
                "cube face size {size} is too large"
            )));
        }
    };
    let cube = CubeImage::new(layout, size);
    let mut data = vec![Rgb::ZERO; w * h];
    for (f, img) in faces.iter().enumerate() {
        for (k, &c) in img.pixels().iter().enumerate() {
            data[cube.texel_index(f, k % size, k / size)] = c;
        }
    }
    Image::from_vec(w, h, data).map_err(|e| MappingError::Parameter(e.to_string()))
}

/// The shape error of a cube layout.
pub(crate) fn shape_error(layout: CubeLayout, width: usize, height: usize) -> MappingError {
    let (cols, rows) = layout.grid();
    MappingError::Shape {
        mapping: Mapping::Cube(layout).name(),
        width,
        height,
        reason: format!("needs {cols} x {rows} square faces: width {cols}s and height {rows}s"),
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;

    #[test]
    fn face_table_inverts() {
        for face in 0..6 {
            for &(sc, tc) in &[(0.0, 0.0), (0.5, -0.25), (-0.9, 0.9)] {
                let d = face_dir(face, sc, tc);
                let (f2, s2, t2) = dir_face(d);
                assert_eq!(f2, face);
                assert!((s2 - sc).abs() < 1e-12 && (t2 - tc).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn split_and_join_round_trip() {
        for layout in CubeLayout::ALL {
            let (cols, rows) = layout.grid();
            let (w, h) = (cols * 3, rows * 3);
            let img = Image::from_fn_par(w, h, |x, y| Rgb::new(x as f32, y as f32, 0.0));
            let faces = split_cube_faces(&img, layout).unwrap();
            let back = join_cube_faces(&faces, layout).unwrap();
            let cube = CubeImage::new(layout, 3);
            for y in 0..h {
                for x in 0..w {
                    let used = cube.locate(x as f64 + 0.5, y as f64 + 0.5).is_some();
                    let expect = if used { *img.get(x, y) } else { Rgb::ZERO };
                    assert_eq!(*back.get(x, y), expect, "{layout:?} {x} {y}");
                }
            }
        }
        let bad = Image::filled(5, 3, Rgb::ZERO);
        assert!(split_cube_faces(&bad, CubeLayout::HorizontalCross).is_err());
    }
}
