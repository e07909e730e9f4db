// Contact manifolds between boxes and spheres: the twin of
// src/reference/collide.rs, step for step (its box_box is box_box_axis, then
// box_box_edge or box_box_face here); capsules' are in capsule.wgsl. A
// manifold's normal points from the first shape to the second;
// dot(on_b - on_a, n) < 0 where the shapes overlap.


// An edge axis must beat the best face axis by this much (m) to be chosen.
const EDGE_BIAS: f32 = 0.005;
// The second box's face must beat the first's by this much (m) to be the reference face.
const FACE_BIAS: f32 = 0.0025;

struct Shape {
    centre: vec3<f32>,
    rot: vec4<f32>,
    half: vec3<f32>, // box half extents; sphere: radius in x; capsule: (radius, half height, radius)
    kind: u32,
}

struct Manifold {
    normal: vec3<f32>,
    count: u32,
    on_a: array<vec3<f32>, 4>,
    on_b: array<vec3<f32>, 4>,
}

fn empty_manifold() -> Manifold {
    var m: Manifold;
    m.count = 0u;
    m.normal = vec3<f32>(0.0, 1.0, 0.0);
    return m;
}

fn sphere_sphere(ca: vec3<f32>, ra: f32, cb: vec3<f32>, rb: f32, margin: f32) -> Manifold {
    var m = empty_manifold();
    let d = cb - ca;
    let dist = length(d);
    if (dist - ra - rb > margin) {
        return m;
    }
    var n = vec3<f32>(0.0, 1.0, 0.0);
    if (dist > 1e-6) {
        n = d / dist;
    }
    m.normal = n;
    m.count = 1u;
    m.on_a[0] = ca + n * ra;
    m.on_b[0] = cb - n * rb;
    return m;
}

// Box first, sphere second.
fn box_sphere(cb: vec3<f32>, rot: vec4<f32>, h: vec3<f32>, cs: vec3<f32>, r: f32, margin: f32) -> Manifold {
    var m = empty_manifold();
    let local = quat_rotate(quat_conj(rot), cs - cb);
    let closest = clamp(local, -h, h);
    let outside = local - closest;
    let dist = length(outside);
    var n_local: vec3<f32>;
    var on_box_local: vec3<f32>;
    if (dist > 1e-6) {
        n_local = outside / dist;
        on_box_local = closest;
    } else {
        // centre inside the box: leave through the nearest face
        let room = h - abs(local);
        var k = 2u;
        if (room.x <= room.y && room.x <= room.z) {
            k = 0u;
        } else if (room.y <= room.z) {
            k = 1u;
        }
        let sign = select(-1.0, 1.0, local[k] >= 0.0);
        n_local = vec3<f32>(0.0);
        n_local[k] = sign;
        on_box_local = local;
        on_box_local[k] = sign * h[k];
    }
    let n = quat_rotate(rot, n_local);
    let on_box = cb + quat_rotate(rot, on_box_local);
    let on_sphere = cs - n * r;
    if (dot(on_sphere - on_box, n) > margin) {
        return m;
    }
    m.normal = n;
    m.count = 1u;
    m.on_a[0] = on_box;
    m.on_b[0] = on_sphere;
    return m;
}

fn flip_manifold(m_in: Manifold) -> Manifold {
    var m = m_in;
    m.normal = -m_in.normal;
    // every point, used or not: a fixed-length loop indexes by constants once unrolled
    for (var k = 0u; k < MAX_POINTS; k = k + 1u) {
        m.on_a[k] = m_in.on_b[k];
        m.on_b[k] = m_in.on_a[k];
    }
    return m;
}

fn box_axes(q: vec4<f32>) -> array<vec3<f32>, 3> {
    return array<vec3<f32>, 3>(
        quat_rotate(q, vec3<f32>(1.0, 0.0, 0.0)),
        quat_rotate(q, vec3<f32>(0.0, 1.0, 0.0)),
        quat_rotate(q, vec3<f32>(0.0, 0.0, 1.0)),
    );
}

