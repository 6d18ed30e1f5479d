//! The viewer's pinhole camera, the same model as `ibl_scene::Camera::Pinhole` (CONVENTIONS
//! section 5c): looks along its -Z with +Y up and +X right; intrinsics `fx, fy, cx, cy` in pixels
//! of the output image, row 0 at the top. The ray through continuous pixel coordinates `(px, py)`
//! is `world_from_camera ((px - cx) / fx, -(py - cy) / fy, -1)`, so a camera-frame point
//! `(x, y, z)` (z < 0) lands at
//!
//! ```text
//! px = cx + fx x / -z,   py = cy - fy y / -z.
//! ```
//!
//! The rasteriser's clip space has x right and y up in `[-1, 1]` and depth in `[0, 1]`:
//! `x_ndc = 2 px / W - 1`, `y_ndc = 1 - 2 py / H`. Depth is reversed and the far plane at
//! infinity (`depth = near / -z`: 1 at the near plane, towards 0 far away), which keeps f32 depth
//! precise over the 40 m ground planes of the example scenes.
//!
//! [`OrbitControl`] is how a user moves it: yaw and pitch about a target at a distance (orbit,
//! Blender's viewport) or about the eye itself (look around, a panorama viewer).

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use ibl_scene::Camera;

/// Near plane of the reversed-Z projection, world units.
pub const NEAR: f32 = 0.01;

/// A pinhole camera at a given output size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputCamera {
    /// Eye, world frame.
    pub position: Vec3,
    /// Rotation from the camera frame (-Z forward, +Y up) to the world.
    pub world_from_camera: Mat3,
    /// `(fx, fy)` in output pixels.
    pub focal_px: Vec2,
    /// `(cx, cy)` in output pixels.
    pub principal_px: Vec2,
    /// Output size, pixels.
    pub size: (u32, u32),
}

impl OutputCamera {
    /// A scene's pinhole camera rendered at `width x height` (intrinsics scaled from its reference
    /// image exactly as `Camera::ray` scales them); `None` for a panorama camera.
    pub fn from_scene(camera: &Camera, width: u32, height: u32) -> Option<OutputCamera> {
        match *camera {
            Camera::Panorama { .. } => None,
            Camera::Pinhole {
                position,
                world_from_camera,
                focal_px,
                principal_px,
                reference_size,
            } => {
                let s = Vec2::new(
                    width as f32 / reference_size.0 as f32,
                    height as f32 / reference_size.1 as f32,
                );
                Some(OutputCamera {
                    position,
                    world_from_camera,
                    focal_px: focal_px * s,
                    principal_px: principal_px * s,
                    size: (width, height),
                })
            }
        }
    }

    /// A camera at `position` with rotation `world_from_camera`, a vertical field of view and the
    /// principal point at the image centre.
    pub fn centred(
        position: Vec3,
        world_from_camera: Mat3,
        vertical_fov_rad: f32,
        width: u32,
        height: u32,
    ) -> OutputCamera {
        let f = 0.5 * height as f32 / (0.5 * vertical_fov_rad).tan();
        OutputCamera {
            position,
            world_from_camera,
            focal_px: Vec2::splat(f),
            principal_px: Vec2::new(width as f32, height as f32) * 0.5,
            size: (width, height),
        }
    }

    /// The unit world direction through continuous pixel coordinates `(px, py)`.
    pub fn ray(&self, px: f32, py: f32) -> Vec3 {
        let d = Vec3::new(
            (px - self.principal_px.x) / self.focal_px.x,
            -(py - self.principal_px.y) / self.focal_px.y,
            -1.0,
        );
        (self.world_from_camera * d).normalize()
    }

    /// Camera frame from world frame (rigid).
    pub fn camera_from_world(&self) -> Mat4 {
        let r = self.world_from_camera.transpose();
        Mat4::from_mat3(r) * Mat4::from_translation(-self.position)
    }

    /// Clip space from the camera frame: the projection of the module notes.
    pub fn clip_from_camera(&self) -> Mat4 {
        let (w, h) = (self.size.0 as f32, self.size.1 as f32);
        let (fx, fy) = (self.focal_px.x, self.focal_px.y);
        let (cx, cy) = (self.principal_px.x, self.principal_px.y);
        // Columns act on (x, y, z, 1); clip w = -z.
        Mat4::from_cols(
            Vec4::new(2.0 * fx / w, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 * fy / h, 0.0, 0.0),
            Vec4::new(1.0 - 2.0 * cx / w, 2.0 * cy / h - 1.0, 0.0, -1.0),
            Vec4::new(0.0, 0.0, NEAR, 0.0),
        )
    }

    /// Clip space from the world frame.
    pub fn clip_from_world(&self) -> Mat4 {
        self.clip_from_camera() * self.camera_from_world()
    }

    /// Pixel coordinates of a world point, `None` behind the camera.
    pub fn project(&self, p: Vec3) -> Option<Vec2> {
        let q = self.world_from_camera.transpose() * (p - self.position);
        (q.z < 0.0).then(|| {
            Vec2::new(
                self.principal_px.x + self.focal_px.x * q.x / -q.z,
                self.principal_px.y - self.focal_px.y * q.y / -q.z,
            )
        })
    }

