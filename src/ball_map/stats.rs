//! The map's figures: detection and errors by ring, over all frames, over the frames the body
//! leaves in sight, within the target's range; where detection first falls below 90%; and
//! the false balls of ball-free frames.

use super::measure::{BodyShadow, FrameRow, Measured, Occlusion};
use crate::experiments::Metrics;
use serde::{Deserialize, Serialize};

/// The detection rate below which a ring counts as lost.
pub const LOST_BELOW: f64 = 0.9;

/// Detection and errors over a set of frames with the ball.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Rates {
    /// Frames.
    pub frames: usize,
    /// Frames with a sighting.
    pub detected: usize,
    /// Detected over frames (`None` without frames).
    pub detection_rate: Option<f64>,
    /// Median range error of the sightings, percent of the true range.
    pub median_range_error_pct: Option<f64>,
    /// Its 90th percentile.
    pub p90_range_error_pct: Option<f64>,
    /// Median signed range error, mm (the bias: positive when the ball is seen too far).
    pub median_range_bias_mm: Option<f64>,
    /// Median size of the bearing error, degrees.
    pub median_bearing_error_deg: Option<f64>,
    /// Why frames were missed: the reason's kind and how often, most often first.
    pub misses: Vec<(String, usize)>,
}

/// The value at quantile `q` of `v` (nearest rank), sorting it.
pub fn quantile(v: &mut [f64], q: f64) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    v.get(((v.len() as f64 - 1.0) * q).round() as usize)
        .copied()
}

impl Rates {
    /// The figures of `rows`.
    pub fn of<'a>(rows: impl Iterator<Item = &'a FrameRow>) -> Self {
        let mut r = Self::default();
        let (mut pct, mut bias, mut bearing) = (Vec::new(), Vec::new(), Vec::new());
        for row in rows {
            r.frames += 1;
            if let (Some(p), Some(b), Some(e)) = (
                row.range_error_pct(),
                row.range_error_mm(),
                row.bearing_error_deg(),
            ) {
                r.detected += 1;
                pct.push(p);
                bias.push(b);
                bearing.push(e.abs());
            } else {
                let kind = miss_kind(row.miss.as_deref().unwrap_or("none"));
                match r.misses.iter_mut().find(|(k, _)| *k == kind) {
                    Some((_, n)) => *n += 1,
                    None => r.misses.push((kind, 1)),
                }
            }
        }
        r.detection_rate = (r.frames > 0).then(|| r.detected as f64 / r.frames as f64);
        r.median_range_error_pct = quantile(&mut pct, 0.5);
        r.p90_range_error_pct = quantile(&mut pct, 0.9);
        r.median_range_bias_mm = quantile(&mut bias, 0.5);
        r.median_bearing_error_deg = quantile(&mut bearing, 0.5);
        r.misses.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        r
    }
}

/// A miss reason's kind: its words before the first figure or colon ("too small").
pub fn miss_kind(reason: &str) -> String {
    let cut = reason
        .find(|c: char| c.is_ascii_digit() || c == ':')
        .unwrap_or(reason.len());
    reason[..cut].trim().to_string()
}

/// One ring of the map: every frame at one distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ring {
    /// Its distance, mm.
    pub distance_mm: f64,
    /// How much of the ball the body hides there (`None`: not known).
    pub occlusion: Option<Occlusion>,
    /// Its figures.
    pub rates: Rates,
}

/// One camera's map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraMap {
    /// The camera.
    pub camera: String,
    /// Its image, width and height in pixels.
    pub image_px: [u32; 2],
    /// Where the body hides the ball.
    pub shadow: Option<BodyShadow>,
    /// By ring, nearest first.
    pub rings: Vec<Ring>,
    /// Over every frame with the ball.
    pub all: Rates,
    /// Over the frames the body leaves the ball in sight.
    pub unoccluded: Rates,
    /// The target's range, mm.
    pub target_range_mm: f64,
    /// Over the frames in sight within the target's range.
    pub within_target: Rates,
    /// The first ring (outward, in sight) where detection falls below 90% after reaching it
    /// (`None`: it never falls, or never reaches 90%).
    pub lost_from_mm: Option<f64>,
    /// Whether any ring in sight reaches 90%.
    pub reaches_90: bool,
}

