// Pass "solve", run `iterations` times per step: the paper's corrective snaps
// (eqs. 9-10). Each body reads every pose from state_in and writes only its
// own slot of state_out (Jacobi across bodies); its own contacts are visited
// in a fixed order, each one seeing the corrections of those before it.

// Push the body's pose by lambda along dir at offset r: translation along dir,
// rotation about r x dir, both weighted by the inverse mass and inertia.
fn snap(s: ptr<function, BodyState>, p: BodyProps, r: vec3<f32>, dir: vec3<f32>, lambda: f32) {
    (*s).pos = vec4<f32>((*s).pos.xyz + dir * (p.inv_inertia.w * lambda), 0.0);
    let dtheta = inv_inertia_world((*s).rot, p.inv_inertia.xyz, cross(r, dir)) * lambda;
    (*s).rot = quat_add_rotation((*s).rot, dtheta);
}

// One contact with the static ground: the normal snap out of penetration,
// then friction that undoes the contact point's sliding since the previous
// pose, up to mu times the normal correction (Coulomb's cone in positions).
fn solve_ground_point(s: ptr<function, BodyState>, p: BodyProps, k: u32) {
    let n = vec3<f32>(0.0, 1.0, 0.0);
    let r = ground_point_offset(p, (*s).rot, k);
    let depth = params.gravity.w - ((*s).pos.y + r.y);
    if (depth <= 0.0) {
        return;
    }
    // normal snap, relaxed by c_r (eq. 10)
    let normal_push = depth * params.relaxation;
    snap(s, p, r, n, normal_push / effective_inv_mass(p, (*s).rot, r, n));

    // friction: sliding of the material point since the previous pose
    let mu = sqrt(p.material.y * params.ground_friction);
    let r_now = ground_point_offset(p, (*s).rot, k);
    let local = quat_rotate(quat_conj((*s).rot), r_now);
    let point_prev = (*s).prev_pos.xyz + quat_rotate((*s).prev_rot, local);
    let slip = ((*s).pos.xyz + r_now) - point_prev;
    let slip_t = slip - n * dot(slip, n);
    let slide = length(slip_t);
    if (slide < 1e-9) {
        return;
    }
    let t = slip_t / slide;
    let undo = min(slide, mu * normal_push);
    snap(s, p, r_now, -t, undo / effective_inv_mass(p, (*s).rot, r_now, t));
}

// One contact with another body, which sits still at its state_in pose
// while this body moves (Jacobi): this body takes its share of the snap,
// w_self / (w_self + w_partner), and the partner takes the rest in its own
// thread from the mirrored contact.
fn solve_pair_contact(s: ptr<function, BodyState>, p: BodyProps, c: Contact) {
    let o = state_in[c.partner];
    let q = props[c.partner];
    let n = c.normal;
    let r = quat_rotate((*s).rot, c.local_self);
    let r_o = quat_rotate(o.rot, c.local_partner);
    let point_o = o.pos.xyz + r_o;
    let depth = dot(point_o - ((*s).pos.xyz + r), n);
    if (depth <= 0.0) {
        return;
    }
    let w_o = effective_inv_mass(q, o.rot, r_o, n);
    let normal_push = depth * params.relaxation;
    snap(s, p, r, n, normal_push / (effective_inv_mass(p, (*s).rot, r, n) + w_o));

    // friction: relative sliding of the two material points since their previous poses
    let r_now = quat_rotate((*s).rot, c.local_self);
    let slip_self = ((*s).pos.xyz + r_now) - ((*s).prev_pos.xyz + quat_rotate((*s).prev_rot, c.local_self));
    let slip_o = point_o - (o.prev_pos.xyz + quat_rotate(o.prev_rot, c.local_partner));
    let slip = slip_self - slip_o;
    let slip_t = slip - n * dot(slip, n);
    let slide = length(slip_t);
    if (slide < 1e-9) {
        return;
    }
    let t = slip_t / slide;
    let mu = sqrt(p.material.y * q.material.y);
    let undo = min(slide, mu * normal_push);
    let w_t = effective_inv_mass(p, (*s).rot, r_now, t) + effective_inv_mass(q, o.rot, r_o, t);
    snap(s, p, r_now, -t, undo / w_t);
}

@compute @workgroup_size(WORKGROUP)
fn solve(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    var s = state_in[i];
    let p = props[i];
    if (!is_fixed(p)) {
        if (params.has_ground != 0u) {
            let count = ground_point_count(p);
            for (var k = 0u; k < count; k = k + 1u) {
                solve_ground_point(&s, p, k);
            }
        }
        let contacts_here = contact_count[i];
        for (var k = 0u; k < contacts_here; k = k + 1u) {
            solve_pair_contact(&s, p, contacts[i * MAX_CONTACTS + k]);
        }
    }
    state_out[i] = s;
}
