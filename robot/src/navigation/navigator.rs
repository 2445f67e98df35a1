//! The navigator: keeps the grid, replans, hands the controller a lookahead point on the plan,
//! and watches the progress.
//!
//! - Replanning: when there is no plan, the target changed, every `replan_period_s`, and when
//!   the robot has strayed from the plan by more than `STRAY_MM`.
//! - Following: the point `lookahead_mm` along the plan beyond the robot's nearest point on
//!   it (or the farthest vertex before it that the robot sees over passable cells). The
//!   controller's goal is that point's direction with the length of the remaining path, so
//!   the approach speed `min(v_max, sqrt(2 alpha d))` is that of the whole way still to go,
//!   lowered where the way turns (ours): a turn by `theta` is taken at no more than
//!   `v_c = v_max max(cos theta, MIN_TURN_SPEED)`, so the goal's distance is at most
//!   `d_turn + v_c^2 / (2 alpha)` for the plan's next sharp vertex `d_turn` ahead, and at most
//!   `v_c^2 / (2 alpha)` when the robot's own course is `theta` off the lookahead's direction.
//!   An acceleration-limited robot at speed turns on a circle of radius `v^2 / alpha` (533 mm
//!   at 400 mm/s and 300 mm/s^2): without this it would swing wide of every bend and round
//!   every replanned way back.
//! - The watchdog (ours): no progress for `watchdog_s` (the robot stayed within
//!   `progress_mm` of where it was), or for twice that long along the route (the remaining
//!   path did not shorten by `progress_mm`; a new plan more than `REBASE_MM` longer, the world
//!   turned out worse than hoped, starts the count again), raises the cost of the cells within
//!   `PENALTY_RADIUS_MM` of the point that far ahead on the plan (where the robot is held up;
//!   not the lookahead point, which on the last leg is the goal, dear to every route alike) by
//!   `PENALTY`, which fades like the grid's
//!   evidence, and replans: a place where the robot keeps failing becomes dearer than
//!   another way round.
//! - Places closed (ours): the controller refusing the plan's step for `refuse_s`, or no
//!   progress for `stall_s`, closes the plan's narrowest place ahead (or a place on the way
//!   closed once before): dearer the first time, impassable the second (unless 160 mm of room
//!   or more), until the target changes; with no route left the goal is reported unreachable
//!   (`too_narrow`, `no_progress`).
//! - Unreachable: while no route through free, unknown or suspect cells reaches the goal, the
//!   controller heads straight for it (it still keeps every command inside the surely free
//!   space), so that the robot looks nearer, where the map is finer; when no route has been
//!   found for `unreachable_s` in a row, the goal is reported unreachable and the robot stops
//!   and stays stopped (until it is given another target). The robot drives through suspect
//!   cells (seen occupied only from afar) to look at them from nearer, but they count as
//!   evidence too: each replan also prices the map as it would be if every far mark were
//!   right (suspect cells blocked and spread by half a sector); a count of seconds goes up
//!   while on that map the goal lies in a closed pocket (under `pocket_area_mm2`, the robot outside
//!   it and within `pocket_sight_mm` of the goal) and down, as fast, while it does not, and the goal is reported unreachable when the
//!   count reaches `pocket_unreachable_s`: a ring of cubes round the goal seen from outside
//!   closes such a pocket, though its far side was never seen from near, while a barrier
//!   across the field closed only by far marks does not (one gap closed in error there would
//!   end a run that a look from nearer would have saved).

use super::config::PlannerConfig;
use super::distances::DistanceFields;
use super::grid::{CellState, GridGeometry, MAX_CELLS, MapSnapshot, OccupancyGrid};
use super::planner::{CostMap, CostSettings, Suspects, length};
use crate::RobotError;
use crate::config::RobotConfig;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_problem::Problem;
use omniloop_vision::FreeSpace;

/// Strayed this far from the plan, the robot replans, mm.
const STRAY_MM: f64 = 120.0;
/// A new plan this much longer than the last restarts the watchdog's count along the route.
const REBASE_MM: f64 = 500.0;
/// The watchdog's penalty: the added cost factor.
const PENALTY: f32 = 4.0;
/// The watchdog's penalty: the radius of the region made dearer, mm.
const PENALTY_RADIUS_MM: f64 = 200.0;
/// A closed place: the centre of the disc closed lies this far ahead on the plan, mm.
const CLOSE_AHEAD_MM: f64 = 150.0;
/// A closed place: the radius of the disc closed, mm.
const CLOSE_RADIUS_MM: f64 = 100.0;
/// A place this far or farther from the nearest blocked or suspect cell is open floor: closed
/// once at most, never given up (a gap of about twice this, 320 mm, which the controller
/// drives through at any speed), mm.
const OPEN_ROOM_MM: f64 = 160.0;
/// With no route at the planner's inflation, a route is sought at the body's radius plus this,
/// mm, before the goal is given up.
const TIGHT_MM: f64 = 10.0;
/// A place closed once: the added cost factor (crossing it costs as much as 2 m of floor
/// round it, so the robot tries every other way first).
const CLOSED_FACTOR: f32 = 20.0;
/// The controller refuses the plan's step while its command makes less headway than this
/// toward the lookahead point, the robot standing, mm/s.
const REFUSE_MM_S: f64 = 30.0;
/// Turns are taken at no more than the speed whose turning circle is this wide, mm (400 mm/s
/// at 300 mm/s^2, with room to spare: a 400 mm/s robot turns as before).
const TURN_RADIUS_MM: f64 = 540.0;
/// The least fraction of the top speed a turn is taken at.
const MIN_TURN_SPEED: f64 = 0.2;
/// A vertex turning the plan by more than this is a bend to slow for, rad.
const BEND_RAD: f64 = 0.35;
/// Below this speed the robot has no course to turn from, mm/s.
const COURSE_MIN_SPEED_MM_S: f64 = 50.0;
/// Padding round the map (or, without one, round start and targets) the grid covers, mm.
const PAD_WITH_MAP_MM: f64 = 400.0;
/// See [`PAD_WITH_MAP_MM`].
const PAD_WITHOUT_MAP_MM: f64 = 2000.0;

