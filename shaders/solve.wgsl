// Passes "solve_contacts", "solve", "joint_rest", "solve_joints" and
// "solve_paths", run in each substep its share of `iterations` times
// (solve_paths twice): the paper's corrective snaps (eqs. 9-10). Contacts are
// relaxed Jacobi style from state_in: solve_contacts (per manifold) writes
// what a pair's points ask of each body (two EndSnaps), and solve (per
// listed body with contacts) sums them in pair order, relaxes
// the sum by c_r and moves its own pose in place (bound as state_out: every
// snap was measured in the pass before). All of a body's snaps are measured on
// one pose, so symmetric contacts cancel and no sum depends on thread timing.
// The reasons behind the constants: docs/decisions/contacts.md, joints.md.

// A snap being summed: translation and rotation (radians, world axes).
struct Snap {
    dx: vec3<f32>,
    dtheta: vec3<f32>,
}

// Each point's normal snap closes its depth, shared by the inverse masses;
// static friction (XPBD) undoes a slide shorter than mu times the summed push.
// The points of one face each ask the whole depth, so their sum is scaled down
// to what moving the bodies apart without turning asks, and their turns by
// how far the points' turns, summed, overshoot a shared turn (`turn_scale`).

// Softened shock propagation (after Guendelman et al. 2003): in a contact
// within 25 degrees of the vertical (|cos| > SHOCK_UP) the lower body counts
// SHOCK times its inverse mass and inertia, so the sweeps' remainder does not
// compress a tall column until it leans. Momentum is not conserved in such a
// contact; the restitution pass, which decides bounces, does not use it.
const SHOCK: f32 = 0.65;
const SHOCK_UP: f32 = 0.9;

// Old overlap deeper than this speed (m/s) times the substep settles: its push
// moves the pose and the previous pose together, so it never becomes velocity.
const SETTLE_SPEED: f32 = 1.0;

// Shallower old overlap is pushed out as velocity (Verlet): that carries a
// stack's support from substep to substep. But what a tall stack is squeezed
// by in its first steps would come back as a throw, so the push becomes
// velocity against gravity only while the body rises slower than this (m/s).
const SUPPORT_SPEED: f32 = 0.2;

// Chebyshev semi-iterative acceleration of the sweeps (Wang 2015), on each
// point's normal push: within a substep, sweep k pushes w_k times what the
// point's depth asks plus w_k - 1 times its push in the sweep before, never
// more than the whole depth (a contact cannot pull back what overshoots),
// with w_1 = 1, w_2 = 2 / (2 - rho^2), w_(k+1) = 4 / (4 - rho^2 w_k) for
// rho the sweep's spectral radius as estimated: a stack's support climbs
// faster than a row a sweep, and the friction budget counts what was
// pushed. Weighting each body's move instead, 0.9 threw large_pyramid
// apart (docs/decisions/contacts.md).
const CHEBYSHEV_RHO: f32 = 0.8;

// The weighted push's excess over the plain one, at most this many times
// what a substep's gravity moves a body (g h^2): loads under gravity are
// carried faster, while bodies placed inside each other part about as fast
// as unweighted (uncapped, fifty boxes at one point parted at up to 3.9 m/s,
// past the 3.5 the tests allow).
const CHEBYSHEV_MOST: f32 = 4.0;

// This sweep's weight (the substep's sweeps so far: status[STATUS_SWEEPS]).
fn sweep_weight() -> f32 {
    let rho2 = CHEBYSHEV_RHO * CHEBYSHEV_RHO;
    // bounded, as every loop here is: the weights settle long before
    let done = min(atomicLoad(&status[STATUS_SWEEPS]), 64u);
    var w = 1.0;
    for (var k = 0u; k < done; k = k + 1u) {
        w = select(4.0 / (4.0 - rho2 * w), 2.0 / (2.0 - rho2), k == 0u);
    }
    return w;
}

// The deepest a body may end a sweep in the ground (m; see solve).
const GROUND_DEPTH: f32 = 0.01;

// Normal pushes against ends that stay are split as friction is (bindings.wgsl's
// friction_split), or the sweeps overshoot and the body rattles: held by k > 0
// such ends, a body counts its inverse mass max(1, c_r s) times against them,
// s its pushes' shares summed (pair_meta's normal_split). Not for a jointed
// body, whose joints would pull it back against the weakened pushes.
// Body i's splits (x: friction's, y: the normal pushes'): 1 unless the other end stays.
fn stay_splits(i: u32, partner_moves: bool) -> vec2<f32> {
    var splits = vec2<f32>(1.0);
    if (!partner_moves && i != GROUND) {
        splits = vec2<f32>(friction_split(i, params.relaxation), pair_meta[i].normal_split);
    }
    return splits;
}

