//! omniloop's end-to-end tests, one module a subject, in one test binary (one link of the
//! workspace for all of them, and their tests shared out over every core). `cargo test --test
//! suite ball::` runs one module's. The sweep's interruption (its signal) and the import-loop
//! check keep binaries of their own.
#![allow(clippy::unwrap_used, clippy::expect_used)] // tests: a broken fixture stops them where it breaks

mod common;

mod avoidance;
mod ball;
mod ball_map;
mod blackout;
mod camera_models;
mod corner55;
mod custom_robot;
mod docs;
mod effects;
mod errors;
mod field_presets;
mod forward;
mod foundation;
mod freespace;
mod heading;
mod mission;
mod mounting;
mod navigation;
mod omnistereo;
mod outcomes;
mod renderer;
mod resection;
mod robustness;
mod selfloc;
mod session;
mod ssl;
mod sweep;
mod teams;
mod timing;
mod truth;
mod viewing;
