//! How the light types' triples appear in serialised data: as arrays `[r, g, b]` and
//! `[x, y, z]` (CONVENTIONS section 7), not as the `{ "r": .. }` maps a derive would write. Used
//! through `#[serde(with = "...")]` on the fields.

/// [`ibl_core::Rgb`] as `[r, g, b]` (f32).
pub mod rgb {
    use ibl_core::Rgb;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `[r, g, b]`.
    pub fn serialize<S: Serializer>(v: &Rgb, s: S) -> Result<S::Ok, S::Error> {
        v.to_array().serialize(s)
    }

    /// Reads `[r, g, b]`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Rgb, D::Error> {
        <[f32; 3]>::deserialize(d).map(Rgb::from_array)
    }
}

/// [`ibl_core::rgb::Rgb64`] as `[r, g, b]` (f64).
pub mod rgb64 {
    use ibl_core::rgb::Rgb64;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `[r, g, b]`.
    pub fn serialize<S: Serializer>(v: &Rgb64, s: S) -> Result<S::Ok, S::Error> {
        v.to_array().serialize(s)
    }

    /// Reads `[r, g, b]`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Rgb64, D::Error> {
        <[f64; 3]>::deserialize(d).map(Rgb64::from_array)
    }
}

/// [`glam::DVec3`] as `[x, y, z]`.
pub mod dvec3 {
    use glam::DVec3;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// Writes `[x, y, z]`.
    pub fn serialize<S: Serializer>(v: &DVec3, s: S) -> Result<S::Ok, S::Error> {
        v.to_array().serialize(s)
    }

    /// Reads `[x, y, z]`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<DVec3, D::Error> {
        <[f64; 3]>::deserialize(d).map(DVec3::from_array)
    }
}
