//! Narrowphase reference (twin of `shaders/collide.wgsl`): contact
//! manifolds between boxes and spheres, and the capsules' (`capsule.rs`)
//! and hulls' (`hull.rs`) by the same rules.
//!
//! A manifold has one normal `n`, pointing from the first shape to the
//! second, and up to `MAX_POINTS` pairs of points (`on_a`, `on_b`) in world
//! space. Its separation `dot(on_b - on_a, n)` is negative where the shapes
//! overlap; pairs up to `margin` apart are kept too (speculative contacts).
// Loops index the box axes by number, as the WGSL twin does, step for step.
#![allow(clippy::needless_range_loop)]

use glam::{Mat3, Quat, Vec2, Vec3};

use std::sync::Arc;

use super::capsule::{box_capsule, round_round, Swept};
use super::hull::{hull_hull, hull_round, Polytope};
use crate::scene::hull::Hull;
use crate::scene::{Body, Shape};

/// Points kept per pair: the clipped polygon (up to 8) is reduced to 4.
pub const MAX_POINTS: usize = 4;

/// A shape placed in the world.
#[derive(Clone, Debug)]
pub struct Placed {
    pub centre: Vec3,
    pub rot: Quat,
    pub shape: ShapeKind,
}

#[derive(Clone, Debug)]
pub enum ShapeKind {
    Box(Vec3),
    Sphere(f32),
    Capsule {
        radius: f32,
        half_height: f32,
    },
    /// A hull, placed in the body's frame at `at` and turned by `rot`.
    Hull {
        hull: Arc<Hull>,
        at: Vec3,
        rot: Quat,
    },
}

/// A shape in its body's own frame (the one the scene places).
impl From<&Shape> for ShapeKind {
    fn from(shape: &Shape) -> ShapeKind {
        match *shape {
            Shape::Box { half_extents } => ShapeKind::Box(Vec3::from(half_extents)),
            Shape::Sphere { radius } => ShapeKind::Sphere(radius),
            Shape::Capsule { radius, half_height } => ShapeKind::Capsule { radius, half_height },
            Shape::Hull(ref h) => ShapeKind::Hull { hull: h.hull_arc(), at: Vec3::ZERO, rot: Quat::IDENTITY },
        }
    }
}

impl ShapeKind {
    /// A body's shape in the frame the simulation keeps its pose in
    /// (`Body::mass_frame`): a hull's moved into it.
    pub fn kept(body: &Body) -> ShapeKind {
        match (&body.shape, body.mass_frame()) {
            (Shape::Hull(h), Some((centre, axes))) => {
                let rot = axes.conjugate();
                ShapeKind::Hull { hull: h.hull_arc(), at: (rot * -centre).as_vec3(), rot: rot.as_quat() }
            }
            (shape, _) => ShapeKind::from(shape),
        }
    }
}

impl Placed {
    /// A round shape as a segment swept by its radius; None for a box or hull.
    fn swept(&self) -> Option<Swept> {
        match self.shape {
            ShapeKind::Sphere(r) => Some(Swept::sphere(self.centre, r)),
            ShapeKind::Capsule { radius, half_height } => Some(Swept::capsule(self.centre, self.rot, radius, half_height)),
            _ => None,
        }
    }

