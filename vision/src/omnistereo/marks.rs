//! Coloured marks (the arena's pillars) in a conical mirror's image.
//!
//! A 90-degree cone images an upright pillar as a radial stripe from the image centre (the
//! height of the cone's tip) out to the image of the pillar's top edge (Sect. 2, Fig. 1). Each
//! pillar has a colour of its own, so a stripe is found and named by colour: every pixel inside
//! the rim is tested for saturation and its chromaticity compared with the palette (the map's
//! colours), which the shading of a surface leaves alone.
//!
//! Per colour the stripe's bearing is the mean azimuth of its pixels around the densest
//! direction (pixels at radius `h` weigh `h`, as their number does). Its outer end, the top
//! edge, is measured on the stripe's central half only (the top rim of a cylinder curves down
//! toward the stripe's sides: over the central half the edge's range stays within 4% of the
//! pillar's radius of the near face's): the edge lies between the outermost pixel of the colour
//! and the nearest pixel beyond it that is not, on the stripe's axis; we take the midpoint.
//! Pixels are sampled at their centres, so without more columns the edge is known to within the
//! pixel spacing along the axis.

use super::numbers::{below, positive, wrap};
use super::rim::MirrorRim;
use crate::VisionError;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Settings of the colour detection (`[vision.omnistereo.marks]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MarkConfig {
    /// A pixel may belong to a mark when `(max - min) / max` of its channels reaches this
    /// (walls and floors are greys or pale tints; the marks are saturated).
    pub min_saturation: f64,
    /// ... and its chromaticity `(r, g) / (r + g + b)` is within this of the mark's colour.
    pub max_chroma_distance: f64,
    /// ... and its brightest channel reaches this, of 255 (the black beyond the rim, with the
    /// sensor's noise, has any saturation and chromaticity).
    pub min_value: u8,
    /// A colour is a mark when at least this many pixels have it.
    pub min_pixels: usize,
    /// Pixels nearer the image centre than this have no usable azimuth, px.
    pub min_radius_px: f64,
    /// A stripe reaching this close to the rim has its top beyond the mirror's view, px.
    pub rim_margin_px: f64,
    /// The colours are first looked for within this fraction of the rim's radius, where every
    /// pillar's stripe starts (see [`detect_marks`]).
    pub seed_fraction: f64,
    /// A colour with too few pixels there is looked for again out to this fraction: a
    /// defocused camera washes out a stripe where it is thinner than its blur, near the centre.
    pub wide_seed_fraction: f64,
}

impl Default for MarkConfig {
    fn default() -> Self {
        Self {
            min_saturation: 0.5,
            max_chroma_distance: 0.08,
            min_value: 48,
            min_pixels: 4,
            min_radius_px: 4.0,
            rim_margin_px: 1.5,
            seed_fraction: 0.12,
            wide_seed_fraction: 0.3,
        }
    }
}

impl MarkConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), VisionError> {
        positive("marks.min_saturation", self.min_saturation)?;
        positive("marks.max_chroma_distance", self.max_chroma_distance)?;
        positive("marks.min_radius_px", self.min_radius_px)?;
        positive("marks.rim_margin_px", self.rim_margin_px)?;
        positive("marks.seed_fraction", self.seed_fraction)?;
        positive("marks.wide_seed_fraction", self.wide_seed_fraction)?;
        below(
            "marks.min_saturation",
            self.min_saturation,
            1.0,
            "must be below 1",
        )
    }
}

/// A mark found in one image.
#[derive(Debug, Clone, PartialEq)]
pub struct ColourMark {
    /// Index of its colour in the palette.
    pub label: usize,
    /// Bearing of the stripe's axis (robot frame, counter-clockwise from x), rad.
    pub bearing_rad: f64,
    /// Half the stripe's angular width, rad.
    pub half_width_rad: f64,
    /// Image radius of the top edge on the axis, px; `None` when the stripe runs to the rim
    /// (the top is beyond the mirror's view).
    pub top_px: Option<f64>,
    /// Pixels of the colour.
    pub pixels: usize,
}

/// Palette chromaticities.
fn chroma(rgb: [u8; 3]) -> [f64; 2] {
    let s = (rgb[0] as f64 + rgb[1] as f64 + rgb[2] as f64).max(1.0);
    [rgb[0] as f64 / s, rgb[1] as f64 / s]
}

/// The palette colour a pixel has, if any.
fn classify(p: [u8; 3], palette: &[[f64; 2]], cfg: &MarkConfig) -> Option<usize> {
    if !saturated(&p, cfg) {
        return None;
    }
    let c = chroma(p);
    let (k, d2) = palette
        .iter()
        .enumerate()
        .map(|(k, q)| (k, (c[0] - q[0]).powi(2) + (c[1] - q[1]).powi(2)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    (d2 <= cfg.max_chroma_distance * cfg.max_chroma_distance).then_some(k)
}

/// Seed pixels a colour needs to be looked for as a stripe.
const MIN_SEEDS: usize = 3;

/// Finds the marks of `palette`'s colours in `img`, whose mirror rim is `rim`: at most one a
/// colour (the densest direction of it).
///
/// Every pillar's stripe starts at the image centre, so the colours are first looked for in the
/// small disc within `seed_fraction` of the rim's radius (pixels nearer than `min_radius_px`
/// left out), then each stripe is measured on the pixels of the wedge around the direction it
/// was seen in: a tenth of the image's pixels instead of all of them. Near the centre a stripe
/// is a pixel or less wide, and a defocused lens mixes it with the floor until no pixel keeps
/// its colour: a colour found there on fewer than three pixels is looked for again within
/// `wide_seed_fraction` of the rim's radius, where the stripe is wider.
pub fn detect_marks(
    img: &RgbaImage,
    rim: &MirrorRim,
    palette: &[[u8; 3]],
    cfg: &MarkConfig,
) -> Vec<ColourMark> {
    let chromas: Vec<[f64; 2]> = palette.iter().map(|c| chroma(*c)).collect();
    let near = (cfg.seed_fraction * rim.radius_px).max(cfg.min_radius_px + 4.0);
    let mut seeds: Vec<(f64, Vec<[f64; 2]>)> = coloured_pixels(img, rim, near, &chromas, cfg)
        .into_iter()
        .map(|pts| (near, pts))
        .collect();
    let wide = (cfg.wide_seed_fraction * rim.radius_px).max(near);
    if wide > near && seeds.iter().any(|(_, pts)| pts.len() < MIN_SEEDS) {
        let again = coloured_pixels(img, rim, wide, &chromas, cfg);
        for ((r, pts), more) in seeds.iter_mut().zip(again) {
            if pts.len() < MIN_SEEDS {
                (*r, *pts) = (wide, more);
            }
        }
    }
    let mut marks = Vec::new();
    for (label, (seed_radius, pts)) in seeds.iter().enumerate() {
        let seed_radius = *seed_radius;
        let Some((axis, _)) = densest_direction(pts, cfg).filter(|_| pts.len() >= MIN_SEEDS) else {
            continue;
        };
        // The stripe's half-angle: each seed pixel's angle off the axis, less its own angular
        // size (half a pixel's diagonal over its radius), which near the centre is large.
        let spread = pts
            .iter()
            .map(|p| {
                let h = p[0].hypot(p[1]).max(cfg.min_radius_px);
                wrap(p[1].atan2(p[0]) - axis).abs() - 0.71 / h
            })
            .filter(|d| *d < 6f64.to_radians())
            .fold(0.0, f64::max);
        let half = (1.3 * spread + 1.0 / seed_radius).clamp(0.02, 0.35);
        let pixels = wedge_pixels(img, rim, axis, half, label, &chromas, cfg);
        if pixels.len() < cfg.min_pixels {
            continue;
        }
        if let Some(m) = stripe(label, axis, &pixels, img, rim, &chromas, cfg) {
            marks.push(m);
        }
    }
    marks
}

/// The densest direction of `pts` (2-degree bins, a peak and its neighbours) and the largest
/// angle of a pixel within 6 degrees of it from it, rad; pixels nearer the centre than
/// `min_radius_px` are left out.
fn densest_direction(pts: &[[f64; 2]], cfg: &MarkConfig) -> Option<(f64, f64)> {
    const BINS: usize = 180;
    let angles: Vec<f64> = pts
        .iter()
        .filter(|p| p[0].hypot(p[1]) >= cfg.min_radius_px)
        .map(|p| p[1].atan2(p[0]))
        .collect();
    if angles.is_empty() {
        return None;
    }
    let bin = |a: f64| (((a + PI) / (2.0 * PI) * BINS as f64) as usize).min(BINS - 1);
    let mut hist = [0usize; BINS];
    angles.iter().for_each(|a| hist[bin(*a)] += 1);
    let peak =
        (0..BINS).max_by_key(|&k| hist[k] + hist[(k + 1) % BINS] + hist[(k + BINS - 1) % BINS])?;
    let peak_rad = (peak as f64 + 0.5) / BINS as f64 * 2.0 * PI - PI;
    let near: Vec<f64> = angles
        .iter()
        .map(|a| wrap(a - peak_rad))
        .filter(|d| d.abs() <= 6f64.to_radians())
        .collect();
    let mean = near.iter().sum::<f64>() / near.len().max(1) as f64;
    let spread = near.iter().map(|d| (d - mean).abs()).fold(0.0, f64::max);
    Some((wrap(peak_rad + mean), spread))
}

/// Whether pixel `px` passes the grey test: bright enough and saturated enough.
fn saturated(px: &[u8], cfg: &MarkConfig) -> bool {
    let (mx, mn) = (px[0].max(px[1]).max(px[2]), px[0].min(px[1]).min(px[2]));
    // (max - min) / max >= min_saturation, in integers.
    let sat_q = (cfg.min_saturation * 256.0).ceil() as u32;
    mx >= cfg.min_value.max(1) && ((mx - mn) as u32) * 256 >= sat_q * mx as u32
}

/// Image coordinates `(X, Y)` of the pixels of each palette colour within `radius` of the
/// rim's centre.
fn coloured_pixels(
    img: &RgbaImage,
    rim: &MirrorRim,
    radius: f64,
    chromas: &[[f64; 2]],
    cfg: &MarkConfig,
) -> Vec<Vec<[f64; 2]>> {
    let mut out = vec![Vec::new(); chromas.len()];
    let (w, h) = (img.width() as usize, img.height() as usize);
    let [cx, cy] = rim.centre_px;
    let r = radius.min(rim.radius_px);
    let v0 = (cy - r).floor().max(0.0) as usize;
    let v1 = ((cy + r).ceil().max(0.0) as usize).min(h);
    let raw = img.as_raw();
    for v in v0..v1 {
        let dy = v as f64 + 0.5 - cy;
        let half = (r * r - dy * dy).max(0.0).sqrt();
        let u0 = (cx - half).floor().max(0.0) as usize;
        let u1 = ((cx + half).ceil().max(0.0) as usize).min(w);
        if u0 >= u1 {
            continue;
        }
        let row = &raw[4 * (v * w + u0)..4 * (v * w + u1)];
        for (j, px) in row.chunks_exact(4).enumerate() {
            if let Some(k) = classify([px[0], px[1], px[2]], chromas, cfg) {
                let (x, y) = rim.image_coords((u0 + j) as f64, v as f64);
                out[k].push([x, y]);
            }
        }
    }
    out
}

/// Image coordinates of the pixels of colour `label` inside the rim whose centres lie within
/// `half` of direction `axis`, or within 1.5 px of that wedge, from the centre out to a few
/// lines past the stripe's end.
///
/// The wedge is the intersection of two half-planes, `cross(u0, p) >= -m` and
/// `cross(p, u1) >= -m` (`u0`, `u1` its edges' directions, `m` the margin). It is scanned line
/// by line from the centre outward, rows when the axis is nearer the image's y axis, columns
/// otherwise, each line an interval; the scan stops six lines after the last that held the
/// colour (the stripe has ended).
fn wedge_pixels(
    img: &RgbaImage,
    rim: &MirrorRim,
    axis: f64,
    half: f64,
    label: usize,
    chromas: &[[f64; 2]],
    cfg: &MarkConfig,
) -> Vec<[f64; 2]> {
    const MARGIN_PX: f64 = 1.5;
    const PAST_END: usize = 6;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let raw = img.as_raw();
    let [cx, cy] = rim.centre_px;
    let r = rim.radius_px;
    let (u0, u1) = (
        [(axis - half).cos(), (axis - half).sin()],
        [(axis + half).cos(), (axis + half).sin()],
    );
    let rows = axis.sin().abs() > axis.cos().abs();
    // Lines from the centre outward along the axis: rows go up (v falls) when the axis points
    // up (Y up); columns go right when it points right.
    let (lines, centre_line, step): (usize, f64, i64) = if rows {
        (h, cy - 0.5, if axis.sin() > 0.0 { -1 } else { 1 })
    } else {
        (w, cx - 0.5, if axis.cos() > 0.0 { 1 } else { -1 })
    };
    let start = (centre_line.round() as i64 - 2 * step).clamp(0, lines as i64 - 1);
    let mut out = Vec::new();
    let (mut seen, mut misses) = (false, 0);
    let mut line = start;
    while (0..lines as i64).contains(&line) && !(seen && misses >= PAST_END) {
        let l = line as usize;
        line += step;
        // Major coordinate of the line, and the constraints a n + b >= 0 on the minor one.
        let major = if rows {
            cy - (l as f64 + 0.5)
        } else {
            l as f64 + 0.5 - cx
        };
        if major.abs() >= r {
            break;
        }
        let chord = (r * r - major * major).sqrt();
        let (mut lo, mut hi) = (-chord, chord);
        let edges = if rows {
            [
                (-u0[1], u0[0] * major + MARGIN_PX),
                (u1[1], -u1[0] * major + MARGIN_PX),
            ]
        } else {
            [
                (u0[0], -u0[1] * major + MARGIN_PX),
                (-u1[0], u1[1] * major + MARGIN_PX),
            ]
        };
        for (a, b) in edges {
            if a > 1e-12 {
                lo = lo.max(-b / a);
            } else if a < -1e-12 {
                hi = hi.min(-b / a);
            } else if b < 0.0 {
                hi = lo - 1.0;
            }
        }
        let before = out.len();
        if lo <= hi {
            // Minor coordinate to pixel index: X = u + 0.5 - cx; Y = cy - v - 0.5.
            let (first, last) = if rows {
                (lo + cx - 0.5, hi + cx - 0.5)
            } else {
                (cy - hi - 0.5, cy - lo - 0.5)
            };
            let limit = if rows { w } else { h } as f64 - 1.0;
            let (first, last) = (first.ceil().max(0.0), last.floor().min(limit));
            if first <= last {
                for i in first as usize..=last as usize {
                    let (u, v) = if rows { (i, l) } else { (l, i) };
                    let k = 4 * (v * w + u);
                    let px = [raw[k], raw[k + 1], raw[k + 2]];
                    if classify(px, chromas, cfg) == Some(label) {
                        let (x, y) = rim.image_coords(u as f64, v as f64);
                        out.push([x, y]);
                    }
                }
            }
        }
        if out.len() > before {
            seen = true;
            misses = 0;
        } else {
            misses += 1;
        }
    }
    out
}

/// The stripe of one colour: its densest direction, bearing, width and top edge.
fn stripe(
    label: usize,
    seed_axis: f64,
    pts: &[[f64; 2]],
    img: &RgbaImage,
    rim: &MirrorRim,
    chromas: &[[f64; 2]],
    cfg: &MarkConfig,
) -> Option<ColourMark> {
    // Angles off the seed's axis without a trigonometric call a pixel: atan(t) by its series,
    // t = across / along <= tan(6 deg) here, to 1e-7 rad.
    let axis0 = [seed_axis.cos(), seed_axis.sin()];
    let max_t = 6f64.to_radians().tan();
    let near: Vec<([f64; 2], f64)> = pts
        .iter()
        .filter_map(|p| {
            let (a, c) = along_across(*p, axis0);
            let t = c / a;
            (a >= cfg.min_radius_px && t.abs() <= max_t).then(|| {
                let t2 = t * t;
                (*p, t * (1.0 - t2 / 3.0 + t2 * t2 / 5.0))
            })
        })
        .collect();
    if near.len() < cfg.min_pixels {
        return None;
    }
    let mean = near.iter().map(|x| x.1).sum::<f64>() / near.len() as f64;
    let outer = near
        .iter()
        .map(|x| along_across(x.0, axis0).0)
        .fold(1.0, f64::max);
    let half_width = near
        .iter()
        .map(|x| (x.1 - mean).abs())
        .fold(0.0, f64::max)
        .max(0.25 / outer);
    let bearing = wrap(seed_axis + mean);
    let axis = [bearing.cos(), bearing.sin()];
    let pixels: Vec<[f64; 2]> = near.iter().map(|x| x.0).collect();
    let top = top_edge(label, &pixels, axis, half_width, img, rim, chromas, cfg);
    Some(ColourMark {
        label,
        bearing_rad: bearing,
        half_width_rad: half_width,
        top_px: top,
        pixels: pts.len(),
    })
}

/// Projection of `p` on the axis and its offset across it.
fn along_across(p: [f64; 2], axis: [f64; 2]) -> (f64, f64) {
    (
        p[0] * axis[0] + p[1] * axis[1],
        -p[0] * axis[1] + p[1] * axis[0],
    )
}

/// The top edge on the stripe's axis: the midpoint between the outermost pixel of the colour
/// in the central band and the nearest pixel beyond it, on the band, that is not of it.
#[allow(clippy::too_many_arguments)]
fn top_edge(
    label: usize,
    near: &[[f64; 2]],
    axis: [f64; 2],
    half_width_rad: f64,
    img: &RgbaImage,
    rim: &MirrorRim,
    chromas: &[[f64; 2]],
    cfg: &MarkConfig,
) -> Option<f64> {
    let outer = near
        .iter()
        .map(|p| along_across(*p, axis).0)
        .fold(0.0, f64::max);
    if outer >= rim.radius_px - cfg.rim_margin_px {
        return None;
    }
    // The central half of the stripe, and never narrower than a pixel's half-diagonal.
    let band = (0.5 * half_width_rad * outer).max(0.71);
    let lo = near
        .iter()
        .map(|p| along_across(*p, axis))
        .filter(|(a, c)| c.abs() <= band && *a >= outer - 4.0)
        .map(|(a, _)| a)
        .fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        return Some(outer + 0.5);
    }
    // Pixels of another colour on the band's centre line just beyond `lo`.
    let centre = [axis[0] * lo, axis[1] * lo];
    let [cx, cy] = rim.centre_px;
    let (w, h) = img.dimensions();
    let mut hi = f64::INFINITY;
    let reach = 3i64;
    let (u0, v0) = (
        (cx + centre[0]).floor() as i64,
        (cy - centre[1]).floor() as i64,
    );
    for v in v0 - reach..=v0 + reach {
        for u in u0 - reach..=u0 + reach {
            if u < 0 || v < 0 || u >= w as i64 || v >= h as i64 {
                continue;
            }
            let p = rim.image_coords(u as f64, v as f64);
            let (a, c) = along_across([p.0, p.1], axis);
            if a <= lo || c.abs() > band.min(0.71) {
                continue;
            }
            let px = img.get_pixel(u as u32, v as u32).0;
            if classify([px[0], px[1], px[2]], chromas, cfg) != Some(label) {
                hi = hi.min(a);
            }
        }
    }
    let spacing = 1.0 / axis[0].abs().max(axis[1].abs());
    Some(if hi.is_finite() && hi - lo <= 2.0 * spacing {
        0.5 * (lo + hi)
    } else {
        lo + 0.5 * spacing
    })
}

#[cfg(test)]
mod tests {
    use super::super::rim::synthetic_disc;
    use super::*;
    use image::Rgba;

    /// A disc, grey inside, with a red wedge of half-width `hw` at `bearing` out to radius
    /// `top`.
    fn wedge(bearing: f64, hw: f64, top: f64) -> (RgbaImage, MirrorRim) {
        synthetic_disc(|h, a| {
            if h < top && wrap(a - bearing).abs() < hw {
                Rgba([200, 30, 25, 255])
            } else {
                Rgba([180, 175, 160, 255])
            }
        })
    }

    #[test]
    fn finds_the_bearing_and_top_of_a_wedge() {
        let palette = [[30, 200, 40], [220, 30, 30]];
        for (bearing, hw, top) in [(0.3, 0.05, 120.0), (-2.0, 0.02, 61.3), (3.1, 0.1, 150.7)] {
            let (img, rim) = wedge(bearing, hw, top);
            let marks = detect_marks(&img, &rim, &palette, &MarkConfig::default());
            assert_eq!(marks.len(), 1, "{marks:?}");
            let m = &marks[0];
            assert_eq!(m.label, 1);
            assert!(wrap(m.bearing_rad - bearing).abs() < 0.005, "{m:?}");
            let t = m.top_px.unwrap();
            assert!((t - top).abs() < 0.8, "top {t} vs {top}");
        }
    }

    #[test]
    fn a_wedge_to_the_rim_has_no_top() {
        let (img, rim) = wedge(1.0, 0.05, 300.0);
        let marks = detect_marks(&img, &rim, &[[220, 30, 30]], &MarkConfig::default());
        assert_eq!(marks.len(), 1);
        assert_eq!(marks[0].top_px, None);
    }

    #[test]
    fn greys_are_no_marks() {
        let (img, rim) = wedge(1.0, 0.0, 0.0);
        assert!(detect_marks(&img, &rim, &[[220, 30, 30]], &MarkConfig::default()).is_empty());
    }
}
