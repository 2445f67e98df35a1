//! `omniloop ssl`: the SSL simulation protocol answered, ssl-vision's frames and the referee's
//! packets as a team's AI gets them, bad input from the network, lockstep's determinism, and
//! what grSim gets wrong (a kicker that misses a ball just ahead, unknown robot ids ignored,
//! a crash on a configuration command), each tested here.

use omniloop::Scenario;
use omniloop::load_scenario;
use omniloop::report::output::write_run;
use omniloop::run::RunOptions;
use omniloop::scenario::ssl::TeamColor;
use omniloop::ssl::wire::referee::Referee;
use omniloop::ssl::wire::sim::{
    MoveCommand, MoveGlobalVelocity, MoveLocalVelocity, MoveWheelVelocity, RobotCommand,
    RobotControl, RobotControlResponse, RobotId, RobotMoveCommand, RobotSpecs,
    SimulationSyncRequest, SimulationSyncResponse, SimulatorCommand, SimulatorConfig,
    SimulatorControl, SimulatorResponse, Team, TeleportBall, TeleportRobot,
};
use omniloop::ssl::wire::vision::{DetectionFrame, DetectionRobot, GeometryData, WrapperPacket};
use omniloop::ssl::{Pace, Ports, ServeOptions, Server, SslSimulator};
use omniloop_sim::RendererChoice;
use prost::Message;
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};
use std::net::UdpSocket;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// The six-against-six scenario, its robots' cameras off (the protocol does not need them).
fn scenario() -> Scenario {
    let mut s = load_scenario(Path::new("scenarios/ssl_match.toml")).unwrap();
    let ssl = s.ssl.as_mut().unwrap();
    ssl.render_cameras = false;
    s
}

fn game() -> SslSimulator {
    SslSimulator::new(&scenario(), &cpu()).unwrap()
}

fn cpu() -> RunOptions {
    RunOptions {
        renderer: RendererChoice::Cpu,
        ..RunOptions::default()
    }
}

fn local(id: u32, forward: f32, left: f32, angular: f32) -> RobotCommand {
    moving(
        id,
        MoveCommand::LocalVelocity(MoveLocalVelocity {
            forward,
            left,
            angular,
        }),
    )
}

fn moving(id: u32, m: MoveCommand) -> RobotCommand {
    RobotCommand {
        id,
        move_command: Some(RobotMoveCommand { command: Some(m) }),
        kick_speed: None,
        kick_angle: None,
        dribbler_speed: None,
    }
}

fn control(
    g: &mut SslSimulator,
    team: TeamColor,
    commands: Vec<RobotCommand>,
) -> RobotControlResponse {
    let bytes = RobotControl {
        robot_commands: commands,
    }
    .encode_to_vec();
    RobotControlResponse::decode(g.robot_control(team, &bytes).as_slice()).unwrap()
}

fn command(g: &mut SslSimulator, c: &SimulatorCommand) -> SimulatorResponse {
    SimulatorResponse::decode(g.simulator_command(&c.encode_to_vec()).as_slice()).unwrap()
}

fn codes(errors: &[omniloop::ssl::wire::sim::SimulatorError]) -> Vec<String> {
    errors.iter().filter_map(|e| e.code.clone()).collect()
}

fn teleport_robot(team: Team, id: u32, x: f32, y: f32, orientation: f32) -> TeleportRobot {
    TeleportRobot {
        id: RobotId {
            id: Some(id),
            team: Some(team as i32),
        },
        x: Some(x),
        y: Some(y),
        orientation: Some(orientation),
        v_x: None,
        v_y: None,
        v_angular: None,
        present: None,
        by_force: None,
    }
}

fn teleport(robots: Vec<TeleportRobot>, ball: Option<TeleportBall>) -> SimulatorCommand {
    SimulatorCommand {
        control: Some(SimulatorControl {
            teleport_ball: ball,
            teleport_robot: robots,
            simulation_speed: None,
        }),
        config: None,
    }
}

