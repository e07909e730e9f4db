// Hull manifolds: the twin of src/reference/hull.rs, step for step. Two
// polytopes (hulls, or a box as the unit cube scaled) are told apart by
// their separating axes: each one's face normals, and the edge pairs whose
// Gauss-map arcs cross (a face of their Minkowski difference). A round shape
// (a sphere, or a capsule's segment) meets a hull as box_capsule meets a box.
// Normals point from the first shape to the second, as in collide.wgsl.

// The most points a face clipped by another can have: its corners and one
// per side of the other (64 each at most, `HullShape`).
const MAX_CLIP: u32 = 128u;
const CLIP_ROOM: u32 = 256u;

// A polytope placed in the world.
struct Solid {
    poly: Poly,
    pos: vec3<f32>,
    rot: vec4<f32>,
}

// How b's frame sits in a's: p_a = m p_b + t.
struct Relative {
    m: mat3x3<f32>,
    t: vec3<f32>,
}

fn relative(a: Solid, b: Solid) -> Relative {
    let to_a = quat_conj(a.rot);
    return Relative(quat_to_mat(quat_mul(to_a, b.rot)), quat_rotate(to_a, b.pos - a.pos));
}

struct FaceAxis {
    sep: f32,
    face: u32,
}

// The face of a that separates b (placed in a's frame by rel) the most, or
// the first that separates them by more than `margin`.
fn best_face(a: Poly, b: Poly, rel: Relative, margin: f32) -> FaceAxis {
    var best = FaceAxis(-3.4e38, 0u);
    let back = transpose(rel.m);
    for (var f = 0u; f < a.faces; f = f + 1u) {
        let plane = poly_plane(a, f);
        let n_b = back * plane.xyz;
        var lowest = 3.4e38;
        for (var k = 0u; k < b.corners; k = k + 1u) {
            lowest = min(lowest, dot(n_b, poly_corner(b, k)));
        }
        let sep = lowest + dot(plane.xyz, rel.t) - plane.w;
        if (sep > best.sep) {
            best = FaceAxis(sep, f);
        }
        // most candidate pairs of a large hull (a drum's panel) are far apart
        if (sep > margin) {
            return best;
        }
    }
    return best;
}

// Whether the arcs of two edges' face normals on the unit sphere (a's a1 to
// a2, b's negated) cross: their cross product is then a candidate axis.
fn minkowski_face(a1: vec3<f32>, a2: vec3<f32>, b1: vec3<f32>, b2: vec3<f32>) -> bool {
    let c = -b1;
    let d = -b2;
    let bxa = cross(a2, a1);
    let dxc = cross(d, c);
    let cba = dot(c, bxa);
    let dba = dot(d, bxa);
    let adc = dot(a1, dxc);
    let bdc = dot(a2, dxc);
    return cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0;
}

struct EdgeAxis {
    sep: f32,
    normal: vec3<f32>, // from a to b, in a's frame
    edge_a: u32,
    edge_b: u32,
}

// The edge pair whose axis separates the two the most, in a's frame. The
// outer loop takes b's edges into a's frame, so the inner one, over a's,
// transforms nothing.
fn best_edges(a: Poly, b: Poly, rel: Relative) -> EdgeAxis {
    var best = EdgeAxis(-3.4e38, vec3<f32>(0.0, 1.0, 0.0), 0u, 0u);
    for (var j = 0u; j < b.edges; j = j + 1u) {
        let eb = poly_edge(b, j);
        let nb1 = rel.m * poly_normal(b, eb.z);
        let nb2 = rel.m * poly_normal(b, eb.w);
        let b0 = rel.m * poly_corner(b, eb.x) + rel.t;
        let db = rel.m * poly_corner(b, eb.y) + rel.t - b0;
        for (var i = 0u; i < a.edges; i = i + 1u) {
            let ea = poly_edge(a, i);
            let na1 = poly_normal(a, ea.z);
            let na2 = poly_normal(a, ea.w);
            if (minkowski_face(na1, na2, nb1, nb2)) {
                let a0 = poly_corner(a, ea.x);
                let da = poly_corner(a, ea.y) - a0;
                let l = cross(da, db);
                let len = length(l);
                if (len >= 1e-5 * length(da) * length(db)) {
                    // outward from a at its edge: between the edge's face normals
                    let n = select(l, -l, dot(l, na1 + na2) < 0.0) / len;
                    let sep = dot(n, b0 - a0);
                    if (sep > best.sep) {
                        best = EdgeAxis(sep, n, i, j);
                    }
                }
            }
        }
    }
    return best;
}