fn project_box(axes: array<vec3<f32>, 3>, h: vec3<f32>, l: vec3<f32>) -> f32 {
    return h.x * abs(dot(axes[0], l)) + h.y * abs(dot(axes[1], l)) + h.z * abs(dot(axes[2], l));
}

fn sign_of(x: f32) -> f32 {
    // like Rust's f32::signum: +1 for +0
    return select(-1.0, 1.0, x >= 0.0);
}

// Closest points of two segments (centre, unit direction, half length).
fn closest_on_edges(pa: vec3<f32>, da: vec3<f32>, la: f32, pb: vec3<f32>, db: vec3<f32>, lb: f32,
                    out_a: ptr<function, vec3<f32>>, out_b: ptr<function, vec3<f32>>) {
    let r = pb - pa;
    let b = dot(da, db);
    let denom = 1.0 - b * b;
    let ra = dot(da, r);
    let rb = dot(db, r);
    var s = 0.0;
    if (denom > 1e-8) {
        s = (ra - b * rb) / denom;
    }
    s = clamp(s, -la, la);
    var t = clamp(b * s - rb, -lb, lb);
    s = clamp(b * t + ra, -la, la);
    t = clamp(b * s - rb, -lb, lb);
    *out_a = pa + da * s;
    *out_b = pb + db * t;
}

// Column k of m.
fn column(m: mat3x3<f32>, k: u32) -> vec3<f32> {
    return select(select(m[2], m[1], k == 1u), m[0], k == 0u);
}

// Component k of v.
fn component(v: vec3<f32>, k: u32) -> f32 {
    return select(select(v.z, v.y, k == 1u), v.x, k == 0u);
}

// z x of two vectors in a plane (twice the signed area of their triangle).
fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// The separating-axis test of two boxes within `margin`: the axis of least separation,
// a face axis (a's 0..3, b's 3..6) unless an edge axis beats it by EDGE_BIAS; a to b.
struct BoxAxis {
    kind: u32, // AXIS_*
    normal: vec3<f32>,
    face: u32,   // AXIS_FACE: the reference face, 0..6
    edge_i: u32, // AXIS_EDGE: a's edge direction
    edge_j: u32, // AXIS_EDGE: b's edge direction
}

const AXIS_APART: u32 = 0u; // separated by more than the margin
const AXIS_FACE: u32 = 1u;
const AXIS_EDGE: u32 = 2u;

