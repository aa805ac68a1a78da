//! Offscreen rendering: the same renderer into a texture, read back as RGBA pixels and
//! written as PNG. Used by `slidebase render` and the render tests.

use std::path::Path;

use super::{Renderer, SceneView};
use crate::{Error, Result};

/// What to tell a user whose machine has no graphics adapter.
pub const NO_ADAPTER_HELP: &str = "no graphics adapter found; on a machine without a GPU install Mesa's \
    software drivers (Debian/Ubuntu: apt install mesa-vulkan-drivers libvulkan1 libegl-mesa0) and try again";

/// A device for offscreen work.
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name and backend, for reports.
    pub adapter_info: String,
}

impl Gpu {
    /// Finds an adapter (any, including Mesa's CPU ones) and opens a device.
    pub fn new() -> Result<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::default(),
            force_fallback_adapter: false,
            compatible_surface: None,
            ..Default::default()
        }))
        .map_err(|e| Error::Platform(format!("{NO_ADAPTER_HELP} ({e})")))?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("slidebase offscreen"),
            required_limits:
                wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| Error::Solver {
            time: 0.0,
            reason: format!("cannot open the graphics device: {e}"),
        })?;
        Ok(Self {
            device,
            queue,
            adapter_info: format!("{} ({:?})", info.name, info.backend),
        })
    }
}

/// The format offscreen images are rendered in (sRGB, so colours match a window's).
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// Renders a view into an RGBA image of `width × height` pixels (row-major, top row first).
pub fn render_rgba(
    gpu: &Gpu,
    renderer: &mut Renderer,
    view: &SceneView<'_>,
    width: u32,
    height: u32,
) -> Result<Vec<u8>> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(Error::invalid(
            "image size",
            format!("{width}×{height} is outside 1…8192 pixels"),
        ));
    }
    let device = &gpu.device;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("slidebase offscreen"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let target = texture.create_view(&wgpu::TextureViewDescriptor::default());
    renderer.resize(width, height);
    renderer.prepare(device, &gpu.queue, view);
    let padded_row = (width * 4).div_ceil(256) * 256;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("slidebase readback"),
        size: u64::from(padded_row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("slidebase offscreen"),
    });
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("slidebase offscreen"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::WHITE),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        renderer.draw(&mut pass);
    }
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit(Some(encoder.finish()));
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| Error::Solver {
            time: 0.0,
            reason: format!("the GPU did not finish: {e}"),
        })?;
    rx.recv()
        .map_err(|_| Error::Solver {
            time: 0.0,
            reason: "the GPU read-back was dropped".into(),
        })?
        .map_err(|e| Error::Solver {
            time: 0.0,
            reason: format!("cannot read the image back: {e}"),
        })?;
    let data = slice.get_mapped_range().map_err(|e| Error::Solver {
        time: 0.0,
        reason: format!("cannot read the image back: {e}"),
    })?;
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for row in 0..height as usize {
        let start = row * padded_row as usize;
        pixels.extend_from_slice(&data[start..start + (width * 4) as usize]);
    }
    Ok(pixels)
}

/// Writes RGBA pixels as a PNG file.
pub fn write_png(path: &Path, pixels: &[u8], width: u32, height: u32) -> Result<()> {
    let file = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder
        .write_header()
        .map_err(|e| Error::Scene(format!("{}: {e}", path.display())))?;
    writer
        .write_image_data(pixels)
        .map_err(|e| Error::Scene(format!("{}: {e}", path.display())))?;
    writer
        .finish()
        .map_err(|e| Error::Scene(format!("{}: {e}", path.display())))
}

/// Options of a rendered picture.
#[derive(Debug, Clone, Copy)]
pub struct PictureOptions {
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Deformation exaggeration.
    pub exaggeration: f32,
    /// Block colouring.
    pub color_by: super::ColorBy,
    /// Layers.
    pub layers: super::Layers,
}

impl Default for PictureOptions {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
            exaggeration: 50.0,
            color_by: super::ColorBy::Strain,
            layers: super::Layers::default(),
        }
    }
}

/// The world window that frames a model: the structure's width with a margin, from a
/// little below the ground to above the roof.
pub fn world_window(frame: &crate::sim::ModelFrame) -> [f32; 3] {
    let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
    for b in frame.blocks.iter().filter(|b| !b.is_ground) {
        for v in &b.vertices {
            for d in 0..2 {
                lo[d] = lo[d].min(v[d]);
                hi[d] = hi[d].max(v[d]);
            }
        }
    }
    if !lo[0].is_finite() {
        return [5.0, -1.0, 5.0];
    }
    let size = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1.0);
    [
        0.5 * (hi[0] - lo[0]) + 0.25 * size,
        lo[1] - 0.12 * size,
        hi[1] + 0.12 * size,
    ]
}

