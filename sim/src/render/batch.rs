//! One GPU shared by many runs: each run's renderer sends its frames to a [`BatchServer`], which
//! waits until every run that has joined has a frame waiting (or `wait` has passed since the
//! first), traces them all in one dispatch with one readback ([`GpuRenderer::render_batch`]) and
//! hands each run its image (and its truth, when the frame asked:
//! [`GpuRenderer::render_batch_truth`]). Runs that render in the same cycle so share the GPU's
//! fixed cost per dispatch; a frame's image is the one it would get alone.

use super::error::RenderError;
use super::gpu::{FrameRequest, GpuRenderer, PixelTruth, TracedFrame};
use super::noise::FrameNoise;
use super::scene::Scene;
use crate::sensor::Sensor;
use nalgebra::Isometry2;
use std::sync::Arc;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::{Duration, Instant};

/// A frame waiting for its batch, and where its image goes.
struct Pending {
    scene: Scene,
    sensor: Sensor,
    pose: Isometry2<f64>,
    noise: Option<FrameNoise>,
    /// Whether the frame asks for its truth.
    truth: bool,
    reply: Sender<Result<TracedFrame, Arc<RenderError>>>,
}

enum Message {
    Join,
    Leave,
    Frame(Box<Pending>),
    Stop,
}

/// The thread that owns the GPU and traces the batches. Dropping it stops the thread and waits
/// for it, so that the GPU device is released before the process exits (a Vulkan driver torn
/// down by the process's exit while another thread still destroys its device can crash).
pub struct BatchServer {
    handle: BatchHandle,
    thread: Option<std::thread::JoinHandle<()>>,
}

/// A way to reach a [`BatchServer`]: clone it into each run.
#[derive(Clone)]
pub struct BatchHandle {
    tx: Sender<Message>,
    name: String,
}

impl std::fmt::Debug for BatchHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "BatchHandle({})", self.name)
    }
}

impl BatchServer {
    /// Starts the server on `gpu`; a batch goes out when every joined run has a frame in it or
    /// `wait` after its first frame.
    pub fn start(mut gpu: GpuRenderer, wait: Duration) -> Self {
        let (tx, rx) = channel();
        let name = format!("{} (batched)", gpu.adapter_name());
        let thread = std::thread::spawn(move || serve(&mut gpu, &rx, wait));
        Self {
            handle: BatchHandle { tx, name },
            thread: Some(thread),
        }
    }

    /// A handle for a run.
    pub fn handle(&self) -> BatchHandle {
        self.handle.clone()
    }
}

impl Drop for BatchServer {
    fn drop(&mut self) {
        let _ = self.handle.tx.send(Message::Stop);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl BatchHandle {
    /// The renderer's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Joins the server: until the client is dropped, batches wait for its frames too.
    pub fn join(&self) -> BatchClient {
        let _ = self.tx.send(Message::Join);
        BatchClient {
            tx: self.tx.clone(),
        }
    }
}

/// One run's place at the server.
pub struct BatchClient {
    tx: Sender<Message>,
}

impl BatchClient {
    /// The image of one frame, traced in the next batch.
    pub fn render(
        &self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
        noise: Option<FrameNoise>,
    ) -> Result<Vec<u32>, RenderError> {
        let request = FrameRequest {
            scene,
            sensor,
            pose,
            noise,
        };
        Ok(self.send(request, false)?.0)
    }

    /// The image of one frame, traced in the next batch, with its truth
    /// ([`GpuRenderer::render_truth`]).
    pub fn render_truth(
        &self,
        request: FrameRequest<'_>,
    ) -> Result<(Vec<u32>, PixelTruth), RenderError> {
        match self.send(request, true)? {
            (pixels, Some(truth)) => Ok((pixels, truth)),
            (_, None) => Err(RenderError::Device("the batch returned no truth".into())),
        }
    }

    /// Sends one frame to the next batch and waits for it.
    fn send(&self, r: FrameRequest<'_>, truth: bool) -> Result<TracedFrame, RenderError> {
        let (reply, rx) = channel();
        let frame = Pending {
            scene: r.scene.clone(),
            sensor: r.sensor.clone(),
            pose: *r.pose,
            noise: r.noise,
            truth,
            reply,
        };
        let gone = || RenderError::Device("the batch renderer stopped".into());
        self.tx
            .send(Message::Frame(Box::new(frame)))
            .map_err(|_| gone())?;
        rx.recv().map_err(|_| gone())?.map_err(RenderError::Batch)
    }
}

impl Drop for BatchClient {
    fn drop(&mut self) {
        let _ = self.tx.send(Message::Leave);
    }
}

/// The server's loop: gather, trace, reply; ends on `Stop` or when every handle and client is
/// gone.
fn serve(gpu: &mut GpuRenderer, rx: &Receiver<Message>, wait: Duration) {
    let mut active = 0usize;
    let mut pending: Vec<Pending> = Vec::new();
    let mut deadline = Instant::now();
    loop {
        let msg = if pending.is_empty() {
            match rx.recv() {
                Ok(m) => m,
                Err(_) => return,
            }
        } else {
            match rx.recv_timeout(deadline.saturating_duration_since(Instant::now())) {
                Ok(m) => m,
                Err(RecvTimeoutError::Timeout) => {
                    flush(gpu, &mut pending);
                    continue;
                }
                Err(RecvTimeoutError::Disconnected) => {
                    flush(gpu, &mut pending);
                    return;
                }
            }
        };
        match msg {
            Message::Join => active += 1,
            Message::Leave => active = active.saturating_sub(1),
            Message::Frame(f) => {
                if pending.is_empty() {
                    deadline = Instant::now() + wait;
                }
                pending.push(*f);
            }
            Message::Stop => {
                flush(gpu, &mut pending);
                return;
            }
        }
        if !pending.is_empty() && pending.len() >= active.max(1) {
            flush(gpu, &mut pending);
        }
    }
}

/// Traces the waiting frames in one batch and sends each its image.
fn flush(gpu: &mut GpuRenderer, pending: &mut Vec<Pending>) {
    let frames = std::mem::take(pending);
    let requests: Vec<FrameRequest> = frames
        .iter()
        .map(|p| FrameRequest {
            scene: &p.scene,
            sensor: &p.sensor,
            pose: &p.pose,
            noise: p.noise,
        })
        .collect();
    let truth: Vec<bool> = frames.iter().map(|p| p.truth).collect();
    match gpu.render_batch_truth(&requests, &truth) {
        Ok(traced) => {
            for (p, frame) in frames.iter().zip(traced) {
                let _ = p.reply.send(Ok(frame));
            }
        }
        Err(e) => {
            let e = Arc::new(e);
            for p in &frames {
                let _ = p.reply.send(Err(e.clone()));
            }
        }
    }
}