fn box_box_axis(ca: vec3<f32>, qa: vec4<f32>, ha: vec3<f32>, cb: vec3<f32>, qb: vec4<f32>, hb: vec3<f32>, margin: f32) -> BoxAxis {
    // In a's frame (column j of r is b's axis j, t is b's centre), all 15 axes
    // with no early exit and no array indexing: a vector's lanes run the same
    // code whatever their pair, and most candidate pairs touch.
    let axes_a = box_axes(qa);
    let axes_b = box_axes(qb);
    let ma = mat3x3<f32>(axes_a[0], axes_a[1], axes_a[2]);
    let r = transpose(ma) * mat3x3<f32>(axes_b[0], axes_b[1], axes_b[2]);
    let ar = mat3x3<f32>(abs(r[0]), abs(r[1]), abs(r[2]));
    let t = (cb - ca) * ma;

    // face axes of a (0..3) and b (3..6): separation, signed offset along the axis
    let sep_a = abs(t) - ha - ar * hb;
    let s_b = t * r;
    let sep_b = abs(s_b) - ha * ar - hb;
    // the best face of each (the first of equals); b's must beat a's by FACE_BIAS
    let a_sep = max(max(sep_a.x, sep_a.y), sep_a.z);
    let b_sep = max(max(sep_b.x, sep_b.y), sep_b.z);
    let a_face = select(select(2u, 1u, sep_a.y >= sep_a.z), 0u, sep_a.x >= sep_a.y && sep_a.x >= sep_a.z);
    let b_face = select(select(2u, 1u, sep_b.y >= sep_b.z), 0u, sep_b.x >= sep_b.y && sep_b.x >= sep_b.z);
    let best_face = select(a_face, 3u + b_face, b_sep > a_sep + FACE_BIAS);
    let best_face_sep = max(a_sep, b_sep);
    var worst = best_face_sep;
    let face_s = select(s_b[best_face % 3u], t[best_face % 3u], best_face < 3u);
    let face_axis = column(mat3x3<f32>(select(axes_b[0], axes_a[0], best_face < 3u), select(axes_b[1], axes_a[1], best_face < 3u),
                                       select(axes_b[2], axes_a[2], best_face < 3u)), best_face % 3u);
    let best_face_n = select(face_axis, -face_axis, face_s < 0.0);

    // edge axes a_i x b_j, in a's frame; near-parallel edges are left to the faces
    var best_edge_sep = -3.4e38;
    var best_edge_l = vec3<f32>(0.0, 1.0, 0.0);
    var best_edge = 0u;
    for (var e = 0u; e < 9u; e = e + 1u) {
        let i = e / 3u;
        let bj = r[e % 3u];
        let l = select(select(vec3<f32>(-bj.y, bj.x, 0.0), vec3<f32>(bj.z, 0.0, -bj.x), i == 1u),
                       vec3<f32>(0.0, -bj.z, bj.y), i == 0u);
        let len = length(l);
        let s = dot(t, l);
        let sep = (abs(s) - dot(ha, abs(l)) - dot(hb, abs(l * r))) / len;
        let counts = len >= 1e-5;
        worst = select(worst, max(worst, sep), counts);
        let better = counts && sep > best_edge_sep;
        best_edge_sep = select(best_edge_sep, sep, better);
        best_edge_l = select(best_edge_l, select(l, -l, s < 0.0) / len, better);
        best_edge = select(best_edge, e, better);
    }
    if (worst > margin) {
        return BoxAxis(AXIS_APART, vec3<f32>(0.0, 1.0, 0.0), 0u, 0u, 0u);
    }
    if (best_edge_sep > best_face_sep + EDGE_BIAS) {
        return BoxAxis(AXIS_EDGE, ma * best_edge_l, 0u, best_edge / 3u, best_edge % 3u);
    }
    return BoxAxis(AXIS_FACE, best_face_n, best_face, 0u, 0u);
}

// The one point of an edge-edge contact along `axis` (an AXIS_EDGE).
fn box_box_edge(ca: vec3<f32>, qa: vec4<f32>, ha: vec3<f32>, cb: vec3<f32>, qb: vec4<f32>, hb: vec3<f32>, axis: BoxAxis) -> Manifold {
    var m = empty_manifold();
    let ma = mat3x3<f32>(quat_rotate(qa, vec3<f32>(1.0, 0.0, 0.0)), quat_rotate(qa, vec3<f32>(0.0, 1.0, 0.0)),
                         quat_rotate(qa, vec3<f32>(0.0, 0.0, 1.0)));
    let mb = mat3x3<f32>(quat_rotate(qb, vec3<f32>(1.0, 0.0, 0.0)), quat_rotate(qb, vec3<f32>(0.0, 1.0, 0.0)),
                         quat_rotate(qb, vec3<f32>(0.0, 0.0, 1.0)));
    let n = axis.normal;
    let edge_i = axis.edge_i;
    let edge_j = axis.edge_j;
    // the edge of a farthest along n, the edge of b farthest along -n (axes
    // picked by select: a per-lane array index is slow on lavapipe)
    var pa = ca;
    var pb = cb;
    for (var k = 0u; k < 3u; k = k + 1u) {
        if (k != edge_i) {
            pa = pa + ma[k] * (ha[k] * sign_of(dot(ma[k], n)));
        }
        if (k != edge_j) {
            pb = pb - mb[k] * (hb[k] * sign_of(dot(mb[k], n)));
        }
    }
    var on_a: vec3<f32>;
    var on_b: vec3<f32>;
    closest_on_edges(pa, column(ma, edge_i), component(ha, edge_i), pb, column(mb, edge_j), component(hb, edge_j), &on_a, &on_b);
    m.normal = n;
    m.count = 1u;
    m.on_a[0] = on_a;
    m.on_b[0] = on_b;
    return m;
}

