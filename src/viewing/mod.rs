//! Watching a run in the tools robotics people use: every cycle on Foxglove channels with
//! Foxglove's well-known schemas ([`Recorder`]), written to an MCAP file (`omniloop run --mcap`),
//! which Foxglove, Rerun and ROS 2's tools open, and served live to the Foxglove app over its
//! WebSocket protocol ([`LiveServer`], `omniloop run --live`), both through one [`FoxgloveLog`];
//! the run paced to real time ([`RealTime`], `--realtime`); an animated GIF of the run
//! ([`GifLog`], `omniloop run --gif`). See `docs/viewing.md`.
//!
//! The loop hands each cycle over (its frames copied) and goes on; one thread of the log's own
//! encodes the frames and logs every message, in the order the cycles came, so the file is the
//! same from run to run. A few cycles may wait to be logged; more, and the loop waits.

pub mod gif;
pub mod live;
pub mod pace;
pub mod recorder;
pub mod scene;

pub use gif::GifLog;
pub use live::{AddressError, LiveError, LiveOptions, LiveServer};
pub use pace::RealTime;
pub use recorder::{Cycle, Recorder, RobotCameras};

use crate::run::Summary;
use crate::run::observer::{CycleObserver, CycleView, ObserverHandle};
use foxglove::messages::SceneUpdate;
use foxglove::{Context, McapWriteOptions, McapWriter, McapWriterHandle};
use recorder::world_update;
use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Cycles that may wait to be written before the loop waits for the log.
const QUEUE: usize = 32;

/// What the loop hands the log's thread.
enum Job {
    World(SceneUpdate),
    Cycle(Box<Cycle>),
    End,
}

/// The loop's side: hands each cycle to the log's thread.
struct Feed(SyncSender<Job>);

impl CycleObserver for Feed {
    fn start(&mut self, world: &omniloop_sim::World, _robots: &[String]) {
        // The log's thread ends only on `Job::End`, so a send cannot fail before it.
        let _ = self.0.send(Job::World(world_update(world)));
    }

    fn cycle(&mut self, view: &CycleView<'_>) {
        let _ = self.0.send(Job::Cycle(Box::new(Cycle::of(view))));
    }
}

/// Why a run cannot be recorded or served.
#[derive(Debug, thiserror::Error)]
pub enum ViewingError {
    /// The file cannot be written.
    #[error("writing {}: {reason}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        reason: std::io::Error,
    },
    /// The live server does not start.
    #[error("{what}: {error}")]
    Live {
        /// The file and the live server's address.
        what: String,
        /// Why.
        error: live::LiveError,
    },
    /// The Foxglove SDK refused (a channel, the writer).
    #[error("{what}: {message}")]
    Foxglove {
        /// The file, or the live server's address.
        what: String,
        /// What the SDK said.
        message: String,
    },
}

/// Where a run's Foxglove channels go: an MCAP file, a live server, or both.
#[derive(Debug, Clone, Default)]
pub struct Sinks {
    /// The MCAP file to write.
    pub mcap: Option<PathBuf>,
    /// How to serve the run live.
    pub live: Option<LiveOptions>,
}

impl Sinks {
    /// What the sinks are, for messages: the file and the address.
    fn name(&self) -> String {
        let file = self.mcap.iter().map(|f| f.display().to_string());
        let live = self.live.iter().map(|l| format!("ws://{}", l.addr));
        file.chain(live).collect::<Vec<_>>().join(" and ")
    }
}

/// A run's Foxglove channels on their own context, logged from a thread of the log's own into
/// an MCAP file and to a live server.
pub struct FoxgloveLog {
    what: String,
    feed: Arc<Mutex<Feed>>,
    worker: JoinHandle<Recorder>,
    writer: Option<(PathBuf, McapWriterHandle<BufWriter<File>>)>,
    live: Option<LiveServer>,
    _ctx: Arc<Context>,
}

