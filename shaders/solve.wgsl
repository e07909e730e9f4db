// Passes "solve_contacts", "solve" and "solve_joints", run in turn
// in each substep its share of `iterations` times: the paper's corrective snaps (eqs. 9-10).
// Contacts are relaxed Jacobi style. Every pose is read from state_in:
// solve_contacts, one invocation per manifold of the pool, measures all of
// a pair's points once and writes what they ask of each of its two bodies
// (its two EndSnaps in snaps); solve, one invocation per listed body
// (`listed_body` in bindings.wgsl), sums what its
// manifolds ask, relaxes the sum by c_r (eq. 10) and writes only its own
// slot of state_out. Joints are then closed in turn, Gauss-Seidel style,
// by solve_joints (below). All of a body's snaps are
// measured on the same starting pose and summed, so symmetric contacts (a
// box resting on four corners) cancel exactly instead of twisting the body
// in the order they were visited, and the sums never depend on thread timing.

// A snap being summed: translation and rotation (radians, world axes).
struct Snap {
    dx: vec3<f32>,
    dtheta: vec3<f32>,
}

// One manifold's points, on the poses of state_in. For each point, the
// normal snap closes the depth, shared by the two bodies by their inverse
// masses (w_a + w_b, where a body the contacts may not move counts 0).
// Static friction (as XPBD has it): if the two material points have slid
// apart since their previous poses by less than mu times the normal push
// summed over this substep, the slide is undone; a larger slide is left to
// dynamic friction in the restitution pass.
//
// Each point's snap moves the bodies as if that point were alone; when
// several points of one face all ask for the same depth d, their sum is
// d x (pair_w x the sum of 1/w), which is d for points at the corners of a
// cube but four times d for points near the middle of a large face (a box
// resting across two others): that overshoot made piles vibrate and walk
// apart. The sum is scaled down to what moving the two bodies apart without
// turning asks for, never up. The points' turns are averaged: each was
// computed as if it alone turned the body.
//
// Shock propagation, softened (Guendelman et al. 2003 treat the lower body
// of a resting pair as immovable while they relax a stack from the ground
// up): in a contact whose normal lies within 25 degrees of the vertical
// (gravity's axis; |cos| > SHOCK_UP), the lower body counts SHOCK times its
// inverse mass and inertia, so what rests on a body pushes it down less
// than the body pushes it up. The Jacobi sweeps leave a remainder in a
// stack every substep; shared by mass alone it compressed tall columns and
// made them lean. Measured (tests/gpu/physics_contacts.rs: boxes shifted
// up to 1 cm and turned up to 1 degree, default settings, 10 s): a column
// of 20 leaned 125 cm and sank 15 cm; with 0.65 it leans 0.4 cm and sinks
// 4.3 cm at most. A 30-row pyramid moved a box 6.9 cm, 5.3 cm with 0.65.
// Stronger (0.5, 0.2) or over every normal within 60 degrees, 1000 piled
// cubes crept more and pyramids of 30 rows moved 8 to 32 cm. Momentum is
// not conserved in such a contact between two free bodies; the restitution
// pass, which decides bounces, does not use it.
const SHOCK: f32 = 0.65;
const SHOCK_UP: f32 = 0.9;

// Old overlap deeper than this speed (m/s) times the substep settles: the
// part of a snap that pushes it out moves the pose without becoming
// velocity (see solve). At 0.5, twenty balls placed at one point were
// still 0.4 m inside each other after 5 s; at the 3 m/s of
// MAX_DEPENETRATION_SPEED, what stayed below it still summed to 8.5 m/s
// for fifty boxes placed at one point (3.15 m/s at 1).
const SETTLE_SPEED: f32 = 1.0;