// Whether x, a point in the plane of face f of h, lies within the face.
fn within_face(h: Poly, f: u32, n: vec3<f32>, x: vec3<f32>) -> bool {
    let run = poly_face_run(h, f);
    var inside = true;
    for (var k = 0u; k < run.y; k = k + 1u) {
        let p = poly_corner(h, poly_index(h, run.x + k));
        let q = poly_corner(h, poly_index(h, run.x + (k + 1u) % run.y));
        inside = inside && dot(cross(q - p, x - p), n) >= 0.0;
    }
    return inside;
}

// The point of face f of h nearest x, a point in its plane: x where it lies
// within the face, else the nearest point of its sides.
fn nearest_on_face(h: Poly, f: u32, n: vec3<f32>, x: vec3<f32>) -> vec3<f32> {
    if (within_face(h, f, n, x)) {
        return x;
    }
    let run = poly_face_run(h, f);
    var best = x;
    var best_d2 = 3.4e38;
    for (var k = 0u; k < run.y; k = k + 1u) {
        let p = poly_corner(h, poly_index(h, run.x + k));
        let q = poly_corner(h, poly_index(h, run.x + (k + 1u) % run.y));
        let t = clamp(dot(x - p, q - p) / dot(q - p, q - p), 0.0, 1.0);
        let on_side = p + (q - p) * t;
        let d2 = dot(on_side - x, on_side - x);
        if (d2 < best_d2) {
            best = on_side;
            best_d2 = d2;
        }
    }
    return best;
}

// The up-to-four points `reduce` keeps of `count` candidates (points and
// their heights above a plane of normal n): the deepest, or on the ground
// (`level`) the farthest from `about` of those within CONTACT_SLOP of the
// deepest (a hull on a face has more than four corners there, and which is
// deepest changes as it settles: a choice by depth alone rocked it); the
// farthest from that; the largest triangle; the largest area added on the
// other side. On the ground the corners that bear (within CONTACT_SLOP of the
// ground, or of the deepest) come first at each choice: a corner only near,
// chosen over one that bears, let a hull tip toward the one left out, for
// good. As src/reference/collide.rs's reduce, the first of equals each time.
// Their indices, distinct, in the order chosen, and how many.
struct Chosen {
    at: vec4<u32>,
    count: u32,
}

fn reduce(p: ptr<function, array<vec3<f32>, MAX_CLIP>>, height: ptr<function, array<f32, MAX_CLIP>>, count: u32, n: vec3<f32>,
          about: vec3<f32>, level: bool) -> Chosen {
    var c0 = 0u;
    for (var i = 0u; i < count; i = i + 1u) {
        if ((*height)[i] < (*height)[c0]) {
            c0 = i;
        }
    }
    let deepest = (*height)[c0];
    let bears = max(deepest, 0.0) + CONTACT_SLOP;
    var far = -1.0;
    for (var i = 0u; i < count; i = i + 1u) {
        let off = (*p)[i] - about;
        let d = dot(off, off) - dot(off, n) * dot(off, n);
        if (level && (*height)[i] <= deepest + CONTACT_SLOP && d > far) {
            far = d;
            c0 = i;
        }
    }
    let p0 = (*p)[c0];
    var c1 = 0u;
    var best = -1.0;
    var rank = false;
    for (var i = 0u; i < count; i = i + 1u) {
        let d = dot((*p)[i] - p0, (*p)[i] - p0);
        let r = level && d > 0.0 && (*height)[i] <= bears;
        if ((r && !rank) || (r == rank && d > best)) {
            best = d;
            c1 = i;
            rank = r;
        }
    }
    let p1 = (*p)[c1];
    var c2 = 0u;
    best = -3.4e38;
    rank = false;
    for (var i = 0u; i < count; i = i + 1u) {
        let area = abs(dot(cross(p1 - p0, (*p)[i] - p0), n));
        let r = level && area > 0.0 && (*height)[i] <= bears;
        if ((r && !rank) || (r == rank && area > best)) {
            best = area;
            c2 = i;
            rank = r;
        }
    }
    let p2 = (*p)[c2];
    let side = sign_of(dot(cross(p1 - p0, p2 - p0), n));
    var c3 = c0;
    best = -3.4e38;
    rank = false;
    for (var i = 0u; i < count; i = i + 1u) {
        let q = (*p)[i];
        let added = max(max(-side * dot(cross(p1 - p0, q - p0), n), -side * dot(cross(p2 - p1, q - p1), n)),
                        -side * dot(cross(p0 - p2, q - p2), n));
        let r = level && added > 0.0 && (*height)[i] <= bears;
        if ((r && !rank) || (r == rank && added > best)) {
            best = added;
            c3 = i;
            rank = r;
        }
    }
    var out = Chosen(vec4<u32>(c0, 0u, 0u, 0u), 1u);
    if (c1 != c0) {
        out.at[out.count] = c1;
        out.count = out.count + 1u;
    }
    if (c2 != c0 && c2 != c1) {
        out.at[out.count] = c2;
        out.count = out.count + 1u;
    }
    if (c3 != c0 && c3 != c1 && c3 != c2) {
        out.at[out.count] = c3;
        out.count = out.count + 1u;
    }
    return out;
}

