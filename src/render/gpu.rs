//! The renderer's GPU plumbing: the WGSL, the records it reads (laid out
//! as in `shaders/render.wgsl`), the pipelines, the buffers and textures,
//! the passes of a frame and the readback of its image.

use bytemuck::{Pod, Zeroable};
use image::RgbaImage;

use super::bodies::{srgb_to_linear, Instances, BACKGROUND_SRGB};
use super::mesh::{icosphere, unit_cube, MeshVertex, ICOSPHERE_LEVEL};
use crate::gpu::types::BodyState;
use crate::gpu::Gpu;
use crate::Error;

/// shaders/render.wgsl, the render pipelines' own part.
pub(crate) const RENDER: &str = include_str!("../../shaders/render.wgsl");

/// The WGSL of every render pipeline: the shared constants, common.wgsl (the
/// body's pose and the quaternion helpers; it binds nothing), render.wgsl.
pub fn shader_source() -> String {
    crate::gpu::shaders::shared_constants() + crate::gpu::shaders::COMMON + RENDER
}

/// Samples per pixel: 4x MSAA, which WebGPU guarantees for both formats below.
pub(crate) const SAMPLES: u32 = 4;
/// The image: 8-bit sRGB, so shading happens in linear light and the bytes
/// read back are what a PNG expects.
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Reversed depth in 32-bit float: even precision from near plane to horizon.
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The shadow map's depth (ordinary, not reversed: it is orthographic).
const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Bind groups kept for state buffers already seen: a world has two.
const BIND_GROUP_CACHE: usize = 4;

/// The renderer's constants (208 bytes), written once; `Globals` in render.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Globals {
    /// World to clip space, column-major, reversed depth.
    pub view_proj: [[f32; 4]; 4],
    /// World to the shadow map's clip space (orthographic along the sun).
    pub light_view_proj: [[f32; 4]; 4],
    /// xyz = camera position (m).
    pub eye: [f32; 4],
    /// xyz = unit vector towards the sun; w = how far shadow lookups move
    /// out along the surface normal (m), about a texel of the shadow map.
    pub light_dir: [f32; 4],
    /// x = ground height (m); y, z = centre of the drawn square (m); w = its half size (m).
    pub ground: [f32; 4],
    /// x = minor grid spacing (m); y = major spacing (m); z, w = distances from
    /// the eye (m) where the fog starts and where it is complete.
    pub grid: [f32; 4],
    /// rgb = background colour, linear.
    pub background: [f32; 4],
}

/// One drawn body (32 bytes); `RenderBody` in render.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct RenderBody {
    /// Box: half extents (m); sphere: the radius three times; capsule:
    /// (radius, half height, radius); hull: 1 three times (its mesh is in metres).
    pub half_extents: [f32; 3],
    /// Index of the body in the state buffer.
    pub body: u32,
    /// Linear RGB.
    pub color: [f32; 3],
    /// `SHAPE_BOX`, `SHAPE_SPHERE`, `SHAPE_CAPSULE` or `SHAPE_HULL` (drawn
    /// from its own mesh, unscaled and plainly coloured).
    pub shape: u32,
}

/// One ball joint (32 bytes); `JointLine` in render.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct JointLine {
    /// In body A's frame, or in world coordinates when `body_a` is -1 (m).
    pub anchor_a: [f32; 3],
    pub body_a: i32,
    pub anchor_b: [f32; 3],
    pub body_b: i32,
}

/// The compiled render pipelines and their bind-group layouts; nothing else.
pub(crate) struct RenderPipelines {
    /// Group 0: globals, states, bodies, joints.
    pub layout: wgpu::BindGroupLayout,
    /// Group 1: the shadow map and its comparison sampler (main pass only).
    pub shadow_layout: wgpu::BindGroupLayout,
    pub shadow: wgpu::RenderPipeline,
    pub bodies: wgpu::RenderPipeline,
    pub ground: wgpu::RenderPipeline,
    pub joints: wgpu::RenderPipeline,
}

