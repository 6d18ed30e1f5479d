//! Goniometric point lights in the scene viewer: a scene's `[[luminaire]]` entries
//! (`Lighting::luminaires`, the CPU renderer's own list), drawn by `point_lights.wgsl` as
//! `ibl-render` draws them (Grosch 2005 section 4.2, EQ5 `E = I(theta, phi) cos theta_e / d^2`,
//! new lights that only the scene with the objects has), each with a hard shadow from both layers.
//!
//! - **Intensity**: each light's candela table times its scale to the probe's units
//!   (`intensity_per_candela`) is resampled once onto a [`MAP_WIDTH`] x [`MAP_HEIGHT`] grid of
//!   its photometric angles, `C` across (0 to 360 degrees, wrapping) and `gamma` down (0 at the
//!   nadir to 180 degrees), texel centres at `(i + 0.5) / W` and `(j + 0.5) / H` of the ranges.
//!   The shader interpolates that grid bilinearly, as `CandelaTable::intensity` interpolates
//!   the table itself; at 1.4 degrees a texel the two differ by the table's change of slope
//!   within a texel: on the bundled umbrella file 0.008 % of the peak on average and 0.4 % at
//!   worst (tested below). The maps are stacked
//!   into one strip texture, light `k` in rows `k H .. (k + 1) H`.
//! - **Shadows**: a point light sees all around it, so its shadow map is a cube: six 90-degree
//!   perspective faces (`face_coords` in `gpu_scene.wgsl`, mirrored by [`face_coords`] here),
//!   each a tile of the same atlases as the directional lights' (tiles `D + 6 k + f` after the
//!   `D` directional ones). A face is drawn only when it can see the layer's casters (the
//!   objects' bounding sphere for the virtual atlas, the real geometry's for the real one:
//!   [`face_sees_sphere`]); a look-up in a face without casters is lit. A light above a flat
//!   real layer does not look the real atlas up on the plane's own side (`point_lights.wgsl`).
//!   Depth is the perspective projection's, between a near and a far plane fitted to the casters
//!   ([`depth_range`]).

use glam::Vec3;
use ibl_core::{Image, Rgb};
use ibl_light::GoniometricLight;

use crate::gpu_scene::{FACES, GpuPointLight, MAX_POINT_LIGHTS, mat3_columns, vec4};
use crate::light_space::AtlasLayout;

/// Columns of a light's intensity map (`C`, 360 degrees).
pub const MAP_WIDTH: usize = 256;

/// Rows of a light's intensity map (`gamma`, 180 degrees).
pub const MAP_HEIGHT: usize = 128;

/// The intensity maps of `lights` stacked into one strip (see the module notes), probe units
/// per sr, `MAP_WIDTH x MAP_HEIGHT * lights.len()` (one black map when there are none).
pub fn intensity_strip(lights: &[GoniometricLight]) -> Image<Rgb> {
    let rows = MAP_HEIGHT * lights.len().max(1);
    Image::from_fn_par(MAP_WIDTH, rows, |i, j| {
        let Some(light) = lights.get(j / MAP_HEIGHT) else {
            return Rgb::ZERO;
        };
        let c = (i as f32 + 0.5) / MAP_WIDTH as f32 * 360.0;
        let gamma = ((j % MAP_HEIGHT) as f32 + 0.5) / MAP_HEIGHT as f32 * 180.0;
        light.intensity_per_candela * light.table.intensity_deg(gamma, c)
    })
}

/// Cube face `face` (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z) of a vector from the light: `(x, y,
/// z)`, z along the face's axis (`gpu_scene.wgsl`'s `face_coords`).
pub fn face_coords(v: Vec3, face: usize) -> Vec3 {
    let s = if face % 2 == 1 { -1.0 } else { 1.0 };
    match face / 2 {
        0 => Vec3::new(v.y, v.z, s * v.x),
        1 => Vec3::new(v.z, v.x, s * v.y),
        _ => Vec3::new(v.x, v.y, s * v.z),
    }
}

/// Whether cube face `face` of a light at `light` can see part of the sphere `(centre,
/// radius)`: the sphere reaches inside all four side planes of the face's pyramid (`|x| <= z`,
/// `|y| <= z`) and in front of its apex. Conservative (a sphere near an edge of the pyramid
/// may pass and be drawn without landing in the face).
pub fn face_sees_sphere(light: Vec3, face: usize, centre: Vec3, radius: f32) -> bool {
    let q = face_coords(centre - light, face);
    let r = radius * std::f32::consts::SQRT_2;
    q.z > -radius && q.x - q.z < r && -q.x - q.z < r && q.y - q.z < r && -q.y - q.z < r
}

