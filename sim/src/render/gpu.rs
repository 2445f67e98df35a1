//! The wgpu compute renderer: `trace.wgsl` traces every pixel of a batch of frames in one
//! dispatch (the z dimension picks the frame); the frames' scenes share one storage buffer per
//! primitive kind, each frame's header saying where its primitives and pixels start; the images
//! are read back together as packed RGBA8. A single frame is a batch of one, so a frame traced
//! alone and in a batch is the same computation.
//!
//! A frame may ask for its truth as well ([`PixelTruth`]): per pixel, the distance along its
//! scene ray and what the ray meets, written to a buffer of its own for just the frames that
//! ask, and read back beside the pixels. A batch where none asks writes and reads none.
//!
//! One [`GpuRenderer`] owns its device, pipeline and buffers; buffers grow when a batch needs more
//! room and are reused otherwise.

use super::error::RenderError;
use super::noise::{FrameNoise, gauss_table};
use super::scene::{SCENE_LISTS, Scene, SceneGlobals};
use super::trace::Code;
use crate::optics::Optics;
use crate::optics::calibrated::{CalibratedCamera, MAX_POLYNOMIAL};
use crate::sensor::Sensor;
use bytemuck::{Pod, Zeroable};
use nalgebra::Isometry2;
use omniloop_vision::camera_model::CameraFile;