// The points of a face contact, in the reference's frame: the incident
// face most anti-parallel to reference face `face` clipped against its
// sides, those within `margin` of its plane, reduced to four; on_a on the
// reference face, on_b on the incident one. None where nothing is kept.
fn face_contact(reference: Poly, face: u32, incident: Poly, rel: Relative, margin: f32) -> Manifold {
    var m = empty_manifold();
    let plane = poly_plane(reference, face);
    let n = plane.xyz;
    m.normal = n;
    var inc = 0u;
    var least = 3.4e38;
    for (var f = 0u; f < incident.faces; f = f + 1u) {
        let c = dot(rel.m * poly_plane(incident, f).xyz, n);
        if (c < least) {
            least = c;
            inc = f;
        }
    }
    // the polygon clipped from one half of `clip` into the other, in turns
    // (no copy of the whole array a side: lavapipe keeps it in memory)
    var clip: array<vec3<f32>, CLIP_ROOM>;
    let inc_run = poly_face_run(incident, inc);
    var count = inc_run.y;
    for (var k = 0u; k < inc_run.y; k = k + 1u) {
        clip[k] = rel.m * poly_corner(incident, poly_index(incident, inc_run.x + k)) + rel.t;
    }
    var src = 0u;
    // Sutherland-Hodgman against each side plane of the reference face
    let run = poly_face_run(reference, face);
    for (var k = 0u; k < run.y; k = k + 1u) {
        let p = poly_corner(reference, poly_index(reference, run.x + k));
        let q = poly_corner(reference, poly_index(reference, run.x + (k + 1u) % run.y));
        let side = cross(q - p, n);
        let offset = dot(side, p);
        let dst = MAX_CLIP - src;
        var out = 0u;
        for (var i = 0u; i < count; i = i + 1u) {
            let s = clip[src + i];
            let e = clip[src + (i + 1u) % count];
            let ds = dot(side, s) - offset;
            let de = dot(side, e) - offset;
            if (ds <= 0.0 && out < MAX_CLIP) {
                clip[dst + out] = s;
                out = out + 1u;
            }
            if ((ds <= 0.0) != (de <= 0.0) && out < MAX_CLIP) {
                clip[dst + out] = s + (e - s) * (ds / (ds - de));
                out = out + 1u;
            }
        }
        src = dst;
        count = out;
    }
    // the points within the margin of the plane, and their heights
    var kept: array<vec3<f32>, MAX_CLIP>;
    var heights: array<f32, MAX_CLIP>;
    var near = 0u;
    for (var i = 0u; i < count; i = i + 1u) {
        let x = clip[src + i];
        let height = dot(n, x) - plane.w;
        if (height <= margin) {
            kept[near] = x;
            heights[near] = height;
            near = near + 1u;
        }
    }
    if (near == 0u) {
        return m;
    }
    let chosen = reduce(&kept, &heights, near, n, vec3<f32>(0.0), false);
    for (var q = 0u; q < chosen.count; q = q + 1u) {
        let x = kept[chosen.at[q]];
        m.on_a[q] = x - n * heights[chosen.at[q]];
        m.on_b[q] = x;
    }
    m.count = chosen.count;
    return m;
}