/// What the navigator did this cycle, for the estimates record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NavigationReport {
    /// The plan, pulled taut: from the robot at the last replan to the target, world mm.
    pub path_mm: Vec<Point2<f64>>,
    /// The point the controller heads for, world mm.
    pub lookahead_mm: Option<Point2<f64>>,
    /// Length of the way still to go along the plan, mm.
    pub remaining_mm: Option<f64>,
    /// Plans made so far.
    pub replans: usize,
    /// Times the watchdog fired so far.
    pub watchdog: usize,
    /// Places closed so far: no progress for `stall_s`, or the controller refusing the plan's
    /// step for `refuse_s`.
    pub closed: usize,
    /// Why the goal was found unreachable (the robot stopped); `None` while it is not.
    pub unreachable: Option<Unreachable>,
    /// Cells free, unknown, suspect and blocked.
    pub cells: [usize; 4],
}

/// Why a goal was reported unreachable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Unreachable {
    /// No route through free, unknown or suspect cells reaches it (or it lies in a pocket
    /// closed by marks from afar).
    NoRoute,
    /// Every route left passes a gap narrower than the robot can drive through.
    TooNarrow,
    /// No progress toward it for `stall_s` with every other route tried, or none on any route
    /// for `give_up_s`.
    NoProgress,
}

impl Unreachable {
    /// The reason as written in records and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::NoRoute => "no_route",
            Self::TooNarrow => "too_narrow",
            Self::NoProgress => "no_progress",
        }
    }

    /// A sentence for the estimates record's `not_found`.
    pub fn explain(self) -> &'static str {
        match self {
            Self::NoRoute => "no route through free or unknown cells reaches it",
            Self::TooNarrow => "every route to it passes a gap narrower than the robot can drive",
            Self::NoProgress => "no progress toward it on any route",
        }
    }
}

/// Progress of the robot, for the watchdog.
#[derive(Debug, Clone)]
struct Watchdog {
    anchor: Point2<f64>,
    anchor_t_s: f64,
    best_mm: f64,
    best_t_s: f64,
}

impl Watchdog {
    fn new(here: Point2<f64>, t_s: f64) -> Self {
        Self {
            anchor: here,
            anchor_t_s: t_s,
            best_mm: f64::INFINITY,
            best_t_s: t_s,
        }
    }

    /// Whether the robot has made no progress for too long.
    fn stuck(&mut self, here: Point2<f64>, remaining_mm: f64, t_s: f64, c: &PlannerConfig) -> bool {
        if (here - self.anchor).norm() > c.progress_mm {
            self.anchor = here;
            self.anchor_t_s = t_s;
        }
        if remaining_mm < self.best_mm - c.progress_mm {
            self.best_mm = remaining_mm;
            self.best_t_s = t_s;
        }
        let stuck =
            t_s - self.anchor_t_s > c.watchdog_s || t_s - self.best_t_s > 2.0 * c.watchdog_s;
        if stuck {
            *self = Self::new(here, t_s);
            self.best_mm = remaining_mm;
        }
        stuck
    }
}

/// The plan being followed.
#[derive(Debug, Clone)]
struct Plan {
    path: Vec<Point2<f64>>,
    made_t_s: f64,
}

/// The robot's navigation: its grid, its plan and the watchdog.
#[derive(Debug, Clone)]
pub struct Navigator {
    config: PlannerConfig,
    costs: CostSettings,
    radius_mm: f64,
    max_speed_mm_s: f64,
    accel_mm_s2: f64,
    accept_mm: f64,
    grid: OccupancyGrid,
    penalty: Vec<f32>,
    penalty_t_s: f64,
    /// Places closed to the planner until the target changes, a level a cell: 1 after one
    /// failure there (dearer by `CLOSED_FACTOR`), 2 after a second (impassable).
    closed: Vec<u8>,
    /// The grid's distance fields, made again only where its blocked or suspect cells changed.
    distances: DistanceFields,
    cost_map: Option<CostMap>,
    plan: Option<Plan>,
    target: Option<Point2<f64>>,
    watchdog: Option<Watchdog>,
    failing_since_s: Option<f64>,
    /// Seconds without a route on the map with every far mark taken as right, net of those
    /// with one, and when that was last counted.
    closed_s: f64,
    closed_t_s: Option<f64>,
    /// Whether the point the robot was last sent toward is the target itself.
    final_leg: bool,
    /// The route's progress for the stall rule: the least remaining way and when it was had.
    stall: (f64, f64),
    /// When the stall rule last started again from a longer plan.
    stall_rebased_s: f64,
    /// The least way still to go since the target was set, and when it was had (for
    /// `give_up_s`; never started again from a longer plan).
    closest: (f64, f64),
    /// Since when the controller has refused every step toward the lookahead point.
    refusing_since_s: Option<f64>,
    /// Why the last place was closed (`stall_s` or `refuse_s`), while one is.
    closed_by: Option<Unreachable>,
    report: NavigationReport,
}

