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

fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(Error::invalid(
            "image size",
            format!("{width}×{height} is outside 1…8192 pixels"),
        ));
    }
    Ok(())
}

fn gpu_error(what: &str, e: impl std::fmt::Display) -> Error {
    Error::Solver {
        time: 0.0,
        reason: format!("{what}: {e}"),
    }
}

/// Renders a view into an RGBA image of `width × height` pixels (row-major, top row first).
pub fn render_rgba(
    gpu: &Gpu,
    renderer: &mut Renderer,
    view: &SceneView<'_>,
    width: u32,
    height: u32,
) -> Result<Vec<u8>> {
    check_size(width, height)?;
    renderer.resize(width, height);
    renderer.prepare(&gpu.device, &gpu.queue, view);
    render_target(gpu, width, height, |_, pass| renderer.draw(pass))
}

/// Creates a target texture, lets `draw` record into a render pass on it (after its own
/// preparation on the encoder), and reads the pixels back.
fn render_target(
    gpu: &Gpu,
    width: u32,
    height: u32,
    draw: impl FnOnce(&mut wgpu::CommandEncoder, &mut wgpu::RenderPass<'static>),
) -> Result<Vec<u8>> {
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
    let mut prep = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("slidebase offscreen uploads"),
    });
    {
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
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
        let mut pass = pass.forget_lifetime();
        draw(&mut prep, &mut pass);
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
    gpu.queue.submit([prep.finish(), encoder.finish()]);
    let slice = buffer.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| gpu_error("the GPU did not finish", e))?;
    rx.recv()
        .map_err(|e| gpu_error("the GPU read-back was dropped", e))?
        .map_err(|e| gpu_error("cannot read the image back", e))?;
    let data = slice
        .get_mapped_range()
        .map_err(|e| gpu_error("cannot read the image back", e))?;
    let mut pixels = Vec::with_capacity((width * height * 4) as usize);
    for row in 0..height as usize {
        let start = row * padded_row as usize;
        pixels.extend_from_slice(&data[start..start + (width * 4) as usize]);
    }
    Ok(pixels)
}

/// Renders egui UIs — with the scene drawn in them through the [`Renderer`]'s paint
/// callback, as in the window — into RGBA images. Used for pictures and video frames with
/// titles, legends and scales; keeps its fonts and pipelines between frames.
pub struct OffscreenUi<'g> {
    gpu: &'g Gpu,
    ctx: egui::Context,
    renderer: egui_wgpu::Renderer,
}

impl<'g> OffscreenUi<'g> {
    /// Prepares egui (light theme) and the renderers on `gpu`.
    pub fn new(gpu: &'g Gpu) -> Self {
        let ctx = egui::Context::default();
        ctx.set_visuals(egui::Visuals::light());
        let mut renderer =
            egui_wgpu::Renderer::new(&gpu.device, FORMAT, egui_wgpu::RendererOptions::default());
        renderer
            .callback_resources
            .insert(Renderer::new(&gpu.device, FORMAT));
        Self { gpu, ctx, renderer }
    }

    /// Draws `build` into an RGBA image of `width × height` pixels (one point per pixel).
    pub fn render(
        &mut self,
        width: u32,
        height: u32,
        mut build: impl FnMut(&mut egui::Ui),
    ) -> Result<Vec<u8>> {
        check_size(width, height)?;
        let size = egui::vec2(width as f32, height as f32);
        let input = || {
            let mut input = egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, size)),
                ..Default::default()
            };
            input
                .viewports
                .entry(egui::ViewportId::ROOT)
                .or_default()
                .native_pixels_per_point = Some(1.0);
            input
        };
        // Two passes: the first lays text out (and loads the fonts); the second is drawn.
        let mut deltas = Vec::new();
        for _ in 0..2 {
            let mut output = self.ctx.run_ui(input(), |ui| {
                egui::CentralPanel::default()
                    .frame(egui::Frame::NONE)
                    .show(ui, &mut build);
            });
            deltas.push(std::mem::take(&mut output.textures_delta));
            if deltas.len() == 2 {
                let jobs = self.ctx.tessellate(output.shapes, output.pixels_per_point);
                for delta in &deltas {
                    for (id, ds) in &delta.set {
                        for d in ds {
                            self.renderer
                                .update_texture(&self.gpu.device, &self.gpu.queue, *id, d);
                        }
                    }
                }
                let screen = egui_wgpu::ScreenDescriptor {
                    size_in_pixels: [width, height],
                    pixels_per_point: output.pixels_per_point,
                };
                let (gpu, renderer) = (self.gpu, &mut self.renderer);
                let pixels = render_target(gpu, width, height, |encoder, pass| {
                    let extra =
                        renderer.update_buffers(&gpu.device, &gpu.queue, encoder, &jobs, &screen);
                    gpu.queue.submit(extra);
                    renderer.render(pass, &jobs, &screen);
                });
                for delta in &mut deltas {
                    for id in &delta.free {
                        self.renderer.free_texture(id);
                    }
                    // Applied above; egui checks that no delta is dropped unapplied.
                    delta.clear();
                }
                return pixels;
            }
        }
        Err(Error::Scene("offscreen egui produced no frame".into()))
    }
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
