//! The self-localization error map: the robot is carried to every point of a grid over the
//! whole floor region, at several headings, and localizes itself from one frame at each in both
//! modes of `vision::floor_localization`: global (from the image alone) and tracking (from a
//! prior pose off the truth by a set distance and angle, as an estimator's could be). Each
//! estimate is scored against the truth; places reported "not localized" are counted apart,
//! with the reason. `omniloop replay selfloc` runs it after E2 and writes `selfloc_map.png`
//! (the figure a user looks at first) and `selfloc_map.csv` (one row per place and mode).

use super::experiment::{Experiment, ExperimentEntry, ExperimentSetup, MetricKeys, Metrics, setup};
use crate::report::topview::{Mark, Panel, Spots, panels_png};
use crate::run::record::Summary;
use crate::run::{OutputFile, RunError, RunOutput, Simulation};
use crate::scenario::Problems;
use crate::scenario::Scenario;
use nalgebra::{Isometry2, Point2, Vector2};
use omniloop_control::wrap_pi;
use omniloop_robot::perception::floor_localization;
use omniloop_sim::SimError;
use omniloop_vision::{
    FloorLocalizer, Localization, LocalizationConfig, LocalizationMethod, LocalizationQuality,
};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::fmt::Write as _;

/// The map's grid and priors (`[experiment.localization_map]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapSpec {
    /// Largest distance between neighbouring grid points along x and y, mm. The points are
    /// spread evenly over where the robot's centre can stand.
    pub spacing_mm: f64,
    /// Headings tried at every grid point, degrees.
    pub headings_deg: Vec<f64>,
    /// Tracking mode: how far the prior's position is from the truth, mm (in a direction drawn
    /// at random).
    pub prior_error_mm: f64,
    /// ... and how far its heading is turned, degrees (either way, drawn at random).
    pub prior_error_deg: f64,
    /// Grid points where the robot's body would come closer than this to a wall or an
    /// obstacle are left out, mm.
    pub clearance_mm: f64,
}

impl Default for MapSpec {
    fn default() -> Self {
        Self {
            spacing_mm: 150.0,
            // A quarter turn apart, none along the field's axes.
            headings_deg: vec![20.0, 110.0, 200.0, 290.0],
            prior_error_mm: 150.0,
            prior_error_deg: 10.0,
            clearance_mm: 10.0,
        }
    }
}

impl MapSpec {
    fn validate(&self, s: &Scenario, c: &mut Problems) {
        let at = "experiment.localization_map";
        if !(self.spacing_mm.is_finite() && self.spacing_mm >= 20.0) {
            c.fail(
                format!("{at}.spacing_mm"),
                format!("must be a finite number >= 20 (got {})", self.spacing_mm),
            );
        }
        if self.headings_deg.is_empty() {
            c.fail(format!("{at}.headings_deg"), "needs at least one heading");
        }
        for (i, h) in self.headings_deg.iter().enumerate() {
            c.finite(format!("{at}.headings_deg[{i}]"), *h);
        }
        for (name, v) in [
            ("prior_error_mm", self.prior_error_mm),
            ("prior_error_deg", self.prior_error_deg),
            ("clearance_mm", self.clearance_mm),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                c.fail(
                    format!("{at}.{name}"),
                    format!("must be a finite number >= 0 (got {v})"),
                );
            }
        }
        if s.control.pose_source != floor_localization::POSE_SOURCE {
            c.fail(
                at,
                "the map localizes the robot's camera images: set control.pose_source = \
                 \"localization\"",
            );
        } else if self.spacing_mm >= 20.0 && grid(self, s).is_empty() {
            c.fail(
                at,
                "no grid point leaves the robot's body clear of the walls and obstacles",
            );
        }
    }
}

/// The registry's entry: `[experiment.localization_map]`.
pub const ENTRY: ExperimentEntry = ExperimentEntry {
    name: "localization_map",
    summary: "the self-localization error map: a grid over the whole floor region, both modes",
    setup: |t| setup::<MapSpec>(t, "localization_map"),
};

impl ExperimentSetup for MapSpec {
    fn check(&self, s: &Scenario, c: &mut Problems) {
        self.validate(s, c);
    }

    fn table(&self, summary: &Summary) -> Option<String> {
        Some(map_table(summary))
    }

    fn procedure(&self, s: &Scenario) -> Result<Box<dyn Experiment>, RunError> {
        let config: LocalizationConfig = s.vision.table("localization")?;
        Ok(Box::new(LocalizationMap::new(self, config)))
    }
}

