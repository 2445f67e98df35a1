//! Stripe-mark recognition (Sect. 3.4): the grey level of each column averaged over a band of
//! rows, binarized, and the widths of successive black and white intervals compared with the
//! marks' width ratios (P 3:5:3:2:11, Q 5:2:5:2:5, O 2:7:2:2:5 in the paper).
//!
//! Where the paper is silent we chose:
//! - the threshold: halfway between the darkest and brightest averaged column of the band (a
//!   band of too little contrast has no marks);
//! - sub-pixel interval ends: where the averaged profile crosses the threshold, interpolated
//!   linearly between the two columns;
//! - the match rule: every stripe's width within `tolerance_fraction` of its expected width
//!   (or `tolerance_px`, whichever is larger) given the pattern's total width; the score is one
//!   less the worst stripe's relative error;
//! - the mark's centre: the boards are seen obliquely, so the middle of the pattern's two ends
//!   is not the image of the board's centre (off by up to 0.5 degrees at 1 m). The six edges of
//!   a mark are the images of six known points of a line, so a 1-D projective map
//!   `x = (a u + b) / (c u + 1)` from the position `u` along the board to the column, fitted to
//!   them, gives the column of its centre `u = 1/2` exactly.

use crate::{VisionError, positive};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// A mark: black and white stripes of the given relative widths, black first and last.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StripePattern {
    /// Name (`P`).
    pub name: String,
    /// Relative widths from the left edge as seen from the front, an odd count of three or more.
    pub widths: Vec<f64>,
}

impl StripePattern {
    /// A pattern called `name` with relative `widths`.
    pub fn new(name: &str, widths: &[f64]) -> Self {
        Self {
            name: name.to_string(),
            widths: widths.to_vec(),
        }
    }

    /// The three marks of the paper (Sect. 3.2): P 3:5:3:2:11, Q 5:2:5:2:5, O 2:7:2:2:5.
    pub fn paper_marks() -> [Self; 3] {
        [
            Self::new("P", &[3.0, 5.0, 3.0, 2.0, 11.0]),
            Self::new("Q", &[5.0, 2.0, 5.0, 2.0, 5.0]),
            Self::new("O", &[2.0, 7.0, 2.0, 2.0, 5.0]),
        ]
    }

    /// Checks that the pattern can be recognized: an odd count of at least three positive widths
    /// (black first and last, so that both ends show against a lighter surrounding).
    pub fn validate(&self) -> Result<(), VisionError> {
        let n = self.widths.len();
        if n < 3 || n.is_multiple_of(2) {
            return Err(VisionError::InvalidParameter {
                name: "stripe count",
                value: n as f64,
                rule: "a mark needs an odd number (3 or more) of stripes, black first and last",
            });
        }
        if let Some(w) = self.widths.iter().find(|w| !(w.is_finite() && **w > 0.0)) {
            return Err(VisionError::InvalidParameter {
                name: "stripe width",
                value: *w,
                rule: "must be > 0",
            });
        }
        Ok(())
    }

    /// Edge positions as fractions of the pattern's width: 0, ..., 1.
    pub fn edges(&self) -> Vec<f64> {
        let total: f64 = self.widths.iter().sum();
        let mut acc = 0.0;
        std::iter::once(0.0)
            .chain(self.widths.iter().map(|w| {
                acc += w;
                acc / total
            }))
            .collect()
    }
}

/// How stripes are matched (`[vision.resection.stripes]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StripeConfig {
    /// A stripe matches when its width is within this fraction of the expected width...
    pub tolerance_fraction: f64,
    /// ...or within this many samples, whichever is larger (the edges' own uncertainty).
    pub tolerance_px: f64,
    /// Least difference between the band's darkest and brightest column, grey levels of 255.
    pub min_contrast: f64,
    /// Least width of a whole mark, samples.
    pub min_width_px: f64,
}

