//! Feature matching by normalised cross-correlation (Lewis 1995; Sect. 2.2.3, eq. (7)):
//!
//! ```text
//! C(m, n) = sum (I(x, y) - I_mn)(t(x - m, y - n) - t_bar)
//!           / [sum (I(x, y) - I_mn)^2  sum (t(x - m, y - n) - t_bar)^2]^0.5
//! ```
//!
//! A template around a feature of the first image is compared with every position of a search
//! window of the second; the best `C` wins. The paper keeps whole pixels; we refine the peak by
//! a parabola through its neighbours along each axis (ours).

use super::grey::Grey;
use serde::{Deserialize, Serialize};

/// Settings of the matcher (`[vision.forward.odometry.ncc]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NccConfig {
    /// Half the template's side, px.
    pub half_template_px: u32,
    /// Half the search window's side around the predicted position, px.
    pub search_px: u32,
    /// Matches scoring less than this are dropped.
    pub min_score: f64,
}

impl Default for NccConfig {
    fn default() -> Self {
        Self {
            half_template_px: 5,
            search_px: 9,
            min_score: 0.85,
        }
    }
}

/// A match: the position in the second image and its score `C`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NccMatch {
    /// Column (to a fraction of a pixel).
    pub x: f64,
    /// Row.
    pub y: f64,
    /// `C` of eq. (7) at the best whole-pixel position.
    pub score: f64,
}

/// Where the template of `a` around `at` lies in `b`, searched around `predicted`.
pub fn match_ncc(
    a: &Grey,
    b: &Grey,
    at: (u32, u32),
    predicted: (f64, f64),
    config: &NccConfig,
) -> Option<NccMatch> {
    let r = config.half_template_px as i64;
    let (w, h) = (a.width() as i64, a.height() as i64);
    let (ax, ay) = (at.0 as i64, at.1 as i64);
    if ax < r || ay < r || ax + r >= w || ay + r >= h {
        return None;
    }
    let side = (2 * r + 1) as usize;
    let mut t = Vec::with_capacity(side * side);
    for dy in -r..=r {
        for dx in -r..=r {
            t.push(a.get_pixel((ax + dx) as u32, (ay + dy) as u32).0[0] as f64);
        }
    }
    let t_bar = t.iter().sum::<f64>() / t.len() as f64;
    t.iter_mut().for_each(|v| *v -= t_bar);
    let tt: f64 = t.iter().map(|v| v * v).sum();
    if tt < 1e-6 {
        return None;
    }
    // Eq. (7) at the template's centre (m, n) in `b`; `patch` is reused from one to the next.
    let mut patch = Vec::with_capacity(side * side);
    let mut score = |m: i64, n: i64| -> Option<f64> {
        if m < r || n < r || m + r >= w || n + r >= h {
            return None;
        }
        patch.clear();
        let (raw, row_px) = (b.as_raw(), b.width() as usize);
        for y in n - r..=n + r {
            let start = y as usize * row_px + (m - r) as usize;
            patch.extend(raw[start..start + side].iter().map(|&p| p as f64));
        }
        let mean = patch.iter().sum::<f64>() / patch.len() as f64;
        let (mut num, mut ii) = (0.0, 0.0);
        for (p, tv) in patch.iter().zip(&t) {
            num += (p - mean) * tv;
            ii += (p - mean) * (p - mean);
        }
        (ii > 1e-6).then(|| num / (ii * tt).sqrt())
    };
    let (cx, cy) = (predicted.0.round() as i64, predicted.1.round() as i64);
    let s = config.search_px as i64;
    let mut best: Option<(i64, i64, f64)> = None;
    for n in cy - s..=cy + s {
        for m in cx - s..=cx + s {
            if let Some(c) = score(m, n)
                && best.is_none_or(|(_, _, bc)| c > bc)
            {
                best = Some((m, n, c));
            }
        }
    }
    let (m, n, c) = best?;
    if c < config.min_score {
        return None;
    }
    let refine = |lo: Option<f64>, hi: Option<f64>| match (lo, hi) {
        (Some(l), Some(h)) => {
            let den = l - 2.0 * c + h;
            if den < -1e-12 {
                (0.5 * (l - h) / den).clamp(-0.5, 0.5)
            } else {
                0.0
            }
        }
        _ => 0.0,
    };
    Some(NccMatch {
        x: m as f64 + refine(score(m - 1, n), score(m + 1, n)),
        y: n as f64 + refine(score(m, n - 1), score(m, n + 1)),
        score: c,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testing::squares;
    use super::*;

    fn shifts(dx: f64, dy: f64) -> Vec<(f64, f64)> {
        let a = squares(128, 96, 0.0, 0.0);
        let b = squares(128, 96, dx, dy);
        [(48u32, 28u32), (72, 52), (30, 60), (50, 80)]
            .iter()
            .map(|&p| {
                let m = match_ncc(&a, &b, p, (p.0 as f64, p.1 as f64), &NccConfig::default())
                    .expect("matched");
                (m.x - p.0 as f64, m.y - p.1 as f64)
            })
            .collect()
    }

    #[test]
    fn integer_shifts_are_recovered_to_the_pixel() {
        for (dx, dy) in [(3.0, -2.0), (-7.0, 4.0), (0.0, 0.0)] {
            for (u, v) in shifts(dx, dy) {
                assert!(
                    (u - dx).abs() < 0.1 && (v - dy).abs() < 0.1,
                    "({dx},{dy}) -> ({u},{v})"
                );
            }
        }
    }

    #[test]
    fn sub_pixel_shifts_are_recovered_to_a_fraction() {
        for (dx, dy) in [(0.5, 0.0), (2.3, -1.6)] {
            for (u, v) in shifts(dx, dy) {
                assert!(
                    (u - dx).abs() < 0.25 && (v - dy).abs() < 0.25,
                    "({dx},{dy}) -> ({u},{v})"
                );
            }
        }
    }

    #[test]
    fn a_flat_template_is_not_matched() {
        let a = squares(128, 96, 0.0, 0.0);
        assert!(match_ncc(&a, &a, (80, 60), (80.0, 60.0), &NccConfig::default()).is_none());
    }
}
