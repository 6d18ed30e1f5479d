//! Pictures of a room for people (8-bit sRGB images in memory; the front ends write them):
//!
//! - [`reflectance_panorama`]: the panorama from the probe centre, each pixel coloured by the
//!   reflectance of the patch it sees (sRGB of `rho`), hidden patches hatched, light patches
//!   pale yellow, face edges dark;
//! - [`reflectance_cutaway`]: the same colouring seen by a pinhole camera from anywhere (above
//!   the room, say), faces seen from behind skipped so the shell does not hide the inside: where
//!   the probe could not see shows as hatching;
//! - [`room_overlay`]: the model's face edges drawn over a tone-mapped picture of the probe, to
//!   check the reconstruction against the panorama.
//!
//! Hatching: diagonal stripes 8 pixels apart, 3 wide, at 45 % brightness, so the hidden patches'
//! (group) reflectance still shows between them.

use glam::Vec3;
use ibl_core::Image;
use ibl_scene::Camera;
use rayon::prelude::*;

use crate::Room;
use crate::depth_map::{NO_PATCH, ProbeDepthMap};
use crate::reflectance::{Estimate, PatchRole};

/// Colour of light-source patches.
const LIGHT_COLOUR: [u8; 3] = [255, 236, 150];
/// Colour where no patch is seen (an open model) or a back side is.
const NOTHING_COLOUR: [u8; 3] = [40, 0, 60];
/// Colour of face edges.
const EDGE_COLOUR: [u8; 3] = [20, 20, 20];

fn srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

fn patch_colour(estimate: &Estimate, patch: u32, x: usize, y: usize, shade: f32) -> [u8; 3] {
    if patch == NO_PATCH {
        return NOTHING_COLOUR;
    }
    let p = &estimate.patches[patch as usize];
    let base = match p.role {
        PatchRole::Light => return LIGHT_COLOUR,
        _ => p.reflectance.to_array().map(|c| srgb8(c * shade)),
    };
    let hatched = p.role == PatchRole::Hidden && (x + y) % 8 < 3;
    if hatched {
        base.map(|c| (f32::from(c) * 0.45) as u8)
    } else {
        base
    }
}

/// The panorama of patches coloured by reflectance, at the depth map's size.
pub fn reflectance_panorama(depth: &ProbeDepthMap, estimate: &Estimate) -> Image<[u8; 3]> {
    let (w, h) = (depth.width(), depth.height());
    Image::from_fn_par(w, h, |x, y| {
        let s = depth.sample(x, y);
        let edge = [(1i64, 0i64), (0, 1)].iter().any(|&(dx, dy)| {
            let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
            let yy = (y as i64 + dy).min(h as i64 - 1) as usize;
            depth.sample(xx, yy).face != s.face
        });
        if edge {
            EDGE_COLOUR
        } else {
            patch_colour(estimate, s.patch, x, y, 1.0)
        }
    })
}

/// The room seen by `camera` (any [`Camera`], e.g. a pinhole above the room looking down),
/// `width x height` pixels, patches coloured by reflectance and lightly shaded by their normal
/// so that faces stand apart; faces seen from behind are passed through.
pub fn reflectance_cutaway(
    room: &Room,
    estimate: &Estimate,
    camera: &Camera,
    width: u32,
    height: u32,
) -> Image<[u8; 3]> {
    let light = Vec3::new(0.3, 0.8, 0.5).normalize();
    let rows: Vec<Vec<[u8; 3]>> = (0..height as usize)
        .into_par_iter()
        .map(|y| {
            (0..width as usize)
                .map(|x| {
                    let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
                    let mut t0 = 0.0f32;
                    // Skip back sides (at most a few: the shell's walls and ceiling).
                    for _ in 0..16 {
                        match room.hit(ray.origin, ray.direction, t0, f32::INFINITY) {
                            Some(hit) if hit.front => {
                                let n = room.patches[hit.patch as usize].normal;
                                let shade = 0.8 + 0.2 * n.dot(light).abs();
                                return patch_colour(estimate, hit.patch, x, y, shade);
                            }
                            Some(hit) => t0 = hit.distance_m + 1e-4,
                            None => return [255, 255, 255],
                        }
                    }
                    [255, 255, 255]
                })
                .collect()
        })
        .collect();
    Image::from_vec(
        width as usize,
        height as usize,
        rows.into_iter().flatten().collect(),
    )
    .unwrap_or_else(|_| Image::filled(1, 1, [255, 255, 255]))
}

/// `picture` (a tone-mapped probe at the depth map's size) with the model's face edges drawn
/// over it in `colour`, two pixels wide.
pub fn room_overlay(
    depth: &ProbeDepthMap,
    picture: &Image<[u8; 3]>,
    colour: [u8; 3],
) -> Image<[u8; 3]> {
    let (w, h) = (depth.width(), depth.height());
    Image::from_fn_par(w, h, |x, y| {
        let s = depth.sample(x, y);
        let edge = [(1i64, 0i64), (0, 1), (-1, 0), (0, -1)]
            .iter()
            .any(|&(dx, dy)| {
                let xx = (x as i64 + dx).rem_euclid(w as i64) as usize;
                let yy = (y as i64 + dy).clamp(0, h as i64 - 1) as usize;
                depth.sample(xx, yy).face != s.face
            });
        if edge && picture.width() == w && picture.height() == h {
            colour
        } else if picture.width() == w && picture.height() == h {
            *picture.get(x, y)
        } else {
            NOTHING_COLOUR
        }
    })
}
