//! What each body looks like, from the scene: its shape, size and colour
//! as the instance records the vertex shader reads, put in draw order;
//! each hull shape's mesh; each joint as its line's record; the colours of
//! a frame. Uploaded once, since the world's steps change none of it (only
//! `Renderer::set_body_color` rewrites a record).

use std::collections::HashMap;
use std::ops::Range;

use super::gpu::{JointLine, RenderBody};
use super::mesh::{hull_mesh, MeshVertex};
use crate::gpu::types::{SHAPE_BOX, SHAPE_CAPSULE, SHAPE_HULL, SHAPE_SPHERE};
use crate::scene::{Body, Scene, Shape};
use crate::world::{hull_key, local_anchor};

/// Background (sRGB): a pale sky; the ground fades into it.
pub(super) const BACKGROUND_SRGB: [f32; 3] = [0.80, 0.85, 0.90];
/// Colour of fixed bodies (sRGB): a neutral grey, the colour of "not moving".
const FIXED_SRGB: [f32; 3] = [0.55, 0.55, 0.55];

/// The bodies as drawn: one instance each, boxes first, then spheres and
/// capsules, then hulls by shape, so that each mesh (a capsule is the
/// sphere's, stretched; each hull shape has its own) is one instanced draw.
pub(super) struct Instances {
    /// In draw order: the boxes' slots, then the spheres' and capsules',
    /// then the hulls'.
    pub(super) bodies: Vec<RenderBody>,
    pub(super) box_count: u32,
    pub(super) round_count: u32,
    /// The meshes of the hull shapes, one after another.
    pub(super) hull_mesh: Vec<MeshVertex>,
    /// One per hull shape: its vertices in `hull_mesh` and its bodies' slots.
    pub(super) hull_runs: Vec<HullRun>,
    /// Each body's slot in `bodies`, by its index in the scene.
    pub(super) slot_of_body: Vec<u32>,
}

/// The bodies of one hull shape, drawn as one instanced draw of its mesh.
pub(super) struct HullRun {
    /// Its mesh's vertices, as indices into `Instances::hull_mesh`.
    pub(super) vertices: Range<u32>,
    /// Its bodies' slots in `Instances::bodies`.
    pub(super) slots: Range<u32>,
}

impl Instances {
    pub(super) fn new(scene: &Scene) -> Instances {
        let record = |i: usize, b: &Body, half_extents: [f32; 3], shape: u32| {
            let srgb = if b.fixed { FIXED_SRGB } else { body_color(i) };
            RenderBody { half_extents, body: i as u32, color: srgb.map(srgb_to_linear), shape }
        };
        let mut instances = Vec::with_capacity(scene.bodies.len());
        for round in [false, true] {
            for (i, b) in scene.bodies.iter().enumerate() {
                let (half_extents, shape) = match b.shape {
                    Shape::Box { half_extents } => (half_extents, SHAPE_BOX),
                    Shape::Sphere { radius } => ([radius; 3], SHAPE_SPHERE),
                    Shape::Capsule { radius, half_height } => ([radius, half_height, radius], SHAPE_CAPSULE),
                    Shape::Hull(_) => continue,
                };
                if (shape != SHAPE_BOX) == round {
                    instances.push(record(i, b, half_extents, shape));
                }
            }
        }
        let box_count = instances.iter().filter(|r| r.shape == SHAPE_BOX).count() as u32;
        let round_count = instances.len() as u32 - box_count;

        // bodies of one shape (and mass frame) share a mesh, as they share
        // the step's hull records
        let mut hull_mesh_vertices = Vec::new();
        let mut shapes: Vec<(Range<u32>, Vec<usize>)> = Vec::new();
        let mut shape_of: HashMap<Vec<u32>, usize> = HashMap::new();
        for (i, b) in scene.bodies.iter().enumerate() {
            let Shape::Hull(h) = &b.shape else { continue };
            let k = *shape_of.entry(hull_key(b, h)).or_insert_with(|| {
                let start = hull_mesh_vertices.len() as u32;
                hull_mesh_vertices.extend(hull_mesh(h.hull(), b.mass_frame()));
                shapes.push((start..hull_mesh_vertices.len() as u32, Vec::new()));
                shapes.len() - 1
            });
            shapes[k].1.push(i);
        }
        let mut hull_runs = Vec::with_capacity(shapes.len());
        for (vertices, members) in shapes {
            let first = instances.len() as u32;
            // the mesh is in metres already: unscaled
            instances.extend(members.into_iter().map(|i| record(i, &scene.bodies[i], [1.0; 3], SHAPE_HULL)));
            hull_runs.push(HullRun { vertices, slots: first..instances.len() as u32 });
        }

        let mut slot_of_body = vec![0u32; scene.bodies.len()];
        for (slot, r) in instances.iter().enumerate() {
            slot_of_body[r.body as usize] = slot as u32;
        }
        Instances { bodies: instances, box_count, round_count, hull_mesh: hull_mesh_vertices, hull_runs, slot_of_body }
    }
}

