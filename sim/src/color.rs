//! Colours of the world's surfaces.

use serde::{Deserialize, Serialize};

/// An 8-bit RGB colour, written `[r, g, b]` in scenario files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rgb(pub [u8; 3]);

impl Rgb {
    /// Components scaled to 0..1.
    pub fn to_unit(self) -> [f32; 3] {
        [
            self.0[0] as f32 / 255.0,
            self.0[1] as f32 / 255.0,
            self.0[2] as f32 / 255.0,
        ]
    }
}
