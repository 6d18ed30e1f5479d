//! Scenes for iblkit (Grosch 2005 section 4; Debevec 1998): what is real and what is virtual, in
//! the world frame of `docs/CONVENTIONS.md` (+Y up, -Z forward, +X right).
//!
//! - [`description`]: the scene file format (TOML, versioned; room files included), validated
//!   field by field.
//! - [`scene`]: a scene ready to render: real and virtual layers (geometry, BVH, shading and patch
//!   attributes), probe, background, camera.
//! - [`camera`]: panorama (the probe seen from its centre) and pinhole cameras.
//! - [`primitives`]: planes, boxes and spheres as meshes.
//! - [`mesh`]: indexed triangle meshes with material groups, validation and placement.
//! - [`material`]: diffuse, glossy (Lambert + normalised Phong) and mirror surfaces.
//! - [`patch`]: per-triangle radiosity attributes (reflectance, outgoing radiance).
//! - [`polygon`]: planar polygons in their own frame (signed area, frame, simplicity).
//! - [`ray`]: rays and hits.
//! - [`bvh`]: a binned-SAH bounding volume hierarchy over triangles (closest hit, any hit).
//!
//! This crate does no I/O: `ibl-io` reads scene files and meshes into these types.

pub mod bvh;
pub mod camera;
pub mod description;
pub mod material;
pub mod mesh;
pub mod patch;
pub mod polygon;
pub mod primitives;
pub mod ray;
pub mod scene;

pub use bvh::Bvh;
pub use camera::Camera;
pub use description::{
    AmbientBands, DescriptionError, FORMAT_VERSION, RenderMode, SamplerKind, SceneDescription,
    ShadowKind,
};
pub use material::Material;
pub use mesh::{MeshError, TriangleMesh};
pub use patch::PatchAttributes;
pub use ray::{Hit, Ray};
pub use scene::{
    Background, GeometryLayer, LayerError, MeshAsset, PlacedMesh, Probe, Scene, SurfacePoint,
    SurfaceTriangle, virtual_layer,
};
