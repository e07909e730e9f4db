// Passes "restitution_contacts", once per substep after the solve, and
// "restitution", after the step's last substep: collisions change velocity by
// rewriting the previous pose (the paper, section III; here disp and
// prev_rot). A contact that approached faster than both RESTITUTION_THRESHOLD
// and what a resting contact can reach (2 |g| dt) leaves at -e times its
// approach speed; slower ones stay at rest, so resting bodies do not hop.
// Dynamic friction takes up to mu times the push's normal impulse from a
// contact still sliding. As in the solve, restitution_contacts measures each
// manifold once (two EndSnaps; it empties the friction budgets) and
// `restituted` sums a body's in pair order. See docs/decisions/restitution.md.

// Approach speeds (m/s) below this never bounce; Box2D's default too.
const RESTITUTION_THRESHOLD: f32 = 1.0;

// An EndSnap's flags in this pass: one of the manifold's points bounced.
const SNAP_BOUNCE: u32 = 1u;

// Velocities a pose implies: disp / dt (disp = x - x_prev) and the rotation q q_prev^*.
fn pose_velocity(disp: vec3<f32>, rot: vec4<f32>, prev_rot: vec4<f32>) -> Velocity {
    let v = disp / params.dt;
    let w = quat_to_rotvec(quat_mul(rot, quat_conj(prev_rot))) / params.dt;
    return Velocity(vec4<f32>(v, 0.0), vec4<f32>(w, 0.0));
}

fn point_velocity(v: Velocity, r: vec3<f32>) -> vec3<f32> {
    return v.linear.xyz + cross(v.angular.xyz, r);
}

