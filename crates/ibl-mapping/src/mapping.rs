//! The [`Mapping`] enum: which parameterisation of the sphere an image uses, its names on the
//! command line, the image shapes it accepts and sensible output sizes, plus the public per-pixel
//! geometry (`pixel_dir`, `dir_to_pixel`, `texel_solid_angles`).
//!
//! Every mapping is a function from continuous image coordinates `(x, y)` (pixel (i, j) covers
//! `[i, i+1) x [j, j+1)`, its centre is `(i + 0.5, j + 0.5)`, row 0 at the top) to a unit direction
//! in the world frame (+Y up, -Z forward, +X right; CONVENTIONS sections 1-3). The formulas live in
//! the noun modules ([`crate::cube`], [`crate::disc`], [`crate::fisheye`], `ibl_core::LatLong`);
//! this module only names them, validates shapes and parameters, and dispatches through the
//! internal `Projection` (a mapping bound to an image size, built once and checked once so that
//! per-sample code never re-validates).
//!
//! Shapes: lat-long accepts any non-zero size (normally 2:1); angular, mirror ball and fisheye
//! need a square; cube layouts need exact multiples of a square face; dual fisheye needs 2:1 (two
//! square halves).

use std::fmt;

pub use crate::error::MappingError;

/// How the cells of a single-image cube map are arranged (see [`crate::cube`] for the exact cells
/// and orientations). Six separate face files are handled with [`crate::split_cube_faces`] and
/// [`crate::join_cube_faces`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CubeLayout {
    /// 4 x 3 cells: `+Y` above `+Z`; middle row `-X +Z +X -Z`; `-Y` below `+Z`.
    HorizontalCross,
    /// 3 x 4 cells: `+Y`; `-X +Z +X`; `-Y`; `-Z` (rotated 180 degrees) at the bottom.
    VerticalCross,
    /// 6 x 1 cells in the order `+X -X +Y -Y +Z -Z`.
    HorizontalStrip,
    /// 1 x 6 cells, top to bottom in the order `+X -X +Y -Y +Z -Z` (cmft's `vstrip`, the "1x6"
    /// strips of Unity and Marmoset).
    VerticalStrip,
}

/// A parameterisation of the sphere of directions by an image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mapping {
    /// Equirectangular (CONVENTIONS section 2), normally 2:1.
    LatLong,
    /// Debevec angular map ("light probe"): square, centre forward (-Z), rim behind (+Z).
    Angular,
    /// Orthographic photo of a mirror ball seen from +Z: square, centre +Z, rim -Z (a single
    /// direction squeezed into the rim: see [`crate::disc`] on its limits).
    MirrorBall,
    /// A cube map in one image, faces in the OpenGL/KTX orientation.
    Cube(CubeLayout),
    /// One equidistant fisheye circle looking forward (-Z), image up = +Y, right = +X.
    Fisheye {
        /// Full field of view across the circle, degrees, in (0, 360].
        fov_deg: f32,
    },
    /// Two equidistant fisheye circles side by side in a 2:1 frame (Gear 360 style): left looks
    /// forward (-Z, right = +X), right looks backward (+Z, right = -X); image up = +Y for both.
    DualFisheye {
        /// Full field of view of each lens, degrees, in (0, 360] (real cameras: about 195).
        fov_deg: f32,
    },
}

/// The canonical names of every mapping, for help texts.
pub const MAPPING_NAMES: [&str; 9] = [
    "latlong",
    "angular",
    "mirror-ball",
    "cube-hcross",
    "cube-vcross",
    "cube-strip",
    "cube-vstrip",
    "fisheye",
    "dual-fisheye",
];

/// Formats a field of view compactly: `195`, `190.5`.
fn fov_text(fov: f32) -> String {
    if fov.fract() == 0.0 && fov.abs() < 1e6 {
        format!("{}", fov as i64)
    } else {
        format!("{fov}")
    }
}

