//! The desktop application: a winit window, egui through egui-winit and egui-wgpu, and the
//! scene renderer drawing under the egui panels. The simulation runs on its own thread
//! (see [`crate::sim`]); each frame drains its messages, advances the playback clock,
//! builds the UI and draws the current frame.

use std::sync::Arc;
use std::time::Instant;

use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use crate::render::offscreen::{side_by_side, world_window};
use crate::render::{Renderer, SceneView};
use crate::sim::SimHandle;
use crate::ui::AppState;
use crate::{Error, Result};

/// What to tell a user who starts the visualizer without a display.
pub const NO_DISPLAY_HELP: &str = "no display to open a window on; the same simulations run headless: \
    `slidebase run`, `slidebase report`, `slidebase render --out frame.png` (or start the visualizer \
    under a desktop, or `xvfb-run slidebase` for screenshots)";

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
    egui_renderer: egui_wgpu::Renderer,
    egui_state: egui_winit::State,
}

struct App {
    gfx: Option<Gfx>,
    state: AppState,
    sim: SimHandle,
    egui: egui::Context,
    last_frame: Instant,
    error: Option<Error>,
    /// Per model: the world window (fixed per run, so the camera does not jump).
    windows: Vec<[f32; 3]>,
    window_generation: u64,
    /// Quit after this many seconds (SLIDEBASE_EXIT_AFTER): smoke tests under Xvfb.
    exit_after: Option<f64>,
    started: Instant,
}

