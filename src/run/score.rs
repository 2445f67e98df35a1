//! Scoring against the truth, on the simulator's side: which targets the robot really reached,
//! how far its free space and pose estimates were from the world.

use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::GoalSpec;
use omniloop_sim::World;
use omniloop_sim::render::TruthFrame;
use omniloop_vision::{FloorPixels, FreeSpace};
use serde::Serialize;

/// The truth-side record of a run.
#[derive(Debug, Clone, Default)]
pub struct TruthScore {
    targets: Vec<Point2<f64>>,
    tolerance_mm: f64,
    reached: Vec<bool>,
    time_to_goal_s: Option<f64>,
    freespace_errors_mm: Vec<f64>,
    pose_errors_mm: Vec<f64>,
    checkpoints: Vec<Point2<f64>>,
    checkpoint_radius_mm: f64,
    /// The heading error at the last cycle of the visit in progress, if one is.
    visit: Option<f64>,
    visit_errors_deg: Vec<f64>,
    floor_ious: Vec<f64>,
}

/// The free-space stage's floor region against the truth's, pixel by pixel, in one cycle: over
/// the template's pixels, the stage's cleaned floor mask (step 1 of Sect. 3.1 of the corner
/// paper) against the pixels whose truth is the floor region (bare floor or its lines).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloorRegionScore {
    /// |estimated AND true| / |estimated OR true| (1 where both are empty).
    pub iou: f64,
    /// Share of the template's pixels judged floor that are not the floor region.
    pub false_free: f64,
    /// Share of the template's pixels of the floor region judged not floor.
    pub false_blocked: f64,
    /// Per direction, the free distance (mm from the sensor axis) that eqs. (5)-(7) give on the
    /// true floor region: what the stage would say were its step 1 perfect.
    pub free_label_mm: Vec<f64>,
    /// Per direction, the free distance in the world (ray cast from the sensor axis, clipped at
    /// the template's range): the geometric truth.
    pub free_true_mm: Vec<f64>,
}

impl FloorRegionScore {
    /// Scores `pixels` (the stage's judgement of a frame) against `truth` (the same frame's),
    /// with the geometric truth `free_true_mm` beside.
    pub fn of(pixels: &FloorPixels, truth: &TruthFrame, free_true_mm: Vec<f64>) -> Self {
        let (w, h) = (truth.width as usize, truth.height as usize);
        let mut true_floor = vec![0u8; pixels.floor.len()];
        let [mut both, mut est_only, mut true_only, mut n] = [0usize; 4];
        for (k, u, v) in pixels.template_pixels() {
            if u >= w || v >= h {
                continue;
            }
            let t = truth.is_floor_region(v * w + u);
            let e = pixels.floor[k] != 0;
            true_floor[k] = u8::from(t);
            n += 1;
            both += usize::from(t && e);
            est_only += usize::from(e && !t);
            true_only += usize::from(t && !e);
        }
        let union = both + est_only + true_only;
        let share = |c: usize| c as f64 / n.max(1) as f64;
        let (_, a) = pixels.template.judge(&true_floor, pixels.r_th);
        let edges = pixels.template.edges_mm();
        Self {
            iou: if union == 0 {
                1.0
            } else {
                both as f64 / union as f64
            },
            false_free: share(est_only),
            false_blocked: share(true_only),
            free_label_mm: a.iter().map(|&i| edges[i]).collect(),
            free_true_mm,
        }
    }
}

impl TruthScore {
    /// A score for the targets of `goal`, if any.
    pub fn new(goal: Option<&GoalSpec>) -> Self {
        let targets = goal.map_or(Vec::new(), GoalSpec::targets);
        Self {
            reached: vec![false; targets.len()],
            tolerance_mm: goal.map_or(0.0, |g| g.tolerance_mm),
            targets,
            checkpoints: goal.map_or(Vec::new(), |g| {
                g.checkpoints_mm
                    .iter()
                    .map(|c| Point2::new(c[0], c[1]))
                    .collect()
            }),
            checkpoint_radius_mm: goal.map_or(0.0, |g| g.checkpoint_radius_mm),
            ..Self::default()
        }
    }

    /// After a cycle whose pose estimate was `estimate` and true pose `truth`: a visit to a
    /// checkpoint lasts while the estimate is within the goal's `checkpoint_radius_mm` of
    /// one (the robot reads its heading there), and is scored by the heading error at its
    /// last cycle.
    pub fn checkpoint(&mut self, estimate: &Isometry2<f64>, truth: &Isometry2<f64>) {
        let here = Point2::from(estimate.translation.vector);
        let inside = self
            .checkpoints
            .iter()
            .any(|c| (c - here).norm() <= self.checkpoint_radius_mm);
        if inside {
            let err = wrap_pi(estimate.rotation.angle() - truth.rotation.angle());
            self.visit = Some(err.to_degrees());
        } else if let Some(err) = self.visit.take() {
            self.visit_errors_deg.push(err.abs());
        }
    }

    /// The heading error at the end of each checkpoint visit, degrees (`None` without
    /// checkpoints).
    pub fn checkpoint_heading_errors_deg(&self) -> Option<Vec<f64>> {
        (!self.checkpoints.is_empty()).then(|| {
            self.visit_errors_deg
                .iter()
                .copied()
                .chain(self.visit.map(f64::abs))
                .collect()
        })
    }

