// Pass "integrate": the paper's position Verlet, eq. 6 for translation and
// eq. 7 for rotation, time-corrected for a changing dt (eq. 11) and damped
// (eq. 12). Reads state_in, writes each body's own slot of state_out (the
// predicted pose, with the current pose as its previous one) and of vel0.

@compute @workgroup_size(WORKGROUP)
fn integrate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    let s = state_in[i];
    let p = props[i];
    let dt = params.dt;
    // a new substep: its contacts' friction budgets start empty
    let first = i * MAX_CONTACTS;
    for (var k = first; k < first + contact_count[i]; k = k + 1u) {
        contacts[k].pushed = 0.0;
    }
    if (is_fixed(p)) {
        state_out[i] = BodyState(s.pos, s.pos, s.rot, s.rot);
        vel0[i] = Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
        return;
    }
    // eq. 11: the last displacement, rescaled to this step's length
    let ratio = dt / params.dt_prev;
    // eq. 12: damping keeps (1 - beta) of it
    let carry = (s.pos.xyz - s.prev_pos.xyz) * (ratio * (1.0 - params.linear_damping));
    // constant acceleration: a dt (dt + dt_prev) / 2 is exact for any pair of
    // steps and equals eq. 6's a dt^2 when dt does not change
    let accel = params.gravity.xyz * (dt * 0.5 * (dt + params.dt_prev));
    let pos = s.pos.xyz + carry + accel;

    // eq. 7 with no torque: repeat the last rotation q_n q_{n-1}^*, scaled by
    // the step ratio and damped by interpolation towards no rotation
    let last = quat_mul(s.rot, quat_conj(s.prev_rot));
    let keep = ratio * (1.0 - params.angular_damping);
    var turn = last;
    if (keep != 1.0) {
        turn = quat_from_rotvec(quat_to_rotvec(last) * keep);
    }
    let rot = normalize(quat_mul(turn, s.rot));
    let spin = quat_to_rotvec(turn);

    state_out[i] = BodyState(vec4<f32>(pos, 0.0), s.pos, rot, s.rot);
    vel0[i] = Velocity(vec4<f32>((pos - s.pos.xyz) / dt, 0.0), vec4<f32>(spin / dt, 0.0));
}