impl RenderPipelines {
    pub(crate) fn new(device: &wgpu::Device) -> RenderPipelines {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("render.wgsl"),
            source: wgpu::ShaderSource::Wgsl(shader_source().into()),
        });
        let storage = |binding: u32| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::VERTEX,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("render"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(std::mem::size_of::<Globals>() as u64),
                    },
                    count: None,
                },
                storage(1), // states
                storage(2), // bodies
                storage(3), // joints
            ],
        });
        let shadow_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("render/shadow_map"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
            ],
        });
        // the shadow pass may not see the shadow map it writes: group 0 only
        let shadow_pass_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("render/shadow"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let main_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("render"),
            bind_group_layouts: &[Some(&layout), Some(&shadow_layout)],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];
        let mesh_layout = || wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<MeshVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attributes,
        };
        let shadow = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("render/shadow"),
            layout: Some(&shadow_pass_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("shadow_vertex"),
                compilation_options: Default::default(),
                buffers: &[Some(mesh_layout())],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: Some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                // pushed away from the sun, more where surfaces slope, against speckled self-shadowing
                bias: wgpu::DepthBiasState { constant: 2, slope_scale: 2.0, clamp: 0.0 },
            }),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let pipeline = |name: &str,
                        buffers: &[Option<wgpu::VertexBufferLayout>],
                        topology: wgpu::PrimitiveTopology,
                        cull_mode: Option<wgpu::Face>,
                        overlay: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(&format!("render/{name}")),
                layout: Some(&main_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(&format!("{name}_vertex")),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState { topology, front_face: wgpu::FrontFace::Ccw, cull_mode, ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(!overlay),
                    // reversed depth: nearer is greater; an overlay ignores depth
                    depth_compare: Some(if overlay { wgpu::CompareFunction::Always } else { wgpu::CompareFunction::Greater }),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState { count: SAMPLES, ..Default::default() },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(&format!("{name}_fragment")),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: COLOR_FORMAT,
                        blend: overlay.then_some(wgpu::BlendState::ALPHA_BLENDING),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let list = wgpu::PrimitiveTopology::TriangleList;
        let bodies = pipeline("body", &[Some(mesh_layout())], list, Some(wgpu::Face::Back), false);
        // the ground shows from below too, if a camera goes there
        let ground = pipeline("ground", &[], list, None, false);
        // joint lines run mostly inside the bodies: drawn on top, unoccluded
        let joints = pipeline("joint", &[], wgpu::PrimitiveTopology::LineList, None, true);
        RenderPipelines { layout, shadow_layout, shadow, bodies, ground, joints }
    }
}

/// The renderer's buffers and textures, all made once at start-up.
pub(crate) struct RenderData {
    pub globals: wgpu::Buffer,
    /// `RenderBody` per body, boxes first, then spheres and capsules, then hulls.
    pub bodies: wgpu::Buffer,
    pub joints: wgpu::Buffer,
    /// The unit cube (36 vertices), then the unit icosphere, then the hulls' meshes.
    pub mesh: wgpu::Buffer,
    /// Bound instead of a world's state buffer when the world has no bodies
    /// (a binding must hold at least one element).
    pub empty_state: wgpu::Buffer,
    pub shadow_map: wgpu::TextureView,
    /// Group 1: the shadow map and its sampler, for the main pass.
    pub shadow_bind_group: wgpu::BindGroup,
    pub msaa: wgpu::TextureView,
    pub depth: wgpu::TextureView,
    /// Where the samples resolve to, and what is copied out.
    pub resolved: wgpu::Texture,
    pub resolved_view: wgpu::TextureView,
    /// Mapped after each frame; rows `padded_row` bytes apart.
    pub readback: wgpu::Buffer,
    pub padded_row: u32,
}

/// The GPU side of a renderer: its pipelines, buffers and textures, and
/// the passes that draw a frame and read the image back. It knows the
/// scene only as the records it was given.
pub(super) struct Canvas {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipelines: RenderPipelines,
    data: RenderData,
    width: u32,
    height: u32,
    box_count: u32,
    round_count: u32,
    sphere_vertices: u32,
    /// Per hull shape: its vertices in `RenderData::mesh`, and its slots.
    hull_runs: Vec<(std::ops::Range<u32>, std::ops::Range<u32>)>,
    joint_count: u32,
    /// Bind groups by the state buffer they bind (a world alternates two).
    bind_groups: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
}

