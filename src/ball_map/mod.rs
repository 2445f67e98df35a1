//! `omniloop replay ball_map`: the ball detector's error map. For each camera (E1's hyperbolic
//! mirror at 256 x 220 and at 512 x 512, the conical and the spherical mirror of the render
//! examples) on E1's robot body at the centre of an open Small-Size field, the ball is put at
//! rings of distances from 150 mm to 3 m all round the robot, several frames each with the
//! camera's noise, and `vision::ball::detect_mirror` is scored against the truth: detected or
//! not (and why), range and bearing error, with the frames the body hides counted apart. Then
//! ball-free frames of E1's camera at random poses count the false balls. Outputs:
//! `ball_map.md`, `ball_map.csv` (a row a frame), `ball_map.png` and `summary.json`.
//!
//! The map is also an experiment (`[experiment.ball_map]`, [`experiment::ENTRY`]), which the
//! robustness replay runs for its ball estimator ([`ROBUSTNESS`]).

pub mod experiment;
pub mod measure;
pub mod replay;
pub mod report;
pub mod scenes;
pub mod spec;
pub mod stats;

pub use experiment::ENTRY;
pub use replay::REPLAY;
pub use scenes::{CAMERAS, Camera, E1, EMPTY, FIELD, ROBUSTNESS, scenario_text};
pub use spec::BallMapSpec;
pub use stats::{BallMapMetrics, CameraMap, FalseBalls};
