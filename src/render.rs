//! Off-screen rendering of a [`World`]: shaded bodies, the ground with a
//! grid, optional joint lines, from a fixed camera that frames the scene.
//!
//! The bodies are drawn straight from [`World::current_state_buffer`], bound
//! read-only in the vertex shader (`shaders/render.wgsl`): nothing is read
//! back to draw, only the finished image is. What never changes (each body's
//! shape, size and colour) is uploaded once from the [`Scene`].
//!
//! ```no_run
//! use std::path::Path;
//! use verlet::{render::{self, Renderer}, scenes, World};
//! let scene = scenes::stack(5);
//! let mut world = World::new(&scene)?;
//! let mut renderer = Renderer::new(world.gpu(), &scene, 640, 480)?;
//! world.step(60)?;
//! let image = renderer.render(&world)?;
//! render::write_png(&image, Path::new("stack.png"))?;
//! # Ok::<(), verlet::Error>(())
//! ```
//!
//! As the step splits pipelines from buffers, [`RenderPipelines`] holds only
//! what is compiled (built once, in [`Renderer::new`]) and [`RenderData`]
//! only buffers and textures; a frame allocates nothing but, the first time
//! it sees each of a world's two state buffers, a bind group for it.

use std::path::Path;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};
use image::RgbaImage;

use crate::gpu::types::{BodyState, SHAPE_BOX, SHAPE_SPHERE};
use crate::gpu::Gpu;
use crate::scene::{Scene, Shape, DEFAULT_FOV_Y};
use crate::world::World;
use crate::Error;

/// shaders/render.wgsl, the render pipelines' own part.
pub const RENDER: &str = include_str!("../shaders/render.wgsl");

/// The WGSL of every render pipeline: the shared constants, common.wgsl (the
/// body's pose and the quaternion helpers; it binds nothing), render.wgsl.
pub fn shader_source() -> String {
    crate::gpu::shaders::shared_constants() + crate::gpu::shaders::COMMON + RENDER
}

/// Samples per pixel: 4x MSAA, which WebGPU guarantees for both formats below.
pub const SAMPLES: u32 = 4;
/// The image: 8-bit sRGB, so shading happens in linear light and the bytes
/// read back are what a PNG expects.
const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// Reversed depth in 32-bit float: even precision from near plane to horizon.
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The shadow map's depth (ordinary, not reversed: it is orthographic).
const SHADOW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The shadow map covers the scene's starting bounding sphere times this,
/// so bodies that roll or swing a little out of it still cast shadows.
const SHADOW_REACH: f32 = 1.5;
/// Where the default camera looks from, relative to the scene's centre:
/// above, in front and a little to the right, so three faces of an
/// axis-aligned box show, each lit differently.
pub const DEFAULT_VIEW_DIRECTION: [f32; 3] = [0.6, 0.5, 1.0];
/// The default camera leaves this much room around the scene's bounding
/// sphere (a factor on the distance that just fits it).
const FRAMING_MARGIN: f32 = 1.05;
/// Towards the sun: high, from the left and in front. Seen from the default
/// camera (right and in front) the top, front and right faces of a box get
/// three distinct shades, and shadows fall back and right, into view.
const LIGHT_DIRECTION: [f32; 3] = [-0.4, 1.0, 0.7];
/// Background (sRGB): a pale sky; the ground fades into it.
const BACKGROUND_SRGB: [f32; 3] = [0.80, 0.85, 0.90];
/// Colour of fixed bodies (sRGB): a neutral grey, the colour of "not moving".
const FIXED_SRGB: [f32; 3] = [0.55, 0.55, 0.55];
/// Subdivisions of the icosahedron for spheres: 1280 triangles, smooth at
/// any size a sphere takes in a frame.
const ICOSPHERE_LEVEL: u32 = 3;
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
    /// Box: half extents (m); sphere: the radius three times.
    pub half_extents: [f32; 3],
    /// Index of the body in the state buffer.
    pub body: u32,
    /// Linear RGB.
    pub color: [f32; 3],
    /// `SHAPE_BOX` or `SHAPE_SPHERE`.
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

/// A vertex of the unit meshes (24 bytes): position and outward normal.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
struct MeshVertex {
    pos: [f32; 3],
    normal: [f32; 3],
}

/// Where the renderer looks from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Eye position (m).
    pub position: [f32; 3],
    /// The point at the centre of the image (m).
    pub target: [f32; 3],
    /// Up in the image: +Y, or +Z when looking straight along Y.
    pub up: [f32; 3],
    /// Vertical field of view (radians).
    pub fov_y: f32,
}

