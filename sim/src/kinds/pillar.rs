//! Pillars (`[[world.pillars]]`): upright cylinders, the landmarks a robot knows by colour.

use super::kind::{Kind, MapFeature, Surroundings};
use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use crate::shapes::{Solid, SolidShape};
use nalgebra::Point2;
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// An upright cylinder standing on the floor (a pillar, a post).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pillar {
    /// Centre of its footprint.
    pub center_mm: [f64; 2],
    /// Radius.
    pub radius_mm: f64,
    /// Height above the floor.
    pub height_mm: f64,
    /// Colour.
    pub rgb: Rgb,
}

impl Kind for Pillar {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        c.positive("radius_mm", self.radius_mm);
        c.positive("height_mm", self.height_mm);
    }

    fn solids(&self, index: u32, out: &mut Vec<Solid>) {
        let pillar = Solid::standing(
            SolidShape::Cylinder {
                center_mm: Point2::from(self.center_mm),
                radius_mm: self.radius_mm,
            },
            self.height_mm,
            self.rgb,
        );
        out.push(pillar.as_object(ObjectId::new(Class::Pillar, index)));
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        out.push(MapFeature::Landmark {
            centre_mm: Point2::from(self.center_mm),
            radius_mm: self.radius_mm,
            rgb: self.rgb,
        });
    }
}
