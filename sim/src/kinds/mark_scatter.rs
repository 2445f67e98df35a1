//! Marks scattered at random over a rectangle of the floor (`[world.mark_scatter]`).

use super::kind::Kind;
use crate::floor_marks::FloorMark;
pub use crate::floor_marks::MarkScatter;

impl Kind for MarkScatter {
    fn floor_marks(&self, out: &mut Vec<FloorMark>) {
        out.extend(self.marks());
    }
}