/// The frames at `spans` (start, length) of `all`, each its own vector. A large batch's copies,
/// into fresh memory, cost ten times its tracing on one core, so they are shared among threads
/// of their own: not rayon's, whose workers may all be waiting on this very batch (runs stepped
/// in parallel that share the GPU).
fn copy_frames(all: &[u32], spans: &[(usize, usize)]) -> Vec<Vec<u32>> {
    let copy = |s: &[(usize, usize)]| -> Vec<Vec<u32>> {
        s.iter().map(|&(at, n)| all[at..at + n].to_vec()).collect()
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    if spans.len() < 2 * threads {
        return copy(spans);
    }
    let per = spans.len().div_ceil(threads);
    std::thread::scope(|scope| {
        let parts: Vec<_> = spans
            .chunks(per)
            .map(|part| scope.spawn(move || copy(part)))
            .collect();
        parts
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// The sensor and pose of one frame, as the shader reads them; `size` is the image's width and
/// height, the optics' kind and where the frame's truth starts (0: no truth, else one more than
/// its first pixel in the truth buffer).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct SensorParams {
    size: [u32; 4],
    intr: [f32; 4],
    p0: [f32; 4],
    p1: [f32; 4],
    p2: [f32; 4],
    /// A calibrated camera's image circle, principal point and polynomial length.
    p3: [f32; 4],
    /// A calibrated camera's intrinsics.
    model: [[f32; 4]; 3],
    mount: [f32; 4],
    pose: [f32; 4],
}

impl SensorParams {
    fn new(s: &Sensor, pose: &Isometry2<f64>, sigma: f32) -> Self {
        let OpticsSlots {
            kind,
            focal,
            p: [p0, p1, p2, p3],
            model,
        } = OpticsSlots::of(s);
        let theta = pose.rotation.angle();
        Self {
            size: [s.width_px, s.height_px, kind, 0],
            intr: [s.cx_px as f32, s.cy_px as f32, focal as f32, sigma],
            p0,
            p1,
            p2,
            p3,
            model,
            mount: [s.mount_mm[0] as f32, s.mount_mm[1] as f32, 0.0, 0.0],
            pose: [
                pose.translation.x as f32,
                pose.translation.y as f32,
                theta.cos() as f32,
                theta.sin() as f32,
            ],
        }
    }
}

/// A sensor's optics in the slots `trace.wgsl` reads: its kind, focal length (px), four
/// parameter rows and the intrinsics' (or a tilted mirror's) rows.
struct OpticsSlots {
    kind: u32,
    focal: f64,
    p: [[f32; 4]; 4],
    model: [[f32; 4]; 3],
}

impl OpticsSlots {
    fn of(s: &Sensor) -> Self {
        let mut p1 = [0.0f32; 4];
        let mut p2 = [0.0f32; 4];
        let mut p3 = [0.0f32; 4];
        let mut model = [[0.0f32; 4]; 3];
        let p0;
        let (kind, focal) = match &s.optics {
            Optics::Hyperbolic(m) => {
                let c = m.focal_half_distance_mm();
                p0 = [
                    m.a_mm as f32,
                    m.b_mm as f32,
                    c as f32,
                    (m.focus_height_mm - c) as f32,
                ];
                p1[0] = m.rim_radius_mm as f32;
                (0u32, m.focal_px)
            }
            Optics::Conical(m) => {
                p0 = [
                    (m.apex_angle_deg.to_radians() / 2.0).tan() as f32,
                    m.tip_distance_mm as f32,
                    m.radius_mm as f32,
                    m.lens_height_mm as f32,
                ];
                (1, m.focal_px)
            }
            Optics::Spherical(m) => {
                p0 = [
                    m.radius_mm as f32,
                    m.camera_distance_mm as f32,
                    m.lens_height_mm as f32,
                    0.0,
                ];
                (2, m.focal_px)
            }
            Optics::Pinhole(c) => {
                let [f, r, u] = c.basis();
                p0 = [f.x as f32, f.y as f32, f.z as f32, c.height_mm as f32];
                p1 = [r.x as f32, r.y as f32, r.z as f32, 0.0];
                p2 = [u.x as f32, u.y as f32, u.z as f32, 0.0];
                (3, c.focal_px)
            }
            Optics::Calibrated(c) => {
                let r = c.rotation_matrix();
                let t = c.translation_mm;
                let row = |i: usize| [r[(i, 0)], r[(i, 1)], r[(i, 2)], t[i]].map(|v| v as f32);
                (p0, p1, p2) = (row(0), row(1), row(2));
                let (kind, values, principal) = calibrated_params(c);
                let [cu, cv] = principal;
                let circle = c.image_circle_px.unwrap_or(-1.0);
                p3 = [circle as f32, cu as f32, cv as f32, 0.0];
                if let Some(CameraFile::Ocam(m)) = c.model() {
                    p3[3] = m.pol.len() as f32;
                }
                for (k, v) in values.iter().enumerate() {
                    model[k / 4][k % 4] = *v as f32;
                }
                (kind, 0.0)
            }
        };
        Self {
            kind,
            focal,
            p: [p0, p1, p2, p3],
            model,
        }
        .mounted(s)
    }

    /// The slots of a mirror off its place: its frame in the fourth row (pivot, pinhole and
    /// frame heights, the flag) and the tilt's rows with the offset in the intrinsics' slots.
    fn mounted(mut self, s: &Sensor) -> Self {
        if let Some(frame) = s.optics.mirror_frame().filter(|_| !s.mounting.is_nominal()) {
            let r = s.mounting.rotation();
            let o = s.mounting.mirror_offset_mm;
            self.p[3] = [
                frame.pivot_mm as f32,
                frame.pinhole_mm as f32,
                frame.z0_mm as f32,
                1.0,
            ];
            for (i, row) in self.model.iter_mut().enumerate() {
                *row = [r[(i, 0)], r[(i, 1)], r[(i, 2)], o[i]].map(|v| v as f32);
            }
        }
        self
    }
}

/// A calibrated camera's kind in the shader (4 unified, 5 double sphere, 6 OCamCalib), its
/// intrinsics in the order `trace.wgsl` reads them, and its principal point; a camera whose
/// file was not read is kind 7, which traces black.
fn calibrated_params(c: &CalibratedCamera) -> (u32, Vec<f64>, [f64; 2]) {
    match c.model() {
        Some(CameraFile::Unified(m, _)) => {
            let [k1, k2, p1, p2] = m.distortion;
            let v = vec![
                m.focal_px[0],
                m.focal_px[1],
                m.skew_px,
                m.xi,
                k1,
                k2,
                p1,
                p2,
            ];
            (4, v, m.principal_px)
        }
        Some(CameraFile::DoubleSphere(m, _)) => {
            let v = vec![m.focal_px[0], m.focal_px[1], m.xi, m.alpha];
            (5, v, m.principal_px)
        }
        Some(CameraFile::Ocam(m)) => {
            let mut v = m.affine.to_vec();
            v.extend(m.pol.iter().take(MAX_POLYNOMIAL));
            (6, v, [m.center_rc[1], m.center_rc[0]])
        }
        None => (7, Vec::new(), [0.0; 2]),
    }
}

/// One frame's header in a batch (`Frame` of `trace.wgsl`); the noise's sigma rides in the
/// sensor's `intr.w`, its key in `offsets2.w`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct FrameParams {
    globals: SceneGlobals,
    sensor: SensorParams,
    /// The frame's first element of each scene list, at its row's `offset_word` of
    /// [`SCENE_LISTS`]; word 6 its first pixel, word 7 its noise's key (`offsets`, `offsets2`
    /// and `offsets3` of `trace.wgsl`).
    offsets: [u32; 12],
}

/// Offset word of a frame's first pixel.
const PIXEL_WORD: usize = 6;
/// Offset word of a frame's noise key.
const NOISE_KEY_WORD: usize = 7;

/// One frame to trace: the scene, the sensor, the robot's pose and the frame's noise.
#[derive(Debug, Clone, Copy)]
pub struct FrameRequest<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The sensor.
    pub sensor: &'a Sensor,
    /// The robot's pose.
    pub pose: &'a Isometry2<f64>,
    /// The frame's sensor noise, drawn by the shader as on the CPU (`None`: a clean frame).
    pub noise: Option<FrameNoise>,
}

/// Per pixel of a frame, the distance along its scene ray to what the ray meets (mm; infinity
/// for the sky, NaN where the pixel sees no mirror) and what that is (a [`Code`]), in the
/// convention of the CPU's [`trace_ray`](super::trace::trace_ray).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PixelTruth {
    /// The distance along each pixel's (unit) scene ray, mm.
    pub t: Vec<f32>,
    /// What each pixel's ray meets.
    pub codes: Vec<Code>,
}

