//! Off-screen rendering of a [`World`]: shaded bodies, the ground with a
//! grid, optional joint lines, from a fixed camera that frames the scene.
//!
//! The bodies are drawn straight from the world's current state buffer, bound
//! read-only in the vertex shader (`shaders/render.wgsl`): nothing is read
//! back to draw, only the finished image is. What never changes (each body's
//! shape, size and colour, each hull shape's mesh) is uploaded once from the
//! [`Scene`].
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
//! The parts: `gpu.rs` is the GPU plumbing (the WGSL and the records it
//! reads, the pipelines, buffers and textures, a frame's passes and the
//! readback); `camera.rs` the maths of where a frame is seen from and lit;
//! `bodies.rs` what each body looks like; `mesh.rs` the meshes;
//! `files.rs` images to files. As the step splits pipelines from buffers,
//! `RenderPipelines` holds only what is compiled (built once, in
//! [`Renderer::new`]) and `RenderData` only buffers and textures; a frame
//! allocates nothing but, the first time it sees each of a world's two
//! state buffers, a bind group for it.

mod bodies;
mod camera;
mod files;
mod gpu;
mod mesh;

pub use camera::CameraView;
pub use files::{contact_sheet, write_gif, write_png};
// For the crate's own tests: the WGSL and the records it reads, checked
// against each other.
#[doc(hidden)]
pub use gpu::{shader_source, Globals, JointLine, RenderBody};

use glam::{Mat4, Vec4};
use image::RgbaImage;

use bodies::{joint_lines, srgb_to_linear, Instances};
use camera::{choose_camera, make_globals, shadow_map_size, view_projection};
use gpu::{padded_row, Canvas};

use crate::gpu::Gpu;
use crate::scene::Scene;
use crate::world::World;
use crate::Error;

/// Choices that do not change the pipelines.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderOptions {
    /// Draw each joint as lines on top of the bodies: body A's centre to its
    /// anchor, anchor A to anchor B (magenta, the joint's error, zero-length
    /// while it holds) and anchor B to body B's centre. Off by default.
    pub draw_joints: bool,
}

/// Draws a world's bodies into an image.
pub struct Renderer {
    canvas: Canvas,
    /// `Gpu::id` of the GPU it draws on.
    gpu: u64,
    width: u32,
    height: u32,
    camera: CameraView,
    view_proj: Mat4,
    options: RenderOptions,
    body_count: usize,
    has_ground: bool,
    /// The host copy of the instance records, and each body's slot in them.
    instances: Vec<RenderBody>,
    slot_of_body: Vec<u32>,
}

impl Renderer {
    /// A renderer for `scene`'s bodies, `width` x `height` pixels, with
    /// default options (no joint lines).
    pub fn new(gpu: &Gpu, scene: &Scene, width: u32, height: u32) -> Result<Renderer, Error> {
        Renderer::with_options(gpu, scene, width, height, RenderOptions::default())
    }

    /// As [`Renderer::new`], with options. Refuses a size of 0 or beyond the
    /// device's `max_texture_dimension_2d` ([`Error::Argument`] naming
    /// `width` or `height`), before allocating anything.
    pub fn with_options(gpu: &Gpu, scene: &Scene, width: u32, height: u32, options: RenderOptions) -> Result<Renderer, Error> {
        scene.validate()?;
        let max = gpu.limits.max_texture_dimension_2d;
        for (name, v) in [("width", width), ("height", height)] {
            if v == 0 || v > max {
                let reason = format!("must be 1 to {max} pixels (this adapter's max_texture_dimension_2d), got {v}");
                return Err(Error::Argument { name, reason });
            }
        }
        let readback_size = padded_row(width) as u64 * height as u64;
        if readback_size > gpu.limits.max_buffer_size {
            let reason = format!(
                "a {width} x {height} image needs a {readback_size}-byte readback buffer, beyond this adapter's \
                 max_buffer_size of {}",
                gpu.limits.max_buffer_size
            );
            return Err(Error::Argument { name: "width", reason });
        }
        let vertex_storage = gpu.adapter.get_downlevel_capabilities().flags.contains(wgpu::DownlevelFlags::VERTEX_STORAGE);
        if !vertex_storage || gpu.limits.max_storage_buffers_per_shader_stage < 3 {
            return Err(Error::Capacity(
                "rendering reads 3 storage buffers in the vertex shader, which this adapter does not allow".into(),
            ));
        }

        let instances = Instances::new(scene);
        let joints = joint_lines(scene);
        let (camera, framing) = choose_camera(scene, width as f32 / height as f32);
        let view_proj = view_projection(&camera, width as f32 / height as f32);
        let shadow_size = shadow_map_size(width, height, max);
        let globals = make_globals(&camera, view_proj, &framing, scene.ground.as_ref().map(|g| g.height), shadow_size);
        let canvas = Canvas::new(gpu, width, height, shadow_size, &globals, &instances, &joints);
        gpu.check()?;
        Ok(Renderer {
            canvas,
            gpu: gpu.id(),
            width,
            height,
            camera,
            view_proj,
            options,
            body_count: scene.bodies.len(),
            has_ground: scene.ground.is_some(),
            instances: instances.bodies,
            slot_of_body: instances.slot_of_body,
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
    /// Refuses a body the scene lacks (naming `index`) and a channel outside
    /// 0..1 or not a number (naming `srgb[k]`), changing nothing.
    pub fn set_body_color(&mut self, index: usize, srgb: [f32; 3]) -> Result<(), Error> {
        let slot = *self
            .slot_of_body
            .get(index)
            .ok_or_else(|| Error::Input(format!("index: no body {index} (the scene has {} bodies)", self.body_count)))?;
        if let Some(k) = srgb.iter().position(|c| !(0.0..=1.0).contains(c)) {
            return Err(Error::Input(format!("srgb[{k}]: must be a number from 0 to 1, got {}", srgb[k])));
        }
        let r = &mut self.instances[slot as usize];
        r.color = srgb.map(srgb_to_linear);
        self.canvas.write_body(slot, r);
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
        if world.gpu().id() != self.gpu {
            return Err(Error::Input(
                "render: the world runs on another Gpu than the renderer was made on (make the renderer with world.gpu())".into(),
            ));
        }
        let state = (self.body_count > 0).then(|| world.current_state_buffer());
        self.canvas.draw(world.gpu(), state, self.has_ground, self.options.draw_joints)
    }
}
