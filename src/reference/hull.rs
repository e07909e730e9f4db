//! Hull manifolds (the CPU reference a hull narrowphase will follow): two
//! convex polytopes (hulls, or boxes as hulls) told apart by their
//! separating axes, the face axes of each and the edge pairs that make a
//! face of their Minkowski difference (Gregorius's Gauss-map test, so most
//! of the edge pairs cost a few dot products); a face contact clips the
//! other's most anti-parallel face against the reference face's sides and
//! keeps up to four points, as two boxes do; an edge contact is the closest
//! points of the two edges.

use glam::{Quat, Vec2, Vec3};

use super::collide::{closest_on_edges, reduce, ContactPoint, Manifold, EDGE_BIAS, FACE_BIAS};
use crate::scene::hull::Hull;

/// A convex polytope placed in the world: its corners, its faces (outward
/// normal, plane offset, corners counter-clockwise seen from outside) and
/// its edges (two corners and the two faces that meet there).
#[derive(Clone, Debug)]
pub struct Polytope {
    pub vertices: Vec<Vec3>,
    pub faces: Vec<(Vec3, f32, Vec<usize>)>,
    pub edges: Vec<(usize, usize, usize, usize)>,
    pub centre: Vec3,
}

impl Polytope {
    /// `hull`, its frame turned by `rot` and moved to `at`.
    pub fn from_hull(hull: &Hull, at: Vec3, rot: Quat) -> Polytope {
        let vertices = hull.vertices.iter().map(|v| at + rot * v.as_vec3()).collect();
        let faces = hull
            .faces
            .iter()
            .map(|f| {
                let n = rot * f.normal.as_vec3();
                (n, n.dot(at) + f.offset as f32, f.corners.clone())
            })
            .collect();
        Polytope::with_edges(vertices, faces, at + rot * hull.centroid.as_vec3())
    }

    /// A box of half extents `h` at `at`, turned by `rot`.
    pub fn from_box(h: Vec3, at: Vec3, rot: Quat) -> Polytope {
        let points: Vec<[f32; 3]> = (0..8)
            .map(|k| {
                let s = |bit: u32, v: f32| if k & bit == 0 { -v } else { v };
                [s(1, h.x), s(2, h.y), s(4, h.z)]
            })
            .collect();
        Polytope::from_hull(&Hull::new(&points).expect("a box spans a volume"), at, rot)
    }

    fn with_edges(vertices: Vec<Vec3>, faces: Vec<(Vec3, f32, Vec<usize>)>, centre: Vec3) -> Polytope {
        // each edge once, from the face that walks it from its lower corner
        let mut edges = Vec::new();
        for (f, (_, _, corners)) in faces.iter().enumerate() {
            for k in 0..corners.len() {
                let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
                if a < b {
                    let other = faces
                        .iter()
                        .position(|(_, _, c)| (0..c.len()).any(|j| c[j] == b && c[(j + 1) % c.len()] == a))
                        .expect("a closed hull: every edge has a face on each side");
                    edges.push((a, b, f, other));
                }
            }
        }
        Polytope { vertices, faces, edges, centre }
    }

    /// The least of `n . v` over the corners: how far the polytope reaches
    /// against n.
    fn lowest_along(&self, n: Vec3) -> f32 {
        self.vertices.iter().map(|v| n.dot(*v)).fold(f32::MAX, f32::min)
    }
}

/// The best face axis of `a` against `b`: its separation and the face.
fn best_face(a: &Polytope, b: &Polytope) -> (f32, usize) {
    let mut best = (f32::MIN, 0);
    for (k, (n, d, _)) in a.faces.iter().enumerate() {
        let sep = b.lowest_along(*n) - d;
        if sep > best.0 {
            best = (sep, k);
        }
    }
    best
}

/// Whether the arcs of two edges' face normals on the unit sphere (a's
/// `a1` to `a2`, b's negated) cross: then their cross product is a face of
/// the Minkowski difference, and a candidate axis.
fn minkowski_face(a1: Vec3, a2: Vec3, b1: Vec3, b2: Vec3) -> bool {
    let (c, d) = (-b1, -b2);
    let bxa = a2.cross(a1);
    let dxc = d.cross(c);
    let cba = c.dot(bxa);
    let dba = d.dot(bxa);
    let adc = a1.dot(dxc);
    let bdc = a2.dot(dxc);
    cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
}