// Points and normal from a's frame to the world.
fn to_world(a: Solid, m_in: Manifold) -> Manifold {
    var m = m_in;
    m.normal = quat_rotate(a.rot, m_in.normal);
    for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
        m.on_a[q] = a.pos + quat_rotate(a.rot, m_in.on_a[q]);
        m.on_b[q] = a.pos + quat_rotate(a.rot, m_in.on_b[q]);
    }
    return m;
}

// The manifold of two polytopes within `margin` (normal from a to b).
fn hull_hull(a: Solid, b: Solid, margin: f32) -> Manifold {
    let none = empty_manifold();
    let rel_b = relative(a, b);
    let rel_a = relative(b, a);
    let face_a = best_face(a.poly, b.poly, rel_b, margin);
    if (face_a.sep > margin) {
        return none;
    }
    let face_b = best_face(b.poly, a.poly, rel_a, margin);
    let face_sep = max(face_a.sep, face_b.sep);
    if (face_sep > margin) {
        return none;
    }
    let edges = best_edges(a.poly, b.poly, rel_b);
    let sep = max(face_sep, edges.sep);
    if (sep > margin) {
        return none;
    }
    // b's face must beat a's by FACE_BIAS to be the reference (as for boxes)
    let flipped = face_b.sep > face_a.sep + FACE_BIAS;
    let edge = edges.sep > face_sep + EDGE_BIAS;
    var m = none;
    if (!edge) {
        var reference = a;
        var incident = b;
        var face = face_a.face;
        if (flipped) {
            reference = b;
            incident = a;
            face = face_b.face;
        }
        let rel = relative(reference, incident);
        m = face_contact(reference.poly, face, incident.poly, rel, margin);
        if (m.count == 0u) {
            // the other's face lies past the reference face's sides: its corner
            // deepest along the face's normal, against the face's nearest point
            let plane = poly_plane(reference.poly, face);
            var deepest = vec3<f32>(0.0);
            var least = 3.4e38;
            for (var k = 0u; k < incident.poly.corners; k = k + 1u) {
                let c = rel.m * poly_corner(incident.poly, k) + rel.t;
                let along = dot(plane.xyz, c);
                if (along < least) {
                    least = along;
                    deepest = c;
                }
            }
            m.count = 1u;
            m.on_a[0] = nearest_on_face(reference.poly, face, plane.xyz, deepest - plane.xyz * (least - plane.w));
            m.on_b[0] = deepest;
        }
        m = to_world(reference, m);
        if (flipped) {
            m = flip_manifold(m);
        }
    } else {
        let ea = poly_edge(a.poly, edges.edge_a);
        let eb = poly_edge(b.poly, edges.edge_b);
        let a0 = poly_corner(a.poly, ea.x);
        let a1 = poly_corner(a.poly, ea.y);
        let b0 = rel_b.m * poly_corner(b.poly, eb.x) + rel_b.t;
        let b1 = rel_b.m * poly_corner(b.poly, eb.y) + rel_b.t;
        var on_a: vec3<f32>;
        var on_b: vec3<f32>;
        closest_on_edges(0.5 * (a0 + a1), normalize(a1 - a0), 0.5 * length(a1 - a0),
                         0.5 * (b0 + b1), normalize(b1 - b0), 0.5 * length(b1 - b0), &on_a, &on_b);
        m.count = 1u;
        m.normal = edges.normal;
        m.on_a[0] = on_a;
        m.on_b[0] = on_b;
        m = to_world(a, m);
    }
    // the axes' separation is only a lower bound on the distance: where they
    // say apart, a pair whose points are all beyond the margin is apart
    if (sep > 0.0) {
        var close = false;
        for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
            close = close || (q < m.count && length(m.on_b[q] - m.on_a[q]) <= margin);
        }
        if (!close) {
            return none;
        }
    }
    return m;
}

