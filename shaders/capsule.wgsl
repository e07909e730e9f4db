// Capsule manifolds: the twin of src/reference/capsule.rs, step for step. A
// capsule (and here a sphere too) is a segment swept by a radius; a
// manifold's normal points from the first shape to the second, as in
// collide.wgsl, whose Manifold, closest_on_edges, component and sign_of these
// use.

// A point of a segment lying along another counts towards a two-point
// contact if at most this share of the smaller radius off the normal line.
const SIDE_BY_SIDE: f32 = 0.1;
// Golden-section steps of the search along a segment for its point nearest a box.
const NEAREST_STEPS: u32 = 32u;
// A nearest point this close to a face's normal line (cosine) rests on that face.
const FACE_ALIGNED: f32 = 0.999;

// A segment (centre, unit direction, half length) swept by a radius.
struct Swept {
    centre: vec3<f32>,
    dir: vec3<f32>,
    half_length: f32,
    radius: f32,
}

// The swept segment of a sphere or capsule (half = (radius, half height, radius)).
fn swept_of(s: Shape) -> Swept {
    let capsule = s.kind == SHAPE_CAPSULE;
    let up = vec3<f32>(0.0, 1.0, 0.0);
    return Swept(s.centre, select(up, quat_rotate(s.rot, up), capsule), select(0.0, s.half.y, capsule), s.half.x);
}

// Two round shapes, one a capsule at least: the closest points of their
// segments, or two points where the segments lie side by side.
fn round_round(a: Swept, b: Swept, margin: f32) -> Manifold {
    var m = empty_manifold();
    var pa: vec3<f32>;
    var pb: vec3<f32>;
    closest_on_edges(a.centre, a.dir, a.half_length, b.centre, b.dir, b.half_length, &pa, &pb);
    let d = pb - pa;
    let dist = length(d);
    if (dist - a.radius - b.radius > margin) {
        return m;
    }
    var n = across(a.dir, b.dir);
    if (dist > 1e-6) {
        n = d / dist;
    }
    m.normal = n;
    // b's ends seen along a's segment, within it: the span they share
    let s0 = clamp(dot(b.centre - b.dir * b.half_length - a.centre, a.dir), -a.half_length, a.half_length);
    let s1 = clamp(dot(b.centre + b.dir * b.half_length - a.centre, a.dir), -a.half_length, a.half_length);
    let off_line = SIDE_BY_SIDE * min(a.radius, b.radius);
    var kept = 0u;
    if (abs(s1 - s0) > off_line) {
        for (var e = 0u; e < 2u; e = e + 1u) {
            let s = select(max(s0, s1), min(s0, s1), e == 0u);
            let on_a = a.centre + a.dir * s;
            let t = clamp(dot(on_a - b.centre, b.dir), -b.half_length, b.half_length);
            let on_b = b.centre + b.dir * t;
            let gap = on_b - on_a;
            let along = dot(gap, n);
            if (length(gap - n * along) <= off_line && along - a.radius - b.radius <= margin) {
                // slot 0 or 1 by comparison (no per-lane index)
                m.on_a[1] = select(m.on_a[1], on_a + n * a.radius, kept == 1u);
                m.on_b[1] = select(m.on_b[1], on_b - n * b.radius, kept == 1u);
                m.on_a[0] = select(m.on_a[0], on_a + n * a.radius, kept == 0u);
                m.on_b[0] = select(m.on_b[0], on_b - n * b.radius, kept == 0u);
                kept = kept + 1u;
            }
        }
    }
    if (kept < 2u) {
        m.on_a[0] = pa + n * a.radius;
        m.on_b[0] = pb - n * b.radius;
        kept = 1u;
    }
    m.count = kept;
    return m;
}

// A unit vector across both unit directions: their cross product, or where
// they are parallel one across `a` alone.
fn across(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    let c = cross(a, b);
    let len = length(c);
    if (len > 1e-6) {
        return c / len;
    }
    let other = select(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0), abs(a.x) < 0.9);
    return normalize(cross(a, other));
}

// Unit vector k of the frame.
fn unit(k: u32) -> vec3<f32> {
    return vec3<f32>(f32(k == 0u), f32(k == 1u), f32(k == 2u));
}