impl PixelTruth {
    /// The truth of the shader's pairs (t's bits, code).
    fn of(pairs: &[[u32; 2]]) -> Self {
        Self {
            t: pairs.iter().map(|p| f32::from_bits(p[0])).collect(),
            codes: pairs.iter().map(|p| p[1]).collect(),
        }
    }
}

/// A frame traced: its packed RGBA8 pixels and, when it asked, its truth.
pub type TracedFrame = (Vec<u32>, Option<PixelTruth>);

/// The concatenated primitives and headers of a batch.
#[derive(Default)]
struct Batch {
    frames: Vec<FrameParams>,
    /// Every frame's scene lists, concatenated, one a row of [`SCENE_LISTS`], as bytes.
    lists: [Vec<u8>; SCENE_LISTS.len()],
    /// How many elements each of `lists` has.
    lengths: [usize; SCENE_LISTS.len()],
    pixels: usize,
    /// The pixels of the frames that ask for their truth.
    truth_pixels: usize,
}

impl Batch {
    /// The batch of `requests`, frame `i` with its truth when `truth[i]` (none past its end).
    fn of(requests: &[FrameRequest<'_>], truth: &[bool]) -> Result<Self, RenderError> {
        let mut b = Self::default();
        let at =
            |n: usize| u32::try_from(n).map_err(|_| RenderError::Device("batch too large".into()));
        for (i, r) in requests.iter().enumerate() {
            let sc = r.scene;
            let (key, sigma) = r.noise.map_or((0, 0.0), |n| (n.key, n.sigma));
            let n = (r.sensor.width_px * r.sensor.height_px) as usize;
            let mut sensor = SensorParams::new(r.sensor, r.pose, sigma);
            if truth.get(i).copied().unwrap_or(false) {
                sensor.size[3] = at(b.truth_pixels + 1)?;
                b.truth_pixels += n;
            }
            let mut offsets = [0; 12];
            for (k, row) in SCENE_LISTS.iter().enumerate() {
                let (bytes, len) = sc.list(row.list);
                offsets[row.offset_word] = at(b.lengths[k])?;
                b.lists[k].extend_from_slice(bytes);
                b.lengths[k] += len;
            }
            offsets[PIXEL_WORD] = at(b.pixels)?;
            offsets[NOISE_KEY_WORD] = key;
            b.frames.push(FrameParams {
                globals: sc.globals,
                sensor,
                offsets,
            });
            b.pixels += n;
        }
        at(b.pixels)?;
        at(b.truth_pixels)?;
        Ok(b)
    }
}

/// A storage buffer that grows to fit.
struct Storage {
    buffer: wgpu::Buffer,
    capacity: u64,
    label: &'static str,
}

impl Storage {
    fn new(
        device: &wgpu::Device,
        label: &'static str,
        capacity: u64,
        usage: wgpu::BufferUsages,
    ) -> Self {
        let capacity = capacity.max(16);
        Self {
            buffer: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: capacity,
                usage,
                mapped_at_creation: false,
            }),
            capacity,
            label,
        }
    }

    /// Writes `bytes`, growing the buffer first when needed; returns whether it was replaced.
    fn write(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, bytes: &[u8]) -> bool {
        let mut grown = false;
        if bytes.len() as u64 > self.capacity {
            *self = Self::new(
                device,
                self.label,
                (bytes.len() as u64).next_power_of_two(),
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            );
            grown = true;
        }
        if !bytes.is_empty() {
            queue.write_buffer(&self.buffer, 0, bytes);
        }
        grown
    }
}

