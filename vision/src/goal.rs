//! A goal in one camera image as the azimuths it covers: every image column of directions
//! (an azimuth bin about the camera axis) that holds a pixel of the goal's colour, merged into
//! runs. What stands in front of the goal (a defender) cuts its run in two, so the widest run
//! is the widest open part of the mouth the camera shows, and its middle the direction to
//! shoot at. A camera higher than the defender sees the top of the goal's back wall over it,
//! so a direction counts only where no dark pixel (a robot's black top or body) lies just
//! nearer than the goal's nearest pixel in it. Ours: the papers have no goals.

use crate::calibration::RadialCalibration;
use crate::forward::ForwardCamera;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A colour by its chromaticity, so that shading does not change it: its brightest channel
/// (`lead`) at least `min_lead`, and each channel over the lead within its bounds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Chroma {
    /// The lead channel: 0 red, 1 green, 2 blue.
    pub lead: usize,
    /// The lead channel at least this (darker pixels are too noisy to judge).
    pub min_lead: u8,
    /// Each channel over the lead, `[lo, hi]`.
    pub over_lead: [[f64; 2]; 3],
}

impl Chroma {
    /// The league's yellow goal ([235, 200, 20]): green 0.85 of red, little blue; the ball's
    /// orange (green 0.43 of red) and white lines (blue as red) are not it.
    pub const YELLOW: Chroma = Chroma {
        lead: 0,
        min_lead: 60,
        over_lead: [[1.0, 1.0], [0.7, 1.05], [0.0, 0.35]],
    };
    /// The league's blue goal ([25, 60, 220]).
    pub const BLUE: Chroma = Chroma {
        lead: 2,
        min_lead: 60,
        over_lead: [[0.0, 0.35], [0.1, 0.5], [1.0, 1.0]],
    };

    /// Whether pixel `p` is of the colour.
    pub fn contains(&self, p: [u8; 3]) -> bool {
        let Some(&lead) = p.get(self.lead) else {
            return false;
        };
        if lead < self.min_lead {
            return false;
        }
        let l = f32::from(lead);
        (0..3).all(|k| {
            let c = f32::from(p[k]);
            c >= self.over_lead[k][0] as f32 * l && c <= self.over_lead[k][1] as f32 * l
        })
    }
}

/// A run of azimuths holding the goal's colour, counter-clockwise from `from_rad` to `to_rad`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GoalRun {
    /// Its first azimuth, rad, in `(-pi, pi]`.
    pub from_rad: f64,
    /// Its last azimuth, rad (counter-clockwise from `from_rad`; may wrap past pi).
    pub to_rad: f64,
    /// Its angular width, rad.
    pub width_rad: f64,
    /// Its middle, rad, in `(-pi, pi]`.
    pub centre_rad: f64,
}

/// Azimuth bins a turn (a degree each: about a pixel at 60 px from the image centre).
pub const BINS: usize = 360;

/// The runs of `color` in a mirror camera's image, widest first; pixels beyond the floor
/// horizon and within `inner_px` of the principal point (the robot itself) are left out.
pub fn goal_runs_mirror(
    img: &RgbaImage,
    cal: &RadialCalibration,
    color: &Chroma,
    inner_px: f64,
) -> Vec<GoalRun> {
    let horizon = cal.horizon_px.min(cal.max_radius_px());
    // The robot's own body (and what it carries) is dark too, about the image centre.
    let body = cal.image_radius_px(OWN_BODY_MM).unwrap_or(0.0);
    runs_by(img, color, body, |u, v| {
        let (x, y) = cal.image_coords(f64::from(u), f64::from(v));
        let r = x.hypot(y);
        // Outward from the image centre is farther on the floor.
        (r > inner_px && r < horizon).then(|| (y.atan2(x), r))
    })
}

/// The runs of `color` in a forward pinhole camera's image, widest first.
pub fn goal_runs_forward(img: &RgbaImage, cam: &ForwardCamera, color: &Chroma) -> Vec<GoalRun> {
    runs_by(img, color, f64::NEG_INFINITY, |u, v| {
        let d = cam.direction(f64::from(u), f64::from(v));
        // Up the image is farther on the floor.
        Some((d.y.atan2(d.x), -f64::from(v)))
    })
}