    /// After a cycle in which the robot headed for target `heading_for` (when its software
    /// does not say, the first target not reached yet), ending at `p` at time `t_s`: the target
    /// counts as reached when the robot centre is within the tolerance of it. Reaching the last
    /// target (the goal) sets the time to goal.
    pub fn targets(&mut self, p: Point2<f64>, heading_for: Option<usize>, t_s: f64) {
        let next = || self.reached.iter().position(|r| !r);
        let Some(i) = heading_for
            .or_else(next)
            .filter(|&i| i < self.targets.len())
        else {
            return;
        };
        if (p - self.targets[i]).norm() <= self.tolerance_mm {
            self.reached[i] = true;
            if i + 1 == self.targets.len() && self.time_to_goal_s.is_none() {
                self.time_to_goal_s = Some(t_s);
            }
        }
    }

    /// The target the robot is on: the first not reached yet (the number of targets once all
    /// are).
    pub fn current_target(&self) -> usize {
        self.reached
            .iter()
            .position(|r| !r)
            .unwrap_or(self.reached.len())
    }

    /// When the goal was reached.
    pub fn time_to_goal_s(&self) -> Option<f64> {
        self.time_to_goal_s
    }

    /// With waypoints: how many of the targets were reached.
    pub fn targets_reached(&self) -> Option<usize> {
        (self.targets.len() > 1).then(|| self.reached.iter().filter(|&&r| r).count())
    }

    /// Compares detected free distances with the world's, direction by direction, for robot
    /// `body` at `pose` whose camera axis sits at `mount_mm` (truth clipped at the template's
    /// range; every other robot is an obstacle). Returns the true distances.
    pub fn freespace(
        &mut self,
        world: &World,
        body: usize,
        pose: &Isometry2<f64>,
        mount_mm: [f64; 2],
        fs: &FreeSpace,
    ) -> Vec<f64> {
        let axis = pose * Point2::new(mount_mm[0], mount_mm[1]);
        let heading = pose.rotation.angle();
        let mut truths = Vec::with_capacity(fs.free_mm.len());
        for (a, free) in fs.direction_rad.iter().zip(&fs.free_mm) {
            let dir = Vector2::new((heading + a).cos(), (heading + a).sin());
            let truth = world
                .ray_cast_mm(axis, dir, fs.range_mm, Some(body))
                .unwrap_or(fs.range_mm);
            self.freespace_errors_mm.push((free - truth).abs());
            truths.push(truth);
        }
        truths
    }

    /// Records a cycle's pixel-level score of the floor region.
    pub fn floor_region(&mut self, score: &FloorRegionScore) {
        self.floor_ious.push(score.iou);
    }

    /// Median over the run of the floor region's intersection over union.
    pub fn floor_region_iou(&self) -> Option<f64> {
        median(&self.floor_ious)
    }

    /// Records the distance of a pose estimate from the true position.
    pub fn pose(&mut self, estimate: Point2<f64>, truth: Point2<f64>) {
        self.pose_errors_mm
            .push((estimate.x - truth.x).hypot(estimate.y - truth.y));
    }

    /// Median |detected - true| free distance over all directions of the run.
    pub fn freespace_error_mm(&self) -> Option<f64> {
        median(&self.freespace_errors_mm)
    }

    /// Median distance of the pose estimate from the truth over the run.
    pub fn pose_error_mm(&self) -> Option<f64> {
        median(&self.pose_errors_mm)
    }
}

/// The `q` quantile of `values` (0.95: the 95th percentile), nearest rank on the sorted values
/// (`None` when empty).
pub fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    v.get(((v.len() as f64 - 1.0) * q.clamp(0.0, 1.0)).round() as usize)
        .copied()
}

/// The median of `values` (`None` when empty).
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_target_counts_only_while_the_robot_heads_for_it() {
        let goal = GoalSpec {
            waypoints_mm: vec![[1000.0, 0.0]],
            ..GoalSpec::to([0.0, 500.0], 100.0)
        };
        let mut s = TruthScore::new(Some(&goal));
        // Passing the goal while heading for the waypoint does not reach the goal.
        s.targets(Point2::new(0.0, 450.0), Some(0), 1.0);
        assert_eq!((s.targets_reached(), s.time_to_goal_s()), (Some(0), None));
        assert_eq!(s.current_target(), 0);
        // The robot believed it reached the waypoint 150 mm short of it: not reached.
        s.targets(Point2::new(850.0, 0.0), Some(0), 2.0);
        s.targets(Point2::new(0.0, 480.0), Some(1), 3.0);
        s.targets(Point2::new(0.0, 500.0), Some(1), 3.5);
        assert_eq!(
            (s.targets_reached(), s.time_to_goal_s()),
            (Some(1), Some(3.0))
        );
        assert_eq!(s.current_target(), 0, "the waypoint is still to be reached");
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
        let hundred: Vec<f64> = (1..=101).map(f64::from).collect();
        assert_eq!(quantile(&hundred, 0.95), Some(96.0));
        assert_eq!(quantile(&[], 0.5), None);
    }
}
