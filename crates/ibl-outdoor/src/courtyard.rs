//! The synthetic courtyard of the validation (the paper's first scenario, section 6: "an object
//! is placed within a courtyard, and the sun moves during the day, as well as clouds"), built
//! from boxes and a ground of paving tiles, with known albedos.
//!
//! World frame of docs/CONVENTIONS.md, metres, north = -Z (east = +X). The yard is 24 x 24 m
//! (`x, z` in [-12, 12]) paved with 1.5 m tiles whose albedo varies by +-20 % around a warm grey
//! (a hash of the tile index: texture the albedo map must recover); beyond it, a 400 m ground of
//! darker asphalt. Buildings: a 12 m brick block along the north side (three facades of slightly
//! different bricks), an 8 m plaster block on the west, a 6 m concrete block on the east, open to
//! the south; a 3.5 m kiosk in the yard casts a shadow the camera sees all day. The probe stands
//! 1.5 m up between the kiosk and the north block (it must see what the camera's samples see,
//! shade included, and the sun at capture time); the camera looks south-south-east down into the yard from a
//! window 7 m up in the north block, so it sees the shadows the buildings and the kiosk cast
//! (northwards) and their shaded north faces as well as sunlit ground. Every surface is Lambertian (the paper's assumption, section 3.1).

use glam::{Vec2, Vec3};
use ibl_core::{Image, Rgb};
use ibl_scene::{Camera, GeometryLayer, Material, PlacedMesh, TriangleMesh, primitives};

use crate::view::ViewGeometry;

/// The courtyard scene.
#[derive(Clone, Debug)]
pub struct Courtyard {
    /// The real geometry with its materials (one mesh per tile, facade or building).
    pub layer: GeometryLayer,
    /// The probe centre, world frame (metres).
    pub probe_position: Vec3,
    /// The fixed video camera.
    pub camera: Camera,
    /// Lower and upper corners of the box an irradiance volume should cover (the yard, 0.3 to
    /// 3.3 m up).
    pub volume_box: (Vec3, Vec3),
}

/// Half the yard's side, metres.
pub const YARD_HALF: f32 = 12.0;
/// Paving tile side, metres.
pub const TILE: f32 = 1.5;

fn diffuse(r: f32, g: f32, b: f32) -> Material {
    Material::Diffuse {
        albedo: Rgb::new(r, g, b),
    }
}

fn placed(name: String, mesh: TriangleMesh, material: Material) -> PlacedMesh {
    PlacedMesh {
        name,
        mesh,
        materials: vec![material],
    }
}

/// A repeatable number in [-1, 1) for a tile.
fn hash(i: i32, j: i32) -> f32 {
    let mut h = (i as u32).wrapping_mul(0x9E37_79B1) ^ (j as u32).wrapping_mul(0x85EB_CA77);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    (h & 0xFFFF) as f32 / 32768.0 - 1.0
}

impl Courtyard {
    /// The yard seen by a camera whose frames are `frame_size` (the camera's reference size).
    pub fn new(frame_size: (u32, u32)) -> Courtyard {
        let mut meshes = Vec::new();
        let tiles = (2.0 * YARD_HALF / TILE).round() as i32;
        for a in 0..tiles {
            for b in 0..tiles {
                let centre = Vec3::new(
                    -YARD_HALF + (a as f32 + 0.5) * TILE,
                    0.0,
                    -YARD_HALF + (b as f32 + 0.5) * TILE,
                );
                let v = 1.0 + 0.2 * hash(a, b);
                let warm = 0.03 * hash(b + 101, a - 7);
                meshes.push(placed(
                    format!("tile {a} {b}"),
                    primitives::plane(centre, Vec3::Y, [TILE, TILE]),
                    diffuse(0.42 * v + warm, 0.38 * v, 0.33 * v - warm),
                ));
            }
        }
        // The ground beyond the yard: four rectangles around it, out to 200 m.
        let asphalt = diffuse(0.22, 0.22, 0.2);
        let far = 200.0;
        let ring = [
            (
                Vec3::new(0.0, 0.0, -(far + YARD_HALF) / 2.0),
                [2.0 * far, far - YARD_HALF],
            ),
            (
                Vec3::new(0.0, 0.0, (far + YARD_HALF) / 2.0),
                [2.0 * far, far - YARD_HALF],
            ),
            (
                Vec3::new(-(far + YARD_HALF) / 2.0, 0.0, 0.0),
                [far - YARD_HALF, 2.0 * YARD_HALF],
            ),
            (
                Vec3::new((far + YARD_HALF) / 2.0, 0.0, 0.0),
                [far - YARD_HALF, 2.0 * YARD_HALF],
            ),
        ];
        for (k, (centre, size)) in ring.into_iter().enumerate() {
            // `plane` lays size[0] along its first tangent; for +Y that is the world x axis
            // only up to sign, so build the rectangle from its corners instead.
            let half = Vec3::new(size[0] / 2.0, 0.0, size[1] / 2.0);
            meshes.push(placed(
                format!("ground {k}"),
                quad(centre - half, centre + half),
                asphalt,
            ));
        }
        let boxes = [
            (
                "north facade west",
                [-12.0, 0.0, -20.0],
                [-4.0, 12.0, -12.0],
                diffuse(0.46, 0.26, 0.19),
            ),
            (
                "north facade middle",
                [-4.0, 0.0, -20.0],
                [4.0, 12.0, -12.0],
                diffuse(0.40, 0.23, 0.17),
            ),
            (
                "north facade east",
                [4.0, 0.0, -20.0],
                [12.0, 12.0, -12.0],
                diffuse(0.50, 0.30, 0.22),
            ),
            (
                "west block",
                [-20.0, 0.0, -12.0],
                [-12.0, 8.0, 8.0],
                diffuse(0.62, 0.58, 0.50),
            ),
            (
                "east block",
                [12.0, 0.0, -12.0],
                [18.0, 6.0, 4.0],
                diffuse(0.38, 0.38, 0.36),
            ),
            (
                "kiosk",
                [1.5, 0.0, -4.5],
                [5.0, 3.5, -1.5],
                diffuse(0.55, 0.48, 0.40),
            ),
        ];
        for (name, lo, hi, material) in boxes {
            meshes.push(placed(
                name.into(),
                primitives::cuboid(Vec3::from(lo), Vec3::from(hi)),
                material,
            ));
        }
        let layer = GeometryLayer::new(meshes);
        let (w, h) = frame_size;
        let focal = Camera::focal_from_vertical_fov(60.0, h);
        let camera = Camera::look_at(
            Vec3::new(-3.0, 7.0, -11.5),
            Vec3::new(2.0, 0.0, 3.0),
            Vec3::Y,
            Vec2::splat(focal),
            Vec2::new(w as f32 / 2.0, h as f32 / 2.0),
            frame_size,
        );
        Courtyard {
            layer,
            probe_position: Vec3::new(0.0, 1.5, -7.0),
            camera,
            volume_box: (Vec3::new(-10.5, 0.3, -10.5), Vec3::new(10.5, 3.3, 10.5)),
        }
    }