/// The brightest channel of a dark pixel at most this: a robot's black top and body (the
/// floor, the lines, the goals and the ball are all brighter).
pub const DARK_MAX: u8 = 50;

/// Floor distance within which dark pixels are the robot's own body, mm (a Small-Size robot's
/// radius is 90 mm; its dribbler and kicker reach a little farther).
pub const OWN_BODY_MM: f64 = 200.0;

/// How far (in the key of [`runs_by`]: image pixels) nearer than a goal's nearest pixel a dark
/// pixel hides the goal there: a robot standing in front of it, whose top is just under the
/// part of the goal seen over it.
pub const HIDING_GAP: f64 = 4.0;

/// The runs of `color` over the azimuths `place` gives each pixel it keeps (with a key that
/// grows with the distance on the floor): a bin is full where it holds the colour and no dark
/// pixel (with a key beyond `dark_from`) lies within [`HIDING_GAP`] nearer than the colour's
/// nearest.
fn runs_by(
    img: &RgbaImage,
    color: &Chroma,
    dark_from: f64,
    place: impl Fn(u32, u32) -> Option<(f64, f64)>,
) -> Vec<GoalRun> {
    let mut goal = vec![f64::INFINITY; BINS];
    for (u, v, p) in img.enumerate_pixels() {
        if color.contains([p[0], p[1], p[2]])
            && let Some((a, key)) = place(u, v)
        {
            let b = bin_of(a);
            goal[b] = goal[b].min(key);
        }
    }
    let mut hidden = vec![false; BINS];
    for (u, v, p) in img.enumerate_pixels() {
        if p[0].max(p[1]).max(p[2]) > DARK_MAX {
            continue;
        }
        if let Some((a, key)) = place(u, v).filter(|&(_, key)| key > dark_from) {
            let b = bin_of(a);
            hidden[b] |= key < goal[b] && key >= goal[b] - HIDING_GAP;
        }
    }
    // A bin between two hidden ones is hidden too: a near robot's top is a few pixels deep,
    // under one a degree near the image centre.
    let bins: Vec<bool> = (0..BINS)
        .map(|k| {
            let between = hidden[(k + BINS - 1) % BINS] && hidden[(k + 1) % BINS];
            goal[k].is_finite() && !hidden[k] && !between
        })
        .collect();
    // A single empty bin between two full ones is noise, not a gap.
    let filled: Vec<bool> = (0..BINS)
        .map(|k| bins[k] || (bins[(k + BINS - 1) % BINS] && bins[(k + 1) % BINS]))
        .collect();
    let mut runs = runs_of(&filled);
    runs.sort_by(|a, b| b.width_rad.total_cmp(&a.width_rad));
    runs
}

/// The bin of azimuth `a`.
fn bin_of(a: f64) -> usize {
    ((a.rem_euclid(TAU) / TAU * BINS as f64) as usize).min(BINS - 1)
}

