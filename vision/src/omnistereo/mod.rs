//! Conical omnistereo (Spacek and Burbridge, "Instantaneous robot self-localization and motion
//! estimation with omnidirectional vision", 2007): two coaxial 90-degree cones, one above the
//! other, see every object above their tips twice; the radial disparity of its two images gives
//! its range (eqs. (1)-(2), Sect. 2). From the ranges:
//! - [`trilateration`]: the position from the three nearest landmarks of a known map, the
//!   heading from their bearings (Sect. 1);
//! - [`compass`]: the rotation between two frames from the angular optic flow, with no
//!   iteration (the paper gives the idea, not the algorithm: ours is per-ring circular
//!   correlation);
//! - [`interframe`]: the translation between two frames, one solution per feature seen in both,
//!   combined by a robust clustering of ours (the paper's `Clumat` is not published).
//!
//! Image conventions (as everywhere in this crate): image coordinates `(X, Y)` from the mirror
//! axis's image, Y up; a scene ray keeps its pixel's azimuth `atan2(Y, X)`, which is the
//! bearing in the robot frame (counter-clockwise from the robot's x axis). A 90-degree cone
//! images a point at horizontal range `r` from the axis and height `z` above its tip at image
//! radius `h = v z / (r + d)`: height goes outward, the horizon is the image centre.

pub mod compass;
pub mod config;
pub mod interframe;
pub mod marks;
pub mod numbers;
pub mod range;
pub mod rim;
pub mod trilateration;

pub use compass::{AngularProfile, CompassConfig, Rotation};
pub use config::OmnistereoConfig;
pub use interframe::{
    Candidate, FeaturePair, Translation, densest_cluster, translation_candidates,
};
pub use marks::{ColourMark, MarkConfig, detect_marks};
pub use range::{RangedMark, StereoGeometry, range_marks};
pub use rim::MirrorRim;
pub use trilateration::{
    LandmarkRange, Trilateration, TrilaterationMode, trilaterate, trilaterate_with_error,
};
