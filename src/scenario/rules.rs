//! The rules a parsed scenario must satisfy, checked once, each failure naming the dotted path
//! of the field it concerns (each experiment adds its own through its registry entry).

use super::check::PoseChecks;
use super::schema::{PilotChoice, Scenario, TimingSpec};
use nalgebra::Point2;
use omniloop_problem::{FieldPath, Problem, Problems};
use omniloop_robot::controllers::{self, CONTROLLERS};
use omniloop_robot::perception::{self, CameraNeed, STAGES, WorldNeed};
use omniloop_robot::{ControllerEntry, RobotConfig, StageEntry};
use omniloop_sim::optics::Optics;
use omniloop_sim::{Layout, SensorSpec};

fn in_floor(world: &Layout, p: Point2<f64>) -> bool {
    world.is_floor(p)
}

/// Every rule the scenario breaks (empty when it is valid).
pub fn validate(s: &Scenario) -> Vec<Problem> {
    let mut c = Problems::new();
    check_run(&mut c, s);
    check_world(&mut c, &s.world);
    check_robot(&mut c, s);
    check_other_robots(&mut c, s);
    check_ball(&mut c, s);
    check_goal(&mut c, s);
    check_software(&mut c, s);
    if let Some(ssl) = &s.ssl {
        c.extend(ssl.check(&s.robot_names()).into_vec());
    }
    if let Some(g) = &s.goal {
        for (k, wp) in g.waypoints_mm.iter().enumerate() {
            if !in_floor(&s.world, Point2::new(wp[0], wp[1])) {
                c.fail(
                    format!("goal.waypoints_mm[{k}]"),
                    format!("({}, {}) mm is outside the floor region", wp[0], wp[1]),
                );
            }
        }
    }
    if s.experiment.0.len() > 1 {
        let names: Vec<&str> = s.experiment.names().collect();
        c.fail(
            "experiment",
            format!(
                "a scenario belongs to one experiment (found {})",
                names.join(", ")
            ),
        );
    }
    c.into_vec()
}

/// `[run]`: positive times, the physics step dividing the control period.
fn check_run(c: &mut Problems, s: &Scenario) {
    let r = &s.run;
    c.positive("run.duration_s", r.duration_s);
    c.positive("run.control_period_s", r.control_period_s);
    c.positive("run.physics_step_s", r.physics_step_s);
    if r.physics_step_s > 0.0 && r.control_period_s > 0.0 {
        let n = r.control_period_s / r.physics_step_s;
        if r.physics_step_s > r.control_period_s || (n - n.round()).abs() > 1e-6 {
            c.fail(
                "run.physics_step_s",
                format!(
                    "must divide run.control_period_s = {} s into a whole number of steps \
                     (got {} s)",
                    r.control_period_s, r.physics_step_s
                ),
            );
        }
    }
}

/// `[world]`: every thing on the floor, each kind checking its own entries.
fn check_world(c: &mut Problems, w: &Layout) {
    c.extend(w.check());
}

/// `[robot]`: its body, where it starts, and its sensors (named once each).
fn check_robot(c: &mut Problems, s: &Scenario) {
    let w = &s.world;
    let rb = &s.robot;
    if let Some(d) = &rb.differential {
        c.positive("robot.differential.track_mm", d.track_mm);
        c.positive(
            "robot.differential.max_turn_rate_deg_s",
            d.max_turn_rate_deg_s,
        );
    }
    c.positive("robot.radius_mm", rb.radius_mm);
    c.positive("robot.height_mm", rb.height_mm);
    c.positive("robot.max_speed_mm_s", rb.max_speed_mm_s);
    c.positive("robot.accel_limit_mm_s2", rb.accel_limit_mm_s2);
    c.positive(
        "robot.angular_accel_limit_rad_s2",
        rb.angular_accel_limit_rad_s2,
    );
    match &rb.start {
        Some(start) => c.pose_in_world("robot.start", start, rb.radius_mm, w),
        None => c.fail(
            "robot.start",
            "missing: where the robot starts, e.g. start = { x_mm = 0.0, y_mm = 0.0 }",
        ),
    }
    if let Some(k) = &rb.kicker {
        let mut p = Problems::under("robot.kicker");
        k.check(rb.radius_mm, &mut p);
        c.extend(p);
    }
    for (i, sensor) in rb.sensors.iter().enumerate() {
        check_sensor(c, &format!("robot.sensors[{i}]"), sensor);
        if rb.sensors[..i].iter().any(|o| o.name == sensor.name) {
            c.fail(
                format!("robot.sensors[{i}].name"),
                format!("sensor name {:?} is used twice", sensor.name),
            );
        }
    }
}