@compute @workgroup_size(WORKGROUP)
fn solve_contacts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let used = manifolds_used();
    let nth = dispatch_index(gid, groups);
    if (nth >= used) {
        return;
    }
    let k = pool_slot(nth, used);
        // read once: the pool is written here, so a second read is a second load
    let m = manifold_of(k);
    let a = m.a;
    let b = m.b;
    let count = m.count;
    let at = point_slot(k);
    var ea = contact_end(a);
    var eb = contact_end(b);
    if (!ea.moves && !eb.moves) {
        return; // neither body reads its snap
    }
    let n = m.normal; // from a to b: a is pushed along -n, b along n
        // SHOCK on the lower body (up_n: n against gravity; > 0: b lies above a)
    let g = length(params.gravity);
    let up_n = select(0.0, -dot(n, params.gravity) / max(g, 1e-30), g > 0.0);
    let shock = select(1.0, SHOCK, abs(up_n) > SHOCK_UP);
    let shock_a = select(1.0, shock, up_n > 0.0);
    let shock_b = select(1.0, shock, up_n < 0.0);
    ea.inv_inertia = ea.inv_inertia * shock_a;
    ea.inv_i_world = ea.inv_i_world * shock_a;
    eb.inv_inertia = eb.inv_inertia * shock_b;
    eb.inv_i_world = eb.inv_i_world * shock_b;
    let mu = combined_friction(ea, eb);
        // x: friction's split, y: the normal pushes' (stay_splits)
    let split_a = stay_splits(a, eb.moves);
    let split_b = stay_splits(b, ea.moves);
        // summed over the points for a (b gets the opposite): pushes, moments, 1 / w
    var normal_j = vec3<f32>(0.0);
    var friction_j = vec3<f32>(0.0);
    var moment_a = vec3<f32>(0.0);
    var moment_b = vec3<f32>(0.0);
    var normal_inv_w = 0.0;
    var friction_inv_w = 0.0;
    var points = 0u;
    var rubbed = 0u;
    var pressed = 0u;
    // each end's turn per unit of its points' asks, summed over them (turn_scale)
    var k_a = vec3<f32>(0.0);
    var k_b = vec3<f32>(0.0);
    // weighted only between two bodies that move and touch no end that
    // stays (the ground, a fixed body, a sleeper), and that are on no joint
    // (closed after each sweep, it pulls back against a weighted push): the
    // form that holds large_pyramid at 8 sweeps and keeps every test
    // (docs/decisions/contacts.md, "Chebyshev weights")
    let weight = sweep_weight();
    let weighted = weight != 1.0 && ea.moves && eb.moves && pair_meta[a].held == 0u && pair_meta[b].held == 0u
        && !is_jointed(a) && !is_jointed(b);
    let most_more = g * params.dt * params.dt * CHEBYSHEV_MOST;
    // depths summed: old overlap that settles, old overlap that supports, all
    var old_depth = 0.0;
    var shallow_depth = 0.0;
    var all_depth = 0.0;
    for (var q = 0u; q < count; q = q + 1u) {
        let pt = point_of(at, q);
        let local_a = end_point(ea, pt.local_a, n);
        let local_b = end_point(eb, pt.local_b, -n);
        let ra = ea.rot_m * local_a;
        let rb = eb.rot_m * local_b;
        let on_a = ea.pos + ra;
        let on_b = eb.pos + rb;
        // how far each material point moved, from disp (no far-out differences)
        let moved_a = ea.disp + ea.turn_m * local_a;
        let moved_b = eb.disp + eb.turn_m * local_b;
        // old overlap (at the previous poses) is pushed out at no more than
        // MAX_DEPENETRATION_SPEED, as a full snap would become velocity;
        // overlap made by this substep's approach is removed whole
        let overlap_before = dot((on_a - moved_a) - (on_b - moved_b), n);
        let held_back = overlap_before - MAX_DEPENETRATION_SPEED * params.dt;
        let overlap = dot(on_a - on_b, n);
        let depth = overlap - max(held_back, 0.0);
        // the part of the depth that is old overlap (the rest this substep made)
        let old = clamp(depth - max(overlap - overlap_before, 0.0), 0.0, max(depth, 0.0));
        let deep = overlap_before > SETTLE_SPEED * params.dt;
        old_depth = old_depth + select(0.0, old, deep);
        shallow_depth = shallow_depth + select(old, 0.0, deep);
        all_depth = all_depth + max(depth, 0.0);
        // a point that pushed earlier this substep keeps its friction while it
        // still touches, so later sweeps' sideways pushes are resisted too
        var push = 0.0;
        var snapped = false;
        if (depth > 0.0) {
            let turn_a = end_turn(ea, ra, n);
            let turn_b = end_turn(eb, rb, n);
            let w = row_inv_mass(ea, turn_a) * split_a.y + row_inv_mass(eb, turn_b) * split_b.y;
            // the push (solve relaxes what the depth asks by c_r), weighted
            push = depth * params.relaxation;
            var asked = depth;
            if (weighted) {
                let more = min((weight - 1.0) * (push + pt.last_push), most_more);
                if (more > 0.0) {
                    push = min(push + more, depth);
                    asked = push / params.relaxation;
                }
            }
            let j = n * (asked / w); // pushes b along n, a along -n
            normal_j = normal_j + j;
            moment_a = moment_a + cross(ra, j);
            moment_b = moment_b + cross(rb, j);
            normal_inv_w = normal_inv_w + 1.0 / w;
            k_a = k_a + turn_a / w;
            k_b = k_b + turn_b / w;
            snapped = true;
        }
        if (depth > 0.0 || (pt.pushed > 0.0 && depth >= -CONTACT_SLOP)) {
            // how far a's point slid against b's since the previous poses
            let slip = moved_a - moved_b;
            let slip_t = slip - n * dot(slip, n);
            let slide = length(slip_t);
            if (slide > 1e-9 && slide <= mu * (pt.pushed + push)) {
                let t = slip_t / slide;
                let turn_a = end_turn(ea, ra, t);
                let turn_b = end_turn(eb, rb, t);
                let w = row_inv_mass(ea, turn_a) * split_a.x + row_inv_mass(eb, turn_b) * split_b.x;
                let j = t * (slide / w); // pulls b along t, a back along -t
                friction_j = friction_j + j;
                moment_a = moment_a + cross(ra, j);
                moment_b = moment_b + cross(rb, j);
                friction_inv_w = friction_inv_w + 1.0 / w;
                k_a = k_a + turn_a / w;
                k_b = k_b + turn_b / w;
                rubbed = rubbed + 1u;
                snapped = true;
            }
        }
        set_pushed(at, q, pt.pushed + push);
        set_last_push(at, q, push);
        if (pt.pushed + push > 0.0) {
            pressed = 1u;
        }
        points = points + u32(snapped);
    }
    var pair_w = 0.0;
    var pair_w_split = 0.0;
    if (ea.moves) {
        pair_w = pair_w + ea.inv_inertia.w;
        pair_w_split = pair_w_split + ea.inv_inertia.w * split_a.y;
    }
    if (eb.moves) {
        pair_w = pair_w + eb.inv_inertia.w;
        pair_w_split = pair_w_split + eb.inv_inertia.w * split_b.y;
    }
    let n_scale = min(1.0, 1.0 / max(pair_w_split * normal_inv_w, 1e-30));
    var f_scale = min(1.0, 1.0 / max(pair_w * friction_inv_w, 1e-30));
    // a capsule turns freely about its axis, and its points lie along it, so
    // their friction turns it as one point's does (the turns are averaged):
    // their pushes are averaged too, or a rolling capsule is held back
    if (HAS_ROUND && (ea.half_height > 0.0 || eb.half_height > 0.0)) {
        f_scale = min(f_scale, 1.0 / f32(max(rubbed, 1u)));
    }
    let j = normal_j * n_scale + friction_j * f_scale;
    // a capsule's points lie along the axis it turns freely about, so they
    // share one turn, their mean (docs/decisions/contacts.md)
    let capsule = HAS_ROUND && (ea.half_height > 0.0 || eb.half_height > 0.0);
    let mean = 1.0 / f32(max(points, 1u));
    let turns_a = select(turn_scale(k_a), mean, capsule);
    let turns_b = select(turn_scale(k_b), mean, capsule);
    let touched = u32(points > 0u);
    // the shares of the snap that settle and that support (see solve)
    let settle = u32(round(clamp(old_depth / max(all_depth, 1e-30), 0.0, 1.0) * SETTLE_ONE));
    let support = u32(round(clamp(shallow_depth / max(all_depth, 1e-30), 0.0, 1.0) * SUPPORT_ONE));
    let flags = select(0u, SNAP_PRESSED, pressed != 0u) | (settle << SETTLE_SHIFT) | (support << SUPPORT_SHIFT);
    let against_a = select(0u, SNAP_FIXED_PARTNER, eb.fixed);
    let against_b = select(0u, SNAP_FIXED_PARTNER, ea.fixed);
    set_snap(contact_ref(k, false), end_snap(ea, -j, -moment_a * turns_a, touched | against_a, flags));
    set_snap(contact_ref(k, true), end_snap(eb, j, moment_b * turns_b, touched | against_b, flags));
}