/// The narrowest cone about the direction from `light` to `centre` that holds every one of
/// `points` (the virtual objects' vertices, so their triangles too, a cone under a half-turn
/// being convex): `[axis x nearest distance, cos of the half-angle]`, what the light tiles test
/// a tile's samples against (`light_tiles.wgsl`'s `point_shadow_reaches`; the objects' shadow
/// from this light can fall only inside it, behind the nearest vertex). `w = -2` where no such
/// cone is narrower than a half-space (the light at or among the objects), `w = 2` without
/// points (no shadow anywhere). O(points).
pub fn shadow_cone(light: Vec3, centre: Vec3, points: &[Vec3]) -> [f32; 4] {
    if points.is_empty() {
        return [0.0, 0.0, 0.0, 2.0];
    }
    let Some(axis) = (centre - light).try_normalize() else {
        return [0.0, 0.0, 0.0, -2.0];
    };
    let (mut cos, mut nearest) = (1.0f32, f32::INFINITY);
    for &p in points {
        let v = p - light;
        let d = v.length();
        nearest = nearest.min(d);
        if d > 0.0 {
            cos = cos.min(v.dot(axis) / d);
        }
    }
    if cos <= 0.0 || nearest <= 0.0 {
        return [0.0, 0.0, 0.0, -2.0];
    }
    let a = axis * nearest;
    [a.x, a.y, a.z, cos]
}

/// Near and far planes for casters in the sphere `(centre, radius)` seen from `light`: far
/// just past its farthest point, near at 0.9 of its nearest (or `far / 10^4` when the light is
/// inside it). With a 32-bit float depth `face_depth` resolves `z^2 / near x 2^-24` at distance
/// z, under 1 % of a 512-texel face's texel at the far plane when near is far / 10^4.
pub fn depth_range(light: Vec3, centre: Vec3, radius: f32) -> (f32, f32) {
    let d = (centre - light).length();
    let far = ((d + radius) * 1.01).max(1e-3);
    let near = (0.9 * (d - radius)).max(far * 1e-4);
    (near, far)
}

/// How a frame's point lights take part in the composite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointLightRole {
    /// Their light is already in the background (a room's important patches and placed
    /// lights): then on real surfaces they only cast the objects' shadows; else they are new
    /// lights, whose whole light joins the background.
    pub in_background: bool,
    /// They light the virtual objects (not in Grosch's fast display, whose objects take all
    /// their light from the irradiance volume).
    pub light_objects: bool,
}

impl PointLightRole {
    /// A scene's `[[luminaire]]` entries: new lights that light everything.
    pub const NEW: PointLightRole = PointLightRole {
        in_background: false,
        light_objects: true,
    };
}

/// A frame's point lights as the atlases fit them.
#[derive(Clone, Copy, Debug)]
pub struct PointLightInputs<'a> {
    /// The lights.
    pub lights: &'a [GoniometricLight],
    /// The scale of their strip of intensity maps (its texels times this are intensities).
    pub map_scale: f32,
    /// How they take part in the composite.
    pub role: PointLightRole,
    /// Per light, the least squared distance counted, m^2 (missing: 0).
    pub near_field_m2: &'a [f32],
}

impl PointLightInputs<'static> {
    /// No point lights.
    pub const NONE: PointLightInputs<'static> = PointLightInputs {
        lights: &[],
        map_scale: 1.0,
        role: PointLightRole::NEW,
        near_field_m2: &[],
    };
}

/// What the faces of a frame's point lights are fitted to.
#[derive(Clone, Copy, Debug)]
pub struct FaceCasters<'a> {
    /// The virtual objects' bounding sphere.
    pub objects: (Vec3, f32),
    /// Their distinct vertices, world frame (each light's [`shadow_cone`]).
    pub points: &'a [Vec3],
    /// The real geometry's bounding sphere (none without real geometry).
    pub real: Option<(Vec3, f32)>,
}

