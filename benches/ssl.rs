//! `omniloop ssl` benchmark: six against six on Division B with a ball, every robot commanded
//! every cycle, side by side in one run:
//! - lockstep over the protocol's UDP ports on loopback (a `SimulationSyncRequest` a step with
//!   both teams' commands, answered with the step's detection frames): cycles per second and
//!   their ratio to real time at 100 Hz;
//! - the same game without the network (the simulator's own cost);
//! - the game with all twelve robots' cameras rendered (256 x 220, CPU), flat out: the rate
//!   the real-time mode can hold on this machine.
//!
//!     cargo bench --bench ssl
#![allow(clippy::unwrap_used, clippy::expect_used)] // a benchmark: a broken fixture stops it where it breaks

mod common;

use omniloop::load_scenario;
use omniloop::run::RunOptions;
use omniloop::scenario::ssl::TeamColor;
use omniloop::ssl::wire::sim::{
    MoveCommand, MoveLocalVelocity, RobotCommand, RobotControl, RobotMoveCommand,
    SimulationSyncRequest, SimulationSyncResponse,
};
use omniloop::ssl::{Pace, Ports, ServeOptions, Server, SslSimulator};
use omniloop_sim::RendererChoice;
use prost::Message;
use std::net::UdpSocket;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Robot `id` turning on a circle: every robot moves and the ball gets pushed about.
fn commands(step: u32) -> RobotControl {
    let phase = step as f32 * 0.01;
    RobotControl {
        robot_commands: (0..6)
            .map(|id| RobotCommand {
                id,
                move_command: Some(RobotMoveCommand {
                    command: Some(MoveCommand::LocalVelocity(MoveLocalVelocity {
                        forward: 1.5,
                        left: 0.3 * (phase + id as f32).sin(),
                        angular: 1.0,
                    })),
                }),
                kick_speed: Some(3.0),
                kick_angle: None,
                dribbler_speed: Some(1000.0),
            })
            .collect(),
    }
}

fn scenario(cameras: bool) -> omniloop::Scenario {
    let mut s = load_scenario(&common::scenario_path("ssl_match.toml")).unwrap();
    let ssl = s.ssl.as_mut().unwrap();
    ssl.render_cameras = cameras;
    ssl.network.bind_address = "127.0.0.1".into();
    (
        ssl.network.control_port,
        ssl.network.blue_port,
        ssl.network.yellow_port,
    ) = (0, 0, 0);
    ssl.network.vision_address = "127.0.0.1:9".into();
    ssl.network.referee_address = "127.0.0.1:9".into();
    s
}

fn cpu() -> RunOptions {
    RunOptions {
        renderer: RendererChoice::Cpu,
        ..RunOptions::default()
    }
}

/// Cycles per second of `steps` lockstep steps over loopback UDP.
fn over_udp(steps: u32) -> f64 {
    let g = SslSimulator::new(&scenario(false), &cpu()).unwrap();
    let ports = Ports::bind(g.spec()).unwrap();
    let bound = ports.bound().unwrap();
    let options = ServeOptions {
        pace: Pace::Lockstep,
        duration_s: Some(f64::from(steps) * 0.01 + 1.0),
        idle_exit_s: Some(0.3),
        log: None,
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
    let start = Instant::now();
    for k in 0..steps {
        let yellow = commands(k).encode_to_vec();
        client.send_to(&yellow, bound.yellow).unwrap();
        let _ = client.recv(&mut buf).unwrap();
        let req = SimulationSyncRequest {
            sim_step: Some(0.01),
            simulator_command: None,
            robot_control: Some(commands(k)),
        };
        client.send_to(&req.encode_to_vec(), bound.blue).unwrap();
        let n = client.recv(&mut buf).unwrap();
        let r = SimulationSyncResponse::decode(&buf[..n]).unwrap();
        assert_eq!(r.detection.len(), 4);
    }
    let rate = f64::from(steps) / start.elapsed().as_secs_f64();
    server.join().unwrap();
    rate
}

/// Cycles per second of `steps` cycles driving the simulator directly.
fn direct(steps: u32, cameras: bool) -> f64 {
    let mut g = SslSimulator::new(&scenario(cameras), &cpu()).unwrap();
    let start = Instant::now();
    for k in 0..steps {
        let c = commands(k).encode_to_vec();
        g.robot_control(TeamColor::Blue, &c);
        g.robot_control(TeamColor::Yellow, &c);
        g.step().unwrap();
    }
    f64::from(steps) / start.elapsed().as_secs_f64()
}

fn main() {
    println!("six against six, Division B, a ball; every robot commanded every cycle (100 Hz)");
    println!(
        "{:<52} {:>8} {:>10} {:>12}",
        "mode", "cycles", "cycles/s", "x real time"
    );
    let line = |name: &str, steps: u32, rate: f64| {
        println!("{name:<52} {steps:>8} {rate:>10.0} {:>12.1}", rate / 100.0);
    };
    // Best of three (the machine may be shared).
    let best = |f: &dyn Fn() -> f64| (0..3).map(|_| f()).fold(0.0, f64::max);
    line(
        "lockstep over UDP, no cameras",
        3000,
        best(&|| over_udp(3000)),
    );
    line(
        "the simulator alone, no cameras",
        3000,
        best(&|| direct(3000, false)),
    );
    line(
        "the simulator alone, 12 cameras 256x220 (CPU)",
        200,
        best(&|| direct(200, true)),
    );
    println!(
        "(grSim, built on this machine, runs six against six on Division B at 230-332 steps/s)"
    );
}
