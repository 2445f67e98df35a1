//! The map's built-in scenes and cameras: each run's scenario is a scene, a camera's
//! `[[robot.sensors]]` table and the placements as `[experiment.ball_map]`.

use super::spec::BallMapSpec;

/// A camera of the map: its name in the tables and its `[[robot.sensors]]` table.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// Short name, in file names (`e1_256`).
    pub id: &'static str,
    /// Its name in the tables and the figure.
    pub title: &'static str,
    /// The sensor's TOML.
    pub sensor: &'static str,
}

/// E1's camera: the corner paper's hyperbolic mirror at 256 x 220.
pub const E1: Camera = Camera {
    id: "e1_256",
    title: "hyperbolic (E1)",
    sensor: include_str!("scenarios/e1_256.toml"),
};

/// The cameras of the replay, in the tables' order.
pub const CAMERAS: [Camera; 4] = [
    E1,
    Camera {
        id: "e1_512",
        title: "hyperbolic at 512 px",
        sensor: include_str!("scenarios/e1_512.toml"),
    },
    Camera {
        id: "conical",
        title: "conical (lower)",
        sensor: include_str!("scenarios/conical.toml"),
    },
    Camera {
        id: "spherical",
        title: "spherical",
        sensor: include_str!("scenarios/spherical.toml"),
    },
];

/// The scene of the map (robot, field, ball), without camera or placements.
pub const FIELD: &str = include_str!("scenarios/field.toml");

/// The ball-free scene, without camera or frame count.
pub const EMPTY: &str = include_str!("scenarios/empty.toml");

/// The robustness replay's ball scenario (file, text): E1's camera, the rings within 1 m.
pub const ROBUSTNESS: (&str, &str) = (
    "ball_map_robustness.toml",
    concat!(
        include_str!("scenarios/field.toml"),
        include_str!("scenarios/robustness.toml"),
        include_str!("scenarios/e1_256.toml")
    ),
);

/// A scenario's text: `scene` with `camera`'s sensor and `spec` as `[experiment.ball_map]`.
pub fn scenario_text(
    scene: &str,
    camera: &Camera,
    spec: &BallMapSpec,
) -> Result<String, toml::ser::Error> {
    let section = toml::to_string(spec)?;
    Ok(format!(
        "{scene}\n[experiment.ball_map]\n{section}{}",
        camera.sensor
    ))
}
