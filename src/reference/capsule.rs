//! Capsule manifolds (twin of `shaders/capsule.wgsl`): a capsule against a
//! sphere, a capsule or a box, as a segment swept by a radius (a sphere is a
//! segment of no length).
//!
//! Round shapes against each other meet at the closest points of their
//! segments, and at two points where two capsules lie side by side. A box
//! and a capsule are told apart by the separating axes of the box and the
//! segment; where the segment misses the box, its closest points say which
//! feature meets it, and a capsule lying on a face gets the ends of its
//! segment clipped to that face, so it rests on two points.

use glam::{Quat, Vec3};

use super::collide::{closest_on_edges, ContactPoint, Manifold, EDGE_BIAS};

/// A point of a segment lying along another counts towards a two-point
/// contact if it is at most this share of the smaller radius off the
/// contact's normal line: capsules side by side touch along a line, crossed
/// ones at a point.
pub const SIDE_BY_SIDE: f32 = 0.1;

/// Golden-section steps of the search along a segment for its point
/// nearest a box: the bracket shrinks to 0.618^32 (about 2e-7) of the
/// segment's length.
pub const NEAREST_STEPS: u32 = 32;

/// A segment (centre, unit direction, half length) swept by a radius.
#[derive(Clone, Copy, Debug)]
pub struct Swept {
    pub centre: Vec3,
    pub dir: Vec3,
    pub half_length: f32,
    pub radius: f32,
}

impl Swept {
    /// The capsule of `radius` and `half_height` centred at `centre`, its
    /// segment along the body's y axis turned by `rot`.
    pub fn capsule(centre: Vec3, rot: Quat, radius: f32, half_height: f32) -> Swept {
        Swept { centre, dir: rot * Vec3::Y, half_length: half_height, radius }
    }

    /// A sphere: a segment of no length.
    pub fn sphere(centre: Vec3, radius: f32) -> Swept {
        Swept { centre, dir: Vec3::Y, half_length: 0.0, radius }
    }

    fn at(&self, s: f32) -> Vec3 {
        self.centre + self.dir * s
    }
}

/// Two round shapes (at least one a capsule): the normal from the closest
/// point of a's segment to b's, one point there, or two where the segments
/// lie side by side along their overlap.
pub fn round_round(a: &Swept, b: &Swept, margin: f32) -> Option<Manifold> {
    let (pa, pb) = closest_on_edges(a.centre, a.dir, a.half_length, b.centre, b.dir, b.half_length);
    let d = pb - pa;
    let dist = d.length();
    if dist - a.radius - b.radius > margin {
        return None;
    }
    let n = if dist > 1e-6 { d / dist } else { across(a.dir, b.dir) };
    let point = |on_a: Vec3, on_b: Vec3| ContactPoint { on_a: on_a + n * a.radius, on_b: on_b - n * b.radius };
    // b's ends seen along a's segment, within it: the span they share
    let s0 = (b.at(-b.half_length) - a.centre).dot(a.dir).clamp(-a.half_length, a.half_length);
    let s1 = (b.at(b.half_length) - a.centre).dot(a.dir).clamp(-a.half_length, a.half_length);
    let off_line = SIDE_BY_SIDE * a.radius.min(b.radius);
    let mut points = Vec::new();
    if (s1 - s0).abs() > off_line {
        for s in [s0.min(s1), s0.max(s1)] {
            let on_a = a.at(s);
            let t = (on_a - b.centre).dot(b.dir).clamp(-b.half_length, b.half_length);
            let on_b = b.at(t);
            let gap = on_b - on_a;
            let along = gap.dot(n);
            if (gap - n * along).length() <= off_line && along - a.radius - b.radius <= margin {
                points.push(point(on_a, on_b));
            }
        }
    }
    if points.len() < 2 {
        points = vec![point(pa, pb)];
    }
    Some(Manifold { normal: n, points })
}