@compute @workgroup_size(WORKGROUP)
fn solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    // the sweep is done once this pass runs: the next one's weight (sweep_weight)
    if (gid.x == 0u) {
        atomicAdd(&status[STATUS_SWEEPS], 1u);
    }
    let i = touching_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    // nothing to sum (run_stages lists every body): the pose stays as
    // integrate wrote it, which cleared HELD
    if (pair_meta[i].contacts == 0u) {
        return;
    }
    // (its previous rotation is read and written where it settles alone)
    var s = out_pose(i);
    let p = props_of(i);
    if (is_fixed(p) || is_kinematic(p) || asleep(s)) {
        return;
    }
    var acc = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    var touching = 0u;
    // SNAP_PRESSED if a contact pushed this substep (integrate's test for sleep)
    var flags = 0u;
    let first = pair_meta[i].list_start;
    let end = first + pair_meta[i].contacts;
    // the snaps' settling and supporting parts, apart (not for a jointed body:
    // its joints measure old gaps at the previous poses, which settling moves)
    var settle = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    var settling = 0u;
    var support_dx = vec3<f32>(0.0);
    // the longest translation one partner asks (the cap below)
    var longest = 0.0;
    var fixed_partners = false;
    let jointed = is_jointed(i);
    for (var e = first; e < end; e = e + 1u) {
        let snap = snap_of(body_pairs[e]);
        let settles = select(snap.flags >> SETTLE_SHIFT, 0u, jointed);
        let supports = select((snap.flags >> SUPPORT_SHIFT) & SUPPORT_MASK, 0u, jointed);
        let lifts = f32(supports) / SUPPORT_ONE;
        support_dx = support_dx + snap.dx * lifts;
        if (settles != 0u) {
            let f = f32(settles) / SETTLE_ONE;
            settle.dx = settle.dx + snap.dx * f;
            settle.dtheta = settle.dtheta + snap.dtheta * f;
            settling = settling + 1u;
            acc.dx = acc.dx + snap.dx * (1.0 - f - lifts);
            acc.dtheta = acc.dtheta + snap.dtheta * (1.0 - f);
        } else {
            acc.dx = acc.dx + snap.dx * (1.0 - lifts);
            acc.dtheta = acc.dtheta + snap.dtheta;
        }
        longest = max(longest, length(snap.dx) * (1.0 - f32(settles) / SETTLE_ONE));
        touching = touching + (snap.count & ~SNAP_FIXED_PARTNER);
        fixed_partners = fixed_partners || (snap.count & SNAP_FIXED_PARTNER) != 0u;
        flags = flags | snap.flags;
    }
    // a jointed body the contacts move: the substep's second solve of the
    // paths has work (solve_paths)
    if (jointed && touching > 0u) {
        atomicStore(&status[STATUS_PATHS_AGAIN], 1u);
    }
    // summed turns overshoot, so each partner's turn is scaled back to one
    // (turn_scale) and the partners' turns are averaged (translations are
    // scaled per partner)
    let split = 1.0 / f32(max(touching, 1u));
    // a snap moves the displacement with the pose: the velocity changes by
    // dx / h, as Verlet's moving x_n while x_(n-1) stays does
    // partners pushing the same way each ask the whole depth, and the relaxed
    // sum of many overshoots (thirty boxes placed at one point rose 27 m): the
    // pose moves no farther than twice the longest single ask, what four
    // partners pushing one way sum to at c_r 0.5 (a box landing across four)
    let asked = length(acc.dx + support_dx) * params.relaxation;
    let cap = min(1.0, 2.0 * longest / max(asked, 1e-30));
    let dx = acc.dx * (params.relaxation * cap);
    let up = support_dx * (params.relaxation * cap);
    s.pos = s.pos + dx + up;
    s.disp = s.disp + dx;
    // the support's push becomes velocity only up to SUPPORT_SPEED upward; the
    // rest of it (all of it without gravity) moves both poses
    let g = length(params.gravity);
    let rise = -params.gravity / max(g, 1e-30);
    let lift = select(0.0, max(dot(up, rise), 0.0), g > 0.0);
    s.disp = s.disp + (up - rise * lift);
    let room = max(SUPPORT_SPEED * params.dt - dot(s.disp, rise), 0.0);
    s.disp = s.disp + rise * min(lift, room);
    s.pos_low = (s.pos_low & ~HELD) | select(0u, HELD, (flags & SNAP_PRESSED) != 0u);
    s.rot = quat_add_rotation(s.rot, acc.dtheta * (params.relaxation * split * cap));
    // Settling (SETTLE_SPEED): both poses move by the mean of the settling parts.
    // A settling body is not at rest, though its velocity may be nil.
    if (settling > 0u) {
        s.rest_time = 0.0;
        let share = params.relaxation / f32(settling);
        s.pos = s.pos + settle.dx * share;
        s.rot = quat_add_rotation(s.rot, settle.dtheta * share);
        state_out[i].prev_rot = quat_add_rotation(state_out[i].prev_rot, settle.dtheta * share);
    }
    // The ground stays whatever presses on it: partners far heavier than a
    // body outweigh its ground contact in the sum, and a pile of heavy boxes
    // on light ones pushed the light ones through it. A body left deeper than
    // GROUND_DEPTH in the ground is lifted to it, both poses alike. Not a
    // jointed body: its joints, closed after the sweep, would pull it back.
    // A select, not a branch: where no joint is compiled in (HAS_JOINTS) the
    // condition is the uniform's alone, and lavapipe compiled such a pass
    // again at every dispatch (docs/lavapipe.md).
    var lowest = s.pos.y - world_extent(s, p).y;
    if (HAS_HULLS && p.shape == SHAPE_HULL) {
        lowest = s.pos.y - body_reach(p, s.rot, vec3<f32>(0.0, -1.0, 0.0));
    }
    let depth = params.ground_height - lowest;
    s.pos.y = select(s.pos.y, s.pos.y + max(depth - GROUND_DEPTH, 0.0), params.has_ground != 0u && !jointed);
    // The same for fixed bodies: walls and floors made of boxes stay too.
    if (fixed_partners && !jointed) {
        for (var e = first; e < end; e = e + 1u) {
            let r = body_pairs[e];
            if ((snap_of(r).count & SNAP_FIXED_PARTNER) != 0u) {
                s.pos = s.pos + out_of_fixed(r, s, p);
            }
        }
    }
    set_pose(i, s);
}

