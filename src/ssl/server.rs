//! The network side of `omniloop ssl`: the protocol's three UDP ports, answered from
//! [`SslSimulator`]; vision and the referee sent where the scenario says (multicast, unicast
//! or loopback). Two paces:
//!
//! - **real time** (default): a control cycle every period of wall time (scaled by the
//!   protocol's `simulation_speed`), whatever arrived taken before it;
//! - **lockstep**: the simulation waits for its clients. A `SimulationSyncRequest` (the
//!   protocol's draft synchronous message, with `sim_step` set: without it a datagram is the
//!   port's own message) applies its commands and advances by `sim_step`,
//!   answered with a `SimulationSyncResponse` holding the detection frames of the step. On a
//!   team's port it also carries that team's `RobotControl`; on the control port its
//!   `SimulatorCommand` only. Plain `RobotControl`s to the team ports are taken and answered
//!   as in real time and hold until the next step. The same scenario, seed and command stream
//!   give byte-identical files.
//!
//! Bad input never stops it: a datagram that does not decode is answered with a
//! `SimulatorError` (`MALFORMED`), a control datagram from a host not allowed is dropped and
//! counted, and past `max_datagrams_per_cycle` a port's datagrams in a cycle are read, dropped
//! and counted.

use super::engine::{Outgoing, SslError, SslHost, SslSimulator};
use super::log::{LogMessage, SslLog};
use super::wire::sim::{RobotControlResponse, SimulationSyncRequest, SimulationSyncResponse};
use super::wire::{MAX_DATAGRAM, decode};
use crate::scenario::ssl::SslSpec;
use crate::scenario::ssl::TeamColor;
use prost::Message;
use std::io::{self, BufWriter, Write};
use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How the simulation keeps time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Pace {
    /// A cycle every control period of wall time.
    #[default]
    RealTime,
    /// A step when a client asks for one.
    Lockstep,
}

/// How to serve.
#[derive(Debug, Clone, Default)]
pub struct ServeOptions {
    /// Real time or lockstep.
    pub pace: Pace,
    /// Stop after this much simulated time (none: the scenario's `run.duration_s`).
    pub duration_s: Option<f64>,
    /// Lockstep: stop when no datagram came for this long of wall time (none: never).
    pub idle_exit_s: Option<f64>,
    /// Write what vision and the referee sent as the league's log file here.
    pub log: Option<PathBuf>,
}

/// Why serving stopped early.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The game failed.
    #[error(transparent)]
    Ssl(#[from] SslError),
    /// A port could not be opened or a file written.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// Why it failed.
        source: io::Error,
    },
}

fn io_err(what: impl Into<String>) -> impl FnOnce(io::Error) -> ServeError {
    let what = what.into();
    move |source| ServeError::Io { what, source }
}

/// The sockets, bound.
pub struct Ports {
    control: UdpSocket,
    blue: UdpSocket,
    yellow: UdpSocket,
    out: UdpSocket,
    vision_to: SocketAddr,
    referee_to: SocketAddr,
    allowed: Vec<IpAddr>,
    per_cycle: usize,
}

/// Where the ports ended up (a port of 0 in the scenario takes a free one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bound {
    /// Simulation control.
    pub control: SocketAddr,
    /// Blue's robot control.
    pub blue: SocketAddr,
    /// Yellow's robot control.
    pub yellow: SocketAddr,
    /// Where vision goes.
    pub vision_to: SocketAddr,
    /// Where the referee goes.
    pub referee_to: SocketAddr,
}

/// What a served game did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ServeReport {
    /// Control cycles run.
    pub cycles: u64,
    /// Simulated time at the end, s.
    pub sim_time_s: f64,
    /// Wall time, s.
    pub wall_s: f64,
    /// Cycles that started later than their time by more than a period (real time).
    pub late_cycles: u64,
    /// Datagrams dropped over a port's limit in a cycle.
    pub flood_dropped: u64,
    /// Control datagrams dropped from hosts not allowed.
    pub refused: u64,
    /// Datagrams that did not decode (answered).
    pub malformed: u64,
    /// Errors answered.
    pub errors: u64,
    /// Goals of blue and yellow.
    pub score: [u32; 2],
}

