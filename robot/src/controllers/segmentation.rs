//! A forward camera's ground segmentation avoidance (Ahmed, Saatchi and Caparrelli,
//! Sect. 2.1.1), with the settings it shares with the flow avoidance (`[control.forward]`).

use crate::boundary::BodyCommand;
use crate::controller::{ControlTable, Controller, ControllerEntry, Situation, parses, settings};
use crate::perception::GroundReading;
use crate::perception::forward::needs_forward_camera;
use serde::{Deserialize, Serialize};

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "segmentation",
    summary: "a forward camera's ground segmentation: straight while the ground ahead reaches \
              far enough, else turn to the clearer side (Ahmed et al., Sect. 2.1.1)",
    tables: &[ControlTable {
        name: "forward",
        check: |spec| parses::<ForwardDriveConfig>(spec, "forward"),
    }],
    needs_goal: false,
    stages: &[crate::perception::forward::GROUND_NAME],
    check_use: needs_forward_camera,
    build: |c| {
        Ok(Box::new(Segmentation {
            drive: settings(c, "forward")?,
            turning: None,
        }))
    },
};

/// How the forward camera's avoidance drives (`[control.forward]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ForwardDriveConfig {
    /// Speed straight ahead, mm/s.
    pub speed_mm_s: f64,
    /// Rate of the turns on the spot, deg/s.
    pub turn_rate_deg_s: f64,
    /// Segmentation: once turning, go on until this many ground pixels more than needed lie
    /// ahead (so the robot does not stop turning at the first clear column).
    pub hysteresis_px: u32,
    /// Optical flow: how long one turn away from the stronger flow lasts, s.
    pub flow_turn_s: f64,
    /// Optical flow: frames after a turn whose flow is not read (it is the turn's own).
    pub flow_settle_frames: u32,
}

impl Default for ForwardDriveConfig {
    fn default() -> Self {
        Self {
            speed_mm_s: 150.0,
            turn_rate_deg_s: 60.0,
            hysteresis_px: 6,
            flow_turn_s: 0.75,
            flow_settle_frames: 2,
        }
    }
}

/// Sect. 2.1.1: straight while the ground ahead is clear; else turn on the spot toward the
/// side with more ground, and keep turning that way until the ground ahead reaches
/// `hysteresis_px` beyond what is needed (the paper says nothing of how long a turn lasts).
pub struct Segmentation {
    drive: ForwardDriveConfig,
    turning: Option<f64>,
}

impl Controller for Segmentation {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let Some(g) = s.percept::<GroundReading>() else {
            return BodyCommand::STOP;
        };
        let enough = match self.turning {
            Some(_) => g.ahead_px > g.needed_px + self.drive.hysteresis_px,
            None => g.clear_ahead(),
        };
        if enough {
            self.turning = None;
            return BodyCommand::forward(self.drive.speed_mm_s);
        }
        let side = *self
            .turning
            .get_or_insert(if g.left_px >= g.right_px { 1.0 } else { -1.0 });
        BodyCommand::turn(side * self.drive.turn_rate_deg_s.to_radians())
    }
}