// How far body i, at pose s, must move to be no deeper than GROUND_DEPTH in
// the fixed partner of its manifold reference r, along the manifold's normal
// n: the overlap of the two shapes' extents along n, as the ground lift
// measures the ground's. Whole shapes, not the manifold's points, so a corner
// the step's turn brought down counts too.
fn out_of_fixed(r: u32, s: BodyState, p: BodyProps) -> vec3<f32> {
    let m = manifold_of(r >> 1u);
    let is_b = (r & 1u) != 0u;
    let other = select(m.b, m.a, is_b);
    // n from this body toward its partner
    let n = select(m.normal, -m.normal, is_b);
    let o = out_state(other);
    let overlap = dot(s.pos - o.pos, n) + body_reach(p, s.rot, n) + body_reach(props_of(other), o.rot, -n);
    return -n * max(overlap - GROUND_DEPTH, 0.0);
}

// A sweep of a path that closes no joint by more than this (m) leaves the
// rest of the pass's sweeps nothing to do, and a path solved directly whose
// joints are all this near closed (or as near as rounding allows) is left
// as it is (path_settled).
const JOINT_SETTLED: f32 = 1e-5;

// Gauss-Seidel sweeps along a path in a solve_joints pass (one pass after
// each relaxation sweep), at most: a pass ends at a sweep that closes no
// joint by more than JOINT_SETTLED. A ragdoll settles in a few; a bridge
// pinned taut at both ends and loaded is the slowest case met, and its gaps
// follow the sweeps a step makes, not its substeps (docs/step.md, "Joints").
const JOINT_SWEEPS_PER_PASS: u32 = 24u;

// Pass "solve_joints", after every solve, once per colour of joint paths
// (joint_lists in src/world/records.rs), one invocation per path of an
// island with a branch or a loop (of at most 128 joints; solve_paths takes
// chains and the paths cut from larger islands): closes the path's joints
// one after the other, outward and back, in place. A Jacobi sum
// carries a correction one link per sweep; a sweep along the path carries it
// all the way. No two paths of a colour share a body that moves, and a path's
// order is fixed, so nothing depends on thread timing. See docs/decisions/joints.md.

// A joint's world anchors' offsets from its ends' centres, ra then rb (nil
// for a joint to the world), at the orientations rot_a and rot_b.
fn joint_anchors(j: JointRef, rot_a: vec4<f32>, rot_b: vec4<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(quat_rotate(rot_a, j.local_self),
                               select(vec3<f32>(0.0), quat_rotate(rot_b, j.local_partner), j.partner != WORLD));
}

// A joint's anchors' offsets, its gap from a's anchor to b's and that gap's
// length, and how much of it may stay open this substep (`bounded`): the gap
// at the previous poses closes at no more than MAX_DEPENETRATION_SPEED (a
// full snap becomes velocity); what this substep opened closes whole.
struct JointGap {
    ra: vec3<f32>,
    rb: vec3<f32>,
    gap: vec3<f32>,
    dist: f32,
    bounded: f32,
}

fn joint_gap(j: JointRef, sa: BodyState, sb: BodyState) -> JointGap {
    let joined = j.partner != WORLD;
    let r = joint_anchors(j, sa.rot, sb.rot);
    let gap = select(j.local_partner, sb.pos + r[1], joined) - (sa.pos + r[0]);
    let moved_a = sa.disp + (r[0] - quat_rotate(sa.prev_rot, j.local_self));
    let moved_b = select(vec3<f32>(0.0), sb.disp + (r[1] - quat_rotate(sb.prev_rot, j.local_partner)), joined);
    let before = length(gap - (moved_b - moved_a));
    return JointGap(r[0], r[1], gap, length(gap), max(before - MAX_DEPENETRATION_SPEED * params.dt, 0.0));
}

