//! Hull manifolds (the CPU reference a hull narrowphase will follow): two
//! convex polytopes (hulls, or boxes as hulls) told apart by their
//! separating axes, the face axes of each and the edge pairs that make a
//! face of their Minkowski difference (Gregorius's Gauss-map test, so most
//! of the edge pairs cost a few dot products); a face contact clips the
//! other's most anti-parallel face against the reference face's sides and
//! keeps up to four points, as two boxes do; an edge contact is the closest
//! points of the two edges.

use glam::{Quat, Vec2, Vec3};

use super::capsule::{nearest_along, Swept, FACE_ALIGNED, SIDE_BY_SIDE};
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
        let edges = hull.edges().into_iter().map(|[a, b, f, g]| (a, b, f, g)).collect();
        Polytope { vertices, faces, edges, centre: at + rot * hull.centroid.as_vec3() }
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

    /// The polytope moved by `by`.
    pub fn moved(&self, by: Vec3) -> Polytope {
        let mut q = self.clone();
        q.vertices.iter_mut().for_each(|v| *v += by);
        q.faces.iter_mut().for_each(|f| f.1 += f.0.dot(by));
        q.centre += by;
        q
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

/// The best edge axis: its separation, normal (from a to b) and the edges;
/// b's edges outside, a's inside, as the GPU takes them (the first of
/// equals wins).
fn best_edges(a: &Polytope, b: &Polytope) -> (f32, Vec3, usize, usize) {
    let mut best = (f32::MIN, Vec3::Y, 0, 0);
    for (j, &(b0, b1, fb, gb)) in b.edges.iter().enumerate() {
        let eb = b.vertices[b1] - b.vertices[b0];
        for (i, &(a0, a1, fa, ga)) in a.edges.iter().enumerate() {
            if !minkowski_face(a.faces[fa].0, a.faces[ga].0, b.faces[fb].0, b.faces[gb].0) {
                continue;
            }
            let ea = a.vertices[a1] - a.vertices[a0];
            let l = ea.cross(eb);
            let len = l.length();
            if len < 1e-5 * ea.length() * eb.length() {
                continue;
            }
            // outward from a at its edge: between the edge's face normals
            let mut l = l / len;
            if l.dot(a.faces[fa].0 + a.faces[ga].0) < 0.0 {
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
    let sep = sep_a.max(sep_b).max(sep_e);
    if sep > margin {
        return None;
    }
    let m = hull_manifold(a, b, margin, (sep_a, face_a), (sep_b, face_b), (sep_e, normal_e, edge_a, edge_b))?;
    // the axes' separation is only a lower bound on the distance (two
    // corners nearest each other are farther apart than any axis says):
    // where they say apart, a pair whose points are all beyond the margin is
    if sep > 0.0 && m.points.iter().all(|p| (p.on_b - p.on_a).length() > margin) {
        return None;
    }
    Some(m)
}

/// The manifold the axes choose: a face contact unless an edge pair's axis
/// beats the faces by `EDGE_BIAS`.
fn hull_manifold(
    a: &Polytope,
    b: &Polytope,
    margin: f32,
    (sep_a, face_a): (f32, usize),
    (sep_b, face_b): (f32, usize),
    (sep_e, normal_e, edge_a, edge_b): (f32, Vec3, usize, usize),
) -> Option<Manifold> {
    let best_face_sep = sep_a.max(sep_b);
    // b's face must beat a's by FACE_BIAS to be the reference (as for boxes)
    let flipped = sep_b > sep_a + FACE_BIAS;
    let (reference, incident, face) = if flipped { (b, a, face_b) } else { (a, b, face_a) };
    let edge = sep_e > best_face_sep + EDGE_BIAS;
    let mut points = if edge { Vec::new() } else { face_contact(reference, face, incident, margin) };
    if points.is_empty() && !edge {
        // the other's face lies past the reference face's sides: its corner
        // deepest along the face's normal, against the face's nearest point
        let (n, d, _) = &reference.faces[face];
        let deepest = incident.vertices.iter().copied().min_by(|p, q| n.dot(*p).total_cmp(&n.dot(*q))).expect("corners");
        points = vec![(nearest_on_face(reference, face, deepest - *n * (n.dot(deepest) - d)), deepest)];
    }
    if points.is_empty() {
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

/// The point of face `face` of `p` nearest `x`, a point in its plane: `x`
/// where it lies within the face, else the nearest point of its sides.
fn nearest_on_face(p: &Polytope, face: usize, x: Vec3) -> Vec3 {
    let (n, _, corners) = &p.faces[face];
    let side = |k: usize| (p.vertices[corners[k]], p.vertices[corners[(k + 1) % corners.len()]]);
    if (0..corners.len()).all(|k| {
        let (a, b) = side(k);
        (b - a).cross(x - a).dot(*n) >= 0.0
    }) {
        return x;
    }
    (0..corners.len())
        .map(|k| {
            let (a, b) = side(k);
            let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            a + (b - a) * t
        })
        .min_by(|p, q| (*p - x).length_squared().total_cmp(&(*q - x).length_squared()))
        .expect("a face has sides")
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
    reduce(candidates, None)
        .into_iter()
        .map(|(at, height)| {
            let on_ref = u * at.x + v * at.y + *n * *d;
            (on_ref, on_ref + *n * height)
        })
        .collect()
}

/// The point of `p` nearest `x` (x itself inside): a face's where x's foot
/// on its plane lies within it, else the nearest point of an edge.
pub fn nearest_on_hull(p: &Polytope, x: Vec3) -> Vec3 {
    let mut inside = true;
    let (mut best, mut best_d2) = (x, f32::MAX);
    for (f, (n, d, _)) in p.faces.iter().enumerate() {
        let above = n.dot(x) - d;
        if above > 0.0 {
            inside = false;
            let foot = x - *n * above;
            if above * above < best_d2 && within_face(p, f, foot) {
                (best, best_d2) = (foot, above * above);
            }
        }
    }
    if inside {
        return x;
    }
    for &(i, j, _, _) in &p.edges {
        let (a, b) = (p.vertices[i], p.vertices[j]);
        let on_edge = a + (b - a) * ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        let d2 = (on_edge - x).length_squared();
        if d2 < best_d2 {
            (best, best_d2) = (on_edge, d2);
        }
    }
    best
}

/// Whether `x`, a point in the plane of face `face`, lies within the face.
fn within_face(p: &Polytope, face: usize, x: Vec3) -> bool {
    let (n, _, corners) = &p.faces[face];
    (0..corners.len()).all(|k| {
        let (a, b) = (p.vertices[corners[k]], p.vertices[corners[(k + 1) % corners.len()]]);
        (b - a).cross(x - a).dot(*n) >= 0.0
    })
}

/// A round shape against face `face` of `p`: its segment clipped to the
/// face's sides, each end of what is left a point (on the face, on the
/// round shape) if within `margin`; the normal is the face's.
fn face_points(p: &Polytope, face: usize, round: &Swept, margin: f32) -> Vec<ContactPoint> {
    let (n, d, corners) = &p.faces[face];
    let (l, r) = (round.half_length, round.radius);
    let p0 = round.centre - round.dir * l;
    let e = round.dir * (2.0 * l);
    let (mut enter, mut leave) = (0.0f32, 1.0f32);
    for k in 0..corners.len() {
        let (a, b) = (p.vertices[corners[k]], p.vertices[corners[(k + 1) % corners.len()]]);
        let side = (b - a).cross(*n);
        let (start, rate) = (side.dot(p0 - a), side.dot(e));
        if rate == 0.0 {
            if start > 0.0 {
                leave = -1.0;
            }
        } else if rate < 0.0 {
            enter = enter.max(-start / rate);
        } else {
            leave = leave.min(-start / rate);
        }
    }
    if enter > leave {
        return Vec::new();
    }
    let two = (leave - enter) * 2.0 * l > SIDE_BY_SIDE * r;
    let ts = if two { vec![enter, leave] } else { vec![0.5 * (enter + leave)] };
    ts.into_iter()
        .map(|t| p0 + e * t)
        .filter(|q| n.dot(*q) - d - r <= margin)
        .map(|q| ContactPoint { on_a: q - *n * (n.dot(q) - d), on_b: q - *n * r })
        .collect()
}

/// A hull first, a sphere or capsule second (normal from the hull), as
/// `box_capsule`: the hull's face axes and its edges crossed with the
/// segment; where the segment misses the hull, its nearest point says which
/// feature meets it, and a capsule lying on a face rests on the ends of its
/// segment clipped to the face.
pub fn hull_round(p: &Polytope, round: &Swept, margin: f32) -> Option<Manifold> {
    // about the hull's centre, as the GPU works in its frame: far from the
    // origin, f32 would blur the flat least the search along the segment seeks
    let o = p.centre;
    let near = p.moved(-o);
    let m = hull_round_near(&near, &Swept { centre: round.centre - o, ..*round }, margin)?;
    let points = m.points.iter().map(|q| ContactPoint { on_a: q.on_a + o, on_b: q.on_b + o }).collect();
    Some(Manifold { normal: m.normal, points })
}

fn hull_round_near(p: &Polytope, round: &Swept, margin: f32) -> Option<Manifold> {
    let (c, d, l, r) = (round.centre, round.dir, round.half_length, round.radius);
    let (mut face_sep, mut face) = (f32::MIN, 0);
    for (f, (n, off, _)) in p.faces.iter().enumerate() {
        let sep = n.dot(c) - n.dot(d).abs() * l - off;
        if sep > face_sep {
            (face_sep, face) = (sep, f);
        }
    }
    // the segment's edge axes: where the edge's arc crosses the circle square to it
    let (mut edge_sep, mut edge, mut edge_n) = (f32::MIN, 0, Vec3::Y);
    if l > 0.0 {
        for (e, &(i, j, f1, f2)) in p.edges.iter().enumerate() {
            let (n1, n2) = (p.faces[f1].0, p.faces[f2].0);
            if n1.dot(d) * n2.dot(d) >= 0.0 {
                continue;
            }
            let along = p.vertices[j] - p.vertices[i];
            let axis = along.cross(d);
            let len = axis.length();
            if len < 1e-5 * along.length() {
                continue;
            }
            let n = if axis.dot(n1 + n2) < 0.0 { -axis } else { axis } / len;
            let sep = n.dot(c - p.vertices[i]);
            if sep > edge_sep {
                (edge_sep, edge, edge_n) = (sep, e, n);
            }
        }
    }
    let worst = face_sep.max(edge_sep);
    if worst - r > margin {
        return None;
    }
    let t = if l > 0.0 { nearest_along(c, d, l, |x| (nearest_on_hull(p, x) - x).length_squared()) } else { 0.0 };
    let on_seg = c + d * t;
    let on_hull = nearest_on_hull(p, on_seg);
    let out = on_seg - on_hull;
    let dist = out.length();
    let misses = worst > 0.0 && dist > 1e-6;
    if misses && dist - r > margin {
        return None;
    }
    let mut n = out / dist.max(1e-30);
    // where it misses, the face its nearest point looks out of, if nearly
    // square to it; else the face of least overlap, unless an edge's
    let (mut aligned, mut near_face) = (-2.0f32, 0);
    for (f, (nf, _, _)) in p.faces.iter().enumerate() {
        if nf.dot(n) > aligned {
            (aligned, near_face) = (nf.dot(n), f);
        }
    }
    let k = if misses { near_face } else { face };
    let along_edge = !misses && edge_sep > face_sep + EDGE_BIAS;
    let mut points =
        if (misses && aligned >= FACE_ALIGNED) || (!misses && !along_edge) { face_points(p, k, round, margin) } else { Vec::new() };
    let (nk, dk, _) = &p.faces[k];
    if !points.is_empty() || !misses {
        n = *nk;
    }
    if misses && points.is_empty() {
        points.push(ContactPoint { on_a: on_hull, on_b: on_seg - n * r });
    }
    if !misses && !along_edge && points.is_empty() {
        // the segment crosses the face's plane beside the face: its end
        // deepest along the normal, against the face's point nearest its foot
        let low = if n.dot(d) > 0.0 { c - d * l } else { c + d * l };
        points.push(ContactPoint { on_a: nearest_on_face(p, k, low - n * (n.dot(low) - dk)), on_b: low - n * r });
    }
    if along_edge {
        n = edge_n;
        let (i, j, _, _) = p.edges[edge];
        let (a, b) = (p.vertices[i], p.vertices[j]);
        let (on_edge, on_segment) = closest_on_edges((a + b) * 0.5, (b - a).normalize(), (b - a).length() * 0.5, c, d, l);
        points = vec![ContactPoint { on_a: on_edge, on_b: on_segment - n * r }];
    }
    Some(Manifold { normal: n, points })
}

/// A hull's contact with the ground at height `ground` within `margin`,
/// normal from the hull down: its corners within the margin, reduced to
/// four as a face contact's. The GPU chooses the four by the heights the
/// step's motion brings them to; for a hull at rest, as here, by the same.
pub fn ground_hull(p: &Polytope, ground: f32, margin: f32) -> Option<Manifold> {
    let near: Vec<Vec3> = p.vertices.iter().copied().filter(|w| w.y - ground <= margin).collect();
    if near.is_empty() {
        return None;
    }
    let candidates = near.iter().map(|w| (Vec2::new(w.z, w.x), w.y - ground)).collect();
    let points = reduce(candidates, Some(Vec2::new(p.centre.z, p.centre.x)))
        .into_iter()
        .map(|(at, height)| {
            let on_b = Vec3::new(at.y, ground, at.x);
            ContactPoint { on_a: on_b + Vec3::Y * height, on_b }
        })
        .collect();
    Some(Manifold { normal: -Vec3::Y, points })
}