// The manifold of a face contact (AXIS_FACE, normal n, reference face best_face):
// the other box's incident face clipped against the reference face's sides in its
// plane, the points within the margin, reduced to four.
fn box_box_face(ca: vec3<f32>, qa: vec4<f32>, ha: vec3<f32>, cb: vec3<f32>, qb: vec4<f32>, hb: vec3<f32>,
                n: vec3<f32>, best_face: u32, margin: f32) -> Manifold {
    var m = empty_manifold();
    let axes_a = box_axes(qa);
    let axes_b = box_axes(qb);
    // reference box owns the face; ref_n points from it to the incident box
    let flipped = best_face >= 3u;
    let face = best_face % 3u;
    let ref_c = select(ca, cb, flipped);
    let ref_h = select(ha, hb, flipped);
    let ref_axes = mat3x3<f32>(select(axes_a[0], axes_b[0], flipped), select(axes_a[1], axes_b[1], flipped),
                               select(axes_a[2], axes_b[2], flipped));
    let inc_c = select(cb, ca, flipped);
    let inc_h = select(hb, ha, flipped);
    let inc_axes = mat3x3<f32>(select(axes_b[0], axes_a[0], flipped), select(axes_b[1], axes_a[1], flipped),
                               select(axes_b[2], axes_a[2], flipped));
    let ref_n = select(n, -n, flipped);
    // incident face: the incident box's face most anti-parallel to ref_n (first of equals)
    let along = abs(ref_n * inc_axes);
    let inc_face = select(select(2u, 1u, along.y >= along.z), 0u, along.x >= along.y && along.x >= along.z);
    let inc_axis = column(inc_axes, inc_face);
    let inc_centre = inc_c + inc_axis * (inc_h[inc_face] * -sign_of(dot(inc_axis, ref_n)));
    let eu = column(inc_axes, (inc_face + 1u) % 3u) * inc_h[(inc_face + 1u) % 3u];
    let ev = column(inc_axes, (inc_face + 2u) % 3u) * inc_h[(inc_face + 2u) % 3u];

    // the reference face's frame: its centre, its two side axes and ref_n
    let ref_centre = ref_c + ref_n * ref_h[face];
    let side_u = (face + 1u) % 3u;
    let side_v = (face + 2u) % 3u;
    let su = column(ref_axes, side_u);
    let sv = column(ref_axes, side_v);
    let to_face = transpose(mat3x3<f32>(su, sv, ref_n));
    let c = to_face * (inc_centre - ref_centre);
    let du = (to_face * eu).xy;
    let dv = (to_face * ev).xy;
    // the incident face's corners, x and y four to a vector, and its edges corner to corner
    let px = c.x + vec4<f32>(du.x, -du.x, -du.x, du.x) + vec4<f32>(dv.x, dv.x, -dv.x, -dv.x);
    let py = c.y + vec4<f32>(du.y, -du.y, -du.y, du.y) + vec4<f32>(dv.y, dv.y, -dv.y, -dv.y);
    let ex = px.yzwx - px;
    let ey = py.yzwx - py;
    // the incident face's height above the reference face at (x, y): c.z + slope .
    // ((x, y) - c.xy); |nf.z| >= 1/sqrt(3), nf being the most parallel axis
    let nf = to_face * inc_axis;
    let slope = -nf.xy / nf.z;

    // The corners of the incident face's part within the reference face, found
    // without clipping in arrays (lavapipe keeps dynamically indexed arrays in
    // memory), as twelve candidates in three groups of four: where each edge
    // enters and leaves the reference face (Liang-Barsky on the two slabs),
    // then the reference face's corners strictly inside the incident face.
    let half = vec2<f32>(ref_h[side_u], ref_h[side_v]);
    let span_x = slab_span(px, ex, half.x);
    let span_y = slab_span(py, ey, half.y);
    let t0 = max(max(vec4<f32>(0.0), span_x.enter), span_y.enter);
    let t1 = min(min(vec4<f32>(1.0), span_x.leave), span_y.leave);
    let crosses = t0 <= t1;
    let leaves = crosses & (t1 < vec4<f32>(1.0)) & (t1 > t0);
    let winding = cross2(du, dv);
    let rx = half.x * vec4<f32>(1.0, -1.0, -1.0, 1.0);
    let ry = half.y * vec4<f32>(1.0, 1.0, -1.0, -1.0);
    let inside = vec4<bool>(inside_face(rx.x, ry.x, px, py, ex, ey, winding), inside_face(rx.y, ry.y, px, py, ex, ey, winding),
                            inside_face(rx.z, ry.z, px, py, ex, ey, winding), inside_face(rx.w, ry.w, px, py, ex, ey, winding));
    let g0 = candidates(px + t0 * ex, py + t0 * ey, crosses, c, slope, margin);
    let g1 = candidates(px + t1 * ex, py + t1 * ey, leaves, c, slope, margin);
    let g2 = candidates(rx, ry, inside, c, slope, margin);

    // those within the margin (`kept`), reduced to four: the deepest, the farthest from
    // it, the largest triangle, the largest area added (first of equals; NONE if none)
    let c0 = best_candidate(-g0.z, -g1.z, -g2.z, g0, g1, g2);
    let p0 = candidate_at(g0, g1, g2, c0).xy;
    let c1 = best_candidate(distance2_to(g0, p0), distance2_to(g1, p0), distance2_to(g2, p0), g0, g1, g2);
    let p1 = candidate_at(g0, g1, g2, c1).xy;
    let c2 = best_candidate(abs(cross2_to(g0, p0, p1 - p0)), abs(cross2_to(g1, p0, p1 - p0)), abs(cross2_to(g2, p0, p1 - p0)),
                            g0, g1, g2);
    let p2 = candidate_at(g0, g1, g2, c2).xy;
    let side = sign_of(cross2(p1 - p0, p2 - p0));
    let c3 = best_candidate(area_added(g0, p0, p1, p2, side), area_added(g1, p0, p1, p2, side),
                            area_added(g2, p0, p1, p2, side), g0, g1, g2);
    // distinct choices only, in the order chosen, into slots 0..count
    let chosen = vec4<u32>(c0, c1, c2, c3);
    let fresh = vec4<bool>(c0 != NONE, c1 != c0, c2 != c0 && c2 != c1, c3 != c0 && c3 != c1 && c3 != c2);
    var slots = vec4<u32>(NONE);
    var count = 0u;
    for (var e = 0u; e < 4u; e = e + 1u) {
        slots = select(slots, vec4<u32>(chosen[e]), vec4<bool>(fresh[e]) & (vec4<u32>(count) == vec4<u32>(0u, 1u, 2u, 3u)));
        count = count + u32(fresh[e]);
    }
    m.normal = n;
    m.count = count;
    for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
        let p = candidate_at(g0, g1, g2, slots[q]);
        let on_ref = ref_centre + su * p.x + sv * p.y;
        let on_inc = on_ref + ref_n * p.z;
        m.on_a[q] = select(on_ref, on_inc, flipped);
        m.on_b[q] = select(on_inc, on_ref, flipped);
    }
    return m;
}

