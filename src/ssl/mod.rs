//! omniloop as a Small-Size League simulator: the league's protocols, so that a team's own AI
//! can drive omniloop's robots while omniloop renders each robot's own cameras (docs/ssl.md).
//!
//! - [`wire`]: the messages of the simulation protocol, ssl-vision and the game controller;
//! - [`commands`]: a robot command judged (units, limits, wheel velocities);
//! - [`vision_out`]: the overhead cameras' detection frames and geometry, with realism;
//! - [`referee_out`]: the referee's packets and the score;
//! - [`log`]: the league's log file of what was sent;
//! - [`engine`]: [`SslSimulator`], the game without the network (its simulation-control
//!   commands in [`control`]);
//! - [`server`]: the UDP ports, paced to real time or in lockstep.

pub mod commands;
pub mod control;
pub mod engine;
pub mod log;
pub mod referee_out;
pub mod server;
pub mod vision_out;
pub mod wire;

pub use engine::{Outgoing, SslError, SslHost, SslLink, SslSimulator, SslSoftware, Tallies};
pub use server::{Bound, Pace, Ports, ServeError, ServeOptions, ServeReport, Server};
