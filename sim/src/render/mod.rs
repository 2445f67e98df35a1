//! Rendering the image a sensor sees: a wgpu compute tracer and a CPU reference that computes
//! the same thing, chosen with `--renderer auto|gpu|cpu`.

pub mod batch;
pub mod cpu;
pub mod effects;
pub mod error;
pub mod gpu;
pub mod noise;
pub mod scene;
pub mod trace;
pub mod truth;

pub use batch::{BatchClient, BatchHandle, BatchServer};
pub use cpu::{CpuRenderer, SensorRays};
pub use effects::CameraEffects;
pub use error::RenderError;
pub use gpu::{FrameRequest, GpuRenderer, PixelTruth, TracedFrame};
pub use noise::{FrameNoise, SensorNoise};
pub use scene::Scene;
pub use truth::{TruthFrame, TruthRays};

use crate::sensor::Sensor;
use image::RgbaImage;
use nalgebra::Isometry2;
use std::str::FromStr;

/// The CPU renderer's name, with its threads.
fn cpu_name() -> String {
    format!("cpu (rayon, {} threads)", rayon::current_num_threads())
}

/// Which renderer to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RendererChoice {
    /// The GPU when an adapter exists, else the CPU.
    #[default]
    Auto,
    /// The GPU (fails without an adapter).
    Gpu,
    /// The CPU reference.
    Cpu,
}

/// A renderer's name that is none of them.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown renderer {0:?} (auto, gpu, cpu)")]
pub struct UnknownRenderer(pub String);

impl FromStr for RendererChoice {
    type Err = UnknownRenderer;
    fn from_str(s: &str) -> Result<Self, UnknownRenderer> {
        match s {
            "auto" => Ok(Self::Auto),
            "gpu" => Ok(Self::Gpu),
            "cpu" => Ok(Self::Cpu),
            other => Err(UnknownRenderer(other.to_string())),
        }
    }
}

enum Backend {
    Cpu(Box<CpuRenderer>),
    Gpu(Box<GpuRenderer>),
    Shared(BatchClient),
}

/// A renderer with its per-sensor caches.
pub struct Renderer {
    backend: Backend,
    name: String,
    rays: Vec<(Sensor, SensorRays)>,
    pixels: Vec<u32>,
    truth: Truth,
}

/// The truth's per-sensor caches and the last frame's distances and codes.
#[derive(Default)]
struct Truth {
    rays: Vec<(Sensor, TruthRays)>,
    t: Vec<f32>,
    codes: Vec<u32>,
}

impl Truth {
    /// The truth of the frame last traced with truth, of `sensor` at `pose` in `scene`.
    fn frame(&mut self, scene: &Scene, sensor: &Sensor, pose: &Isometry2<f64>) -> TruthFrame {
        let k = match self.rays.iter().position(|(s, _)| s == sensor) {
            Some(k) => k,
            None => {
                // One entry a sensor name: a camera on a pan unit replaces its own.
                self.rays.retain(|(s, _)| s.name != sensor.name);
                self.rays.push((sensor.clone(), TruthRays::new(sensor)));
                self.rays.len() - 1
            }
        };
        truth::truth_frame(scene, sensor, &self.rays[k].1, pose, &self.t, &self.codes)
    }
}

impl Renderer {
    /// Opens the chosen renderer. With `Auto`, the GPU when a hardware adapter opens; with no
    /// adapter, or only a software one (a rasterizer such as Mesa's llvmpipe, which traces
    /// these frames slower than the CPU renderer), the CPU, saying why through `notice`.
    pub fn new(choice: RendererChoice, notice: impl FnOnce(&str)) -> Result<Self, RenderError> {
        let backend = match choice {
            RendererChoice::Cpu => Backend::Cpu(Box::default()),
            RendererChoice::Gpu => Backend::Gpu(Box::new(GpuRenderer::new()?)),
            RendererChoice::Auto => match GpuRenderer::adapter() {
                Ok(a) if a.get_info().device_type == wgpu::DeviceType::Cpu => {
                    notice(&format!(
                        "renderer: the only GPU adapter is a software one ({}); using the CPU \
                         renderer, which is faster here (--renderer gpu uses the adapter anyway)",
                        a.get_info().name
                    ));
                    Backend::Cpu(Box::default())
                }
                other => match other.and_then(GpuRenderer::with_adapter) {
                    Ok(g) => Backend::Gpu(Box::new(g)),
                    Err(e) => {
                        notice(&format!("renderer: {e}; using the CPU renderer"));
                        Backend::Cpu(Box::default())
                    }
                },
            },
        };
        let name = match &backend {
            Backend::Cpu(_) => cpu_name(),
            Backend::Gpu(g) => g.adapter_name().to_string(),
            Backend::Shared(_) => "shared GPU (batched)".to_string(),
        };
        Ok(Self {
            backend,
            name,
            rays: Vec::new(),
            pixels: Vec::new(),
            truth: Truth::default(),
        })
    }