// The parameters t at which edges p + t e (four at once) enter and leave the slab
// |x| <= h; an edge parallel to it spans everything or nothing.
struct SlabSpan {
    enter: vec4<f32>,
    leave: vec4<f32>,
}

fn slab_span(p: vec4<f32>, e: vec4<f32>, h: f32) -> SlabSpan {
    let parallel = e == vec4<f32>(0.0);
    let d = select(e, vec4<f32>(1.0), parallel);
    let ta = (-h - p) / d;
    let tb = (h - p) / d;
    let within = abs(p) <= vec4<f32>(h);
    let all_or_none = select(vec4<f32>(3.4e38), vec4<f32>(-3.4e38), within);
    return SlabSpan(select(min(ta, tb), all_or_none, parallel), select(max(ta, tb), -all_or_none, parallel));
}

// Whether (x, y) lies strictly on the inner side of the four edges p + t e
// of a face wound as `winding` says.
fn inside_face(x: f32, y: f32, px: vec4<f32>, py: vec4<f32>, ex: vec4<f32>, ey: vec4<f32>, winding: f32) -> bool {
    return all((ex * (y - py) - ey * (x - px)) * winding > vec4<f32>(0.0));
}

// Four candidate points of a face contact in the reference face's plane, their
// heights above it, and which are kept (corners of the overlap within the margin).
struct Candidates {
    x: vec4<f32>,
    y: vec4<f32>,
    z: vec4<f32>,
    kept: vec4<bool>,
}

