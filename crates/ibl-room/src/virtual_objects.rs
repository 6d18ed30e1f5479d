//! Virtual objects in the room (Grosch 2005, section 4.1): objects the user inserts, lit by the
//! room's light and shadowing it, composited into the probe.
//!
//! Grosch's two displays of the object:
//!
//! - **Fast** ([`DisplayMode::Fast`]): the object is shaded by the irradiance volume's first value,
//!   the irradiance from *all* directions ([`crate::irradiance_volume`], trilinear with the
//!   visibility-aware weights), `L = rho E_all(x, n) / pi`. Nothing on the object is shadowed
//!   but what the volume's interpolation carries.
//! - **Improved** ([`DisplayMode::Improved`]): the volume's second value, the *unimportant* light
//!   alone, plus the direct light of every important patch ([`crate::important`]) recomputed at
//!   the point with shadows: `L = rho (E_unimportant(x, n) + sum_i E_i(x, n)) / pi`, where a
//!   patch's light is blocked by the room (real on virtual) and by the objects themselves.
//!
//! In both, the objects' **shadows on the real surfaces** subtract what they take from the
//! important patches (the paper's `dL_i = rho E_i / pi`, `L'_pixel = L_pixel - dL_i`): at a real
//! point `x` of patch `p`, `rho_p / pi` times the part of each `E_i(x)` that reaches `x` through
//! the room but not past the objects (the difference of the two shadow images of \[GM00\]).
//! Grosch stores `dL_i` at patch vertices; here it is evaluated at each displayed point, so the
//! shadow is as sharp as the picture.
//!
//! **Beyond the paper: the objects' effect on the unimportant light** (improved display only).
//! The volume was gathered without the objects, so it cannot know that a sphere's underside faces
//! a floor the sphere itself darkens, or that the floor at its foot no longer sees the walls
//! behind it. The improved display corrects both by a *differential gather*: `K` cosine-
//! distributed rays from the point (`occlusion_rays`; `E = (pi / K) sum L`) add `(pi / K) sum
//! (L_with - L_without)` over the unimportant light (from a real point, whose change comes only
//! from rays that meet an object, the rays fill the cone of the objects' bounding sphere
//! instead, each weighted `cos W / K` for the cone's solid angle `W`), where a ray that meets an object brings the
//! object's radiance instead of the room's (the object as the fast display shades it, which
//! ends the recursion), and a ray from an object that meets the room brings the room's radiance
//! less the objects' shadow on it, that shadow's own unimportant part gathered the same way (a
//! sphere's underside faces floor the sphere hides from the rest of the room; one level deep:
//! the inner gather's rays do not look for shadows again). Rays that meet an important patch are left out: that light is
//! recomputed with its own shadow rays. On the validation's sphere (`tests/virtual_objects.rs`)
//! this takes the relative MSE over the sphere and its neighbourhood from the fast display's 6.7 %
//! to 0.72 % (`docs/ROOMS.md` section 13).
//!
//! **New lights** ([`ObjectDisplay::with_lamps`], section 4.2) light the objects by EQ5 through
//! shadow rays (the room and the objects block them), and the objects' shadow of their light is
//! subtracted from the room like the important patches'; their light on the room comes with the
//! room's radiance field ([`RoomRadiance::with_added_light`]), and so does its bounce in the
//! volume.
//!
//! **Mirrors** reflect the room: a mirror's radiance is its reflectance times the room's radiance
//! along the reflected ray ([`RoomRadiance`], the probe's texture where it saw; the paper's
//! floating-point reflection map), less the objects' shadow where that ray lands (a mirror sphere
//! shows the dark floor under itself). A glossy material is shaded as its diffuse part plus its
//! specular reflectance times that mirror image (the lobe's width is not blurred in).
//!
//! **An important patch as a light** is `s x s` stratified points over its area, each radiating
//! `L A / s^2` with `dE = L (A / s^2) cos(t_l) cos(t_r) / max(r^2, A / s^2)` to a receiver at
//! distance `r` (the clamp keeps a receiver within one cell of the patch finite: it bounds the
//! cell's solid angle by about `pi`), one shadow ray per point: soft shadows from the patch's
//! extent.
//!
//! **The picture** is the probe re-rendered from its own centre ([`ObjectDisplay::panorama`]),
//! `n x n` rays per pixel: a ray that meets an object first takes the object's radiance, one that
//! meets the room takes the probe pixel's radiance minus the objects' shadow at its point. From a
//! moved camera ([`ObjectDisplay::view`], section 4.4) a ray that meets the room takes the room's
//! radiance field there instead (the probe's texture where it saw, the fill where it did not),
//! minus the same shadow.
//! World frame, metres; radiance in the probe's units.