// Shallower old overlap is pushed out as velocity, as Verlet has it: that
// velocity carries a stack's support from one substep to the next (with
// every old overlap settled instead, a column of ten sank at 1.3 m/s). But
// the sweeps carry support up a stack one body per sweep, and what a tall
// stack stores before they reach its top comes back as a throw: a 30-row
// pyramid placed at rest sank 2 cm at the top in its first 4 steps, and
// its rows' pushes out of that overlap (about 1 mm each, 0.2 m/s) added
// up to 2.9 m/s at the top box, which flew 47 cm up and landed
// centimetres aside; a pyramid that had fallen asleep did the same, less,
// when a poke woke it. So a body's push out of such overlap becomes
// velocity against gravity only while the body rises slower than
// SUPPORT_SPEED; the rest of it moves the pose and the previous pose
// together, as settling does (see solve). A resting body's push only
// cancels what gravity added in the substep, far below the cap. Measured
// (600 steps, the largest move of any box; 30-row pyramids with every box
// shifted up to 1 cm and turned up to 1 degree: ten at random and six by
// the tests' pattern): 3.6-6.8 cm before, 1.7-1.8 cm at 0.2 m/s (1.2-1.3
// at 0.1, 2.6-2.8 at 0.5, 2.2-2.9 at 1); the slept 30-row pyramid's top
// box rose 6 cm when poked, now 0.3 cm. Against gravity only: capped along
// every direction, bodies placed inside each other with no gravity part
// slowly (twenty balls at one point were still 0.5 m inside each other
// after 5 s at 1 m/s).
const SUPPORT_SPEED: f32 = 0.2;

// Normal pushes against ends that stay are split too. A sweep moves a
// body by c_r times the sum of its pushes, each its share of a depth: 1
// against an end that stays, w_self / (w_self + w_partner) against one
// that moves; past a gain of 2 the sweeps overshoot and the body flips
// every sweep. A cube wedged between sleepers (four below, three above)
// went up and down 0.6 mm every other step at 0.11 m/s for good, awake;
// in pyramids of 12 to 20 rows a box under two sleepers and on two awake
// boxes did so against them (the mode's gain there is 4: c_r 4 = 2, no
// decay). A body held by k > 0 ends that stay counts its inverse mass
// max(1, c_r s) times in its pushes against them, s its shares summed
// (pair_meta's normal_split, from contact_lists). With this and dynamic
// friction's split (restitution.wgsl), 1000 piled cubes (seeds 7 to 14)
// are all at rest after 15 s, no cube moving in the second after (before:
// six of eight kept a cube at 0.06 to 0.11 m/s), and the built-in pyramids
// of 8 to 20 rows sleep whole. Splitting by k alone left the pyramids of
// 12 rows and more; splitting every body's pushes by s, held or not, left
// piles creeping up to 4 cm a second. Not for a jointed body: its joints,
// closed after each sweep, pull it back against weakened pushes (ragdolls
// on a pile kept a limb bobbing 14 cm for seconds).
// Body i's splits in a manifold (friction's, the normal pushes'): 1 unless
// the other end stays (and read only then).
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
    // the header, read once (the pool is written here, so a second read
    // is a second load: a loop over the lanes on lavapipe)
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
    // the lower body of a stacked pair counts SHOCK times its inverse mass
    // (up_n: n's component against gravity; > 0: b lies above a)
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
    // pushes against an end that stays are split (stay_splits)
    // (x: friction's, y: the normal pushes')
    let split_a = stay_splits(a, eb.moves);
    let split_b = stay_splits(b, ea.moves);
    // summed over the points, for a: normal and friction pushes (b gets the
    // opposite), their moments about each centre, the sums of 1 / w
    var normal_j = vec3<f32>(0.0);
    var friction_j = vec3<f32>(0.0);
    var moment_a = vec3<f32>(0.0);
    var moment_b = vec3<f32>(0.0);
    var normal_inv_w = 0.0;
    var friction_inv_w = 0.0;
    var points = 0u;
    var pressed = 0u;
    // summed over the points: the part of their depths that pushes out old
    // overlap deeper than SETTLE_SPEED allows, the part that pushes out
    // shallower old overlap, and all of it
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
        // how far each material point moved since the previous poses, from
        // the displacements (no difference of two far-out positions)
        let moved_a = ea.disp + ea.turn_m * local_a;
        let moved_b = eb.disp + eb.turn_m * local_b;
        // Overlap the bodies already had at their previous poses is pushed
        // out at no more than MAX_DEPENETRATION_SPEED: a full snap in one
        // substep would turn into that much velocity (Verlet), and deep
        // overlaps (thin limbs passing through each other, bodies placed
        // overlapping) launched bodies at tens of m/s. Overlap made by this
        // substep's approach is removed whole.
        let overlap_before = dot((on_a - moved_a) - (on_b - moved_b), n);
        let held_back = overlap_before - MAX_DEPENETRATION_SPEED * params.dt;
        let overlap = dot(on_a - on_b, n);
        let depth = overlap - max(held_back, 0.0);
        // of such a point's depth, what is old overlap (the rest this
        // substep's approach made)
        let old = clamp(depth - max(overlap - overlap_before, 0.0), 0.0, max(depth, 0.0));
        let deep = overlap_before > SETTLE_SPEED * params.dt;
        old_depth = old_depth + select(0.0, old, deep);
        shallow_depth = shallow_depth + select(old, 0.0, deep);
        all_depth = all_depth + max(depth, 0.0);
        // a contact that pushed earlier in this substep keeps its friction
        // while it still touches, even once its depth is resolved, so
        // sideways pushes from other contacts in later sweeps are resisted too
        var push = 0.0;
        var snapped = false;
        if (depth > 0.0) {
            let w = end_inv_mass(ea, ra, n) * split_a.y + end_inv_mass(eb, rb, n) * split_b.y;
            let j = n * (depth / w); // pushes b along n, a along -n
            normal_j = normal_j + j;
            moment_a = moment_a + cross(ra, j);
            moment_b = moment_b + cross(rb, j);
            normal_inv_w = normal_inv_w + 1.0 / w;
            push = depth * params.relaxation;
            snapped = true;
        }
        if (depth > 0.0 || (pt.pushed > 0.0 && depth >= -CONTACT_SLOP)) {
            // how far a's point slid against b's since the previous poses
            let slip = moved_a - moved_b;
            let slip_t = slip - n * dot(slip, n);
            let slide = length(slip_t);
            if (slide > 1e-9 && slide <= mu * (pt.pushed + push)) {
                let t = slip_t / slide;
                let w = end_inv_mass(ea, ra, t) * split_a.x + end_inv_mass(eb, rb, t) * split_b.x;
                let j = t * (slide / w); // pulls b along t, a back along -t
                friction_j = friction_j + j;
                moment_a = moment_a + cross(ra, j);
                moment_b = moment_b + cross(rb, j);
                friction_inv_w = friction_inv_w + 1.0 / w;
                snapped = true;
            }
        }
        set_pushed(at, q, pt.pushed + push);
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
    let f_scale = min(1.0, 1.0 / max(pair_w * friction_inv_w, 1e-30));
    let j = normal_j * n_scale + friction_j * f_scale;
    let turns = 1.0 / f32(max(points, 1u));
    let touched = u32(points > 0u);
    // the shares of the snap that settle and that support (see solve)
    let settle = u32(round(clamp(old_depth / max(all_depth, 1e-30), 0.0, 1.0) * SETTLE_ONE));
    let support = u32(round(clamp(shallow_depth / max(all_depth, 1e-30), 0.0, 1.0) * SUPPORT_ONE));
    let flags = select(0u, SNAP_PRESSED, pressed != 0u) | (settle << SETTLE_SHIFT) | (support << SUPPORT_SHIFT);
    set_snap(contact_ref(k, false), end_snap(ea, -j, -moment_a * turns, touched, flags));
    set_snap(contact_ref(k, true), end_snap(eb, j, moment_b * turns, touched, flags));
}