/// Opens the visualizer on the default scene (three-storey on El Centro, sliding and fixed
/// base side by side) and runs until the window closes.
pub fn run_app() -> Result<()> {
    let event_loop =
        EventLoop::new().map_err(|e| Error::Platform(format!("{NO_DISPLAY_HELP} ({e})")))?;
    event_loop.set_control_flow(winit::event_loop::ControlFlow::Poll);
    let mut app = App {
        gfx: None,
        state: AppState::default(),
        sim: SimHandle::spawn(),
        egui: egui::Context::default(),
        last_frame: Instant::now(),
        error: None,
        windows: Vec::new(),
        window_generation: 0,
        exit_after: std::env::var("SLIDEBASE_EXIT_AFTER")
            .ok()
            .and_then(|v| v.parse().ok()),
        started: Instant::now(),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::Scene(format!("the window's event loop failed: {e}")))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        // SLIDEBASE_WINDOW=WIDTHxHEIGHT sets the initial size (screenshots, measurements).
        let (w, h) = std::env::var("SLIDEBASE_WINDOW")
            .ok()
            .and_then(|v| {
                v.split_once('x')
                    .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
            })
            .unwrap_or((1600.0, 900.0));
        let attrs = Window::default_attributes()
            .with_title("slidebase — sliding-base structures under earthquakes (DDA)")
            .with_inner_size(winit::dpi::LogicalSize::new(w, h));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| Error::Scene(format!("cannot open a window: {e}")))?,
        );
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance
            .create_surface(window.clone())
            .map_err(|e| Error::Scene(format!("cannot draw into the window: {e}")))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| {
            Error::Platform(format!(
                "{} ({e})",
                crate::render::offscreen::NO_ADAPTER_HELP
            ))
        })?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("slidebase"),
            required_limits:
                wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .map_err(|e| Error::Scene(format!("cannot open the graphics device: {e}")))?;
        let size = window.inner_size();
        let caps = surface.get_capabilities(&adapter);
        let format = caps
            .formats
            .iter()
            .copied()
            .find(wgpu::TextureFormat::is_srgb)
            .unwrap_or(caps.formats[0]);
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoNoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&device, &config);
        let mut renderer = Renderer::new(&device, format);
        renderer.resize(config.width, config.height);
        let egui_renderer =
            egui_wgpu::Renderer::new(&device, format, egui_wgpu::RendererOptions::default());
        let egui_state = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        self.gfx = Some(Gfx {
            window,
            surface,
            device,
            queue,
            config,
            renderer,
            egui_renderer,
            egui_state,
        });
        Ok(())
    }

    fn frame(&mut self) {
        // Messages from the simulation: it never waits for us, we never wait for it.
        while let Ok(msg) = self.sim.messages.try_recv() {
            self.state.ingest(msg);
        }
        for cmd in self.state.take_commands() {
            self.sim.send(cmd);
        }
        let now = Instant::now();
        let dt = now.duration_since(self.last_frame).as_secs_f64().min(0.25);
        self.last_frame = now;
        self.state.advance(dt);
        if self.state.timeline.generation != self.window_generation
            && let Some(first) = self.state.timeline.frames.first()
        {
            self.windows = first.models.iter().map(world_window).collect();
            self.window_generation = self.state.timeline.generation;
        }
        let Some(gfx) = self.gfx.as_mut() else { return };
        let t_ui = Instant::now();
        let raw_input = gfx.egui_state.take_egui_input(&gfx.window);
        let mut scene_rect = egui::Rect::NOTHING;
        let state = &mut self.state;
        let output = self.egui.run_ui(raw_input, |ui| {
            scene_rect = state.ui(ui);
        });
        gfx.egui_state
            .handle_platform_output(&gfx.window, output.platform_output);
        let ppp = output.pixels_per_point;
        let ui_ms = t_ui.elapsed().as_secs_f64() * 1e3;
        let t_tess = Instant::now();
        let paint_jobs = self.egui.tessellate(output.shapes, ppp);
        let tess_ms = t_tess.elapsed().as_secs_f64() * 1e3;
        let t_gpu = Instant::now();
        // Texture updates first: they must be applied even when this frame is skipped.
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                gfx.egui_renderer
                    .update_texture(&gfx.device, &gfx.queue, *id, delta);
            }
        }
        for id in &output.textures_delta.free {
            gfx.egui_renderer.free_texture(id);
        }
        let mut textures_delta = output.textures_delta;
        textures_delta.clear();
        let texture = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gfx.surface.configure(&gfx.device, &gfx.config);
                return;
            }
            _ => return,
        };
        let view = texture
            .texture
            .create_view(&wgpu::TextureViewDescriptor::default());
        // The scene, in the central area left by the panels.
        let frames: Vec<crate::sim::ModelFrame> = self
            .state
            .current()
            .map(|f| f.models.clone())
            .unwrap_or_default();
        let ranges = slip_ranges(&self.state);
        let (w, h) = (gfx.config.width, gfx.config.height);
        let area = [
            scene_rect.left() * ppp,
            scene_rect.top() * ppp,
            scene_rect.width() * ppp,
            scene_rect.height() * ppp,
        ];
        let mut panels = side_by_side(
            &frames,
            &self.windows,
            &ranges,
            area[2].max(1.0) as u32,
            area[3].max(1.0) as u32,
        );
        for p in &mut panels {
            p.rect[0] += area[0];
            p.rect[1] += area[1];
        }
        let scene = SceneView {
            panels,
            exaggeration: self.state.exaggeration,
            color_by: self.state.color_by,
            color_max: self.state.color_max(),
            layers: self.state.layers,
        };
        gfx.renderer.resize(w, h);
        gfx.renderer.prepare(&gfx.device, &gfx.queue, &scene);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [w, h],
            pixels_per_point: ppp,
        };
        let mut encoder = gfx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("slidebase frame"),
            });
        let extra = gfx.egui_renderer.update_buffers(
            &gfx.device,
            &gfx.queue,
            &mut encoder,
            &paint_jobs,
            &screen,
        );
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("slidebase frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
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
            gfx.renderer.draw(&mut pass);
            gfx.egui_renderer.render(&mut pass, &paint_jobs, &screen);
        }
        gfx.queue
            .submit(extra.into_iter().chain(std::iter::once(encoder.finish())));
        gfx.window.pre_present_notify();
        gfx.queue.present(texture);
        // SLIDEBASE_PROFILE=1 prints where each frame's time goes (see docs/visualizer.md).
        if std::env::var("SLIDEBASE_PROFILE").is_ok() {
            eprintln!(
                "ui {ui_ms:.1} ms, tessellate {tess_ms:.1} ms, gpu+present {:.1} ms",
                t_gpu.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}

/// Slip range reached so far by each model (the trace on the ground).
fn slip_ranges(state: &AppState) -> Vec<[f32; 2]> {
    let n = state.timeline.frames.first().map_or(0, |f| f.models.len());
    let upto = state.timeline.index_at(state.play_time).unwrap_or(0);
    (0..n)
        .map(|m| {
            state.timeline.frames[..=upto.min(state.timeline.frames.len().saturating_sub(1))]
                .iter()
                .filter_map(|f| f.models.get(m).map(|x| x.probes.slip as f32))
                .fold([0.0f32, 0.0], |r, s| [r[0].min(s), r[1].max(s)])
        })
        .collect()
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_none()
            && let Err(e) = self.init(event_loop)
        {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Some(gfx) = self.gfx.as_mut() {
            let response = gfx.egui_state.on_window_event(&gfx.window, &event);
            if response.repaint {
                gfx.window.request_redraw();
            }
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(gfx) = self.gfx.as_mut() {
                    gfx.config.width = size.width.max(1);
                    gfx.config.height = size.height.max(1);
                    gfx.surface.configure(&gfx.device, &gfx.config);
                    gfx.renderer.resize(gfx.config.width, gfx.config.height);
                }
            }
            WindowEvent::RedrawRequested => {
                self.frame();
                if let Some(after) = self.exit_after
                    && self.started.elapsed().as_secs_f64() >= after
                {
                    println!(
                        "frame time {:.1} ms, simulation {:.1}× real time, frame copy-out {:.0} µs, batch take-in {:.1} µs",
                        self.state.frame_ms,
                        self.state.timeline.sim_speed,
                        self.state.extract_us,
                        self.state.handoff_us
                    );
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(gfx) = &self.gfx {
            gfx.window.request_redraw();
        }
    }
}