impl Mapping {
    /// The mapping's name: `latlong`, `angular`, `mirror-ball`, `cube-hcross`, `cube-vcross`,
    /// `cube-strip`, `cube-vstrip`, `fisheye-<fov>`, `dual-fisheye-<fov>` (e.g. `dual-fisheye-195`). Every name
    /// is accepted back by [`Mapping::parse`].
    pub fn name(&self) -> String {
        match self {
            Mapping::LatLong => "latlong".into(),
            Mapping::Angular => "angular".into(),
            Mapping::MirrorBall => "mirror-ball".into(),
            Mapping::Cube(l) => l.name().into(),
            Mapping::Fisheye { fov_deg } => format!("fisheye-{}", fov_text(*fov_deg)),
            Mapping::DualFisheye { fov_deg } => format!("dual-fisheye-{}", fov_text(*fov_deg)),
        }
    }

    /// Looks a mapping up by name, case-insensitively. Accepts the canonical names and the
    /// aliases `lat-long`, `equirect`, `equirectangular`; `angular-map`, `probe`, `light-probe`;
    /// `ball`, `mirrorball`, `chrome-ball`; `cross`, `hcross`, `cube`, `vcross`, `strip`,
    /// `hstrip`; `dual`, `dualfisheye`. `fov_deg` is used by the fisheye mappings unless the name
    /// carries its own (`fisheye-195`, `dual-fisheye:200`). The field of view is checked later
    /// (by [`Mapping::validate`], `check_shape` and every conversion), not here.
    pub fn parse(name: &str, fov_deg: f32) -> Option<Mapping> {
        let lower = name.trim().to_ascii_lowercase().replace('_', "-");
        let (base, fov) = split_fov_suffix(&lower);
        let fov = fov.unwrap_or(fov_deg);
        let m = match base {
            "latlong" | "lat-long" | "equirect" | "equirectangular" | "longlat" => Mapping::LatLong,
            "angular" | "angular-map" | "probe" | "light-probe" | "lightprobe" => Mapping::Angular,
            "mirror-ball" | "mirrorball" | "ball" | "chrome-ball" => Mapping::MirrorBall,
            "cube-hcross" | "hcross" | "cross" | "cube" | "cube-cross" | "horizontal-cross" => {
                Mapping::Cube(CubeLayout::HorizontalCross)
            }
            "cube-vcross" | "vcross" | "vertical-cross" => Mapping::Cube(CubeLayout::VerticalCross),
            "cube-strip" | "strip" | "hstrip" | "horizontal-strip" | "cube-hstrip" => {
                Mapping::Cube(CubeLayout::HorizontalStrip)
            }
            "cube-vstrip" | "vstrip" | "vertical-strip" => Mapping::Cube(CubeLayout::VerticalStrip),
            "fisheye" => Mapping::Fisheye { fov_deg: fov },
            "dual-fisheye" | "dualfisheye" | "dual" => Mapping::DualFisheye { fov_deg: fov },
            _ => return None,
        };
        Some(m)
    }

    /// The field of view of the fisheye mappings, degrees; `None` for the others.
    pub fn fov_deg(&self) -> Option<f32> {
        match self {
            Mapping::Fisheye { fov_deg } | Mapping::DualFisheye { fov_deg } => Some(*fov_deg),
            _ => None,
        }
    }

    /// Checks the mapping's own parameters: a fisheye field of view must be in (0, 360].
    pub fn validate(&self) -> Result<(), MappingError> {
        if let Some(fov) = self.fov_deg()
            && !(fov > 0.0 && fov <= 360.0)
        {
            return Err(MappingError::Parameter(format!(
                "{}: the field of view must be in (0, 360] degrees, got {fov}",
                self.name()
            )));
        }
        Ok(())
    }

