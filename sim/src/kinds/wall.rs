//! Free-standing walls (`[[world.walls]]`).

use super::kind::{Kind, MapFeature, Surroundings};
use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use crate::shapes::{Solid, SolidShape};
use nalgebra::{Point2, Vector2};
use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};

/// A free-standing wall: a segment with thickness, height and colour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wall {
    /// One end of the wall's centre line.
    pub from_mm: [f64; 2],
    /// The other end of the wall's centre line.
    pub to_mm: [f64; 2],
    /// Thickness across the centre line.
    #[serde(default = "default_wall_thickness")]
    pub thickness_mm: f64,
    /// Height above the floor.
    #[serde(default = "default_wall_height")]
    pub height_mm: f64,
    /// Colour.
    #[serde(default = "default_wall_rgb")]
    pub rgb: Rgb,
}

fn default_wall_thickness() -> f64 {
    100.0
}
fn default_wall_height() -> f64 {
    150.0
}
fn default_wall_rgb() -> Rgb {
    Rgb([235, 235, 235])
}

impl Wall {
    /// The wall as a standing box on its centre line.
    pub fn solid(&self) -> Solid {
        let a = Vector2::from(self.from_mm);
        let b = Vector2::from(self.to_mm);
        let d = b - a;
        Solid::standing(
            SolidShape::Box {
                center_mm: Point2::from((a + b) / 2.0),
                half_extents_mm: Vector2::new(d.norm() / 2.0, self.thickness_mm / 2.0),
                angle_rad: d.y.atan2(d.x),
            },
            self.height_mm,
            self.rgb,
        )
    }
}

impl Kind for Wall {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        c.positive("thickness_mm", self.thickness_mm);
        c.positive("height_mm", self.height_mm);
        let len = ((self.to_mm[0] - self.from_mm[0]).powi(2)
            + (self.to_mm[1] - self.from_mm[1]).powi(2))
        .sqrt();
        if len.is_nan() || len <= 0.0 {
            c.fail("to_mm", "must differ from from_mm");
        }
    }

    fn solids(&self, _index: u32, out: &mut Vec<Solid>) {
        out.push(self.solid().as_object(ObjectId::of(Class::Wall)));
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        out.push(MapFeature::Segment {
            from_mm: Point2::from(self.from_mm),
            to_mm: Point2::from(self.to_mm),
            half_thickness_mm: 0.5 * self.thickness_mm,
        });
    }
}
