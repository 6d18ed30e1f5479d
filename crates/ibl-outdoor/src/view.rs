//! What a view sees of the scene model: per pixel, the surface point its centre ray hits (or the
//! sky), for the probe's lat-long panorama or a calibrated pinhole camera.
//!
//! Jensen, Andersen & Madsen 2006 (section 4.1) keep every offline map "in the environment
//! map", one value per probe pixel, because the relighting is a per-pixel operation. A pixel here
//! is its centre ray (`ibl_scene::Camera::ray` at `(i + 0.5, j + 0.5)`), so a pixel straddling
//! two surfaces takes the nearer one at its centre; the estimator's robust loss absorbs the few
//! such pixels. Normals face the viewer (surfaces are two-sided, as in `ibl-scene`).
//!
//! [`ProbeProjection`] is the projective mapping of the probe onto the model that the paper uses
//! to take the albedo map (and any other probe map) to another view's surface points: a world
//! point belongs to the probe pixel in its direction from the probe centre when the probe's
//! centre ray there ends at that point (within a tolerance of 1 % of the distance plus two pixel
//! footprints), i.e. when the probe saw it.

use glam::{Mat3, Vec3};
use ibl_core::LatLong;
use ibl_scene::{Camera, GeometryLayer, Ray};
use rayon::prelude::*;

/// A surface point seen by a pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// World position, metres.
    pub position: Vec3,
    /// Unit shading normal, facing the viewer.
    pub normal: Vec3,
    /// Distance from the view's origin, metres.
    pub distance: f32,
    /// The triangle (index in the layer).
    pub triangle: u32,
}

/// Per pixel of a view, the surface its centre ray meets (`None`: the sky).
#[derive(Clone, Debug)]
pub struct ViewGeometry {
    width: usize,
    height: usize,
    hits: Vec<Option<SurfaceHit>>,
}

impl ViewGeometry {
    /// Casts the centre ray of every pixel of a `width x height` image of `camera` into `layer`.
    /// O(W H log T).
    pub fn new(layer: &GeometryLayer, camera: &Camera, width: usize, height: usize) -> Self {
        let hits = (0..width * height)
            .into_par_iter()
            .map(|k| {
                let (i, j) = (k % width, k / width);
                let ray = camera.ray(i as f32 + 0.5, j as f32 + 0.5, width as u32, height as u32);
                cast(layer, &ray)
            })
            .collect();
        ViewGeometry {
            width,
            height,
            hits,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The hit of pixel `(i, j)`.
    pub fn hit(&self, i: usize, j: usize) -> Option<&SurfaceHit> {
        self.hits[j * self.width + i].as_ref()
    }

    /// All pixels, row-major.
    pub fn hits(&self) -> &[Option<SurfaceHit>] {
        &self.hits
    }

    /// Indices (row-major) of the pixels that see a surface.
    pub fn surface_pixels(&self) -> Vec<usize> {
        (0..self.hits.len())
            .filter(|&k| self.hits[k].is_some())
            .collect()
    }
}

/// One sub-pixel ray of a pixel's footprint: where it goes and what it meets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootprintRay {
    /// Unit world direction of the ray.
    pub direction: Vec3,
    /// The surface it meets (`None`: it leaves the model, the sky).
    pub hit: Option<SurfaceHit>,
}

/// The `side x side` grid of sub-pixel rays through pixel `(i, j)` (at `(i + (a + 0.5) / side,
/// j + (b + 0.5) / side)`, row by row) of a `width x height` image of `camera`, with what each
/// meets. Used to integrate the sun term over a pixel's footprint (shadow edges, grazing ground)
/// and to find the pixels that straddle two surfaces or a surface and the sky.
pub fn pixel_footprint(
    layer: &GeometryLayer,
    camera: &Camera,
    size: (usize, usize),
    pixel: (usize, usize),
    side: usize,
) -> Vec<FootprintRay> {
    let (width, height) = size;
    let (i, j) = pixel;
    let mut out = Vec::with_capacity(side * side);
    for b in 0..side {
        for a in 0..side {
            let ray = camera.ray(
                i as f32 + (a as f32 + 0.5) / side as f32,
                j as f32 + (b as f32 + 0.5) / side as f32,
                width as u32,
                height as u32,
            );
            out.push(FootprintRay {
                direction: ray.direction,
                hit: cast(layer, &ray),
            });
        }
    }
    out
}

/// The closest hit of `ray` in `layer`, with the normal turned towards the ray's origin.
pub fn cast(layer: &GeometryLayer, ray: &Ray) -> Option<SurfaceHit> {
    let hit = layer.bvh.closest_hit(ray, 0.0, f32::INFINITY)?;
    let surface = layer.surface_point(&hit, ray.direction);
    Some(SurfaceHit {
        position: surface.position,
        normal: surface.shading_normal,
        distance: hit.t,
        triangle: hit.triangle,
    })
}

/// The probe's projective mapping onto the model.
#[derive(Clone, Debug)]
pub struct ProbeProjection {
    /// Probe centre, world frame.
    pub position: Vec3,
    /// Rotation from the probe frame to the world.
    pub world_from_probe: Mat3,
    /// What the probe's pixels see.
    pub view: ViewGeometry,
}

/// Relative depth tolerance of [`ProbeProjection::pixel_of`].
const DEPTH_TOLERANCE: f32 = 0.01;

impl ProbeProjection {
    /// The probe at `position` with `world_from_probe`, seeing `layer` in a `width x width/2`
    /// lat-long.
    pub fn new(
        layer: &GeometryLayer,
        position: Vec3,
        world_from_probe: Mat3,
        width: usize,
    ) -> Self {
        let camera = Camera::Panorama {
            position,
            world_from_probe,
        };
        let height = (width / 2).max(1);
        ProbeProjection {
            position,
            world_from_probe,
            view: ViewGeometry::new(layer, &camera, width, height),
        }
    }