/// Each joint of the scene as the record of its lines, its anchors in the
/// frames the bodies' poses are kept in (`Body::mass_frame`), as the
/// state buffer holds them.
pub(super) fn joint_lines(scene: &Scene) -> Vec<JointLine> {
    let anchor = |j: &crate::scene::Joint, k: usize| local_anchor(scene, j, k);
    scene
        .joints
        .iter()
        .map(|j| JointLine { anchor_a: anchor(j, 0), body_a: j.bodies[0], anchor_b: anchor(j, 1), body_b: j.bodies[1] })
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::HullShape;

    fn hull(points: &[[f32; 3]], kinematic: bool) -> Body {
        let mut b = Body::new(Shape::Hull(HullShape::new(points.to_vec()).unwrap()), [0.0; 3]);
        b.kinematic = kinematic;
        b
    }

    /// Hulls come after the boxes and round bodies, one run per shape and
    /// mass frame, each with its own mesh; every body keeps its slot.
    #[test]
    fn hulls_are_drawn_last_one_run_a_shape() {
        let tetra = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let wedge = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let mut scene = crate::scenes::drop();
        scene.bodies = vec![
            hull(&tetra, false),
            crate::scenes::sphere_body(0.5, [3.0, 0.0, 0.0]),
            hull(&wedge, false),
            hull(&tetra, true),
            crate::scenes::box_body([0.5; 3], [6.0, 0.0, 0.0]),
            hull(&tetra, false),
        ];
        let inst = Instances::new(&scene);
        let order: Vec<u32> = inst.bodies.iter().map(|r| r.body).collect();
        assert_eq!(order, vec![4, 1, 0, 5, 2, 3]);
        assert_eq!((inst.box_count, inst.round_count), (1, 1));
        let runs: Vec<(Range<u32>, Range<u32>)> = inst.hull_runs.iter().map(|r| (r.vertices.clone(), r.slots.clone())).collect();
        // a tetrahedron is 4 triangles, the wedge 8; the kinematic one has its own mesh
        assert_eq!(runs, vec![(0..12, 2..4), (12..36, 4..5), (36..48, 5..6)]);
        assert_eq!(inst.hull_mesh.len(), 48);
        assert!(inst.bodies[2..].iter().all(|r| r.shape == SHAPE_HULL && r.half_extents == [1.0; 3]));
        for (body, &slot) in inst.slot_of_body.iter().enumerate() {
            assert_eq!(inst.bodies[slot as usize].body, body as u32);
        }
    }

    /// A joint's anchor on a hull is drawn from the hull's kept pose: its
    /// centre of mass is that frame's origin.
    #[test]
    fn joint_anchors_on_hulls_are_in_the_kept_frame() {
        let tetra = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 0.0, 1.0]];
        let mut scene = crate::scenes::drop();
        scene.bodies = vec![hull(&tetra, false), hull(&tetra, true)];
        let c = [1.25, 0.25, 0.25];
        scene.joints = vec![crate::scene::Joint { bodies: [0, 1], anchors: [c, c] }];
        let lines = joint_lines(&scene);
        assert!(lines[0].anchor_a.iter().all(|v| v.abs() < 1e-6), "{:?}", lines[0].anchor_a);
        assert_eq!(lines[0].anchor_b, c);
    }
}