impl Default for StripeConfig {
    fn default() -> Self {
        Self {
            tolerance_fraction: 0.25,
            tolerance_px: 0.8,
            min_contrast: 48.0,
            min_width_px: 10.0,
        }
    }
}

impl StripeConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        positive("stripes.tolerance_fraction", self.tolerance_fraction)?;
        positive("stripes.tolerance_px", self.tolerance_px)?;
        positive("stripes.min_contrast", self.min_contrast)?;
        positive("stripes.min_width_px", self.min_width_px)
    }
}

/// A mark found in a profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StripeMatch {
    /// Index of the pattern.
    pub mark: usize,
    /// Position of the board's centre in the profile (samples; the column for an image band).
    pub centre: f64,
    /// Position of the mark's left end.
    pub left: f64,
    /// Width of the whole pattern, samples.
    pub width: f64,
    /// One less the worst stripe's relative width error (1: perfect).
    pub score: f64,
}

/// The mean luminance of each column over rows `rows[0]..=rows[1]` (Sect. 3.4, Fig. 6(a)).
pub fn band_profile(image: &image::RgbaImage, rows: [u32; 2]) -> Vec<f32> {
    let (w, h) = image.dimensions();
    let (r0, r1) = (rows[0].min(h - 1), rows[1].min(h - 1));
    let mut sum = vec![0.0f32; w as usize];
    let raw: &[u8] = image.as_raw();
    for row in r0..=r1 {
        let line = &raw[(row * w * 4) as usize..((row + 1) * w * 4) as usize];
        for (s, px) in sum.iter_mut().zip(line.chunks_exact(4)) {
            *s += luminance(px);
        }
    }
    let n = (r1 - r0 + 1) as f32;
    sum.iter_mut().for_each(|s| *s /= n);
    sum
}

/// Rec. 601 luminance of an RGBA pixel, 0..255.
pub fn luminance(px: &[u8]) -> f32 {
    0.299 * px[0] as f32 + 0.587 * px[1] as f32 + 0.114 * px[2] as f32
}

/// A threshold crossing: position and whether the profile goes dark after it.
#[derive(Debug, Clone, Copy)]
struct Edge {
    at: f64,
    falling: bool,
}

/// Binarizes `profile` halfway between its extremes and returns the crossings (Fig. 6(b)), or
/// why there are none worth reading.
fn crossings(profile: &[f32], min_contrast: f64) -> Result<Vec<Edge>, VisionError> {
    let (lo, hi) = profile
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    if profile.len() < 2 || ((hi - lo) as f64) < min_contrast {
        return Err(VisionError::LowContrast {
            contrast: f64::from((hi - lo).max(0.0)),
            needed: min_contrast,
        });
    }
    let t = 0.5 * (lo + hi);
    let mut edges = Vec::new();
    for (i, pair) in profile.windows(2).enumerate() {
        let (a, b) = (pair[0], pair[1]);
        if (a >= t) != (b >= t) {
            edges.push(Edge {
                at: i as f64 + ((t - a) / (b - a)) as f64,
                falling: a >= t,
            });
        }
    }
    Ok(edges)
}

/// Every mark of `patterns` in a linear profile (the columns of a band), best first.
pub fn find_stripes(
    profile: &[f32],
    patterns: &[StripePattern],
    config: &StripeConfig,
) -> Result<Vec<StripeMatch>, VisionError> {
    let edges = crossings(profile, config.min_contrast)?;
    let mut found = Vec::new();
    for start in 0..edges.len() {
        if !edges[start].falling {
            continue;
        }
        if let Some(m) = best_match(&edges[start..], patterns, config) {
            found.push(m);
        }
    }
    found.sort_by(|a, b| b.score.total_cmp(&a.score));
    Ok(found)
}