    /// A renderer whose frames go to the shared GPU of `server`, traced in batches with other
    /// runs' frames.
    pub fn shared(server: &BatchHandle) -> Self {
        Self {
            backend: Backend::Shared(server.join()),
            name: server.name().to_string(),
            rays: Vec::new(),
            pixels: Vec::new(),
            truth: Truth::default(),
        }
    }

    /// The CPU renderer.
    pub fn cpu() -> Self {
        Self {
            backend: Backend::Cpu(Box::default()),
            name: cpu_name(),
            rays: Vec::new(),
            pixels: Vec::new(),
            truth: Truth::default(),
        }
    }

    /// Name of the renderer: the adapter for the GPU, `cpu (...)` otherwise.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The GPU renderer it opened, to share (`None` for the CPU or a shared GPU).
    pub fn into_gpu(self) -> Option<GpuRenderer> {
        match self.backend {
            Backend::Gpu(g) => Some(*g),
            Backend::Cpu(_) | Backend::Shared(_) => None,
        }
    }

    /// Whether frames are traced on a GPU adapter.
    pub fn is_gpu(&self) -> bool {
        matches!(self.backend, Backend::Gpu(_) | Backend::Shared(_))
    }

    /// Renders the clean frame (no noise) as packed RGBA8 into the renderer's scratch buffer.
    pub fn render_packed(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
    ) -> Result<&[u32], RenderError> {
        self.trace(scene, sensor, pose, None, false)?;
        Ok(&self.pixels)
    }

