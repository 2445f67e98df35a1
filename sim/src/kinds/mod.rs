//! The kinds of things on the floor: each is a scenario entry type with its own file here, and
//! one line of the registry below. That line declares the kind's module, gives [`Layout`] the
//! kind's field (`[world.KEY]` or `[[world.KEY]]`) and makes every system reach it through
//! [`Kind`]: the scenario's checks, the physics world's solids, the renderer's primitives and
//! their truth classes, the floor region and its paint, the top view and MCAP (drawn from the
//! solids), reachability and the map the robot is told. No system names a kind.
//!
//! A kind made of existing primitives (boxes, quad prisms, cylinders on the floor) is a file
//! with its entry type and its `impl Kind`, plus its registry line.

pub mod kind;

pub use kind::{FieldLines, Kind, KindVisitor, MapFeature, Stripes, Surroundings, entry_path};

/// The registry: each line declares the kind's module and gives `Layout` its field, in the
/// order the systems go through the kinds.
macro_rules! things_on_the_floor {
    ($($(#[$doc:meta])* $key:ident: $holder:ident<$module:ident::$kind:ident>,)*) => {
        $(pub mod $module;)*

        /// The world as plain data: the floor's colours and the things on the floor, one field
        /// a kind. Scenario files embed it as `[world]`.
        #[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(deny_unknown_fields, default)]
        pub struct Layout {
            /// Colour of the floor region (field green).
            pub floor_rgb: crate::color::Rgb,
            /// Colour of the floor outside the floor region.
            pub outside_rgb: crate::color::Rgb,
            /// Colour of the field's white lines.
            pub line_rgb: crate::color::Rgb,
            $($(#[$doc])* pub $key: $holder<$module::$kind>,)*
        }

        impl Default for Layout {
            fn default() -> Self {
                Self {
                    floor_rgb: crate::color::Rgb([30, 130, 55]),
                    outside_rgb: crate::color::Rgb([120, 100, 80]),
                    line_rgb: crate::color::Rgb([240, 240, 240]),
                    $($key: Default::default(),)*
                }
            }
        }

        impl Layout {
            /// Goes through every kind of the registry in its order, with its entries.
            pub fn visit_kinds(&self, visitor: &mut impl KindVisitor) {
                $(visitor.visit::<$module::$kind>(
                    concat!("world.", stringify!($key)),
                    stringify!($holder) == "Vec",
                    self.$key.as_slice(),
                );)*
            }
        }
    };
}

things_on_the_floor! {
    /// Corridors: floor and walls from a centre polyline and a width (`[[world.corridors]]`).
    corridors: Vec<corridor::Corridor>,
    /// The RoboCup Small-Size field, when present (`[world.field]`).
    field: Option<field::FieldSpec>,
    /// Extra rectangles of floor colour (`[[world.floor_rects]]`). With no floor rectangle of
    /// any kind the whole plane is floor.
    floor_rects: Vec<floor_rect::FloorRect>,
    /// Free-standing walls (`[[world.walls]]`).
    walls: Vec<wall::Wall>,
    /// Cubes (`[[world.cubes]]`).
    cubes: Vec<cube::Cube>,
    /// Pillars (`[[world.pillars]]`).
    pillars: Vec<pillar::Pillar>,
    /// Striped boards, the landmarks (`[[world.boards]]`).
    boards: Vec<board::Board>,
    /// Marks painted on the floor (`[[world.floor_marks]]`).
    floor_marks: Vec<floor_mark::FloorMark>,
    /// Marks scattered at random over a rectangle of the floor (`[world.mark_scatter]`).
    mark_scatter: Option<mark_scatter::MarkScatter>,
    /// The ball (`[world.ball]`), when there is one.
    ball: Option<ball::BallSpec>,
}
