//! The distance fields the planner prices a grid by: from every cell's centre to the nearest
//! blocked cell's centre and to the nearest suspect cell's centre, by the exact Euclidean
//! distance transform of Felzenszwalb and Huttenlocher (by `imageproc`).
//!
//! The transform is the planner's largest cost (a fifth of a patrol's run time when each replan
//! transformed the grid anew), and between two replans the grid's blocked and suspect cells
//! mostly stay the same: [`DistanceFields::update`] transforms again only a state whose cells
//! changed. The fields are then those of a fresh transform, bit for bit.

use super::grid::{CellState, GridGeometry, OccupancyGrid};
use imageproc::distance_transform::euclidean_squared_distance_transform;
use imageproc::image::GrayImage;
use std::sync::Arc;

/// Each cell's distance to the nearest cell of one state, mm, row-major from the lower-left
/// cell; `None` when no cell is in that state.
pub type Field = Option<Arc<[f32]>>;

/// A cell's mark: in neither state, suspect, blocked.
const NONE: u8 = 0;
const SUSPECT: u8 = 1;
const BLOCKED: u8 = 2;

/// The distance fields of a grid, kept up to date by [`Self::update`].
#[derive(Debug, Clone, Default)]
pub struct DistanceFields {
    /// The grid the fields were made for, and each cell's mark then.
    geometry: Option<GridGeometry>,
    marks: Vec<u8>,
    blocked_mm: Field,
    suspect_mm: Field,
}

impl DistanceFields {
    /// The fields of `grid`.
    pub fn of(grid: &OccupancyGrid) -> Self {
        let mut fields = Self::default();
        fields.update(grid);
        fields
    }

    /// Brings the fields up to `grid`: a state's field is transformed again when one of its
    /// cells changed since the last update (or the grid is another one).
    pub fn update(&mut self, grid: &OccupancyGrid) {
        let g = *grid.geometry();
        let fresh = self.geometry != Some(g);
        if fresh {
            self.geometry = Some(g);
            self.marks = vec![NONE; g.len()];
        }
        let (mut blocked_moved, mut suspect_moved) = (fresh, fresh);
        for (mark, state) in self.marks.iter_mut().zip(grid.states()) {
            let now = match state {
                CellState::Blocked => BLOCKED,
                CellState::Suspect => SUSPECT,
                CellState::Free | CellState::Unknown => NONE,
            };
            if *mark != now {
                blocked_moved |= (*mark == BLOCKED) != (now == BLOCKED);
                suspect_moved |= (*mark == SUSPECT) != (now == SUSPECT);
                *mark = now;
            }
        }
        if blocked_moved {
            self.blocked_mm = transform(&g, &self.marks, BLOCKED);
        }
        if suspect_moved {
            self.suspect_mm = transform(&g, &self.marks, SUSPECT);
        }
    }

    /// Each cell's distance to the nearest blocked cell, mm (`None`: there is none).
    pub fn blocked_mm(&self) -> &Field {
        &self.blocked_mm
    }

    /// Each cell's distance to the nearest suspect cell, mm (`None`: there is none).
    pub fn suspect_mm(&self) -> &Field {
        &self.suspect_mm
    }
}

/// The distance from every cell's centre to the nearest centre of a cell marked `mark`, mm;
/// `None` when no cell is (no transform then).
fn transform(g: &GridGeometry, marks: &[u8], mark: u8) -> Field {
    let mut marked = GrayImage::new(g.width as u32, g.height as u32);
    let mut any = false;
    for (px, &m) in marked.pixels_mut().zip(marks) {
        if m == mark {
            px.0[0] = 255;
            any = true;
        }
    }
    let cell2 = (g.cell_mm * g.cell_mm) as f32;
    any.then(|| {
        euclidean_squared_distance_transform(&marked)
            .as_raw()
            .iter()
            .map(|&d2| (d2 as f32 * cell2).sqrt())
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{MapSegment, WorldMap};
    use crate::navigation::config::PlannerConfig;
    use nalgebra::Point2;

    fn grid_with_wall(x_mm: f64) -> OccupancyGrid {
        let g =
            GridGeometry::covering(Point2::new(-500.0, -500.0), Point2::new(500.0, 500.0), 20.0);
        let map = WorldMap {
            bounds: vec![MapSegment {
                from_mm: Point2::new(x_mm, -400.0),
                to_mm: Point2::new(x_mm, 400.0),
                half_thickness_mm: 10.0,
            }],
            ..WorldMap::default()
        };
        OccupancyGrid::new(g, &map, &PlannerConfig::default())
    }

    #[test]
    fn kept_fields_follow_the_grid_and_equal_a_fresh_transform() {
        let (near, far) = (grid_with_wall(100.0), grid_with_wall(-300.0));
        let mut kept = DistanceFields::of(&near);
        let wall = kept.blocked_mm().clone().unwrap();
        assert!(kept.suspect_mm().is_none());
        // Unchanged, the field is the one already made; changed, it is made again.
        kept.update(&near);
        assert!(Arc::ptr_eq(&wall, kept.blocked_mm().as_ref().unwrap()));
        kept.update(&far);
        let moved = kept.blocked_mm().clone().unwrap();
        assert!(!Arc::ptr_eq(&wall, &moved));
        let fresh = DistanceFields::of(&far);
        let bits = |f: &[f32]| f.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&moved), bits(fresh.blocked_mm().as_ref().unwrap()));
        // A cell at the wall is at 0, one 400 mm off it (20 cells) at 400 mm.
        let g = *far.geometry();
        let at = |x: f64| moved[g.cell_of(Point2::new(x, 0.0)).unwrap()];
        assert_eq!(at(-300.0), 0.0);
        assert!((at(100.0) - 400.0).abs() <= 20.0, "{}", at(100.0));
    }
}
