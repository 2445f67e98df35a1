//! A run served live over the Foxglove WebSocket protocol (`foxglove.websocket.v1`, the
//! `foxglove` crate's server): the same channels as the MCAP file, so the Foxglove app shows the
//! run as it goes. A viewer that subscribes to `/world` after the run began gets the world's
//! scene again, to itself. The run may wait for a first viewer, and the server lingers after the
//! run until its viewers have everything (they disconnect) or a time limit passes.

use foxglove::messages::SceneUpdate;
use foxglove::websocket::{ChannelView, Client, ServerListener};
use foxglove::{Channel, Context, PartialMetadata, WebSocketServer, WebSocketServerHandle};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// Messages a viewer's queue holds before the oldest are dropped (a camera frame is one).
const BACKLOG: usize = 16_384;

/// How a run is served live.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LiveOptions {
    /// The address to listen on, `HOST:PORT` (port 0: any free port).
    pub addr: String,
    /// Wait before the first cycle until a viewer subscribes to a channel.
    pub wait_for_viewer: bool,
    /// After the run, serve its viewers until they disconnect, at most this long (s).
    pub linger_s: f64,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            addr: "127.0.0.1:8765".into(),
            wait_for_viewer: false,
            linger_s: 2.0,
        }
    }
}

/// Why a live address is not `HOST:PORT`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum AddressError {
    /// No `:`.
    #[error("live address {0:?}: expected HOST:PORT")]
    NoPort(String),
    /// A port that is not a number in `0..=65535`.
    #[error("live address {addr:?}: port {port:?}: {reason}")]
    BadPort {
        /// The address.
        addr: String,
        /// The port as written.
        port: String,
        /// Why it is not one.
        reason: std::num::ParseIntError,
    },
    /// Nothing before the `:`.
    #[error("live address {0:?}: no host")]
    NoHost(String),
}

/// Why a live server does not start.
#[derive(Debug, thiserror::Error)]
pub enum LiveError {
    /// The address is not `HOST:PORT`.
    #[error(transparent)]
    Address(#[from] AddressError),
    /// The server cannot listen there.
    #[error("serving on {addr}: {reason}")]
    Serve {
        /// The address.
        addr: String,
        /// What the Foxglove SDK said.
        reason: foxglove::FoxgloveError,
    },
}

impl LiveOptions {
    /// The host and port of `addr`, or why it is not one.
    pub fn host_port(&self) -> Result<(String, u16), AddressError> {
        let (host, port) = self
            .addr
            .rsplit_once(':')
            .ok_or_else(|| AddressError::NoPort(self.addr.clone()))?;
        let port = port
            .parse::<u16>()
            .map_err(|reason| AddressError::BadPort {
                addr: self.addr.clone(),
                port: port.to_string(),
                reason,
            })?;
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() {
            return Err(AddressError::NoHost(self.addr.clone()));
        }
        Ok((host.to_string(), port))
    }
}

/// The world's scene and its channel, once the run has logged it.
type WorldSlot = Mutex<Option<(Arc<Channel<SceneUpdate>>, SceneUpdate)>>;

/// What the server's callbacks share with the run.
#[derive(Default)]
struct Viewers {
    /// Set once a viewer subscribed to any channel.
    subscribed: Mutex<bool>,
    arrived: Condvar,
    world: WorldSlot,
}

impl ServerListener for Viewers {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        *self.subscribed.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.arrived.notify_all();
        if channel.topic() == "/world" {
            let world = self.world.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((ch, scene)) = world.as_ref() {
                ch.log_with_meta_to_sink(
                    scene,
                    PartialMetadata::with_log_time(0),
                    client.sink_id(),
                );
            }
        }
    }
}

/// Keeps the world's scene for viewers who subscribe to `/world` after it was logged.
pub struct WorldKeeper(Arc<Viewers>);

impl WorldKeeper {
    /// Remembers `scene`, logged on `channel`.
    pub fn keep(&self, channel: Arc<Channel<SceneUpdate>>, scene: SceneUpdate) {
        *self.0.world.lock().unwrap_or_else(|e| e.into_inner()) = Some((channel, scene));
    }
}

/// The live server of one run.
pub struct LiveServer {
    handle: WebSocketServerHandle,
    viewers: Arc<Viewers>,
    options: LiveOptions,
}

impl LiveServer {
    /// Starts serving `ctx`'s channels.
    pub fn start(ctx: &Arc<Context>, options: &LiveOptions) -> Result<Self, LiveError> {
        let (host, port) = options.host_port()?;
        let viewers = Arc::new(Viewers::default());
        let handle = WebSocketServer::new()
            .name("omniloop")
            .context(ctx)
            .bind(host, port)
            .message_backlog_size(BACKLOG)
            .listener(viewers.clone())
            .start_blocking()
            .map_err(|reason| LiveError::Serve {
                addr: options.addr.clone(),
                reason,
            })?;
        Ok(Self {
            handle,
            viewers,
            options: options.clone(),
        })
    }

    /// The port it listens on (the one given, or the one found for port 0).
    pub fn port(&self) -> u16 {
        self.handle.port()
    }

    /// The host it listens on.
    pub fn host(&self) -> String {
        self.options
            .host_port()
            .map_or_else(|_| self.options.addr.clone(), |(h, _)| h)
    }

    /// Whether the run waits for a viewer.
    pub fn waits_for_viewer(&self) -> bool {
        self.options.wait_for_viewer
    }

    /// Blocks until a viewer subscribes to a channel, when the options ask for it.
    pub fn wait_for_viewer(&self) {
        if !self.options.wait_for_viewer {
            return;
        }
        let mut subscribed = self
            .viewers
            .subscribed
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        while !*subscribed {
            subscribed = self
                .viewers
                .arrived
                .wait(subscribed)
                .unwrap_or_else(|e| e.into_inner());
        }
    }

    /// What keeps the world's scene for viewers who subscribe to `/world` later.
    pub fn world_keeper(&self) -> WorldKeeper {
        WorldKeeper(self.viewers.clone())
    }

    /// Serves the viewers until they disconnect or the linger time passes, then stops.
    pub fn finish(self) {
        let until = Instant::now() + Duration::from_secs_f64(self.options.linger_s.max(0.0));
        while self.handle.client_count() > 0 && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(20));
        }
        self.handle.stop().wait_blocking();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addresses_parse_or_say_why_not() {
        let at = |a: &str| {
            LiveOptions {
                addr: a.into(),
                ..LiveOptions::default()
            }
            .host_port()
        };
        assert_eq!(at("127.0.0.1:8765"), Ok(("127.0.0.1".into(), 8765)));
        assert_eq!(at("[::1]:0"), Ok(("::1".into(), 0)));
        let e = at("localhost").unwrap_err();
        assert_eq!(e, AddressError::NoPort("localhost".into()));
        assert!(e.to_string().contains("HOST:PORT"), "{e}");
        let e = at("localhost:http").unwrap_err().to_string();
        assert!(e.contains("port \"http\""), "{e}");
        let e = at(":80").unwrap_err().to_string();
        assert!(e.contains("no host"), "{e}");
    }
}