// The point of h nearest x (x itself inside): a face's where x's foot on
// its plane lies within it, else the nearest point of an edge.
fn nearest_on_hull(h: Poly, x: vec3<f32>) -> vec3<f32> {
    var inside = true;
    var best = x;
    var best_d2 = 3.4e38;
    for (var f = 0u; f < h.faces; f = f + 1u) {
        let plane = poly_plane(h, f);
        let above = dot(plane.xyz, x) - plane.w;
        if (above > 0.0) {
            inside = false;
            let foot = x - plane.xyz * above;
            if (above * above < best_d2 && within_face(h, f, plane.xyz, foot)) {
                best = foot;
                best_d2 = above * above;
            }
        }
    }
    for (var e = 0u; e < h.edges; e = e + 1u) {
        let edge = poly_edge(h, e);
        let p = poly_corner(h, edge.x);
        let q = poly_corner(h, edge.y);
        let on_edge = p + (q - p) * clamp(dot(x - p, q - p) / dot(q - p, q - p), 0.0, 1.0);
        let d2 = dot(on_edge - x, on_edge - x);
        if (d2 < best_d2) {
            best = on_edge;
            best_d2 = d2;
        }
    }
    return select(best, x, inside);
}

// Where along the segment (c + d t, |t| <= l) the point nearest h lies: the
// distance to a convex set is convex along a line (golden-section search).
fn nearest_to_hull(h: Poly, c: vec3<f32>, d: vec3<f32>, l: f32) -> f32 {
    let ratio = 0.618034;
    var lo = -l;
    var hi = l;
    var x1 = hi - ratio * (hi - lo);
    var x2 = lo + ratio * (hi - lo);
    var f1 = hull_distance2(h, c + d * x1);
    var f2 = hull_distance2(h, c + d * x2);
    for (var k = 0u; k < NEAREST_STEPS; k = k + 1u) {
        let left = f1 <= f2;
        hi = select(hi, x2, left);
        lo = select(x1, lo, left);
        let fresh = select(lo + ratio * (hi - lo), hi - ratio * (hi - lo), left);
        let f = hull_distance2(h, c + d * fresh);
        let kept_x = select(x2, x1, left);
        let kept_f = select(f2, f1, left);
        x1 = select(kept_x, fresh, left);
        f1 = select(kept_f, f, left);
        x2 = select(fresh, kept_x, left);
        f2 = select(f, kept_f, left);
    }
    return 0.5 * (lo + hi);
}

fn hull_distance2(h: Poly, x: vec3<f32>) -> f32 {
    let gap = nearest_on_hull(h, x) - x;
    return dot(gap, gap);
}

// The round shape (`local`: in the hull's frame) against face f of h: its
// segment clipped to the face's sides, each end of what is left a point (on
// the face, on the round shape) if within the margin; the normal is the face's.
fn hull_face_points(h: Poly, f: u32, local: Swept, margin: f32) -> Manifold {
    var m = empty_manifold();
    let plane = poly_plane(h, f);
    let n = plane.xyz;
    m.normal = n;
    let l = local.half_length;
    let r = local.radius;
    let p0 = local.centre - local.dir * l;
    let e = local.dir * (2.0 * l);
    var enter = 0.0;
    var leave = 1.0;
    let run = poly_face_run(h, f);
    for (var k = 0u; k < run.y; k = k + 1u) {
        let a = poly_corner(h, poly_index(h, run.x + k));
        let b = poly_corner(h, poly_index(h, run.x + (k + 1u) % run.y));
        let side = cross(b - a, n);
        let start = dot(side, p0 - a);
        let rate = dot(side, e);
        if (rate == 0.0) {
            leave = select(leave, -1.0, start > 0.0);
        } else {
            let t = -start / rate;
            enter = select(enter, max(enter, t), rate < 0.0);
            leave = select(min(leave, t), leave, rate < 0.0);
        }
    }
    if (enter > leave) {
        return m;
    }
    let two = (leave - enter) * 2.0 * l > SIDE_BY_SIDE * r;
    let middle = 0.5 * (enter + leave);
    for (var q = 0u; q < 2u; q = q + 1u) {
        let t = select(middle, select(leave, enter, q == 0u), two);
        let p = p0 + e * t;
        let height = dot(n, p) - plane.w;
        if ((q == 0u || two) && height - r <= margin) {
            m.on_a[m.count] = p - n * height;
            m.on_b[m.count] = p - n * r;
            m.count = m.count + 1u;
        }
    }
    return m;
}