/// The grid points: evenly spread over the floor region's bounding box less the robot's
/// radius and the clearance, `spacing_mm` apart at most, where the robot's body stands clear
/// of every wall and obstacle.
pub fn grid(spec: &MapSpec, s: &Scenario) -> Vec<Point2<f64>> {
    let layout = &s.world;
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for r in layout.all_floor_rects() {
        let (sin, cos) = r.angle_deg.to_radians().sin_cos();
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            let (dx, dy) = (a * r.size_mm[0] / 2.0, b * r.size_mm[1] / 2.0);
            let (x, y) = (
                r.center_mm[0] + cos * dx - sin * dy,
                r.center_mm[1] + sin * dx + cos * dy,
            );
            (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
        }
    }
    let body = s.robot.radius_mm + spec.clearance_mm;
    if x0 > x1 || x1 - x0 < 2.0 * body || y1 - y0 < 2.0 * body {
        return Vec::new();
    }
    let axis = |lo: f64, hi: f64| -> Vec<f64> {
        let n = ((hi - lo) / spec.spacing_mm).ceil().max(0.0) as usize + 1;
        if n == 1 {
            return vec![(lo + hi) / 2.0];
        }
        (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect()
    };
    let solids = layout.solids();
    let fits = |p: Point2<f64>| {
        layout.is_floor(p) && solids.iter().all(|o| o.shape.distance_mm(p) >= body)
    };
    let ys = axis(y0 + body, y1 - body);
    axis(x0 + body, x1 - body)
        .into_iter()
        .flat_map(|x| ys.iter().map(move |&y| Point2::new(x, y)))
        .filter(|&p| fits(p))
        .collect()
}

/// A mode of the localizer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// From the image alone.
    Global,
    /// From a prior pose.
    Tracking,
}

impl Mode {
    const ALL: [Mode; 2] = [Mode::Global, Mode::Tracking];

    fn name(self) -> &'static str {
        match self {
            Mode::Global => "global",
            Mode::Tracking => "tracking",
        }
    }
}

/// One localization at one place in one mode.
#[derive(Debug, Clone, PartialEq)]
pub struct MapEntry {
    /// The mode.
    pub mode: Mode,
    /// The true pose: x_mm, y_mm, heading_deg.
    pub truth: [f64; 3],
    /// The prior given (tracking): x_mm, y_mm, heading_deg.
    pub prior: Option<[f64; 3]>,
    /// The estimate's position error, mm (`None`: not localized).
    pub error_mm: Option<f64>,
    /// ... and heading error, degrees.
    pub error_deg: Option<f64>,
    /// Whether the estimate's half-turn twin lies nearer the truth (the wrong solution).
    pub wrong_twin: bool,
    /// Whether the goals' colours chose the solution.
    pub resolved_by_goals: bool,
    /// The estimate's quality record.
    pub quality: Option<LocalizationQuality>,
    /// Why it was not localized (empty when it was).
    pub reason: String,
}

/// The bands of the map's colours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Band {
    Within10,
    Within30,
    Within100,
    Gross,
    NotLocalized,
}

impl Band {
    const ALL: [Band; 5] = [
        Band::Within10,
        Band::Within30,
        Band::Within100,
        Band::Gross,
        Band::NotLocalized,
    ];

    fn of(e: &MapEntry) -> Band {
        match (e.error_mm, e.error_deg) {
            (Some(mm), Some(deg)) if mm <= 10.0 && deg <= 1.0 => Band::Within10,
            (Some(mm), Some(deg)) if mm <= 30.0 && deg <= 1.0 => Band::Within30,
            (Some(mm), Some(deg)) if mm <= 100.0 && deg <= 5.0 => Band::Within100,
            (Some(_), Some(_)) => Band::Gross,
            _ => Band::NotLocalized,
        }
    }

    fn label(self) -> &'static str {
        match self {
            Band::Within10 => "within 10 mm and 1 deg",
            Band::Within30 => "within 30 mm and 1 deg",
            Band::Within100 => "within 100 mm and 5 deg",
            Band::Gross => "gross, over 100 mm or 5 deg",
            Band::NotLocalized => "not localized",
        }
    }

    fn rgb(self) -> [u8; 3] {
        match self {
            Band::Within10 => [30, 80, 220],
            Band::Within30 => [0, 200, 230],
            Band::Within100 => [250, 160, 0],
            Band::Gross => [220, 0, 0],
            Band::NotLocalized => [0, 0, 0],
        }
    }
}