    /// Detects the mapping from the aspect ratio alone: 2:1 lat-long, 1:1 angular (a mirror ball
    /// is square too: shape cannot tell them apart), 4:3 horizontal cross, 3:4 vertical cross,
    /// 6:1 horizontal strip, 1:6 vertical strip; `None` for any other shape (an empty image included), which no
    /// caller may take for lat-long without saying so.
    pub fn detect_from_shape(width: usize, height: usize) -> Option<Mapping> {
        let (w, h) = (width as u128, height as u128);
        if w == 0 || h == 0 {
            None
        } else if w == 2 * h {
            Some(Mapping::LatLong)
        } else if w == h {
            Some(Mapping::Angular)
        } else if 3 * w == 4 * h {
            Some(Mapping::Cube(CubeLayout::HorizontalCross))
        } else if 4 * w == 3 * h {
            Some(Mapping::Cube(CubeLayout::VerticalCross))
        } else if w == 6 * h {
            Some(Mapping::Cube(CubeLayout::HorizontalStrip))
        } else if 6 * w == h {
            Some(Mapping::Cube(CubeLayout::VerticalStrip))
        } else {
            None
        }
    }

    /// The output size for a requested width, adjusted to the mapping's shape: lat-long
    /// `2s x s` (s = width / 2), disc mappings `w x w`, horizontal cross `4s x 3s` (s = width / 4),
    /// vertical cross `3s x 4s` (s = width / 3), strip `6s x s` (s = width / 6), dual fisheye
    /// `2s x s`. Never zero: a width too small for one face gives the smallest valid size.
    pub fn size_for_width(&self, width: usize) -> (usize, usize) {
        match self {
            Mapping::LatLong | Mapping::DualFisheye { .. } => {
                let s = (width / 2).max(1);
                (2 * s, s)
            }
            Mapping::Angular | Mapping::MirrorBall | Mapping::Fisheye { .. } => {
                let s = width.max(1);
                (s, s)
            }
            Mapping::Cube(layout) => {
                let (cols, rows) = layout.grid();
                let s = (width / cols).max(1);
                (cols * s, rows * s)
            }
        }
    }

    /// Angular resolution of a `w x h` image of this mapping as an equivalent lat-long width
    /// (pixels per 360 degrees): lat-long `w`, angular `w` (its diameter spans 360 degrees),
    /// mirror ball `w / 2` (its rim is badly undersampled, so it gets twice the pixels), cube
    /// `4 x face`, fisheye `w * 360 / fov`, dual fisheye `h * 360 / fov`.
    fn equivalent_latlong_width(&self, w: usize, h: usize) -> f64 {
        let (w, h) = (w as f64, h as f64);
        match self {
            Mapping::LatLong | Mapping::Angular => w,
            Mapping::MirrorBall => w / 2.0,
            Mapping::Cube(layout) => 4.0 * w / layout.grid().0 as f64,
            Mapping::Fisheye { fov_deg } => w * 360.0 / f64::from(fov_deg.max(1e-3)),
            Mapping::DualFisheye { fov_deg } => h * 360.0 / f64::from(fov_deg.max(1e-3)),
        }
    }

    /// A sensible output size for converting a `src_w x src_h` image of mapping `source` into
    /// this mapping, keeping the source's angular resolution: lat-long 512 x 256 gives a cube
    /// face of 128, an angular map 512 wide, a mirror ball 1024 wide, a 180-degree fisheye 256
    /// wide and a 200-degree dual fisheye 568 x 284.
    pub fn default_size_for(&self, source: Mapping, src_w: usize, src_h: usize) -> (usize, usize) {
        let e = source
            .equivalent_latlong_width(src_w, src_h)
            .clamp(1.0, 1e9);
        let width = match self {
            Mapping::LatLong | Mapping::Angular => e,
            Mapping::MirrorBall => 2.0 * e,
            Mapping::Cube(layout) => (e / 4.0).round() * layout.grid().0 as f64,
            Mapping::Fisheye { fov_deg } => e * f64::from(*fov_deg) / 360.0,
            Mapping::DualFisheye { fov_deg } => 2.0 * e * f64::from(*fov_deg) / 360.0,
        };
        let width = if width.is_finite() {
            width.round().max(1.0) as usize
        } else {
            1
        };
        self.size_for_width(width)
    }
}