impl Navigator {
    /// A navigator for the robot `config` describes, with the planner settings `planner`.
    pub fn new(config: &RobotConfig, planner: PlannerConfig) -> Result<Self, RobotError> {
        let geometry = grid_geometry(config, planner.cell_mm)?;
        let accept_mm = config
            .goal
            .as_ref()
            .map_or(100.0, |g| g.tolerance_mm - g.estimate_margin_mm)
            .max(planner.cell_mm);
        Ok(Self {
            costs: CostSettings {
                inflated_mm: config.body.radius_mm + planner.inflation_mm,
                comfort_mm: planner.comfort_mm,
                unknown_cost: planner.unknown_cost,
            },
            radius_mm: config.body.radius_mm,
            max_speed_mm_s: config.body.max_speed_mm_s,
            accel_mm_s2: config.body.accel_limit_mm_s2,
            accept_mm,
            grid: OccupancyGrid::new(geometry, &config.map, &planner),
            penalty: vec![0.0; geometry.len()],
            penalty_t_s: 0.0,
            closed: vec![0; geometry.len()],
            distances: DistanceFields::default(),
            cost_map: None,
            plan: None,
            target: None,
            watchdog: None,
            failing_since_s: None,
            closed_s: 0.0,
            closed_t_s: None,
            final_leg: true,
            stall: (f64::INFINITY, 0.0),
            stall_rebased_s: f64::NEG_INFINITY,
            closest: (f64::INFINITY, 0.0),
            refusing_since_s: None,
            closed_by: None,
            report: NavigationReport::default(),
            config: planner,
        })
    }

    /// Whether the point the robot was last sent toward is the target itself (the plan's end
    /// lies within the lookahead, or there is no plan), not a point on the way.
    pub fn on_final_leg(&self) -> bool {
        self.final_leg
    }

    /// What it did this cycle.
    pub fn report(&self) -> &NavigationReport {
        &self.report
    }

    /// The grid's cells now.
    pub fn map(&self) -> MapSnapshot {
        self.grid.snapshot()
    }

    /// How far along the ray `u` (body frame, a unit vector from the robot's centre at the
    /// estimated `pose`) the map holds floor seen free without a break, from `from_mm` out to
    /// `to_mm`; `from_mm` when the cell there is not free. The walk stops in the first cell not
    /// free, and the answer stops short of it by half a cell's diagonal: a cell is free when its
    /// centre lay in a sector seen surely free, so its far corner may hold the obstacle.
    ///
    /// The controller's near-field memory keeps the same evidence (sectors seen surely free)
    /// for 2 s and 250 mm of odometry; the map keeps it in the localized frame for `forget_s`.
    /// Where the memory has forgotten the floor by the body, the map still says how far off
    /// the obstacle in a blind direction stands, so the controller keeps from it the clearance
    /// the planner planned with instead of from a blind point at the body's edge.
    pub fn free_along(
        &self,
        pose: &Isometry2<f64>,
        u: Vector2<f64>,
        from_mm: f64,
        to_mm: f64,
    ) -> f64 {
        let g = self.grid.geometry();
        let step = 0.25 * g.cell_mm;
        let slack = 0.5 * std::f64::consts::SQRT_2 * g.cell_mm;
        let free = |d: f64| {
            let p = pose * Point2::from(u * d);
            g.cell_of(p)
                .is_some_and(|i| self.grid.state(i) == CellState::Free)
        };
        let mut d = from_mm;
        while d + step <= to_mm && free(d + step) {
            d += step;
        }
        if d >= to_mm - step {
            return to_mm;
        }
        (d - slack).max(from_mm)
    }

    /// One cycle: takes the free space seen (if any) from the estimated `pose`, and returns
    /// where the controller should head for `target` (world mm), the robot moving at
    /// `velocity_body_mm_s`: a body-frame vector whose direction is the lookahead point's and
    /// whose length is the way still to go (shortened before bends); `None` to stop (no
    /// route, or the goal unreachable).
    pub fn steer(
        &mut self,
        fs: Option<&FreeSpace>,
        pose: &Isometry2<f64>,
        velocity_body_mm_s: Vector2<f64>,
        target: Point2<f64>,
        t_s: f64,
    ) -> Option<Vector2<f64>> {
        if let Some(fs) = fs {
            self.grid.observe(fs, pose, self.radius_mm, t_s);
        }
        let here = Point2::from(pose.translation.vector);
        if self.target != Some(target) {
            self.target = Some(target);
            self.plan = None;
            self.failing_since_s = None;
            self.closed_s = 0.0;
            self.closed_t_s = None;
            self.watchdog = Some(Watchdog::new(here, t_s));
            self.report.unreachable = None;
            self.stall = (f64::INFINITY, t_s);
            self.stall_rebased_s = f64::NEG_INFINITY;
            self.closest = (f64::INFINITY, t_s);
            self.refusing_since_s = None;
            self.closed_by = None;
            self.closed.fill(0);
        }
        self.report.cells = self.grid.counts();
        self.final_leg = true;
        if self.report.unreachable.is_some() {
            return self.stop();
        }
        if (target - here).norm() <= self.accept_mm {
            self.report.lookahead_mm = Some(target);
            self.report.remaining_mm = Some((target - here).norm());
            return Some(pose.inverse_transform_vector(&(target - here)));
        }
        let remaining = self.report.remaining_mm.unwrap_or(f64::INFINITY);
        if self.gave_up(remaining, t_s) {
            self.report.unreachable = Some(Unreachable::NoProgress);
            return self.stop();
        }
        let fired = self
            .watchdog
            .as_mut()
            .is_some_and(|w| w.stuck(here, remaining, t_s, &self.config));
        if fired {
            self.report.watchdog += 1;
            // The place just ahead on the plan, where the robot is held up (not the lookahead
            // point, which on the last leg is the goal itself, dear to every route alike).
            let ahead = self.plan.as_ref().map_or(here, |plan| {
                let (_, s_near) = distance_to_path(&plan.path, here);
                point_at(
                    &plan.path,
                    (s_near + PENALTY_RADIUS_MM).min(length(&plan.path)),
                )
            });
            self.penalise(ahead, t_s);
            self.plan = None;
        }
        if self.stalled(remaining, t_s) {
            self.close_ahead(
                here,
                2.0 * self.config.lookahead_mm,
                Unreachable::NoProgress,
            );
        }
        if self.needs_plan(here, t_s) && !self.replan(here, target, t_s) {
            if self.report.unreachable.is_some() {
                return self.stop();
            }
            self.report.lookahead_mm = Some(target);
            self.report.remaining_mm = None;
            return Some(pose.inverse_transform_vector(&(target - here)));
        }
        let course = pose.rotation * velocity_body_mm_s;
        self.follow(pose, here, course)
    }

