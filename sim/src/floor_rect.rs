//! Rectangles of floor colour: the floor region of corridors and rooms.

use nalgebra::Point2;
use serde::{Deserialize, Serialize};

/// A rectangle of floor colour (for floors other than the field, e.g. corridors).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorRect {
    /// Centre of the rectangle.
    pub center_mm: [f64; 2],
    /// Full side lengths along its own x and y axes.
    pub size_mm: [f64; 2],
    /// Rotation of its x axis from the world x axis.
    #[serde(default)]
    pub angle_deg: f64,
}

impl FloorRect {
    /// Does the rectangle contain `p` (boundary included)?
    pub fn contains(&self, p: Point2<f64>) -> bool {
        let (s, c) = self.angle_deg.to_radians().sin_cos();
        let d = p - Point2::from(self.center_mm);
        let lx = c * d.x + s * d.y;
        let ly = -s * d.x + c * d.y;
        lx.abs() <= self.size_mm[0] / 2.0 && ly.abs() <= self.size_mm[1] / 2.0
    }
}