/// A capsule whose nearest point to a box lies this close to a face's normal
/// line (cosine; about 2.6 degrees) rests on that face where its segment,
/// clipped to the face, comes within the margin: a capsule lying on a face
/// has a flat least distance, and the search may stop at either end of it,
/// off the face's edge.
pub const FACE_ALIGNED: f32 = 0.999;

/// A unit vector across both unit directions (their segments cross): their
/// cross product, or where they are parallel one across `a` alone.
pub fn across(a: Vec3, b: Vec3) -> Vec3 {
    let c = a.cross(b);
    let len = c.length();
    if len > 1e-6 {
        return c / len;
    }
    let other = if a.x.abs() < 0.9 { Vec3::X } else { Vec3::Z };
    a.cross(other).normalize()
}

/// Box first, capsule second: the normal points from the box to the capsule.
pub fn box_capsule(cb: Vec3, rot: Quat, h: Vec3, capsule: &Swept, margin: f32) -> Option<Manifold> {
    let to_local = rot.conjugate();
    let c = to_local * (capsule.centre - cb);
    let d = to_local * capsule.dir;
    let (l, r) = (capsule.half_length, capsule.radius);
    let local = Swept { centre: c, dir: d, ..*capsule };
    // the box's face axes
    let face_sep = c.abs() - h - d.abs() * l;
    let face = if face_sep.x >= face_sep.y && face_sep.x >= face_sep.z {
        0
    } else if face_sep.y >= face_sep.z {
        1
    } else {
        2
    };
    let best_face_sep = face_sep[face];
    // each box edge crossed with the segment (the segment has no extent across it)
    let mut best_edge_sep = -f32::MAX;
    let mut best_edge = 0;
    let mut best_edge_l = Vec3::Y;
    for k in 0..3 {
        let mut e = Vec3::ZERO;
        e[k] = 1.0;
        let axis = e.cross(d);
        let len = axis.length();
        if len < 1e-5 {
            continue;
        }
        let s = c.dot(axis);
        let sep = (s.abs() - h.dot(axis.abs())) / len;
        if sep > best_edge_sep {
            best_edge_sep = sep;
            best_edge = k;
            best_edge_l = if s < 0.0 { -axis / len } else { axis / len };
        }
    }
    let worst = best_face_sep.max(best_edge_sep);
    if worst - r > margin {
        return None;
    }
    // where the segment misses the box, its nearest point says which feature meets it
    let on_seg = c + d * nearest_to_box(c, d, l, h);
    let on_box = on_seg.clamp(-h, h);
    let out = on_seg - on_box;
    let dist = out.length();
    let (n_local, points) = if worst > 0.0 && dist > 1e-6 {
        if dist - r > margin {
            return None;
        }
        let n = out / dist;
        let k = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
            0
        } else if n.y.abs() >= n.z.abs() {
            1
        } else {
            2
        };
        let on_face = if n[k].abs() >= FACE_ALIGNED { face_points(&local, h, k, sign(n[k]), margin) } else { Vec::new() };
        if on_face.is_empty() {
            (n, vec![(on_box, on_seg - n * r)])
        } else {
            let mut face_n = Vec3::ZERO;
            face_n[k] = sign(n[k]);
            (face_n, on_face)
        }
    } else if best_edge_sep > best_face_sep + EDGE_BIAS {
        // the segment passes into the box across an edge: that edge, farthest along n
        let n = best_edge_l;
        let mut edge_centre = Vec3::ZERO;
        for j in 0..3 {
            if j != best_edge {
                edge_centre[j] = h[j] * sign(n[j]);
            }
        }
        let mut e = Vec3::ZERO;
        e[best_edge] = 1.0;
        let (on_box, on_seg) = closest_on_edges(edge_centre, e, h[best_edge], c, d, l);
        (n, vec![(on_box, on_seg - n * r)])
    } else {
        let s = sign(c[face]);
        let mut n = Vec3::ZERO;
        n[face] = s;
        (n, face_points(&local, h, face, s, margin))
    };
    let points: Vec<ContactPoint> = points
        .into_iter()
        .map(|(on_box, on_capsule)| ContactPoint { on_a: cb + rot * on_box, on_b: cb + rot * on_capsule })
        .collect();
    if points.is_empty() {
        return None;
    }
    Some(Manifold { normal: rot * n_local, points })
}

