//! Cubes standing on the floor (`[[world.cubes]]`): obstacles a robot could push away, so its
//! map knows them as boxes.

use super::kind::{Kind, MapFeature, Surroundings};
use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use crate::shapes::{Solid, SolidShape};
use nalgebra::{Point2, Rotation2, Vector2};
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// A cube standing on the floor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cube {
    /// Centre of its footprint.
    pub center_mm: [f64; 2],
    /// Side length.
    #[serde(default = "default_cube_size")]
    pub size_mm: f64,
    /// Rotation about the vertical axis.
    #[serde(default)]
    pub angle_deg: f64,
    /// Colour.
    #[serde(default = "default_cube_rgb")]
    pub rgb: Rgb,
}

fn default_cube_size() -> f64 {
    130.0
}
fn default_cube_rgb() -> Rgb {
    Rgb([40, 40, 40])
}

impl Cube {
    /// Its footprint's corners, counter-clockwise.
    pub fn corners_mm(&self) -> [Point2<f64>; 4] {
        let (h, a) = (0.5 * self.size_mm, self.angle_deg.to_radians());
        let c = Point2::from(self.center_mm);
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(sx, sy)| c + Rotation2::new(a) * Vector2::new(sx * h, sy * h))
    }
}

impl Kind for Cube {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        c.positive("size_mm", self.size_mm);
    }

    fn solids(&self, index: u32, out: &mut Vec<Solid>) {
        let cube = Solid::standing(
            SolidShape::Box {
                center_mm: Point2::from(self.center_mm),
                half_extents_mm: Vector2::new(self.size_mm / 2.0, self.size_mm / 2.0),
                angle_rad: self.angle_deg.to_radians(),
            },
            self.size_mm,
            self.rgb,
        );
        out.push(cube.as_object(ObjectId::new(Class::Cube, index)));
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        let c = self.corners_mm();
        out.extend((0..4).map(|k| MapFeature::BoxEdge {
            from_mm: c[k],
            to_mm: c[(k + 1) % 4],
        }));
    }
}