/// Every mark in a circular profile of `n` samples (an angular profile all round the robot):
/// the profile is read with its end wrapped before its start and its start after its end, and
/// each mark is reported once, with its position within `0..n`.
pub fn find_stripes_circular(
    profile: &[f32],
    patterns: &[StripePattern],
    config: &StripeConfig,
) -> Result<Vec<StripeMatch>, VisionError> {
    let n = profile.len();
    let pad = n / 4;
    let unrolled: Vec<f32> = profile[n - pad..]
        .iter()
        .chain(profile)
        .chain(&profile[..pad])
        .copied()
        .collect();
    let mut found = find_stripes(&unrolled, patterns, config)?;
    let (lo, hi) = (pad as f64, (pad + n) as f64);
    found.retain(|m| (lo..hi).contains(&m.left));
    for m in &mut found {
        m.left -= lo;
        m.centre = (m.centre - lo).rem_euclid(n as f64);
    }
    Ok(found)
}

/// The best pattern whose stripes start at the first of `edges` (a falling one), if any.
fn best_match(
    edges: &[Edge],
    patterns: &[StripePattern],
    config: &StripeConfig,
) -> Option<StripeMatch> {
    let mut best: Option<StripeMatch> = None;
    for (k, p) in patterns.iter().enumerate() {
        let n = p.widths.len();
        if edges.len() < n + 1 {
            continue;
        }
        let x: Vec<f64> = edges[..=n].iter().map(|e| e.at).collect();
        let width = x[n] - x[0];
        if width < config.min_width_px {
            continue;
        }
        let u = p.edges();
        let mut worst = 0.0f64;
        let mut ok = true;
        for s in 0..n {
            let expected = width * (u[s + 1] - u[s]);
            let err = (x[s + 1] - x[s] - expected).abs();
            ok &= err <= (config.tolerance_fraction * expected).max(config.tolerance_px);
            worst = worst.max(err / expected);
        }
        let score = 1.0 - worst;
        if ok && best.is_none_or(|b| score > b.score) {
            best = Some(StripeMatch {
                mark: k,
                centre: projective_centre(&u, &x),
                left: x[0],
                width,
                score,
            });
        }
    }
    best
}

