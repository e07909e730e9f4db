// Pass "restitution", once per step after the solve: collisions change
// velocity by rewriting the previous pose (the paper, section III). A contact
// that was approaching faster than a resting contact can (2 |g| dt) leaves
// with -e times its approach speed along the normal; slower ones stay at
// rest, so resting bodies do not hop.

// Velocities a pose implies: (linear, angular) from the pose and its previous one.
fn implied_velocity(s: BodyState) -> Velocity {
    let dt = params.dt;
    let v = (s.pos.xyz - s.prev_pos.xyz) / dt;
    let w = quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))) / dt;
    return Velocity(vec4<f32>(v, 0.0), vec4<f32>(w, 0.0));
}

// Bounce of one touching contact: if the points were approaching faster than
// the threshold, make them part at e times that speed (this body's share).
fn bounce(v: ptr<function, vec3<f32>>, w: ptr<function, vec3<f32>>, s: BodyState, p: BodyProps,
          r: vec3<f32>, n: vec3<f32>, approach_before: f32, partner_now: vec3<f32>, w_partner: f32, e: f32) -> bool {
    let threshold = 2.0 * length(params.gravity.xyz) * params.dt;
    if (approach_before > -threshold) {
        return false;
    }
    let vn = dot(*v + cross(*w, r) - partner_now, n);
    let target_vn = -e * approach_before;
    if (vn >= target_vn) {
        return false;
    }
    let lambda = (target_vn - vn) / (effective_inv_mass(p, s.rot, r, n) + w_partner);
    *v = *v + n * (p.inv_inertia.w * lambda);
    *w = *w + inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, n)) * lambda;
    return true;
}

@compute @workgroup_size(WORKGROUP)
fn restitution(@builtin(global_invocation_id) gid: vec3<u32>) {
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
    let before = vel0[i];
    let now = implied_velocity(s);
    var v = now.linear.xyz;
    var w = now.angular.xyz;
    var changed = false;
    if (params.has_ground != 0u) {
        let n = vec3<f32>(0.0, 1.0, 0.0);
        let e = max(p.material.x, params.ground_restitution);
        let count = ground_point_count(p);
        for (var k = 0u; k < count; k = k + 1u) {
            let r = ground_point_offset(p, s.rot, k);
            if ((s.pos.y + r.y) - params.gravity.w > CONTACT_SLOP) {
                continue;
            }
            let approach = dot(before.linear.xyz + cross(before.angular.xyz, r), n);
            changed = bounce(&v, &w, s, p, r, n, approach, vec3<f32>(0.0), 0.0, e) || changed;
        }
    }
    let contacts_here = contact_count[i];
    for (var k = 0u; k < contacts_here; k = k + 1u) {
        let c = contacts[i * MAX_CONTACTS + k];
        let o = state_in[c.partner];
        let q = props[c.partner];
        let r = quat_rotate(s.rot, c.local_self);
        let r_o = quat_rotate(o.rot, c.local_partner);
        let n = c.normal;
        if (dot((s.pos.xyz + r) - (o.pos.xyz + r_o), n) > CONTACT_SLOP) {
            continue;
        }
        let b = vel0[c.partner];
        let approach = dot(before.linear.xyz + cross(before.angular.xyz, r) - (b.linear.xyz + cross(b.angular.xyz, r_o)), n);
        let o_now = implied_velocity(o);
        let partner_point = o_now.linear.xyz + cross(o_now.angular.xyz, r_o);
        let e = max(p.material.x, q.material.x);
        changed = bounce(&v, &w, s, p, r, n, approach, partner_point, effective_inv_mass(q, o.rot, r_o, n), e) || changed;
    }
    if (changed) {
        s.prev_pos = vec4<f32>(s.pos.xyz - v * params.dt, 0.0);
        s.prev_rot = normalize(quat_mul(quat_from_rotvec(-w * params.dt), s.rot));
    }
    state_out[i] = s;
}