// Closes one joint (eq. 9) on the states *sa and *sb of its body and partner
// (sb unused for a joint to the world): they move along the gap between the
// anchors, by their generalised inverse masses, and the displacement moves
// with the pose, as solve's snaps do. Says which of the two it moved, and
// how far it closed the gap in *closed.
fn close_joint(j: JointRef, sa: ptr<function, BodyState>, sb: ptr<function, BodyState>, closed: ptr<function, f32>) -> vec2<bool> {
    let joined = j.partner != WORLD;
    let pa = props_of(j.body);
    let pb = props_of(select(j.body, j.partner, joined));
    let g = joint_gap(j, *sa, *sb);
    let ra = g.ra;
    let rb = g.rb;
    let dist = g.dist;
    let bounded = g.bounded;
    let n = g.gap / max(dist, 1e-30); // a moves along n, b against it
    // each end's turn per unit push along n, found once for its mass and its move
    let turn_a = inv_inertia_world((*sa).rot, pa.inv_inertia.xyz, cross(ra, n));
    let turn_b = inv_inertia_world((*sb).rot, pb.inv_inertia.xyz, cross(rb, n));
    let wa = select(pa.inv_inertia.w + dot(cross(ra, n), turn_a), 0.0, is_fixed(pa));
    let wb = select(0.0, pb.inv_inertia.w + dot(cross(rb, n), turn_b), joined && !is_fixed(pb));
    if (dist <= bounded + 1e-7 || wa + wb <= 0.0) {
        *closed = 0.0;
        return vec2<bool>(false);
    }
    *closed = dist - bounded;
    let lambda = (dist - bounded) / (wa + wb);
    if (wa > 0.0) {
        let dx = n * (pa.inv_inertia.w * lambda);
        (*sa).pos = (*sa).pos + dx;
        (*sa).disp = (*sa).disp + dx;
        (*sa).rot = quat_add_rotation((*sa).rot, turn_a * lambda);
    }
    if (wb > 0.0) {
        let dx = n * (-pb.inv_inertia.w * lambda);
        (*sb).pos = (*sb).pos + dx;
        (*sb).disp = (*sb).disp + dx;
        (*sb).rot = quat_add_rotation((*sb).rot, turn_b * -lambda);
    }
    return vec2<bool>(wa > 0.0, wb > 0.0);
}

// Passes "joint_rest_clear", "joint_rest_gather" and "joint_rest", in a
// step's first substep after its first solve, where bodies sleep: an island
// sleeps and wakes as one (a jointed body falls asleep only in that substep,
// see integrate, so the later ones find its island's bodies alike). Every
// body takes the island's least rest time, or none if nothing holds the
// island up (no contact presses it, no joint to the world or a fixed body). The island's least time and whether it is held are
// gathered over its joints, one invocation each, with integer atomics (a
// minimum and an or: the same result in any order), so no invocation reads
// a whole island and an island may be as large as a scene.

// Empties each island's words: no time yet (the bits of the largest f32), not held.
@compute @workgroup_size(WORKGROUP)
fn joint_rest_clear(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.island_count) {
        return;
    }
    atomicStore(&island_rest[2u * gid.x], bitcast<u32>(3.4e38f));
    atomicStore(&island_rest[2u * gid.x + 1u], 0u);
}

// The island of the nth joint of the islands' lists (they follow the bodies'
// lists in joint_start, island k's from joint_start[body_count + 1 + k]),
// or NONE past the last: a binary search over the islands' starts.
fn island_joint(nth: u32) -> vec2<u32> {
    let islands = params.body_count + 1u;
    let e = joint_start[islands] + nth;
    if (e >= joint_start[islands + params.island_count]) {
        return vec2<u32>(NONE, e);
    }
    // the last island whose start is at or before e: lo's start <= e < hi's
    var lo = 0u;
    var hi = params.island_count;
    for (var step = 0u; step < 32u; step = step + 1u) {
        let mid = (lo + hi) / 2u;
        if (hi - lo > 1u && joint_start[islands + mid] <= e) {
            lo = mid;
        } else if (hi - lo > 1u) {
            hi = mid;
        }
    }
    return vec2<u32>(lo, e);
}

// Whether the joints may move body i (not the world, not fixed or kinematic).
fn joint_moves(i: u32) -> bool {
    let p = props_of(i);
    return i != WORLD && !is_fixed(p) && !is_kinematic(p);
}

// Each joint adds its bodies' rest times and holds to its island's words.
@compute @workgroup_size(WORKGROUP)
fn joint_rest_gather(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let at = island_joint(dispatch_index(gid, groups));
    if (at.x == NONE) {
        return;
    }
    let j = joint_refs[at.y];
    let s = out_state(j.body);
    var rest = s.rest_time;
    var held = (s.pos_low & HELD) != 0u;
    if (joint_moves(j.partner)) {
        let o = out_state(j.partner);
        rest = min(rest, o.rest_time);
        held = held || (o.pos_low & HELD) != 0u;
    } else {
        held = true;
    }
    // a rest time is never negative, so its bits order as the times do
    atomicMin(&island_rest[2u * at.x], bitcast<u32>(max(rest, 0.0)));
    if (held) {
        atomicOr(&island_rest[2u * at.x + 1u], 1u);
    }
}

// Each joint gives its bodies the island's rest time (a body of several
// joints is given the same time by each).
@compute @workgroup_size(WORKGROUP)
fn joint_rest(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let at = island_joint(dispatch_index(gid, groups));
    if (at.x == NONE) {
        return;
    }
    let held = atomicLoad(&island_rest[2u * at.x + 1u]) != 0u;
    let rest = select(0.0, bitcast<f32>(atomicLoad(&island_rest[2u * at.x])), held);
    let j = joint_refs[at.y];
    set_rest_time(j.body, rest);
    if (joint_moves(j.partner)) {
        set_rest_time(j.partner, rest);
    }
}

