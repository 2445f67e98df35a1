//! Obstacle avoidance by ground segmentation (Sect. 2.1.1, Figs. 2 and 5).
//!
//! The ground region is grown from the bottom of the image (the paper's middle bottom, which
//! the robot's speed keeps clear of obstacles) over pixels within a tolerance of the ground's
//! level, tracked over the last few frames: a sudden change of the level at the bottom centre
//! means an obstacle is right in front, and the region is then grown from the tracked level
//! instead. The visible ground map fills each column upward from the bottom until the first
//! pixel that is not ground and is dilated; the robot goes straight while more than 30 ground
//! pixels (scaled with the image height; the paper's images are 120 rows high) lie ahead.
//!
//! "Ahead" is ours where the paper says "from the centre bottom": every column that images the
//! robot's path (its width, at the floor row 30 pixels up) must show that many, so an obstacle
//! off the centre line but in the robot's way stops it too. The sides' clearances are the mean
//! run of ground over the left and the right half.

use super::camera::ForwardCamera;
use super::grey::Grey;
use image::{GrayImage, Luma};
use imageproc::distance_transform::Norm;
use nalgebra::Point2;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Settings of the segmentation (`[vision.forward.ground]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GroundConfig {
    /// A pixel is ground when its level is within this of the ground's, grey levels.
    pub tolerance: f32,
    /// A change of the bottom centre's level by more than this from the tracked level is an
    /// obstacle in front ("a sudden change in the intensity").
    pub jump: f32,
    /// Frames over which the ground level is tracked.
    pub history: usize,
    /// Ground pixels needed ahead to go straight at the reference height (the paper's 30).
    pub ahead_px: f64,
    /// The image height `ahead_px` is for.
    pub reference_height_px: f64,
    /// Gaussian smoothing before segmentation, px (0: none).
    pub smooth_sigma_px: f32,
    /// Dilation of the visible ground map, px.
    pub dilate_px: u8,
}

impl Default for GroundConfig {
    fn default() -> Self {
        Self {
            tolerance: 28.0,
            jump: 40.0,
            history: 5,
            ahead_px: 30.0,
            reference_height_px: 120.0,
            smooth_sigma_px: 1.0,
            dilate_px: 1,
        }
    }
}

/// What the segmentation of one frame shows.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundView {
    /// The visible ground map (255 ground, 0 not).
    pub map: GrayImage,
    /// The fewest ground pixels from the bottom over the columns of the robot's path.
    pub ahead_px: u32,
    /// Ground pixels needed ahead to go straight (the paper's 30, scaled).
    pub needed_px: u32,
    /// Mean run of ground from the bottom over the left half of the image, px.
    pub left_px: f64,
    /// The same over the right half.
    pub right_px: f64,
    /// The ground level the region was grown from.
    pub ground_level: f32,
    /// Whether the bottom centre's level jumped away from the tracked ground level.
    pub jumped: bool,
}

impl GroundView {
    /// Whether the way ahead is clear: more ground pixels ahead than needed.
    pub fn clear_ahead(&self) -> bool {
        self.ahead_px > self.needed_px
    }
}

/// The segmentation of one camera, with the ground level it tracks.
#[derive(Debug, Clone)]
pub struct GroundSegmenter {
    config: GroundConfig,
    levels: VecDeque<f32>,
    /// Columns that image the robot's path at the row `needed` pixels up.
    path_columns: Vec<u32>,
    needed_px: u32,
}

impl GroundSegmenter {
    /// A segmenter for `camera` on a robot `body_width_mm` wide.
    pub fn new(camera: &ForwardCamera, body_width_mm: f64, config: GroundConfig) -> Self {
        let h = camera.height_px;
        let needed_px = ((config.ahead_px * h as f64 / config.reference_height_px).round() as u32)
            .clamp(1, h - 1);
        let row = (h - 1 - needed_px) as f64;
        let half = 0.5 * body_width_mm;
        let mut path_columns: Vec<u32> = (0..camera.width_px)
            .filter(|&x| {
                camera
                    .floor_point(x as f64, row)
                    .is_some_and(|p: Point2<f64>| p.y.abs() <= half)
            })
            .collect();
        if path_columns.is_empty() {
            path_columns.push(camera.width_px / 2);
        }
        Self {
            config,
            levels: VecDeque::new(),
            path_columns,
            needed_px,
        }
    }

    /// The columns that image the robot's path.
    pub fn path_columns(&self) -> &[u32] {
        &self.path_columns
    }

    /// Segments one frame and updates the tracked ground level.
    pub fn update(&mut self, image: &Grey) -> GroundView {
        let c = &self.config;
        let img = if c.smooth_sigma_px > 0.0 {
            imageproc::filter::gaussian_blur_f32(image, c.smooth_sigma_px)
        } else {
            image.clone()
        };
        let (w, h) = img.dimensions();
        let seed = bottom_centre_level(&img);
        let tracked = (!self.levels.is_empty())
            .then(|| self.levels.iter().sum::<f32>() / self.levels.len() as f32);
        let jumped = tracked.is_some_and(|t| (seed - t).abs() > c.jump);
        let level = match tracked {
            Some(t) if jumped => t,
            _ => seed,
        };
        let region = grow(&img, level, c.tolerance);
        if !jumped {
            self.levels.push_back(seed);
            while self.levels.len() > c.history.max(1) {
                self.levels.pop_front();
            }
        }
        let mut map = GrayImage::new(w, h);
        let mut runs = vec![0u32; w as usize];
        for x in 0..w {
            let mut y = h;
            while y > 0 && region[((y - 1) * w + x) as usize] {
                y -= 1;
                map.put_pixel(x, y, Luma([255]));
            }
            runs[x as usize] = h - y;
        }
        if c.dilate_px > 0 {
            map = imageproc::morphology::dilate(&map, Norm::LInf, c.dilate_px);
        }
        let ahead_px = self
            .path_columns
            .iter()
            .map(|&x| runs[x as usize])
            .min()
            .unwrap_or(0);
        let half = (w / 2) as usize;
        let mean = |r: &[u32]| r.iter().map(|&v| v as f64).sum::<f64>() / r.len().max(1) as f64;
        GroundView {
            map,
            ahead_px,
            needed_px: self.needed_px,
            left_px: mean(&runs[..half]),
            right_px: mean(&runs[half..]),
            ground_level: level,
            jumped,
        }
    }
}

/// The median level of the bottom three rows' middle eighth.
fn bottom_centre_level(img: &Grey) -> f32 {
    let (w, h) = img.dimensions();
    let (x0, x1) = (w / 2 - (w / 16).max(1), w / 2 + (w / 16).max(1));
    let mut v: Vec<f32> = (h.saturating_sub(3)..h)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| img.get_pixel(x, y).0[0])
        .collect();
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

/// The region of pixels within `tolerance` of `level` 4-connected to the bottom row.
fn grow(img: &Grey, level: f32, tolerance: f32) -> Vec<bool> {
    let (w, h) = img.dimensions();
    let ground = |x: u32, y: u32| (img.get_pixel(x, y).0[0] - level).abs() <= tolerance;
    let mut region = vec![false; (w * h) as usize];
    let mut stack: Vec<(u32, u32)> = Vec::new();
    for x in 0..w {
        if ground(x, h - 1) {
            region[((h - 1) * w + x) as usize] = true;
            stack.push((x, h - 1));
        }
    }
    while let Some((x, y)) = stack.pop() {
        let mut visit = |xx: u32, yy: u32| {
            let i = (yy * w + xx) as usize;
            if !region[i] && ground(xx, yy) {
                region[i] = true;
                stack.push((xx, yy));
            }
        };
        if x > 0 {
            visit(x - 1, y);
        }
        if x + 1 < w {
            visit(x + 1, y);
        }
        if y > 0 {
            visit(x, y - 1);
        }
        if y + 1 < h {
            visit(x, y + 1);
        }
    }
    region
}

#[cfg(test)]
mod tests {
    use super::super::testing::camera;
    use super::*;

    /// A light floor with a dark block whose bottom edge is at row `bottom` between columns
    /// `x0..x1`.
    fn scene(x0: u32, x1: u32, bottom: u32) -> Grey {
        Grey::from_fn(160, 120, |x, y| {
            let block = (x0..x1).contains(&x) && y < bottom;
            Luma([if block { 60.0 } else { 200.0 }])
        })
    }

    #[test]
    fn a_block_in_the_path_stops_the_robot_and_the_clearer_side_is_found() {
        let c = camera();
        let mut g = GroundSegmenter::new(&c, 120.0, GroundConfig::default());
        // The path covers the middle of the image, not its edges.
        let cols = g.path_columns();
        assert!(cols.contains(&80) && !cols.contains(&0) && !cols.contains(&159));
        let free = g.update(&scene(0, 0, 0));
        assert!(
            free.clear_ahead() && free.ahead_px == 120,
            "{}",
            free.ahead_px
        );
        // A block 100 rows deep (20 rows of ground below it) on the left half.
        let v = g.update(&scene(30, 90, 100));
        assert_eq!(v.needed_px, 30);
        assert!(!v.clear_ahead(), "ahead {}", v.ahead_px);
        assert!(v.right_px > v.left_px, "{} {}", v.left_px, v.right_px);
        // The same block far up the image leaves the way clear.
        let v = g.update(&scene(30, 90, 60));
        assert!(v.clear_ahead());
        // Outside the path (image edge), it does not count.
        let v = g.update(&scene(0, 8, 115));
        assert!(v.clear_ahead());
    }

    #[test]
    fn an_obstacle_filling_the_bottom_centre_is_a_sudden_change() {
        let c = camera();
        let mut g = GroundSegmenter::new(&c, 120.0, GroundConfig::default());
        for _ in 0..3 {
            g.update(&scene(0, 0, 0));
        }
        let v = g.update(&scene(40, 120, 120));
        assert!(v.jumped);
        assert_eq!(v.ahead_px, 0);
        assert!((v.ground_level - 200.0).abs() < 1.0);
        assert!(v.map.get_pixel(5, 119).0[0] == 255 && v.map.get_pixel(80, 119).0[0] == 0);
    }
}
