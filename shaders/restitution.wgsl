// Pass "restitution", once per step after the solve: collisions change
// velocity by rewriting the previous pose (the paper, section III). A contact
// that was approaching faster than a resting contact can (2 |g| dt) leaves
// with -e times its approach speed along the normal; slower ones stay at
// rest, so resting bodies do not hop.

@compute @workgroup_size(WORKGROUP)
fn restitution(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    var s = state_in[i];
    let p = props[i];
    if (is_fixed(p) || params.has_ground == 0u) {
        state_out[i] = s;
        return;
    }
    let dt = params.dt;
    let n = vec3<f32>(0.0, 1.0, 0.0);
    let before = vel0[i];
    // velocities implied by the solved pose
    var v = (s.pos.xyz - s.prev_pos.xyz) / dt;
    var w = quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))) / dt;
    let threshold = 2.0 * length(params.gravity.xyz) * dt;
    let e = max(p.material.x, params.ground_restitution);
    var changed = false;
    let count = ground_point_count(p);
    for (var k = 0u; k < count; k = k + 1u) {
        let r = ground_point_offset(p, s.rot, k);
        let gap = (s.pos.y + r.y) - params.gravity.w;
        if (gap > CONTACT_SLOP) {
            continue;
        }
        // approach speed of this point before the solve
        let vn_before = dot(before.linear.xyz + cross(before.angular.xyz, r), n);
        if (vn_before > -threshold) {
            continue;
        }
        let vn = dot(v + cross(w, r), n);
        let target_vn = -e * vn_before;
        if (vn >= target_vn) {
            continue;
        }
        let lambda = (target_vn - vn) / effective_inv_mass(p, s.rot, r, n);
        v = v + n * (p.inv_inertia.w * lambda);
        w = w + inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, n)) * lambda;
        changed = true;
    }
    if (changed) {
        s.prev_pos = vec4<f32>(s.pos.xyz - v * dt, 0.0);
        s.prev_rot = normalize(quat_mul(quat_from_rotvec(-w * dt), s.rot));
    }
    state_out[i] = s;
}