use glam::Vec3;
use ibl_core::{Image, LatLong, Rgb};
use ibl_light::GoniometricLight;
use ibl_scene::{Camera, GeometryLayer, Material, Ray, SurfacePoint};
use ibl_sh::{LeakControl, VolumeLayer};

use crate::important::ImportantLights;
use crate::irradiance_volume::{KeyPointVisibility, RoomVolume};
use crate::novel_view::{HoleFill, MAX_VIEW_PIXELS};
use crate::room_radiance::RoomRadiance;
use crate::{Room, RoomError};

/// Rays leave a surface this far along its normal and stop this far before a light point,
/// metres (as the form factors' offset).
const RAY_OFFSET_M: f32 = 1e-4;

/// Most rays (or light points) per pixel (or patch) side accepted.
pub const MAX_SAMPLES_PER_AXIS: u32 = 8;

/// Which of Grosch's two displays shades the objects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DisplayMode {
    /// The volume's total irradiance, no recomputed light (the paper's fast display).
    Fast,
    /// The volume's unimportant irradiance plus the important patches recomputed with shadows.
    Improved,
}

/// How the objects are displayed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectDisplaySettings {
    /// Fast or improved.
    pub mode: DisplayMode,
    /// Points per important patch side (`s x s` light points, each with a shadow ray).
    pub light_samples_per_axis: u32,
    /// Rays per pixel side.
    pub samples_per_axis: u32,
    /// Cosine-distributed rays of the improved display's differential gather (0: none, the
    /// paper's improved display).
    pub occlusion_rays: u32,
}

/// Most rays of the differential gather accepted.
pub const MAX_OCCLUSION_RAYS: u32 = 1024;

impl Default for ObjectDisplaySettings {
    /// The improved display, 2 x 2 points per important patch, 2 x 2 rays per pixel, 32 rays of
    /// differential gather.
    fn default() -> Self {
        ObjectDisplaySettings {
            mode: DisplayMode::Improved,
            light_samples_per_axis: 2,
            samples_per_axis: 2,
            occlusion_rays: 32,
        }
    }
}

/// One point of an important patch.
#[derive(Clone, Copy, Debug)]
struct LightPoint {
    position: Vec3,
    /// The patch's front normal.
    normal: Vec3,
    /// `L A / s^2`: radiance times the point's share of the area.
    power: Rgb,
    /// `A / s^2`, m^2: the least squared distance counted (module doc).
    cell_m2: f32,
}

/// What one light point gives a receiver.
#[derive(Clone, Copy, Debug, Default)]
struct ImportantLight {
    /// Irradiance reaching the point (through the room and past the objects).
    open: Rgb,
    /// Irradiance the room lets through but the objects block.
    blocked_by_objects: Rgb,
}

impl ImportantLight {
    /// Adds `e` where [`ObjectDisplay::objects_block`] says it goes (nothing for `None`).
    fn add(&mut self, objects_block: Option<bool>, e: Rgb) {
        match objects_block {
            Some(true) => self.blocked_by_objects += e,
            Some(false) => self.open += e,
            None => {}
        }
    }
}

/// The room with virtual objects, ready to be displayed.
pub struct ObjectDisplay<'a> {
    room: &'a Room,
    radiance: &'a RoomRadiance<'a>,
    volume: &'a RoomVolume,
    reflectance: &'a [Rgb],
    objects: &'a GeometryLayer,
    settings: ObjectDisplaySettings,
    light_points: Vec<LightPoint>,
    /// Per patch, whether it is an important light.
    important: Vec<bool>,
    /// A sphere around every object (centre, radius; metres): rays and segments that miss it
    /// cannot meet an object, so the room's points far from the objects cost a few tests only.
    bound: Option<(Vec3, f32)>,
    /// New goniometric lights (section 4.2) lighting the objects, shadowed by them.
    lamps: &'a [GoniometricLight],
}