// The velocities of a contact's end after the solve: zero for the ground.
fn end_velocity(i: u32, e: ContactEnd) -> Velocity {
    if (i == GROUND) {
        return Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return pose_velocity(e.disp, e.rot, e.prev_rot);
}

// ... and before it (integrate's vel0): zero for an end the contacts may not move,
// as integrate writes for a fixed body or a sleeper (an unlisted one is not integrated).
fn end_velocity_before(i: u32, e: ContactEnd) -> Velocity {
    if (!e.moves) {
        return Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
    }
    return vel0[i];
}

@compute @workgroup_size(WORKGROUP)
fn restitution_contacts(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let used = manifolds_used();
    let nth = dispatch_index(gid, groups);
    if (nth >= used) {
        return;
    }
    let k = pool_slot(nth, used);
    let m = manifold_of(k); // read once (see solve_contacts)
    let a = m.a;
    let b = m.b;
    let ea = contact_end(a);
    let eb = contact_end(b);
    let n = m.normal; // from a to b
    let count = m.count;
    let at = point_slot(k);
    if (!ea.moves && !eb.moves) {
        for (var q = 0u; q < count; q = q + 1u) {
            set_pushed(at, q, 0.0);
        }
        return;
    }
    let va0 = end_velocity_before(a, ea);
    let vb0 = end_velocity_before(b, eb);
    let va = end_velocity(a, ea);
    let vb = end_velocity(b, eb);
    let threshold = max(2.0 * length(params.gravity) * params.dt, RESTITUTION_THRESHOLD);
    let mu = combined_friction(ea, eb);
    let e = combined_restitution(ea, eb);
    // against an end that stays (never both ends stay here) each contact cuts
    // at most its share of the sliding (friction_split); between two bodies
    // that move, all of it, and `restituted` caps the sum
    var split_a = 1.0;
    var split_b = 1.0;
    if (!eb.moves) {
        split_a = friction_split(a, 1.0);
    } else if (!ea.moves) {
        split_b = friction_split(b, 1.0);
    }
    // summed over the points: the velocity change asked of b (a gets the opposite;
    // times the inverse masses later), its moments; the bounces apart, with their 1 / w
    var j = vec3<f32>(0.0);
    var moment_a = vec3<f32>(0.0);
    var moment_b = vec3<f32>(0.0);
    var bounce_j = vec3<f32>(0.0);
    var bounce_moment_a = vec3<f32>(0.0);
    var bounce_moment_b = vec3<f32>(0.0);
    var bounce_inv_w = 0.0;
    var acting = 0u;
    var rubbing = 0u;
    // each end's turn per unit of the points' changes, summed (turn_scale)
    var k_a = vec3<f32>(0.0);
    var k_b = vec3<f32>(0.0);
    for (var q = 0u; q < count; q = q + 1u) {
        let pt = point_of(at, q);
        set_pushed(at, q, 0.0);
        let ra = ea.rot_m * end_point(ea, pt.local_a, n);
        let rb = eb.rot_m * end_point(eb, pt.local_b, -n);
        // touching?
        if (dot((eb.pos + rb) - (ea.pos + ra), n) > CONTACT_SLOP) {
            continue;
        }
        // the pair's inverse mass along n at the point (friction's bound, the bounce)
        let w_n = end_inv_mass(ea, ra, n) + end_inv_mass(eb, rb, n);
        // a's point's velocity relative to b's after the solve; the approach before it
        let relative_now = point_velocity(va, ra) - point_velocity(vb, rb);
        let approach = -dot(point_velocity(va0, ra) - point_velocity(vb0, rb), n);
        var impulse = vec3<f32>(0.0);
        var bounce = vec3<f32>(0.0);
        var acted = false;
        // dynamic friction against the sliding left after the solve
        let v_t = relative_now - n * dot(relative_now, n);
        let sliding = length(v_t);
        if (pt.pushed > 0.0 && sliding > 1e-6) {
            let t = v_t / sliding;
            // Coulomb's bound is on the impulse: mu times the normal one (the
            // push through the inverse mass along n); bounding the velocity
            // change instead gave a sliding ball 3.5 times too little friction
            let w_t = end_inv_mass(ea, ra, t) * split_a + end_inv_mass(eb, rb, t) * split_b;
            k_a = k_a + end_turn(ea, ra, t) / w_t;
            k_b = k_b + end_turn(eb, rb, t) / w_t;
            let j = min(mu * pt.pushed / params.dt / max(w_n, 1e-30), sliding / w_t);
            impulse = impulse + t * j;
            rubbing = rubbing + 1u;
            acted = true;
        }
        // restitution of a fast approach (approach < 0: closing), along a's push -n
        let vn = -dot(relative_now, n);
        let target_vn = -e * approach;
        if (approach < -threshold && vn < target_vn) {
            k_a = k_a + end_turn(ea, ra, n) / w_n;
            k_b = k_b + end_turn(eb, rb, n) / w_n;
            bounce = n * ((target_vn - vn) / w_n);
            bounce_inv_w = bounce_inv_w + 1.0 / w_n;
            acted = true;
        }
        if (acted) {
            j = j + impulse;
            moment_a = moment_a + cross(ra, impulse);
            moment_b = moment_b + cross(rb, impulse);
            bounce_j = bounce_j + bounce;
            bounce_moment_a = bounce_moment_a + cross(ra, bounce);
            bounce_moment_b = bounce_moment_b + cross(rb, bounce);
            acting = acting + 1u;
        }
    }
    // a capsule's points lie along the axis it turns freely about: their
    // friction's pushes are averaged, as their turns are (`restituted`), and
    // as in the solve
    if (HAS_ROUND && (ea.half_height > 0.0 || eb.half_height > 0.0)) {
        j = j / f32(max(rubbing, 1u));
    }
    // Each point's bounce is computed as if it alone turned the approach
    // around, so the sum is scaled down to what moving the two bodies apart
    // without turning asks, never up, as the solve's pushes are.
    var pair_w = 0.0;
    if (ea.moves) {
        pair_w = pair_w + ea.inv_inertia.w;
    }
    if (eb.moves) {
        pair_w = pair_w + eb.inv_inertia.w;
    }
    let bounce_scale = min(1.0, 1.0 / max(pair_w * bounce_inv_w, 1e-30));
    j = j + bounce_j * bounce_scale;
    moment_a = moment_a + bounce_moment_a * bounce_scale;
    moment_b = moment_b + bounce_moment_b * bounce_scale;
    let flags = select(0u, SNAP_BOUNCE, bounce_inv_w > 0.0);
    // Each end's summed turns are scaled back to one (turn_scale), and
    // `restituted` averages its manifolds' turns, as the solve does. A capsule's
    // points (along its free axis) and a jointed body's (its joints pull back
    // against a stronger turn: ten capsule ragdolls kept a limb moving) keep
    // the mean over the points instead.
    let capsule = HAS_ROUND && (ea.half_height > 0.0 || eb.half_height > 0.0);
    let jointed = is_jointed(a) || (b != GROUND && is_jointed(b)); // a is never the ground
    let mean = capsule || jointed;
    let turns_a = select(turn_scale(k_a), 1.0, mean);
    let turns_b = select(turn_scale(k_b), 1.0, mean);
    let counted = select(min(acting, 1u), acting, mean);
    set_snap(contact_ref(k, false), end_snap(ea, -j, -moment_a * turns_a, counted, flags));
    set_snap(contact_ref(k, true), end_snap(eb, j, moment_b * turns_b, counted, flags));
}

// The body half: body i's state with what its manifolds ask applied (summed in
// pair order), or s_in itself for a body fixed, asleep or touching nothing, or
// where nothing is `pending`. The pass `restitution` applies it after the last
// substep, integrate before every later one; `pending` enters by a select.
fn restituted(i: u32, s_in: BodyState, p: BodyProps, pending: bool) -> BodyState {
    var s = s_in;
    let first = pair_meta[i].list_start;
    let acts = moves_by_contacts(s, p);
    let end = select(first, first + pair_meta[i].contacts, acts && pending);
    var dv = vec3<f32>(0.0);
    var dw = vec3<f32>(0.0);
    var acting = 0u;
    // Manifolds that bounce the body the same way each ask for the whole
    // bounce, so a bouncing manifold adds only what the changes before it fall
    // short of along its direction: bounces the same way count once, at right
    // angles each in full.
    var bounces = vec3<f32>(0.0);
    // Each partner's friction stops the whole slide against it: for a body
    // pressed by many, partners sliding the same way sum to an overshoot that
    // grew (thirty boxes placed at one point rose 27 m), so the sum is capped
    // at the longest single change. Splitting each by the body's manifold
    // count instead left pyramid rows too little friction to stay put.
    var longest = 0.0;
    // the body's manifolds in pair order (contact_lists)
    for (var e = first; e < end; e = e + 1u) {
        let snap = snap_of(body_pairs[e]);
        let size = length(snap.dx);
        if ((snap.flags & SNAP_BOUNCE) != 0u && size > 0.0) {
            let along = snap.dx / size;
            bounces = bounces + along * max(size - dot(bounces, along), 0.0);
        } else {
            dv = dv + snap.dx;
            longest = max(longest, size);
        }
        dw = dw + snap.dtheta;
        acting = acting + snap.count;
    }
    dv = dv * min(1.0, longest / max(length(dv), 1e-30));
    dv = dv + bounces;
    // the turns averaged over the manifolds that acted (over their points
    // for a capsule's or a jointed body's; restitution_contacts)
    dw = dw / f32(max(acting, 1u));
    if (any(dv != vec3<f32>(0.0)) || any(dw != vec3<f32>(0.0))) {
        let now = pose_velocity(s.disp, s.rot, s.prev_rot);
        let v = now.linear.xyz + dv;
        let w = now.angular.xyz + dw;
        s.disp = v * params.dt;
        s.prev_rot = normalize(quat_mul(quat_from_rotvec(-w * params.dt), s.rot));
    }
    return s;
}

// Over every listed body, into the other state buffer: a body that fell
// asleep in the step's last substep then holds its pose in both, as a
// sleeper the next step leaves out must (`listed_body`).
@compute @workgroup_size(WORKGROUP)
fn restitution(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = listed_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    set_state(i, restituted(i, state_of(i), props_of(i), true));
}

// In place of `restitution` in a world where no body sleeps, over the listed
// bodies with contacts alone (each reads and writes only its own pose, and
// the snaps were measured in the pass before): every body is listed in
// every pass there, so one that touches nothing needs no copy into the
// other buffer, where the next step's integrate writes it.
@compute @workgroup_size(WORKGROUP)
fn restitution_in_place(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = touching_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    set_state(i, restituted(i, out_state(i), props_of(i), true));
}