// Body i's state along a path: from the registers if the joint just closed
// holds it (held, kept), else from memory.
fn held_or_loaded(i: u32, held: vec2<u32>, kept: array<BodyState, 2>) -> BodyState {
    if (held[0] == i) {
        return kept[0];
    }
    if (held[1] == i) {
        return kept[1];
    }
    return out_state(i);
}

// Whether body i is held in the registers and moved since it was written.
fn unwritten(i: u32, held: vec2<u32>, moved: vec2<bool>) -> bool {
    return (held[0] == i && moved[0]) || (held[1] == i && moved[1]);
}

// A direct path's ends as its elimination holds them: the body (NONE for the
// world or a body the joints do not move), its pose, inverse mass and world
// inverse inertia.
struct PathEnd {
    i: u32,
    s: BodyState,
    inv_mass: f32,
    w: mat3x3<f32>,
}

// The way back reads no previous orientation (`back`): it is neither loaded
// there nor stored again (set_moved).
fn path_end(i: u32, held: array<PathEnd, 2>, back: bool) -> PathEnd {
    if (i == WORLD) {
        return PathEnd(NONE, BodyState(), 0.0, mat3x3<f32>());
    }
    if (held[0].i == i) {
        return held[0];
    }
    if (held[1].i == i) {
        return held[1];
    }
    var s: BodyState;
    if (back) {
        s = state_from(StateWords(state_out[i].a, state_out[i].b, state_out[i].rot, vec4<f32>(0.0)));
    } else {
        s = out_state(i);
    }
    let p = props_of(i);
    if (is_fixed(p)) {
        return PathEnd(NONE, s, 0.0, mat3x3<f32>());
    }
    return PathEnd(i, s, p.inv_inertia.w, world_inv_inertia(quat_to_mat(s.rot), p.inv_inertia.xyz));
}

// Body i's pose as the way back moved it: all but its previous orientation,
// which the way back does not change.
fn set_moved(i: u32, s: BodyState) {
    state_out[i].a = vec4<f32>(s.pos, s.rest_time);
    state_out[i].b = vec4<f32>(s.disp, bitcast<f32>(s.pos_low));
    state_out[i].rot = s.rot;
}

// [v]x: skew(v) * u = cross(v, u).
fn skew(v: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(0.0, v.z, -v.y), vec3<f32>(-v.z, 0.0, v.x), vec3<f32>(v.y, -v.x, 0.0));
}

// How far end e's point at r moves for a unit push at its point s (world axes).
fn end_response(e: PathEnd, r: vec3<f32>, s: vec3<f32>) -> mat3x3<f32> {
    let m = e.inv_mass;
    return mat3x3<f32>(vec3<f32>(m, 0.0, 0.0), vec3<f32>(0.0, m, 0.0), vec3<f32>(0.0, 0.0, m)) - skew(r) * e.w * skew(s);
}

// m's inverse, or zero where m is (both ends stay).
fn inverse3(m: mat3x3<f32>) -> mat3x3<f32> {
    let r0 = cross(m[1], m[2]);
    let r1 = cross(m[2], m[0]);
    let r2 = cross(m[0], m[1]);
    let det = dot(m[0], r0);
    let scale = select(0.0, 1.0 / det, det > 0.0);
    return transpose(mat3x3<f32>(r0, r1, r2)) * scale;
}

// A joint's world anchors' offsets from its ends' centres, and the part of its
// gap to close (joint_gap's, less what may stay open), as close_joint closes it.
struct PathJoint {
    ra: vec3<f32>,
    rb: vec3<f32>,
    close: vec3<f32>,
}

fn path_joint(j: JointRef, sa: BodyState, sb: BodyState) -> PathJoint {
    let g = joint_gap(j, sa, sb);
    let part = select(1.0 - g.bounded / max(g.dist, 1e-30), 0.0, g.dist <= g.bounded + 1e-7);
    return PathJoint(g.ra, g.rb, g.gap * part);
}

// A joint's PATH_SLOT words of path_scratch: its pivot's inverse, the
// eliminated gap in the w's. Its coupling to the joint before, and which of
// its ends it shares with it, are not kept: the way back works them out
// again from the same poses and records, a load and a store fewer a joint,
// which are what a path's loop costs on lavapipe.

// Whether every joint of a path is closed within JOINT_SETTLED, as the
// swept passes end, or within what its ends' f32 positions can tell apart
// (two steps of their largest coordinate's spacing: 15 um 64 to 128 m out):
// its solve would move nothing that matters. Most solves of a path the other
// colour barely moved, or that the substep's first solve left closed, end here.
fn path_settled(first: u32, end: u32) -> bool {
    // the body a joint shares with the one before is not loaded again
    var held = vec2<u32>(NONE);
    var kept: array<Placed, 2>;
    for (var k = first; k < end; k = k + 1u) {
        let j = joint_refs[k];
        let b = select(j.body, j.partner, j.partner != WORLD);
        let pa = placed_or_loaded(j.body, held, kept);
        let pb = placed_or_loaded(b, held, kept);
        held = vec2<u32>(j.body, b);
        kept[0] = pa;
        kept[1] = pb;
        // remainder_unit is 1/512 of a coordinate's spacing
        let unit = max(remainder_unit(pa.pos), remainder_unit(pb.pos));
        let rounding = 1024.0 * max(unit.x, max(unit.y, unit.z));
        let limit = JOINT_SETTLED + rounding;
        // the part of a gap to close is never longer than the gap, so a gap
        // shorter than the limit needs no more, nor its ends' previous poses
        // (the anchors as joint_gap has them)
        let r = joint_anchors(j, pa.rot, pb.rot);
        let gap = select(j.local_partner, pb.pos + r[1], j.partner != WORLD) - (pa.pos + r[0]);
        if (length(gap) >= limit && length(path_joint(j, out_state(j.body), out_state(b)).close) >= limit) {
            return false;
        }
    }
    return true;
}