fn ball_at(x: f32, y: f32, vx: f32, vy: f32) -> TeleportBall {
    TeleportBall {
        x: Some(x),
        y: Some(y),
        z: None,
        vx: Some(vx),
        vy: Some(vy),
        vz: None,
        teleport_safely: None,
        roll: None,
        by_force: None,
    }
}

/// Steps `n` cycles; the detection frames of the last cycle that had any.
fn steps(g: &mut SslSimulator, n: usize) -> Vec<DetectionFrame> {
    let mut last = Vec::new();
    for _ in 0..n {
        let out = g.step().unwrap();
        if !out.detections.is_empty() {
            last = out.detections;
        }
    }
    last
}

/// Where vision saw robot `id` of `team` (the first camera reporting it).
fn seen(frames: &[DetectionFrame], team: TeamColor, id: u32) -> Option<DetectionRobot> {
    frames.iter().find_map(|f| {
        let list = match team {
            TeamColor::Blue => &f.robots_blue,
            TeamColor::Yellow => &f.robots_yellow,
        };
        list.iter().find(|r| r.robot_id == Some(id)).cloned()
    })
}

#[test]
fn local_global_and_wheel_commands_move_the_robots_their_way_and_the_timeout_stops_them() {
    let mut g = game();
    let before = steps(&mut g, 1);
    let b0 = seen(&before, TeamColor::Blue, 3).unwrap();
    let y0 = seen(&before, TeamColor::Yellow, 3).unwrap();
    let w0 = seen(&before, TeamColor::Blue, 4).unwrap();
    for _ in 0..50 {
        let r = control(
            &mut g,
            TeamColor::Blue,
            vec![
                local(3, 1.0, 0.0, 0.0),
                moving(
                    4,
                    MoveCommand::WheelVelocity(MoveWheelVelocity {
                        // Straight ahead at 1 m/s with the default wheel angles (60, 135, 225, 300).
                        front_right: 0.866,
                        back_right: 0.707,
                        back_left: -0.707,
                        front_left: -0.866,
                    }),
                ),
            ],
        );
        assert!(r.errors.is_empty(), "{:?}", r.errors);
        assert_eq!(r.feedback.len(), 6, "feedback for the team's six robots");
        // Yellow faces -x: a field-frame command to +x drives it backwards.
        let r = control(
            &mut g,
            TeamColor::Yellow,
            vec![moving(
                3,
                MoveCommand::GlobalVelocity(MoveGlobalVelocity {
                    x: 1.0,
                    y: 0.0,
                    angular: 0.0,
                }),
            )],
        );
        assert!(r.errors.is_empty(), "{:?}", r.errors);
        steps(&mut g, 1);
    }
    let after = steps(&mut g, 1);
    let b1 = seen(&after, TeamColor::Blue, 3).unwrap();
    let y1 = seen(&after, TeamColor::Yellow, 3).unwrap();
    let w1 = seen(&after, TeamColor::Blue, 4).unwrap();
    // 0.5 s at up to 1 m/s after accelerating at 4 m/s²: about 375 mm.
    assert!(
        (300.0..500.0).contains(&(b1.x - b0.x)),
        "local: {} -> {}",
        b0.x,
        b1.x
    );
    assert!(
        (300.0..500.0).contains(&(y1.x - y0.x)),
        "global: {} -> {}",
        y0.x,
        y1.x
    );
    assert!(
        (300.0..500.0).contains(&(w1.x - w0.x)),
        "wheels: {} -> {}",
        w0.x,
        w1.x
    );
    assert!((b1.y - b0.y).abs() < 5.0 && (w1.y - w0.y).abs() < 15.0);
    // No command for longer than the timeout (0.1 s): the robots stop where they are.
    let t1 = steps(&mut g, 40);
    let t2 = steps(&mut g, 20);
    let (a, b) = (
        seen(&t1, TeamColor::Blue, 3).unwrap(),
        seen(&t2, TeamColor::Blue, 3).unwrap(),
    );
    assert!(
        (a.x - b.x).abs() < 0.5,
        "still moving after the timeout: {} -> {}",
        a.x,
        b.x
    );
}