// A hull first, a sphere or capsule second (normal from the hull), as
// box_capsule: the hull's face axes and its edges crossed with the segment;
// where the segment misses the hull, its nearest point says which feature
// meets it.
fn hull_round(a: Solid, round: Swept, margin: f32) -> Manifold {
    let h = a.poly;
    let to_local = quat_conj(a.rot);
    let c = quat_rotate(to_local, round.centre - a.pos);
    let d = quat_rotate(to_local, round.dir);
    let l = round.half_length;
    let r = round.radius;
    let local = Swept(c, d, l, r);
    var face = 0u;
    var face_sep = -3.4e38;
    for (var f = 0u; f < h.faces; f = f + 1u) {
        let plane = poly_plane(h, f);
        let sep = dot(plane.xyz, c) - abs(dot(plane.xyz, d)) * l - plane.w;
        if (sep > face_sep) {
            face_sep = sep;
            face = f;
        }
    }
    // the segment's edge axes: where the edge's arc crosses the circle square to it
    var edge_sep = -3.4e38;
    var edge = 0u;
    var edge_n = vec3<f32>(0.0, 1.0, 0.0);
    if (l > 0.0) {
        for (var e = 0u; e < h.edges; e = e + 1u) {
            let ed = poly_edge(h, e);
            let n1 = poly_plane(h, ed.z).xyz;
            let n2 = poly_plane(h, ed.w).xyz;
            if (dot(n1, d) * dot(n2, d) < 0.0) {
                let p = poly_corner(h, ed.x);
                let along = poly_corner(h, ed.y) - p;
                let axis = cross(along, d);
                let len = length(axis);
                if (len >= 1e-5 * length(along)) {
                    let n = select(axis, -axis, dot(axis, n1 + n2) < 0.0) / len;
                    let sep = dot(n, c - p);
                    if (sep > edge_sep) {
                        edge_sep = sep;
                        edge = e;
                        edge_n = n;
                    }
                }
            }
        }
    }
    let worst = max(face_sep, edge_sep);
    if (worst - r > margin) {
        return empty_manifold();
    }
    var t = 0.0;
    if (l > 0.0) {
        t = nearest_to_hull(h, c, d, l);
    }
    let on_seg = c + d * t;
    let on_hull = nearest_on_hull(h, on_seg);
    let out = on_seg - on_hull;
    let dist = length(out);
    let misses = worst > 0.0 && dist > 1e-6;
    if (misses && dist - r > margin) {
        return empty_manifold();
    }
    var n = out / max(dist, 1e-30);
    // where it misses, the face its nearest point looks out of, if nearly
    // square to it; else the face of least overlap, unless an edge's
    var near_face = 0u;
    var aligned = -2.0;
    for (var f = 0u; f < h.faces; f = f + 1u) {
        let c_f = dot(poly_plane(h, f).xyz, n);
        if (c_f > aligned) {
            aligned = c_f;
            near_face = f;
        }
    }
    let k = select(face, near_face, misses);
    let along_edge = !misses && edge_sep > face_sep + EDGE_BIAS;
    var m = empty_manifold();
    if ((misses && aligned >= FACE_ALIGNED) || (!misses && !along_edge)) {
        m = hull_face_points(h, k, local, margin);
    }
    let plane = poly_plane(h, k);
    if (m.count > 0u || !misses) {
        n = plane.xyz;
    }
    if (misses && m.count == 0u) {
        m.count = 1u;
        m.on_a[0] = on_hull;
        m.on_b[0] = on_seg - n * r;
    }
    if (!misses && !along_edge && m.count == 0u) {
        // the segment crosses the face's plane beside the face: its end
        // deepest along the normal, against the face's point nearest its foot
        let low = select(c + d * l, c - d * l, dot(n, d) > 0.0);
        m.count = 1u;
        m.on_a[0] = nearest_on_face(h, k, n, low - n * (dot(n, low) - plane.w));
        m.on_b[0] = low - n * r;
    }
    if (along_edge) {
        n = edge_n;
        let ed = poly_edge(h, edge);
        let p = poly_corner(h, ed.x);
        let q = poly_corner(h, ed.y);
        var on_edge: vec3<f32>;
        var on_segment: vec3<f32>;
        closest_on_edges(0.5 * (p + q), normalize(q - p), 0.5 * length(q - p), c, d, l, &on_edge, &on_segment);
        m.count = 1u;
        m.on_a[0] = on_edge;
        m.on_b[0] = on_segment - n * r;
    }
    m.normal = n;
    return to_world(a, m);
}