    /// Hears the controller's command this cycle (body frame), the robot moving at
    /// `velocity_body_mm_s`: a command that makes no headway toward the lookahead point while
    /// the robot stands, for `refuse_s` in a row, is the controller refusing a step the plan
    /// allows, and closes the place ahead to the planner (a gap the plan takes and the
    /// controller will not drive through: the planner hears of it and plans round it).
    pub fn heard(
        &mut self,
        command_body_mm_s: Vector2<f64>,
        velocity_body_mm_s: Vector2<f64>,
        pose: &Isometry2<f64>,
        t_s: f64,
    ) {
        let here = Point2::from(pose.translation.vector);
        let ahead = match (&self.plan, self.report.lookahead_mm) {
            (Some(_), Some(p)) if (p - here).norm() > self.accept_mm => p,
            _ => {
                self.refusing_since_s = None;
                return;
            }
        };
        let toward = pose.inverse_transform_vector(&(ahead - here)).normalize();
        let refusing = command_body_mm_s.dot(&toward) < REFUSE_MM_S
            && velocity_body_mm_s.norm() < COURSE_MIN_SPEED_MM_S;
        if !refusing {
            self.refusing_since_s = None;
            return;
        }
        let since = *self.refusing_since_s.get_or_insert(t_s);
        if t_s - since >= self.config.refuse_s - 1e-9 {
            self.refusing_since_s = None;
            self.close_ahead(here, self.config.lookahead_mm, Unreachable::TooNarrow);
        }
    }

    /// Whether the remaining way has not been shorter, by `progress_mm`, than its least so far
    /// for `give_up_s`.
    fn gave_up(&mut self, remaining_mm: f64, t_s: f64) -> bool {
        if remaining_mm < self.closest.0 - self.config.progress_mm || !self.closest.0.is_finite() {
            if remaining_mm.is_finite() {
                self.closest = (remaining_mm, t_s);
            }
            return false;
        }
        t_s - self.closest.1 >= self.config.give_up_s - 1e-9
    }

    /// Whether the remaining way has not shortened by `progress_mm` for `stall_s` (restarting
    /// the count then).
    fn stalled(&mut self, remaining_mm: f64, t_s: f64) -> bool {
        if remaining_mm < self.stall.0 - self.config.progress_mm || !self.stall.0.is_finite() {
            self.stall = (remaining_mm, t_s);
            return false;
        }
        let stalled = t_s - self.stall.1 >= self.config.stall_s - 1e-9;
        if stalled {
            self.stall = (remaining_mm, t_s);
        }
        stalled
    }

    /// Closes to the planner, until the target changes, the disc of `CLOSE_RADIUS_MM` round
    /// the narrowest place of the plan within `window_mm` ahead of the robot (at least
    /// `CLOSE_AHEAD_MM` ahead): the gap the robot fails to pass, not the floor where it stands
    /// (which may be where two routes part); or, when the plan passes a place closed once
    /// within that reach, that place (the robot failed again on the way through it). Closed once, the place is dearer by
    /// `CLOSED_FACTOR` (every other way is tried first); failed there again, it is impassable,
    /// and with no route left the goal is reported unreachable for `why`. Drops the plan.
    fn close_ahead(&mut self, here: Point2<f64>, window_mm: f64, why: Unreachable) {
        let (Some(plan), Some(costs)) = (self.plan.take(), &self.cost_map) else {
            return;
        };
        let (_, s_near) = distance_to_path(&plan.path, here);
        let total = length(&plan.path);
        let step = 0.5 * costs.geometry().cell_mm;
        let g = *self.grid.geometry();
        let closed_once = |p: Point2<f64>| g.cell_of(p).is_some_and(|i| self.closed[i] > 0);
        // The narrowest place ahead; but a place on the way closed once already is where the
        // robot failed again.
        let mut best = (f64::INFINITY, None);
        let mut s = (s_near + CLOSE_AHEAD_MM).min(total);
        while s <= (s_near + window_mm).min(total) {
            let p = point_at(&plan.path, s);
            if closed_once(p) {
                best = (costs.room_at(p), Some(p));
                break;
            }
            let room = costs.room_at(p);
            if room < best.0 {
                best = (room, Some(p));
            }
            s += step;
        }
        let at = best.1.unwrap_or_else(|| point_at(&plan.path, s.min(total)));
        let r = (CLOSE_RADIUS_MM / g.cell_mm).ceil() as i64;
        let Some((cx, cy)) = g.coords_of(at) else {
            return;
        };
        let cells: Vec<usize> = disc_cells(cx, cy, r, &g)
            .map(|(x, y)| y * g.width + x)
            .filter(|&i| (g.centre(i) - at).norm() <= CLOSE_RADIUS_MM)
            .collect();
        // Failing a second time where it failed before, the robot gives the place up; but not
        // open floor, where what held it up was not the room to pass.
        let narrow = best.0 < OPEN_ROOM_MM;
        let again = narrow && g.cell_of(at).is_some_and(|i| self.closed[i] > 0);
        for i in cells {
            self.closed[i] = self.closed[i].max(if again { 2 } else { 1 });
        }
        if again {
            self.closed_by = Some(why);
        }
        self.report.closed += 1;
    }

    /// Why no route reaches `target`: a place the navigator closed, when a route exists
    /// without the closed places; else no route on the map.
    fn why_no_route(&mut self, here: Point2<f64>, target: Point2<f64>) -> Unreachable {
        let Some(why) = self.closed_by else {
            return Unreachable::NoRoute;
        };
        self.distances.update(&self.grid);
        let costs = CostMap::priced(
            &self.grid,
            &self.distances,
            &self.tight_costs(),
            &self.penalty,
            here,
            Suspects::Costly,
        );
        match costs.plan(here, target, self.accept_mm) {
            Some(_) => why,
            None => Unreachable::NoRoute,
        }
    }