    /// Vertical field of view, radians.
    pub fn vertical_fov(&self) -> f32 {
        2.0 * (0.5 * self.size.1 as f32 / self.focal_px.y).atan()
    }
}

/// A rotation whose camera looks along `forward` with `up` as the up hint (glTF convention).
pub fn looking(forward: Vec3, up: Vec3) -> Mat3 {
    let back = -forward.normalize();
    let right = up.cross(back).normalize_or(Vec3::X);
    let true_up = back.cross(right);
    Mat3::from_cols(right, true_up, back)
}

/// How the user turns and moves the camera: yaw about world +Y and pitch about the camera's
/// right axis, either about a target in front of the eye (orbit) or about the eye (look around).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitControl {
    /// The point orbited, world frame.
    pub target: Vec3,
    /// Eye-to-target distance, world units (0: the eye is the target, pure look-around).
    pub distance: f32,
    /// Rotation about world +Y, radians (0 looks along -Z, positive turns left).
    pub yaw: f32,
    /// Elevation of the view direction, radians (positive looks up), within +-89 degrees.
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub vertical_fov: f32,
}

/// Largest pitch, radians (89 degrees: the view never flips over the pole).
const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;

impl OrbitControl {
    /// The control that reproduces an eye and a viewing direction.
    pub fn from_view(eye: Vec3, forward: Vec3, distance: f32, vertical_fov: f32) -> OrbitControl {
        let f = forward.normalize_or(Vec3::NEG_Z);
        OrbitControl {
            target: eye + f * distance,
            distance,
            yaw: (-f.x).atan2(-f.z),
            pitch: f.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            vertical_fov,
        }
    }

    /// Unit viewing direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sy * cp, sp, -cy * cp)
    }

    /// The eye position.
    pub fn eye(&self) -> Vec3 {
        self.target - self.forward() * self.distance
    }

    /// Turns by `d_yaw`, `d_pitch` radians (pitch clamped).
    pub fn turn(&mut self, d_yaw: f32, d_pitch: f32) {
        self.yaw = (self.yaw + d_yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + d_pitch).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Moves the target (and the eye with it) by `right` and `up` world units in the view plane.
    pub fn pan(&mut self, right: f32, up: f32) {
        let r = looking(self.forward(), Vec3::Y);
        self.target += r.x_axis * right + r.y_axis * up;
    }

    /// Multiplies the distance by `factor` (kept above 1 cm).
    pub fn dolly(&mut self, factor: f32) {
        self.distance = (self.distance * factor).max(0.01);
    }

    /// The camera at `width x height`, principal point at the centre.
    pub fn camera(&self, width: u32, height: u32) -> OutputCamera {
        OutputCamera::centred(
            self.eye(),
            looking(self.forward(), Vec3::Y),
            self.vertical_fov,
            width,
            height,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene_camera() -> Camera {
        Camera::look_at(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, -0.75, -1.2),
            Vec3::Y,
            Vec2::splat(Camera::focal_from_vertical_fov(40.0, 480)),
            Vec2::new(300.0, 250.0),
            (640, 480),
        )
    }

    #[test]
    fn rays_match_the_scene_camera() {
        let scene = scene_camera();
        let out = OutputCamera::from_scene(&scene, 320, 240).expect("pinhole");
        for (x, y) in [(0.5, 0.5), (160.0, 120.0), (319.5, 10.25)] {
            let a = out.ray(x, y);
            let b = scene.ray(x, y, 320, 240).direction;
            // Two f32 evaluations of the same formula: a few ulps.
            assert!((a - b).length() < 1e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn the_projection_inverts_the_ray() {
        let out = OutputCamera::from_scene(&scene_camera(), 640, 480).expect("pinhole");
        let clip_from_world = out.clip_from_world();
        for (x, y) in [(10.5, 20.5), (320.0, 240.0), (600.0, 470.0)] {
            let p = out.position + out.ray(x, y) * 3.7;
            let px = out.project(p).expect("in front");
            // f32 round trip through a normalised direction: 1e-3 pixels, measured 1e-4.
            assert!((px - Vec2::new(x, y)).length() < 1e-3, "{px} vs ({x}, {y})");
            let clip = clip_from_world * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let expected = Vec2::new(2.0 * x / 640.0 - 1.0, 1.0 - 2.0 * y / 480.0);
            assert!((ndc.truncate() - expected).length() < 1e-5);
            // Reversed depth: near / distance along the view axis.
            let z = (out.world_from_camera.transpose() * (p - out.position)).z;
            assert!((ndc.z - NEAR / -z).abs() < 1e-7);
        }
    }

    #[test]
    fn the_orbit_reproduces_its_view() {
        let eye = Vec3::new(1.0, 2.0, 3.0);
        let forward = Vec3::new(-0.3, -0.4, -0.8).normalize();
        let orbit = OrbitControl::from_view(eye, forward, 2.5, 0.7);
        assert!((orbit.forward() - forward).length() < 1e-5);
        assert!((orbit.eye() - eye).length() < 1e-5);
        let cam = orbit.camera(100, 50);
        assert!((cam.ray(50.0, 25.0) - forward).length() < 1e-5);
        assert!((cam.vertical_fov() - 0.7).abs() < 1e-5);
    }
}