#[test]
fn a_ball_placed_105_mm_ahead_of_a_robot_that_just_drove_is_touched_and_kicked() {
    // grSim's kicker missed this one: no contact reported, no kick.
    let mut g = game();
    for _ in 0..30 {
        control(&mut g, TeamColor::Blue, vec![local(3, 1.5, 0.0, 0.0)]);
        steps(&mut g, 1);
    }
    command(
        &mut g,
        &teleport(
            vec![teleport_robot(Team::Blue, 3, -1.0, 0.5, 0.0)],
            Some(ball_at(-0.895, 0.5, 0.0, 0.0)),
        ),
    );
    // Up to the ball with the dribbler on: the light barrier reports it.
    let mut contact_at = None;
    for k in 0..50 {
        let mut c = local(3, 0.3, 0.0, 0.0);
        c.dribbler_speed = Some(3000.0);
        let r = control(&mut g, TeamColor::Blue, vec![c]);
        assert!(r.errors.is_empty(), "{:?}", r.errors);
        if r.feedback
            .iter()
            .any(|f| f.id == 3 && f.dribbler_ball_contact == Some(true))
        {
            contact_at = Some(k);
            break;
        }
        steps(&mut g, 1);
    }
    assert!(
        contact_at.is_some_and(|k| k < 20),
        "the light barrier saw the ball at {contact_at:?}"
    );
    // Then the kick: vision sees the ball leave at the kick's 4 m/s, plus the robot's own
    // speed (at most 0.3 m/s) as it still rolls on.
    let mut fastest = 0.0f32;
    let mut last: Option<(f32, f32)> = None;
    for _ in 0..30 {
        let mut c = local(3, 0.0, 0.0, 0.0);
        c.kick_speed = Some(4.0);
        assert!(control(&mut g, TeamColor::Blue, vec![c]).errors.is_empty());
        let frames = steps(&mut g, 1);
        if let Some(b) = frames.iter().find_map(|f| f.balls.first()) {
            if let Some((x, y)) = last {
                fastest = fastest.max(((b.x - x).powi(2) + (b.y - y).powi(2)).sqrt() / 0.01);
            }
            last = Some((b.x, b.y));
        }
    }
    assert!(
        (3500.0..4400.0).contains(&fastest),
        "the ball went at most {fastest} mm/s"
    );
}