    /// The costs of a tight route: the body's radius plus `TIGHT_MM` inflated.
    fn tight_costs(&self) -> CostSettings {
        CostSettings {
            inflated_mm: self.radius_mm + TIGHT_MM,
            ..self.costs
        }
    }

    /// The watchdog's penalties with the closed places: dearer once, impassable twice; but
    /// never impassable under the robot's body at `here` (a robot that drifted into a place
    /// it gave up must be able to back out of it: shut, it had no route at all).
    fn penalties(&self, here: Point2<f64>) -> Vec<f32> {
        let mut penalties: Vec<f32> = self
            .penalty
            .iter()
            .zip(&self.closed)
            .map(|(&p, &c)| match c {
                0 => p,
                1 => p + CLOSED_FACTOR,
                _ => f32::INFINITY,
            })
            .collect();
        let g = self.grid.geometry();
        if let Some((cx, cy)) = g.coords_of(here) {
            let r = (self.radius_mm / g.cell_mm).ceil() as i64;
            for (x, y) in disc_cells(cx, cy, r, g) {
                let i = y * g.width + x;
                if penalties[i].is_infinite() {
                    penalties[i] = self.penalty[i] + CLOSED_FACTOR;
                }
            }
        }
        penalties
    }

    fn stop(&mut self) -> Option<Vector2<f64>> {
        self.report.lookahead_mm = None;
        self.report.remaining_mm = None;
        None
    }

    /// Whether to plan again now.
    fn needs_plan(&self, here: Point2<f64>, t_s: f64) -> bool {
        let Some(plan) = &self.plan else {
            return true;
        };
        t_s - plan.made_t_s >= self.config.replan_period_s - 1e-9
            || distance_to_path(&plan.path, here).0 > STRAY_MM
    }

    /// Plans from `here` to `target`; false when no route exists (and, after
    /// `unreachable_s` of that, marks the goal unreachable).
    fn replan(&mut self, here: Point2<f64>, target: Point2<f64>, t_s: f64) -> bool {
        self.fade_penalty(t_s);
        let penalties = if self.closed_by.is_some() || self.report.closed > 0 {
            std::borrow::Cow::Owned(self.penalties(here))
        } else {
            std::borrow::Cow::Borrowed(&self.penalty[..])
        };
        self.distances.update(&self.grid);
        let (grid, fields) = (&self.grid, &self.distances);
        let mut costs = CostMap::priced(
            grid,
            fields,
            &self.costs,
            &penalties,
            here,
            Suspects::Costly,
        );
        let mut found = costs.plan(here, target, self.accept_mm);
        if found.is_none() {
            // No route with the comfort of the inflation: one the body fits, with
            // `TIGHT_MM` to spare, before giving up (the map's edges are a cell and a ring
            // out, and the controller drives where its body fits).
            let tight = self.tight_costs();
            costs = CostMap::priced(grid, fields, &tight, &penalties, here, Suspects::Costly);
            found = costs.plan(here, target, self.accept_mm);
        }
        self.report.replans += 1;
        let Some((cells, _)) = found else {
            let since = *self.failing_since_s.get_or_insert(t_s);
            if t_s - since >= self.config.unreachable_s - 1e-9 {
                self.report.unreachable = Some(self.why_no_route(here, target));
            }
            self.plan = None;
            self.cost_map = Some(costs);
            return false;
        };
        self.failing_since_s = None;
        if self.closed_on_far_marks(here, target, t_s) {
            self.report.unreachable = Some(Unreachable::NoRoute);
            self.plan = None;
            self.cost_map = Some(costs);
            return false;
        }
        let path = costs.taut(here, &cells, target);
        let new_len = length(&path);
        if let (Some(w), Some(old)) = (&mut self.watchdog, self.report.remaining_mm)
            && new_len > old + REBASE_MM
        {
            w.best_mm = new_len;
            w.best_t_s = t_s;
            // The stall rule starts again from a longer plan at most once a `stall_s`: a robot
            // sent back and forth between two routes makes a longer plan every few seconds.
            if t_s - self.stall_rebased_s >= self.config.stall_s {
                self.stall = (new_len, t_s);
                self.stall_rebased_s = t_s;
            }
        }
        self.report.path_mm = path.clone();
        self.plan = Some(Plan {
            path,
            made_t_s: t_s,
        });
        self.cost_map = Some(costs);
        true
    }

    /// Counts the time the map with every far mark taken as right has no route from `here` to
    /// `target`; whether that reached `pocket_unreachable_s`.
    fn closed_on_far_marks(&mut self, here: Point2<f64>, target: Point2<f64>, t_s: f64) -> bool {
        let dt = self.closed_t_s.map_or(0.0, |t0| t_s - t0);
        self.closed_t_s = Some(t_s);
        let suspects = self.report.cells[2] > 0;
        let pocket =
            (self.config.pocket_area_mm2 / (self.grid.geometry().cell_mm.powi(2))) as usize;
        // Whether the robot's body fits, without the planner's inflation (a comfort margin).
        let body = CostSettings {
            inflated_mm: self.radius_mm,
            ..self.costs
        };
        let closed = suspects && (target - here).norm() <= self.config.pocket_sight_mm && {
            self.distances.update(&self.grid);
            let (grid, fields) = (&self.grid, &self.distances);
            CostMap::priced(grid, fields, &body, &[], here, Suspects::Blocked).goal_in_pocket(
                here,
                target,
                self.accept_mm,
                pocket,
            )
        };
        self.closed_s = (self.closed_s + if closed { dt } else { -dt }).max(0.0);
        closed && self.closed_s >= self.config.pocket_unreachable_s - 1e-9
    }