/// Whether the segment `origin + t direction`, `0 <= t <= t_max` (unit `direction`), passes
/// through the sphere `(centre, radius)`.
fn segment_meets_sphere(origin: Vec3, direction: Vec3, t_max: f32, (c, r): (Vec3, f32)) -> bool {
    let t = (c - origin).dot(direction).clamp(0.0, t_max);
    (origin + direction * t - c).length_squared() <= r * r
}

/// A picture with objects: the radiance and, per pixel, the fraction of rays that met an object.
#[derive(Clone, Debug)]
pub struct ObjectPicture {
    /// Radiance, probe units.
    pub image: Image<Rgb>,
    /// Fraction of each pixel's rays that met an object.
    pub coverage: Image<f32>,
}

impl ObjectPicture {
    /// A `w x h` picture of `n x n` rays per pixel: `ray(i, j, a, b, unimportant)` is pixel
    /// `(i, j)`'s ray `(a, b)`, its radiance and whether it met an object (`None`: black, no
    /// object); `unimportant` is the cache of the unimportant shadow the pixel's rays share.
    fn supersampled(
        w: usize,
        h: usize,
        n: u32,
        ray: impl Fn(usize, usize, u32, u32, &mut Option<Rgb>) -> Option<(Rgb, bool)> + Sync,
    ) -> ObjectPicture {
        let pixels = Image::from_fn_par(w, h, |i, j| {
            let (mut sum, mut hits) = (Rgb::ZERO, 0u32);
            let mut unimportant = None;
            for b in 0..n {
                for a in 0..n {
                    if let Some((l, object)) = ray(i, j, a, b, &mut unimportant) {
                        sum += l;
                        hits += u32::from(object);
                    }
                }
            }
            let k = (n * n) as f32;
            (sum / k, hits as f32 / k)
        });
        ObjectPicture {
            image: pixels.map(|p| p.0),
            coverage: pixels.map(|p| p.1),
        }
    }
}