impl Ports {
    /// Binds the scenario's ports (`port_override` replaces each port and address where set).
    pub fn bind(spec: &SslSpec) -> Result<Self, ServeError> {
        let n = &spec.network;
        let ip: IpAddr = n
            .bind_address
            .parse()
            .unwrap_or(IpAddr::V4(Ipv4Addr::UNSPECIFIED));
        let open = |port: u16, what: &str| -> Result<UdpSocket, ServeError> {
            let s = UdpSocket::bind((ip, port))
                .map_err(io_err(format!("opening the {what} port {ip}:{port}")))?;
            s.set_nonblocking(true)
                .map_err(io_err(format!("the {what} port")))?;
            Ok(s)
        };
        let parse = |a: &str, what: &str| -> Result<SocketAddr, ServeError> {
            a.parse()
                .map_err(|_| io_err(what)(io::Error::other(format!("{a:?} is not address:port"))))
        };
        let out =
            UdpSocket::bind((Ipv4Addr::UNSPECIFIED, 0)).map_err(io_err("the sending socket"))?;
        // Multicast stays on this machine's network and reaches its own listeners.
        let _ = out.set_multicast_ttl_v4(1);
        let _ = out.set_multicast_loop_v4(true);
        let mut allowed: Vec<IpAddr> = (n.allowed_hosts.iter())
            .filter_map(|h| h.parse().ok())
            .collect();
        allowed.extend([
            IpAddr::V4(Ipv4Addr::LOCALHOST),
            IpAddr::V6(std::net::Ipv6Addr::LOCALHOST),
        ]);
        Ok(Self {
            control: open(n.control_port, "simulation-control")?,
            blue: open(n.blue_port, "blue robot-control")?,
            yellow: open(n.yellow_port, "yellow robot-control")?,
            out,
            vision_to: parse(&n.vision_address, "the vision address")?,
            referee_to: parse(&n.referee_address, "the referee address")?,
            allowed,
            per_cycle: n.max_datagrams_per_cycle,
        })
    }

    /// Where the ports ended up.
    pub fn bound(&self) -> Result<Bound, ServeError> {
        let addr = |s: &UdpSocket| s.local_addr().map_err(io_err("a port's address"));
        Ok(Bound {
            control: addr(&self.control)?,
            blue: addr(&self.blue)?,
            yellow: addr(&self.yellow)?,
            vision_to: self.vision_to,
            referee_to: self.referee_to,
        })
    }
}

/// Which port a datagram came to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Port {
    Control,
    Team(TeamColor),
}

/// The game being served: the simulator, its ports, its log and its tallies.
pub struct Server<H: SslHost = SslSimulator> {
    sim: H,
    ports: Ports,
    log: Option<SslLog<BufWriter<std::fs::File>>>,
    report: ServeReport,
    reported_errors: u64,
    buf: Vec<u8>,
}

impl<H: SslHost> Server<H> {
    /// Serves `sim` on `ports`, logging to `options.log`.
    pub fn new(sim: H, ports: Ports, options: &ServeOptions) -> Result<Self, ServeError> {
        let log = match &options.log {
            Some(path) => {
                let f = std::fs::File::create(path)
                    .map_err(io_err(format!("creating {}", path.display())))?;
                Some(SslLog::new(BufWriter::new(f)).map_err(io_err("writing the log"))?)
            }
            None => None,
        };
        Ok(Self {
            sim,
            ports,
            log,
            report: ServeReport::default(),
            reported_errors: 0,
            buf: vec![0; MAX_DATAGRAM + 1],
        })
    }

    /// Runs until the time is up, `stop` is set or (lockstep) the clients fall idle.
    pub fn run(
        mut self,
        options: &ServeOptions,
        stop: &Arc<AtomicBool>,
    ) -> Result<(H, ServeReport), ServeError> {
        let start = Instant::now();
        let end_s = options
            .duration_s
            .unwrap_or(self.sim.simulation().scenario().run.duration_s);
        match options.pace {
            Pace::RealTime => self.real_time(end_s, stop)?,
            Pace::Lockstep => self.lockstep(end_s, options.idle_exit_s, stop)?,
        }
        if let Some(log) = self.log.take() {
            log.finish().map_err(io_err("writing the log"))?;
        }
        let t = self.sim.link().tallies();
        self.report.wall_s = start.elapsed().as_secs_f64();
        self.report.sim_time_s = self.sim.simulation().world().time_s();
        self.report.malformed = t.malformed;
        self.report.errors = t.errors;
        self.report.score = self.sim.link().score();
        Ok((self.sim, self.report))
    }