    /// The controller's goal vector for the robot at `here`, moving at `course` (world frame),
    /// on the current plan.
    fn follow(
        &mut self,
        pose: &Isometry2<f64>,
        here: Point2<f64>,
        course: Vector2<f64>,
    ) -> Option<Vector2<f64>> {
        let (plan, costs) = (self.plan.as_ref()?, self.cost_map.as_ref()?);
        let path = &plan.path;
        let (_, s_near) = distance_to_path(path, here);
        let total = length(path);
        let mut s = (s_near + self.config.lookahead_mm).min(total);
        let mut point = point_at(path, s);
        // Back off to the farthest point before it that the robot sees over passable cells.
        let step = 0.5 * costs.geometry().cell_mm;
        while s > s_near + step && !costs.line_clear(here, point) {
            s -= step;
            point = point_at(path, s);
        }
        let remaining = (point - here).norm() + (total - s);
        self.final_leg = s >= total;
        self.report.lookahead_mm = Some(point);
        self.report.remaining_mm = Some(remaining);
        let v = point - here;
        if v.norm() < 1e-6 {
            return Some(Vector2::zeros());
        }
        let mut reach = remaining;
        if let Some((d_turn, theta)) = next_bend(path, s_near) {
            reach = reach.min(d_turn + self.braking_mm(theta));
        }
        if course.norm() > COURSE_MIN_SPEED_MM_S {
            reach = reach.min(self.braking_mm(course.angle(&v)));
        }
        Some(pose.inverse_transform_vector(&(v.normalize() * reach)))
    }

    /// The distance in which the robot brakes to the speed it takes a turn by `theta` at
    /// (infinite for a gentle turn): `v_c = v_t max(cos theta, MIN_TURN_SPEED)`, with `v_t`
    /// the top speed, or, for a faster robot, the speed whose turning circle `v^2 / alpha` is
    /// `TURN_RADIUS_MM` (400 mm/s at 300 mm/s^2): the turn speed scaled by a top speed of
    /// 2000 mm/s (400 mm/s for a right angle, a 533 mm circle) swung robots round every bend
    /// of their plan in loops a metre across.
    fn braking_mm(&self, theta: f64) -> f64 {
        if theta <= BEND_RAD {
            return f64::INFINITY;
        }
        let turning = (self.accel_mm_s2 * TURN_RADIUS_MM).sqrt();
        let v = self.max_speed_mm_s.min(turning) * theta.cos().max(MIN_TURN_SPEED);
        v * v / (2.0 * self.accel_mm_s2)
    }

    /// Makes the cells round `at` dearer.
    fn penalise(&mut self, at: Point2<f64>, t_s: f64) {
        self.fade_penalty(t_s);
        let g = *self.grid.geometry();
        let r = (PENALTY_RADIUS_MM / g.cell_mm).ceil() as i64;
        let Some((cx, cy)) = g.coords_of(at) else {
            return;
        };
        for (x, y) in disc_cells(cx, cy, r, &g) {
            let i = y * g.width + x;
            if (g.centre(i) - at).norm() <= PENALTY_RADIUS_MM {
                self.penalty[i] += PENALTY;
            }
        }
    }

    /// Lets the watchdog's penalties fade like the grid's evidence.
    fn fade_penalty(&mut self, t_s: f64) {
        let dt = t_s - self.penalty_t_s;
        if dt > 0.0 {
            let k = (-dt / self.config.forget_s).exp() as f32;
            for p in &mut self.penalty {
                *p *= k;
            }
        }
        self.penalty_t_s = t_s;
    }
}

/// The grid for a robot: the map it is given (or, without one, its start and targets) and
/// some room round it.
fn grid_geometry(config: &RobotConfig, cell_mm: f64) -> Result<GridGeometry, RobotError> {
    let m = &config.map;
    let mut points: Vec<Point2<f64>> = vec![Point2::from(config.start.translation.vector)];
    points.extend(config.goal.iter().flat_map(|g| g.targets()));
    let mapped: Vec<Point2<f64>> = m
        .bounds
        .iter()
        .chain(&m.segments)
        .flat_map(|s| [s.from_mm, s.to_mm])
        .chain(m.landmarks.iter().map(|l| l.centre_mm))
        .collect();
    let pad = if m.bounds.is_empty() {
        PAD_WITHOUT_MAP_MM
    } else {
        PAD_WITH_MAP_MM
    };
    points.extend(mapped);
    let lo = points.iter().fold(points[0], |a, p| a.inf(p)) - Vector2::repeat(pad);
    let hi = points.iter().fold(points[0], |a, p| a.sup(p)) + Vector2::repeat(pad);
    let g = GridGeometry::covering(lo, hi, cell_mm);
    if g.len() > MAX_CELLS {
        return Err(RobotError::Field(Problem::new(
            "control.planner.cell_mm",
            format!(
                "a grid of {cell_mm} mm cells over {:.0} x {:.0} mm has {} cells, more than \
                 {MAX_CELLS}: raise cell_mm",
                hi.x - lo.x,
                hi.y - lo.y,
                g.len()
            ),
        )));
    }
    Ok(g)
}

/// The cells of the grid within `r` cells of column `cx`, row `cy` along each axis.
fn disc_cells(
    cx: usize,
    cy: usize,
    r: i64,
    g: &GridGeometry,
) -> impl Iterator<Item = (usize, usize)> + use<> {
    let (w, h) = (g.width as i64, g.height as i64);
    let (cx, cy) = (cx as i64, cy as i64);
    (-r..=r)
        .flat_map(move |dy| (-r..=r).map(move |dx| (cx + dx, cy + dy)))
        .filter(move |&(x, y)| x >= 0 && y >= 0 && x < w && y < h)
        .map(|(x, y)| (x as usize, y as usize))
}