/// Like `f32::signum` for +0: +1.
fn sign(x: f32) -> f32 {
    if x >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// Where along the segment (c + d t, |t| <= l) the point nearest the box of
/// half extents h lies: the squared distance to a box is convex along a
/// line, so a golden-section search finds its least.
fn nearest_to_box(c: Vec3, d: Vec3, l: f32, h: Vec3) -> f32 {
    nearest_along(c, d, l, |p| (p - p.clamp(-h, h)).length_squared())
}

/// Where along the segment (c + d t, |t| <= l) the least of `dist2`, a
/// function convex along the line (a squared distance to a convex shape),
/// lies, by golden-section search.
pub(crate) fn nearest_along(c: Vec3, d: Vec3, l: f32, dist2: impl Fn(Vec3) -> f32) -> f32 {
    let dist2 = |t: f32| dist2(c + d * t);
    let ratio = 0.618_034_f32;
    let (mut lo, mut hi) = (-l, l);
    let mut x1 = hi - ratio * (hi - lo);
    let mut x2 = lo + ratio * (hi - lo);
    let (mut f1, mut f2) = (dist2(x1), dist2(x2));
    for _ in 0..NEAREST_STEPS {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - ratio * (hi - lo);
            f1 = dist2(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + ratio * (hi - lo);
            f2 = dist2(x2);
        }
    }
    0.5 * (lo + hi)
}

/// The capsule (`local`: in the box's frame) against face `k` (outward sign
/// `s`) of the box: its segment clipped to the face's sides, each end of what is left
/// a point (on the face, on the capsule) if within the margin.
fn face_points(local: &Swept, h: Vec3, k: usize, s: f32, margin: f32) -> Vec<(Vec3, Vec3)> {
    let (c, d, l, r) = (local.centre, local.dir, local.half_length, local.radius);
    let (p0, p1) = (c - d * l, c + d * l);
    let e = p1 - p0;
    let (mut enter, mut leave) = (0.0_f32, 1.0_f32);
    for j in [(k + 1) % 3, (k + 2) % 3] {
        if e[j] == 0.0 {
            if p0[j].abs() > h[j] {
                leave = -1.0;
            }
            continue;
        }
        let ta = (-h[j] - p0[j]) / e[j];
        let tb = (h[j] - p0[j]) / e[j];
        enter = enter.max(ta.min(tb));
        leave = leave.min(ta.max(tb));
    }
    if enter > leave {
        return Vec::new();
    }
    let mut n = Vec3::ZERO;
    n[k] = s;
    let ends = if (leave - enter) * 2.0 * l > SIDE_BY_SIDE * r { vec![enter, leave] } else { vec![0.5 * (enter + leave)] };
    ends.into_iter()
        .filter_map(|t| {
            let q = p0 + e * t;
            let height = s * q[k] - h[k];
            let mut on_face = q;
            on_face[k] = s * h[k];
            (height - r <= margin).then_some((on_face, q - n * r))
        })
        .collect()
}

/// A capsule's contact with the ground at height `ground` within `margin`:
/// the lowest point of the ball at each end of its segment.
pub fn ground_capsule(capsule: &Swept, ground: f32, margin: f32) -> Option<Manifold> {
    let points: Vec<ContactPoint> = [-capsule.half_length, capsule.half_length]
        .into_iter()
        .map(|s| capsule.at(s) - Vec3::Y * capsule.radius)
        .filter(|lowest| lowest.y - ground <= margin)
        .map(|lowest| ContactPoint { on_a: lowest, on_b: Vec3::new(lowest.x, ground, lowest.z) })
        .collect();
    (!points.is_empty()).then_some(Manifold { normal: Vec3::NEG_Y, points })
}