// Box first, capsule second: the normal points from the box to the capsule.
fn box_capsule(cb: vec3<f32>, rot: vec4<f32>, h: vec3<f32>, capsule: Swept, margin: f32) -> Manifold {
    var m = empty_manifold();
    let to_local = quat_conj(rot);
    let c = quat_rotate(to_local, capsule.centre - cb);
    let d = quat_rotate(to_local, capsule.dir);
    let l = capsule.half_length;
    let r = capsule.radius;
    let local = Swept(c, d, l, r);
    // the box's face axes
    let face_sep = abs(c) - h - abs(d) * l;
    let face = select(select(2u, 1u, face_sep.y >= face_sep.z), 0u, face_sep.x >= face_sep.y && face_sep.x >= face_sep.z);
    let best_face_sep = component(face_sep, face);
    // each box edge crossed with the segment (the segment has no extent across it)
    var best_edge_sep = -3.4e38;
    var best_edge = 0u;
    var best_edge_l = vec3<f32>(0.0, 1.0, 0.0);
    for (var k = 0u; k < 3u; k = k + 1u) {
        let axis = cross(unit(k), d);
        let len = length(axis);
        let s = dot(c, axis);
        let sep = (abs(s) - dot(h, abs(axis))) / len;
        let better = len >= 1e-5 && sep > best_edge_sep;
        best_edge_sep = select(best_edge_sep, sep, better);
        best_edge = select(best_edge, k, better);
        best_edge_l = select(best_edge_l, select(axis, -axis, s < 0.0) / len, better);
    }
    let worst = max(best_face_sep, best_edge_sep);
    if (worst - r > margin) {
        return m;
    }
    // where the segment misses the box, its nearest point says which feature meets it
    let on_seg = c + d * nearest_to_box(c, d, l, h);
    let on_box = clamp(on_seg, -h, h);
    let out = on_seg - on_box;
    let dist = length(out);
    let misses = worst > 0.0 && dist > 1e-6;
    if (misses && dist - r > margin) {
        return m;
    }
    // the face the capsule may lie on (one call of face_points in the kernel):
    // where it misses the box, the face its nearest point looks out of, if
    // nearly square to it; else the face of least overlap, unless an edge's
    var n = out / dist;
    let an = abs(n);
    let near_face = select(select(2u, 1u, an.y >= an.z), 0u, an.x >= an.y && an.x >= an.z);
    let k = select(face, near_face, misses);
    let s = select(sign_of(component(c, face)), sign_of(component(n, near_face)), misses);
    let edge = !misses && best_edge_sep > best_face_sep + EDGE_BIAS;
    if ((misses && component(an, near_face) >= FACE_ALIGNED) || (!misses && !edge)) {
        m = face_points(local, h, k, s, margin);
    }
    if (m.count > 0u || !misses) {
        n = unit(k) * s;
    }
    if (misses && m.count == 0u) {
        m.count = 1u;
        m.on_a[0] = on_box;
        m.on_b[0] = on_seg - n * r;
    }
    if (edge) {
        // the segment passes into the box across an edge: that edge, farthest along n
        n = best_edge_l;
        let edge_centre = h * vec3<f32>(sign_of(n.x), sign_of(n.y), sign_of(n.z)) * (vec3<f32>(1.0) - unit(best_edge));
        var on_edge: vec3<f32>;
        var on_segment: vec3<f32>;
        closest_on_edges(edge_centre, unit(best_edge), component(h, best_edge), c, d, l, &on_edge, &on_segment);
        m.count = 1u;
        m.on_a[0] = on_edge;
        m.on_b[0] = on_segment - n * r;
    }
    // back to the world
    m.normal = quat_rotate(rot, n);
    for (var q = 0u; q < 2u; q = q + 1u) {
        m.on_a[q] = cb + quat_rotate(rot, m.on_a[q]);
        m.on_b[q] = cb + quat_rotate(rot, m.on_b[q]);
    }
    return m;
}

