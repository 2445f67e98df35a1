//! Marks painted on the floor one by one (`[[world.floor_marks]]`).

use super::kind::Kind;
pub use crate::floor_marks::FloorMark;

impl Kind for FloorMark {
    fn floor_marks(&self, out: &mut Vec<FloorMark>) {
        out.push(self.clone());
    }
}