// A body's position and orientation, all that a settled joint's gap reads.
struct Placed {
    pos: vec3<f32>,
    rot: vec4<f32>,
}

// Body i's position and orientation: from the registers if the joint before
// holds it (held, kept), else from memory (two of its pose's four words).
fn placed_or_loaded(i: u32, held: vec2<u32>, kept: array<Placed, 2>) -> Placed {
    if (held[0] == i) {
        return kept[0];
    }
    if (held[1] == i) {
        return kept[1];
    }
    return Placed(state_out[i].a.xyz, state_out[i].rot);
}

// Which end of a joint (its ends a and b: NONE unless they move) it shares
// with the joint before (that joint's ends), and which end there:
// x here, y there, each 1 for a joint's body, 2 for its partner, 0 for none.
fn shared_end(a: u32, b: u32, before: vec2<u32>) -> vec2<u32> {
    if (a != NONE && a == before.x) {
        return vec2<u32>(1u, 1u);
    }
    if (a != NONE && a == before.y) {
        return vec2<u32>(1u, 2u);
    }
    if (b != NONE && b == before.x) {
        return vec2<u32>(2u, 1u);
    }
    if (b != NONE && b == before.y) {
        return vec2<u32>(2u, 2u);
    }
    return vec2<u32>(0u);
}