    /// Traces a frame into the scratch buffer: on a GPU with `noise` drawn by the shader
    /// (returns true), on the CPU clean (returns false: the noise is the caller's to draw).
    /// With `truth`, each pixel's distance and what it meets go to the truth's buffers too.
    fn trace(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
        noise: Option<FrameNoise>,
        truth: bool,
    ) -> Result<bool, RenderError> {
        let n = (sensor.width_px * sensor.height_px) as usize;
        self.pixels.resize(n, 0);
        if truth {
            self.truth.t.resize(n, 0.0);
            self.truth.codes.resize(n, 0);
        }
        let request = FrameRequest {
            scene,
            sensor,
            pose,
            noise,
        };
        match &mut self.backend {
            Backend::Gpu(g) if truth => {
                let (t, codes) = (&mut self.truth.t, &mut self.truth.codes);
                g.render_truth(request, &mut self.pixels, t, codes)?;
            }
            Backend::Gpu(g) => g.render(scene, sensor, pose, noise, &mut self.pixels)?,
            Backend::Shared(client) if truth => {
                let (pixels, t) = client.render_truth(request)?;
                (self.pixels, self.truth.t, self.truth.codes) = (pixels, t.t, t.codes);
            }
            Backend::Shared(client) => self.pixels = client.render(scene, sensor, pose, noise)?,
            Backend::Cpu(c) => {
                // One cache entry a sensor name, traced again when the sensor changed (a camera
                // on a pan unit).
                let k = match self.rays.iter().position(|(s, _)| s.name == sensor.name) {
                    Some(k) => {
                        if self.rays[k].0 != *sensor {
                            self.rays[k] = (sensor.clone(), SensorRays::retraced(sensor));
                        }
                        k
                    }
                    None => {
                        self.rays.push((sensor.clone(), SensorRays::new(sensor)));
                        self.rays.len() - 1
                    }
                };
                let rays = &mut self.rays[k].1;
                if truth {
                    let buffers = (&mut self.truth.t[..], &mut self.truth.codes[..]);
                    c.render_truth(scene, rays, pose, &mut self.pixels, buffers);
                } else {
                    c.render(scene, rays, pose, &mut self.pixels);
                }
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Renders the frames of `requests` (each with its noise, if any) as packed RGBA8, in
    /// order: on the GPU in one dispatch with one readback, on the CPU one after the other.
    pub fn render_batch_packed(
        &mut self,
        requests: &[FrameRequest<'_>],
    ) -> Result<Vec<Vec<u32>>, RenderError> {
        if let Backend::Gpu(g) = &mut self.backend {
            return g.render_batch(requests);
        }
        let mut out = Vec::with_capacity(requests.len());
        for r in requests {
            let drawn = self.trace(r.scene, r.sensor, r.pose, r.noise, false)?;
            match r.noise {
                Some(n) if !drawn => {
                    let mut rgba = vec![0u8; self.pixels.len() * 4];
                    noise::apply(&self.pixels, n, &mut rgba);
                    out.push(
                        rgba.chunks_exact(4)
                            .map(|p| u32::from_le_bytes([p[0], p[1], p[2], p[3]]))
                            .collect(),
                    );
                }
                _ => out.push(self.pixels.clone()),
            }
        }
        Ok(out)
    }

    /// Renders a frame with the sensor's noise, the next frame of `noise` (or none when
    /// `None`): the GPU draws it in the shader, the CPU after tracing, the same values.
    pub fn render(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
        noise: Option<&mut SensorNoise>,
    ) -> Result<RgbaImage, RenderError> {
        self.render_exposed(scene, sensor, std::slice::from_ref(pose), noise)
    }

    /// Renders a frame as [`Renderer::render`] does, through the sensor's camera effects:
    /// `poses` are where the robot was during the exposure (the first alone without motion
    /// blur; [`effects::exposure_poses`] gives them).
    pub fn render_exposed(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        poses: &[Isometry2<f64>],
        noise: Option<&mut SensorNoise>,
    ) -> Result<RgbaImage, RenderError> {
        self.exposed(scene, sensor, poses, noise, false)
    }

    /// [`Renderer::render_exposed`] with the truth of the frame at the exposure's first pose
    /// (the frame's own pose): the images are the same.
    pub fn render_exposed_truth(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        poses: &[Isometry2<f64>],
        noise: Option<&mut SensorNoise>,
    ) -> Result<(RgbaImage, TruthFrame), RenderError> {
        let img = self.exposed(scene, sensor, poses, noise, true)?;
        let pose = poses.first().copied().unwrap_or_else(Isometry2::identity);
        Ok((img, self.truth.frame(scene, sensor, &pose)))
    }

    /// The truth of a frame of `sensor` at `pose` in `scene`, without its image.
    pub fn render_truth(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
    ) -> Result<TruthFrame, RenderError> {
        self.trace(scene, sensor, pose, None, true)?;
        Ok(self.truth.frame(scene, sensor, pose))
    }

    fn exposed(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        poses: &[Isometry2<f64>],
        noise: Option<&mut SensorNoise>,
        truth: bool,
    ) -> Result<RgbaImage, RenderError> {
        let Some(pose) = poses.first() else {
            return Err(RenderError::Invalid("a frame needs a pose".into()));
        };
        let frame_noise = noise.map(|n| n.next_frame(sensor.noise_sigma as f32));
        if !sensor.effects.is_off() {
            let used = &poses[..poses.len().min(sensor.effects.sub_frames())];
            let mut sub_frames = Vec::with_capacity(used.len());
            for (i, p) in used.iter().enumerate() {
                self.trace(scene, sensor, p, None, truth && i == 0)?;
                sub_frames.push(self.pixels.clone());
            }
            let size = [sensor.width_px, sensor.height_px];
            let rgba = effects::develop(
                &sensor.effects,
                &sub_frames,
                size,
                [sensor.cx_px, sensor.cy_px],
                frame_noise,
            );
            let mut img = RgbaImage::from_raw(size[0], size[1], rgba)
                .ok_or_else(|| RenderError::Invalid("frame size".into()))?;
            if let Some(levels) = sensor.grey_levels {
                quantise_grey(&mut img, levels);
            }
            return effects::compress(img, sensor.effects.jpeg_quality);
        }
        let mut img = RgbaImage::new(sensor.width_px, sensor.height_px);
        let drawn = self.trace(scene, sensor, pose, frame_noise, truth)?;
        match frame_noise {
            Some(fnz) if !drawn => noise::apply(&self.pixels, fnz, &mut img),
            _ => {
                for (p, out) in self.pixels.iter().zip(img.chunks_exact_mut(4)) {
                    out.copy_from_slice(&p.to_le_bytes());
                }
            }
        }
        if let Some(levels) = sensor.grey_levels {
            quantise_grey(&mut img, levels);
        }
        Ok(img)
    }
}

/// Turns `img` grey with its Rec. 601 luminance quantised to `levels` levels spread over 0..255
/// (level `k` is `round(255 k / (levels - 1))`), as a digitizer of that many grey levels gives.
pub fn quantise_grey(img: &mut RgbaImage, levels: u32) {
    let top = (levels.clamp(2, 256) - 1) as f32;
    for px in img.chunks_exact_mut(4) {
        let y = 0.299 * px[0] as f32 + 0.587 * px[1] as f32 + 0.114 * px[2] as f32;
        let k = (y / 255.0 * top).round();
        let g = (k * 255.0 / top).round() as u8;
        px[..3].fill(g);
    }
}

#[cfg(test)]
mod grey_tests {
    use super::*;

    #[test]
    fn sixteen_grey_levels() {
        let mut img =
            RgbaImage::from_fn(256, 1, |u, _| image::Rgba([u as u8, u as u8, u as u8, 255]));
        quantise_grey(&mut img, 16);
        let mut levels: Vec<u8> = img.pixels().map(|p| p.0[0]).collect();
        assert!(img.pixels().all(|p| p.0[0] == p.0[1] && p.0[1] == p.0[2]));
        levels.dedup();
        assert_eq!(levels.len(), 16, "{levels:?}");
        assert!(levels.iter().all(|l| l % 17 == 0));
    }
}
