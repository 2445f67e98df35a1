//! The wgpu compute renderer: `trace.wgsl` traces every pixel of a frame; the scene and the
//! sensor are storage and uniform buffers; the image is read back as packed RGBA8.
//!
//! One [`GpuRenderer`] owns its device, pipeline and buffers; buffers grow when a scene or an
//! image needs more room and are reused otherwise.

use super::RenderError;
use super::scene::{BoardPrim, BoxPrim, CylinderPrim, FloorRectPrim, QuadPrim, Scene};
use crate::optics::Optics;
use crate::sensor::Sensor;
use bytemuck::{Pod, Zeroable};
use nalgebra::Isometry2;

/// The sensor and pose of one frame, as the shader reads them.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct SensorParams {
    size: [u32; 4],
    intr: [f32; 4],
    p0: [f32; 4],
    p1: [f32; 4],
    p2: [f32; 4],
    mount: [f32; 4],
    pose: [f32; 4],
}

impl SensorParams {
    fn new(s: &Sensor, pose: &Isometry2<f64>) -> Self {
        let mut p1 = [0.0f32; 4];
        let mut p2 = [0.0f32; 4];
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
        };
        let theta = pose.rotation.angle();
        Self {
            size: [s.width_px, s.height_px, kind, 0],
            intr: [s.cx_px as f32, s.cy_px as f32, focal as f32, 0.0],
            p0,
            p1,
            p2,
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

/// Renders frames with a wgpu compute shader.
pub struct GpuRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    adapter_name: String,
    globals: wgpu::Buffer,
    sensor: wgpu::Buffer,
    boxes: Storage,
    cylinders: Storage,
    boards: Storage,
    stripes: Storage,
    rects: Storage,
    quads: Storage,
    pixels: wgpu::Buffer,
    readback: wgpu::Buffer,
    pixel_capacity: u64,
    bind_group: Option<wgpu::BindGroup>,
}

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
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("trace.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("trace.wgsl").into()),
        });
        use wgpu::BufferBindingType as B;
        let ro = B::Storage { read_only: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("trace"),
            entries: &[
                entry(0, B::Uniform),
                entry(1, B::Uniform),
                entry(2, ro),
                entry(3, ro),
                entry(4, ro),
                entry(5, ro),
                entry(6, ro),
                entry(7, B::Storage { read_only: false }),
                entry(8, ro),
            ],
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
        let uniform = |label, size| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let globals = uniform(
            "globals",
            std::mem::size_of::<super::scene::SceneGlobals>() as u64,
        );
        let sensor = uniform("sensor", std::mem::size_of::<SensorParams>() as u64);
        let boxes = Storage::new(&device, "boxes", 64 * 48, STORAGE_RW);
        let cylinders = Storage::new(&device, "cylinders", 16 * 32, STORAGE_RW);
        let boards = Storage::new(&device, "boards", 4 * 48, STORAGE_RW);
        let stripes = Storage::new(&device, "stripes", 64 * 4, STORAGE_RW);
        let rects = Storage::new(&device, "rects", 8 * 48, STORAGE_RW);
        let quads = Storage::new(&device, "quads", 16 * 64, STORAGE_RW);
        let (pixels, readback) = Self::pixel_buffers(&device, 256 * 256 * 4);
        Ok(Self {
            device,
            queue,
            pipeline,
            layout,
            adapter_name,
            globals,
            sensor,
            boxes,
            cylinders,
            boards,
            stripes,
            rects,
            quads,
            pixels,
            readback,
            pixel_capacity: 256 * 256 * 4,
            bind_group: None,
        })
    }

    fn pixel_buffers(device: &wgpu::Device, bytes: u64) -> (wgpu::Buffer, wgpu::Buffer) {
        let pixels = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pixels"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (pixels, readback)
    }

    /// Name and backend of the adapter.
    pub fn adapter_name(&self) -> &str {
        &self.adapter_name
    }

    /// Renders one frame into `out` (packed RGBA8, `width * height` pixels).
    pub fn render(
        &mut self,
        scene: &Scene,
        sensor: &Sensor,
        pose: &Isometry2<f64>,
        out: &mut [u32],
    ) -> Result<(), RenderError> {
        let n = (sensor.width_px * sensor.height_px) as usize;
        assert_eq!(out.len(), n);
        let bytes = (n * 4) as u64;
        let mut rebind = self.bind_group.is_none();
        if bytes > self.pixel_capacity {
            let cap = bytes.next_power_of_two();
            (self.pixels, self.readback) = Self::pixel_buffers(&self.device, cap);
            self.pixel_capacity = cap;
            rebind = true;
        }
        let (d, q) = (&self.device, &self.queue);
        q.write_buffer(&self.globals, 0, bytemuck::bytes_of(&scene.globals));
        q.write_buffer(
            &self.sensor,
            0,
            bytemuck::bytes_of(&SensorParams::new(sensor, pose)),
        );
        rebind |= self
            .boxes
            .write(d, q, bytemuck::cast_slice::<BoxPrim, u8>(&scene.boxes));
        rebind |= self.cylinders.write(
            d,
            q,
            bytemuck::cast_slice::<CylinderPrim, u8>(&scene.cylinders),
        );
        rebind |= self
            .boards
            .write(d, q, bytemuck::cast_slice::<BoardPrim, u8>(&scene.boards));
        rebind |= self
            .stripes
            .write(d, q, bytemuck::cast_slice::<f32, u8>(&scene.stripe_edges));
        rebind |= self.rects.write(
            d,
            q,
            bytemuck::cast_slice::<FloorRectPrim, u8>(&scene.floor_rects),
        );
        rebind |= self
            .quads
            .write(d, q, bytemuck::cast_slice::<QuadPrim, u8>(&scene.quads));
        if rebind {
            let buffers = [
                &self.globals,
                &self.sensor,
                &self.boxes.buffer,
                &self.cylinders.buffer,
                &self.boards.buffer,
                &self.stripes.buffer,
                &self.rects.buffer,
                &self.pixels,
                &self.quads.buffer,
            ];
            let entries: Vec<wgpu::BindGroupEntry> = buffers
                .iter()
                .enumerate()
                .map(|(i, b)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: b.as_entire_binding(),
                })
                .collect();
            self.bind_group = Some(self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("trace"),
                layout: &self.layout,
                entries: &entries,
            }));
        }
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("frame"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, self.bind_group.as_ref(), &[]);
            pass.dispatch_workgroups(sensor.width_px.div_ceil(8), sensor.height_px.div_ceil(8), 1);
        }
        encoder.copy_buffer_to_buffer(&self.pixels, 0, &self.readback, 0, Some(bytes));
        self.queue.submit([encoder.finish()]);
        let slice = self.readback.slice(0..bytes);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Device(e.to_string()))?;
        rx.recv()
            .map_err(|e| RenderError::Device(e.to_string()))?
            .map_err(|e| RenderError::Device(e.to_string()))?;
        {
            let view = slice
                .get_mapped_range()
                .map_err(|e| RenderError::Device(e.to_string()))?;
            out.copy_from_slice(bytemuck::cast_slice(&view));
        }
        self.readback.unmap();
        Ok(())
    }
}
