//! Extra rectangles of floor colour (`[[world.floor_rects]]`), adding to the floor region.

use super::kind::{Kind, Surroundings};
pub use crate::floor_rect::FloorRect;
use omniloop_problem::Problems;

impl Kind for FloorRect {
    fn check(&self, _: &[Self], _: &dyn Surroundings, c: &mut Problems) {
        c.positive("size_mm", self.size_mm[0]);
        c.positive("size_mm", self.size_mm[1]);
    }

    fn floor_rects(&self, out: &mut Vec<FloorRect>) {
        out.push(self.clone());
    }
}
