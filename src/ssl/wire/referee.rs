//! The game controller's `Referee` message (github.com/RoboCup-SSL/ssl-game-controller,
//! proto2, no package), written from its documentation with its field numbers. Times are in
//! microseconds. The game events (fields 16 and 17) are left out: a decoder skips them.

/// The kind of match (`MatchType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum MatchType {
    /// Not set.
    UnknownMatch = 0,
    /// Group phase.
    GroupPhase = 1,
    /// Elimination phase.
    EliminationPhase = 2,
    /// A friendly.
    Friendly = 3,
}

/// A team's robots' hull colour (`HullColor`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum HullColor {
    /// Not set.
    Unknown = 0,
    /// Dark.
    Dark = 1,
    /// Light.
    Light = 2,
}

/// The game's stage (`Referee.Stage`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum Stage {
    /// Before the first half.
    NormalFirstHalfPre = 0,
    /// The first half.
    NormalFirstHalf = 1,
    /// Half time.
    NormalHalfTime = 2,
    /// Before the second half.
    NormalSecondHalfPre = 3,
    /// The second half.
    NormalSecondHalf = 4,
    /// Before extra time.
    ExtraTimeBreak = 5,
    /// Before extra time's first half.
    ExtraFirstHalfPre = 6,
    /// Extra time's first half.
    ExtraFirstHalf = 7,
    /// Extra time's half time.
    ExtraHalfTime = 8,
    /// Before extra time's second half.
    ExtraSecondHalfPre = 9,
    /// Extra time's second half.
    ExtraSecondHalf = 10,
    /// Before the penalty shoot-out.
    PenaltyShootoutBreak = 11,
    /// The penalty shoot-out.
    PenaltyShootout = 12,
    /// After the game.
    PostGame = 13,
}

/// The referee's command (`Referee.Command`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum Command {
    /// Every robot stops at once.
    Halt = 0,
    /// Robots keep 0.5 m from the ball.
    Stop = 1,
    /// The prepared kick may be taken.
    NormalStart = 2,
    /// Either team may play the ball.
    ForceStart = 3,
    /// Yellow prepares a kick-off.
    PrepareKickoffYellow = 4,
    /// Blue prepares a kick-off.
    PrepareKickoffBlue = 5,
    /// Yellow prepares a penalty.
    PreparePenaltyYellow = 6,
    /// Blue prepares a penalty.
    PreparePenaltyBlue = 7,
    /// A direct free kick for yellow.
    DirectFreeYellow = 8,
    /// A direct free kick for blue.
    DirectFreeBlue = 9,
    /// An indirect free kick for yellow (no longer used).
    IndirectFreeYellow = 10,
    /// An indirect free kick for blue (no longer used).
    IndirectFreeBlue = 11,
    /// Yellow's time-out.
    TimeoutYellow = 12,
    /// Blue's time-out.
    TimeoutBlue = 13,
    /// A goal for yellow (no longer used).
    GoalYellow = 14,
    /// A goal for blue (no longer used).
    GoalBlue = 15,
    /// Yellow places the ball.
    BallPlacementYellow = 16,
    /// Blue places the ball.
    BallPlacementBlue = 17,
}