/// Choices that do not change the pipelines.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderOptions {
    /// Draw each joint as lines on top of the bodies: body A's centre to its
    /// anchor, anchor A to anchor B (magenta, the joint's error, zero-length
    /// while it holds) and anchor B to body B's centre. Off by default.
    pub draw_joints: bool,
}

/// The compiled render pipelines and their bind-group layouts; nothing else.
pub struct RenderPipelines {
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
    pub fn new(device: &wgpu::Device) -> RenderPipelines {
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
pub struct RenderData {
    pub globals: wgpu::Buffer,
    /// `RenderBody` per body, boxes first, then spheres.
    pub bodies: wgpu::Buffer,
    pub joints: wgpu::Buffer,
    /// The unit cube (36 vertices), then the unit icosphere.
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

/// Draws a world's bodies into an image.
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipelines: RenderPipelines,
    data: RenderData,
    width: u32,
    height: u32,
    camera: CameraView,
    view_proj: Mat4,
    options: RenderOptions,
    body_count: usize,
    box_count: u32,
    sphere_count: u32,
    sphere_vertices: u32,
    joint_count: u32,
    has_ground: bool,
    /// The host copy of `data.bodies`, and each body's slot in it.
    instances: Vec<RenderBody>,
    slot_of_body: Vec<u32>,
    /// Bind groups by the state buffer they bind (a world alternates two).
    bind_groups: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
}

impl Renderer {
    /// A renderer for `scene`'s bodies, `width` x `height` pixels, with
    /// default options (no joint lines).
    pub fn new(gpu: &Gpu, scene: &Scene, width: u32, height: u32) -> Result<Renderer, Error> {
        Renderer::with_options(gpu, scene, width, height, RenderOptions::default())
    }

    /// As [`Renderer::new`], with options. Refuses a size of 0 or beyond the
    /// device's `max_texture_dimension_2d`, naming the `--width`/`--height`
    /// flag, before allocating anything.
    pub fn with_options(gpu: &Gpu, scene: &Scene, width: u32, height: u32, options: RenderOptions) -> Result<Renderer, Error> {
        scene.validate()?;
        let max = gpu.limits.max_texture_dimension_2d;
        for (flag, v) in [("--width", width), ("--height", height)] {
            if v == 0 || v > max {
                return Err(Error::Input(format!(
                    "{flag}: must be 1 to {max} pixels (this adapter's max_texture_dimension_2d), got {v}"
                )));
            }
        }
        let padded_row = (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback_size = padded_row as u64 * height as u64;
        if readback_size > gpu.limits.max_buffer_size {
            return Err(Error::Input(format!(
                "--width, --height: a {width} x {height} image needs a {readback_size}-byte readback buffer, \
                 beyond this adapter's max_buffer_size of {}",
                gpu.limits.max_buffer_size
            )));
        }
        let vertex_storage = gpu.adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::VERTEX_STORAGE);
        if !vertex_storage || gpu.limits.max_storage_buffers_per_shader_stage < 3 {
            return Err(Error::Capacity(
                "rendering reads 3 storage buffers in the vertex shader, which this adapter does not allow".into(),
            ));
        }
        let device = &gpu.device;

        // what each body looks like: boxes first, then spheres, so each mesh is one draw
        let mut instances = Vec::with_capacity(scene.bodies.len());
        for want in [SHAPE_BOX, SHAPE_SPHERE] {
            for (i, b) in scene.bodies.iter().enumerate() {
                let (half_extents, shape) = match b.shape {
                    Shape::Box { half_extents } => (half_extents, SHAPE_BOX),
                    Shape::Sphere { radius } => ([radius; 3], SHAPE_SPHERE),
                };
                if shape == want {
                    let srgb = if b.fixed { FIXED_SRGB } else { body_color(i) };
                    instances.push(RenderBody { half_extents, body: i as u32, color: srgb.map(srgb_to_linear), shape });
                }
            }
        }
        let box_count = instances.iter().filter(|r| r.shape == SHAPE_BOX).count() as u32;
        let sphere_count = instances.len() as u32 - box_count;
        let mut slot_of_body = vec![0u32; scene.bodies.len()];
        for (slot, r) in instances.iter().enumerate() {
            slot_of_body[r.body as usize] = slot as u32;
        }
        let joints: Vec<JointLine> = scene
            .joints
            .iter()
            .map(|j| JointLine { anchor_a: j.anchors[0], body_a: j.bodies[0], anchor_b: j.anchors[1], body_b: j.bodies[1] })
            .collect();

        let (camera, framing) = choose_camera(scene, width as f32 / height as f32);
        let view_proj = view_projection(&camera, width as f32 / height as f32);
        let shadow_size = shadow_map_size(width, height, max);
        let globals = make_globals(&camera, view_proj, &framing, scene.ground.as_ref().map(|g| g.height), shadow_size);

        let mut mesh = unit_cube();
        let cube_vertices = mesh.len();
        mesh.extend(icosphere(ICOSPHERE_LEVEL));
        let sphere_vertices = (mesh.len() - cube_vertices) as u32;

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
        let data = RenderData {
            globals: buffer("render/globals", bytemuck::bytes_of(&globals), wgpu::BufferUsages::UNIFORM),
            bodies: buffer("render/bodies", bytemuck::cast_slice(&instances), storage),
            joints: buffer("render/joints", bytemuck::cast_slice(&joints), storage),
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
                size: readback_size,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            padded_row,
        };
        gpu.check()?;
        Ok(Renderer {
            device: gpu.device.clone(),
            queue: gpu.queue.clone(),
            pipelines,
            data,
            width,
            height,
            camera,
            view_proj,
            options,
            body_count: scene.bodies.len(),
            box_count,
            sphere_count,
            sphere_vertices,
            joint_count: joints.len() as u32,
            has_ground: scene.ground.is_some(),
            instances,
            slot_of_body,
            bind_groups: Vec::new(),
        })
    }

    /// The camera in use: the scene's, or one that frames the scene.
    pub fn camera(&self) -> CameraView {
        self.camera
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn options(&self) -> RenderOptions {
        self.options
    }

    /// Turns joint lines on or off for the next frames.
    pub fn set_draw_joints(&mut self, on: bool) {
        self.options.draw_joints = on;
    }

    /// Paints body `index` in `srgb` (each 0..1) instead of its own colour.
    pub fn set_body_color(&mut self, index: usize, srgb: [f32; 3]) -> Result<(), Error> {
        let slot = *self
            .slot_of_body
            .get(index)
            .ok_or_else(|| Error::Input(format!("body {index}: the scene has {} bodies", self.body_count)))?;
        let r = &mut self.instances[slot as usize];
        r.color = srgb.map(|c| srgb_to_linear(c.clamp(0.0, 1.0)));
        let offset = slot as u64 * std::mem::size_of::<RenderBody>() as u64;
        self.queue.write_buffer(&self.data.bodies, offset, bytemuck::bytes_of(r));
        Ok(())
    }

    /// Where `world_point` lands in the image, in pixels from the top-left
    /// corner (pixel (i, j) covers [i, i+1) x [j, j+1)); `None` when it is
    /// behind the camera or outside the image.
    pub fn project(&self, world_point: [f32; 3]) -> Option<[f32; 2]> {
        let clip = self.view_proj * Vec4::new(world_point[0], world_point[1], world_point[2], 1.0);
        if clip.w <= 0.0 {
            return None;
        }
        let (x, y) = (clip.x / clip.w, clip.y / clip.w);
        let px = (x * 0.5 + 0.5) * self.width as f32;
        let py = (0.5 - y * 0.5) * self.height as f32;
        let inside = (0.0..=self.width as f32).contains(&px) && (0.0..=self.height as f32).contains(&py);
        inside.then_some([px, py])
    }

    /// Draws `world` as it is now and reads the image back (a blocking wait).
    /// The world must come from the scene this renderer was made for, on the
    /// same device.
    pub fn render(&mut self, world: &World) -> Result<RgbaImage, Error> {
        if world.body_count() != self.body_count {
            return Err(Error::Input(format!(
                "render: the world has {} bodies but the renderer was made for a scene of {}",
                world.body_count(),
                self.body_count
            )));
        }
        if world.gpu().device != self.device {
            return Err(Error::Input("render: the world lives on another device than the renderer".into()));
        }
        let state = if self.body_count == 0 { self.data.empty_state.clone() } else { world.current_state_buffer().clone() };
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
            if self.has_ground {
                pass.set_pipeline(&self.pipelines.ground);
                pass.draw(0..6, 0..1);
            }
            if self.options.draw_joints && self.joint_count > 0 {
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
        self.queue.submit([enc.finish()]);

        let (tx, rx) = std::sync::mpsc::channel();
        self.data.readback.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        world.gpu().wait()?;
        let gpu_err = |e: String| Error::Gpu(crate::gpu::GpuError::Runtime(e));
        rx.recv().map_err(|e| gpu_err(e.to_string()))?.map_err(|e| gpu_err(e.to_string()))?;
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

    /// One instanced draw per mesh: the boxes' slots, then the spheres'.
    fn draw_bodies(&self, pass: &mut wgpu::RenderPass) {
        if self.box_count > 0 {
            pass.draw(0..36, 0..self.box_count);
        }
        if self.sphere_count > 0 {
            pass.draw(36..36 + self.sphere_vertices, self.box_count..self.box_count + self.sphere_count);
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

/// The scene's extent: the bodies' starting bounding box (each body as its
/// bounding sphere), stretched down to the ground when there is one, since
/// bodies above it fall onto it. A bounding sphere of that box frames it.
#[derive(Clone, Copy, Debug)]
struct Framing {
    centre: Vec3,
    /// Radius of the bounding sphere (m), at least 1 mm.
    radius: f32,
}

fn framing(scene: &Scene) -> Framing {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for b in &scene.bodies {
        let p = Vec3::from_array(b.position);
        let r = Vec3::splat(b.shape.bounding_radius());
        lo = lo.min(p - r);
        hi = hi.max(p + r);
    }
    if scene.bodies.is_empty() {
        // nothing to frame: a 2 m box on the ground (or the origin)
        let y = scene.ground.as_ref().map_or(0.0, |g| g.height);
        lo = Vec3::new(-1.0, y, -1.0);
        hi = Vec3::new(1.0, y + 2.0, 1.0);
    }
    if let Some(g) = &scene.ground {
        lo.y = lo.y.min(g.height);
        hi.y = hi.y.max(g.height);
    }
    Framing { centre: 0.5 * (lo + hi), radius: (0.5 * (hi - lo).length()).max(1e-3) }
}

/// Up in the image: +Y, or +Z when looking (nearly) straight along Y.
fn up_for(forward: Vec3) -> Vec3 {
    if forward.normalize_or_zero().y.abs() > 0.999 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The scene's camera if it has one; else one looking at the centre of the
/// scene from `DEFAULT_VIEW_DIRECTION`, just far enough that the bounding
/// sphere fits both the vertical and the horizontal field of view.
fn choose_camera(scene: &Scene, aspect: f32) -> (CameraView, Framing) {
    let f = framing(scene);
    let camera = match &scene.camera {
        Some(c) => {
            let forward = Vec3::from_array(c.target) - Vec3::from_array(c.position);
            CameraView { position: c.position, target: c.target, up: up_for(forward).to_array(), fov_y: c.fov_y }
        }
        None => {
            let fov_y = DEFAULT_FOV_Y;
            let fov_x = 2.0 * ((0.5 * fov_y).tan() * aspect).atan();
            // a sphere of radius R fits a cone of half angle a from R / sin(a) away
            let distance = f.radius / (0.5 * fov_y.min(fov_x)).sin() * FRAMING_MARGIN;
            let position = f.centre + Vec3::from_array(DEFAULT_VIEW_DIRECTION).normalize() * distance;
            CameraView {
                position: position.to_array(),
                target: f.centre.to_array(),
                up: up_for(f.centre - position).to_array(),
                fov_y: DEFAULT_FOV_Y,
            }
        }
    };
    (camera, f)
}

/// World to clip space: a right-handed view, and a perspective with the
/// far plane at infinity and depth reversed (near = 1). The near plane sits
/// at a thousandth of the distance to the target: close enough for any body
/// in front of the camera, and reversed float depth loses nothing by it.
fn view_projection(camera: &CameraView, aspect: f32) -> Mat4 {
    let eye = Vec3::from_array(camera.position);
    let target = Vec3::from_array(camera.target);
    let view = Mat4::look_at_rh(eye, target, Vec3::from_array(camera.up));
    let near = (1e-3 * eye.distance(target)).max(1e-5);
    let proj = Mat4::perspective_infinite_reverse_rh(camera.fov_y, aspect, near);
    proj * view
}

/// Texels along each side of the shadow map, for an image of `width` x
/// `height`: the map covers about 1.5 times what the image does (see
/// `SHADOW_REACH`), so 1.5 times the image's larger side, rounded up to a
/// power of two, keeps about a texel per pixel. Clearing and filling a
/// bigger map is most of a frame's cost on a software rasteriser.
fn shadow_map_size(width: u32, height: u32, max: u32) -> u32 {
    (3 * width.max(height) / 2).next_power_of_two().clamp(512, 4096).min(max)
}

fn make_globals(camera: &CameraView, view_proj: Mat4, f: &Framing, ground: Option<f32>, shadow_size: u32) -> Globals {
    let eye = Vec3::from_array(camera.position);
    let r = f.radius;
    let to_scene = eye.distance(f.centre);
    // fog from just behind the scene to well beyond, so the plane's edge never shows
    let (fog_start, fog_end) = (to_scene + 2.0 * r, to_scene + 8.0 * r);
    // minor lines a power of ten apart, about a twentieth of the scene's width or more
    let minor = 10f32.powf((r / 2.0).log10().floor());
    let light = Vec3::from_array(LIGHT_DIRECTION).normalize();
    // the sun's view: an orthographic box around the scene, looking along the light
    let reach = SHADOW_REACH * r;
    let sun_up = up_for(-light);
    let light_view = Mat4::look_at_rh(f.centre + 2.0 * reach * light, f.centre, sun_up);
    let light_proj = Mat4::orthographic_rh(-reach, reach, -reach, reach, 0.0, 4.0 * reach);
    let texel = 2.0 * reach / shadow_size as f32;
    let bg = BACKGROUND_SRGB.map(srgb_to_linear);
    Globals {
        view_proj: view_proj.to_cols_array_2d(),
        light_view_proj: (light_proj * light_view).to_cols_array_2d(),
        eye: [eye.x, eye.y, eye.z, 1.0],
        light_dir: [light.x, light.y, light.z, 1.5 * texel],
        ground: match ground {
            Some(h) => [h, f.centre.x, f.centre.z, fog_end + to_scene],
            None => [0.0; 4],
        },
        grid: [minor, 10.0 * minor, fog_start, fog_end],
        background: [bg[0], bg[1], bg[2], 1.0],
    }
}

/// Body `index`'s colour (sRGB): hues a golden angle apart, so neighbours in
/// a scene differ and no two of the first dozen look alike; body 0 is red.
pub fn body_color(index: usize) -> [f32; 3] {
    let hue = (index as f64 * 0.618_033_988_749_895).fract() as f32;
    hsv_to_rgb(hue, 0.6, 0.9)
}

fn hsv_to_rgb(h: f32, s: f32, v: f32) -> [f32; 3] {
    let h6 = h * 6.0;
    let f = |n: f32| {
        let k = (n + h6) % 6.0;
        v - v * s * (k.min(4.0 - k).clamp(0.0, 1.0))
    };
    [f(5.0), f(3.0), f(1.0)]
}

/// sRGB-encoded to linear light (the exact piecewise curve).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A triangle wound counter-clockwise seen from outside (where its normal
/// points): the winding back-face culling keeps.
fn outward(a: Vec3, b: Vec3, c: Vec3, out: Vec3) -> [Vec3; 3] {
    if (b - a).cross(c - a).dot(out) >= 0.0 {
        [a, b, c]
    } else {
        [a, c, b]
    }
}

/// The cube [-1, 1]^3 as 12 triangles with face normals.
fn unit_cube() -> Vec<MeshVertex> {
    let mut v = Vec::with_capacity(36);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let unit = |k: usize| Vec3::AXES[k % 3];
            let (n, u, w) = (sign * unit(axis), unit(axis + 1), unit(axis + 2));
            let corner = |a: f32, b: f32| n + a * u + b * w;
            let quad = [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                for p in outward(quad[tri[0]], quad[tri[1]], quad[tri[2]], n) {
                    v.push(MeshVertex { pos: p.to_array(), normal: n.to_array() });
                }
            }
        }
    }
    v
}

/// The unit sphere: an icosahedron with each triangle split in four `level`
/// times, pushed out to the sphere, smooth normals.
fn icosphere(level: u32) -> Vec<MeshVertex> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let p = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|a| Vec3::from_array(a).normalize());
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[Vec3; 3]> = faces.iter().map(|f| [p[f[0]], p[f[1]], p[f[2]]]).collect();
    for _ in 0..level {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = ((a + b).normalize(), (b + c).normalize(), (c + a).normalize());
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    tris.into_iter()
        .flat_map(|[a, b, c]| outward(a, b, c, a + b + c))
        .map(|q| MeshVertex { pos: q.to_array(), normal: q.to_array() })
        .collect()
}

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

fn image_error(path: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::IoError(source) => io_error(path, source),
        other => io_error(path, std::io::Error::other(other)),
    }
}

/// Writes `img` as a PNG file, atomically (`output::AtomicFile`).
pub fn write_png(img: &RgbaImage, path: &Path) -> Result<(), Error> {
    let mut file = crate::output::AtomicFile::create(path)?;
    img.write_with_encoder(image::codecs::png::PngEncoder::new(file.writer())).map_err(|e| image_error(path, e))?;
    file.commit()
}

/// Writes `frames` (all of one size) as an animated GIF that loops forever,
/// each frame shown `frame_ms` milliseconds (GIF counts in hundredths of a
/// second: each frame's delay is rounded so that the frames together take
/// their whole time).
pub fn write_gif(frames: &[RgbaImage], frame_ms: f64, path: &Path) -> Result<(), Error> {
    let Some(first) = frames.first() else {
        return Err(Error::Input(format!("{}: no frames to write", path.display())));
    };
    if let Some(k) = frames.iter().position(|f| f.dimensions() != first.dimensions()) {
        return Err(Error::Input(format!(
            "{}: frame {k} is {:?} but frame 0 is {:?}; a GIF's frames share one size",
            path.display(),
            frames[k].dimensions(),
            first.dimensions()
        )));
    }
    let mut file = crate::output::AtomicFile::create(path)?;
    {
        // speed 10 of 1..30: the encoder's default balance of palette quality and time
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(file.writer(), 10);
        encoder.set_repeat(image::codecs::gif::Repeat::Infinite).map_err(|e| image_error(path, e))?;
        // a GIF keeps delays in hundredths of a second: each frame's runs
        // to where the one after it starts, rounded, so the whole plays for
        // its frames' time (a delay of 33.3 ms rounded alone is 30 ms: 1 s
        // played in 0.9 s)
        let at = |k: usize| (k as f64 * frame_ms / 10.0).round() as u32;
        let delay = |k: usize| image::Delay::from_numer_denom_ms(10 * (at(k + 1) - at(k)), 1);
        encoder
            .encode_frames(frames.iter().enumerate().map(|(k, f)| image::Frame::from_parts(f.clone(), 0, 0, delay(k))))
            .map_err(|e| image_error(path, e))?;
    }
    file.commit()
}

/// `frames` tiled into one image, `columns` to a row in order, each scaled
/// to `tile_width` pixels wide if given (keeping its aspect), with a 2-pixel
/// white gutter. Frames of different sizes get cells of the largest.
pub fn contact_sheet(frames: &[RgbaImage], columns: u32, tile_width: Option<u32>) -> Result<RgbaImage, Error> {
    if frames.is_empty() || columns == 0 {
        return Err(Error::Input("contact sheet: needs at least one frame and one column".into()));
    }
    let scaled: Vec<std::borrow::Cow<RgbaImage>> = frames
        .iter()
        .map(|f| match tile_width {
            Some(w) if w > 0 && w != f.width() => {
                let h = ((f.height() as u64 * w as u64) / f.width() as u64).max(1) as u32;
                std::borrow::Cow::Owned(image::imageops::resize(f, w, h, image::imageops::FilterType::Triangle))
            }
            _ => std::borrow::Cow::Borrowed(f),
        })
        .collect();
    const GUTTER: u32 = 2;
    let cell_w = scaled.iter().map(|f| f.width()).max().unwrap_or(1);
    let cell_h = scaled.iter().map(|f| f.height()).max().unwrap_or(1);
    let columns = columns.min(frames.len() as u32);
    let rows = (frames.len() as u32).div_ceil(columns);
    let mut sheet = RgbaImage::from_pixel(
        columns * cell_w + (columns + 1) * GUTTER,
        rows * cell_h + (rows + 1) * GUTTER,
        image::Rgba([255, 255, 255, 255]),
    );
    for (k, f) in scaled.iter().enumerate() {
        let (col, row) = (k as u32 % columns, k as u32 / columns);
        let x = GUTTER + col * (cell_w + GUTTER);
        let y = GUTTER + row * (cell_h + GUTTER);
        image::imageops::replace(&mut sheet, f.as_ref(), x as i64, y as i64);
    }
    Ok(sheet)
}
