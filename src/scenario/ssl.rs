//! `[ssl]`: the scenario as a Small-Size League simulator (`omniloop ssl`): which robots are
//! whose, the ports and addresses, the overhead vision it publishes and its realism, the
//! referee. Plain data with defaults; [`SslSpec::check`] validates it once, naming the field.

use omniloop_problem::Problems;
use serde::{Deserialize, Serialize};
use std::net::SocketAddr;

/// A team's colour on the field.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TeamColor {
    /// Blue (defends the goal at -x).
    Blue,
    /// Yellow (defends the goal at +x).
    Yellow,
}

impl TeamColor {
    /// Both, blue first.
    pub const BOTH: [Self; 2] = [Self::Blue, Self::Yellow];

    /// `blue` or `yellow`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Blue => "blue",
            Self::Yellow => "yellow",
        }
    }
}

/// `[ssl]`: everything `omniloop ssl` adds to a scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SslSpec {
    /// The blue team's robots by name, robot id 0 first (empty: the scenario's robots whose
    /// names start with `blue`, in order).
    pub blue: Vec<String>,
    /// The yellow team's robots by name, id 0 first (empty: the names starting with `yellow`).
    pub yellow: Vec<String>,
    /// The teams whose robots the protocol drives; the others run their scenario software
    /// (the built-in stack on their own cameras): a mixed floor.
    pub protocol_teams: Vec<TeamColor>,
    /// A robot that hears no command for this long stops (and its dribbler with it).
    pub command_timeout_s: f64,
    /// Render every robot's cameras each cycle (off: no camera is rendered; for speed).
    pub render_cameras: bool,
    /// The four wheels' angles, degrees clockwise from forward: front right, back right, back
    /// left, front left (the protocol's `RobotWheelAngles`), for wheel-velocity commands.
    pub wheel_angles_deg: [f64; 4],
    /// Ports and addresses.
    pub network: SslNetwork,
    /// The overhead vision published as ssl-vision's packets.
    pub vision: SslVision,
    /// The referee's packets.
    pub referee: SslReferee,
}

impl Default for SslSpec {
    fn default() -> Self {
        Self {
            blue: Vec::new(),
            yellow: Vec::new(),
            protocol_teams: TeamColor::BOTH.to_vec(),
            command_timeout_s: 0.1,
            render_cameras: true,
            wheel_angles_deg: [60.0, 135.0, 225.0, 300.0],
            network: SslNetwork::default(),
            vision: SslVision::default(),
            referee: SslReferee::default(),
        }
    }
}

/// `[ssl.network]`: the simulation protocol's ports and where vision and the referee go.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SslNetwork {
    /// The address the three ports listen on (`0.0.0.0`: every interface).
    pub bind_address: String,
    /// Simulation control (`SimulatorCommand`).
    pub control_port: u16,
    /// The blue team's robot control (`RobotControl`).
    pub blue_port: u16,
    /// The yellow team's robot control.
    pub yellow_port: u16,
    /// Where vision goes: multicast, unicast or loopback, `address:port`.
    pub vision_address: String,
    /// Where the referee's packets go, `address:port`.
    pub referee_address: String,
    /// Hosts besides this one allowed on the control port (the team ports take any host).
    pub allowed_hosts: Vec<String>,
    /// Datagrams taken from one port in one cycle; the rest are dropped and counted.
    pub max_datagrams_per_cycle: usize,
}

impl Default for SslNetwork {
    fn default() -> Self {
        Self {
            bind_address: "0.0.0.0".to_string(),
            control_port: 10300,
            blue_port: 10301,
            yellow_port: 10302,
            vision_address: "224.5.23.2:10020".to_string(),
            referee_address: "224.5.23.1:10003".to_string(),
            allowed_hosts: Vec::new(),
            max_datagrams_per_cycle: 200,
        }
    }
}

/// `[ssl.vision]`: the overhead cameras and what they report.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SslVision {
    /// Overhead cameras along the field's length and across it (each reports what lies in
    /// its part of the field, grown by `overlap_mm`).
    pub cameras: [u32; 2],
    /// How far each camera sees past its part of the field, mm.
    pub overlap_mm: f64,
    /// The cameras' height above the floor, mm (for the ball hidden by robots).
    pub camera_height_mm: f64,
    /// A detection frame every this many control cycles.
    pub every_cycles: u32,
    /// A geometry packet every this many seconds (and at the start).
    pub geometry_period_s: f64,
    /// Errors as a real vision system has them (off by default).
    pub realism: SslRealism,
}