/// The best edge axis: its separation, normal (from a to b) and the edges.
fn best_edges(a: &Polytope, b: &Polytope) -> (f32, Vec3, usize, usize) {
    let mut best = (f32::MIN, Vec3::Y, 0, 0);
    for (i, &(a0, a1, fa, ga)) in a.edges.iter().enumerate() {
        let ea = a.vertices[a1] - a.vertices[a0];
        for (j, &(b0, b1, fb, gb)) in b.edges.iter().enumerate() {
            if !minkowski_face(a.faces[fa].0, a.faces[ga].0, b.faces[fb].0, b.faces[gb].0) {
                continue;
            }
            let eb = b.vertices[b1] - b.vertices[b0];
            let l = ea.cross(eb);
            let len = l.length();
            if len < 1e-5 * ea.length() * eb.length() {
                continue;
            }
            let mut l = l / len;
            if l.dot(a.vertices[a0] - a.centre) < 0.0 {
                l = -l;
            }
            let sep = l.dot(b.vertices[b0] - a.vertices[a0]);
            if sep > best.0 {
                best = (sep, l, i, j);
            }
        }
    }
    best
}

/// The manifold of two polytopes within `margin` (normal from a to b), or
/// None where a separating axis keeps them more than `margin` apart.
pub fn hull_hull(a: &Polytope, b: &Polytope, margin: f32) -> Option<Manifold> {
    let (sep_a, face_a) = best_face(a, b);
    let (sep_b, face_b) = best_face(b, a);
    let (sep_e, normal_e, edge_a, edge_b) = best_edges(a, b);
    if sep_a.max(sep_b).max(sep_e) > margin {
        return None;
    }
    let best_face_sep = sep_a.max(sep_b);
    // b's face must beat a's by FACE_BIAS to be the reference (as for boxes)
    let flipped = sep_b > sep_a + FACE_BIAS;
    let (reference, incident, face) = if flipped { (b, a, face_b) } else { (a, b, face_a) };
    let points = if sep_e > best_face_sep + EDGE_BIAS { Vec::new() } else { face_contact(reference, face, incident, margin) };
    if points.is_empty() {
        // an edge contact, or a face contact whose clipping kept nothing (the
        // other's face lies past the reference face's sides): the edges meet
        if sep_e == f32::MIN {
            return None;
        }
        let (a0, a1, _, _) = a.edges[edge_a];
        let (b0, b1, _, _) = b.edges[edge_b];
        let segment = |p: &Polytope, i: usize, j: usize| {
            let (s, e) = (p.vertices[i], p.vertices[j]);
            ((s + e) * 0.5, (e - s).normalize(), (e - s).length() * 0.5)
        };
        let ((ca, da, la), (cb, db, lb)) = (segment(a, a0, a1), segment(b, b0, b1));
        let (on_a, on_b) = closest_on_edges(ca, da, la, cb, db, lb);
        return Some(Manifold { normal: normal_e, points: vec![ContactPoint { on_a, on_b }] });
    }
    let n = reference.faces[face].0;
    let points = points
        .into_iter()
        .map(
            |(on_ref, on_inc)| {
                if flipped {
                    ContactPoint { on_a: on_inc, on_b: on_ref }
                } else {
                    ContactPoint { on_a: on_ref, on_b: on_inc }
                }
            },
        )
        .collect();
    Some(Manifold { normal: if flipped { -n } else { n }, points })
}

/// The points of a face contact: `incident`'s face most anti-parallel to
/// the reference face clipped against the reference face's sides, those
/// within `margin` of its plane, reduced to four; each as (on the
/// reference face, on the incident one).
fn face_contact(reference: &Polytope, face: usize, incident: &Polytope, margin: f32) -> Vec<(Vec3, Vec3)> {
    let (n, d, corners) = &reference.faces[face];
    let inc = (0..incident.faces.len())
        .min_by(|&i, &j| incident.faces[i].0.dot(*n).total_cmp(&incident.faces[j].0.dot(*n)))
        .expect("a hull has faces");
    let mut polygon: Vec<Vec3> = incident.faces[inc].2.iter().map(|&k| incident.vertices[k]).collect();
    // Sutherland-Hodgman against each side plane of the reference face
    for k in 0..corners.len() {
        let (p, q) = (reference.vertices[corners[k]], reference.vertices[corners[(k + 1) % corners.len()]]);
        let side = (q - p).cross(*n);
        let offset = side.dot(p);
        let mut kept = Vec::with_capacity(polygon.len() + 1);
        for i in 0..polygon.len() {
            let (s, e) = (polygon[i], polygon[(i + 1) % polygon.len()]);
            let (ds, de) = (side.dot(s) - offset, side.dot(e) - offset);
            if ds <= 0.0 {
                kept.push(s);
            }
            if (ds <= 0.0) != (de <= 0.0) {
                kept.push(s + (e - s) * (ds / (ds - de)));
            }
        }
        polygon = kept;
        if polygon.is_empty() {
            return Vec::new();
        }
    }
    // in the reference face's plane: coordinates and heights above it
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let candidates: Vec<(Vec2, f32)> =
        polygon.iter().map(|p| (Vec2::new(p.dot(u), p.dot(v)), n.dot(*p) - d)).filter(|&(_, height)| height <= margin).collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    reduce(candidates)
        .into_iter()
        .map(|(at, height)| {
            let on_ref = u * at.x + v * at.y + *n * *d;
            (on_ref, on_ref + *n * height)
        })
        .collect()
}
