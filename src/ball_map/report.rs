//! The map's tables (`ball_map.md`), its frames (`ball_map.csv`) and its figure
//! (`ball_map.png`: detection rate and median range error against distance, a curve a camera).

use super::measure::{FrameRow, Occlusion};
use super::stats::{CameraMap, FalseBalls, LOST_BELOW, Rates, Ring};
use crate::report::charts::{Chart, PALETTE, Series, Style, charts_png};
use crate::report::topview::FigureError;
use std::fmt::Write as _;

/// `12.3`, or `-` for none.
fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_string(), |v| format!("{v:.digits$}"))
}

/// A rate as a percentage.
fn pct(v: Option<f64>) -> String {
    num(v.map(|v| 100.0 * v), 1)
}

/// Misses as `reason (n), ...`, or `-`.
fn misses(r: &Rates) -> String {
    if r.misses.is_empty() {
        return "-".into();
    }
    let parts: Vec<String> = r.misses.iter().map(|(k, n)| format!("{k} ({n})")).collect();
    parts.join(", ")
}

/// Where detection falls below 90%, in words.
pub fn lost_words(m: &CameraMap) -> String {
    let last = m.rings.last().map_or(0.0, |r| r.distance_mm);
    match (m.lost_from_mm, m.reaches_90) {
        (Some(d), _) => format!("{d:.0} mm"),
        (None, true) => format!("not within {last:.0} mm"),
        (None, false) => "never reaches 90%".into(),
    }
}

/// The summary table: a row a camera.
pub fn summary_table(maps: &[CameraMap]) -> String {
    let mut s = String::new();
    let target = maps.first().map_or(1000.0, |m| m.target_range_mm);
    let _ = writeln!(
        s,
        "| camera | image, px | body hides the ball within, mm | detected, % of all frames | \
         detected, % in sight | in sight within {target:.0} mm: detected, % | median range \
         error, % | median bearing error, deg | detection below {:.0}% from |",
        100.0 * LOST_BELOW
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for m in maps {
        let w = &m.within_target;
        let _ = writeln!(
            s,
            "| {} | {} x {} | {} | {} | {} | {} | {} | {} | {} |",
            m.camera,
            m.image_px[0],
            m.image_px[1],
            num(m.shadow.map(|b| b.hidden_mm), 0),
            pct(m.all.detection_rate),
            pct(m.unoccluded.detection_rate),
            pct(w.detection_rate),
            num(w.median_range_error_pct, 2),
            num(w.median_bearing_error_deg, 2),
            lost_words(m)
        );
    }
    s
}

/// One camera's table by ring, with a line on its body's shadow and its misses.
pub fn camera_table(m: &CameraMap) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "### {} ({} x {})\n",
        m.camera, m.image_px[0], m.image_px[1]
    );
    match m.shadow {
        Some(b) => {
            let _ = writeln!(
                s,
                "The body hides the ball's top within {:.0} mm and all of it is in view beyond \
                 {:.0} mm (the ray over the body's edge is {:.1} degrees below the horizontal).",
                b.hidden_mm, b.clear_mm, b.grazing_depression_deg
            );
        }
        None => {
            let _ = writeln!(s, "No ray of this camera reaches the floor past the body.");
        }
    }
    let _ = writeln!(
        s,
        "Detection falls below {:.0}% from: {}. Misses in sight: {}.\n",
        100.0 * LOST_BELOW,
        lost_words(m),
        misses(&m.unoccluded)
    );
    let _ = writeln!(
        s,
        "| distance, mm | ball | frames | detected, % | median range error, % | p90 range \
         error, % | median range bias, mm | median bearing error, deg |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in &m.rings {
        let x = &r.rates;
        let _ = writeln!(
            s,
            "| {:.0} | {} | {} | {} | {} | {} | {} | {} |",
            r.distance_mm,
            r.occlusion.map_or("-", Occlusion::name),
            x.frames,
            pct(x.detection_rate),
            num(x.median_range_error_pct, 2),
            num(x.p90_range_error_pct, 2),
            num(x.median_range_bias_mm, 1),
            num(x.median_bearing_error_deg, 2)
        );
    }
    s
}

/// The false balls in one line.
pub fn false_ball_line(camera: &str, f: &FalseBalls) -> String {
    let largest = if f.false_balls > 0 {
        format!(" (largest blob {} px)", f.largest_pixels)
    } else {
        String::new()
    };
    format!(
        "False balls: {} of {} ball-free frames of {camera}{largest}; the others: {}.",
        f.false_balls,
        f.frames,
        misses(&Rates {
            misses: f.misses.clone(),
            ..Rates::default()
        })
    )
}