impl Default for SslVision {
    fn default() -> Self {
        Self {
            cameras: [2, 2],
            overlap_mm: 300.0,
            camera_height_mm: 4000.0,
            every_cycles: 1,
            geometry_period_s: 1.0,
            realism: SslRealism::default(),
        }
    }
}

/// `[ssl.vision.realism]`: noise, delay, missed detections and occlusion, as ER-Force's
/// simulator's "realistic" preset sets them (the defaults here, used once `enabled`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SslRealism {
    /// Apply the table (off: vision reports the truth, at once, every object).
    pub enabled: bool,
    /// Standard deviation of the ball's position, mm.
    pub ball_noise_mm: f64,
    /// Standard deviation of a robot's position, mm.
    pub robot_noise_mm: f64,
    /// Standard deviation of a robot's orientation, rad.
    pub robot_noise_rad: f64,
    /// From capture to sending, s.
    pub delay_s: f64,
    /// Chance that a camera misses the ball in a frame.
    pub ball_miss: f64,
    /// Chance that a camera misses a robot in a frame.
    pub robot_miss: f64,
    /// A ball hidden from a camera by a robot is not reported by it.
    pub occlusion: bool,
}

impl Default for SslRealism {
    fn default() -> Self {
        Self {
            enabled: false,
            ball_noise_mm: 1.4,
            robot_noise_mm: 1.3,
            robot_noise_rad: 0.01,
            delay_s: 0.035,
            ball_miss: 0.05,
            robot_miss: 0.02,
            occlusion: true,
        }
    }
}

/// `[ssl.referee]`: the referee's packets (off when an external game controller runs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SslReferee {
    /// Publish `Referee` packets.
    pub enabled: bool,
    /// A packet every this many seconds.
    pub period_s: f64,
    /// The command from the start.
    pub command: String,
    /// Commands at set times (`{ t_s = 5.0, command = "STOP" }`), in order.
    pub script: Vec<RefereeCue>,
}

impl Default for SslReferee {
    fn default() -> Self {
        Self {
            enabled: true,
            period_s: 0.1,
            command: "FORCE_START".to_string(),
            script: Vec::new(),
        }
    }
}

/// One scripted referee command.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefereeCue {
    /// When, s of simulated time.
    pub t_s: f64,
    /// The command (`HALT`, `STOP`, `FORCE_START`, `NORMAL_START`, ...).
    pub command: String,
}

/// The referee commands a scenario may name, in the game controller's numbering.
pub const REFEREE_COMMANDS: [&str; 18] = [
    "HALT",
    "STOP",
    "NORMAL_START",
    "FORCE_START",
    "PREPARE_KICKOFF_YELLOW",
    "PREPARE_KICKOFF_BLUE",
    "PREPARE_PENALTY_YELLOW",
    "PREPARE_PENALTY_BLUE",
    "DIRECT_FREE_YELLOW",
    "DIRECT_FREE_BLUE",
    "INDIRECT_FREE_YELLOW",
    "INDIRECT_FREE_BLUE",
    "TIMEOUT_YELLOW",
    "TIMEOUT_BLUE",
    "GOAL_YELLOW",
    "GOAL_BLUE",
    "BALL_PLACEMENT_YELLOW",
    "BALL_PLACEMENT_BLUE",
];

/// The game controller's number of a referee command named in a scenario.
pub fn referee_command_number(name: &str) -> Option<i32> {
    let k = REFEREE_COMMANDS.iter().position(|c| *c == name)?;
    i32::try_from(k).ok()
}

impl SslSpec {
    /// The names of `team`'s robots by id: the table's list, or those of the scenario's robots
    /// (`names`, in order) that start with the team's colour.
    pub fn team_names(&self, team: TeamColor, names: &[String]) -> Vec<String> {
        let listed = match team {
            TeamColor::Blue => &self.blue,
            TeamColor::Yellow => &self.yellow,
        };
        if !listed.is_empty() {
            return listed.clone();
        }
        (names.iter())
            .filter(|n| n.starts_with(team.name()))
            .cloned()
            .collect()
    }

