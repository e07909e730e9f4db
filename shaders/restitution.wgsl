// Pass "restitution", once per substep after the solve: collisions change
// velocity by rewriting the previous pose (the paper, section III). A contact
// that was approaching faster than a resting contact can (2 |g| dt), and
// faster than RESTITUTION_THRESHOLD, leaves with -e times its approach speed
// along the normal; slower ones stay at rest, so resting bodies do not hop.
// The floor matters with substeps: at dt = 1/480 s, 2 |g| dt is 4 cm/s, and
// a limb held against a surface by a joint then bounced every substep and
// pumped energy in (a ragdoll's forearm jittered forever). Dynamic friction acts here too: a
// contact still sliding after the solve loses up to mu times the normal
// velocity change its push made (mu |dv_n|, Coulomb's law per substep).
// Every contact is measured on the velocities after the solve and the
// changes summed, the turns split among the contacts as in the solve.

// Approach speeds (m/s) below this never bounce; Box2D's default too.
const RESTITUTION_THRESHOLD: f32 = 1.0;

// Velocities a pose implies: (x - x_prev) / dt and the rotation q q_prev^*.
fn implied_velocity(s: BodyState) -> Velocity {
    let v = (s.pos.xyz - s.prev_pos.xyz) / params.dt;
    let w = quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))) / params.dt;
    return Velocity(vec4<f32>(v, 0.0), vec4<f32>(w, 0.0));
}

fn point_velocity(v: Velocity, r: vec3<f32>) -> vec3<f32> {
    return v.linear.xyz + cross(v.angular.xyz, r);
}

@compute @workgroup_size(WORKGROUP)
fn restitution(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    var s = state_in[i];
    let p = props[i];
    let first = pair_meta[i].list_start;
    let end = min(first + pair_meta[i].total, arrayLength(&body_pairs));
    if (is_fixed(p) || first == end || asleep(s)) {
        state_out[i] = s;
        return;
    }
    let before = vel0[i];
    let now = implied_velocity(s);
    let threshold = max(2.0 * length(params.gravity.xyz) * params.dt, RESTITUTION_THRESHOLD);
    var dv = vec3<f32>(0.0);
    var dw = vec3<f32>(0.0);
    var acting = 0u;
    // the body's pairs in pair order (pairs.wgsl); each point's friction
    // budget is emptied for the next substep once it has been used here
    for (var e = first; e < end; e = e + 1u) {
        let q = body_pairs[e];
        if (q == NONE || pairs[q].manifold == NONE) {
            continue;
        }
        let pr = pairs[q];
        let self_is_a = pr.a == i;
        let normal = manifolds[pr.manifold].normal;
        // the partner's velocities before the solve and now, once per pair
        let partner = select(pr.a, pr.b, self_is_a);
        var partner_v0 = Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
        var partner_v = partner_v0;
        if (partner != GROUND) {
            partner_v0 = vel0[partner];
            partner_v = implied_velocity(state_in[partner]);
        }
        for (var k = 0u; k < manifolds[pr.manifold].count; k = k + 1u) {
            let c = contact_view(pr, normal, manifolds[pr.manifold].points[k], self_is_a);
            if (self_is_a) {
                manifolds[pr.manifold].points[k].pushed_a = 0.0;
            } else {
                manifolds[pr.manifold].points[k].pushed_b = 0.0;
            }
            let o = partner_point(c);
            let n = c.normal;
            let r = quat_rotate(s.rot, c.local_self);
            // touching?
            if (dot((s.pos.xyz + r) - o.point, n) > CONTACT_SLOP) {
                continue;
            }
            // approach speed of the two points before the solve, and now
            let partner_before = point_velocity(partner_v0, o.r);
            let partner_now = point_velocity(partner_v, o.r);
            let relative_now = point_velocity(now, r) - partner_now;
            let w_self_n = effective_inv_mass(p, s.rot, r, n);
            var acted = false;
            // dynamic friction against the sliding left after the solve
            let v_t = relative_now - n * dot(relative_now, n);
            let sliding = length(v_t);
            if (c.pushed > 0.0 && sliding > 1e-6) {
                let t = v_t / sliding;
                let cut = min(combined_friction(p, c) * c.pushed / params.dt, sliding);
                let lambda_t = cut / (effective_inv_mass(p, s.rot, r, t) + partner_inv_mass(c, o.r, t));
                dv = dv - t * (p.inv_inertia.w * lambda_t);
                dw = dw - inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, t)) * lambda_t;
                acted = true;
            }
            // restitution of a fast approach
            let approach = dot(point_velocity(before, r) - partner_before, n);
            let vn = dot(relative_now, n);
            let target_vn = -combined_restitution(p, c) * approach;
            if (approach < -threshold && vn < target_vn) {
                let lambda = (target_vn - vn) / (w_self_n + partner_inv_mass(c, o.r, n));
                dv = dv + n * (p.inv_inertia.w * lambda);
                dw = dw + inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, n)) * lambda;
                acted = true;
            }
            if (acted) {
                acting = acting + 1u;
            }
        }
    }
    dw = dw / f32(max(acting, 1u));
    if (any(dv != vec3<f32>(0.0)) || any(dw != vec3<f32>(0.0))) {
        let v = now.linear.xyz + dv;
        let w = now.angular.xyz + dw;
        s.prev_pos = vec4<f32>(s.pos.xyz - v * params.dt, s.prev_pos.w);
        s.prev_rot = normalize(quat_mul(quat_from_rotvec(-w * params.dt), s.rot));
    }
    state_out[i] = s;
}