/// Column names of `ball_map.csv`, in order.
pub const CSV_HEADER: &str = "camera,distance_mm,direction,draw,robot_x_mm,robot_y_mm,\
robot_heading_deg,true_x_mm,true_y_mm,true_range_mm,true_bearing_deg,ball,detected,miss,\
seen_x_mm,seen_y_mm,seen_range_mm,seen_bearing_deg,pixels,range_error_mm,range_error_pct,\
bearing_error_deg";

/// The CSV's rows of one camera's frames (no header).
pub fn csv_rows(camera: &str, rows: &[FrameRow], out: &mut String) {
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.3}"));
    let camera = camera.replace(',', ";");
    for r in rows {
        let seen = r.seen.as_ref();
        let _ = writeln!(
            out,
            "{camera},{},{},{},{:.1},{:.1},{:.3},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.distance_mm,
            r.direction,
            r.draw,
            r.robot[0],
            r.robot[1],
            r.robot[2],
            opt(r.truth_mm.map(|t| t[0])),
            opt(r.truth_mm.map(|t| t[1])),
            opt(r.true_range_mm()),
            opt(r.true_bearing_deg()),
            r.occlusion.map_or("", Occlusion::name),
            u8::from(seen.is_some()),
            r.miss.as_deref().unwrap_or("").replace(',', ";"),
            opt(seen.map(|s| s.position_mm[0])),
            opt(seen.map(|s| s.position_mm[1])),
            opt(seen.map(|s| s.range_mm)),
            opt(seen.map(|s| s.bearing_deg)),
            seen.map_or(String::new(), |s| s.pixels.to_string()),
            opt(r.range_error_mm()),
            opt(r.range_error_pct()),
            opt(r.bearing_error_deg()),
        );
    }
}

/// The CSV of one run's frames, with its header.
pub fn csv(camera: &str, rows: &[FrameRow]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    csv_rows(camera, rows, &mut out);
    out
}

/// The range-error panel's top: the largest median where the whole ball is in view, within 2%
/// to 20%.
fn error_top(maps: &[CameraMap]) -> f64 {
    let most = (maps.iter().flat_map(|m| &m.rings))
        .filter(|r| matches!(r.occlusion, None | Some(Occlusion::Clear)))
        .filter_map(|r| r.rates.median_range_error_pct)
        .fold(0.0, f64::max);
    (1.15 * most).clamp(2.0, 20.0)
}

/// `ball_map.png`: detection rate (of the frames in sight) and median range error (where the
/// whole ball is in view) against distance, a curve a camera; errors above the panel are drawn
/// at its top.
pub fn figure(maps: &[CameraMap]) -> Result<Vec<u8>, FigureError> {
    let far = maps
        .iter()
        .filter_map(|m| m.rings.last())
        .map(|r| r.distance_mm)
        .fold(1000.0, f64::max);
    let top = error_top(maps);
    // A line a camera, then its rings as dots (unlabelled, the first camera's last, so that
    // curves on top of each other stay in sight).
    let curves = |y: &dyn Fn(&Ring) -> Option<f64>| {
        let series = |k: usize, m: &CameraMap, style| Series {
            label: if style == Style::Line {
                m.camera.clone()
            } else {
                String::new()
            },
            rgb: PALETTE[k % PALETTE.len()],
            points: (m.rings.iter())
                .filter_map(|r| Some((r.distance_mm, y(r)?)))
                .collect(),
            style,
        };
        let lines = maps
            .iter()
            .enumerate()
            .map(|(k, m)| series(k, m, Style::Line));
        let dots = maps.iter().enumerate().rev();
        lines
            .chain(dots.map(|(k, m)| series(k, m, Style::Dots)))
            .collect::<Vec<_>>()
    };
    // Detection where the ball is in sight; errors where all of it is (the body biases them
    // where it hides the ball's lower part).
    let rate = |r: &Ring| {
        let shown = r.occlusion != Some(Occlusion::Hidden);
        r.rates.detection_rate.filter(|_| shown).map(|v| 100.0 * v)
    };
    let error = |r: &Ring| {
        let whole = matches!(r.occlusion, None | Some(Occlusion::Clear));
        let e = r.rates.median_range_error_pct.filter(|_| whole);
        e.map(|v| v.min(top))
    };
    let charts = [
        Chart {
            title: "Ball detected, % of frames in sight".into(),
            x_label: "distance, mm".into(),
            y_label: "detected, %".into(),
            x_range: (0.0, far * 1.02),
            y_range: (0.0, 105.0),
            series: curves(&rate),
        },
        Chart {
            title: format!("Median range error, %, whole ball in view (up to {top:.0}%)"),
            x_label: "distance, mm".into(),
            y_label: "range error, %".into(),
            x_range: (0.0, far * 1.02),
            y_range: (0.0, top * 1.05),
            series: curves(&error),
        },
    ];
    charts_png("ball_map.png", &charts, 2, (560, 400))
}