/// Distance from `p` to a polyline, and the arc length of the nearest point on it.
fn distance_to_path(path: &[Point2<f64>], p: Point2<f64>) -> (f64, f64) {
    let mut best = (f64::INFINITY, 0.0);
    let mut s0 = 0.0;
    for w in path.windows(2) {
        let ab = w[1] - w[0];
        let len = ab.norm();
        let t = if len > 0.0 {
            ((p - w[0]).dot(&ab) / (len * len)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = (p - (w[0] + ab * t)).norm();
        if d < best.0 {
            best = (d, s0 + t * len);
        }
        s0 += len;
    }
    if path.len() == 1 {
        best = ((p - path[0]).norm(), 0.0);
    }
    best
}

/// The next vertex beyond arc length `s` where the polyline turns by more than `BEND_RAD`: its
/// distance along the line from `s` and the turn's angle.
fn next_bend(path: &[Point2<f64>], s: f64) -> Option<(f64, f64)> {
    let mut at = 0.0;
    for w in path.windows(3) {
        at += (w[1] - w[0]).norm();
        if at <= s {
            continue;
        }
        let theta = (w[1] - w[0]).angle(&(w[2] - w[1]));
        if theta > BEND_RAD {
            return Some((at - s, theta));
        }
    }
    None
}

/// The point at arc length `s` along a polyline.
fn point_at(path: &[Point2<f64>], s: f64) -> Point2<f64> {
    let mut left = s.max(0.0);
    for w in path.windows(2) {
        let len = (w[1] - w[0]).norm();
        if left <= len && len > 0.0 {
            return w[0] + (w[1] - w[0]) * (left / len);
        }
        left -= len;
    }
    *path.last().unwrap_or(&Point2::origin())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{GoalSpec, MapSegment, WorldMap};
    use std::f64::consts::TAU;

    fn robot(map: WorldMap, goal: [f64; 2]) -> RobotConfig {
        RobotConfig {
            name: "robot".to_string(),
            start: Isometry2::new(Vector2::new(-1000.0, 0.0), 0.0),
            goal: Some(GoalSpec::to(goal, 100.0)),
            map,
            ..RobotConfig::for_tests()
        }
    }

    fn box_map(half: f64) -> WorldMap {
        let c = [[-half, -half], [half, -half], [half, half], [-half, half]];
        WorldMap {
            bounds: (0..4)
                .map(|k| MapSegment {
                    from_mm: Point2::new(c[k][0], c[k][1]),
                    to_mm: Point2::new(c[(k + 1) % 4][0], c[(k + 1) % 4][1]),
                    half_thickness_mm: 25.0,
                })
                .collect(),
            ..WorldMap::default()
        }
    }

    /// Free space of a robot that sees nothing but open floor.
    fn open_floor() -> FreeSpace {
        let n = 32;
        FreeSpace {
            direction_rad: (0..n).map(|j| j as f64 * TAU / n as f64).collect(),
            a: vec![6; n],
            free_mm: vec![1000.0; n],
            clear_mm: vec![960.0; n],
            range_mm: 1000.0,
            ..FreeSpace::default()
        }
    }

    #[test]
    fn heads_along_the_plan_with_the_remaining_way_as_the_goals_distance() {
        let cfg = robot(box_map(1500.0), [1000.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let v = nav
            .steer(
                Some(&open_floor()),
                &cfg.start,
                Vector2::zeros(),
                Point2::new(1000.0, 0.0),
                0.0,
            )
            .unwrap();
        assert!(v.y.abs() < 1e-6 && v.x > 1900.0 && v.x < 2100.0, "{v:?}");
        assert_eq!(nav.report().replans, 1);
        assert!(nav.report().unreachable.is_none());
    }

    #[test]
    fn a_goal_walled_off_is_reported_unreachable_after_two_seconds_and_the_robot_stops() {
        // The goal inside a closed square the map knows.
        let mut map = box_map(1500.0);
        let inner = box_map(300.0);
        map.bounds.extend(inner.bounds.iter().map(|s| MapSegment {
            from_mm: s.from_mm + Vector2::new(700.0, 0.0),
            to_mm: s.to_mm + Vector2::new(700.0, 0.0),
            ..*s
        }));
        let cfg = robot(map, [700.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let goal = Point2::new(700.0, 0.0);
        let mut t = 0.0;
        while t < 1.9 {
            let v = nav.steer(None, &cfg.start, Vector2::zeros(), goal, t);
            assert!(
                v.is_some_and(|v| v.x > 0.0),
                "heads for the goal while it looks"
            );
            assert!(nav.report().unreachable.is_none(), "not yet at {t} s");
            t += 0.04;
        }
        for _ in 0..5 {
            nav.steer(None, &cfg.start, Vector2::zeros(), goal, t);
            t += 0.04;
        }
        assert_eq!(nav.report().unreachable, Some(Unreachable::NoRoute));
        assert!(
            nav.steer(
                Some(&open_floor()),
                &cfg.start,
                Vector2::zeros(),
                goal,
                t + 5.0
            )
            .is_none(),
            "stays stopped"
        );
    }

    #[test]
    fn the_watchdog_fires_when_the_robot_stays_put_and_makes_the_place_dearer() {
        let cfg = robot(box_map(1500.0), [1000.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let goal = Point2::new(1000.0, 0.0);
        let mut t = 0.0;
        while t < 4.2 {
            nav.steer(Some(&open_floor()), &cfg.start, Vector2::zeros(), goal, t);
            t += 0.04;
        }
        assert_eq!(nav.report().watchdog, 1);
        assert!(nav.penalty.iter().any(|&p| p > 3.0));
    }

    #[test]
    fn a_robot_that_circles_the_goal_without_nearing_it_gives_it_up_after_give_up_s() {
        let cfg = robot(box_map(1500.0), [0.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let goal = Point2::origin();
        // Round the goal at 800 mm, once every 8 s: moving, on open floor, never nearer.
        let at = |t: f64| {
            let a = TAU * t / 8.0;
            Isometry2::new(Vector2::new(-800.0 * a.cos(), 800.0 * a.sin()), 0.0)
        };
        let mut t = 0.0;
        while t < 29.5 {
            nav.steer(Some(&open_floor()), &at(t), Vector2::zeros(), goal, t);
            assert!(nav.report().unreachable.is_none(), "not yet at {t} s");
            t += 0.04;
        }
        while t < 30.5 {
            nav.steer(Some(&open_floor()), &at(t), Vector2::zeros(), goal, t);
            t += 0.04;
        }
        assert_eq!(nav.report().unreachable, Some(Unreachable::NoProgress));
        // A robot that nears the goal steadily is never given up.
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let mut t = 0.0;
        while t < 40.0 {
            let x = -1400.0 + 30.0 * t;
            let pose = Isometry2::new(Vector2::new(x, 0.0), 0.0);
            nav.steer(Some(&open_floor()), &pose, Vector2::zeros(), goal, t);
            assert!(nav.report().unreachable.is_none(), "given up at {t} s");
            t += 0.04;
        }
    }

    /// A box with a corridor 300 mm wide between the walls' faces from the robot to the goal:
    /// the only route, and a narrow one (under `OPEN_ROOM_MM` from the walls).
    fn corridor_map() -> WorldMap {
        let mut map = box_map(1500.0);
        for y in [-175.0, 175.0] {
            map.bounds.push(MapSegment {
                from_mm: Point2::new(-1300.0, y),
                to_mm: Point2::new(1300.0, y),
                half_thickness_mm: 25.0,
            });
        }
        map
    }

    #[test]
    fn a_robot_that_makes_no_progress_closes_the_place_ahead_and_twice_there_gives_the_goal_up() {
        let cfg = robot(corridor_map(), [1000.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let goal = Point2::new(1000.0, 0.0);
        let mut t = 0.0;
        // The robot stands where it is, whatever it is told (held up by what it cannot pass).
        while t < 10.5 {
            nav.steer(Some(&open_floor()), &cfg.start, Vector2::zeros(), goal, t);
            t += 0.04;
        }
        assert_eq!(nav.report().closed, 1, "closed once after stall_s (10 s)");
        assert!(nav.closed.contains(&1) && !nav.closed.contains(&2));
        assert!(
            nav.report().unreachable.is_none(),
            "the only route is dearer, not shut"
        );
        while t < 25.0 {
            nav.steer(Some(&open_floor()), &cfg.start, Vector2::zeros(), goal, t);
            t += 0.04;
        }
        assert_eq!(nav.report().closed, 2);
        assert!(nav.closed.contains(&2), "failed there again: impassable");
        assert_eq!(nav.report().unreachable, Some(Unreachable::NoProgress));
        // A new target opens every place again.
        let other = Point2::new(-1300.0, 0.0);
        nav.steer(Some(&open_floor()), &cfg.start, Vector2::zeros(), other, t);
        assert!(nav.closed.iter().all(|&c| c == 0));
        assert!(nav.report().unreachable.is_none());
    }

    #[test]
    fn a_step_the_controller_refuses_for_refuse_s_closes_the_gap_ahead_to_the_planner() {
        let cfg = robot(corridor_map(), [1000.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let goal = Point2::new(1000.0, 0.0);
        let mut t = 0.0;
        let step = |nav: &mut Navigator, t: f64, command: Vector2<f64>| {
            nav.steer(Some(&open_floor()), &cfg.start, Vector2::zeros(), goal, t);
            nav.heard(command, Vector2::zeros(), &cfg.start, t);
        };
        // Heading on toward the plan's point: no refusal, however long.
        while t < 3.9 {
            step(&mut nav, t, Vector2::new(200.0, 0.0));
            t += 0.04;
        }
        assert_eq!(nav.report().closed, 0);
        // Sideways only, standing: the controller refuses the plan's step.
        let from = t;
        while t < from + 3.9 {
            step(&mut nav, t, Vector2::new(0.0, 100.0));
            t += 0.04;
        }
        assert_eq!(nav.report().closed, 0, "not before refuse_s (4 s)");
        step(&mut nav, t + 0.2, Vector2::new(0.0, 100.0));
        assert_eq!(nav.report().closed, 1);
        assert!(nav.closed.contains(&1));
    }

    #[test]
    fn the_map_says_how_far_the_floor_is_free_along_a_ray() {
        let cfg = robot(box_map(1500.0), [1000.0, 0.0]);
        let mut nav = Navigator::new(&cfg, PlannerConfig::default()).unwrap();
        let u = Vector2::new(1.0, 0.0);
        // Nothing seen yet: no floor known beyond the body's edge.
        assert_eq!(nav.free_along(&cfg.start, u, 90.0, 200.0), 90.0);
        for k in 0..10 {
            nav.steer(
                Some(&open_floor()),
                &cfg.start,
                Vector2::zeros(),
                Point2::new(1000.0, 0.0),
                k as f64 * 0.04,
            );
        }
        // Open floor seen from here and there: free out to the template's inner edge. (The
        // floor under the body is never seen: seen from where the robot stands, the map holds
        // only what lies beyond the inner edge.)
        let d = nav.free_along(
            &(cfg.start * Isometry2::translation(-300.0, 0.0)),
            u,
            90.0,
            200.0,
        );
        assert!((d - 200.0).abs() < 1e-9, "{d}");
        // Toward the box's wall (its face at x = -1475), from 175 mm off it: the walk ends in
        // the last free cell, half a cell's diagonal short of the first not free.
        let by_wall = Isometry2::new(Vector2::new(-1300.0, 0.0), 0.0);
        let d = nav.free_along(&by_wall, -u, 90.0, 400.0);
        assert!(d > 120.0 && d < 175.0, "{d}");
    }

    #[test]
    fn a_grid_too_large_for_its_cells_is_a_config_error_naming_the_field() {
        let mut cfg = robot(WorldMap::default(), [200_000.0, 0.0]);
        cfg.goal = Some(GoalSpec::to([200_000.0, 0.0], 100.0));
        let err = Navigator::new(&cfg, PlannerConfig::default()).unwrap_err();
        assert!(err.to_string().contains("control.planner.cell_mm"), "{err}");
    }
}
