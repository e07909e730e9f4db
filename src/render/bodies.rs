//! What each body looks like, from the scene: its shape, size and colour
//! as the instance records the vertex shader reads, put in draw order;
//! each joint as its line's record; the colours of a frame. Uploaded once,
//! since the world's steps change none of it (only
//! `Renderer::set_body_color` rewrites a record).

use super::gpu::{JointLine, RenderBody};
use crate::gpu::types::{SHAPE_BOX, SHAPE_CAPSULE, SHAPE_SPHERE};
use crate::scene::{Scene, Shape};

/// Background (sRGB): a pale sky; the ground fades into it.
pub(super) const BACKGROUND_SRGB: [f32; 3] = [0.80, 0.85, 0.90];
/// Colour of fixed bodies (sRGB): a neutral grey, the colour of "not moving".
const FIXED_SRGB: [f32; 3] = [0.55, 0.55, 0.55];

/// The bodies as drawn: one instance each, boxes first, then spheres and
/// capsules, so that each mesh (a capsule is the sphere's, stretched) is
/// one instanced draw.
pub(super) struct Instances {
    /// In draw order: the boxes' slots, then the spheres' and capsules'.
    pub(super) bodies: Vec<RenderBody>,
    pub(super) box_count: u32,
    pub(super) round_count: u32,
    /// Each body's slot in `bodies`, by its index in the scene.
    pub(super) slot_of_body: Vec<u32>,
}

impl Instances {
    pub(super) fn new(scene: &Scene) -> Instances {
        let mut instances = Vec::with_capacity(scene.bodies.len());
        for round in [false, true] {
            for (i, b) in scene.bodies.iter().enumerate() {
                let (half_extents, shape) = match b.shape {
                    Shape::Box { half_extents } => (half_extents, SHAPE_BOX),
                    Shape::Sphere { radius } => ([radius; 3], SHAPE_SPHERE),
                    Shape::Capsule { radius, half_height } => ([radius, half_height, radius], SHAPE_CAPSULE),
                    // not drawn faceted yet (worlds refuse hulls until their contacts are on the GPU)
                    Shape::Hull(ref h) => ([h.hull().radius_about(h.hull().centroid) as f32; 3], SHAPE_SPHERE),
                };
                if (shape != SHAPE_BOX) == round {
                    let srgb = if b.fixed { FIXED_SRGB } else { body_color(i) };
                    instances.push(RenderBody { half_extents, body: i as u32, color: srgb.map(srgb_to_linear), shape });
                }
            }
        }
        let box_count = instances.iter().filter(|r| r.shape == SHAPE_BOX).count() as u32;
        let round_count = instances.len() as u32 - box_count;
        let mut slot_of_body = vec![0u32; scene.bodies.len()];
        for (slot, r) in instances.iter().enumerate() {
            slot_of_body[r.body as usize] = slot as u32;
        }
        Instances { bodies: instances, box_count, round_count, slot_of_body }
    }
}

/// Each joint of the scene as the record of its lines.
pub(super) fn joint_lines(scene: &Scene) -> Vec<JointLine> {
    scene
        .joints
        .iter()
        .map(|j| JointLine { anchor_a: j.anchors[0], body_a: j.bodies[0], anchor_b: j.anchors[1], body_b: j.bodies[1] })
        .collect()
}

/// Body `index`'s colour (sRGB): hues a golden angle apart, so neighbours in
/// a scene differ and no two of the first dozen look alike; body 0 is red.
pub(crate) fn body_color(index: usize) -> [f32; 3] {
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
pub(super) fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