/// The GPU records of `inputs.lights`, their faces in tiles `first_tile + 6 k + f` of
/// `layout`, fitted to `casters`.
pub fn gpu_point_lights(
    inputs: &PointLightInputs<'_>,
    layout: &AtlasLayout,
    first_tile: u32,
    casters: FaceCasters<'_>,
) -> Vec<GpuPointLight> {
    let PointLightInputs {
        lights,
        map_scale,
        role,
        near_field_m2,
    } = *inputs;
    let flag = |b: bool| if b { 1.0 } else { 0.0 };
    let strip_rows = lights.len().max(1) as f32;
    lights
        .iter()
        .take(MAX_POINT_LIGHTS)
        .enumerate()
        .map(|(k, light)| {
            let p = light.position;
            let (objects_centre, objects_radius) = casters.objects;
            // One near and far for both atlases: the larger span of the two caster sets.
            let (mut near, mut far) = depth_range(p, objects_centre, objects_radius);
            if let Some((c, r)) = casters.real {
                let (n, f) = depth_range(p, c, r);
                near = near.min(n);
                far = far.max(f);
            }
            near = near.max(far * 1e-4);
            let tile = |f: usize| {
                layout
                    .uv_rect(first_tile + (FACES * k + f) as u32)
                    .to_array()
            };
            let real_faces = std::array::from_fn(|f| match casters.real {
                Some((c, r)) if face_sees_sphere(p, f, c, r) => tile(f),
                _ => [0.0; 4],
            });
            let virtual_faces = std::array::from_fn(|f| {
                if face_sees_sphere(p, f, objects_centre, objects_radius) {
                    tile(f)
                } else {
                    [0.0; 4]
                }
            });
            GpuPointLight {
                position: vec4(p, near),
                shadow: [
                    far,
                    layout.tile as f32,
                    flag(role.in_background),
                    flag(role.light_objects),
                ],
                light_from_world: mat3_columns(light.world_from_light.transpose()),
                map: [
                    k as f32 / strip_rows,
                    1.0 / strip_rows,
                    map_scale,
                    near_field_m2.get(k).copied().unwrap_or(0.0).max(0.0),
                ],
                real_faces,
                virtual_faces,
                shadow_cone: shadow_cone(p, objects_centre, casters.points),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat3;
    use ibl_light::CandelaTable;

    fn light_at(p: Vec3) -> GoniometricLight {
        GoniometricLight {
            position: p,
            world_from_light: Mat3::IDENTITY,
            table: CandelaTable::new(vec![0.0, 45.0, 90.0], vec![0.0], vec![100.0, 80.0, 0.0])
                .expect("a table"),
            intensity_per_candela: Rgb::new(1.0, 0.5, 0.25),
        }
    }

    #[test]
    fn the_faces_split_every_direction_and_look_along_their_axis() {
        // Every direction lies in exactly the face of its largest component, at z = that
        // component's magnitude and |x|, |y| <= z.
        for k in 0..500 {
            let t = k as f32 * 0.618_034;
            let v = Vec3::new(t.sin() * 3.0, (t * 1.7).cos(), (t * 2.3).sin() * 2.0);
            let a = v.abs();
            let face = if a.x >= a.y && a.x >= a.z {
                usize::from(v.x < 0.0)
            } else if a.y >= a.z {
                2 + usize::from(v.y < 0.0)
            } else {
                4 + usize::from(v.z < 0.0)
            };
            let q = face_coords(v, face);
            assert!((q.z - a.max_element()).abs() < 1e-6);
            assert!(q.x.abs() <= q.z + 1e-6 && q.y.abs() <= q.z + 1e-6);
        }
    }

    #[test]
    fn a_face_sees_a_sphere_only_inside_its_pyramid() {
        let light = Vec3::ZERO;
        let below = (Vec3::new(0.0, -2.0, 0.0), 0.5);
        let seen: Vec<usize> = (0..FACES)
            .filter(|&f| face_sees_sphere(light, f, below.0, below.1))
            .collect();
        assert_eq!(
            seen,
            vec![3],
            "a small sphere straight below: the -y face only"
        );
        // A sphere around the light is seen by every face.
        assert!((0..FACES).all(|f| face_sees_sphere(light, f, Vec3::new(0.1, 0.0, 0.0), 1.0)));
        // A sphere below and to the side straddles two faces.
        let side = (Vec3::new(2.0, -2.0, 0.0), 0.3);
        let seen: Vec<usize> = (0..FACES)
            .filter(|&f| face_sees_sphere(light, f, side.0, side.1))
            .collect();
        assert_eq!(seen, vec![0, 3]);
    }

    #[test]
    fn the_shadow_cone_holds_every_caster_and_no_more() {
        let light = Vec3::new(0.0, 3.0, 0.0);
        let points = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(-0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.25),
        ];
        let centre = Vec3::new(0.0, 0.5, 0.0);
        let [x, y, z, cos] = shadow_cone(light, centre, &points);
        let axis = Vec3::new(x, y, z);
        // Straight down, 2 m to the nearest point; the widest point 0.5 m aside 3 m down.
        assert!((axis.normalize() - Vec3::NEG_Y).length() < 1e-6);
        assert!((axis.length() - 2.0).abs() < 1e-6);
        let widest = 3.0 / 9.25f32.sqrt();
        assert!((cos - widest).abs() < 1e-6, "{cos} against {widest}");
        for p in points {
            assert!((p - light).normalize().dot(axis.normalize()) >= cos - 1e-6);
        }
        // A light among the objects: no cone narrower than a half-space; none without objects.
        assert_eq!(
            shadow_cone(Vec3::new(0.0, 0.5, 0.0), centre, &points)[3],
            -2.0
        );
        assert_eq!(shadow_cone(light, centre, &[])[3], 2.0);
    }

    #[test]
    fn the_depth_range_encloses_the_casters() {
        let (near, far) = depth_range(Vec3::ZERO, Vec3::new(0.0, -3.0, 0.0), 1.0);
        assert!(near <= 2.0 && near > 1.0 && (4.0..4.1).contains(&far));
        let (near, far) = depth_range(Vec3::ZERO, Vec3::new(0.2, 0.0, 0.0), 1.0);
        assert!(near > 0.0 && near <= far * 1e-4 * 1.0001 && far >= 1.2);
    }

    #[test]
    fn the_strip_holds_each_tables_intensity_on_its_rows() {
        let lights = [light_at(Vec3::ZERO), {
            let mut l = light_at(Vec3::ONE);
            l.intensity_per_candela = Rgb::splat(2.0);
            l
        }];
        let strip = intensity_strip(&lights);
        assert_eq!((strip.width(), strip.height()), (MAP_WIDTH, 2 * MAP_HEIGHT));
        for (k, light) in lights.iter().enumerate() {
            for j in [0, 31, 64, 100, 127] {
                let gamma = (j as f32 + 0.5) / MAP_HEIGHT as f32 * 180.0;
                let want = light.intensity_per_candela * light.table.intensity_deg(gamma, 0.0);
                let got = *strip.get(7, k * MAP_HEIGHT + j);
                assert!((got.r - want.r).abs() <= 1e-4 * want.r.max(1.0), "{k} {j}");
            }
        }
        // Below the horizon (gamma > 90 degrees) the table sends nothing.
        assert_eq!(*strip.get(0, MAP_HEIGHT - 1), Rgb::ZERO);
    }

    #[test]
    fn the_bilinear_map_follows_the_table_on_a_real_file() {
        // The bundled umbrella luminaire: the map's bilinear interpolant between texel centres
        // against the table's own interpolant, over directions between texel centres.
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../assets/photometry/ies/umbrella.ies"
        );
        let table = ibl_io::photometry::read_photometry(std::path::Path::new(path))
            .expect("the bundled IES file reads")
            .table()
            .clone();
        let light = GoniometricLight {
            table,
            ..light_at(Vec3::ZERO)
        };
        let strip = intensity_strip(std::slice::from_ref(&light));
        let peak = light.table.peak();
        let (w, h) = (MAP_WIDTH as f32, MAP_HEIGHT as f32);
        let at = |i: f32, j: f32| strip.get((i.rem_euclid(w)) as usize, j as usize).r;
        let mut worst = 0.0f32;
        let mut sum = 0.0f32;
        let n = 2000;
        for k in 0..n {
            let (u, v) = ((k as f32 * 0.618_034) % 1.0, (k as f32 * 0.414_214) % 1.0);
            let gamma = (0.5 + v * (h - 1.0)) / h * 180.0;
            let c = u * 360.0;
            let (x, y) = (u * w - 0.5, gamma / 180.0 * h - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let (fx, fy) = (x - x0, y - y0);
            let map = (1.0 - fy) * ((1.0 - fx) * at(x0, y0) + fx * at(x0 + 1.0, y0))
                + fy * ((1.0 - fx) * at(x0, y0 + 1.0) + fx * at(x0 + 1.0, y0 + 1.0));
            let exact = light.table.intensity_deg(gamma, c);
            let error = (map - exact).abs() / peak;
            worst = worst.max(error);
            sum += error;
        }
        eprintln!(
            "umbrella map: mean error {:.2e}, worst {:.2e} of the peak",
            sum / n as f32,
            worst
        );
        // Bilinear resampling of a piecewise-bilinear table: the error is the table's change of
        // slope within one texel (1.4 degrees). Measured: mean 7.7e-5, worst 3.8e-3 of the
        // peak; the bounds leave about 3 times that.
        assert!(sum / n as f32 <= 2.5e-4, "mean {}", sum / n as f32);
        assert!(worst <= 0.01, "worst {worst}");
    }
}
