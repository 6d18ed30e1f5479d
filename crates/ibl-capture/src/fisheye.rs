//! Stitching the two equidistant fisheye images of a 360-degree camera into one lat-long map.
//!
//! **Lenses** (CONVENTIONS section 3): each image holds one equidistant circle inscribed in a
//! square, `r = alpha / (fov / 2)` with `alpha` the angle from the optical axis. The front lens
//! looks forward (-Z, image right = +X, up = +Y); the back lens looks backward (+Z, image right
//! = -X, up = +Y), i.e. it is the front lens turned by `Ry(180 degrees)`. A real back lens is
//! a little off that ideal: [`FisheyeOptions::back_rotation`] gives its error `E` in its own
//! frame (yaw about its up, pitch about its right, roll about its optical axis, CONVENTIONS
//! section 1's `Ry Rx Rz`), so `world_from_back = Ry(180) E`. A single dual-fisheye frame (2:1,
//! the front circle on the left, the back on the right, as consumer cameras write it) is split
//! into its two square halves.
//!
//! **Resampling.** Each lens goes through `ibl_mapping::resample` (Fisheye -> LatLong with its
//! `world_from_lens`; energy-conserving area averaging, 0 where the lens sees nothing). This
//! does not use `Mapping::DualFisheye` directly because that fixes the back lens at its ideal
//! pose and feathers over the whole overlap.
//!
//! **Blending.** For a texel with centre direction `d`, `beta_f` and `beta_b` are its angles
//! (degrees) from the front and the back lens axes, and `s = (beta_b - beta_f) / 2` its angle
//! from the seam (exactly `90 - beta_f` when the axes are opposite). The front weight is
//! `w_f = smoothstep(s / blend + 1/2)` (a C1 ramp over `blend_deg` centred on the seam, a hard
//! cut for `blend_deg = 0`), `w_b = 1 - w_f`; a lens' weight is 0 beyond its half field of view
//! and the two are renormalised, so every direction is counted once. Requiring
//! `blend_deg <= fov - 180` keeps the feather inside the overlap of ideal lenses.
//!
//! **Coverage.** Two lenses of field of view `fov` with axes `180 - tilt` degrees apart (`tilt`
//! is the angle between the back axis and +Z) leave no gap iff `tilt <= fov - 180`; larger
//! rotations are refused.
//!
//! Cost: two resamplings to the output size (O(W H k^2) each, see `ibl_mapping::resample`) plus
//! O(W H) for the blend; rows in parallel, deterministic.

use glam::{DVec3, Mat3};
use ibl_core::{EulerDegrees, Image, LatLong, Rgb};
use ibl_mapping::{Mapping, resample};

use crate::CaptureError;
use crate::ball::smoothstep;

/// How to stitch a fisheye pair (see the module note).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FisheyeOptions {
    /// Field of view of each lens, degrees, in (180, 360] (consumer cameras: about 195).
    pub fov_deg: f32,
    /// The back lens' deviation from its ideal pose (looking +Z), in its own frame, degrees:
    /// `world_from_back = Ry(180) Ry(yaw) Rx(pitch) Rz(roll)`.
    pub back_rotation: EulerDegrees,
    /// Width of the lat-long output, pixels (the output is `2 s x s`, `s = width / 2`).
    pub width: usize,
    /// Width of the feathered seam, degrees, in [0, fov - 180].
    pub blend_deg: f32,
}

impl Default for FisheyeOptions {
    /// 195-degree lenses, ideal back lens, 2048 x 1024 output, 10-degree seam.
    fn default() -> Self {
        FisheyeOptions {
            fov_deg: 195.0,
            back_rotation: EulerDegrees::default(),
            width: 2048,
            blend_deg: 10.0,
        }
    }
}