/// A buffer the shader writes and its twin the host maps to read it back, grown together to
/// fit.
struct Output {
    buffer: wgpu::Buffer,
    readback: wgpu::Buffer,
    capacity: u64,
    label: &'static str,
}

impl Output {
    fn new(device: &wgpu::Device, label: &'static str, capacity: u64) -> Self {
        let capacity = capacity.max(16);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: capacity,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            readback,
            capacity,
            label,
        }
    }

    /// Makes room for `bytes`, replacing both buffers when too small; returns whether it did.
    fn fit(&mut self, device: &wgpu::Device, bytes: u64) -> bool {
        if bytes <= self.capacity {
            return false;
        }
        *self = Self::new(device, self.label, bytes.next_power_of_two());
        true
    }

    /// Copies the first `bytes` the shader wrote to the readback buffer (none: nothing).
    fn copy(&self, encoder: &mut wgpu::CommandEncoder, bytes: u64) {
        if bytes > 0 {
            encoder.copy_buffer_to_buffer(&self.buffer, 0, &self.readback, 0, Some(bytes));
        }
    }
}

/// Asks for the first `bytes` of `buffer` mapped for reading; the receiver says when they are.
fn map_read(
    buffer: &wgpu::Buffer,
    bytes: u64,
) -> std::sync::mpsc::Receiver<Result<(), wgpu::BufferAsyncError>> {
    let (tx, rx) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..bytes, move |r| {
        let _ = tx.send(r);
    });
    rx
}

/// Renders frames with a wgpu compute shader.
pub struct GpuRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    adapter_name: String,
    frames: Storage,
    /// The scene lists' buffers, one a row of [`SCENE_LISTS`].
    lists: [Storage; SCENE_LISTS.len()],
    /// The noise's Gaussian table, written once.
    gauss: wgpu::Buffer,
    /// The frames' packed RGBA8 pixels.
    pixels: Output,
    /// The truth of the frames that ask for it: per pixel t's bits and the code (16 bytes
    /// until a frame asks).
    truth: Output,
    bind_group: Option<wgpu::BindGroup>,
}