fn candidates(x: vec4<f32>, y: vec4<f32>, corner: vec4<bool>, c: vec3<f32>, slope: vec2<f32>, margin: f32) -> Candidates {
    let z = c.z + (slope.x * (x - c.x) + slope.y * (y - c.y));
    return Candidates(x, y, z, corner & (z <= vec4<f32>(margin)));
}

// Candidate k of the twelve (x, y, z): group k / 4, lane k % 4.
fn candidate_at(g0: Candidates, g1: Candidates, g2: Candidates, k: u32) -> vec3<f32> {
    let lane = k % 4u;
    let x = select(select(g2.x, g1.x, k < 8u), g0.x, k < 4u);
    let y = select(select(g2.y, g1.y, k < 8u), g0.y, k < 4u);
    let z = select(select(g2.z, g1.z, k < 8u), g0.z, k < 4u);
    return vec3<f32>(x[lane], y[lane], z[lane]);
}

// The kept candidate of highest score (scores by group), the first of equals; or NONE.
fn best_candidate(s0: vec4<f32>, s1: vec4<f32>, s2: vec4<f32>, g0: Candidates, g1: Candidates, g2: Candidates) -> u32 {
    var score = -3.4e38;
    var best = NONE;
    for (var k = 0u; k < 12u; k = k + 1u) {
        let lane = k % 4u;
        let s = select(select(s2, s1, k < 8u), s0, k < 4u)[lane];
        let kept = select(select(g2.kept, g1.kept, k < 8u), g0.kept, k < 4u)[lane];
        if (kept && s > score) {
            score = s;
            best = k;
        }
    }
    return best;
}

// Squared distances of four candidates from p.
fn distance2_to(g: Candidates, p: vec2<f32>) -> vec4<f32> {
    let dx = g.x - p.x;
    let dy = g.y - p.y;
    return dx * dx + dy * dy;
}

// cross2(d, q - o) for four candidates q.
fn cross2_to(g: Candidates, o: vec2<f32>, d: vec2<f32>) -> vec4<f32> {
    return d.x * (g.y - o.y) - d.y * (g.x - o.x);
}

// Twice the area four candidates add outside triangle p0 p1 p2 (winding `side`).
fn area_added(g: Candidates, p0: vec2<f32>, p1: vec2<f32>, p2: vec2<f32>, side: f32) -> vec4<f32> {
    return max(max(-side * cross2_to(g, p0, p1 - p0), -side * cross2_to(g, p1, p2 - p1)), -side * cross2_to(g, p2, p0 - p2));
}

// The manifold of a pair of which at least one is round (a sphere or a
// capsule, capsule.wgsl). A box and a round shape are measured box first, in
// one call for either order (one copy of each in the kernel), and flipped
// back when the round shape came first.
fn collide_round(a: Shape, b: Shape, margin: f32) -> Manifold {
    if (a.kind == SHAPE_SPHERE && b.kind == SHAPE_SPHERE) {
        return sphere_sphere(a.centre, a.half.x, b.centre, b.half.x, margin);
    }
    if (a.kind != SHAPE_BOX && b.kind != SHAPE_BOX) {
        return round_round(swept_of(a), swept_of(b), margin);
    }
    let flip = a.kind != SHAPE_BOX;
    let box_centre = select(a.centre, b.centre, flip);
    let box_rot = select(a.rot, b.rot, flip);
    let box_half = select(a.half, b.half, flip);
    var round = b;
    if (flip) {
        round = a;
    }
    var m: Manifold;
    if (round.kind == SHAPE_SPHERE) {
        m = box_sphere(box_centre, box_rot, box_half, round.centre, round.half.x, margin);
    } else {
        m = box_capsule(box_centre, box_rot, box_half, swept_of(round), margin);
    }
    if (flip) {
        return flip_manifold(m);
    }
    return m;
}