/// `[world.ball]` clear of every robot at the start (its figures and its place on the floor
/// are its kind's check).
fn check_ball(c: &mut Problems, s: &Scenario) {
    let Some(b) = &s.world.ball else {
        return;
    };
    let at = Point2::from(b.center_mm);
    if !(at.x.is_finite() && at.y.is_finite() && b.radius_mm > 0.0) {
        return;
    }
    let names = s.robot_names();
    for (i, body) in s.robot_bodies().iter().enumerate() {
        let local = body.start.inverse_transform_point(&at);
        let front = body.kicker.map(|k| k.front_mm);
        let (d, _) = omniloop_sim::kicker::body_distance(local, body.radius_mm, front);
        // Touching (at its front, where a kicker plays it) is allowed; overlapping is not.
        if d < b.radius_mm - 1e-6 {
            let name = names.get(i).cloned();
            let name = name.unwrap_or_else(|| format!("other_robots[{}]", i - names.len()));
            c.fail(
                "world.ball.center_mm",
                format!("({}, {}) mm is inside robot {name}", at.x, at.y),
            );
        }
    }
}

/// `[[other_robots]]`: their bodies, starts and waypoints on the floor.
fn check_other_robots(c: &mut Problems, s: &Scenario) {
    let w = &s.world;
    for (i, o) in s.other_robots.iter().enumerate() {
        let p = format!("other_robots[{i}]");
        c.positive(format!("{p}.radius_mm"), o.radius_mm);
        c.positive(format!("{p}.height_mm"), o.height_mm);
        c.positive(format!("{p}.max_speed_mm_s"), o.max_speed_mm_s);
        c.positive(format!("{p}.accel_limit_mm_s2"), o.accel_limit_mm_s2);
        c.pose_in_world(&format!("{p}.start"), &o.start, o.radius_mm, w);
        for (k, wp) in o.waypoints_mm.iter().enumerate() {
            if !in_floor(w, Point2::new(wp[0], wp[1])) {
                c.fail(
                    format!("{p}.waypoints_mm[{k}]"),
                    format!("({}, {}) mm is outside the floor region", wp[0], wp[1]),
                );
            }
        }
    }
}

/// `[goal]`: a finite point on the floor, a tolerance with room for the estimate's margin.
fn check_goal(c: &mut Problems, s: &Scenario) {
    let w = &s.world;
    if let Some(g) = &s.goal {
        c.finite("goal.x_mm", g.x_mm);
        c.finite("goal.y_mm", g.y_mm);
        c.positive("goal.tolerance_mm", g.tolerance_mm);
        if !(g.estimate_margin_mm >= 0.0 && g.estimate_margin_mm < g.tolerance_mm) {
            c.fail(
                "goal.estimate_margin_mm",
                format!(
                    "must lie in [0, tolerance_mm = {}) (got {})",
                    g.tolerance_mm, g.estimate_margin_mm
                ),
            );
        }
        if !in_floor(w, g.point()) {
            c.fail(
                "goal.x_mm",
                format!(
                    "goal ({}, {}) mm is outside the floor region",
                    g.x_mm, g.y_mm
                ),
            );
        }
    }
}

/// `[robot.timing]`: latencies >= 0 (a command's in whole physics steps), a drop rate below 1.
fn check_timing(c: &mut Problems, t: &TimingSpec, physics_step_s: f64) {
    for (key, v) in [
        ("frame_latency_s", t.frame_latency_s),
        ("command_latency_s", t.command_latency_s),
    ] {
        if !(v.is_finite() && (0.0..=10.0).contains(&v)) {
            c.fail(
                format!("robot.timing.{key}"),
                format!("must lie in [0, 10] (got {v})"),
            );
        }
    }
    let steps = t.command_latency_s / physics_step_s;
    if steps.is_finite() && (steps - steps.round()).abs() > 1e-6 {
        c.fail(
            "robot.timing.command_latency_s",
            format!(
                "must be a whole number of physics steps of {physics_step_s} s (got {})",
                t.command_latency_s
            ),
        );
    }
    let r = t.frame_drop_rate;
    if !(r.is_finite() && (0.0..1.0).contains(&r)) {
        c.fail(
            "robot.timing.frame_drop_rate",
            format!("must lie in [0, 1) (got {r})"),
        );
    }
}