/// `trace.wgsl` after the declarations laid out from [`SCENE_LISTS`]: each list's binding
/// (`boxes`, ...) and the offset word of its first element in a frame (`FIRST_BOXES`, ...).
fn shader_source() -> String {
    let mut text = String::from("// Laid out from SCENE_LISTS (sim/src/render/scene.rs).\n");
    for row in SCENE_LISTS {
        let (name, ty) = (row.list.name(), row.list.wgsl_type());
        text += &format!(
            "@group(0) @binding({}) var<storage, read> {name}: array<{ty}>;\n",
            row.binding
        );
        let first = format!("FIRST_{}", name.to_uppercase());
        text += &format!("const {first}: u32 = {}u;\n", row.offset_word);
    }
    text += &format!(
        "const FIRST_PIXEL: u32 = {PIXEL_WORD}u;\nconst NOISE_KEY: u32 = {NOISE_KEY_WORD}u;\n"
    );
    text + include_str!("trace.wgsl")
}

/// The bindings of `trace.wgsl` that are not scene lists ([`SCENE_LISTS`] has theirs).
const FRAMES_BINDING: u32 = 0;
const PIXELS_BINDING: u32 = 7;
const GAUSS_BINDING: u32 = 9;
const TRUTH_BINDING: u32 = 10;

const STORAGE_RW: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST);

