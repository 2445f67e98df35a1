//! Watching a run in the tools robotics people use: every cycle on Foxglove channels with
//! Foxglove's well-known schemas ([`Recorder`]), written to an MCAP file ([`McapLog`], `omniloop
//! run --mcap`), which Foxglove, Rerun and ROS 2's tools open; an animated GIF of the run
//! ([`GifLog`], `omniloop run --gif`). See `docs/viewing.md`.
//!
//! The loop hands each cycle over (its frames copied) and goes on; one thread of the log's own
//! encodes the frames and writes every message, in the order the cycles came, so the file is
//! the same from run to run. A few cycles may wait to be written; more, and the loop waits.

pub mod gif;
pub mod recorder;
pub mod scene;

pub use gif::GifLog;
pub use recorder::{Cycle, Recorder};

use crate::run::Summary;
use crate::run::observer::{CycleObserver, CycleView, ObserverHandle};
use foxglove::messages::SceneUpdate;
use foxglove::{Context, McapWriter, McapWriterHandle};
use recorder::world_update;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
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
    fn start(&mut self, world: &omniloop_sim::World) {
        // The log's thread ends only on `Job::End`, so a send cannot fail before it.
        let _ = self.0.send(Job::World(world_update(world)));
    }

    fn cycle(&mut self, view: &CycleView<'_>) {
        let _ = self.0.send(Job::Cycle(Box::new(Cycle::of(view))));
    }
}

/// Why a run cannot be recorded.
#[derive(Debug, thiserror::Error)]
pub enum ViewingError {
    /// The file cannot be written.
    #[error("writing {}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The Foxglove SDK refused (a channel, the writer).
    #[error("{}: {message}", file.display())]
    Foxglove {
        /// The file.
        file: PathBuf,
        /// What the SDK said.
        message: String,
    },
}

/// A run recorded into an MCAP file: its own Foxglove context, the channels (on the log's
/// thread), the writer.
pub struct McapLog {
    file: PathBuf,
    feed: Arc<Mutex<Feed>>,
    worker: JoinHandle<Recorder>,
    writer: McapWriterHandle<BufWriter<File>>,
    _ctx: Arc<Context>,
}

impl McapLog {
    /// Creates (or replaces) `file` and the channels that write into it.
    pub fn create(file: &Path) -> Result<Self, ViewingError> {
        let fail = |e: foxglove::FoxgloveError| ViewingError::Foxglove {
            file: file.to_path_buf(),
            message: e.to_string(),
        };
        let io = |source| ViewingError::Io {
            file: file.to_path_buf(),
            source,
        };
        if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let out = BufWriter::new(File::create(file).map_err(io)?);
        let ctx = Context::new();
        let writer = McapWriter::new().context(&ctx).create(out).map_err(fail)?;
        let mut recorder = Recorder::new(&ctx).map_err(fail)?;
        let (tx, rx) = sync_channel::<Job>(QUEUE);
        let worker = std::thread::spawn(move || {
            while let Ok(job) = rx.recv() {
                match job {
                    Job::World(scene) => recorder.world(&scene),
                    Job::Cycle(c) => recorder.cycle(&c),
                    Job::End => break,
                }
            }
            recorder
        });
        Ok(Self {
            file: file.to_path_buf(),
            feed: Arc::new(Mutex::new(Feed(tx))),
            worker,
            writer,
            _ctx: ctx,
        })
    }

    /// What the run's options take to record every cycle.
    pub fn observer(&self) -> ObserverHandle {
        let shared: Arc<Mutex<dyn CycleObserver>> = self.feed.clone();
        ObserverHandle(shared)
    }

    /// Waits for every cycle to be written, writes the summary (at the run's last time) and
    /// closes the file.
    pub fn finish(self, summary: &Summary) -> Result<PathBuf, ViewingError> {
        let fail = |message: String| ViewingError::Foxglove {
            file: self.file.clone(),
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
        self.writer.close().map_err(|e| ViewingError::Foxglove {
            file: self.file.clone(),
            message: e.to_string(),
        })?;
        Ok(self.file)
    }
}