@compute @workgroup_size(WORKGROUP)
fn solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = listed_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    var s = state_of(i);
    let p = props_of(i);
    if (is_fixed(p) || asleep(s)) {
        set_state(i, s);
        return;
    }
    var acc = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    var touching = 0u;
    // SNAP_PRESSED if a contact pushed in this substep: integrate's test
    // for sleeping
    var flags = 0u;
    let first = pair_meta[i].list_start;
    let end = first + pair_meta[i].contacts;
    // the parts of the snaps that push out old overlap, apart (not for a
    // jointed body: its joints measure their old gaps at the previous poses,
    // which settling moves)
    var settle = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    var settling = 0u;
    // the parts that push out shallower old overlap (SUPPORT_SPEED), apart
    // (not for a jointed body either)
    var support_dx = vec3<f32>(0.0);
    let jointed = is_jointed(i);
    // the body's manifolds in pair order (contact_lists)
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
        touching = touching + snap.count;
        flags = flags | snap.flags;
    }
    // Each snap turns the body as if it were the only one; summed they
    // overshoot (four corners correcting a twist turn it back about twice too
    // far), so a partner's points share one turn (their mean, in
    // solve_contacts) and the partners' turns are averaged too (mass
    // splitting, for the inertia only: translations are scaled per partner).
    let split = 1.0 / f32(max(touching, 1u));
    // a snap moves the displacement with the pose: the velocity changes by
    // dx / h, as Verlet's moving x_n while x_(n-1) stays does
    let dx = acc.dx * params.relaxation;
    let up = support_dx * params.relaxation;
    s.pos = s.pos + dx + up;
    s.disp = s.disp + dx;
    // the support's push against gravity becomes velocity only up to
    // SUPPORT_SPEED upward; the rest of it, and all of it without gravity,
    // as any snap
    let g = length(params.gravity);
    let rise = -params.gravity / max(g, 1e-30);
    let lift = select(0.0, max(dot(up, rise), 0.0), g > 0.0);
    s.disp = s.disp + (up - rise * lift);
    let room = max(SUPPORT_SPEED * params.dt - dot(s.disp, rise), 0.0);
    s.disp = s.disp + rise * min(lift, room);
    s.pos_low = (s.pos_low & ~HELD) | select(0u, HELD, (flags & SNAP_PRESSED) != 0u);
    s.rot = quat_add_rotation(s.rot, acc.dtheta * (params.relaxation * split));
    // Settling: old overlap deeper than SETTLE_SPEED allows in a substep
    // (bodies placed inside each other, a hard landing the sweeps left
    // unresolved) is pushed out without turning into velocity: the pose
    // moves and the previous pose with it, by the mean of those parts of
    // the snaps. Each contact pushes out at no more than
    // MAX_DEPENETRATION_SPEED, but a body inside several others at once was
    // pushed by each of them and the push stayed as velocity: ten unit
    // boxes placed at one point flew apart at 11.5 m/s, fifty diverged. A
    // settling body is not at rest, though its velocity may be nil: asleep,
    // it would stay inside the others.
    if (settling > 0u) {
        s.rest_time = 0.0;
        let share = params.relaxation / f32(settling);
        s.pos = s.pos + settle.dx * share;
        s.rot = quat_add_rotation(s.rot, settle.dtheta * share);
        s.prev_rot = quat_add_rotation(s.prev_rot, settle.dtheta * share);
    }
    set_state(i, s);
}

