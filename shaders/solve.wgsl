// Passes "solve_contacts" and "solve", run in turn `iterations` times per
// substep: the paper's corrective snaps (eqs. 9-10), Jacobi style. Every
// pose is read from state_in: solve_contacts, one invocation per manifold of
// the pool, measures all of a pair's points once and writes what they ask of
// each of its two bodies (snaps[manifold]); solve, one invocation per body,
// sums what its manifolds and joints ask, relaxes the sum by c_r (eq. 10)
// and writes only its own slot of state_out. All of a body's snaps are
// measured on the same starting pose and summed, so symmetric contacts (a
// box resting on four corners) cancel exactly instead of twisting the body
// in the order they were visited, and the sums never depend on thread timing.

// A snap being summed: translation and rotation (radians, world axes).
struct Snap {
    dx: vec3<f32>,
    dtheta: vec3<f32>,
}

// Add a push of lambda along dir at offset r: translation along dir, rotation
// about r x dir, both weighted by the body's inverse mass and inertia.
fn add_push(acc: ptr<function, Snap>, p: BodyProps, rot: vec4<f32>, r: vec3<f32>, dir: vec3<f32>, lambda: f32) {
    (*acc).dx = (*acc).dx + dir * (p.inv_inertia.w * lambda);
    (*acc).dtheta = (*acc).dtheta + inv_inertia_world(rot, p.inv_inertia.xyz, cross(r, dir)) * lambda;
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
@compute @workgroup_size(WORKGROUP)
fn solve_contacts(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= manifolds_used()) {
        return;
    }
    let k = pool_slot(gid.x);
    let ea = contact_end(manifolds[k].a);
    let eb = contact_end(manifolds[k].b);
    if (!ea.moves && !eb.moves) {
        return; // neither body reads its snap
    }
    let n = manifolds[k].normal; // from a to b: a is pushed along -n, b along n
    let mu = combined_friction(ea, eb);
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
    for (var q = 0u; q < manifolds[k].count; q = q + 1u) {
        let pt = manifolds[k].points[q];
        let ra = quat_rotate(ea.rot, pt.local_a);
        let rb = quat_rotate(eb.rot, pt.local_b);
        let on_a = ea.pos + ra;
        let on_b = eb.pos + rb;
        // how far each material point moved since the previous poses, from
        // the displacements (no difference of two far-out positions)
        let moved_a = ea.disp + (ra - quat_rotate(ea.prev_rot, pt.local_a));
        let moved_b = eb.disp + (rb - quat_rotate(eb.prev_rot, pt.local_b));
        // Overlap the bodies already had at their previous poses is pushed
        // out at no more than MAX_DEPENETRATION_SPEED: a full snap in one
        // substep would turn into that much velocity (Verlet), and deep
        // overlaps (thin limbs passing through each other, bodies placed
        // overlapping) launched bodies at tens of m/s. Overlap made by this
        // substep's approach is removed whole.
        let overlap_before = dot((on_a - moved_a) - (on_b - moved_b), n);
        let depth = dot(on_a - on_b, n) - max(overlap_before - MAX_DEPENETRATION_SPEED * params.dt, 0.0);
        // a contact that pushed earlier in this substep keeps its friction
        // while it still touches, even once its depth is resolved, so
        // sideways pushes from other contacts in later sweeps are resisted too
        var push = 0.0;
        var snapped = false;
        if (depth > 0.0) {
            let w = end_inv_mass(ea, ra, n) + end_inv_mass(eb, rb, n);
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
                let w = end_inv_mass(ea, ra, t) + end_inv_mass(eb, rb, t);
                let j = t * (slide / w); // pulls b along t, a back along -t
                friction_j = friction_j + j;
                moment_a = moment_a + cross(ra, j);
                moment_b = moment_b + cross(rb, j);
                friction_inv_w = friction_inv_w + 1.0 / w;
                snapped = true;
            }
        }
        manifolds[k].points[q].pushed = pt.pushed + push;
        if (pt.pushed + push > 0.0) {
            pressed = 1u;
        }
        points = points + u32(snapped);
    }
    var pair_w = 0.0;
    if (ea.moves) {
        pair_w = pair_w + ea.inv_inertia.w;
    }
    if (eb.moves) {
        pair_w = pair_w + eb.inv_inertia.w;
    }
    let n_scale = min(1.0, 1.0 / max(pair_w * normal_inv_w, 1e-30));
    let f_scale = min(1.0, 1.0 / max(pair_w * friction_inv_w, 1e-30));
    let j = normal_j * n_scale + friction_j * f_scale;
    let turns = 1.0 / f32(max(points, 1u));
    let touched = u32(points > 0u);
    snaps[k] = ManifoldSnaps(end_snap(ea, -j, -moment_a * turns, touched, pressed),
                             end_snap(eb, j, moment_b * turns, touched, pressed));
}

// One end of a ball joint: snap this body's share of the gap between the two
// anchors, along the gap.
fn add_joint(acc: ptr<function, Snap>, s: BodyState, p: BodyProps, j: JointRef) -> bool {
    let r = quat_rotate(s.rot, j.local_self);
    var target_point = j.local_partner;
    var r_o = vec3<f32>(0.0);
    var w_o = 0.0;
    if (j.partner != WORLD) {
        let o = state_in[j.partner];
        r_o = quat_rotate(o.rot, j.local_partner);
        target_point = o.pos + r_o;
    }
    let gap = target_point - (s.pos + r);
    let dist = length(gap);
    if (dist < 1e-7) {
        return false;
    }
    let n = gap / dist;
    if (j.partner != WORLD) {
        w_o = effective_inv_mass(props[j.partner], state_in[j.partner].rot, r_o, n);
    }
    add_push(acc, p, s.rot, r, n, dist / (effective_inv_mass(p, s.rot, r, n) + w_o));
    return true;
}

@compute @workgroup_size(WORKGROUP)
fn solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    var s = state_in[i];
    let p = props[i];
    if (is_fixed(p) || asleep(s)) {
        state_out[i] = s;
        return;
    }
    var acc = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    var touching = 0u;
    // 1 if a contact pushed in this substep: integrate's test for sleeping
    var pressed = 0u;
    // the body's manifolds in pair order (contact_lists)
    let first = pair_meta[i].list_start;
    for (var e = first; e < first + pair_meta[i].contacts; e = e + 1u) {
        let snap = snap_of(body_pairs[e]);
        acc.dx = acc.dx + snap.dx;
        acc.dtheta = acc.dtheta + snap.dtheta;
        touching = touching + snap.count;
        pressed = max(pressed, snap.pressed);
    }
    for (var k = joint_start[i]; k < joint_start[i + 1u]; k = k + 1u) {
        if (add_joint(&acc, s, p, joint_refs[k])) {
            touching = touching + 1u;
        }
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
    s.pos = s.pos + dx;
    s.disp = s.disp + dx;
    s.pos_low = (s.pos_low & ~HELD) | select(0u, HELD, pressed != 0u);
    s.rot = quat_add_rotation(s.rot, acc.dtheta * (params.relaxation * split));
    state_out[i] = s;
}