/// The map's metrics (`summary.json`: `map`, then a key per mode).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LocalizationMapMetrics {
    /// How the map was made.
    pub map: MapSettings,
    /// The figures of global mode.
    pub global: ModeStats,
    /// The figures of tracking mode.
    pub tracking: ModeStats,
}

impl Metrics for LocalizationMapMetrics {}

impl LocalizationMapMetrics {
    /// The figures of `mode`.
    pub fn mode(&self, mode: Mode) -> &ModeStats {
        match mode {
            Mode::Global => &self.global,
            Mode::Tracking => &self.tracking,
        }
    }
}

/// The procedure and metrics of the map.
pub struct LocalizationMap {
    spec: MapSpec,
    config: LocalizationConfig,
    entries: Vec<MapEntry>,
}

impl LocalizationMap {
    /// The map `spec` describes, localizing with the settings `config`.
    pub fn new(spec: &MapSpec, config: LocalizationConfig) -> Self {
        Self {
            spec: spec.clone(),
            config,
            entries: Vec::new(),
        }
    }
}

/// How the map was made (`summary.json`: `map`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapSettings {
    /// The method of `[vision.localization]`.
    pub method: LocalizationMethod,
    /// The grid and priors.
    pub spec: MapSpec,
}

/// The seed of the priors' offsets, derived from the run's seed.
fn prior_seed(seed: u64) -> u64 {
    seed ^ 0x7E1F_3A90_5C4D_2B18
}

/// `[x_mm, y_mm, heading_deg]` of a pose.
fn triple(p: &Isometry2<f64>) -> [f64; 3] {
    [
        p.translation.x,
        p.translation.y,
        p.rotation.angle().to_degrees(),
    ]
}

/// Scores one localization against the truth.
fn score(
    mode: Mode,
    truth: &Isometry2<f64>,
    prior: Option<&Isometry2<f64>>,
    result: Localization,
) -> MapEntry {
    let mut e = MapEntry {
        mode,
        truth: triple(truth),
        prior: prior.map(triple),
        error_mm: None,
        error_deg: None,
        wrong_twin: false,
        resolved_by_goals: false,
        quality: None,
        reason: String::new(),
    };
    match result {
        Localization::Localized(est) => {
            let err = |q: &Isometry2<f64>| (q.translation.vector - truth.translation.vector).norm();
            e.error_mm = Some(err(&est.pose));
            e.error_deg = Some(
                wrap_pi(est.pose.rotation.angle() - truth.rotation.angle())
                    .abs()
                    .to_degrees(),
            );
            e.wrong_twin = err(&est.alternative) < err(&est.pose);
            e.resolved_by_goals = est.quality.resolved_by_goals;
            e.quality = Some(est.quality);
        }
        Localization::NotLocalized(why) => e.reason = why,
    }
    e
}

impl LocalizationMap {
    /// The metrics of the places localized so far.
    fn measure(&self) -> LocalizationMapMetrics {
        let stats = |mode| ModeStats::of(self.entries.iter().filter(|e| e.mode == mode));
        LocalizationMapMetrics {
            map: MapSettings {
                method: self.config.method,
                spec: self.spec.clone(),
            },
            global: stats(Mode::Global),
            tracking: stats(Mode::Tracking),
        }
    }
}

impl Experiment for LocalizationMap {
    fn drives(&self) -> bool {
        false
    }

