//! The referee's packets (`Referee`, as the game controller sends them): the command the
//! scenario scripts, the score from the simulator's goal events. Blue defends the goal at -x,
//! so a goal into -x is yellow's.

use super::wire::referee::{Referee, Stage, TeamInfo};
use crate::scenario::ssl::{SslReferee, referee_command_number};
use omniloop_sim::game::{BallEvent, GoalSide};

/// The referee: its script, the command now and the score.
pub struct RefereeOut {
    spec: SslReferee,
    command: i32,
    command_counter: u32,
    command_since_s: f64,
    next_cue: usize,
    /// Goals for blue and yellow.
    pub score: [u32; 2],
    events_seen: usize,
    last_sent_s: Option<f64>,
    /// A command set from outside, to send at once.
    set_now: bool,
}

/// Microseconds of simulated time.
fn micros(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e6).round() as u64
}

impl RefereeOut {
    /// The referee of `spec` (its starting command checked with the scenario).
    pub fn new(spec: &SslReferee) -> Self {
        Self {
            command: referee_command_number(&spec.command).unwrap_or(0),
            spec: spec.clone(),
            command_counter: 0,
            command_since_s: 0.0,
            next_cue: 0,
            score: [0, 0],
            events_seen: 0,
            last_sent_s: None,
            set_now: false,
        }
    }

    /// Takes the game's new events (goals) and the script's cues due by `t_s`; a packet when
    /// one is due (every `period_s`, and at once on a new command or goal).
    pub fn update(&mut self, t_s: f64, events: &[BallEvent]) -> Option<Referee> {
        let mut news = std::mem::take(&mut self.set_now);
        for e in events.iter().skip(self.events_seen) {
            if let BallEvent::Goal { goal, .. } = e {
                let scorer = match goal {
                    GoalSide::NegX => 1,
                    GoalSide::PosX => 0,
                };
                self.score[scorer] += 1;
                news = true;
            }
        }
        self.events_seen = events.len();
        while let Some(cue) = self.spec.script.get(self.next_cue) {
            if cue.t_s > t_s + 1e-9 {
                break;
            }
            self.command = referee_command_number(&cue.command).unwrap_or(self.command);
            self.command_counter += 1;
            self.command_since_s = t_s;
            self.next_cue += 1;
            news = true;
        }
        let due = self
            .last_sent_s
            .is_none_or(|last| t_s - last >= self.spec.period_s - 1e-9);
        if !(self.spec.enabled && (news || due)) {
            return None;
        }
        self.last_sent_s = Some(t_s);
        Some(self.packet(t_s))
    }

    /// Sets the command at `t_s` (from the control port), sent with the next packet.
    pub fn set_command(&mut self, command: i32, t_s: f64) {
        self.command = command;
        self.command_counter += 1;
        self.command_since_s = t_s;
        self.set_now = true;
    }

    /// The command now, in the game controller's numbering.
    pub fn command(&self) -> i32 {
        self.command
    }

    fn packet(&self, t_s: f64) -> Referee {
        let team = |name: &str, score: u32| TeamInfo {
            name: name.to_string(),
            score,
            red_cards: 0,
            yellow_card_times: Vec::new(),
            yellow_cards: 0,
            timeouts: 4,
            timeout_time: 300_000_000,
            goalkeeper: 0,
            foul_counter: None,
            ball_placement_failures: None,
            can_place_ball: None,
            max_allowed_bots: None,
            bot_substitution_intent: None,
            ball_placement_failures_reached: None,
            bot_substitution_allowed: None,
            bot_substitutions_left: None,
            bot_substitution_time_left: None,
            hull_color: None,
        };
        Referee {
            packet_timestamp: micros(t_s),
            stage: Stage::NormalFirstHalf as i32,
            stage_time_left: None,
            command: self.command,
            command_counter: self.command_counter,
            command_timestamp: micros(self.command_since_s),
            yellow: team("yellow", self.score[1]),
            blue: team("blue", self.score[0]),
            designated_position: None,
            blue_team_on_positive_half: Some(false),
            next_command: None,
            current_action_time_remaining: None,
            source_identifier: Some("omniloop".to_string()),
            match_type: None,
            status_message: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::ssl::RefereeCue;

    #[test]
    fn goals_score_and_the_script_changes_the_command() {
        let spec = SslReferee {
            script: vec![RefereeCue {
                t_s: 1.0,
                command: "STOP".to_string(),
            }],
            ..SslReferee::default()
        };
        let mut r = RefereeOut::new(&spec);
        let first = r.update(0.0, &[]).unwrap();
        assert_eq!(first.command, 3, "FORCE_START");
        assert!(r.update(0.05, &[]).is_none(), "not due yet");
        let goal = BallEvent::Goal {
            t_s: 0.06,
            goal: GoalSide::NegX,
            by: None,
        };
        let p = r.update(0.06, &[goal]).unwrap();
        assert_eq!((p.blue.score, p.yellow.score), (0, 1));
        let p = r.update(1.0, &[goal]).unwrap();
        assert_eq!((p.command, p.command_counter), (1, 1));
        assert_eq!(p.yellow.score, 1, "an event counts once");
    }
}