    /// A box or hull as a polytope in the world; None for a round shape.
    pub fn polytope(&self) -> Option<Polytope> {
        match &self.shape {
            ShapeKind::Box(h) => Some(Polytope::from_box(*h, self.centre, self.rot)),
            ShapeKind::Hull { hull, at, rot } => Some(Polytope::from_hull(hull, self.centre + self.rot * *at, self.rot * *rot)),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    pub on_a: Vec3,
    pub on_b: Vec3,
}

impl ContactPoint {
    pub fn separation(&self, n: Vec3) -> f32 {
        (self.on_b - self.on_a).dot(n)
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Manifold {
    pub normal: Vec3,
    pub points: Vec<ContactPoint>,
}

/// An edge axis must beat the best face axis by this much (m) to be chosen:
/// faces give stable multi-point manifolds, edges one point (Box2D prefers
/// faces by its linear slop, 5 mm, likewise). Depths can thus exceed the
/// true overlap by at most this.
pub const EDGE_BIAS: f32 = 0.005;

/// The second box's best face axis must beat the first's by this much (m) to
/// give the reference face. Two nearly parallel faces (a box lying tilted on
/// another) otherwise take turns from step to step, and their manifolds
/// differ (each clips the other's face to its own): a lower leg lying across
/// four piled boxes rocked at 5 cm/s for good. Box3D prefers the first
/// hull's face by half its linear slop likewise.
pub const FACE_BIAS: f32 = 0.0025;

/// The manifold between `a` and `b`, or None when they are more than
/// `margin` apart.
pub fn collide(a: &Placed, b: &Placed, margin: f32) -> Option<Manifold> {
    match (a.shape.clone(), b.shape.clone()) {
        (ShapeKind::Hull { .. }, _) | (_, ShapeKind::Hull { .. }) => match (a.swept(), b.swept()) {
            (None, None) => hull_hull(&a.polytope()?, &b.polytope()?, margin),
            (None, Some(round)) => hull_round(&a.polytope()?, &round, margin),
            (Some(round), _) => hull_round(&b.polytope()?, &round, margin).map(|m| flip(&m)),
        },
        (ShapeKind::Sphere(ra), ShapeKind::Sphere(rb)) => sphere_sphere(a.centre, ra, b.centre, rb, margin),
        (ShapeKind::Box(h), ShapeKind::Sphere(r)) => box_sphere(a.centre, a.rot, h, b.centre, r, margin),
        (ShapeKind::Sphere(r), ShapeKind::Box(h)) => box_sphere(b.centre, b.rot, h, a.centre, r, margin).map(|m| flip(&m)),
        (ShapeKind::Box(ha), ShapeKind::Box(hb)) => box_box(a.centre, a.rot, ha, b.centre, b.rot, hb, margin),
        (ShapeKind::Box(h), ShapeKind::Capsule { .. }) => box_capsule(a.centre, a.rot, h, &b.swept()?, margin),
        (ShapeKind::Capsule { .. }, ShapeKind::Box(h)) => box_capsule(b.centre, b.rot, h, &a.swept()?, margin).map(|m| flip(&m)),
        (ShapeKind::Capsule { .. }, _) | (_, ShapeKind::Capsule { .. }) => round_round(&a.swept()?, &b.swept()?, margin),
    }
}

fn flip(m: &Manifold) -> Manifold {
    Manifold { normal: -m.normal, points: m.points.iter().map(|p| ContactPoint { on_a: p.on_b, on_b: p.on_a }).collect() }
}

pub(crate) fn sphere_sphere(ca: Vec3, ra: f32, cb: Vec3, rb: f32, margin: f32) -> Option<Manifold> {
    let d = cb - ca;
    let dist = d.length();
    if dist - ra - rb > margin {
        return None;
    }
    let n = if dist > 1e-6 { d / dist } else { Vec3::Y };
    Some(Manifold { normal: n, points: vec![ContactPoint { on_a: ca + n * ra, on_b: cb - n * rb }] })
}

/// Box first, sphere second: the normal points from the box to the sphere.
pub(crate) fn box_sphere(cb: Vec3, rot: Quat, h: Vec3, cs: Vec3, r: f32, margin: f32) -> Option<Manifold> {
    let local = rot.conjugate() * (cs - cb);
    let closest = local.clamp(-h, h);
    let outside = local - closest;
    let dist = outside.length();
    let (n_local, on_box_local) = if dist > 1e-6 {
        (outside / dist, closest)
    } else {
        // centre inside the box: leave through the nearest face
        let room = h - local.abs();
        let k = if room.x <= room.y && room.x <= room.z {
            0
        } else if room.y <= room.z {
            1
        } else {
            2
        };
        let sign = if local[k] >= 0.0 { 1.0 } else { -1.0 };
        let mut n = Vec3::ZERO;
        n[k] = sign;
        let mut p = local;
        p[k] = sign * h[k];
        (n, p)
    };
    let n = rot * n_local;
    let on_box = cb + rot * on_box_local;
    let on_sphere = cs - n * r;
    if (on_sphere - on_box).dot(n) > margin {
        return None;
    }
    Some(Manifold { normal: n, points: vec![ContactPoint { on_a: on_box, on_b: on_sphere }] })
}

/// Separating axes, then clipping of the incident face against the
/// reference face's sides, reduced to at most four points.
pub fn box_box(ca: Vec3, qa: Quat, ha: Vec3, cb: Vec3, qb: Quat, hb: Vec3, margin: f32) -> Option<Manifold> {
    let ra = Mat3::from_quat(qa);
    let rb = Mat3::from_quat(qb);
    let axes_a = [ra.x_axis, ra.y_axis, ra.z_axis];
    let axes_b = [rb.x_axis, rb.y_axis, rb.z_axis];
    let d = cb - ca;
    // everything in a's frame: column j of r is b's axis j, t is b's centre
    let r = ra.transpose() * rb;
    let ar = Mat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
    let t = ra.transpose() * d;

    // face axes of a (0..3) and b (3..6): separation, signed offset along the axis
    let sep_a = t.abs() - ha - ar * hb;
    let s_b = r.transpose() * t;
    let sep_b = s_b.abs() - ar.transpose() * ha - hb;
    // the best face of each (the first of equals); b's is the reference face
    // only if it beats a's by FACE_BIAS
    let first_best = |s: Vec3| {
        if s.x >= s.y && s.x >= s.z {
            0
        } else if s.y >= s.z {
            1
        } else {
            2
        }
    };
    let (a_sep, b_sep) = (sep_a.max_element(), sep_b.max_element());
    let face_k = if b_sep > a_sep + FACE_BIAS { 3 + first_best(sep_b) } else { first_best(sep_a) };
    let best_face = (a_sep.max(b_sep), face_k);
    let mut worst = best_face.0;
    let (face_s, face_axis) = if face_k < 3 { (t[face_k], axes_a[face_k]) } else { (s_b[face_k - 3], axes_b[face_k - 3]) };
    let best_face = (best_face.0, if face_s < 0.0 { -face_axis } else { face_axis }, face_k);

    // edge axes a_i x b_j, in a's frame; near-parallel edges are left to the face axes
    let mut best_edge = (f32::MIN, Vec3::ZERO, 0usize, 0usize);
    for i in 0..3 {
        for j in 0..3 {
            let bj = r.col(j);
            let l = Vec3::AXES[i].cross(bj);
            let len = l.length();
            if len < 1e-5 {
                continue;
            }
            let s = t.dot(l);
            let sep = (s.abs() - ha.dot(l.abs()) - hb.dot((r.transpose() * l).abs())) / len;
            worst = worst.max(sep);
            if sep > best_edge.0 {
                best_edge = (sep, ra * (if s < 0.0 { -l } else { l } / len), i, j);
            }
        }
    }
    if worst > margin {
        return None;
    }

    if best_edge.0 > best_face.0 + EDGE_BIAS {
        let (_, n, i, j) = best_edge;
        // the edge of a farthest along n, the edge of b farthest along -n
        let mut pa = ca;
        let mut pb = cb;
        for k in 0..3 {
            if k != i {
                pa += axes_a[k] * (ha[k] * axes_a[k].dot(n).signum());
            }
            if k != j {
                pb -= axes_b[k] * (hb[k] * axes_b[k].dot(n).signum());
            }
        }
        let (on_a, on_b) = closest_on_edges(pa, axes_a[i], ha[i], pb, axes_b[j], hb[j]);
        return Some(Manifold { normal: n, points: vec![ContactPoint { on_a, on_b }] });
    }

    let (_, n, k) = best_face;
    // reference box owns the face; incident box is the other, n points ref -> inc
    let (ref_c, ref_axes, ref_h, inc_c, inc_axes, inc_h, ref_n, flipped) =
        if k < 3 { (ca, axes_a, ha, cb, axes_b, hb, n, false) } else { (cb, axes_b, hb, ca, axes_a, ha, -n, true) };
    let face = k % 3;
    // incident face: the face of the incident box most anti-parallel to ref_n (the first of equals)
    let along = Vec3::new(inc_axes[0].dot(ref_n).abs(), inc_axes[1].dot(ref_n).abs(), inc_axes[2].dot(ref_n).abs());
    let inc_face = if along.x >= along.y && along.x >= along.z {
        0
    } else if along.y >= along.z {
        1
    } else {
        2
    };
    let inc_axis = inc_axes[inc_face];
    let inc_centre = inc_c + inc_axis * (inc_h[inc_face] * -inc_axis.dot(ref_n).signum());
    let (u, v) = ((inc_face + 1) % 3, (inc_face + 2) % 3);
    let (eu, ev) = (inc_axes[u] * inc_h[u], inc_axes[v] * inc_h[v]);

    // the reference face's frame: its centre, its two side axes and ref_n;
    // the clipping runs in its plane, a point's height above it follows
    // from the incident face's plane
    let ref_centre = ref_c + ref_n * ref_h[face];
    let (side_u, side_v) = ((face + 1) % 3, (face + 2) % 3);
    let (su, sv) = (ref_axes[side_u], ref_axes[side_v]);
    let to_face = Mat3::from_cols(su, sv, ref_n).transpose();
    let c = to_face * (inc_centre - ref_centre);
    let (du, dv) = ((to_face * eu).truncate(), (to_face * ev).truncate());
    let corners = [c.truncate() + du + dv, c.truncate() - du + dv, c.truncate() - du - dv, c.truncate() + du - dv];
    let nf = to_face * inc_axis;
    let slope = -nf.truncate() / nf.z;
    let height = |p: Vec2| c.z + slope.dot(p - c.truncate());

    // the corners of the incident face's part within the reference face,
    // those within the margin of it
    let half = Vec2::new(ref_h[side_u], ref_h[side_v]);
    let points: Vec<(Vec2, f32)> =
        overlap_corners(corners, half, du.perp_dot(dv)).into_iter().map(|p| (p, height(p))).filter(|&(_, z)| z <= margin).collect();
    if points.is_empty() {
        return None;
    }
    let points = reduce(points, None)
        .into_iter()
        .map(|(p, z)| {
            let on_ref = ref_centre + su * p.x + sv * p.y;
            let on_inc = on_ref + ref_n * z;
            if flipped {
                ContactPoint { on_a: on_inc, on_b: on_ref }
            } else {
                ContactPoint { on_a: on_ref, on_b: on_inc }
            }
        })
        .collect();
    Some(Manifold { normal: n, points })
}

/// The corners of the part of a convex quadrilateral (`corners`, wound as
/// the sign of `winding` says) within the rectangle |x| <= half.x,
/// |y| <= half.y, in the GPU's candidate order: where each edge enters the
/// rectangle (its start when that lies in it), then where each leaves it
/// before its end (Liang-Barsky), then the rectangle's corners strictly
/// inside the quadrilateral.
fn overlap_corners(corners: [Vec2; 4], half: Vec2, winding: f32) -> Vec<Vec2> {
    // the parameters at which p + t e enters and leaves the slab |x| <= h
    let slab = |p: f32, e: f32, h: f32| {
        if e == 0.0 {
            if p.abs() <= h {
                (f32::MIN, f32::MAX)
            } else {
                (f32::MAX, f32::MIN)
            }
        } else {
            let (ta, tb) = ((-h - p) / e, (h - p) / e);
            (ta.min(tb), ta.max(tb))
        }
    };
    let mut enter = Vec::with_capacity(4);
    let mut leave = Vec::with_capacity(4);
    for k in 0..4 {
        let p = corners[k];
        let e = corners[(k + 1) % 4] - p;
        let (x0, x1) = slab(p.x, e.x, half.x);
        let (y0, y1) = slab(p.y, e.y, half.y);
        let t0 = 0.0f32.max(x0).max(y0);
        let t1 = 1.0f32.min(x1).min(y1);
        if t0 <= t1 {
            enter.push(p + t0 * e);
            if t1 < 1.0 && t1 > t0 {
                leave.push(p + t1 * e);
            }
        }
    }
    let inside = |r: Vec2| (0..4).all(|k| (corners[(k + 1) % 4] - corners[k]).perp_dot(r - corners[k]) * winding > 0.0);
    let rect = [Vec2::new(half.x, half.y), Vec2::new(-half.x, half.y), Vec2::new(-half.x, -half.y), Vec2::new(half.x, -half.y)];
    enter.into_iter().chain(leave).chain(rect.into_iter().filter(|&r| inside(r))).collect()
}

/// Closest points of two segments, each given by centre, unit direction and half length.
pub(crate) fn closest_on_edges(pa: Vec3, da: Vec3, la: f32, pb: Vec3, db: Vec3, lb: f32) -> (Vec3, Vec3) {
    let r = pb - pa;
    let b = da.dot(db);
    let denom = 1.0 - b * b;
    let (ra, rb) = (da.dot(r), db.dot(r));
    let mut s = if denom > 1e-8 { (ra - b * rb) / denom } else { 0.0 };
    s = s.clamp(-la, la);
    let mut t = (b * s - rb).clamp(-lb, lb);
    s = (b * t + ra).clamp(-la, la);
    t = (b * s - rb).clamp(-lb, lb);
    (pa + da * s, pb + db * t)
}

/// At most four points (in the reference face's plane, with their height
/// above it) that keep the deepest one and span the most area. Run on every
/// face contact, as on the GPU: four or fewer points in general position
/// all stay, a point that adds no area (between two others on a line) goes.
/// With `about` (a hull's centre, on the ground), the first is the one
/// farthest from it of those within `CONTACT_SLOP` of the deepest: a hull
/// resting on a face has more than four corners on the ground, and the
/// deepest of them changes as it settles by less than a millimetre; a choice
/// by depth alone rocked it. On the ground the corners that bear (within
/// `CONTACT_SLOP` of the ground, or of the deepest) come first at every
/// choice: a corner only near, chosen over one that bears, let a hull tip
/// toward the one left out, for good.
pub(crate) fn reduce(points: Vec<(Vec2, f32)>, about: Option<Vec2>) -> Vec<(Vec2, f32)> {
    // 1: deepest (the first of equals, as every choice here)
    let mut chosen = [0usize; 4];
    for (i, p) in points.iter().enumerate() {
        if p.1 < points[chosen[0]].1 {
            chosen[0] = i;
        }
    }
    let deepest = points[chosen[0]].1;
    let bears = deepest.max(0.0) + crate::limits::CONTACT_SLOP;
    // whether point i, adding `score` (distance or area) to the choice, bears
    let ranked = |i: usize, score: f32| about.is_some() && score > 0.0 && points[i].1 <= bears;
    // the best of (rank, score), the first of equals
    let pick = |score: &dyn Fn(Vec2) -> f32, init: f32, first: usize| {
        let (mut at, mut best, mut rank) = (first, init, false);
        for (i, p) in points.iter().enumerate() {
            let s = score(p.0);
            let r = ranked(i, s);
            if (r && !rank) || (r == rank && s > best) {
                (at, best, rank) = (i, s, r);
            }
        }
        at
    };
    if let Some(c) = about {
        let mut best = -1.0;
        for (i, p) in points.iter().enumerate() {
            let d = (p.0 - c).length_squared();
            if p.1 <= deepest + crate::limits::CONTACT_SLOP && d > best {
                best = d;
                chosen[0] = i;
            }
        }
    }
    // 2: farthest from it
    let p0 = points[chosen[0]].0;
    chosen[1] = pick(&|q| (q - p0).length_squared(), -1.0, 0);
    // 3: largest triangle; 4: largest area added on the other side
    let p1 = points[chosen[1]].0;
    chosen[2] = pick(&|q| (p1 - p0).perp_dot(q - p0).abs(), f32::MIN, 0);
    let p2 = points[chosen[2]].0;
    let side = (p1 - p0).perp_dot(p2 - p0).signum();
    // area added outside the triangle
    let added = |q: Vec2| {
        [(p0, p1), (p1, p2), (p2, p0)].iter().map(|(e0, e1)| -side * (*e1 - *e0).perp_dot(q - *e0)).fold(f32::MIN, f32::max)
    };
    chosen[3] = pick(&added, f32::MIN, chosen[0]);
    // distinct choices only, in the order chosen
    let mut out = Vec::with_capacity(4);
    for (c, &i) in chosen.iter().enumerate() {
        if !chosen[..c].contains(&i) {
            out.push(points[i]);
        }
    }
    out
}