/// Whether panels are stacked one above the other (a tall area) rather than side by side.
pub fn stack_vertically(width: f32, height: f32, panels: usize) -> bool {
    panels > 1 && height > 0.8 * width
}

/// Lays out models side by side (or stacked, in a tall area) in `width × height` pixels.
pub fn side_by_side<'a>(
    frames: &'a [crate::sim::ModelFrame],
    windows: &[[f32; 3]],
    slip_ranges: &[[f32; 2]],
    width: u32,
    height: u32,
) -> Vec<super::PanelView<'a>> {
    let n = frames.len().max(1) as f32;
    let stacked = stack_vertically(width as f32, height as f32, frames.len());
    let (w, h) = if stacked {
        (width as f32, height as f32 / n)
    } else {
        (width as f32 / n, height as f32)
    };
    frames
        .iter()
        .enumerate()
        .map(|(k, frame)| super::PanelView {
            frame,
            rect: if stacked {
                [0.0, k as f32 * h, w, h]
            } else {
                [k as f32 * w, 0.0, w, h]
            },
            window: windows
                .get(k)
                .copied()
                .unwrap_or_else(|| world_window(frame)),
            slip_range: slip_ranges.get(k).copied().unwrap_or([0.0, 0.0]),
        })
        .collect()
}

/// What `render_run_png` drew.
#[derive(Debug, Clone)]
pub struct PictureInfo {
    /// The adapter used.
    pub adapter: String,
    /// Simulated time shown, s.
    pub time: f64,
    /// Largest colour measure (the top of the scale).
    pub color_max: f32,
    /// Wall-clock time of the simulation, s.
    pub simulate_s: f64,
    /// Wall-clock time of rendering and writing, s.
    pub render_s: f64,
}

/// Runs a configuration to `time` and renders its models side by side into a PNG.
pub fn render_run_png(
    config: &crate::sim::SimConfig,
    time: f64,
    options: &PictureOptions,
    path: &Path,
) -> Result<PictureInfo> {
    crate::error::require_non_negative("--time", time)?;
    // The run is checked (and set up) before the graphics adapter is looked for, so that
    // a bad flag is reported as such on any machine.
    let t0 = std::time::Instant::now();
    let mut run = crate::sim::prepare(config)?;
    let prepared = t0.elapsed();
    let gpu = Gpu::new()?;
    let t0 = std::time::Instant::now() - prepared;
    let time = time.min(run.duration);
    let windows: Vec<[f32; 3]> = run
        .models
        .iter()
        .map(|(d, ex)| world_window(&ex.extract(d, Some(&run.motion))))
        .collect();
    let mut ranges = vec![[0.0f32, 0.0]; run.models.len()];
    let motion = run.motion.clone();
    for (k, (dda, ex)) in run.models.iter_mut().enumerate() {
        let base_slip = |d: &crate::dda::Dda| ex.extract(d, Some(&motion)).probes.slip as f32;
        let mut range = [0.0f32, 0.0];
        let mut counter = 0usize;
        dda.run_until(time, |d, _| {
            counter += 1;
            if counter.is_multiple_of(10) {
                let s = base_slip(d);
                range = [range[0].min(s), range[1].max(s)];
            }
        })?;
        ranges[k] = range;
    }
    let frames: Vec<crate::sim::ModelFrame> = run
        .models
        .iter()
        .map(|(d, ex)| ex.extract(d, Some(&run.motion)))
        .collect();
    let simulate_s = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let color_max = frames
        .iter()
        .flat_map(|f| f.blocks.iter().filter(|b| !b.is_ground))
        .map(|b| super::geometry::color_measure(options.color_by, &b.stress, &b.strain))
        .fold(f32::MIN_POSITIVE, f32::max);
    let view = SceneView {
        panels: side_by_side(&frames, &windows, &ranges, options.width, options.height),
        exaggeration: options.exaggeration,
        color_by: options.color_by,
        color_max,
        layers: options.layers,
    };
    let mut renderer = Renderer::new(&gpu.device, FORMAT);
    let pixels = render_rgba(&gpu, &mut renderer, &view, options.width, options.height)?;
    write_png(path, &pixels, options.width, options.height)?;
    Ok(PictureInfo {
        adapter: gpu.adapter_info,
        time,
        color_max,
        simulate_s,
        render_s: t1.elapsed().as_secs_f64(),
    })
}
