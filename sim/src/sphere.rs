//! Spheres in the scene: a ball on the floor or in the air, as the renderers see it.
//!
//! A sphere is what the renderers trace, not a solid of the physics: it has no footprint in
//! the plane and takes no part in clearance or free-space queries. The scene takes spheres
//! through [`crate::render::Scene::with_spheres`].

use crate::color::Rgb;
use crate::labels::ObjectId;

/// A sphere: its centre (x, y on the floor plane and the height of the centre above the
/// floor), radius, colour and what it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre: x, y (mm, world frame) and the height of the centre above the floor (mm).
    pub center_mm: [f64; 3],
    /// Radius (mm).
    pub radius_mm: f64,
    /// Surface colour.
    pub rgb: Rgb,
    /// What it is (its label in the truth beside a frame).
    pub object: ObjectId,
}