// Pass "solve_joints", after every solve, once per colour of the joint
// paths (see joint_lists in src/world/records.rs): ball joints closed one
// after the other along each path, in place on the poses solve just wrote,
// one invocation per path of the colour. No two paths of a colour share a
// body that moves, and a path's joints come in a fixed order, so the result
// never depends on thread timing. Jacobi carries a correction one link per
// sweep: a user's chain of 21 links opened 2.1 cm (3 sweeps) and 8 mm (8),
// ragdolls wedged on a pile 7 cm. In turn, a sweep outward along a path
// and back carries it along the whole path, and the colours one after the
// other carry it between paths. Each joint's snap closes its whole gap
// (eq. 9 with nothing to overshoot: no other snap is summed with it; only
// an old gap's closing speed is bounded, see close_joint), shared by the
// two bodies' generalised inverse masses along the gap, and moves the
// displacement with the pose, as solve's snaps do. A pass makes up to
// params.joint_sweeps such sweeps along each path (see
// JOINT_SWEEPS_PER_SUBSTEP in src/world.rs), fewer along one cut from a
// large island (CUT_PATH_CLOSES in src/world/records.rs).

// Close one joint: body j.body and its partner (or the world) move along
// the gap between the two anchors until they meet, or until it has closed
// by as much as MAX_DEPENETRATION_SPEED allows in this substep.
fn close_joint(j: JointRef) {
    let a = j.body;
    let joined = j.partner != WORLD;
    let b = select(a, j.partner, joined);
    var sa = out_state(a);
    var sb = out_state(b);
    let pa = props_of(a);
    let pb = props_of(b);
    let ra = quat_rotate(sa.rot, j.local_self);
    let rb = quat_rotate(sb.rot, j.local_partner);
    let gap = select(j.local_partner, sb.pos + rb, joined) - (sa.pos + ra);
    let dist = length(gap);
    // The gap the joint had at the previous poses (from the displacements:
    // no difference of two far-out positions) closes at no more than
    // MAX_DEPENETRATION_SPEED, as overlap does; what this substep opened
    // closes whole. A full snap in one substep turns into velocity: a ring
    // of boxes placed 1 m from where its joints want them was thrown at
    // 48 m/s, and joints that cannot all close (a loop of the wrong
    // lengths) fought until a body spun past the fault limit.
    let moved_a = sa.disp + (ra - quat_rotate(sa.prev_rot, j.local_self));
    let moved_b = select(vec3<f32>(0.0), sb.disp + (rb - quat_rotate(sb.prev_rot, j.local_partner)), joined);
    let before = length(gap - (moved_b - moved_a));
    let bounded = max(before - MAX_DEPENETRATION_SPEED * params.dt, 0.0);
    let n = gap / max(dist, 1e-30); // a moves along n, b against it
    let wa = select(effective_inv_mass(pa, sa.rot, ra, n), 0.0, is_fixed(pa));
    let wb = select(0.0, effective_inv_mass(pb, sb.rot, rb, n), joined && !is_fixed(pb));
    if (dist <= bounded + 1e-7 || wa + wb <= 0.0) {
        return;
    }
    let lambda = (dist - bounded) / (wa + wb);
    if (wa > 0.0) {
        let dx = n * (pa.inv_inertia.w * lambda);
        sa.pos = sa.pos + dx;
        sa.disp = sa.disp + dx;
        sa.rot = quat_add_rotation(sa.rot, inv_inertia_world(sa.rot, pa.inv_inertia.xyz, cross(ra, n)) * lambda);
        set_state(a, sa);
    }
    if (wb > 0.0) {
        let dx = n * (-pb.inv_inertia.w * lambda);
        sb.pos = sb.pos + dx;
        sb.disp = sb.disp + dx;
        sb.rot = quat_add_rotation(sb.rot, inv_inertia_world(sb.rot, pb.inv_inertia.xyz, cross(rb, n)) * -lambda);
        set_state(b, sb);
    }
}

