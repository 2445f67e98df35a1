//! Marks painted on the floor: squares and discs of their own colour (the dark marks a forward
//! camera tracks for visual odometry), given one by one or scattered over an area at random.

use crate::color::Rgb;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

/// The outline of a floor mark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MarkShape {
    /// A square `size_mm` on a side.
    #[default]
    Square,
    /// A disc `size_mm` across.
    Disc,
}

/// A mark painted on the floor (`[[world.floor_marks]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FloorMark {
    /// Centre.
    pub center_mm: [f64; 2],
    /// Side of a square, diameter of a disc.
    pub size_mm: f64,
    /// Its outline.
    #[serde(default)]
    pub shape: MarkShape,
    /// Rotation of a square from the world axes.
    #[serde(default)]
    pub angle_deg: f64,
    /// Colour.
    #[serde(default = "default_mark_rgb")]
    pub rgb: Rgb,
}

fn default_mark_rgb() -> Rgb {
    Rgb([35, 35, 40])
}

/// Marks scattered at random over a rectangle (`[world.mark_scatter]`): squares and discs in
/// equal numbers on average, sizes uniform in a range, at uniform positions and angles, from a
/// seed of their own (the layout does not change with the run's seed).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkScatter {
    /// The rectangle: x min, y min, x max, y max.
    pub area_mm: [f64; 4],
    /// Marks per square metre.
    pub per_m2: f64,
    /// Smallest and largest size.
    #[serde(default = "default_sizes")]
    pub size_mm: [f64; 2],
    /// Colour of every mark.
    #[serde(default = "default_mark_rgb")]
    pub rgb: Rgb,
    /// Seed of the positions.
    #[serde(default)]
    pub seed: u64,
}

fn default_sizes() -> [f64; 2] {
    [20.0, 60.0]
}

impl MarkScatter {
    /// The marks: `per_m2` times the area (rounded), drawn from the seed.
    pub fn marks(&self) -> Vec<FloorMark> {
        let [x0, y0, x1, y1] = self.area_mm;
        let area_m2 = ((x1 - x0) * (y1 - y0)).abs() * 1e-6;
        let n = (self.per_m2 * area_m2).round().max(0.0) as usize;
        let mut rng = StdRng::seed_from_u64(self.seed);
        (0..n)
            .map(|_| {
                let x = x0 + (x1 - x0) * rng.random::<f64>();
                let y = y0 + (y1 - y0) * rng.random::<f64>();
                let size =
                    self.size_mm[0] + (self.size_mm[1] - self.size_mm[0]) * rng.random::<f64>();
                let shape = if rng.random::<bool>() {
                    MarkShape::Square
                } else {
                    MarkShape::Disc
                };
                FloorMark {
                    center_mm: [x, y],
                    size_mm: size,
                    shape,
                    angle_deg: 90.0 * rng.random::<f64>(),
                    rgb: self.rgb,
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scatter_has_its_density_and_sizes_and_is_the_same_from_the_same_seed() {
        let s = MarkScatter {
            area_mm: [-1000.0, -1000.0, 1000.0, 1000.0],
            per_m2: 5.0,
            size_mm: [20.0, 60.0],
            rgb: default_mark_rgb(),
            seed: 3,
        };
        let m = s.marks();
        assert_eq!(m.len(), 20);
        assert!(m.iter().all(|k| (20.0..=60.0).contains(&k.size_mm)));
        assert!(m.iter().all(|k| k.center_mm[0].abs() <= 1000.0));
        assert!(m.iter().any(|k| k.shape == MarkShape::Disc));
        assert!(m.iter().any(|k| k.shape == MarkShape::Square));
        assert_eq!(m, s.marks());
        assert_ne!(m, MarkScatter { seed: 4, ..s }.marks());
    }
}