    /// The probe pixel `(i, j)` in the world direction `d` (unit).
    pub fn pixel_towards(&self, d: Vec3) -> (usize, usize) {
        let grid = LatLong::new(self.view.width(), self.view.height());
        grid.dir_to_pixel((self.world_from_probe.transpose() * d).as_dvec3())
    }

    /// The probe pixel that saw the world point `point`, `None` when the probe did not see it
    /// (something nearer in that pixel, or sky).
    pub fn pixel_of(&self, point: Vec3) -> Option<(usize, usize)> {
        let offset = point - self.position;
        let distance = offset.length();
        if distance.is_nan() || distance <= 0.0 {
            return None;
        }
        let (i, j) = self.pixel_towards(offset / distance);
        let hit = self.view.hit(i, j)?;
        // Two pixel footprints at that distance (a lat-long pixel spans pi / H radians).
        let footprint = 2.0 * distance * std::f32::consts::PI / self.view.height() as f32;
        ((hit.position - point).length() <= DEPTH_TOLERANCE * distance + footprint)
            .then_some((i, j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ibl_core::Rgb;
    use ibl_scene::{Material, PlacedMesh, primitives};

    fn floor_and_box() -> GeometryLayer {
        let diffuse = Material::Diffuse {
            albedo: Rgb::splat(0.5),
        };
        GeometryLayer::new(vec![
            PlacedMesh {
                name: "ground".into(),
                mesh: primitives::plane(Vec3::ZERO, Vec3::Y, [100.0, 100.0]),
                materials: vec![diffuse],
            },
            PlacedMesh {
                name: "box".into(),
                mesh: primitives::cuboid(Vec3::new(-1.0, 0.0, -6.0), Vec3::new(1.0, 2.0, -4.0)),
                materials: vec![diffuse],
            },
        ])
    }

    #[test]
    fn panorama_sees_ground_below_and_sky_above() {
        let layer = floor_and_box();
        let probe = ProbeProjection::new(&layer, Vec3::new(0.0, 1.0, 0.0), Mat3::IDENTITY, 64);
        let v = &probe.view;
        assert!(v.hit(10, 2).is_none(), "top rows are sky");
        let below = v.hit(10, 30).unwrap();
        assert!((below.normal - Vec3::Y).length() < 1e-6);
        assert!(below.position.y.abs() < 1e-4);
        // Straight ahead (-Z) is the box's front face at z = -4, normal +Z towards the probe.
        let ahead = v.hit(32, 16).unwrap();
        assert!((ahead.position.z + 4.0).abs() < 1e-3);
        assert!((ahead.normal - Vec3::Z).length() < 1e-6);
        // The front face is seen; the box's back face is not.
        assert!(probe.pixel_of(Vec3::new(0.0, 1.0, -4.0)).is_some());
        assert!(probe.pixel_of(Vec3::new(0.0, 1.0, -6.0)).is_none());
        // A ground point behind the probe is seen.
        assert!(probe.pixel_of(Vec3::new(0.0, 0.0, 3.0)).is_some());
    }
}