#[test]
fn unknown_robots_bad_values_and_configuration_are_answered_with_errors_and_the_game_goes_on() {
    let mut g = game();
    // grSim ignores unknown robot ids without a word.
    let r = control(&mut g, TeamColor::Blue, vec![local(11, 1.0, 0.0, 0.0)]);
    assert_eq!(codes(&r.errors), ["UNKNOWN_ROBOT"]);
    let r = control(
        &mut g,
        TeamColor::Yellow,
        vec![local(0, f32::NAN, 0.0, 0.0), local(1, 1e9, 0.0, 0.0)],
    );
    assert_eq!(codes(&r.errors), ["INVALID_VELOCITY", "INVALID_VELOCITY"]);
    let mut kick = local(2, 0.0, 0.0, 0.0);
    kick.kick_speed = Some(50.0);
    assert_eq!(
        codes(&control(&mut g, TeamColor::Yellow, vec![kick]).errors),
        ["KICK_OVER_LIMIT"]
    );
    // grSim's headless mode crashed on a configuration command: here each field it cannot take
    // is named.
    let config = SimulatorCommand {
        control: None,
        config: Some(SimulatorConfig {
            geometry: Some(GeometryData::default()),
            robot_specs: vec![RobotSpecs {
                id: RobotId {
                    id: Some(0),
                    team: Some(Team::Blue as i32),
                },
                radius: Some(0.09),
                height: Some(0.15),
                mass: Some(2.3),
                max_linear_kick_speed: None,
                max_chip_kick_speed: None,
                center_to_dribbler: None,
                limits: None,
                wheel_angles: None,
                custom: Vec::new(),
            }],
            realism_config: None,
            vision_port: Some(10020),
        }),
    };
    let r = command(&mut g, &config);
    let messages: Vec<String> = r.errors.iter().filter_map(|e| e.message.clone()).collect();
    assert_eq!(messages.len(), 2, "{messages:?}");
    assert!(messages[0].starts_with("config.geometry"), "{messages:?}");
    assert!(
        messages[1].starts_with("config.robot_specs[0].mass"),
        "{messages:?}"
    );
    // Garbage, a truncated packet, a datagram over the limit: answered, not taken.
    let good = RobotControl {
        robot_commands: vec![local(0, 1.0, 0.0, 0.0)],
    }
    .encode_to_vec();
    for bad in [
        vec![0xff; 40],
        good[..good.len() - 3].to_vec(),
        vec![0; 70_000],
    ] {
        let r = RobotControlResponse::decode(g.robot_control(TeamColor::Blue, &bad).as_slice())
            .unwrap();
        assert!(
            matches!(
                codes(&r.errors)[0].as_str(),
                "MALFORMED" | "DATAGRAM_TOO_LONG"
            ),
            "{:?}",
            r.errors
        );
    }
    assert_eq!(g.tallies().malformed, 3);
    // Still answering, still stepping.
    assert!(
        control(&mut g, TeamColor::Blue, vec![local(0, 1.0, 0.0, 0.0)])
            .errors
            .is_empty()
    );
    steps(&mut g, 5);
}

#[test]
fn robots_leave_and_come_back_and_a_goal_reaches_the_referees_score() {
    let mut g = game();
    let mut gone = teleport_robot(Team::Yellow, 5, 0.0, 0.0, 0.0);
    gone.present = Some(false);
    let r = command(
        &mut g,
        &teleport(vec![gone], Some(ball_at(4.0, 0.2, 2.0, 0.0))),
    );
    assert!(r.errors.is_empty(), "{:?}", r.errors);
    let mut referee = None;
    let mut vision = Vec::new();
    for _ in 0..100 {
        let out = g.step().unwrap();
        if !out.detections.is_empty() {
            vision = out.detections;
        }
        referee = out.referee.or(referee);
    }
    assert!(
        seen(&vision, TeamColor::Yellow, 5).is_none(),
        "a robot off the field is not seen"
    );
    let r = control(&mut g, TeamColor::Yellow, vec![local(5, 1.0, 0.0, 0.0)]);
    assert_eq!(codes(&r.errors), ["ROBOT_ABSENT"]);
    let score = Referee::decode(referee.unwrap().as_slice()).unwrap();
    // Into the goal at +x, yellow's: blue scores.
    assert_eq!((score.blue.score, score.yellow.score), (1, 0));
    let mut back = teleport_robot(Team::Yellow, 5, 1.0, -1.0, 1.0);
    back.present = Some(true);
    assert!(
        command(&mut g, &teleport(vec![back], None))
            .errors
            .is_empty()
    );
    let r = seen(&steps(&mut g, 1), TeamColor::Yellow, 5).unwrap();
    assert!((r.x - 1000.0).abs() < 1.0 && (r.y + 1000.0).abs() < 1.0);
}