// Where along the segment (c + d t, |t| <= l) the point nearest the box of half
// extents h lies: the squared distance to a box is convex along a line, so a
// golden-section search finds its least.
fn nearest_to_box(c: vec3<f32>, d: vec3<f32>, l: f32, h: vec3<f32>) -> f32 {
    let ratio = 0.618034;
    var lo = -l;
    var hi = l;
    var x1 = hi - ratio * (hi - lo);
    var x2 = lo + ratio * (hi - lo);
    var f1 = box_distance2(c + d * x1, h);
    var f2 = box_distance2(c + d * x2, h);
    for (var k = 0u; k < NEAREST_STEPS; k = k + 1u) {
        // one new point a step, on the side the least is not
        let left = f1 <= f2;
        hi = select(hi, x2, left);
        lo = select(x1, lo, left);
        let fresh = select(lo + ratio * (hi - lo), hi - ratio * (hi - lo), left);
        let f = box_distance2(c + d * fresh, h);
        let kept_x = select(x2, x1, left);
        let kept_f = select(f2, f1, left);
        x1 = select(kept_x, fresh, left);
        f1 = select(kept_f, f, left);
        x2 = select(fresh, kept_x, left);
        f2 = select(f, kept_f, left);
    }
    return 0.5 * (lo + hi);
}

// Squared distance from p to the box of half extents h (0 inside).
fn box_distance2(p: vec3<f32>, h: vec3<f32>) -> f32 {
    let out = p - clamp(p, -h, h);
    return dot(out, out);
}

// The capsule (`local`: in the box's frame) against face k (outward sign s) of the box:
// its segment clipped to the face's sides, each end of what is left a point (on
// the face, on the capsule) if within the margin; the normal is left to the caller.
fn face_points(local: Swept, h: vec3<f32>, k: u32, s: f32, margin: f32) -> Manifold {
    var m = empty_manifold();
    let l = local.half_length;
    let r = local.radius;
    let p0 = local.centre - local.dir * l;
    let e = local.dir * (2.0 * l);
    var enter = 0.0;
    var leave = 1.0;
    for (var step = 1u; step < 3u; step = step + 1u) {
        let j = (k + step) % 3u;
        let ej = component(e, j);
        let pj = component(p0, j);
        let hj = component(h, j);
        if (ej == 0.0) {
            leave = select(leave, -1.0, abs(pj) > hj);
        } else {
            let ta = (-hj - pj) / ej;
            let tb = (hj - pj) / ej;
            enter = max(enter, min(ta, tb));
            leave = min(leave, max(ta, tb));
        }
    }
    if (enter > leave) {
        return m;
    }
    let n = unit(k) * s;
    let two = (leave - enter) * 2.0 * l > SIDE_BY_SIDE * r;
    let middle = 0.5 * (enter + leave);
    for (var q = 0u; q < 2u; q = q + 1u) {
        let t = select(middle, select(leave, enter, q == 0u), two);
        let p = p0 + e * t;
        let height = s * component(p, k) - component(h, k);
        let on_face = p + unit(k) * (s * component(h, k) - component(p, k));
        let keep = (q == 0u || two) && height - r <= margin;
        m.on_a[1] = select(m.on_a[1], on_face, keep && m.count == 1u);
        m.on_b[1] = select(m.on_b[1], p - n * r, keep && m.count == 1u);
        m.on_a[0] = select(m.on_a[0], on_face, keep && m.count == 0u);
        m.on_b[0] = select(m.on_b[0], p - n * r, keep && m.count == 0u);
        m.count = m.count + u32(keep);
    }
    return m;
}

// A capsule's contact with the ground within `margin`, normal from the body
// down: the lowest point of the ball at each end of its segment.
fn ground_capsule(capsule: Swept, ground: f32, margin: f32) -> Manifold {
    var m = empty_manifold();
    m.normal = vec3<f32>(0.0, -1.0, 0.0);
    for (var e = 0u; e < 2u; e = e + 1u) {
        let end = capsule.centre + capsule.dir * select(capsule.half_length, -capsule.half_length, e == 0u);
        let lowest = end - vec3<f32>(0.0, capsule.radius, 0.0);
        let keep = lowest.y - ground <= margin;
        let on_ground = vec3<f32>(lowest.x, ground, lowest.z);
        m.on_a[1] = select(m.on_a[1], lowest, keep && m.count == 1u);
        m.on_b[1] = select(m.on_b[1], on_ground, keep && m.count == 1u);
        m.on_a[0] = select(m.on_a[0], lowest, keep && m.count == 0u);
        m.on_b[0] = select(m.on_b[0], on_ground, keep && m.count == 0u);
        m.count = m.count + u32(keep);
    }
    return m;
}
