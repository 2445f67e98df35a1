//! A forward camera's Horn-Schunck flow-balance avoidance (Ahmed, Saatchi and Caparrelli,
//! Sect. 2.1.2).

use super::segmentation::ForwardDriveConfig;
use crate::boundary::BodyCommand;
use crate::controller::{ControlTable, Controller, ControllerEntry, Situation, parses, settings};
use crate::perception::forward::{ForwardVisionConfig, needs_forward_camera};
use crate::perception::stage::vision_settings;
use omniloop_vision::forward::FlowBalance;

/// The registry's entry.
pub const ENTRY: ControllerEntry = ControllerEntry {
    name: "optical_flow",
    summary: "a forward camera's Horn-Schunck flow balance: straight until the flow is strong, \
              then turn away from the side with more (Ahmed et al., Sect. 2.1.2)",
    tables: &[ControlTable {
        name: "forward",
        check: |spec| parses::<ForwardDriveConfig>(spec, "forward"),
    }],
    needs_goal: false,
    stages: &[crate::perception::forward::FLOW_NAME],
    check_use: needs_forward_camera,
    build: |c| {
        Ok(Box::new(FlowAvoidance {
            drive: settings(c, "forward")?,
            threshold_px: vision_settings::<ForwardVisionConfig>(c, "forward")?
                .flow
                .threshold_px,
            turn: None,
            settle: 0,
        }))
    },
};

/// Sect. 2.1.2: straight until the mean flow magnitude passes the threshold, then a turn on the
/// spot of `flow_turn_s` away from the side with the stronger flow; the flow of the frames
/// during and just after a turn is the turn's own and is not read.
pub struct FlowAvoidance {
    drive: ForwardDriveConfig,
    threshold_px: f32,
    /// Direction and end time of the turn under way.
    turn: Option<(f64, f64)>,
    settle: u32,
}

impl Controller for FlowAvoidance {
    fn decide(&mut self, s: &Situation<'_>) -> BodyCommand {
        let rate = self.drive.turn_rate_deg_s.to_radians();
        if let Some((side, until)) = self.turn {
            if s.t_s < until {
                return BodyCommand::turn(side * rate);
            }
            self.turn = None;
            self.settle = self.drive.flow_settle_frames;
        }
        if self.settle > 0 {
            self.settle -= 1;
            return BodyCommand::forward(self.drive.speed_mm_s);
        }
        match s.percept::<FlowBalance>() {
            Some(f) if f.larger_px() > self.threshold_px => {
                let side = if f.left_px > f.right_px { -1.0 } else { 1.0 };
                self.turn = Some((side, s.t_s + self.drive.flow_turn_s));
                BodyCommand::turn(side * rate)
            }
            _ => BodyCommand::forward(self.drive.speed_mm_s),
        }
    }
}
