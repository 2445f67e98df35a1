//! The knobs of the robustness replay: what each one sets in a scenario, and at which levels.
//! A new knob is one more entry in [`KNOBS`].

use crate::experiments::registry::takes_frames;
use crate::scenario::Scenario;
use toml::Value;

/// One way the world, the camera or the timing departs from the ideal.
pub struct Knob {
    /// Short name (`noise`), the column of `robustness.csv`.
    pub name: &'static str,
    /// What the level measures, with its unit (`noise sigma, grey levels`).
    pub label: &'static str,
    /// The level's unit, short (`px`; empty for a count of grey levels).
    pub unit: &'static str,
    /// The levels tried, the first the gentlest (the scenario's own value or none).
    pub levels: &'static [f64],
    /// The scenario keys and their values at `level`.
    pub values: fn(&Scenario, f64) -> Vec<(String, Value)>,
    /// Why the knob cannot reach the scenario's estimator (`None`: it can). Where the rules
    /// refuse a value (a mirror mounting on a pinhole camera), the refusal says why instead.
    pub not_applicable: fn(&Scenario) -> Option<&'static str>,
}

/// Every knob, in the order of the tables.
pub const KNOBS: &[Knob] = &[
    Knob {
        name: "noise",
        label: "noise sigma, grey levels",
        unit: "",
        levels: &[2.0, 4.0, 8.0, 12.0, 16.0],
        values: |s, v| every_sensor(s, "noise_sigma", Value::Float(v)),
        not_applicable: always,
    },
    Knob {
        name: "defocus",
        label: "defocus sigma, px",
        unit: "px",
        levels: &[0.0, 0.5, 1.0, 1.5, 2.0],
        values: |s, v| every_sensor(s, "effects.defocus_px", Value::Float(v)),
        not_applicable: always,
    },
    Knob {
        name: "exposure",
        label: "exposure, ms",
        unit: "ms",
        levels: &[0.0, 5.0, 10.0, 15.0, 20.0],
        values: |s, v| every_sensor(s, "effects.exposure_s", Value::Float(v / 1000.0)),
        not_applicable: always,
    },
    Knob {
        name: "tilt",
        label: "mirror tilt, degrees",
        unit: "deg",
        levels: &[0.0, 0.5, 1.0, 1.5, 2.0],
        values: |s, v| every_sensor(s, "mounting.mirror_tilt_deg", Value::Float(v)),
        not_applicable: always,
    },
    Knob {
        name: "offset",
        label: "mirror offset along x, mm",
        unit: "mm",
        levels: &[0.0, 0.5, 1.0, 1.5, 2.0],
        values: |s, v| {
            let xyz = [v, 0.0, 0.0].map(Value::Float).to_vec();
            every_sensor(s, "mounting.mirror_offset_mm", Value::Array(xyz))
        },
        not_applicable: always,
    },
    Knob {
        name: "latency",
        label: "frame latency, ms",
        unit: "ms",
        levels: &[0.0, 30.0, 60.0, 90.0, 120.0],
        values: |_, v| timing("frame_latency_s", v / 1000.0),
        not_applicable: frames_taken_by_experiment,
    },
    Knob {
        name: "drop",
        label: "frames dropped, %",
        unit: "%",
        levels: &[0.0, 10.0, 20.0, 30.0],
        values: |_, v| timing("frame_drop_rate", v / 100.0),
        not_applicable: frames_taken_by_experiment,
    },
];

/// The knob called `name`.
pub fn knob(name: &str) -> Option<&'static Knob> {
    KNOBS.iter().find(|k| k.name == name)
}

/// `robot.sensors[i].KEY = value` for every sensor of the scenario: the camera's knobs change
/// all its sensors alike (both mirrors of an omnistereo pair).
fn every_sensor(s: &Scenario, key: &str, value: Value) -> Vec<(String, Value)> {
    (0..s.robot.sensors.len())
        .map(|i| (format!("robot.sensors[{i}].{key}"), value.clone()))
        .collect()
}

/// `robot.timing.KEY = value`.
fn timing(key: &str, value: f64) -> Vec<(String, Value)> {
    vec![(format!("robot.timing.{key}"), Value::Float(value))]
}

/// Applies to every scenario.
fn always(_: &Scenario) -> Option<&'static str> {
    None
}

/// Timing reaches the estimators that get their frames from the loop, not an experiment that
/// renders its own at placed poses.
fn frames_taken_by_experiment(s: &Scenario) -> Option<&'static str> {
    takes_frames(s).then_some(
        "the experiment renders its own frames at placed poses, outside the loop's timing",
    )
}