// One direct solve of a chain, or of a path cut from a larger island (a
// chain too: each joint shares one body with the next): the 3D gaps of all
// its joints closed at once, as the linear system of their pushes (block
// tridiagonal, 3 x 3 blocks) solved by elimination forward and substitution
// back. What the Gauss-Seidel sweeps approach along the path in many
// closes, one pass reaches; the colours' turns still carry corrections
// between paths. Such a chain is held at one point at most (joint_lists),
// so its system is never singular.
fn solve_path(first: u32, end: u32, slot0: u32) -> bool {
    let n = end - first;
    if (path_settled(first, end)) {
        return false;
    }
    var widest = 0.0; // the widest gap this solve closes (PATH_RECHECK)
    var held: array<PathEnd, 2>;
    held[0].i = NONE;
    held[1].i = NONE;
    var pivot = mat3x3<f32>();  // the joint before's pivot's inverse
    var gap = vec3<f32>(0.0);   // and its eliminated gap
    var prev = PathJoint(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    for (var k = 0u; k < n; k = k + 1u) {
        let j = joint_refs[first + k];
        let a = path_end(j.body, held, false);
        let b = path_end(j.partner, held, false);
        let pj = path_joint(j, a.s, b.s);
        widest = max(widest, length(pj.close));
        var m = end_response(a, pj.ra, pj.ra) + end_response(b, pj.rb, pj.rb);
        let link = shared_end(a.i, b.i, vec2<u32>(held[0].i, held[1].i));
        var coupling = mat3x3<f32>();
        if (link.x != 0u) {
            var x = b;
            if (link.x == 1u) {
                x = a;
            }
            let r_here = select(pj.rb, pj.ra, link.x == 1u);
            let r_there = select(prev.rb, prev.ra, link.y == 1u);
            // a joint pushes its body by +lambda and its partner by -lambda
            let sign = select(-1.0, 1.0, link.x == link.y);
            coupling = end_response(x, r_here, r_there) * sign;
            let l = coupling * pivot;
            m = m - l * transpose(coupling);
            gap = pj.close - l * gap;
        } else {
            gap = pj.close;
        }
        pivot = inverse3(m);
        let at = (slot0 + k) * PATH_SLOT;
        path_scratch[at] = vec4<f32>(pivot[0], gap.x);
        path_scratch[at + 1u] = vec4<f32>(pivot[1], gap.y);
        path_scratch[at + 2u] = vec4<f32>(pivot[2], gap.z);
        held[0] = a;
        held[1] = b;
        prev = pj;
    }
    // back: each joint's push, each body moved once all its pushes are known
    // (the body shared with the joint before waits for it in `wait`)
    var after_push = vec3<f32>(0.0); // the push of the joint after
    var after_r = vec3<f32>(0.0);    // its anchor on the body it shares with this joint (`wait`)
    var after_link = 0u;             // which of its ends that is (0: none)
    var wait = PathEnd(NONE, BodyState(), 0.0, mat3x3<f32>());
    var wait_push = vec3<f32>(0.0);  // summed push on `wait`
    var wait_turn = vec3<f32>(0.0);  // and its moment
    for (var t = 0u; t < n; t = t + 1u) {
        let k = n - 1u - t;
        let at = (slot0 + k) * PATH_SLOT;
        let w0 = path_scratch[at];
        let w1 = path_scratch[at + 1u];
        let w2 = path_scratch[at + 2u];
        let j = joint_refs[first + k];
        var kept: array<PathEnd, 2>;
        kept[0] = wait;
        kept[1].i = NONE;
        let a = path_end(j.body, kept, true);
        let b = path_end(j.partner, kept, true);
        // which of its ends it shares with the joint before, as the
        // elimination found it (a moving end matches that joint's record)
        var shares = 0u;
        if (k > 0u) {
            let before = joint_refs[first + k - 1u];
            shares = shared_end(a.i, b.i, vec2<u32>(before.body, before.partner)).x;
        }
        let r = joint_anchors(j, a.s.rot, b.s.rot);
        // the joint after's coupling to this one, as the elimination formed it,
        // times its push, transposed
        var after = vec3<f32>(0.0);
        if (after_link != 0u) {
            let there = select(2u, 1u, a.i == wait.i);
            let sign = select(-1.0, 1.0, after_link == there);
            let coupling = end_response(wait, after_r, select(r[1], r[0], there == 1u)) * sign;
            after = vec3<f32>(dot(coupling[0], after_push), dot(coupling[1], after_push), dot(coupling[2], after_push));
        }
        let push = mat3x3<f32>(w0.xyz, w1.xyz, w2.xyz) * (vec3<f32>(w0.w, w1.w, w2.w) - after);
        after_push = push;
        after_link = shares;
        after_r = select(r[1], r[0], shares == 1u);
        // the body the joint after left waiting, before this joint's end takes its place
        let waited = wait.i;
        let waited_push = wait_push;
        let waited_turn = wait_turn;
        for (var e = 0u; e < 2u; e = e + 1u) {
            var x = b;
            if (e == 0u) {
                x = a;
            }
            if (x.i == NONE) {
                continue;
            }
            let p = push * select(-1.0, 1.0, e == 0u);
            var total = p;
            var turn = cross(select(r[1], r[0], e == 0u), p);
            if (x.i == waited) {
                total = total + waited_push;
                turn = turn + waited_turn;
            }
            if (shares == e + 1u) {
                wait = x;
                wait_push = total;
                wait_turn = turn;
            } else {
                let dx = total * x.inv_mass;
                x.s.pos = x.s.pos + dx;
                x.s.disp = x.s.disp + dx;
                x.s.rot = quat_add_rotation(x.s.rot, x.w * turn);
                set_moved(x.i, x.s);
            }
        }
        if (shares == 0u) {
            wait.i = NONE;
        }
    }
    return widest > PATH_RECHECK;
}

// The joints of path gid.x of this pass's colour, if it is of the kind asked
// (solved directly, or swept) and its island is awake:
// (first, end) in joint_refs, or (NONE, NONE).
fn colour_path(gid: vec3<u32>, direct: bool) -> vec2<u32> {
    let path = params.path_first + gid.x;
    if (path >= params.path_end) {
        return vec2<u32>(NONE);
    }
    // path p's joints follow the islands' in joint_start, and after all
    // paths, each one's closes a solve_joints pass: 0 for a path solved directly (joint_lists)
    let at = params.body_count + params.island_count + 2u + path;
    if ((joint_start[at + 1u + params.path_count] == 0u) != direct) {
        return vec2<u32>(NONE);
    }
    let first = joint_start[at];
    // an asleep island is left as it is (joint_rest shares its rest time)
    if (asleep(out_state(joint_refs[first].body))) {
        return vec2<u32>(NONE);
    }
    return vec2<u32>(first, joint_start[at + 1u]);
}

// A path solved directly closes its gaps to within what its turns leave of
// the linear answer, about gap^2 / 2r for a lever r: a solve of gaps up to
// this (m) leaves them within JOINT_SETTLED for levers of 5 cm or more.
const PATH_RECHECK: f32 = 1e-3;

// Pass "solve_paths", once per colour after a substep's first sweep, and
// again after its last (twice after a single one) where the contacts pushed
// a jointed body since the substep began or a first solve closed a gap wider
// than PATH_RECHECK (status[STATUS_PATHS_AGAIN]): where paths meet a path's
// solve moves their shared bodies, and the colours' turns carry that, but
// only under load do their joints need it twice (docs/decisions/joints.md).
// One invocation per chain or path cut from a larger island: the path
// solved directly (solve_path).
@compute @workgroup_size(PATH_WORKGROUP)
fn solve_paths(@builtin(global_invocation_id) gid: vec3<u32>) {
    // (no invocation of a second solve sets it: all read the same)
    if (params.second != 0u && atomicLoad(&status[STATUS_PATHS_AGAIN]) == 0u) {
        return;
    }
    let path = colour_path(gid, true);
    if (path.x == NONE) {
        return;
    }
    let wide = solve_path(path.x, path.y, path.x - joint_start[params.body_count + params.island_count + 2u]);
    if (wide && params.second == 0u) {
        atomicStore(&status[STATUS_PATHS_AGAIN], 1u);
    }
}

@compute @workgroup_size(PATH_WORKGROUP)
fn solve_joints(@builtin(global_invocation_id) gid: vec3<u32>) {
    let path = colour_path(gid, false);
    if (path.x == NONE) {
        return;
    }
    let first = path.x;
    let end = path.y;
    // the sweeps out and back as one loop counted by the path's length (a loop
    // bounded by a uniform alone is recompiled by lavapipe every dispatch)
    let n = end - first;
    let sweeps = JOINT_SWEEPS_PER_PASS;
    // Consecutive joints of a path share a body, so the two bodies of the last
    // joint closed stay in registers (held[k], its state kept[k], moved[k] if
    // not yet written back) rather than going to memory and back each close.
    var held = vec2<u32>(NONE);
    var kept: array<BodyState, 2>;
    var moved = vec2<bool>(false);
    // the most a close of this sweep moved its joint: a sweep that closes
    // none by more than JOINT_SETTLED ends the pass
    var widest = 0.0;
    for (var t = 0u; t < 2u * n * sweeps; t = t + 1u) {
        let r = t % (2u * n);
        let j = joint_refs[select(first + r, end - 1u - (r - n), r >= n)];
        let a = j.body;
        let b = select(a, j.partner, j.partner != WORLD);
        // a held body this joint does not close is done with: written back
        for (var k = 0u; k < 2u; k = k + 1u) {
            if (moved[k] && held[k] != a && held[k] != b) {
                set_state(held[k], kept[k]);
            }
        }
        var sa = held_or_loaded(a, held, kept);
        var sb = held_or_loaded(b, held, kept);
        let was = vec2<bool>(unwritten(a, held, moved), unwritten(b, held, moved));
        var closed = 0.0;
        let now = close_joint(j, &sa, &sb, &closed);
        held = vec2<u32>(a, select(NONE, b, b != a));
        kept[0] = sa;
        kept[1] = sb;
        moved = (was | now) & vec2<bool>(true, b != a);
        widest = max(widest, closed);
        if (r + 1u == 2u * n) {
            if (widest < JOINT_SETTLED) {
                break;
            }
            widest = 0.0;
        }
    }
    for (var k = 0u; k < 2u; k = k + 1u) {
        if (moved[k]) {
            set_state(held[k], kept[k]);
        }
    }
}