impl<'a> ObjectDisplay<'a> {
    /// The objects `objects` in the room of `radiance` (its probe texture and estimate), lit by
    /// `volume` (built for the same room with `important`'s patches) and `important`'s patches;
    /// `reflectance` per patch (the estimate's) for the shadows on real surfaces.
    pub fn new(
        radiance: &'a RoomRadiance<'a>,
        volume: &'a RoomVolume,
        important: &ImportantLights,
        reflectance: &'a [Rgb],
        objects: &'a GeometryLayer,
        settings: ObjectDisplaySettings,
    ) -> Result<ObjectDisplay<'a>, RoomError> {
        let room = radiance.room();
        if reflectance.len() != room.patches.len() {
            return Err(RoomError::Parameter(format!(
                "{} reflectances for a room of {} patches",
                reflectance.len(),
                room.patches.len()
            )));
        }
        for (name, n) in [
            ("light_samples_per_axis", settings.light_samples_per_axis),
            ("samples_per_axis", settings.samples_per_axis),
        ] {
            if !(1..=MAX_SAMPLES_PER_AXIS).contains(&n) {
                return Err(RoomError::Parameter(format!(
                    "{name} {n} (1 to {MAX_SAMPLES_PER_AXIS})"
                )));
            }
        }
        if settings.occlusion_rays > MAX_OCCLUSION_RAYS {
            return Err(RoomError::Parameter(format!(
                "occlusion_rays {} (at most {MAX_OCCLUSION_RAYS})",
                settings.occlusion_rays
            )));
        }
        let s = settings.light_samples_per_axis;
        let inv = 1.0 / s as f32;
        let mut light_points = Vec::new();
        for light in &important.important {
            let Some(patch) = room.patches.get(light.patch as usize) else {
                return Err(RoomError::Parameter(format!(
                    "important patch {} is not in the room",
                    light.patch
                )));
            };
            let cell_m2 = patch.area_m2 * inv * inv;
            let power = Rgb::from_array(light.radiance) * cell_m2;
            for i in 0..s {
                for j in 0..s {
                    light_points.push(LightPoint {
                        position: patch
                            .shape
                            .point((i as f32 + 0.5) * inv, (j as f32 + 0.5) * inv),
                        normal: patch.normal,
                        power,
                        cell_m2,
                    });
                }
            }
        }
        Ok(ObjectDisplay {
            room,
            radiance,
            volume,
            reflectance,
            objects,
            settings,
            light_points,
            important: crate::irradiance_volume::important_mask(room.patches.len(), important),
            bound: objects
                .bvh
                .bounds()
                .map(|(min, max)| ((min + max) * 0.5, (max - min).length() * 0.5 + RAY_OFFSET_M)),
            lamps: &[],
        })
    }

    /// The same display with the new lights `lamps` (section 4.2; the field and the volume it
    /// was made with should carry their light on the room, [`RoomRadiance::with_added_light`]):
    /// their direct light (EQ5) lights the objects through shadow rays, and the objects' shadow
    /// of it is subtracted from the room.
    pub fn with_lamps(mut self, lamps: &'a [GoniometricLight]) -> ObjectDisplay<'a> {
        self.lamps = lamps;
        self
    }

    /// Whether the segment from `origin` to a light at `target` is blocked by the objects
    /// (`Some(true)`) or open (`Some(false)`); `None` when the room blocks it or its ends are
    /// within two offsets of each other. With `blocked_only` a segment that misses the objects'
    /// bounding sphere is `None` untested (only the objects' part is asked for).
    fn objects_block(&self, origin: Vec3, target: Vec3, blocked_only: bool) -> Option<bool> {
        let to = target - origin;
        let distance = to.length();
        if distance <= 2.0 * RAY_OFFSET_M {
            return None;
        }
        let direction = to / distance;
        let t_max = distance - RAY_OFFSET_M;
        let near_objects = self
            .bound
            .is_some_and(|b| segment_meets_sphere(origin, direction, t_max, b));
        if blocked_only && !near_objects {
            return None;
        }
        if self.room.occluded(origin, direction, 0.0, t_max) {
            return None;
        }
        Some(
            near_objects
                && self
                    .objects
                    .bvh
                    .occluded(&Ray::new(origin, direction), 0.0, t_max),
        )
    }

    /// The new lights' direct light at `x` (unit normal `n`, rays from `origin`), split into what
    /// arrives and what only the objects block; with `blocked_only` as [`Self::objects_block`].
    fn lamp_light(&self, x: Vec3, n: Vec3, origin: Vec3, blocked_only: bool) -> ImportantLight {
        let mut sum = ImportantLight::default();
        for lamp in self.lamps {
            let e = lamp.irradiance_at(x, n);
            if e.max_channel() <= 0.0 {
                continue;
            }
            sum.add(self.objects_block(origin, lamp.position, blocked_only), e);
        }
        sum
    }

    /// The important patches' light at `x` (unit normal `n`, rays from `origin` just above the
    /// surface), split into what arrives and what only the objects block; with `blocked_only`
    /// as [`Self::objects_block`].
    fn important_light(
        &self,
        x: Vec3,
        n: Vec3,
        origin: Vec3,
        blocked_only: bool,
    ) -> ImportantLight {
        let mut sum = ImportantLight::default();
        for p in &self.light_points {
            let to = p.position - x;
            let r2 = to.length_squared();
            if r2 <= 0.0 {
                continue;
            }
            let w = to / r2.sqrt();
            let (cos_r, cos_l) = (n.dot(w), -p.normal.dot(w));
            if cos_r <= 0.0 || cos_l <= 0.0 {
                continue;
            }
            // dE = L (A / s^2) cos cos / max(r^2, A / s^2).
            let e = p.power * (cos_r * cos_l / r2.max(p.cell_m2));
            sum.add(self.objects_block(origin, p.position, blocked_only), e);
        }
        sum
    }

    /// The volume's irradiance of `layer` at `x` for normal `n` (visibility-aware weights; the
    /// plain valid-corner weights where every corner is hidden; 0 where none is valid).
    fn volume_irradiance(&self, x: Vec3, n: Vec3, layer: VolumeLayer) -> Rgb {
        let leak = LeakControl::Facing(n);
        let sample = |visibility| self.volume.sample(self.room, x, layer, leak, visibility);
        sample(KeyPointVisibility::Unoccluded)
            .or_else(|| sample(KeyPointVisibility::Any))
            .map_or(Rgb::ZERO, |p| {
                Rgb::from_array(p.irradiance(n)).map(|v| v.max(0.0))
            })
    }

    /// The differential gather at `x` (unit normal `n`, rays from `origin`): `sum (L_with -
    /// L_without) w_k` of the unimportant light over `K` rays (module doc): cosine-distributed
    /// over the hemisphere from an object (`from_object`; then rays that meet the room bring its
    /// radiance less the objects' shadow there), uniform in the objects' bounding cone from the
    /// room. The rays are a fixed stratified set turned by an angle hashed from `x`, so
    /// neighbouring points do not share their errors.
    fn unimportant_change(&self, x: Vec3, n: Vec3, origin: Vec3, from_object: bool) -> Rgb {
        let k = self.settings.occlusion_rays;
        if k == 0 {
            return Rgb::ZERO;
        }
        let turn = hash_angle(x);
        // From the room only rays that meet an object change anything: they are drawn in the
        // cone of the objects' bounding sphere (uniform in its solid angle `W`, each weighted
        // `cos W / K`) rather than over the hemisphere (`pi / K`), so that an object far away
        // is met by every ray of the cone instead of by one ray in a hundred.
        let cone = match self.bound {
            Some((c, r)) if !from_object => {
                let to = c - origin;
                let d = to.length();
                (d > r).then(|| (to / d, (1.0 - (r / d).powi(2)).max(0.0).sqrt()))
            }
            _ => None,
        };
        let (axis, cos_max) = cone.unwrap_or((n, 0.0));
        let (t, b) = ibl_scene::primitives::tangents(axis);
        let mut sum = Rgb::ZERO;
        for i in 0..k {
            // Hammersley point (i + 1/2) / K and the radical inverse of i, turned per point.
            let u1 = (i as f32 + 0.5) / k as f32;
            let u2 = (i.reverse_bits() as f32 / 4_294_967_296.0 + turn).fract();
            let phi = std::f32::consts::TAU * u2;
            let (w, weight) = match cone {
                // Uniform in the cone: cos theta = 1 - u1 (1 - cos_max).
                Some(_) => {
                    let cos = 1.0 - u1 * (1.0 - cos_max);
                    let sin = (1.0 - cos * cos).max(0.0).sqrt();
                    let w =
                        (t * (sin * phi.cos()) + b * (sin * phi.sin()) + axis * cos).normalize();
                    let solid_angle = std::f32::consts::TAU * (1.0 - cos_max);
                    (w, n.dot(w).max(0.0) * solid_angle / k as f32)
                }
                // Cosine-distributed over the hemisphere.
                None => {
                    let r = u1.sqrt();
                    let w = (t * (r * phi.cos()) + b * (r * phi.sin()) + axis * (1.0 - u1).sqrt())
                        .normalize();
                    (w, std::f32::consts::PI / k as f32)
                }
            };
            if weight <= 0.0 {
                continue;
            }
            if !from_object
                && !self
                    .bound
                    .is_some_and(|bound| segment_meets_sphere(origin, w, f32::INFINITY, bound))
            {
                continue;
            }
            let room_hit = self.room.hit(origin, w, 0.0, f32::INFINITY);
            let limit = room_hit.map_or(f32::INFINITY, |h| h.distance_m);
            let object = self
                .objects
                .bvh
                .closest_hit(&Ray::new(origin, w), 0.0, limit);
            // The room's unimportant radiance along the ray without the objects.
            let without = match room_hit {
                Some(h) if h.front && !self.important[h.patch as usize] => {
                    let point = origin + w * h.distance_m;
                    Some((self.radiance.at(point, h.patch as usize).0, h.patch, point))
                }
                _ => None,
            };
            match (object, without) {
                (Some(hit), without) => {
                    let surface = self.objects.surface_point(&hit, w);
                    let seen = self.fast_object_radiance(&surface, -w);
                    sum += (seen - without.map_or(Rgb::ZERO, |(l, _, _)| l)) * weight;
                }
                (None, Some((_, patch, point))) if from_object => {
                    sum = sum - self.shadow_loss(patch as usize, point, true) * weight;
                }
                _ => {}
            }
        }
        sum
    }

    /// Radiance leaving an object's surface point `surface` towards `wo` (unit, away from it),
    /// in the settings' display mode.
    fn object_radiance(&self, surface: &SurfacePoint, wo: Vec3) -> Rgb {
        self.shade_object(surface, wo, self.settings.mode)
    }

    /// The same in the fast display: what the room sees of an object in the differential gather.
    fn fast_object_radiance(&self, surface: &SurfacePoint, wo: Vec3) -> Rgb {
        self.shade_object(surface, wo, DisplayMode::Fast)
    }

    fn shade_object(&self, surface: &SurfacePoint, wo: Vec3, mode: DisplayMode) -> Rgb {
        let n = surface.shading_normal;
        let origin = surface.position + surface.geometric_normal * RAY_OFFSET_M;
        let albedo = surface.material.diffuse_albedo();
        let diffuse = if albedo.max_channel() > 0.0 {
            let e = match mode {
                DisplayMode::Fast => self.volume_irradiance(origin, n, VolumeLayer::AllLight),
                DisplayMode::Improved => {
                    (self.volume_irradiance(origin, n, VolumeLayer::UnimportantLight)
                        + self.unimportant_change(surface.position, n, origin, true))
                    .map(|v| v.max(0.0))
                        + self
                            .important_light(surface.position, n, origin, false)
                            .open
                }
            } + self.lamp_light(surface.position, n, origin, false).open;
            albedo * e / std::f32::consts::PI
        } else {
            Rgb::ZERO
        };
        let specular = match surface.material {
            Material::Diffuse { .. } => Rgb::ZERO,
            Material::Mirror { reflectance } => reflectance,
            Material::Glossy { specular, .. } => specular,
        };
        if specular.max_channel() <= 0.0 {
            return diffuse;
        }
        // The room along the mirror direction, with the objects' shadow on it (the improved
        // display's with its unimportant part); another object is not reflected.
        let r = (2.0 * n.dot(wo) * n - wo).normalize();
        let reflected = self
            .radiance
            .along(origin, r, 0.0)
            .map_or(Rgb::ZERO, |hit| {
                let point = origin + r * hit.distance_m;
                let gather = mode == DisplayMode::Improved;
                (hit.radiance - self.shadow_loss(hit.patch as usize, point, gather))
                    .map(|v| v.max(0.0))
            });
        diffuse + specular * reflected
    }

    /// The radiance the objects' shadow takes from real point `x` of patch `patch`: the
    /// important light they block and, with `gather` (the improved display's), what they change
    /// of the unimportant light there.
    fn shadow_loss(&self, patch: usize, x: Vec3, gather: bool) -> Rgb {
        let rho = self.reflectance[patch].map(|v| v.clamp(0.0, 1.0));
        if rho.max_channel() <= 0.0 {
            return Rgb::ZERO;
        }
        let n = self.room.patches[patch].normal;
        let origin = x + n * RAY_OFFSET_M;
        let lost = self.important_light(x, n, origin, true).blocked_by_objects
            + self.lamp_light(x, n, origin, true).blocked_by_objects;
        let loss = rho * lost / std::f32::consts::PI;
        if gather {
            loss + self.unimportant_shadow(patch, x)
        } else {
            loss
        }
    }

    /// The unimportant part of [`Self::shadow_loss`]: `-rho / pi` times the differential gather.
    fn unimportant_shadow(&self, patch: usize, x: Vec3) -> Rgb {
        let rho = self.reflectance[patch].map(|v| v.clamp(0.0, 1.0));
        if rho.max_channel() <= 0.0 {
            return Rgb::ZERO;
        }
        let n = self.room.patches[patch].normal;
        let change = self.unimportant_change(x, n, x + n * RAY_OFFSET_M, false);
        rho * change * (-1.0 / std::f32::consts::PI)
    }

    /// The radiance along one unit ray `origin + t direction`, and whether it met an object.
    /// A ray that meets the room takes `observed` there when given (the probe pixel, for rays
    /// from the probe's centre), else the room's radiance field at the point (textured by
    /// `fill` where the probe did not see it, as a novel view), less the objects' shadow.
    /// `unimportant` caches, per pixel, the improved display's unimportant part of the shadow at
    /// the first real point one of its rays meets: that part is smooth (it comes from the whole
    /// cone of the objects), so the pixel's other rays reuse it; the important part, which makes
    /// the sharp edges, is evaluated at every ray's point.
    fn trace(
        &self,
        origin: Vec3,
        direction: Vec3,
        observed: Option<Rgb>,
        fill: HoleFill,
        unimportant: &mut Option<Rgb>,
    ) -> Option<(Rgb, bool)> {
        let real = self.room.hit(origin, direction, 0.0, f32::INFINITY);
        let limit = real.map_or(f32::INFINITY, |h| h.distance_m);
        let ray = Ray::new(origin, direction);
        if let Some(hit) = self.objects.bvh.closest_hit(&ray, 0.0, limit) {
            let surface = self.objects.surface_point(&hit, direction);
            return Some((self.object_radiance(&surface, -direction), true));
        }
        let h = real.filter(|h| h.front)?;
        let x = origin + direction * h.distance_m;
        let patch = h.patch as usize;
        let radiance = match observed {
            Some(l) => l,
            None => {
                let (l, seen) = self.radiance.at(x, patch);
                match (seen, fill) {
                    (false, HoleFill::Textured(texture)) => {
                        l * texture.modulation(self.room.patches[patch].face as usize, x)
                    }
                    _ => l,
                }
            }
        };
        let mut loss = self.shadow_loss(patch, x, false);
        if self.settings.mode == DisplayMode::Improved {
            loss += *unimportant.get_or_insert_with(|| self.unimportant_shadow(patch, x));
        }
        Some(((radiance - loss).map(|v| v.max(0.0)), false))
    }

    /// The room with the objects through `camera` (a moved camera of section 4.4, or any
    /// camera inside the room) at `width x height`, `samples_per_axis^2` rays per pixel; the
    /// surfaces the probe did not see filled by `fill`, rays that meet nothing black.
    pub fn view(
        &self,
        camera: &Camera,
        width: u32,
        height: u32,
        fill: HoleFill,
    ) -> Result<ObjectPicture, RoomError> {
        let (w, h) = (width as usize, height as usize);
        if w == 0 || h == 0 || w.saturating_mul(h) > MAX_VIEW_PIXELS {
            return Err(RoomError::Parameter(format!(
                "a {width} x {height} view is empty or more than {MAX_VIEW_PIXELS} pixels"
            )));
        }
        let n = self.settings.samples_per_axis;
        Ok(ObjectPicture::supersampled(
            w,
            h,
            n,
            |i, j, a, b, unimportant| {
                let x = i as f32 + (a as f32 + 0.5) / n as f32;
                let y = j as f32 + (b as f32 + 0.5) / n as f32;
                let ray = camera.ray(x, y, width, height);
                self.trace(ray.origin, ray.direction, None, fill, unimportant)
            },
        ))
    }

    /// The probe (`probe`, lat-long, its pixels the room as the probe saw it) re-rendered with
    /// the objects from the probe's centre, `samples_per_axis^2` rays per pixel.
    pub fn panorama(&self, probe: &Image<Rgb>) -> Result<ObjectPicture, RoomError> {
        let (w, h) = (probe.width(), probe.height());
        if w == 0 || h == 0 {
            return Err(RoomError::Parameter("the probe is empty".into()));
        }
        let n = self.settings.samples_per_axis;
        Ok(ObjectPicture::supersampled(
            w,
            h,
            n,
            |i, j, a, b, unimportant| {
                let observed = *probe.get(i, j);
                let u = (i as f64 + (f64::from(a) + 0.5) / f64::from(n)) / w as f64;
                let v = (j as f64 + (f64::from(b) + 0.5) / f64::from(n)) / h as f64;
                let d = self.room.world_from_probe * LatLong::uv_to_dir(u, v);
                let traced = self.trace(
                    self.room.probe_position,
                    d.normalize(),
                    Some(observed),
                    HoleFill::Estimate,
                    unimportant,
                );
                Some(traced.unwrap_or((observed, false)))
            },
        ))
    }
}

/// A turn in [0, 1) from a point's coordinates (a 32-bit integer hash of its bits).
fn hash_angle(x: Vec3) -> f32 {
    let mut h: u32 = 0x9e37_79b9;
    for v in x.to_array() {
        h ^= v.to_bits();
        h = h.wrapping_mul(0x85eb_ca6b);
        h ^= h >> 13;
        h = h.wrapping_mul(0xc2b2_ae35);
        h ^= h >> 16;
    }
    h as f32 / 4_294_967_296.0
}