/// A team's standing (`Referee.TeamInfo`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct TeamInfo {
    /// Its name.
    #[prost(string, required, tag = "1")]
    pub name: String,
    /// Its goals.
    #[prost(uint32, required, tag = "2")]
    pub score: u32,
    /// Red cards.
    #[prost(uint32, required, tag = "3")]
    pub red_cards: u32,
    /// Each yellow card's time left, µs, ascending.
    #[prost(uint32, repeated, packed = "true", tag = "4")]
    pub yellow_card_times: Vec<u32>,
    /// Yellow cards.
    #[prost(uint32, required, tag = "5")]
    pub yellow_cards: u32,
    /// Time-outs left.
    #[prost(uint32, required, tag = "6")]
    pub timeouts: u32,
    /// Time-out time left, µs.
    #[prost(uint32, required, tag = "7")]
    pub timeout_time: u32,
    /// The goalkeeper's number.
    #[prost(uint32, required, tag = "8")]
    pub goalkeeper: u32,
    /// Fouls.
    #[prost(uint32, optional, tag = "9")]
    pub foul_counter: Option<u32>,
    /// Failed ball placements.
    #[prost(uint32, optional, tag = "10")]
    pub ball_placement_failures: Option<u32>,
    /// Whether it may place the ball.
    #[prost(bool, optional, tag = "12")]
    pub can_place_ball: Option<bool>,
    /// How many robots it may have on the field.
    #[prost(uint32, optional, tag = "13")]
    pub max_allowed_bots: Option<u32>,
    /// It wants to substitute a robot.
    #[prost(bool, optional, tag = "14")]
    pub bot_substitution_intent: Option<bool>,
    /// It has failed too many ball placements.
    #[prost(bool, optional, tag = "15")]
    pub ball_placement_failures_reached: Option<bool>,
    /// It may substitute a robot now.
    #[prost(bool, optional, tag = "16")]
    pub bot_substitution_allowed: Option<bool>,
    /// Substitutions left.
    #[prost(uint32, optional, tag = "17")]
    pub bot_substitutions_left: Option<u32>,
    /// Substitution time left, µs.
    #[prost(uint32, optional, tag = "18")]
    pub bot_substitution_time_left: Option<u32>,
    /// Its robots' hull colour ([`HullColor`]).
    #[prost(enumeration = "HullColor", optional, tag = "19")]
    pub hull_color: Option<i32>,
}

/// A point on the field, mm (`Referee.Point`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct Point {
    /// mm.
    #[prost(float, required, tag = "1")]
    pub x: f32,
    /// mm.
    #[prost(float, required, tag = "2")]
    pub y: f32,
}

/// The referee's packet (`Referee`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct Referee {
    /// When sent, Unix µs.
    #[prost(uint64, required, tag = "1")]
    pub packet_timestamp: u64,
    /// The stage ([`Stage`]).
    #[prost(enumeration = "Stage", required, tag = "2")]
    pub stage: i32,
    /// The stage's time left, µs (may be negative).
    #[prost(sint64, optional, tag = "3")]
    pub stage_time_left: Option<i64>,
    /// The command ([`Command`]).
    #[prost(enumeration = "Command", required, tag = "4")]
    pub command: i32,
    /// Commands issued so far.
    #[prost(uint32, required, tag = "5")]
    pub command_counter: u32,
    /// When the command was issued, Unix µs.
    #[prost(uint64, required, tag = "6")]
    pub command_timestamp: u64,
    /// The yellow team.
    #[prost(message, required, tag = "7")]
    pub yellow: TeamInfo,
    /// The blue team.
    #[prost(message, required, tag = "8")]
    pub blue: TeamInfo,
    /// Where the ball is to be placed, mm.
    #[prost(message, optional, tag = "9")]
    pub designated_position: Option<Point>,
    /// Whether blue's goal is at +x.
    #[prost(bool, optional, tag = "10")]
    pub blue_team_on_positive_half: Option<bool>,
    /// The command after this stoppage ([`Command`]).
    #[prost(enumeration = "Command", optional, tag = "12")]
    pub next_command: Option<i32>,
    /// Time left for the current action, µs (may be negative).
    #[prost(int64, optional, tag = "15")]
    pub current_action_time_remaining: Option<i64>,
    /// The sender's random id.
    #[prost(string, optional, tag = "18")]
    pub source_identifier: Option<String>,
    /// The kind of match ([`MatchType`]).
    #[prost(
        enumeration = "MatchType",
        optional,
        tag = "19",
        default = "UnknownMatch"
    )]
    pub match_type: Option<i32>,
    /// A message for people.
    #[prost(string, optional, tag = "20")]
    pub status_message: Option<String>,
}