/// Bytes between rows of the image read back: a row's, padded as a copy
/// out of a texture needs (`COPY_BYTES_PER_ROW_ALIGNMENT`).
pub(super) fn padded_row(width: u32) -> u32 {
    (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

impl Canvas {
    /// Compiles the pipelines and makes and fills every buffer and texture
    /// a `width` x `height` frame needs, with a shadow map of
    /// `shadow_size` texels a side. Errors surface at the next `gpu.check()`.
    pub(super) fn new(
        gpu: &Gpu,
        width: u32,
        height: u32,
        shadow_size: u32,
        globals: &Globals,
        instances: &Instances,
        joints: &[JointLine],
    ) -> Canvas {
        let device = &gpu.device;
        let mut mesh = unit_cube();
        let cube_vertices = mesh.len();
        mesh.extend(icosphere(ICOSPHERE_LEVEL));
        let sphere_vertices = (mesh.len() - cube_vertices) as u32;
        let hulls_start = mesh.len() as u32;
        mesh.extend_from_slice(&instances.hull_mesh);
        let hull_runs = instances
            .hull_runs
            .iter()
            .map(|r| (hulls_start + r.vertices.start..hulls_start + r.vertices.end, r.slots.clone()))
            .collect();

        let buffer = |label: &str, bytes: &[u8], usage: wgpu::BufferUsages| {
            let buf = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (bytes.len() as u64).max(64).next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT),
                usage: usage | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            if !bytes.is_empty() {
                gpu.queue.write_buffer(&buf, 0, bytes);
            }
            buf
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let texture = |label: &str, format: wgpu::TextureFormat, samples: u32, usage: wgpu::TextureUsages| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let resolved = texture("render/resolved", COLOR_FORMAT, 1, attachment | wgpu::TextureUsages::COPY_SRC);
        let pipelines = RenderPipelines::new(device);
        let shadow_map = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("render/shadow_map"),
                size: wgpu::Extent3d { width: shadow_size, height: shadow_size, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: SHADOW_FORMAT,
                usage: attachment | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            })
            .create_view(&Default::default());
        // linear filtering of a comparison: each lookup is itself a 2x2 percentage-closer filter
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("render/shadow_sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let shadow_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("render/shadow_map"),
            layout: &pipelines.shadow_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&shadow_map) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&shadow_sampler) },
            ],
        });
        let padded_row = padded_row(width);
        let data = RenderData {
            globals: buffer("render/globals", bytemuck::bytes_of(globals), wgpu::BufferUsages::UNIFORM),
            bodies: buffer("render/bodies", bytemuck::cast_slice(&instances.bodies), storage),
            joints: buffer("render/joints", bytemuck::cast_slice(joints), storage),
            mesh: buffer("render/mesh", bytemuck::cast_slice(&mesh), wgpu::BufferUsages::VERTEX),
            empty_state: buffer("render/empty_state", bytemuck::bytes_of(&BodyState::default()), storage),
            shadow_map,
            shadow_bind_group,
            msaa: texture("render/msaa", COLOR_FORMAT, SAMPLES, attachment).create_view(&Default::default()),
            depth: texture("render/depth", DEPTH_FORMAT, SAMPLES, attachment).create_view(&Default::default()),
            resolved_view: resolved.create_view(&Default::default()),
            resolved,
            readback: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("render/readback"),
                size: padded_row as u64 * height as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            padded_row,
        };
        Canvas {
            device: gpu.device.clone(),
            queue: gpu.queue.clone(),
            pipelines,
            data,
            width,
            height,
            box_count: instances.box_count,
            round_count: instances.round_count,
            sphere_vertices,
            hull_runs,
            joint_count: joints.len() as u32,
            bind_groups: Vec::new(),
        }
    }

    /// Rewrites the instance record in `slot` (a body's new colour).
    pub(super) fn write_body(&self, slot: u32, body: &RenderBody) {
        let offset = slot as u64 * std::mem::size_of::<RenderBody>() as u64;
        self.queue.write_buffer(&self.data.bodies, offset, bytemuck::bytes_of(body));
    }

    /// Draws a frame of the bodies whose states `state` holds (None: there
    /// are none), the ground and the joint lines if asked, and reads the
    /// image back, waiting on `gpu`.
    pub(super) fn draw(&mut self, gpu: &Gpu, state: Option<&wgpu::Buffer>, ground: bool, joints: bool) -> Result<RgbaImage, Error> {
        let state = state.unwrap_or(&self.data.empty_state).clone();
        let bind_group = self.bind_group(&state);

        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("render") });
        // 1. the bodies' depth as the sun sees them
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("render/shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.data.shadow_map,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_pipeline(&self.pipelines.shadow);
            pass.set_vertex_buffer(0, self.data.mesh.slice(..));
            self.draw_bodies(&mut pass);
        }
        // 2. the image: bodies, ground, joint lines; 4 samples resolved into one
        {
            let bg = BACKGROUND_SRGB.map(srgb_to_linear);
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("render/frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &self.data.msaa,
                    depth_slice: None,
                    resolve_target: Some(&self.data.resolved_view),
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: bg[0] as f64, g: bg[1] as f64, b: bg[2] as f64, a: 1.0 }),
                        // only the resolved image is needed
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.data.depth,
                    // reversed depth: clear to the far plane, 0
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_bind_group(1, &self.data.shadow_bind_group, &[]);
            // bodies first: they hide most of the ground, whose fragments the depth test then skips
            pass.set_pipeline(&self.pipelines.bodies);
            pass.set_vertex_buffer(0, self.data.mesh.slice(..));
            self.draw_bodies(&mut pass);
            if ground {
                pass.set_pipeline(&self.pipelines.ground);
                pass.draw(0..6, 0..1);
            }
            if joints && self.joint_count > 0 {
                pass.set_pipeline(&self.pipelines.joints);
                pass.draw(0..6, 0..self.joint_count);
            }
        }
        // 3. out to the host
        enc.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.data.resolved,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &self.data.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.data.padded_row),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d { width: self.width, height: self.height, depth_or_array_layers: 1 },
        );
        gpu.submit(enc.finish());

        let (tx, rx) = std::sync::mpsc::channel();
        self.data.readback.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        gpu.wait()?;
        let gpu_err = |e: String| Error::Gpu(crate::gpu::GpuError::Runtime(e));
        // wgpu calls back while polling, so after the wait the answer is in
        // (or never comes, on a broken device: do not block on it)
        rx.recv_timeout(std::time::Duration::from_secs(1))
            .map_err(|_| gpu_err("render: the image's readback never completed".into()))?
            .map_err(|e| gpu_err(e.to_string()))?;
        let row = 4 * self.width as usize;
        let pixels = self.data.readback.get_mapped_range(..).map(|mapped| {
            // drop each row's padding up to COPY_BYTES_PER_ROW_ALIGNMENT
            let mut pixels = Vec::with_capacity(row * self.height as usize);
            for padded in mapped.chunks(self.data.padded_row as usize) {
                pixels.extend_from_slice(&padded[..row]);
            }
            pixels
        });
        // unmapped whatever happened, so the next frame can copy into it
        self.data.readback.unmap();
        let pixels = pixels.map_err(|e| gpu_err(e.to_string()))?;
        RgbaImage::from_raw(self.width, self.height, pixels).ok_or_else(|| gpu_err("render: readback has the wrong size".into()))
    }

    /// One instanced draw per mesh: the boxes' slots, then the spheres' and
    /// capsules', then each hull shape's.
    fn draw_bodies(&self, pass: &mut wgpu::RenderPass) {
        if self.box_count > 0 {
            pass.draw(0..36, 0..self.box_count);
        }
        if self.round_count > 0 {
            pass.draw(36..36 + self.sphere_vertices, self.box_count..self.box_count + self.round_count);
        }
        for (vertices, slots) in &self.hull_runs {
            pass.draw(vertices.clone(), slots.clone());
        }
    }

    /// The bind group for a world's state buffer, made the first time it is seen.
    fn bind_group(&mut self, state: &wgpu::Buffer) -> wgpu::BindGroup {
        if let Some((_, bg)) = self.bind_groups.iter().find(|(b, _)| b == state) {
            return bg.clone();
        }
        let bg = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("render"),
            layout: &self.pipelines.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.data.globals.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: state.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: self.data.bodies.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: self.data.joints.as_entire_binding() },
            ],
        });
        if self.bind_groups.len() == BIND_GROUP_CACHE {
            self.bind_groups.remove(0);
        }
        self.bind_groups.push((state.clone(), bg.clone()));
        bg
    }
}