    /// Carries the robot to every grid point and heading; at each, one frame, localized in
    /// global mode and, from a prior `prior_error_mm` and `prior_error_deg` off, in tracking
    /// mode.
    fn run(
        &mut self,
        sim: &mut Simulation,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<(), RunError> {
        let s = sim.scenario().clone();
        let cal = sim.vision_calibration().cloned().ok_or_else(|| {
            SimError::Invalid("the localization map needs the robot's vision camera".into())
        })?;
        let mut global = FloorLocalizer::new(self.config.clone(), &cal)?;
        let mut tracking = FloorLocalizer::new(self.config.clone(), &cal)?;
        let mut rng = StdRng::seed_from_u64(prior_seed(s.seed));
        let points = grid(&self.spec, &s);
        let total = (points.len() * self.spec.headings_deg.len()) as u64;
        let mut done = 0;
        for p in &points {
            for h in &self.spec.headings_deg {
                let truth = Isometry2::new(p.coords, h.to_radians());
                sim.place_robot(truth);
                let direction = rng.random_range(0.0..TAU);
                let turn = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                let prior = Isometry2::new(
                    p.coords
                        + self.spec.prior_error_mm * Vector2::new(direction.cos(), direction.sin()),
                    truth.rotation.angle() + turn * self.spec.prior_error_deg.to_radians(),
                );
                let img = sim.vision_frame()?.ok_or_else(|| {
                    SimError::Invalid("the robot's vision camera is not rendered".into())
                })?;
                let g = global.locate(img, None)?;
                let t = tracking.track(img, &prior)?;
                for (mode, prior, result) in
                    [(Mode::Global, None, g), (Mode::Tracking, Some(&prior), t)]
                {
                    let mut entry = score(mode, &truth, prior, result);
                    // The heading as the spec gives it, not wrapped into (-180, 180].
                    entry.truth[2] = *h;
                    self.entries.push(entry);
                }
                done += 1;
                progress(done, total);
            }
        }
        Ok(())
    }

    fn metrics(&self, _out: &RunOutput) -> MetricKeys {
        self.measure().keys()
    }

    fn files(&self, scenario: &Scenario, out: &RunOutput) -> Result<Vec<OutputFile>, RunError> {
        let png = map_figure(scenario, &out.summary, &self.entries)
            .map_err(|e| SimError::Invalid(e.to_string()))?;
        Ok(vec![
            OutputFile {
                name: "selfloc_map.csv".into(),
                bytes: map_csv(&self.entries).into_bytes(),
            },
            OutputFile {
                name: "selfloc_map.png".into(),
                bytes: png,
            },
        ])
    }
}

/// The figures of one mode (`summary.json`: `global`, `tracking`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ModeStats {
    /// Places tried (grid points times headings).
    pub places: usize,
    /// Places with an estimate.
    pub localized: usize,
    /// Estimates over 100 mm or 5 degrees off.
    pub gross: usize,
    /// Estimates over 30 mm or 1 degree off (the gross ones included).
    pub beyond_30mm_1deg: usize,
    /// Estimates that took the wrong one of the two half-turn solutions.
    pub wrong_twin: usize,
    /// Median position error of the estimates, mm.
    pub median_error_mm: Option<f64>,
    /// 95th percentile, mm.
    pub p95_error_mm: Option<f64>,
    /// The largest position error and where (x_mm, y_mm, heading_deg).
    pub worst_error_mm: Option<(f64, [f64; 3])>,
    /// The largest heading error (degrees) and where.
    pub worst_heading_deg: Option<(f64, [f64; 3])>,
    /// Why places were not localized: the reason's words before its figures, and how often.
    pub not_localized: Vec<(String, usize)>,
}

impl ModeStats {
    fn of<'a>(entries: impl Iterator<Item = &'a MapEntry>) -> Self {
        let mut st = Self::default();
        let mut errors = Vec::new();
        for e in entries {
            st.places += 1;
            let (Some(mm), Some(deg)) = (e.error_mm, e.error_deg) else {
                let why = reason_kind(&e.reason);
                match st.not_localized.iter_mut().find(|(k, _)| *k == why) {
                    Some((_, n)) => *n += 1,
                    None => st.not_localized.push((why, 1)),
                }
                continue;
            };
            st.localized += 1;
            st.gross += usize::from(mm > 100.0 || deg > 5.0);
            st.beyond_30mm_1deg += usize::from(mm > 30.0 || deg > 1.0);
            st.wrong_twin += usize::from(e.wrong_twin);
            errors.push(mm);
            if st.worst_error_mm.is_none_or(|(w, _)| mm > w) {
                st.worst_error_mm = Some((mm, e.truth));
            }
            if st.worst_heading_deg.is_none_or(|(w, _)| deg > w) {
                st.worst_heading_deg = Some((deg, e.truth));
            }
        }
        errors.sort_by(f64::total_cmp);
        let at = |q: f64| {
            errors
                .get(((errors.len() as f64 - 1.0) * q).round() as usize)
                .copied()
        };
        st.median_error_mm = at(0.5);
        st.p95_error_mm = at(0.95);
        st.not_localized
            .sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        st
    }
}

/// A reason's kind: its words up to the first figure or parenthesis ("fit residual",
/// "the fitted field explains only").
fn reason_kind(reason: &str) -> String {
    let first = reason.split(';').next().unwrap_or(reason);
    let cut = first
        .find(|c: char| c.is_ascii_digit() || c == '(')
        .unwrap_or(first.len());
    first[..cut].trim().trim_end_matches(':').to_string()
}

