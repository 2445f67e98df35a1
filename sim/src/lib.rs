//! omniloop-sim: the simulated side of omniloop. A rapier2d world holds the RoboCup
//! Small-Size field (or any floor of walls, cubes and pillars) and acceleration-limited
//! omnidirectional robots.

pub mod calibration;
pub mod color;
pub mod floor_marks;
pub mod floor_rect;
pub mod game;
pub mod kicker;
pub mod kinds;
pub mod labels;
pub mod layout;
pub mod optics;
pub mod reachability;
pub mod render;
pub mod sensor;
pub mod shapes;
pub mod sphere;
pub mod world;

// The kinds' modules under their old paths too.
pub use kinds::{ball, corridor};

pub use ball::{BallSpec, BallState};
pub use color::Rgb;
pub use corridor::Corridor;
pub use floor_marks::{FloorMark, MarkScatter, MarkShape};
pub use floor_rect::FloorRect;
pub use game::{BallEvent, BallFigures, GoalSide, Release};
pub use kicker::{BallCommand, Kick, KickerSpec};
pub use kinds::board::Board;
pub use kinds::cube::Cube;
pub use kinds::field::{FieldPreset, FieldSpec};
pub use kinds::pillar::Pillar;
pub use kinds::wall::Wall;
pub use kinds::{FieldLines, Kind, KindVisitor, MapFeature, Stripes, Surroundings};
pub use layout::Layout;
pub use reachability::{Reachability, Target, reachability};
pub use render::{
    CameraEffects, FrameNoise, FrameRequest, RenderError, Renderer, RendererChoice, Scene,
    SensorNoise,
};
pub use sensor::{Sensor, SensorSpec};
pub use shapes::{Solid, SolidShape};
pub use sphere::Sphere;
pub use world::{ContactsByClass, RobotBodySpec, RobotState, RobotStats, World};

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A world or sensor description that cannot be built.
    #[error("invalid world: {0}")]
    Invalid(String),
}