impl FoxgloveLog {
    /// Creates (or replaces) the MCAP file, starts the live server and makes the channels
    /// (each robot's cameras among them, so a viewer sees them before the first frame).
    pub fn create(sinks: &Sinks, robots: &[RobotCameras]) -> Result<Self, ViewingError> {
        let what = sinks.name();
        let fail = |message: String| ViewingError::Foxglove {
            what: what.clone(),
            message,
        };
        let ctx = Context::new();
        let writer = match &sinks.mcap {
            Some(file) => Some((file.clone(), mcap_writer(&ctx, file)?)),
            None => None,
        };
        let live = match &sinks.live {
            Some(options) => {
                Some(
                    LiveServer::start(&ctx, options).map_err(|error| ViewingError::Live {
                        what: what.clone(),
                        error,
                    })?,
                )
            }
            None => None,
        };
        let mut recorder = Recorder::new(&ctx, robots).map_err(|e| fail(e.to_string()))?;
        let keeper = live.as_ref().map(LiveServer::world_keeper);
        let (tx, rx) = sync_channel::<Job>(QUEUE);
        let worker = std::thread::spawn(move || {
            while let Ok(job) = rx.recv() {
                match job {
                    Job::World(scene) => {
                        recorder.world(&scene);
                        if let Some(k) = &keeper {
                            k.keep(recorder.world_channel(), scene);
                        }
                    }
                    Job::Cycle(c) => recorder.cycle(&c),
                    Job::End => break,
                }
            }
            recorder
        });
        Ok(Self {
            what,
            feed: Arc::new(Mutex::new(Feed(tx))),
            worker,
            writer,
            live,
            _ctx: ctx,
        })
    }

    /// The live server, when there is one.
    pub fn live(&self) -> Option<&LiveServer> {
        self.live.as_ref()
    }

    /// What the run's options take to log every cycle.
    pub fn observer(&self) -> ObserverHandle {
        let shared: Arc<Mutex<dyn CycleObserver>> = self.feed.clone();
        ObserverHandle(shared)
    }

    /// Waits for every cycle to be logged, logs the summary (at the run's last time), closes
    /// the file and lets the live viewers have the rest; the MCAP file, if any.
    pub fn finish(self, summary: &Summary) -> Result<Option<PathBuf>, ViewingError> {
        let fail = |message: String| ViewingError::Foxglove {
            what: self.what.clone(),
            message,
        };
        let sent = self
            .feed
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .0
            .send(Job::End);
        let recorder = match (sent, self.worker.join()) {
            (Ok(()), Ok(r)) => r,
            _ => return Err(fail("the log's thread stopped before the run ended".into())),
        };
        recorder.summary(summary.sim_time_s, summary);
        if let Some(p) = &recorder.problem {
            return Err(fail(p.clone()));
        }
        drop(recorder);
        if let Some(live) = self.live {
            live.finish();
        }
        match self.writer {
            Some((file, w)) => {
                w.close().map_err(|e| fail(e.to_string()))?;
                Ok(Some(file))
            }
            None => Ok(None),
        }
    }
}

/// An MCAP writer into `file` (created with its folder) on `ctx`.
fn mcap_writer(
    ctx: &Arc<Context>,
    file: &std::path::Path,
) -> Result<McapWriterHandle<BufWriter<File>>, ViewingError> {
    let io = |reason| ViewingError::Io {
        file: file.to_path_buf(),
        reason,
    };
    if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(io)?;
    }
    let out = BufWriter::new(File::create(file).map_err(io)?);
    // Chunks are not compressed: zstd over the noisy frames costs a tenth of the loop's time
    // and saves little (see `docs/viewing.md`).
    McapWriter::with_options(McapWriteOptions::new().compression(None))
        .context(ctx)
        .create(out)
        .map_err(|e| ViewingError::Foxglove {
            what: file.display().to_string(),
            message: e.to_string(),
        })
}
