//! A session served over the Small-Size League's protocols (`robot="ssl"`): the robots of the
//! protocol's teams take their commands from `omniloop ssl`'s ports, vision and the referee go
//! out each step, and everything else of `omniloop.Simulation` (the frames of every robot's
//! cameras, odometry, truth, records, the ROS 2 bridge on top) works as for any session.

use omniloop::Session;
use omniloop::robot::{RobotConfig, RobotError, RobotSoftware};
use omniloop::run::{RunError, RunOptions, Simulation};
use omniloop::scenario::Scenario;
use omniloop::scenario::ssl::TeamColor;
use omniloop::ssl::wire::sim::{RobotControl, SimulatorCommand, SimulatorError};
use omniloop::ssl::{
    Bound, Outgoing, Ports, ServeOptions, Server, SslError, SslHost, SslLink, SslSoftware,
};

/// A session and the protocol's side beside it.
pub struct SessionHost {
    session: Session,
    link: SslLink,
}

impl SslHost for SessionHost {
    fn simulation(&self) -> &Simulation {
        self.session.simulation()
    }

    fn link(&self) -> &SslLink {
        &self.link
    }

    fn robot_control(&mut self, team: TeamColor, bytes: &[u8]) -> Vec<u8> {
        self.link
            .robot_control(self.session.simulation(), team, bytes)
    }

    fn simulator_command(&mut self, bytes: &[u8]) -> Vec<u8> {
        self.link
            .simulator_command(self.session.simulation_mut(), bytes)
    }

    fn command_errors(&mut self, c: &SimulatorCommand) -> Vec<SimulatorError> {
        self.link.command_errors(self.session.simulation_mut(), c)
    }

    fn control_errors(&mut self, team: TeamColor, c: &RobotControl) -> Vec<SimulatorError> {
        self.link.control_errors(self.session.simulation(), team, c)
    }

    fn step(&mut self) -> Result<Outgoing, SslError> {
        self.link.before_cycle(self.session.simulation());
        self.session.step()?;
        Ok(self.link.after_cycle(self.session.simulation()))
    }
}

/// The run a `Simulation` steps: a plain session, or one served over the protocol.
pub enum Engine {
    /// Stepped by Python alone.
    Plain(Box<Session>),
    /// Served on the protocol's ports, each step taking what arrived.
    Served(Box<Server<SessionHost>>, Bound),
}

impl Engine {
    /// The session.
    pub fn session(&self) -> &Session {
        match self {
            Self::Plain(s) => s,
            Self::Served(server, _) => &server.host().session,
        }
    }

    /// The session, to change the world between steps.
    pub fn session_mut(&mut self) -> &mut Session {
        match self {
            Self::Plain(s) => s,
            Self::Served(server, _) => &mut server.host_mut().session,
        }
    }

    /// Where the protocol's ports are, when served.
    pub fn ports(&self) -> Option<&Bound> {
        match self {
            Self::Plain(_) => None,
            Self::Served(_, bound) => Some(bound),
        }
    }

    /// One control cycle: served, what waits on the ports first and the packets after.
    pub fn step(&mut self) -> Result<(), RunError> {
        match self {
            Self::Plain(s) => s.step(),
            Self::Served(server, _) => server.serve_cycle().map(|_| ()).map_err(|e| match e {
                omniloop::ssl::ServeError::Ssl(SslError::Run(e)) => e,
                other => RunError::Scenario(format!("serving the SSL protocol: {other}")),
            }),
        }
    }
}

/// Builds the session of `scenario`, served over the protocol when `served`: the protocol's
/// robots on its software, the others on what `software` builds.
pub fn engine(
    scenario: &Scenario,
    options: &RunOptions,
    served: bool,
    mut software: impl FnMut(&RobotConfig) -> Result<Box<dyn RobotSoftware>, RobotError>,
) -> Result<Engine, RunError> {
    if !served {
        return Ok(Engine::Plain(Box::new(Session::new(
            scenario,
            options,
            software,
            |_| {},
        )?)));
    }
    let ssl_error = |e: SslError| match e {
        SslError::Run(e) => e,
        other => RunError::Scenario(other.to_string()),
    };
    let mut plan = SslSoftware::plan(scenario).map_err(ssl_error)?;
    let session = Session::new(
        scenario,
        options,
        |config| match plan.build(config) {
            Some(remote) => Ok(remote),
            None => software(config),
        },
        |_| {},
    )?;
    let link = SslLink::new(session.simulation(), plan).map_err(ssl_error)?;
    let serve_error = |e: omniloop::ssl::ServeError| RunError::Scenario(e.to_string());
    let ports = Ports::bind(link.spec()).map_err(serve_error)?;
    let bound = ports.bound().map_err(serve_error)?;
    let host = SessionHost { session, link };
    let server = Server::new(host, ports, &ServeOptions::default()).map_err(serve_error)?;
    Ok(Engine::Served(Box::new(server), bound))
}