    /// The game being served.
    pub fn host(&self) -> &H {
        &self.sim
    }

    /// The game being served, to reach it between cycles.
    pub fn host_mut(&mut self) -> &mut H {
        &mut self.sim
    }

    /// One cycle for a host that keeps time itself: what waits on the ports taken and
    /// answered, a control cycle, its vision and referee packets sent.
    pub fn serve_cycle(&mut self) -> Result<Outgoing, ServeError> {
        for port in [
            Port::Control,
            Port::Team(TeamColor::Blue),
            Port::Team(TeamColor::Yellow),
        ] {
            self.drain(port, false)?;
        }
        let out = self.sim.step()?;
        self.report.cycles += 1;
        self.send(&out)?;
        Ok(out)
    }

    fn real_time(&mut self, end_s: f64, stop: &Arc<AtomicBool>) -> Result<(), ServeError> {
        let period = self.sim.simulation().scenario().run.control_period_s;
        let mut next = Instant::now();
        while self.sim.simulation().world().time_s() < end_s - 1e-9 && !stop.load(Ordering::Relaxed)
        {
            self.serve_cycle()?;
            next += Duration::from_secs_f64(period / self.sim.link().speed());
            let now = Instant::now();
            if now > next + Duration::from_secs_f64(period) {
                self.report.late_cycles += 1;
                next = now;
            } else if next > now {
                std::thread::sleep(next - now);
            }
        }
        Ok(())
    }

    fn lockstep(
        &mut self,
        end_s: f64,
        idle_s: Option<f64>,
        stop: &Arc<AtomicBool>,
    ) -> Result<(), ServeError> {
        let mut last_heard = Instant::now();
        while self.sim.simulation().world().time_s() < end_s - 1e-9 && !stop.load(Ordering::Relaxed)
        {
            let mut any = false;
            for port in [
                Port::Control,
                Port::Team(TeamColor::Blue),
                Port::Team(TeamColor::Yellow),
            ] {
                any |= self.drain(port, true)? > 0;
            }
            let quiet = last_heard.elapsed();
            if any {
                last_heard = Instant::now();
            } else if idle_s.is_some_and(|s| quiet.as_secs_f64() > s) {
                break;
            } else if quiet < Duration::from_millis(5) {
                // A client in lockstep answers within microseconds: stay on the core a while
                // (a sleep costs more than a step's work).
                std::thread::yield_now();
            } else {
                std::thread::sleep(Duration::from_micros(200));
            }
        }
        Ok(())
    }

    fn socket(&self, port: Port) -> &UdpSocket {
        match port {
            Port::Control => &self.ports.control,
            Port::Team(TeamColor::Blue) => &self.ports.blue,
            Port::Team(TeamColor::Yellow) => &self.ports.yellow,
        }
    }

    /// Takes what waits on `port`, up to the limit (the rest read and counted); answers each.
    /// How many were taken.
    fn drain(&mut self, port: Port, lockstep: bool) -> Result<usize, ServeError> {
        let mut taken = 0;
        for _ in 0..self.ports.per_cycle.saturating_mul(20) {
            let mut buf = std::mem::take(&mut self.buf);
            let got = self.socket(port).recv_from(&mut buf);
            let (len, from) = match got {
                Ok(r) => r,
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => {
                    self.buf = buf;
                    break;
                }
                // A reset from an earlier answer's unreachable sender, or the like: go on.
                Err(_) => {
                    self.buf = buf;
                    continue;
                }
            };
            if port == Port::Control && !self.ports.allowed.contains(&from.ip()) {
                self.report.refused += 1;
                self.say(format!(
                    "refused a control datagram from {from} (not in [ssl.network] allowed_hosts)"
                ));
            } else if taken >= self.ports.per_cycle {
                self.report.flood_dropped += 1;
            } else {
                taken += 1;
                let answer = self.answer(port, &buf[..len], lockstep)?;
                // An answer that cannot be sent (the sender gone) is the sender's loss.
                let _ = self.socket(port).send_to(&answer, from);
            }
            self.buf = buf;
        }
        self.say_errors();
        Ok(taken)
    }