/// The robot's software: its controller and pose source by their registered names, their
/// tables, the stages they run and what those need of the robot (checked by their own code),
/// the odometry's errors, and vision's camera.
fn check_software(c: &mut Problems, s: &Scenario) {
    let o = &s.odometry;
    for (key, v) in [
        ("speed_noise_frac", o.speed_noise_frac),
        ("omega_noise_rad_s", o.omega_noise_rad_s),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            c.fail(format!("odometry.{key}"), format!("must be >= 0 (got {v})"));
        }
    }
    if !(o.scale_bias_frac.is_finite() && o.scale_bias_frac > -1.0) {
        c.fail(
            "odometry.scale_bias_frac",
            format!("must be > -1 (got {})", o.scale_bias_frac),
        );
    }
    c.finite("odometry.omega_bias_rad_s", o.omega_bias_rad_s);
    if !(o.slip_s.is_finite() && o.slip_s >= 0.0) {
        c.fail(
            "odometry.slip_s",
            format!("must be >= 0 (got {})", o.slip_s),
        );
    }
    check_timing(c, &s.robot.timing, s.run.physics_step_s);
    let g = s.control.localization_gain;
    if g.is_nan() || !(0.0..=1.0).contains(&g) {
        c.fail(
            "control.localization_gain",
            format!("must lie in [0, 1] (got {g})"),
        );
    }
    if s.run.pilot == PilotChoice::Truth && s.goal.is_none() {
        c.fail(
            "run.pilot",
            "the truth pilot drives to the goal: add a [goal] table",
        );
    }
    let Some(controller) = controller(c, s) else {
        return;
    };
    if !perception::is_pose_source(&s.control.pose_source) {
        c.fail(
            "control.pose_source",
            format!(
                "no pose source {:?} (there are: {})",
                s.control.pose_source,
                perception::pose_sources()
            ),
        );
        return;
    }
    check_tables(c, s, controller);
    check_vision_tables(c, s);
    let stages = s.stages();
    check_world_for(c, s, &stages);
    let Some(config) = software_config(c, s, &stages) else {
        return;
    };
    c.merge((controller.check_use)(&config));
    for stage in &stages {
        c.merge((stage.check)(&config));
    }
}

/// The registered controller `control.kind` names, or the problem.
fn controller(c: &mut Problems, s: &Scenario) -> Option<&'static ControllerEntry> {
    let kind = &s.control.kind;
    let Some(entry) = controllers::find(kind) else {
        let why = if kind == "go_to_goal_truth" {
            "\"go_to_goal_truth\" is the simulator's pilot, not the robot's controller: write \
             [run] pilot = \"truth\""
                .to_string()
        } else {
            format!(
                "no controller {kind:?} (there are: {})",
                controllers::names()
            )
        };
        c.fail("control.kind", why);
        return None;
    };
    if entry.needs_goal && s.goal.is_none() {
        c.fail(
            "control.kind",
            format!("controller {kind:?} needs a [goal] table"),
        );
    }
    Some(entry)
}

/// Every table written under `[control]` belongs to a registered controller or stage, which
/// checks it (a table controllers share is checked once; the chosen controller's always).
fn check_tables(c: &mut Problems, s: &Scenario, chosen: &ControllerEntry) {
    let spec = &s.control;
    let controller_tables = || CONTROLLERS.iter().flat_map(|e| e.tables.iter());
    let mut checked: Vec<&str> = Vec::new();
    for name in spec.tables.names() {
        if let Some(table) = controller_tables().find(|t| t.name == name) {
            c.merge((table.check)(spec));
            checked.push(name);
        } else if !STAGES.iter().any(|e| e.table == Some(name)) {
            let tables = controller_tables().map(|t| t.name);
            let tables = tables.chain(STAGES.iter().filter_map(|e| e.table));
            let keys = ["kind", "pose_source", "localization_gain"];
            unknown_table(c, "control", name, &keys, tables);
        }
    }
    for table in chosen.tables.iter().filter(|t| !checked.contains(&t.name)) {
        c.merge((table.check)(spec));
    }
}