#[test]
fn random_and_mutated_datagrams_never_stop_the_simulator() {
    let mut g = game();
    let mut rng = StdRng::seed_from_u64(58);
    let seeds: Vec<Vec<u8>> = vec![
        RobotControl {
            robot_commands: (0..6).map(|i| local(i, 1.0, 0.5, 1.0)).collect(),
        }
        .encode_to_vec(),
        teleport(
            vec![teleport_robot(Team::Blue, 1, 0.5, 0.5, 0.0)],
            Some(ball_at(0.1, 0.1, 1.0, 0.0)),
        )
        .encode_to_vec(),
        SimulationSyncRequest {
            sim_step: Some(0.01),
            simulator_command: None,
            robot_control: None,
        }
        .encode_to_vec(),
    ];
    let mut answered = 0u64;
    for k in 0..100_000u32 {
        let bytes: Vec<u8> = if k % 2 == 0 {
            let n = rng.random_range(0..64);
            (0..n).map(|_| rng.random::<u8>()).collect()
        } else {
            let mut b = seeds[(k as usize / 2) % seeds.len()].clone();
            for _ in 0..rng.random_range(1..4) {
                let i = rng.random_range(0..b.len());
                b[i] = rng.random();
            }
            b.truncate(rng.random_range(1..=b.len()));
            b
        };
        let answer = if k % 3 == 0 {
            g.simulator_command(&bytes)
        } else {
            g.robot_control(
                if k % 3 == 1 {
                    TeamColor::Blue
                } else {
                    TeamColor::Yellow
                },
                &bytes,
            )
        };
        answered += u64::from(!answer.is_empty() || bytes.is_empty());
        let _ =
            omniloop::ssl::wire::decode::<SimulationSyncRequest>(&bytes, "SimulationSyncRequest");
        let _ = omniloop::ssl::wire::decode::<WrapperPacket>(&bytes, "SSL_WrapperPacket");
        if k % 5000 == 0 {
            steps(&mut g, 1);
        }
    }
    assert!(answered > 90_000, "{answered} answered");
    assert_eq!(g.tallies().datagrams, 100_000);
    steps(&mut g, 10);
}

/// The scenario served on free ports of `bind_address`, vision and the referee sent to the
/// socket returned beside it (keep it open while the game runs).
fn on_free_ports(bind_address: &str) -> (Scenario, UdpSocket) {
    let mut s = scenario();
    let sink = UdpSocket::bind("127.0.0.1:0").unwrap();
    let n = &mut s.ssl.as_mut().unwrap().network;
    n.bind_address = bind_address.into();
    (n.control_port, n.blue_port, n.yellow_port) = (0, 0, 0);
    n.vision_address = sink.local_addr().unwrap().to_string();
    n.referee_address = n.vision_address.clone();
    (s, sink)
}

/// A lockstep game on free loopback ports, its files into `out`: 200 sync steps of fixed
/// commands to blue, a teleport on the way.
fn lockstep_game(out: &Path) -> Vec<(String, Vec<u8>)> {
    let (mut s, _sink) = on_free_ports("127.0.0.1");
    s.ssl.as_mut().unwrap().vision.realism.enabled = true;
    let scenario = s.clone();
    let g = SslSimulator::new(&s, &cpu()).unwrap();
    let ports = Ports::bind(g.spec()).unwrap();
    let bound = ports.bound().unwrap();
    let options = ServeOptions {
        pace: Pace::Lockstep,
        duration_s: Some(10.0),
        idle_exit_s: Some(0.5),
        log: Some(out.join("ssl.log")),
    };
    let stop = Arc::new(AtomicBool::new(false));
    let server = std::thread::spawn(move || {
        Server::new(g, ports, &options)
            .unwrap()
            .run(&options, &stop)
            .unwrap()
    });
    let client = UdpSocket::bind("127.0.0.1:0").unwrap();
    client
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let mut buf = vec![0u8; 65_536];
    // A configuration alone to the control port is a `SimulatorCommand`, not a sync request
    // (whose second field it would decode as): answered as one, vision moved to another port.
    let moved = UdpSocket::bind("127.0.0.1:0").unwrap();
    let config = SimulatorCommand {
        control: None,
        config: Some(SimulatorConfig {
            vision_port: Some(u32::from(moved.local_addr().unwrap().port())),
            ..SimulatorConfig::default()
        }),
    };
    client
        .send_to(&config.encode_to_vec(), bound.control)
        .unwrap();
    let n = client.recv(&mut buf).unwrap();
    assert!(
        SimulatorResponse::decode(&buf[..n])
            .unwrap()
            .errors
            .is_empty()
    );
    let mut frames = 0;
    for k in 0..200u32 {
        let req = SimulationSyncRequest {
            sim_step: Some(0.01),
            simulator_command: (k == 50)
                .then(|| teleport(Vec::new(), Some(ball_at(0.5, 0.3, -1.0, 0.0)))),
            robot_control: Some(RobotControl {
                robot_commands: (0..6).map(|i| local(i, 0.8, 0.1 * i as f32, 0.5)).collect(),
            }),
        };
        client.send_to(&req.encode_to_vec(), bound.blue).unwrap();
        let n = client.recv(&mut buf).unwrap();
        let r = SimulationSyncResponse::decode(&buf[..n]).unwrap();
        assert!(r.robot_control_response.unwrap().errors.is_empty());
        frames += r.detection.len();
    }
    // A frame a camera a step, but for the last three steps' frames: 35 ms on their way.
    assert_eq!(frames, 197 * 4);
    moved
        .set_read_timeout(Some(Duration::from_secs(1)))
        .unwrap();
    let n = moved
        .recv(&mut buf)
        .expect("vision on the port the configuration set");
    assert!(WrapperPacket::decode(&buf[..n]).is_ok());
    let (g, report) = server.join().unwrap();
    assert_eq!(report.cycles, 200);
    write_run(out, &scenario, &g.finish(0.0)).unwrap();
    [
        "ssl.log",
        "trajectory.csv",
        "ball.csv",
        "events.jsonl",
        "robots/blue4/trajectory.csv",
    ]
    .map(|f| (f.to_string(), std::fs::read(out.join(f)).unwrap()))
    .to_vec()
}