/// The figures of one mode in a summary.
pub fn mode_stats(m: &Summary, mode: Mode) -> Option<ModeStats> {
    LocalizationMapMetrics::of(m).map(|x| x.mode(mode).clone())
}

/// The map as a Markdown table, one row per mode.
pub fn map_table(m: &Summary) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Self-localization error map\n");
    let settings = LocalizationMapMetrics::of(m).map(|x| x.map);
    let how = settings.map_or(String::new(), |st| {
        format!(
            " Method: {}. Grid {} mm apart at most, headings {:?} deg; tracking priors {} mm and \
             {} deg off the truth.",
            match st.method {
                LocalizationMethod::Paper => "the paper's",
                LocalizationMethod::Robust => "robust",
            },
            st.spec.spacing_mm,
            st.spec.headings_deg,
            st.spec.prior_error_mm,
            st.spec.prior_error_deg,
        )
    });
    let _ = writeln!(
        s,
        "Renderer: {}. Seed {}.{how} Every grid place localized from one frame, in global mode \
         (no prior) and in tracking mode (from the prior).\n",
        m.renderer.clone().unwrap_or_else(|| "-".into()),
        m.seed
    );
    let _ = writeln!(
        s,
        "| mode | places | localized | gross (> 100 mm or > 5 deg) | > 30 mm or > 1 deg | wrong twin | median (mm) | p95 (mm) | worst (mm) at | worst (deg) at |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|---:|---|---|");
    let fmt = |v: Option<f64>| v.map_or("-".into(), |x| format!("{x:.1}"));
    let worst = |w: Option<(f64, [f64; 3])>, digits: usize| {
        w.map_or("-".into(), |(v, p)| {
            format!("{v:.digits$} at ({:.0}, {:.0}, {:.0})", p[0], p[1], p[2])
        })
    };
    for mode in Mode::ALL {
        let Some(st) = mode_stats(m, mode) else {
            continue;
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} ({:.1}%) | {} | {} | {} | {} | {} | {} | {} |",
            mode.name(),
            st.places,
            st.localized,
            100.0 * st.localized as f64 / st.places.max(1) as f64,
            st.gross,
            st.beyond_30mm_1deg,
            st.wrong_twin,
            fmt(st.median_error_mm),
            fmt(st.p95_error_mm),
            worst(st.worst_error_mm, 1),
            worst(st.worst_heading_deg, 2),
        );
    }
    for mode in Mode::ALL {
        if let Some(st) = mode_stats(m, mode)
            && !st.not_localized.is_empty()
        {
            let reasons: Vec<String> = st
                .not_localized
                .iter()
                .map(|(k, n)| format!("{k} ({n})"))
                .collect();
            let _ = writeln!(
                s,
                "\nNot localized, {}: {}.",
                mode.name(),
                reasons.join("; ")
            );
        }
    }
    s
}

/// One row per place and mode.
fn map_csv(entries: &[MapEntry]) -> String {
    let mut s = String::from(
        "mode,x_mm,y_mm,heading_deg,prior_x_mm,prior_y_mm,prior_heading_deg,localized,\
         error_mm,error_deg,wrong_twin,resolved_by_goals,rms_residual_mm,points,\
         boundary_points,inlier_fraction,sigma_x_mm,sigma_y_mm,sigma_deg,hull_cut,reason\n",
    );
    let num = |v: Option<f64>| v.map_or(String::new(), |x| format!("{x:.3}"));
    for e in entries {
        let q = e.quality.as_ref();
        let [px, py, ph] = e.prior.map_or([None; 3], |p| p.map(Some));
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},\"{}\"",
            e.mode.name(),
            e.truth[0],
            e.truth[1],
            e.truth[2],
            num(px),
            num(py),
            num(ph),
            u8::from(e.error_mm.is_some()),
            num(e.error_mm),
            num(e.error_deg),
            u8::from(e.wrong_twin),
            u8::from(e.resolved_by_goals),
            num(q.map(|q| q.rms_residual_mm)),
            q.map_or(String::new(), |q| q.points.to_string()),
            q.map_or(String::new(), |q| q.boundary_points.to_string()),
            num(q.map(|q| q.inlier_fraction)),
            num(q.map(|q| q.sigma[0])),
            num(q.map(|q| q.sigma[1])),
            num(q.map(|q| q.sigma[2].to_degrees())),
            q.map_or(String::new(), |q| u8::from(q.hull_cut).to_string()),
            e.reason.replace('"', "\"\""),
        );
    }
    s
}

