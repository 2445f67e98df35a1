//! The registry of replays (`omniloop replay NAME`): a replay of a paper's experiment, or one
//! built on many runs, is its own module with a [`Replay`] and one line in [`REPLAYS`].

use crate::experiments::{Replay, corner, forward, heading, omnistereo, places, resection};
use crate::robustness;

/// Every replay, in the order `omniloop replay --list` shows them.
pub const REPLAYS: &[Replay] = &[
    corner::REPLAY,
    places::REPLAY,
    heading::REPLAY,
    omnistereo::REPLAY,
    resection::REPLAY,
    forward::REPLAY,
    robustness::REPLAY,
    crate::blackout::REPLAY,
    crate::ball_map::REPLAY,
];

/// The replay called `name`.
pub fn replay(name: &str) -> Option<&'static Replay> {
    REPLAYS.iter().find(|r| r.name == name)
}