    /// The virtual object of the validation and the demo: a statue (a 1 m plinth of white stone
    /// and a 0.6 m sphere of bronze-coloured stone on it, both Lambertian as the paper's model
    /// assumes) west of the kiosk, 10 m in front of the camera: in the sun until the afternoon,
    /// when the west block's shadow reaches it (a real shadow on the virtual object), its own
    /// shadow on the paving the camera sees.
    pub fn statue() -> GeometryLayer {
        GeometryLayer::new(vec![
            placed(
                "plinth".into(),
                primitives::cuboid(Vec3::new(-4.45, 0.0, -1.45), Vec3::new(-3.55, 1.0, -0.55)),
                diffuse(0.72, 0.70, 0.66),
            ),
            placed(
                "sphere".into(),
                primitives::sphere(Vec3::new(-4.0, 1.6, -1.0), 0.6, 3),
                diffuse(0.55, 0.36, 0.20),
            ),
        ])
    }

    /// The mask of marked diffuse surfaces for `frame_size` frames: every pixel that sees the
    /// model (everything in the synthetic yard is diffuse).
    pub fn diffuse_mask(&self, frame_size: (usize, usize)) -> Image<bool> {
        let view = ViewGeometry::new(&self.layer, &self.camera, frame_size.0, frame_size.1);
        let hits = view.hits();
        Image::from_fn_par(frame_size.0, frame_size.1, |i, j| {
            hits[j * frame_size.0 + i].is_some()
        })
    }
}

/// A horizontal rectangle from `lo` to `hi` (same `y`), facing up.
fn quad(lo: Vec3, hi: Vec3) -> TriangleMesh {
    let positions = vec![
        Vec3::new(lo.x, lo.y, lo.z),
        Vec3::new(lo.x, lo.y, hi.z),
        Vec3::new(hi.x, lo.y, hi.z),
        Vec3::new(hi.x, lo.y, lo.z),
    ];
    TriangleMesh {
        positions,
        normals: vec![Vec3::Y; 4],
        // (0, 1, 2): (lo.x, lo.z) -> (lo.x, hi.z) -> (hi.x, hi.z) turns counter-clockwise seen
        // from above (+Y): (0,0,1) x (1,0,0) = (0, 1, 0).
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        material_slots: vec![0, 0],
        material_names: vec!["default".into()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_yard_is_closed_underneath_and_the_camera_sees_it() {
        let yard = Courtyard::new((80, 60));
        // Every downward ray from above the yard and the ring meets the ground.
        for (x, z) in [
            (0.0, 0.0),
            (11.9, -11.9),
            (50.0, 3.0),
            (-150.0, -150.0),
            (5.0, 150.0),
        ] {
            let ray = ibl_scene::Ray::new(Vec3::new(x, 30.0, z), Vec3::NEG_Y);
            assert!(
                yard.layer
                    .bvh
                    .closest_hit(&ray, 0.0, f32::INFINITY)
                    .is_some(),
                "{x} {z}"
            );
        }
        let mask = yard.diffuse_mask((80, 60));
        let seen = mask.pixels().iter().filter(|&&m| m).count();
        assert!(seen > 80 * 60 * 3 / 4, "{seen}");
        // Ground quads face up.
        for s in &yard.layer.surfaces {
            assert!(s.geometric_normal.length() > 0.99);
        }
    }
}