/// The map: one panel per mode, every place a spot set off from its grid point toward its
/// heading, coloured by its error band.
fn map_figure(
    scenario: &Scenario,
    summary: &Summary,
    entries: &[MapEntry],
) -> Result<Vec<u8>, crate::report::topview::FigureError> {
    // Far enough from the grid point to tell the headings apart, near enough to stay by it.
    const OFFSET_MM: f64 = 45.0;
    let panels: Vec<Panel<'_>> = Mode::ALL
        .iter()
        .map(|&mode| {
            let spots = Band::ALL
                .iter()
                .map(|&band| {
                    let points: Vec<Point2<f64>> = entries
                        .iter()
                        .filter(|e| e.mode == mode && Band::of(e) == band)
                        .map(|e| {
                            let h = e.truth[2].to_radians();
                            Point2::new(
                                e.truth[0] + OFFSET_MM * h.cos(),
                                e.truth[1] + OFFSET_MM * h.sin(),
                            )
                        })
                        .collect();
                    Spots {
                        label: format!("{} ({})", band.label(), points.len()),
                        rgb: band.rgb(),
                        points,
                        mark: if band == Band::NotLocalized {
                            Mark::Cross
                        } else {
                            Mark::Disc
                        },
                        size_px: 4,
                    }
                })
                .collect();
            let st = mode_stats(summary, mode).unwrap_or_default();
            Panel {
                title: format!(
                    "{} mode: {} of {} places localized, {} gross",
                    mode.name(),
                    st.localized,
                    st.places,
                    st.gross
                ),
                layout: &scenario.world,
                paths: Vec::new(),
                markers: Vec::new(),
                spots,
                grid: None,
            }
        })
        .collect();
    panels_png("selfloc_map.png", &panels, 1000)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::experiment::tests::round_trip;

    #[test]
    fn reasons_are_grouped_by_their_words() {
        assert_eq!(
            reason_kind("fit residual 31.2 mm (at most 25.0)"),
            "fit residual"
        );
        assert_eq!(
            reason_kind("tracking: the fitted field explains only 41% of the boundary points"),
            "tracking: the fitted field explains only"
        );
        assert_eq!(
            reason_kind("floor region too small (812 pixels, need 2000)"),
            "floor region too small"
        );
    }

    #[test]
    fn bands_follow_the_targets() {
        let mut e = MapEntry {
            mode: Mode::Global,
            truth: [0.0; 3],
            prior: None,
            error_mm: Some(29.0),
            error_deg: Some(0.5),
            wrong_twin: false,
            resolved_by_goals: true,
            quality: None,
            reason: String::new(),
        };
        assert_eq!(Band::of(&e), Band::Within30);
        e.error_deg = Some(1.5);
        assert_eq!(Band::of(&e), Band::Within100);
        e.error_mm = Some(101.0);
        assert_eq!(Band::of(&e), Band::Gross);
        e.error_mm = None;
        assert_eq!(Band::of(&e), Band::NotLocalized);
    }

    #[test]
    fn the_metrics_read_back_from_the_summary_for_the_table() {
        let mut map = LocalizationMap::new(&MapSpec::default(), LocalizationConfig::default());
        let entry = |mode, error_mm: Option<f64>| MapEntry {
            mode,
            truth: [100.0, -200.0, 90.0],
            prior: None,
            error_mm,
            error_deg: error_mm.map(|_| 0.4),
            wrong_twin: false,
            resolved_by_goals: true,
            quality: None,
            reason: if error_mm.is_some() {
                String::new()
            } else {
                "fit residual 31.2 mm (at most 25.0)".into()
            },
        };
        map.entries = vec![
            entry(Mode::Global, Some(12.0)),
            entry(Mode::Global, None),
            entry(Mode::Tracking, Some(4.0)),
        ];
        let m = map.measure();
        assert_eq!((m.global.places, m.global.localized), (2, 1));
        assert_eq!(m.tracking.median_error_mm, Some(4.0));
        let summary = round_trip(&m);
        let keys: Vec<&String> = summary.experiment.keys().collect();
        assert_eq!(keys, ["map", "global", "tracking"]);
        assert_eq!(mode_stats(&summary, Mode::Global), Some(m.global.clone()));
        let table = map_table(&summary);
        assert!(
            table.contains("Not localized, global: fit residual (1)."),
            "{table}"
        );
        assert!(table.contains("| tracking | 1 | 1 (100.0%) |"), "{table}");
    }
}