// Pass "joint_rest", once a substep after its first solve, in place: an
// island sleeps and wakes as one. Every body of it takes the least rest
// time of them all (so none sleeps before the last comes to rest, and
// waking one wakes all), or none if nothing holds the island up (no body
// of it pressed by a contact, no joint to the world or a fixed body: it
// flies free). One invocation per island; an island of n joints takes 2n
// loop trips, within LOOP_TRIPS (bindings.wgsl); World::with_gpu refuses
// a larger one.
@compute @workgroup_size(WORKGROUP)
fn joint_rest(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.island_count) {
        return;
    }
    // island k's joints follow the bodies' joint lists in joint_start
    let at = params.body_count + 1u + gid.x;
    let first = joint_start[at];
    let end = joint_start[at + 1u];
    var rest = 3.4e38;
    var held = false;
    for (var e = first; e < end; e = e + 1u) {
        let j = joint_refs[e];
        let s = out_state(j.body);
        rest = min(rest, s.rest_time);
        held = held || (s.pos_low & HELD) != 0u;
        if (j.partner == WORLD || is_fixed(props_of(j.partner))) {
            held = true;
        } else {
            let o = out_state(j.partner);
            rest = min(rest, o.rest_time);
            held = held || (o.pos_low & HELD) != 0u;
        }
    }
    rest = select(0.0, rest, held);
    for (var e = first; e < end; e = e + 1u) {
        set_rest_time(joint_refs[e].body, rest);
        let partner = joint_refs[e].partner;
        if (partner != WORLD && !is_fixed(props_of(partner))) {
            set_rest_time(partner, rest);
        }
    }
}

@compute @workgroup_size(WORKGROUP)
fn solve_joints(@builtin(global_invocation_id) gid: vec3<u32>) {
    let path = params.path_first + gid.x;
    if (path >= params.path_end) {
        return;
    }
    // path p's joints follow the islands' in joint_start
    let at = params.body_count + params.island_count + 2u + path;
    let first = joint_start[at];
    let end = joint_start[at + 1u];
    // asleep, the island is left as it is (joint_rest gave every body of
    // it the island's rest time)
    if (params.sleep_after > 0.0 && out_state(joint_refs[first].body).rest_time >= params.sleep_after) {
        return;
    }
    // the sweeps forward then back, as one loop whose trip count is the
    // path's own (a loop bounded by a uniform alone makes lavapipe compile
    // the kernel again for every dispatch), within the path's budget of
    // joint closes (after the paths' starts: CUT_PATH_CLOSES for a path cut
    // from a large island, none for a whole island)
    let n = end - first;
    let closes = joint_start[params.body_count + params.island_count + 3u + params.path_count + path];
    let sweeps = max(min(params.joint_sweeps, closes / (2u * n)), 1u);
    for (var t = 0u; t < 2u * n * sweeps; t = t + 1u) {
        let r = t % (2u * n);
        close_joint(joint_refs[select(first + r, end - 1u - (r - n), r >= n)]);
    }
}