// A hull's contact with the ground within `margin`, normal from the body
// down: its corners within the margin, reduced to four as a face contact's.
// The manifold serves the step's substeps, so corners are chosen by how low
// the step's motion (disp and the turn from prev_rot, repeated) brings them:
// a corner left out would sink unresisted while the body tips toward it.
fn ground_hull(a: Solid, disp: vec3<f32>, prev_rot: vec4<f32>, ground: f32, margin: f32) -> Manifold {
    var m = empty_manifold();
    m.normal = vec3<f32>(0.0, -1.0, 0.0);
    let r = quat_to_mat(a.rot);
    let turn = r - quat_to_mat(prev_rot);
    let steps = f32(params.substeps);
    var corners: array<vec3<f32>, MAX_CLIP>;
    var heights: array<f32, MAX_CLIP>;
    var near = 0u;
    for (var k = 0u; k < a.poly.corners; k = k + 1u) {
        let c = poly_corner(a.poly, k);
        let w = a.pos + r * c;
        if (w.y - ground <= margin) {
            corners[near] = w;
            heights[near] = w.y - ground + min((disp + turn * c).y * steps, 0.0);
            near = near + 1u;
        }
    }
    if (near == 0u) {
        return m;
    }
    let chosen = reduce(&corners, &heights, near, vec3<f32>(0.0, 1.0, 0.0), a.pos, true);
    for (var q = 0u; q < chosen.count; q = q + 1u) {
        let w = corners[chosen.at[q]];
        m.on_a[q] = w;
        m.on_b[q] = vec3<f32>(w.x, ground, w.z);
    }
    m.count = chosen.count;
    return m;
}

// Bodies i and j, one a hull at least (j may be GROUND), within `margin`:
// their manifold, normal from i to j. Bodies whose bounding spheres are
// apart have none: a kinematic drum panel's frame is the drum's axis, so
// the broadphase pairs it with all the drum holds.
fn collide_hull(i: u32, j: u32, margin: f32) -> Manifold {
    let pi = props_of(i);
    let si = state_of(i);
    if (j == GROUND) {
        return ground_hull(Solid(poly_of(pi), si.pos, si.rot), si.disp, si.prev_rot, params.ground_height, margin);
    }
    let pj = props_of(j);
    let sj = state_of(j);
    let a = Solid(poly_of(pi), si.pos, si.rot);
    let b = Solid(poly_of(pj), sj.pos, sj.rot);
    let sa = bounding_sphere(a, pi);
    let sb = bounding_sphere(b, pj);
    if (length(sb.xyz - sa.xyz) > sa.w + sb.w + margin) {
        return empty_manifold();
    }
    let round_i = pi.shape == SHAPE_SPHERE || pi.shape == SHAPE_CAPSULE;
    let round_j = pj.shape == SHAPE_SPHERE || pj.shape == SHAPE_CAPSULE;
    if (round_i || round_j) {
        // the hull first
        var hull = a;
        if (round_i) {
            hull = b;
        }
        let other = select(j, i, round_i);
        let po = props_of(other);
        let so = state_of(other);
        let m = hull_round(hull, swept_of(Shape(so.pos, so.rot, po.half_extents.xyz, po.shape)), margin);
        if (round_i) {
            return flip_manifold(m);
        }
        return m;
    }
    return hull_hull(a, b, margin);
}

// A body's bounding sphere (centre, radius): a hull's about its corners'
// box, any other's about its centre.
fn bounding_sphere(a: Solid, p: BodyProps) -> vec4<f32> {
    if (p.shape == SHAPE_HULL) {
        let s = poly_sphere(a.poly);
        return vec4<f32>(a.pos + quat_rotate(a.rot, s.xyz), s.w);
    }
    return vec4<f32>(a.pos, p.half_extents.w);
}
