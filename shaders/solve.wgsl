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
// dynamic friction in the restitution pass. Returns the push (m).
fn add_contact(acc: ptr<function, Snap>, s: BodyState, p: BodyProps, c: Contact) -> f32 {
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
        add_push(acc, p, s.rot, r, n, depth / (effective_inv_mass(p, s.rot, r, n) + partner_inv_mass(c, o.r, n)));
        push = depth * params.relaxation;
    } else if (c.pushed <= 0.0 || depth < -CONTACT_SLOP) {
        return 0.0;
    }
    let slip = (s.pos.xyz + r) - self_before - (o.point - o.before);
    let slip_t = slip - n * dot(slip, n);
    let slide = length(slip_t);
    if (slide > 1e-9 && slide <= combined_friction(p, c) * (c.pushed + push)) {
        let t = slip_t / slide;
        add_push(acc, p, s.rot, r, -t, slide / (effective_inv_mass(p, s.rot, r, t) + partner_inv_mass(c, o.r, t)));
    }
    return push;
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
    if (is_fixed(p)) {
        state_out[i] = s;
        return;
    }
    var acc = Snap(vec3<f32>(0.0), vec3<f32>(0.0));
    let first = i * MAX_CONTACTS;
    let count = contact_count[i];
    var touching = 0u;
    for (var k = first; k < first + count; k = k + 1u) {
        let before = acc;
        let push = add_contact(&acc, s, p, contacts[k]);
        contacts[k].pushed = contacts[k].pushed + push;
        if (any(acc.dx != before.dx) || any(acc.dtheta != before.dtheta)) {
            touching = touching + 1u;
        }
    }
    for (var k = joint_start[i]; k < joint_start[i + 1u]; k = k + 1u) {
        if (add_joint(&acc, s, p, joint_refs[k])) {
            touching = touching + 1u;
        }
    }
    // Each contact's snap turns the body as if it were the only one; summed
    // over several contacts the turns overshoot (four corners correcting a
    // twist turn it back about twice too far), so the rotation is split
    // among the active contacts (mass splitting, for the inertia only: the
    // translations of a face's points already add up to the face's push).
    let split = 1.0 / f32(max(touching, 1u));
    s.pos = vec4<f32>(s.pos.xyz + acc.dx * params.relaxation, 0.0);
    s.rot = quat_add_rotation(s.rot, acc.dtheta * (params.relaxation * split));
    state_out[i] = s;
}
