// Pass "solve", run `iterations` times per substep: the paper's corrective
// snaps (eqs. 9-10). Each body reads every pose from state_in and writes only
// its own slot of state_out and of its own contacts. All of a body's
// contacts are measured on the same starting pose and their snaps summed
// (Jacobi within the body as across bodies), so symmetric contacts (a box
// resting on four corners) cancel exactly instead of twisting the body in
// the order they were visited; the sum is then relaxed by c_r (eq. 10).

// A snap being summed: translation and rotation (radians, world axes).
struct Snap {
    dx: vec3<f32>,
    dtheta: vec3<f32>,
}

// What one partner's points ask for, kept apart until the partner's last
// point so that it can be scaled and averaged as a whole (see `flush`).
struct PartnerSum {
    normal_dx: vec3<f32>,   // summed translation of the normal snaps
    normal_inv_w: f32,      // sum over those points of 1 / (w_self + w_partner)
    friction_dx: vec3<f32>, // summed translation of the static-friction snaps
    friction_inv_w: f32,
    pair_w: f32,            // inverse masses of the two bodies, summed
    dtheta: vec3<f32>,      // summed rotation of the points' snaps
    points: u32,            // points that snapped
}

// Add a push of lambda along dir at offset r: translation along dir, rotation
// about r x dir, both weighted by the body's inverse mass and inertia.
fn add_push(acc: ptr<function, Snap>, p: BodyProps, rot: vec4<f32>, r: vec3<f32>, dir: vec3<f32>, lambda: f32) {
    (*acc).dx = (*acc).dx + dir * (p.inv_inertia.w * lambda);
    (*acc).dtheta = (*acc).dtheta + inv_inertia_world(rot, p.inv_inertia.xyz, cross(r, dir)) * lambda;
}

// One contact: the normal snap takes this body's share of the depth,
// w_self / (w_self + w_partner), the partner the rest in its own thread.
// Static friction (as XPBD has it): if the two material points have slid
// apart since their previous poses by less than mu times the normal push
// summed over this substep, the slide is undone; a larger slide is left to
// dynamic friction in the restitution pass. The snaps are added to the
// partner's sum `m`. Returns the push (m).
fn add_contact(m: ptr<function, PartnerSum>, s: BodyState, p: BodyProps, c: Contact) -> f32 {
    let o = partner_point(c);
    let n = c.normal;
    let r = quat_rotate(s.rot, c.local_self);
    let self_before = s.prev_pos.xyz + quat_rotate(s.prev_rot, c.local_self);
    // Overlap the bodies already had at their previous poses is pushed out at
    // no more than MAX_DEPENETRATION_SPEED: a full snap in one substep would
    // turn into that much velocity (Verlet), and deep overlaps (thin limbs
    // passing through each other, bodies placed overlapping) launched bodies
    // at tens of m/s. Overlap made by this substep's approach is removed whole.
    let overlap_before = dot(o.before - self_before, n);
    let depth = dot(o.point - (s.pos.xyz + r), n) - max(overlap_before - MAX_DEPENETRATION_SPEED * params.dt, 0.0);
    // a contact that pushed earlier in this substep keeps its friction while
    // it still touches, even once its depth is resolved, so sideways pushes
    // from other contacts in later iterations are resisted too
    var push = 0.0;
    if (depth > 0.0) {
        let w = effective_inv_mass(p, s.rot, r, n) + partner_inv_mass(c, o.r, n);
        (*m).dtheta = (*m).dtheta + inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, n)) * (depth / w);
        (*m).normal_dx = (*m).normal_dx + n * (p.inv_inertia.w * depth / w);
        (*m).normal_inv_w = (*m).normal_inv_w + 1.0 / w;
        push = depth * params.relaxation;
    } else if (c.pushed <= 0.0 || depth < -CONTACT_SLOP) {
        return 0.0;
    }
    let slip = (s.pos.xyz + r) - self_before - (o.point - o.before);
    let slip_t = slip - n * dot(slip, n);
    let slide = length(slip_t);
    if (slide > 1e-9 && slide <= combined_friction(p, c) * (c.pushed + push)) {
        let t = slip_t / slide;
        let w = effective_inv_mass(p, s.rot, r, t) + partner_inv_mass(c, o.r, t);
        (*m).dtheta = (*m).dtheta - inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, t)) * (slide / w);
        (*m).friction_dx = (*m).friction_dx - t * (p.inv_inertia.w * slide / w);
        (*m).friction_inv_w = (*m).friction_inv_w + 1.0 / w;
    }
    return push;
}