    /// The table's problems, each naming its field under `ssl`, for a scenario whose robots
    /// are `names`.
    pub fn check(&self, names: &[String]) -> Problems {
        let mut c = Problems::under("ssl");
        let mut seen = std::collections::HashSet::new();
        for team in TeamColor::BOTH {
            let list = self.team_names(team, names);
            if list.len() > 16 {
                c.fail(
                    team.name(),
                    format!("{} robots: ids go up to 15", list.len()),
                );
            }
            for (k, n) in list.iter().enumerate() {
                if !names.contains(n) {
                    c.fail(
                        format!("{}[{k}]", team.name()),
                        format!("no robot called {n:?} in [[robots]]"),
                    );
                } else if !seen.insert(n.clone()) {
                    c.fail(
                        format!("{}[{k}]", team.name()),
                        format!("{n:?} is in a team already"),
                    );
                }
            }
        }
        if seen.is_empty() {
            c.fail(
                "blue",
                "no robot in either team: name them (blue = [...]) or start their names with \
                 blue or yellow",
            );
        }
        c.positive("command_timeout_s", self.command_timeout_s);
        for (k, a) in self.wheel_angles_deg.iter().enumerate() {
            c.finite(format!("wheel_angles_deg[{k}]"), *a);
        }
        self.network.check(&mut c);
        self.vision.check(&mut c);
        self.referee.check(&mut c);
        c
    }
}

impl SslNetwork {
    fn check(&self, c: &mut Problems) {
        if self.bind_address.parse::<std::net::IpAddr>().is_err() {
            c.fail(
                "network.bind_address",
                format!("{:?} is not an IP address", self.bind_address),
            );
        }
        for (key, v) in [
            ("network.vision_address", &self.vision_address),
            ("network.referee_address", &self.referee_address),
        ] {
            if v.parse::<SocketAddr>().is_err() {
                c.fail(key, format!("{v:?} is not an address:port"));
            }
        }
        for (k, h) in self.allowed_hosts.iter().enumerate() {
            if h.parse::<std::net::IpAddr>().is_err() {
                c.fail(
                    format!("network.allowed_hosts[{k}]"),
                    format!("{h:?} is not an IP address"),
                );
            }
        }
        if self.max_datagrams_per_cycle == 0 {
            c.fail("network.max_datagrams_per_cycle", "must be at least 1");
        }
    }
}

impl SslVision {
    fn check(&self, c: &mut Problems) {
        if !(1..=8).contains(&self.cameras[0]) || !(1..=8).contains(&self.cameras[1]) {
            c.fail("vision.cameras", "1 to 8 cameras each way");
        }
        c.non_negative("vision.overlap_mm", self.overlap_mm);
        c.positive("vision.camera_height_mm", self.camera_height_mm);
        if self.every_cycles == 0 {
            c.fail("vision.every_cycles", "must be at least 1");
        }
        c.positive("vision.geometry_period_s", self.geometry_period_s);
        let r = &self.realism;
        c.non_negative("vision.realism.ball_noise_mm", r.ball_noise_mm);
        c.non_negative("vision.realism.robot_noise_mm", r.robot_noise_mm);
        c.non_negative("vision.realism.robot_noise_rad", r.robot_noise_rad);
        c.non_negative("vision.realism.delay_s", r.delay_s);
        for (key, p) in [
            ("vision.realism.ball_miss", r.ball_miss),
            ("vision.realism.robot_miss", r.robot_miss),
        ] {
            if !(0.0..=1.0).contains(&p) {
                c.fail(key, format!("{p} is not a chance between 0 and 1"));
            }
        }
    }
}

impl SslReferee {
    fn check(&self, c: &mut Problems) {
        c.positive("referee.period_s", self.period_s);
        let known = || REFEREE_COMMANDS.join(", ");
        if referee_command_number(&self.command).is_none() {
            c.fail(
                "referee.command",
                format!("{:?} is not one of {}", self.command, known()),
            );
        }
        let mut last = 0.0;
        for (k, cue) in self.script.iter().enumerate() {
            if referee_command_number(&cue.command).is_none() {
                c.fail(
                    format!("referee.script[{k}].command"),
                    format!("{:?} is not one of {}", cue.command, known()),
                );
            }
            if !(cue.t_s.is_finite() && cue.t_s >= last) {
                c.fail(
                    format!("referee.script[{k}].t_s"),
                    format!("{} s: the cues go in time order from 0", cue.t_s),
                );
            }
            last = cue.t_s.max(last);
        }
    }
}
