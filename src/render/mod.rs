//! The wgpu renderer: draws a [`geometry::SceneView`] with one pipeline of coloured
//! triangles. It knows nothing about windows: it is created from a device and a target
//! format, told the target size, and renders into whatever texture view it is given — a
//! window's surface or an offscreen texture (see [`offscreen`]).

pub mod geometry;
pub mod layout;
pub mod offscreen;

use wgpu::util::DeviceExt;

pub use geometry::{ColorBy, Layers, PanelView, SceneView, Vertex, ViewBox};
pub use layout::{Camera, Fit, Follow};

/// The scene renderer.
pub struct Renderer {
    pipeline: wgpu::RenderPipeline,
    vertex_buffer: wgpu::Buffer,
    capacity: usize,
    vertex_count: u32,
    size: [u32; 2],
}

impl Renderer {
    /// Creates the pipeline for targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("slidebase scene"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/scene.wgsl").into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("slidebase scene"),
            bind_group_layouts: &[],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x2, 1 => Float32x4];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("slidebase scene"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<Vertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let capacity = 4096;
        let vertex_buffer = Self::buffer(device, capacity);
        Self {
            pipeline,
            vertex_buffer,
            capacity,
            vertex_count: 0,
            size: [1, 1],
        }
    }

    fn buffer(device: &wgpu::Device, capacity: usize) -> wgpu::Buffer {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("slidebase scene vertices"),
            contents: bytemuck::cast_slice(&vec![
                Vertex {
                    position: [0.0; 2],
                    color: [0.0; 4]
                };
                capacity
            ]),
            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        })
    }

    /// Sets the size of the target in pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.size = [width.max(1), height.max(1)];
    }

    /// Target size in pixels.
    pub fn size(&self) -> [u32; 2] {
        self.size
    }

    /// Tessellates the view and uploads it; call before [`Renderer::draw`].
    pub fn prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, view: &SceneView<'_>) {
        let vertices = geometry::build(view, [self.size[0] as f32, self.size[1] as f32]);
        self.upload(device, queue, &vertices);
    }

    /// Uploads triangles tessellated already (clip space of the target); call before
    /// [`Renderer::draw`].
    pub fn upload(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, vertices: &[Vertex]) {
        if vertices.len() > self.capacity {
            self.capacity = vertices.len().next_power_of_two();
            self.vertex_buffer = Self::buffer(device, self.capacity);
        }
        if !vertices.is_empty() {
            queue.write_buffer(&self.vertex_buffer, 0, bytemuck::cast_slice(vertices));
        }
        self.vertex_count = vertices.len() as u32;
    }

    /// Records the draw into a render pass whose target has the size given to `resize`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.vertex_count == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_vertex_buffer(0, self.vertex_buffer.slice(..));
        pass.draw(0..self.vertex_count, 0..1);
    }
}
