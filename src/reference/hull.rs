//! Hull manifolds (the CPU reference a hull narrowphase will follow): two
//! convex polytopes (hulls, or boxes as hulls) told apart by their
//! separating axes, the face axes of each and the edge pairs that make a
//! face of their Minkowski difference (Gregorius's Gauss-map test, so most
//! of the edge pairs cost a few dot products); a face contact clips the
//! other's most anti-parallel face against the reference face's sides and
//! keeps up to four points, as two boxes do; an edge contact is the closest
//! points of the two edges.
// The elimination indexes rows and columns by number, as written.
#![allow(clippy::needless_range_loop)]

use glam::{DVec3, Quat, Vec2, Vec3};

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
    let sep = sep_a.max(sep_b).max(sep_e);
    // the axes' separation is the true distance's lower bound (two corners
    // nearest each other are farther apart): where they say apart, the
    // distance itself decides
    if sep > margin || (sep > 0.0 && distance(&a.vertices, &b.vertices) > margin) {
        return None;
    }
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
    reduce(candidates)
        .into_iter()
        .map(|(at, height)| {
            let on_ref = u * at.x + v * at.y + *n * *d;
            (on_ref, on_ref + *n * height)
        })
        .collect()
}

/// The least distance between the convex hulls of two sets of points (0
/// where they overlap), by GJK: the point of the Minkowski difference
/// nearest the origin, approached by simplices of its support points.
pub fn distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    let support = |d: DVec3| {
        let far =
            |set: &[Vec3], d: DVec3| set.iter().map(|p| p.as_dvec3()).max_by(|p, q| p.dot(d).total_cmp(&q.dot(d))).expect("points");
        far(a, d) - far(b, -d)
    };
    let mut simplex = vec![support(DVec3::X)];
    let mut v = simplex[0];
    for _ in 0..64 {
        let vv = v.length_squared();
        if vv < 1e-18 {
            return 0.0;
        }
        let w = support(-v);
        // no support point nearer the origin along -v: v is the nearest
        if vv - v.dot(w) <= 1e-9 * vv || simplex.iter().any(|p| (*p - w).length_squared() < 1e-24) {
            break;
        }
        simplex.push(w);
        (v, simplex) = nearest_on_simplex(&simplex);
    }
    v.length() as f32
}

/// The point of a simplex (1 to 4 points) nearest the origin, and the
/// smallest face of it that holds that point: over every face, the nearest
/// point of its affine hull, kept where it lies within the face.
fn nearest_on_simplex(points: &[DVec3]) -> (DVec3, Vec<DVec3>) {
    let mut best: Option<(f64, DVec3, Vec<DVec3>)> = None;
    for mask in 1u32..(1 << points.len()) {
        let face: Vec<DVec3> = (0..points.len()).filter(|k| mask & (1 << k) != 0).map(|k| points[k]).collect();
        let Some(x) = nearest_in_face(&face) else { continue };
        let d = x.length_squared();
        // fewer points for equal distances: the smallest face that holds it
        if best.as_ref().is_none_or(|(bd, _, bf)| d < bd - 1e-18 || (d <= bd + 1e-18 && face.len() < bf.len())) {
            best = Some((d, x, face));
        }
    }
    let (_, x, face) = best.expect("a single point is always its own face");
    (x, face)
}

/// The nearest point to the origin of the affine hull of `face`, where it
/// lies within `face` (its weights all at least 0); None otherwise.
fn nearest_in_face(face: &[DVec3]) -> Option<DVec3> {
    let p0 = face[0];
    let e: Vec<DVec3> = face[1..].iter().map(|p| *p - p0).collect();
    let k = e.len();
    // the normal equations G mu = -E^T p0, k <= 3, by Gaussian elimination
    let mut m = [[0.0f64; 4]; 3];
    for i in 0..k {
        for j in 0..k {
            m[i][j] = e[i].dot(e[j]);
        }
        m[i][3] = -e[i].dot(p0);
    }
    for c in 0..k {
        let pivot = (c..k).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[pivot][c].abs() < 1e-18 {
            return None;
        }
        m.swap(c, pivot);
        for r in 0..k {
            if r != c {
                let f = m[r][c] / m[c][c];
                for col in c..4 {
                    m[r][col] -= f * m[c][col];
                }
            }
        }
    }
    let mu: Vec<f64> = (0..k).map(|i| m[i][3] / m[i][i]).collect();
    let first = 1.0 - mu.iter().sum::<f64>();
    if first < -1e-9 || mu.iter().any(|&w| w < -1e-9) {
        return None;
    }
    Some(p0 + e.iter().zip(&mu).map(|(d, w)| *d * *w).sum::<DVec3>())
}