/// Stitches a front and a back fisheye image (each square, same size), or with `back = None` a
/// single dual-fisheye frame `front` (2:1, front circle left, back circle right), into a
/// `2 s x s` lat-long map (`s = options.width / 2`) with a feathered seam (module note).
/// Errors: [`CaptureError::Parameter`] for a field of view outside (180, 360], a seam width
/// outside [0, fov - 180], a non-finite rotation or one that tilts the back lens by more than
/// `fov - 180` degrees, or a width under 2; [`CaptureError::Invalid`] for images that are not
/// square and equal (a pair) or not 2:1 (a dual frame). Cost O(W H k^2) (module note).
pub fn stitch_fisheye_pair(
    front: &Image<Rgb>,
    back: Option<&Image<Rgb>>,
    options: FisheyeOptions,
) -> Result<Image<Rgb>, CaptureError> {
    let FisheyeOptions {
        fov_deg,
        back_rotation,
        width,
        blend_deg,
    } = options;
    if !(fov_deg > 180.0 && fov_deg <= 360.0) {
        return Err(CaptureError::Parameter(format!(
            "each lens of a fisheye pair must see more than 180 degrees (up to 360) to cover the \
             sphere, got {fov_deg}"
        )));
    }
    let overlap = fov_deg - 180.0;
    if !(blend_deg >= 0.0 && blend_deg <= overlap) {
        return Err(CaptureError::Parameter(format!(
            "the seam width must be in [0, {overlap}] degrees (the lenses' overlap) for a \
             {fov_deg}-degree field of view, got {blend_deg}"
        )));
    }
    if width < 2 {
        return Err(CaptureError::Parameter(format!(
            "the lat-long width must be at least 2, got {width}"
        )));
    }
    let EulerDegrees {
        yaw_deg,
        pitch_deg,
        roll_deg,
    } = back_rotation;
    if !(yaw_deg.is_finite() && pitch_deg.is_finite() && roll_deg.is_finite()) {
        return Err(CaptureError::Parameter(format!(
            "the back lens rotation must be finite, got ({yaw_deg}, {pitch_deg}, {roll_deg})"
        )));
    }
    let world_from_back =
        Mat3::from_rotation_y(std::f32::consts::PI) * back_rotation.world_from_probe();
    let back_axis = (world_from_back * glam::Vec3::NEG_Z).as_dvec3().normalize();
    let tilt = back_axis.z.clamp(-1.0, 1.0).acos().to_degrees();
    if tilt > f64::from(overlap) {
        return Err(CaptureError::Parameter(format!(
            "the back lens rotation tilts its axis by {tilt:.1} degrees; lenses of {fov_deg} \
             degrees leave a gap beyond {overlap} degrees"
        )));
    }
    let halves;
    let (front_img, back_img) = match back {
        Some(b) => {
            let (w, h) = (front.width(), front.height());
            if w != h || w == 0 || (b.width(), b.height()) != (w, h) {
                return Err(CaptureError::Invalid(format!(
                    "a fisheye pair needs two square images of the same size, got {w} x {h} and \
                     {} x {}",
                    b.width(),
                    b.height()
                )));
            }
            (front, b)
        }
        None => {
            let (w, h) = (front.width(), front.height());
            if w != 2 * h || h == 0 {
                return Err(CaptureError::Invalid(format!(
                    "a dual-fisheye frame must be 2:1 (two square halves), got {w} x {h}"
                )));
            }
            let half = |x0: usize| Image::from_fn_par(h, h, |i, j| *front.get(x0 + i, j));
            halves = (half(0), half(h));
            (&halves.0, &halves.1)
        }
    };
    let lens = Mapping::Fisheye { fov_deg };
    let (w, h) = Mapping::LatLong.size_for_width(width);
    let to_latlong = |img: &Image<Rgb>, world_from_lens: Mat3| {
        resample(
            img,
            lens,
            Mapping::LatLong,
            w,
            h,
            world_from_lens,
            &|_, _| {},
        )
        .map_err(|e| CaptureError::Parameter(e.to_string()))
    };
    let front_ll = to_latlong(front_img, Mat3::IDENTITY)?;
    let back_ll = to_latlong(back_img, world_from_back)?;
    let ll = LatLong::new(w, h);
    let half_fov = f64::from(fov_deg) / 2.0;
    let blend = f64::from(blend_deg);
    let angle = |d: DVec3, axis: DVec3| d.dot(axis).clamp(-1.0, 1.0).acos().to_degrees();
    Ok(Image::from_fn_par(w, h, |i, j| {
        let d = ll.pixel_dir64(i, j);
        let beta_f = angle(d, DVec3::NEG_Z);
        let beta_b = angle(d, back_axis);
        let s = 0.5 * (beta_b - beta_f);
        let ramp = if blend > 0.0 {
            smoothstep(s / blend + 0.5)
        } else if s >= 0.0 {
            1.0
        } else {
            0.0
        };
        let wf = if beta_f <= half_fov { ramp } else { 0.0 };
        let wb = if beta_b <= half_fov { 1.0 - ramp } else { 0.0 };
        let total = wf + wb;
        if total > 0.0 {
            *front_ll.get(i, j) * (wf / total) as f32 + *back_ll.get(i, j) * (wb / total) as f32
        } else {
            Rgb::ZERO
        }
    }))
}