    /// The answer to one datagram; in lockstep a sync request steps the simulation.
    fn answer(&mut self, port: Port, bytes: &[u8], lockstep: bool) -> Result<Vec<u8>, ServeError> {
        // A sync request sets its step: without one, the datagram is the port's own message
        // (a `SimulatorCommand` with only `config` would decode as a sync request too).
        let sync = lockstep
            .then(|| decode::<SimulationSyncRequest>(bytes, "SimulationSyncRequest").ok())
            .flatten()
            .filter(|r| r.sim_step.is_some());
        if let Some(req) = sync {
            return self.sync(port, &req);
        }
        Ok(match port {
            Port::Control => self.sim.simulator_command(bytes),
            Port::Team(team) => self.sim.robot_control(team, bytes),
        })
    }

    fn sync(&mut self, port: Port, req: &SimulationSyncRequest) -> Result<Vec<u8>, ServeError> {
        let mut errors = match &req.simulator_command {
            Some(c) => self.sim.command_errors(c),
            None => Vec::new(),
        };
        let team = match port {
            Port::Team(t) => Some(t),
            Port::Control => None,
        };
        match (team, &req.robot_control) {
            (Some(t), Some(rc)) => errors.extend(self.sim.control_errors(t, rc)),
            (None, Some(_)) => errors.push(super::commands::error(
                "ROBOT_CONTROL_ON_CONTROL_PORT",
                "a sync request's robot_control goes to its team's port".to_string(),
            )),
            _ => {}
        }
        let period = self.sim.simulation().scenario().run.control_period_s;
        let step = req.sim_step.map_or(0.0, f64::from);
        let cycles = if step.is_finite() && step > 0.0 {
            (step / period).round().max(1.0) as u64
        } else {
            0
        };
        let mut detection = Vec::new();
        for _ in 0..cycles.min(100_000) {
            let out = self.sim.step()?;
            self.report.cycles += 1;
            self.send(&out)?;
            detection.extend(out.detections);
        }
        let response = SimulationSyncResponse {
            detection,
            robot_control_response: Some(RobotControlResponse {
                errors,
                feedback: (team.map(|t| self.sim.link().team_feedback(self.sim.simulation(), t)))
                    .unwrap_or_default(),
            }),
        };
        Ok(response.encode_to_vec())
    }

    /// Sends a cycle's vision and referee packets, and logs them.
    fn send(&mut self, out: &Outgoing) -> Result<(), ServeError> {
        let mut vision_to = self.ports.vision_to;
        if let Some(p) = self.sim.link().vision_port() {
            vision_to.set_port(p);
        }
        for p in &out.vision {
            let _ = self.ports.out.send_to(p, vision_to);
            if let Some(log) = &mut self.log {
                log.write(out.t_s, LogMessage::Vision2014, p)
                    .map_err(io_err("writing the log"))?;
            }
        }
        if let Some(r) = &out.referee {
            let _ = self.ports.out.send_to(r, self.ports.referee_to);
            if let Some(log) = &mut self.log {
                log.write(out.t_s, LogMessage::Referee2013, r)
                    .map_err(io_err("writing the log"))?;
            }
        }
        Ok(())
    }

    /// A line for the user, the first few of a kind only.
    fn say(&mut self, line: String) {
        if self.report.refused <= 5 {
            eprintln!("omniloop ssl: {line}");
        }
    }

    /// The errors answered since the last report, as a count now and then.
    fn say_errors(&mut self) {
        let t = self.sim.link().tallies();
        if t.errors > self.reported_errors
            && (self.reported_errors < 10 || t.errors - self.reported_errors >= 1000)
        {
            eprintln!(
                "omniloop ssl: {} errors answered so far ({} malformed datagrams)",
                t.errors, t.malformed
            );
            self.reported_errors = t.errors;
        }
        let _ = io::stderr().flush();
    }
}