impl CameraMap {
    /// The map of the frames with the ball in `m`; `None` when it has none.
    pub fn of(m: &Measured, target_range_mm: f64) -> Option<Self> {
        let rows: Vec<&FrameRow> = m.rows.iter().filter(|r| r.truth_mm.is_some()).collect();
        if rows.is_empty() {
            return None;
        }
        let mut distances: Vec<f64> = rows.iter().map(|r| r.distance_mm).collect();
        distances.sort_by(f64::total_cmp);
        distances.dedup();
        let rings: Vec<Ring> = distances
            .iter()
            .map(|&d| {
                let at = || rows.iter().copied().filter(move |r| r.distance_mm == d);
                Ring {
                    distance_mm: d,
                    occlusion: at().find_map(|r| r.occlusion),
                    rates: Rates::of(at()),
                }
            })
            .collect();
        let in_sight = || rows.iter().copied().filter(|r| r.unoccluded());
        let (lost_from_mm, reaches_90) = lost_from(&rings);
        Some(Self {
            camera: m.camera.clone(),
            image_px: m.image_px,
            shadow: m.shadow,
            all: Rates::of(rows.iter().copied()),
            unoccluded: Rates::of(in_sight()),
            target_range_mm,
            within_target: Rates::of(in_sight().filter(|r| r.distance_mm <= target_range_mm)),
            rings,
            lost_from_mm,
            reaches_90,
        })
    }
}

/// Outward over the rings in sight: the first whose detection is below 90% after one reached
/// it, and whether one reached it.
fn lost_from(rings: &[Ring]) -> (Option<f64>, bool) {
    let mut reached = false;
    for r in rings
        .iter()
        .filter(|r| r.occlusion != Some(Occlusion::Hidden))
    {
        let Some(rate) = r.rates.detection_rate else {
            continue;
        };
        if rate >= LOST_BELOW {
            reached = true;
        } else if reached {
            return (Some(r.distance_mm), true);
        }
    }
    (None, reached)
}

/// What ball-free frames showed.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FalseBalls {
    /// Ball-free frames.
    pub frames: usize,
    /// Frames in which the detector reported a ball.
    pub false_balls: usize,
    /// The largest false blob, pixels.
    pub largest_pixels: usize,
    /// Why the other frames showed none: the reason's kind and how often.
    pub misses: Vec<(String, usize)>,
}

impl FalseBalls {
    /// The false balls of the ball-free frames of `m`; `None` when it has none.
    pub fn of(m: &Measured) -> Option<Self> {
        let rows: Vec<&FrameRow> = m.rows.iter().filter(|r| r.truth_mm.is_none()).collect();
        if rows.is_empty() {
            return None;
        }
        let seen = rows.iter().filter_map(|r| r.seen.as_ref());
        let misses = Rates::of(rows.iter().copied()).misses;
        Some(Self {
            frames: rows.len(),
            false_balls: seen.clone().count(),
            largest_pixels: seen.map(|s| s.pixels).max().unwrap_or(0),
            misses,
        })
    }
}

/// The figures of one run of the experiment (`summary.json`: `ball_map`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallMapFigures {
    /// The map, with a ball in the world.
    pub map: Option<CameraMap>,
    /// The false balls, without one.
    pub false_balls: Option<FalseBalls>,
}

/// The experiment's metrics: `summary.json`'s `ball_map`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BallMapMetrics {
    /// The run's figures.
    pub ball_map: BallMapFigures,
}

impl Metrics for BallMapMetrics {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ball_map::measure::Seen;

    fn frame(d: f64, seen_range: Option<f64>, occlusion: Occlusion) -> FrameRow {
        FrameRow {
            distance_mm: d,
            direction: 0,
            draw: 0,
            robot: [0.0; 3],
            truth_mm: Some([d, 0.0]),
            occlusion: Some(occlusion),
            seen: seen_range.map(|r| Seen {
                position_mm: [r, 0.0],
                range_mm: r,
                bearing_deg: 0.5,
                pixels: 4,
            }),
            miss: seen_range
                .is_none()
                .then(|| "too small: 1 px, need 2".to_string()),
        }
    }

    #[test]
    fn rings_rates_and_where_detection_is_lost() {
        let mut rows = vec![frame(200.0, None, Occlusion::Hidden)];
        for (d, seen) in [(500.0, 10), (1000.0, 10), (2000.0, 8), (3000.0, 10)] {
            for k in 0..10 {
                let r = (k < seen).then_some(d * 1.02);
                rows.push(frame(d, r, Occlusion::Clear));
            }
        }
        let m = Measured {
            camera: "omni".into(),
            image_px: [256, 220],
            shadow: None,
            rows,
        };
        let map = CameraMap::of(&m, 1000.0).unwrap();
        assert_eq!(map.rings.len(), 5);
        assert_eq!(map.all.frames, 41);
        assert_eq!(map.unoccluded.frames, 40);
        assert_eq!(map.within_target.frames, 20);
        assert_eq!(map.within_target.detection_rate, Some(1.0));
        let median = map.within_target.median_range_error_pct.unwrap();
        assert!((median - 2.0).abs() < 1e-9, "{median}");
        assert_eq!(map.lost_from_mm, Some(2000.0));
        assert!(map.reaches_90);
        assert_eq!(map.unoccluded.misses, vec![("too small".to_string(), 2)]);
        assert!(FalseBalls::of(&m).is_none());
    }
}