#[test]
fn lockstep_runs_of_the_same_command_stream_give_byte_identical_files() {
    let dir = tempfile_dir("ssl_lockstep");
    let a = lockstep_game(&dir.join("a"));
    let b = lockstep_game(&dir.join("b"));
    assert!(a[0].1.len() > 10_000, "{} bytes logged", a[0].1.len());
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "the two runs' {name} differ");
    }
}

fn tempfile_dir(name: &str) -> std::path::PathBuf {
    let dir = super::common::tmp(name);
    for sub in ["a", "b"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    dir
}

/// This machine's address on its network (not loopback), as another host would send from.
fn network_address() -> std::net::IpAddr {
    let probe = UdpSocket::bind("0.0.0.0:0").unwrap();
    // Connecting a UDP socket sends nothing: it only picks the interface of the route.
    probe
        .connect("192.0.2.200:9")
        .or_else(|_| probe.connect("10.255.255.254:9"))
        .unwrap();
    let ip = probe.local_addr().unwrap().ip();
    assert!(
        !ip.is_loopback() && !ip.is_unspecified(),
        "no network address here: {ip}"
    );
    ip
}

#[test]
fn in_real_time_floods_and_strangers_on_the_control_port_are_dropped_and_counted() {
    let (s, _sink) = on_free_ports("0.0.0.0");
    let g = SslSimulator::new(&s, &cpu()).unwrap();
    let ports = Ports::bind(g.spec()).unwrap();
    let bound = ports.bound().unwrap();
    let options = ServeOptions {
        duration_s: Some(2.0),
        ..ServeOptions::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let server = std::thread::spawn(move || {
        Server::new(g, ports, &options)
            .unwrap()
            .run(&options, &stop)
            .unwrap()
    });
    let port = |a: std::net::SocketAddr| std::net::SocketAddr::from(([127, 0, 0, 1], a.port()));
    // A stranger: a control command from this machine's network address.
    let stranger = UdpSocket::bind((network_address(), 0)).unwrap();
    stranger
        .set_read_timeout(Some(Duration::from_millis(300)))
        .unwrap();
    let ball = teleport(Vec::new(), Some(ball_at(1.0, 1.0, 0.0, 0.0))).encode_to_vec();
    let to = std::net::SocketAddr::new(stranger.local_addr().unwrap().ip(), bound.control.port());
    stranger.send_to(&ball, to).unwrap();
    let mut buf = vec![0u8; 65_536];
    assert!(stranger.recv(&mut buf).is_err(), "a stranger was answered");
    // A flood of garbage to blue's port: thousands in a burst.
    let client = UdpSocket::bind("127.0.0.1:0").unwrap();
    client
        .set_read_timeout(Some(Duration::from_secs(2)))
        .unwrap();
    for k in 0..5000u32 {
        let _ = client.send_to(&k.to_le_bytes(), port(bound.blue));
    }
    // Still answering: a good command after the flood (answers to the flood read first).
    std::thread::sleep(Duration::from_millis(300));
    while client
        .set_read_timeout(Some(Duration::from_millis(50)))
        .is_ok()
        && client.recv(&mut buf).is_ok()
    {}
    client
        .set_read_timeout(Some(Duration::from_secs(2)))
        .unwrap();
    let good = RobotControl {
        robot_commands: vec![local(0, 1.0, 0.0, 0.0)],
    }
    .encode_to_vec();
    client.send_to(&good, port(bound.blue)).unwrap();
    let n = client.recv(&mut buf).unwrap();
    let r = RobotControlResponse::decode(&buf[..n]).unwrap();
    assert!(r.errors.is_empty() && r.feedback.len() == 6, "{r:?}");
    let (_, report) = server.join().unwrap();
    assert_eq!(report.refused, 1);
    // What the socket's buffer held (the kernel drops the rest of a burst): up to 200 a cycle
    // taken and answered, the others read and counted.
    assert!(report.malformed >= 200, "{report:?}");
    assert!(report.flood_dropped > 0, "no flood was dropped: {report:?}");
    assert!(report.cycles >= 150, "{report:?}");
}

#[test]
fn a_mixed_floor_plays_one_team_over_the_protocol_and_the_other_on_its_own_cameras() {
    let mut s = scenario();
    let ssl = s.ssl.as_mut().unwrap();
    ssl.protocol_teams = vec![TeamColor::Blue];
    ssl.render_cameras = true;
    let frames = super::common::tmp("ssl_frames");
    let options = RunOptions {
        save_frames_every: Some(10),
        frames_dir: Some(frames.clone()),
        ..cpu()
    };
    let mut g = SslSimulator::new(&s, &options).unwrap();
    let start = steps(&mut g, 1);
    let r = control(&mut g, TeamColor::Yellow, vec![local(0, 1.0, 0.0, 0.0)]);
    assert_eq!(codes(&r.errors), ["TEAM_NOT_REMOTE"]);
    for _ in 0..30 {
        control(&mut g, TeamColor::Blue, vec![local(0, 1.0, 0.0, 0.0)]);
        steps(&mut g, 1);
    }
    let end = steps(&mut g, 1);
    // The built-in striker looks for the ball on its own camera: turning or driving.
    let moved = (0..6).filter(|&id| {
        let (a, b) = (
            seen(&start, TeamColor::Yellow, id).unwrap(),
            seen(&end, TeamColor::Yellow, id).unwrap(),
        );
        let turned = (a.orientation.unwrap() - b.orientation.unwrap()).abs() > 0.05;
        turned || (a.x - b.x).hypot(a.y - b.y) > 20.0
    });
    assert!(moved.count() >= 3, "the yellow strikers stood still");
    let blue =
        seen(&end, TeamColor::Blue, 0).unwrap().x - seen(&start, TeamColor::Blue, 0).unwrap().x;
    assert!(blue > 100.0, "blue 0 drove {blue} mm");
    // Every robot's camera was rendered and saved, the protocol's robots' too.
    for name in ["blue1", "yellow6"] {
        let saved = std::fs::read_dir(frames.join(name)).unwrap().count();
        assert!(saved >= 3, "{name}: {saved} frames saved");
    }
}

#[test]
fn a_ball_teleported_with_roll_rolls_at_once_and_goes_further_than_a_sliding_one() {
    let travel = |roll: bool| {
        let mut g = game();
        let mut b = ball_at(0.0, 1.0, 2.0, 0.0);
        b.roll = Some(roll);
        assert!(
            command(&mut g, &teleport(Vec::new(), Some(b)))
                .errors
                .is_empty()
        );
        let frames = steps(&mut g, 30);
        frames
            .iter()
            .find_map(|f| f.balls.first().map(|b| b.x))
            .unwrap()
    };
    let (sliding, rolling) = (travel(false), travel(true));
    assert!(
        rolling > sliding + 20.0,
        "rolling {rolling} mm, sliding {sliding} mm"
    );
}

#[test]
fn a_game_controllers_referee_message_to_the_control_port_sets_the_command() {
    let mut g = game();
    let first = Referee::decode(g.step().unwrap().referee.unwrap().as_slice()).unwrap();
    assert_eq!(first.command, 3, "FORCE_START from the scenario");
    let halt = Referee {
        command: 0,
        source_identifier: Some("a game controller".to_string()),
        ..Referee::default()
    };
    let r =
        SimulatorResponse::decode(g.simulator_command(&halt.encode_to_vec()).as_slice()).unwrap();
    assert!(r.errors.is_empty(), "{:?}", r.errors);
    let next = Referee::decode(g.step().unwrap().referee.unwrap().as_slice()).unwrap();
    assert_eq!(
        (next.command, next.command_counter),
        (0, 1),
        "HALT, counted"
    );
    let bad = Referee {
        command: 99,
        ..halt
    };
    let r =
        SimulatorResponse::decode(g.simulator_command(&bad.encode_to_vec()).as_slice()).unwrap();
    assert_eq!(codes(&r.errors), ["INVALID_REFEREE_COMMAND"]);
}

#[test]
fn the_command_line_serves_a_game_and_records_every_robots_camera_as_mcap() {
    let out = super::common::tmp("ssl_cli_mcap");
    let line = super::common::omniloop([
        "ssl",
        "scenarios/ssl_match.toml",
        "--duration-s",
        "0.05",
        "--renderer",
        "cpu",
        "--bind",
        "127.0.0.1",
        "--control-port",
        "0",
        "--blue-port",
        "0",
        "--yellow-port",
        "0",
        "--vision",
        "127.0.0.1:9",
        "--referee",
        "127.0.0.1:9",
        "--mcap",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(line.contains("5 cycles"), "{line}");
    let bytes = std::fs::read(out.join("run.mcap")).unwrap();
    let mut cameras = std::collections::BTreeSet::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let topic = m.unwrap().channel.topic.clone();
        if topic.ends_with("/camera/omni") {
            cameras.insert(topic);
        }
    }
    assert_eq!(cameras.len(), 12, "{cameras:?}");
    let log = std::fs::read(out.join("ssl.log")).unwrap();
    assert_eq!(&log[..12], b"SSL_LOG_FILE");
}

#[test]
fn team_lists_name_robots_of_the_whole_team() {
    // Each robot is checked in its one-robot form; the lists name the others too.
    let from = "protocol_teams = [\"blue\", \"yellow\"]";
    let listed =
        format!("blue = [\"blue2\", \"blue1\", \"blue3\"]\nyellow = [\"yellow1\"]\n{from}");
    let (code, err) = crate::common::check_variant("ssl_match.toml", "ssl_lists_ok", from, &listed);
    assert_eq!(code, Some(0), "{err}");
    let unknown = format!("blue = [\"blue1\", \"blue9\"]\n{from}");
    let (code, err) =
        crate::common::check_variant("ssl_match.toml", "ssl_lists_bad", from, &unknown);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("field `ssl.blue[1]`: no robot called \"blue9\""),
        "{err}"
    );
    assert_eq!(err.matches("no robot called").count(), 1, "{err}");
}