/// The image of the board's middle `u = 1/2`, from the images `x` of its stripe edges at
/// fractions `u`: least squares for `x = (a u + b) / (c u + 1)`, linear in `(a, b, c)` as
/// `a u + b - c u x = x`. Falls back to the middle of the ends when the fit is singular.
pub fn projective_centre(u: &[f64], x: &[f64]) -> f64 {
    let mut ata = Matrix3::<f64>::zeros();
    let mut atb = Vector3::<f64>::zeros();
    // Centred on the first edge so that the system is well scaled.
    let x0 = x[0];
    for (&ui, &xi) in u.iter().zip(x) {
        let xi = xi - x0;
        let row = Vector3::new(ui, 1.0, -ui * xi);
        ata += row * row.transpose();
        atb += row * xi;
    }
    let midpoint = 0.5 * (x[0] + x[x.len() - 1]);
    match ata.lu().solve(&atb) {
        Some(s) if (0.5 * s[2] + 1.0).abs() > 1e-6 => {
            let c = (0.5 * s[0] + s[1]) / (0.5 * s[2] + 1.0) + x0;
            if c.is_finite() { c } else { midpoint }
        }
        _ => midpoint,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{RngExt, SeedableRng};

    /// A profile of `n` samples: light background (200), the pattern's stripes (black 20, white
    /// 235) from `left` over `width` samples, each sample the area-weighted mean of its cell.
    fn render(widths: &[f64], left: f64, width: f64, n: usize) -> Vec<f32> {
        let p = StripePattern::new("t", widths);
        let e: Vec<f64> = p.edges().iter().map(|u| left + u * width).collect();
        let value = |x: f64| -> f32 {
            if x < e[0] || x >= e[e.len() - 1] {
                return 200.0;
            }
            let k = e
                .windows(2)
                .position(|w| x >= w[0] && x < w[1])
                .unwrap_or(0);
            if k % 2 == 0 { 20.0 } else { 235.0 }
        };
        (0..n)
            .map(|i| {
                let sub = 16;
                (0..sub)
                    .map(|s| value(i as f64 - 0.5 + (s as f64 + 0.5) / sub as f64))
                    .sum::<f32>()
                    / sub as f32
            })
            .collect()
    }

    #[test]
    fn each_mark_is_recognized_at_several_scales_and_not_taken_for_another() {
        let marks = StripePattern::paper_marks();
        for (k, m) in marks.iter().enumerate() {
            for width in [24.0, 36.0, 60.0, 120.0] {
                let left = 50.3;
                let prof = render(&m.widths, left, width, 256);
                let found = find_stripes(&prof, &marks, &StripeConfig::default()).unwrap();
                assert_eq!(found.len(), 1, "{} at {width}: {found:?}", m.name);
                assert_eq!(found[0].mark, k, "{} at {width}", m.name);
                let centre = left + width / 2.0;
                assert!(
                    (found[0].centre - centre).abs() < 0.25,
                    "{} at {width}: centre {} want {centre}",
                    m.name,
                    found[0].centre
                );
            }
        }
    }

    #[test]
    fn random_stripe_patterns_are_rejected() {
        let marks = StripePattern::paper_marks();
        let mut rng = StdRng::seed_from_u64(7);
        let (mut accepted, trials) = (0, 2000);
        for _ in 0..trials {
            let widths: Vec<f64> = (0..5).map(|_| rng.random_range(1.0..12.0)).collect();
            let prof = render(&widths, 40.0, 80.0, 200);
            let found = find_stripes(&prof, &marks, &StripeConfig::default()).unwrap();
            accepted += usize::from(!found.is_empty());
        }
        assert!(
            accepted * 100 < trials,
            "{accepted} of {trials} random patterns taken for a mark"
        );
    }

    #[test]
    fn a_board_seen_obliquely_is_centred_by_its_projective_map() {
        // Edges of P on a board 300 mm wide, 1100 mm away, turned 45 degrees: x = f X / Z.
        let p = &StripePattern::paper_marks()[0];
        let (f, a) = (516.0, 45f64.to_radians());
        let col = |u: f64| {
            let s = (u - 0.5) * 300.0;
            128.0 + f * (s * a.cos()) / (1100.0 + s * a.sin())
        };
        let u = p.edges();
        let x: Vec<f64> = u.iter().map(|&u| col(u)).collect();
        let exact = col(0.5);
        let mid = 0.5 * (x[0] + x[5]);
        assert!(
            (mid - exact).abs() > 2.0,
            "the ends' middle is off: {mid} vs {exact}"
        );
        assert!((projective_centre(&u, &x) - exact).abs() < 1e-6);
    }

    #[test]
    fn a_mark_across_the_wrap_of_a_circular_profile_is_found_once() {
        let marks = StripePattern::paper_marks();
        // Centre at 120, turned so that the mark starts at 380 and ends past the wrap.
        let prof = render(&marks[1].widths, 100.0, 40.0, 400);
        let rotated: Vec<f32> = (0..400).map(|i| prof[(i + 120) % 400]).collect();
        let found = find_stripes_circular(&rotated, &marks, &StripeConfig::default()).unwrap();
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].mark, 1);
        assert!((found[0].centre - 0.0).abs() < 0.2 || (found[0].centre - 400.0).abs() < 0.2);
    }

    #[test]
    fn a_flat_band_is_not_found_with_its_contrast() {
        let err = find_stripes(
            &[100.0; 64],
            &StripePattern::paper_marks(),
            &StripeConfig::default(),
        )
        .unwrap_err();
        assert!(
            matches!(err, VisionError::LowContrast { contrast, .. } if contrast == 0.0),
            "{err:?}"
        );
        assert!(err.to_string().contains("contrast 0"), "{err}");
    }
}
