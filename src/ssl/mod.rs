//! omniloop as a Small-Size League simulator: the league's protocols, so that a team's own AI
//! can drive omniloop's robots. [`wire`] holds the messages of the simulation protocol,
//! ssl-vision and the game controller.

pub mod wire;