/// The runs of full bins, a run over the wrap joined.
fn runs_of(full: &[bool]) -> Vec<GoalRun> {
    let n = full.len();
    let Some(start) = (0..n).find(|&k| !full[k]) else {
        return Vec::new();
    };
    let step = TAU / n as f64;
    let mut runs = Vec::new();
    let mut k = 0;
    while k < n {
        let i = (start + k) % n;
        if !full[i] {
            k += 1;
            continue;
        }
        let len = (k..n).take_while(|&j| full[(start + j) % n]).count();
        let from = i as f64 * step;
        let width = len as f64 * step;
        let wrap = |a: f64| (a + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
        runs.push(GoalRun {
            from_rad: wrap(from),
            to_rad: wrap(from) + width,
            width_rad: width,
            centre_rad: wrap(from + 0.5 * width),
        });
        k += len;
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgba;

    #[test]
    fn a_defender_cuts_the_goal_in_two_and_the_widest_part_comes_first() {
        let mut full = vec![false; BINS];
        // The goal from 10 to 30 degrees, a defender over 14 to 18.
        for (k, f) in full.iter_mut().enumerate().take(30).skip(10) {
            *f = !(14..18).contains(&k);
        }
        let mut runs = runs_of(&full);
        runs.sort_by(|a, b| b.width_rad.total_cmp(&a.width_rad));
        assert_eq!(runs.len(), 2);
        assert!(
            (runs[0].centre_rad.to_degrees() - 24.0).abs() < 0.2,
            "{runs:?}"
        );
        assert!((runs[0].width_rad.to_degrees() - 12.0).abs() < 0.01);
    }

    #[test]
    fn a_run_over_the_back_is_one_run() {
        let mut full = vec![false; BINS];
        for k in (0..2).chain(BINS - 2..BINS) {
            full[k] = true;
        }
        let runs = runs_of(&full);
        assert_eq!(runs.len(), 1);
        assert!(runs[0].centre_rad.abs() < 1e-9, "{runs:?}");
        assert!((runs[0].width_rad.to_degrees() - 4.0).abs() < 1e-9);
    }

    #[test]
    fn yellow_pixels_ahead_give_a_run_ahead() {
        let mut img = RgbaImage::from_pixel(101, 101, Rgba([30, 130, 55, 255]));
        for v in 45..56 {
            img.put_pixel(95, v, Rgba([235, 200, 20, 255]));
        }
        let runs = runs_by(&img, &Chroma::YELLOW, 0.0, |u, v| {
            let (x, y) = (f64::from(u) - 50.0, 50.0 - f64::from(v));
            Some((y.atan2(x), x.hypot(y)))
        });
        assert_eq!(runs.len(), 1);
        assert!(runs[0].centre_rad.abs() < 0.02, "{runs:?}");
        assert!(
            !Chroma::YELLOW.contains([255, 110, 20]),
            "the ball is not the goal"
        );
        assert!(!Chroma::YELLOW.contains([240, 240, 240]), "nor a line");
    }
}

#[cfg(test)]
mod over_a_defender {
    use super::*;
    use image::Rgba;

    #[test]
    fn a_dark_robot_in_front_of_the_goal_cuts_its_run_though_the_goal_shows_over_it() {
        // The goal's back wall at 40 to 44 px out, 20 degrees either side of ahead; a robot's
        // black top nearer (at 36 to 38 px) over 2 to 8 degrees; a dark wall beyond the goal
        // elsewhere changes nothing.
        let mut img = RgbaImage::from_pixel(121, 121, Rgba([30, 130, 55, 255]));
        let put = |img: &mut RgbaImage, r: f64, deg: f64, c: [u8; 3]| {
            let a = deg.to_radians();
            let (u, v) = (60.0 + r * a.cos(), 60.0 - r * a.sin());
            img.put_pixel(
                u.round() as u32,
                v.round() as u32,
                Rgba([c[0], c[1], c[2], 255]),
            );
        };
        for k in -200..=200 {
            let deg = f64::from(k) * 0.1;
            for r in [40.0, 41.0, 42.0, 43.0, 44.0] {
                put(&mut img, r, deg, [235, 200, 20]);
            }
            put(&mut img, 50.0, deg, [20, 20, 20]);
            if (2.0..=8.0).contains(&deg) {
                for r in [36.0, 37.0, 38.0] {
                    put(&mut img, r, deg, [20, 20, 20]);
                }
            }
        }
        // The robot's own dark body about the centre is left out.
        for u in 55..66 {
            for v in 55..66 {
                img.put_pixel(u, v, Rgba([10, 10, 10, 255]));
            }
        }
        let runs = runs_by(&img, &Chroma::YELLOW, 8.0, |u, v| {
            let (x, y) = (f64::from(u) - 60.0, 60.0 - f64::from(v));
            Some((y.atan2(x), x.hypot(y)))
        });
        assert_eq!(runs.len(), 2, "{runs:?}");
        // The wider part, -20 to 2 degrees, first.
        assert!(
            (runs[0].centre_rad.to_degrees() + 9.0).abs() < 1.5,
            "{runs:?}"
        );
        assert!(
            (runs[1].centre_rad.to_degrees() - 14.0).abs() < 1.5,
            "{runs:?}"
        );
    }
}