fn entry(binding: u32, ty: wgpu::BufferBindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl GpuRenderer {
    /// Opens the first adapter wgpu offers (hardware or a software driver such as lavapipe).
    pub fn new() -> Result<Self, RenderError> {
        Self::with_adapter(Self::adapter()?)
    }

    /// The first adapter when it is a hardware GPU; `None` when there is none or only a
    /// software rasterizer.
    pub fn hardware() -> Result<Option<Self>, RenderError> {
        match Self::adapter() {
            Ok(a) if a.get_info().device_type != wgpu::DeviceType::Cpu => {
                Self::with_adapter(a).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// The adapter wgpu offers first, preferring high performance.
    pub fn adapter() -> Result<wgpu::Adapter, RenderError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.flags = wgpu::InstanceFlags::empty();
        let instance = wgpu::Instance::new(desc.with_env());
        pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| RenderError::NoAdapter(e.to_string()))
    }

    /// Opens `adapter`: device, shader and buffers.
    pub fn with_adapter(adapter: wgpu::Adapter) -> Result<Self, RenderError> {
        let info = adapter.get_info();
        let adapter_name = format!("{} ({:?})", info.name, info.backend);
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("omniloop"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device(e.to_string()))?;
        let (pipeline, layout) = Self::trace_pipeline(&device);
        let frames = Storage::new(
            &device,
            "frames",
            std::mem::size_of::<FrameParams>() as u64,
            STORAGE_RW,
        );
        let lists = SCENE_LISTS.map(|row| {
            let bytes = row.initial_room * row.list.element_bytes() as u64;
            Storage::new(&device, row.list.name(), bytes, STORAGE_RW)
        });
        let table: &[u8] = bytemuck::cast_slice(gauss_table());
        let gauss = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gauss"),
            size: table.len() as u64,
            usage: STORAGE_RW,
            mapped_at_creation: false,
        });
        queue.write_buffer(&gauss, 0, table);
        let pixels = Output::new(&device, "pixels", 256 * 256 * 4);
        let truth = Output::new(&device, "truth", 0);
        Ok(Self {
            device,
            queue,
            pipeline,
            layout,
            adapter_name,
            frames,
            lists,
            gauss,
            pixels,
            truth,
            bind_group: None,
        })
    }

    /// The compute pipeline of `trace.wgsl` and the layout of its bindings.
    fn trace_pipeline(device: &wgpu::Device) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("trace.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        use wgpu::BufferBindingType as B;
        let ro = B::Storage { read_only: true };
        let rw = B::Storage { read_only: false };
        let mut entries = vec![
            entry(FRAMES_BINDING, ro),
            entry(PIXELS_BINDING, rw),
            entry(GAUSS_BINDING, ro),
            entry(TRUTH_BINDING, rw),
        ];
        entries.extend(SCENE_LISTS.iter().map(|row| entry(row.binding, ro)));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace"),
            entries: &entries,
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("trace"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("trace"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        (pipeline, layout)
    }

    /// Name and backend of the adapter.
    pub fn adapter_name(&self) -> &str {
        &self.adapter_name
    }

    /// Renders one frame with `noise` (none: clean) into `out` (packed RGBA8, `width *
    /// height` pixels).
    pub fn render(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
        noise: Option<FrameNoise>,
        out: &mut [u32],
    ) -> Result<(), RenderError> {
        let n = (sensor.width_px * sensor.height_px) as usize;
        assert_eq!(out.len(), n);
        let request = FrameRequest {
            scene,
            sensor,
            pose,
            noise,
        };
        self.trace(&[request], &[], |all, _| out.copy_from_slice(all))
    }

    /// Renders one frame as [`GpuRenderer::render`] does (the same pixels) with each pixel's
    /// truth: the distance along its scene ray to what it meets into `t` (mm; infinity for the
    /// sky, NaN where the pixel sees no mirror) and what that is into `codes` ([`Code`]), as
    /// the CPU's [`trace_ray`](super::trace::trace_ray) gives them.
    pub fn render_truth(
        &mut self,
        request: FrameRequest<'_>,
        out: &mut [u32],
        t: &mut [f32],
        codes: &mut [Code],
    ) -> Result<(), RenderError> {
        let n = (request.sensor.width_px * request.sensor.height_px) as usize;
        assert!(out.len() == n && t.len() == n && codes.len() == n);
        self.trace(&[request], &[true], |all, truth| {
            out.copy_from_slice(all);
            for ((tk, ck), p) in t.iter_mut().zip(codes.iter_mut()).zip(truth) {
                (*tk, *ck) = (f32::from_bits(p[0]), p[1]);
            }
        })
    }

    /// Renders every frame of `requests` in one dispatch with one readback: each image packed
    /// RGBA8, `width * height` pixels, in the order asked.
    pub fn render_batch(
        &mut self,
        requests: &[FrameRequest<'_>],
    ) -> Result<Vec<Vec<u32>>, RenderError> {
        let frames = self.render_batch_truth(requests, &[])?;
        Ok(frames.into_iter().map(|(pixels, _)| pixels).collect())
    }

    /// [`GpuRenderer::render_batch`] with the truth of frame `i` when `truth[i]` (none past
    /// its end): the frames' pixels are the same, and those that ask get their truth too.
    pub fn render_batch_truth(
        &mut self,
        requests: &[FrameRequest<'_>],
        truth: &[bool],
    ) -> Result<Vec<TracedFrame>, RenderError> {
        if requests.is_empty() {
            return Ok(Vec::new());
        }
        let asks = |i: usize| truth.get(i).copied().unwrap_or(false);
        // Each frame's place in the readback.
        let spans: Vec<(usize, usize)> = requests
            .iter()
            .scan(0, |at, r| {
                let n = (r.sensor.width_px * r.sensor.height_px) as usize;
                *at += n;
                Some((*at - n, n))
            })
            .collect();
        let mut out = Vec::new();
        self.trace(requests, truth, |all, pairs| {
            let mut at = 0;
            out = (copy_frames(all, &spans).into_iter().enumerate())
                .map(|(i, pixels)| {
                    let truth = asks(i).then(|| {
                        at += pixels.len();
                        PixelTruth::of(&pairs[at - pixels.len()..at])
                    });
                    (pixels, truth)
                })
                .collect();
        })?;
        Ok(out)
    }

    /// Traces `requests` (not empty) in one dispatch, frame `i` with its truth when `truth[i]`,
    /// and hands `take` their pixels, frame after frame, and the truth of those that asked
    /// (t's bits, code), straight from the mapped readback buffers.
    fn trace(
        &mut self,
        requests: &[FrameRequest<'_>],
        truth: &[bool],
        take: impl FnOnce(&[u32], &[[u32; 2]]),
    ) -> Result<(), RenderError> {
        let batch = Batch::of(requests, truth)?;
        let bytes = (batch.pixels * 4) as u64;
        let truth_bytes = (batch.truth_pixels * 8) as u64;
        let mut rebind = self.upload(&batch, bytes, truth_bytes);
        rebind |= self.bind_group.is_none();
        if rebind {
            self.rebind();
        }
        let max_w = requests
            .iter()
            .map(|r| r.sensor.width_px)
            .max()
            .unwrap_or(1);
        let max_h = requests
            .iter()
            .map(|r| r.sensor.height_px)
            .max()
            .unwrap_or(1);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("batch"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, self.bind_group.as_ref(), &[]);
            pass.dispatch_workgroups(max_w.div_ceil(8), max_h.div_ceil(8), requests.len() as u32);
        }
        self.pixels.copy(&mut encoder, bytes);
        self.truth.copy(&mut encoder, truth_bytes);
        self.queue.submit([encoder.finish()]);
        self.read_back(bytes, truth_bytes, take)
    }

    /// Writes the batch's buffers, growing those too small (the outputs to `pixel_bytes` and
    /// `truth_bytes`); returns whether any was replaced.
    fn upload(&mut self, b: &Batch, pixel_bytes: u64, truth_bytes: u64) -> bool {
        let mut rebind = self.pixels.fit(&self.device, pixel_bytes);
        rebind |= self.truth.fit(&self.device, truth_bytes);
        let (d, q) = (&self.device, &self.queue);
        rebind |= self.frames.write(d, q, bytemuck::cast_slice(&b.frames));
        for (buffer, bytes) in self.lists.iter_mut().zip(&b.lists) {
            rebind |= buffer.write(d, q, bytes);
        }
        rebind
    }

    /// A new bind group over the current buffers.
    fn rebind(&mut self) {
        let mut buffers = vec![
            (FRAMES_BINDING, &self.frames.buffer),
            (PIXELS_BINDING, &self.pixels.buffer),
            (GAUSS_BINDING, &self.gauss),
            (TRUTH_BINDING, &self.truth.buffer),
        ];
        let lists = SCENE_LISTS.iter().zip(&self.lists);
        buffers.extend(lists.map(|(row, storage)| (row.binding, &storage.buffer)));
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: *i,
                resource: b.as_entire_binding(),
            })
            .collect();
        self.bind_group = Some(self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("trace"),
            layout: &self.layout,
            entries: &entries,
        }));
    }

    /// Maps the first `bytes` of the pixels' readback buffer and the first `truth_bytes` of
    /// the truth's (none: not mapped) and hands them to `take`.
    fn read_back(
        &mut self,
        bytes: u64,
        truth_bytes: u64,
        take: impl FnOnce(&[u32], &[[u32; 2]]),
    ) -> Result<(), RenderError> {
        let device_error = |e: &dyn std::fmt::Display| RenderError::Device(e.to_string());
        let pixels = map_read(&self.pixels.readback, bytes);
        let truth = (truth_bytes > 0).then(|| map_read(&self.truth.readback, truth_bytes));
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| device_error(&e))?;
        for rx in std::iter::once(pixels).chain(truth) {
            rx.recv()
                .map_err(|e| device_error(&e))?
                .map_err(|e| device_error(&e))?;
        }
        {
            let view =
                (self.pixels.readback.get_mapped_range(0..bytes)).map_err(|e| device_error(&e))?;
            let truth_view = (truth_bytes > 0)
                .then(|| self.truth.readback.get_mapped_range(0..truth_bytes))
                .transpose()
                .map_err(|e| device_error(&e))?;
            let pairs = truth_view
                .as_deref()
                .map_or(&[][..], |v| bytemuck::cast_slice::<u8, [u32; 2]>(v));
            take(bytemuck::cast_slice::<u8, u32>(&view), pairs);
        }
        self.pixels.readback.unmap();
        if truth_bytes > 0 {
            self.truth.readback.unmap();
        }
        Ok(())
    }
}