impl fmt::Display for Mapping {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

impl CubeLayout {
    /// Every layout, in a stable order.
    pub const ALL: [CubeLayout; 4] = [
        CubeLayout::HorizontalCross,
        CubeLayout::VerticalCross,
        CubeLayout::HorizontalStrip,
        CubeLayout::VerticalStrip,
    ];

    /// The layout's mapping name: `cube-hcross`, `cube-vcross`, `cube-strip`, `cube-vstrip`.
    pub fn name(self) -> &'static str {
        match self {
            CubeLayout::HorizontalCross => "cube-hcross",
            CubeLayout::VerticalCross => "cube-vcross",
            CubeLayout::HorizontalStrip => "cube-strip",
            CubeLayout::VerticalStrip => "cube-vstrip",
        }
    }

    /// The grid of cells as `(columns, rows)`: 4 x 3, 3 x 4, 6 x 1 or 1 x 6.
    pub fn grid(self) -> (usize, usize) {
        match self {
            CubeLayout::HorizontalCross => (4, 3),
            CubeLayout::VerticalCross => (3, 4),
            CubeLayout::HorizontalStrip => (6, 1),
            CubeLayout::VerticalStrip => (1, 6),
        }
    }
}

/// Splits `fisheye-195`, `fisheye:195` or `fisheye195` into the base name and the field of view.
fn split_fov_suffix(name: &str) -> (&str, Option<f32>) {
    let digits_start = name
        .char_indices()
        .rev()
        .take_while(|(_, c)| c.is_ascii_digit() || *c == '.')
        .last()
        .map(|(i, _)| i);
    if let Some(i) = digits_start
        && i > 0
        && let Ok(v) = name[i..].parse::<f32>()
    {
        let base = name[..i].trim_end_matches(['-', ':', '@', ' ']);
        if base.contains("fisheye") || base == "dual" {
            return (base, Some(v));
        }
    }
    (name, None)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may panic
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_parse() {
        let all = [
            Mapping::LatLong,
            Mapping::Angular,
            Mapping::MirrorBall,
            Mapping::Cube(CubeLayout::HorizontalCross),
            Mapping::Cube(CubeLayout::VerticalCross),
            Mapping::Cube(CubeLayout::HorizontalStrip),
            Mapping::Cube(CubeLayout::VerticalStrip),
            Mapping::Fisheye { fov_deg: 180.0 },
            Mapping::DualFisheye { fov_deg: 195.5 },
        ];
        for m in all {
            assert_eq!(Mapping::parse(&m.name(), 123.0), Some(m), "{}", m.name());
        }
        for (i, m) in all.iter().enumerate() {
            assert!(m.name().starts_with(MAPPING_NAMES[i]));
            let fov = m.fov_deg().unwrap_or(180.0);
            assert_eq!(Mapping::parse(MAPPING_NAMES[i], fov), Some(*m));
        }
    }

    #[test]
    fn aliases_and_fov() {
        assert_eq!(Mapping::parse("Equirect", 0.0), Some(Mapping::LatLong));
        assert_eq!(Mapping::parse("probe", 0.0), Some(Mapping::Angular));
        assert_eq!(Mapping::parse("angular-map", 0.0), Some(Mapping::Angular));
        assert_eq!(Mapping::parse("ball", 0.0), Some(Mapping::MirrorBall));
        assert_eq!(
            Mapping::parse("cross", 0.0),
            Some(Mapping::Cube(CubeLayout::HorizontalCross))
        );
        assert_eq!(
            Mapping::parse("strip", 0.0),
            Some(Mapping::Cube(CubeLayout::HorizontalStrip))
        );
        assert_eq!(
            Mapping::parse("fisheye", 190.0),
            Some(Mapping::Fisheye { fov_deg: 190.0 })
        );
        assert_eq!(
            Mapping::parse("dual-fisheye:200", 180.0),
            Some(Mapping::DualFisheye { fov_deg: 200.0 })
        );
        assert_eq!(Mapping::parse("nonsense", 180.0), None);
        assert_eq!(Mapping::parse("", 180.0), None);
    }

    #[test]
    fn shapes_are_detected_and_checked() {
        let detect = Mapping::detect_from_shape;
        assert_eq!(detect(512, 256), Some(Mapping::LatLong));
        assert_eq!(detect(300, 300), Some(Mapping::Angular));
        assert_eq!(
            detect(512, 384),
            Some(Mapping::Cube(CubeLayout::HorizontalCross))
        );
        assert_eq!(
            detect(384, 512),
            Some(Mapping::Cube(CubeLayout::VerticalCross))
        );
        assert_eq!(
            detect(768, 128),
            Some(Mapping::Cube(CubeLayout::HorizontalStrip))
        );
        // Issue 13: a 2:3 photo and an empty image are no mapping, never lat-long.
        // Issue 13: a 1:6 strip is a cube map, not a lat-long smear.
        assert_eq!(
            detect(64, 384),
            Some(Mapping::Cube(CubeLayout::VerticalStrip))
        );
        assert_eq!(detect(400, 600), None);
        assert_eq!(detect(0, 0), None);
        assert_eq!(detect(usize::MAX, 3), None);
        assert!(
            Mapping::Cube(CubeLayout::HorizontalCross)
                .check_shape(512, 384)
                .is_ok()
        );
        assert!(
            Mapping::Cube(CubeLayout::HorizontalCross)
                .check_shape(512, 385)
                .is_err()
        );
        assert!(Mapping::Angular.check_shape(512, 256).is_err());
        assert!(Mapping::LatLong.check_shape(0, 256).is_err());
        assert!(
            Mapping::DualFisheye { fov_deg: 195.0 }
                .check_shape(512, 256)
                .is_ok()
        );
        assert!(
            Mapping::Fisheye { fov_deg: 0.0 }
                .check_shape(256, 256)
                .is_err()
        );
        assert!(
            Mapping::Fisheye { fov_deg: 361.0 }
                .check_shape(256, 256)
                .is_err()
        );
        assert!(
            Mapping::Fisheye { fov_deg: f32::NAN }
                .check_shape(256, 256)
                .is_err()
        );
    }

    #[test]
    fn sizes() {
        let ll = Mapping::LatLong;
        assert_eq!(ll.size_for_width(513), (512, 256));
        assert_eq!(
            Mapping::Cube(CubeLayout::HorizontalCross).size_for_width(1000),
            (1000, 750)
        );
        assert_eq!(
            Mapping::Cube(CubeLayout::VerticalCross).size_for_width(100),
            (99, 132)
        );
        assert_eq!(
            Mapping::Cube(CubeLayout::HorizontalStrip).size_for_width(0),
            (6, 1)
        );
        let cube = Mapping::Cube(CubeLayout::HorizontalCross);
        assert_eq!(cube.default_size_for(ll, 512, 256), (512, 384));
        assert_eq!(Mapping::Angular.default_size_for(ll, 512, 256), (512, 512));
        assert_eq!(
            Mapping::MirrorBall.default_size_for(ll, 512, 256),
            (1024, 1024)
        );
        assert_eq!(
            ll.default_size_for(Mapping::MirrorBall, 1024, 1024),
            (512, 256)
        );
        assert_eq!(ll.default_size_for(cube, 512, 384), (512, 256));
        let dual = Mapping::DualFisheye { fov_deg: 200.0 };
        assert_eq!(dual.default_size_for(ll, 512, 256), (568, 284));
        assert_eq!(
            Mapping::Fisheye { fov_deg: 180.0 }.default_size_for(ll, 512, 256),
            (256, 256)
        );
    }
}