// Adds one partner's snaps to the body's and empties `m`; returns 1 if the
// partner pushed at all. Each point's snap moves the body as if that point
// were alone; when several points of one face all ask for the same depth d,
// their sum is d x (pair_w x the sum of 1/w), which is d for points at the
// corners of a cube but four times d for points near the middle of a large
// face (a box resting across two others): that overshoot made piles vibrate
// and walk apart. The sum is scaled down to what moving the two bodies apart
// without turning asks for, never up. The points' turns are averaged: each
// was computed as if it alone turned the body.
fn flush(acc: ptr<function, Snap>, m: ptr<function, PartnerSum>) -> u32 {
    let touched = u32((*m).points > 0u);
    let n_scale = min(1.0, 1.0 / max((*m).pair_w * (*m).normal_inv_w, 1e-30));
    let f_scale = min(1.0, 1.0 / max((*m).pair_w * (*m).friction_inv_w, 1e-30));
    (*acc).dx = (*acc).dx + (*m).normal_dx * n_scale + (*m).friction_dx * f_scale;
    (*acc).dtheta = (*acc).dtheta + (*m).dtheta / f32(max((*m).points, 1u));
    *m = PartnerSum(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, 0.0, vec3<f32>(0.0), 0u);
    return touched;
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
        target_point = o.pos.xyz + r_o;
    }
    let gap = target_point - (s.pos.xyz + r);
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
    var pressed = 0.0;
    var m = PartnerSum(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0, 0.0, vec3<f32>(0.0), 0u);
    // the body's pairs in pair order (pairs.wgsl), one manifold each
    let first = pair_meta[i].list_start;
    let end = min(first + pair_meta[i].total, arrayLength(&body_pairs));
    for (var e = first; e < end; e = e + 1u) {
        let q = body_pairs[e];
        if (q == NONE) {
            continue;
        }
        let pr = pairs[q];
        if (pr.manifold == NONE) {
            continue;
        }
        let self_is_a = pr.a == i;
        let normal = manifolds[pr.manifold].normal;
        let points = manifolds[pr.manifold].count;
        for (var k = 0u; k < points; k = k + 1u) {
            let c = contact_view(pr, normal, manifolds[pr.manifold].points[k], self_is_a);
            m.pair_w = p.inv_inertia.w;
            if (partner_moves(c)) {
                m.pair_w = m.pair_w + props[c.partner].inv_inertia.w;
            }
            let count_before = m.normal_inv_w + m.friction_inv_w;
            let push = add_contact(&m, s, p, c);
            if (self_is_a) {
                manifolds[pr.manifold].points[k].pushed_a = c.pushed + push;
            } else {
                manifolds[pr.manifold].points[k].pushed_b = c.pushed + push;
            }
            if (c.pushed + push > 0.0) {
                pressed = 1.0;
            }
            if (m.normal_inv_w + m.friction_inv_w != count_before) {
                m.points = m.points + 1u;
            }
        }
        touching = touching + flush(&acc, &m);
    }
    for (var k = joint_start[i]; k < joint_start[i + 1u]; k = k + 1u) {
        if (add_joint(&acc, s, p, joint_refs[k])) {
            touching = touching + 1u;
        }
    }
    // Each snap turns the body as if it were the only one; summed they
    // overshoot (four corners correcting a twist turn it back about twice too
    // far), so a partner's points share one turn (their mean, in `flush`) and
    // the partners' turns are averaged too (mass splitting, for the inertia
    // only: translations are scaled per partner in `flush`).
    let split = 1.0 / f32(max(touching, 1u));
    s.pos = vec4<f32>(s.pos.xyz + acc.dx * params.relaxation, s.pos.w);
    s.prev_pos.w = pressed;
    s.rot = quat_add_rotation(s.rot, acc.dtheta * (params.relaxation * split));
    state_out[i] = s;
}