/// Every table written under `[vision]` belongs to a registered stage, which checks its values
/// (a table stages share is checked once), whether or not the stage runs.
fn check_vision_tables(c: &mut Problems, s: &Scenario) {
    for name in s.vision.tables.names() {
        if let Some(owner) = STAGES.iter().find(|e| e.vision_table == Some(name)) {
            c.merge((owner.check_vision)(&s.vision));
        } else {
            let tables = STAGES.iter().filter_map(|e| e.vision_table);
            unknown_table(c, "vision", name, &["sensor", "calibration_file"], tables);
        }
    }
}

/// Table `name` of `section` is no registered part's: the problem lists the section's own
/// `keys` and the registered `tables`.
fn unknown_table<'a>(
    c: &mut Problems,
    section: &str,
    name: &str,
    keys: &[&'a str],
    tables: impl Iterator<Item = &'a str>,
) {
    let mut known = keys.to_vec();
    for t in tables {
        if !known.contains(&t) {
            known.push(t);
        }
    }
    let why = format!(
        "unknown field `{name}`, expected one of {}",
        known.join(", ")
    );
    c.fail(format!("{section}.{name}"), why);
}

/// What the stages need of the world that the robot is not told (its map holds the rest), as
/// their registry entries declare it ([`WorldNeed`]).
fn check_world_for(c: &mut Problems, s: &Scenario, stages: &[&'static StageEntry]) {
    let mut needs: Vec<WorldNeed> = Vec::new();
    for need in stages.iter().flat_map(|e| e.world) {
        if !needs.contains(need) {
            needs.push(*need);
        }
    }
    for need in needs {
        match need {
            WorldNeed::Field if s.world.field.is_none() => c.fail(
                "control.pose_source",
                "self-localization matches the floor region to the field: add [world.field]",
            ),
            WorldNeed::Field => {}
            WorldNeed::StereoRig => {
                if let Err(p) = s.stereo_rig() {
                    c.extend([p]);
                }
            }
            WorldNeed::ResectionCamera => check_resection_camera(c, s),
        }
    }
}

/// The configuration the robot's software is built from, with vision's camera calibrated when
/// a stage needs it, or `None` when the camera cannot serve (the problem recorded).
fn software_config(
    c: &mut Problems,
    s: &Scenario,
    stages: &[&'static StageEntry],
) -> Option<RobotConfig> {
    if !s.needs_calibration() {
        return Some(s.robot_config(Vec::new(), Vec::new()));
    }
    // Vision sees through a mirror sensor: its calibration must work.
    let sensors = &s.robot.sensors;
    let index = match s.vision_sensor_index() {
        Ok(i) => i,
        Err(e) => {
            let field = if s.vision.sensor.is_some() {
                "vision.sensor"
            } else if s.stages().iter().any(|e| e.pose_source.is_none()) {
                "control.kind"
            } else {
                "control.pose_source"
            };
            c.fail(field, format!("vision sees through a camera: {e}"));
            return None;
        }
    };
    if sensors[index].optics.pinhole().is_some() {
        c.fail(
            "vision.sensor",
            format!(
                "free space and self-localization need a mirror sensor; {:?} is not one",
                sensors[index].name
            ),
        );
        return None;
    }
    // Optics at fault are reported with the sensor; its calibration would only repeat them.
    if !sensors[index].optics.problems().is_empty() {
        return None;
    }
    let cal = match &s.vision.calibration_file {
        Some(path) => match omniloop_vision::RadialCalibration::load(path) {
            Ok(cal) => cal,
            Err(e) => {
                c.fail("vision.calibration_file", e.to_string());
                return None;
            }
        },
        None => match super::calibrate::calibrate_sensor(&sensors[index]) {
            Ok(cal) => cal,
            Err(e) => {
                c.fail(format!("robot.sensors[{index}]"), e.to_string());
                return None;
            }
        },
    };
    let needs_floor = stages.iter().any(|e| e.camera == CameraNeed::MirrorFloor);
    if needs_floor && let Err(e) = cal.validate() {
        c.fail(
            format!("robot.sensors[{index}]"),
            format!(
                "free space and self-localization need the floor in the image: {e} in the \
                 image-to-floor map of {:?}",
                sensors[index].name
            ),
        );
        return None;
    }
    let mut cal = cal;
    cal.sensor = sensors[index].name.clone();
    Some(s.robot_config(vec![cal], Vec::new()))
}

/// Resection reads bearings through vision's camera, level when it is a pinhole.
fn check_resection_camera(c: &mut Problems, s: &Scenario) {
    match s.vision_sensor_index() {
        Err(e) => c.fail(
            "vision.sensor",
            format!("resection sees through a camera: {e}"),
        ),
        Ok(i) => {
            if let Some(cam) = s.robot.sensors[i].optics.pinhole()
                && cam.tilt_deg != 0.0
            {
                c.fail(
                    format!("robot.sensors[{i}].pinhole.tilt_deg"),
                    format!(
                        "resection reads bearings from a level camera (Sect. 3.2): must be 0 \
                         (got {})",
                        cam.tilt_deg
                    ),
                );
            }
        }
    }
}

fn check_sensor(c: &mut Problems, p: &str, s: &SensorSpec) {
    if s.name.trim().is_empty() {
        c.fail(format!("{p}.name"), "must not be empty");
    }
    for (key, v) in [("width_px", s.width_px), ("height_px", s.height_px)] {
        if !(8..=4096).contains(&v) {
            c.fail(format!("{p}.{key}"), format!("must be 8..=4096 (got {v})"));
        }
    }
    let inside = |x: f64, y: f64| {
        (0.0..=s.width_px as f64).contains(&x) && (0.0..=s.height_px as f64).contains(&y)
    };
    if let Some([x, y]) = s.principal_point_px.filter(|&[x, y]| !inside(x, y)) {
        c.fail(
            format!("{p}.principal_point_px"),
            format!(
                "({x}, {y}) lies outside the {}x{} image",
                s.width_px, s.height_px
            ),
        );
    }
    if !(s.noise_sigma.is_finite() && s.noise_sigma >= 0.0) {
        c.fail(
            format!("{p}.noise_sigma"),
            format!("must be >= 0 (got {})", s.noise_sigma),
        );
    }
    if let Some(n) = s.grey_levels.filter(|n| !(2..=256).contains(n)) {
        c.fail(
            format!("{p}.grey_levels"),
            format!("must be 2..=256 (got {n})"),
        );
    }
    let sensor = FieldPath::parse(p);
    c.extend(s.optics.problems().into_iter().map(|q| q.under(&sensor)));
    let effects = FieldPath::parse(&format!("{p}.effects"));
    c.extend(s.effects.problems().into_iter().map(|q| q.under(&effects)));
    let mounting = FieldPath::parse(&format!("{p}.mounting"));
    c.extend(
        s.mounting
            .problems()
            .into_iter()
            .map(|q| q.under(&mounting)),
    );
    if !s.mounting.is_nominal() && matches!(s.optics, Optics::Pinhole(_) | Optics::Calibrated(_)) {
        c.fail(
            format!("{p}.mounting"),
            format!(
                "a {} camera has no mirror to mount off its place",
                s.optics.kind()
            ),
        );
    }
    if let Some(model) = s.optics.calibrated().and_then(|cam| cam.model()) {
        check_calibrated_size(c, p, s, model);
    }
}

/// A calibrated camera's image is the one its model was calibrated for.
fn check_calibrated_size(
    c: &mut Problems,
    p: &str,
    s: &SensorSpec,
    model: &omniloop_vision::camera_model::CameraFile,
) {
    let [w, h] = model.size_px();
    if [s.width_px, s.height_px] != [w, h] {
        let key = if s.width_px != w {
            "width_px"
        } else {
            "height_px"
        };
        c.fail(
            format!("{p}.{key}"),
            format!(
                "the calibration file describes a {w}x{h} image; the sensor is {}x{}",
                s.width_px, s.height_px
            ),
        );
    }
    let [u, v] = model.principal_px();
    if let Some([x, y]) = s
        .principal_point_px
        .filter(|&[x, y]| (x - u - 0.5).abs() > 1e-9 || (y - v - 0.5).abs() > 1e-9)
    {
        c.fail(
            format!("{p}.principal_point_px"),
            format!(
                "({x}, {y}) is not the calibration's ({}, {}) (pixel edges at integers); \
                 leave it out",
                u + 0.5,
                v + 0.5
            ),
        );
    }
}
