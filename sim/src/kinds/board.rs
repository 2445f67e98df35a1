//! Striped boards (`[[world.boards]]`): flat upright boards carrying vertical stripes, the
//! marks a robot knows by name.

use super::kind::{Kind, MapFeature, Stripes, Surroundings};
use crate::color::Rgb;
use crate::labels::{Class, ObjectId};
use crate::shapes::{Solid, SolidShape};
use nalgebra::{Point2, Vector2};
use omniloop_problem::Problems;
use omniloop_vision::resection::StripePattern;
use serde::{Deserialize, Serialize};

/// A flat upright board carrying vertical stripes (a landmark), e.g. the marks of the
/// three-mark resection paper: black and white stripes with given width ratios.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Board {
    /// What the board is called (the mark's name, `P`), if anything.
    #[serde(default)]
    pub name: Option<String>,
    /// One end of the board.
    pub from_mm: [f64; 2],
    /// The other end.
    pub to_mm: [f64; 2],
    /// Height of its lower edge above the floor.
    #[serde(default)]
    pub bottom_mm: f64,
    /// Height of its upper edge above the floor.
    pub top_mm: f64,
    /// Thickness.
    #[serde(default = "default_board_thickness")]
    pub thickness_mm: f64,
    /// Relative widths of the stripes from `from_mm` to `to_mm`, alternating `rgb_a`, `rgb_b`.
    pub stripes: Vec<f64>,
    /// Colour of the first, third, ... stripe.
    #[serde(default = "default_board_a")]
    pub rgb_a: Rgb,
    /// Colour of the second, fourth, ... stripe.
    #[serde(default = "default_board_b")]
    pub rgb_b: Rgb,
}

fn default_board_thickness() -> f64 {
    10.0
}
fn default_board_a() -> Rgb {
    Rgb([15, 15, 15])
}
fn default_board_b() -> Rgb {
    Rgb([245, 245, 245])
}

impl Board {
    /// Cumulative stripe boundaries as fractions of the board's length, ending at 1.
    pub fn stripe_edges(&self) -> Vec<f64> {
        let total: f64 = self.stripes.iter().sum();
        let mut acc = 0.0;
        self.stripes
            .iter()
            .map(|w| {
                acc += w;
                acc / total
            })
            .collect()
    }
}

impl Kind for Board {
    /// A named board is named once in the world, and its stripes make a mark.
    fn check(&self, earlier: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        let Some(name) = &self.name else { return };
        if earlier.iter().filter_map(|b| b.name.as_ref()).any(|n| n == name) {
            c.fail("name", format!("{name:?} names two boards"));
        }
        if let Err(e) = StripePattern::new(name, &self.stripes).validate() {
            c.fail("stripes", format!("mark {name:?}: {e}"));
        }
    }

    fn solids(&self, index: u32, out: &mut Vec<Solid>) {
        let a = Vector2::from(self.from_mm);
        let e = Vector2::from(self.to_mm);
        let d = e - a;
        out.push(Solid {
            shape: SolidShape::Box {
                center_mm: Point2::from((a + e) / 2.0),
                half_extents_mm: Vector2::new(d.norm() / 2.0, self.thickness_mm / 2.0),
                angle_rad: d.y.atan2(d.x),
            },
            base_mm: self.bottom_mm,
            height_mm: self.top_mm,
            rgb: self.rgb_a,
            top_rgb: None,
            board: Some(index as usize),
            object: ObjectId::new(Class::Board, index),
        });
    }

    fn stripes(&self, out: &mut Vec<Stripes>) {
        out.push(Stripes {
            edges: self.stripe_edges(),
            rgb_a: self.rgb_a,
            rgb_b: self.rgb_b,
        });
    }

    fn map(&self, out: &mut Vec<MapFeature>) {
        let (from, to) = (Point2::from(self.from_mm), Point2::from(self.to_mm));
        out.push(MapFeature::Segment {
            from_mm: from,
            to_mm: to,
            half_thickness_mm: 0.5 * self.thickness_mm,
        });
        if let Some(name) = &self.name {
            out.push(MapFeature::Mark {
                name: name.clone(),
                centre_mm: nalgebra::center(&from, &to),
                stripes: self.stripes.clone(),
            });
        }
    }
}
