// Pass "integrate": the paper's position Verlet, eqs. 6 and 7, time-corrected
// for a changing dt (eq. 11) and damped (eq. 12). Reads state_in, writes each
// body's own slot of state_out (the predicted pose) and of vel0. After a
// step's first substep it first applies the last substep's restitution
// (restitution.wgsl's `restituted`): a dispatch and a state copy fewer.
//
// Numerical faults: every substep, with no readback, a body whose pose is not
// finite, lies beyond MAX_DISTANCE, or moved or turned faster than MAX_SPEED,
// MAX_SPIN or MAX_TURN (or its speed_limit) over the last substep is
// flagged in status[STATUS_FAULT] and status[STATUS_FAULT_STEP] (bindings.wgsl: the lowest such body of the first
// step that found any, with that step's index) and parked at rest at its last
// sane pose; the step goes on. A run with no fault is bit-identical to one
// without the check, and the host reads the flag only on request.

// The WAKES bit body i's pose carries out of this substep: in the first, the
// narrowphase's WOKEN_NOW (cleared for the next step), so the body wakes once
// the pair list holds all its pairs again; in the others, as it came in. Only
// a sleeper can have been woken, so an awake body touches no atomic.
fn wakes_next(i: u32, s: BodyState) -> u32 {
    let first = params.substep == 0u;
    var now = 0u;
    if (asleep(s)) {
        now = atomicLoad(&pair_meta[i].woken);
        // later substeps store it unchanged (nothing sets it after the narrowphase)
        atomicStore(&pair_meta[i].woken, select(now, 0u, first));
    }
    return select(s.pos_low & WAKES, select(0u, WAKES, (now & WOKEN_NOW) != 0u), first);
}

// Notes that a body moves, or is due to wake, after the step (status[STATUS_MOVING]:
// the world is at rest after a step that noted none), in the step's last
// substep. Loaded before stored, so only the first store of a step writes (an
// atomic is a loop over the lanes on lavapipe).
fn moved() {
    if (atomicLoad(&status[STATUS_MOVING]) < select(0u, 1u, params.substep + 1u == params.substeps)) {
        atomicStore(&status[STATUS_MOVING], 1u);
    }
}

// Beyond MAX_DISTANCE, MAX_SPEED, MAX_SPIN and MAX_TURN (m, m/s, rad/s, rad
// per substep; src/limits.rs, which decodes the faults) a body is absurd. A
// pose pair holds less than half a turn, so MAX_TURN bounds a spin whatever
// MAX_SPIN allows. A fault is stored as 8 * body + FAULT_* in
// status[STATUS_FAULT], its step in status[STATUS_FAULT_STEP] (NO_FAULT in both before any).

// FAULT_ENERGY: faster than all the scene's energy could move this body alone
// (BodyProps' speed_limit), which only the solver can do; checked while
// params.speed_limits holds (nothing has added energy since the scene began).


fn usable_rotation(q: vec4<f32>) -> bool {
    let d = dot(q, q);
    return all_finite(q) && d > 1e-6 && d < 1e6;
}

// FAULT_* of a body's state, or NO_FAULT.
fn fault_of(s: BodyState, p: BodyProps) -> u32 {
    let finite = all_finite(vec4<f32>(s.pos, 0.0)) && all_finite(vec4<f32>(s.disp, 0.0))
        && all_finite(s.rot) && all_finite(s.prev_rot);
    if (!finite) {
        return FAULT_NON_FINITE;
    }
    if (!near(s.pos)) {
        return FAULT_FAR;
    }
    let moved = s.disp;
    let reach = MAX_SPEED * params.dt_prev;
    if (dot(moved, moved) > reach * reach) {
        return FAULT_FAST;
    }
    let allowed = p.speed_limit * params.dt_prev;
    // (`&`, not `&&`: no branch on a uniform alone, see integrate below)
    if ((params.speed_limits != 0u) & (p.speed_limit > 0.0) & (dot(moved, moved) > allowed * allowed)) {
        return FAULT_ENERGY;
    }
    let turned = length(quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))));
    if (turned > min(MAX_TURN, MAX_SPIN * params.dt_prev)) {
        return FAULT_SPIN;
    }
    return NO_FAULT;
}

// Records a fault of body i unless an earlier step already recorded one:
// within one dispatch every thread has the same step_index, and dispatches
// run in order, so status[STATUS_FAULT] and status[STATUS_FAULT_STEP] always describe the same event.
fn report_fault(i: u32, fault: u32) {
    let first = atomicLoad(&status[STATUS_FAULT_STEP]);
    if (first == NO_FAULT || first == params.step_index) {
        atomicMin(&status[STATUS_FAULT_STEP], params.step_index);
        atomicMin(&status[STATUS_FAULT], 8u * i + fault);
    }
}

// v, behind a barrier the shader compiler cannot see through: a driver may
// simplify float arithmetic not marked exact (naga marks none), and Mesa's
// optimiser folds (a + b) - a to b, which turns TwoSum's remainder into 0.
fn opaque(v: vec3<f32>) -> vec3<f32> {
    return bitcast<vec3<f32>>(bitcast<vec3<u32>>(v) ^ vec3<u32>(params.opaque_zero));
}

// No branch here depends on the per-substep uniforms alone (selects instead):
// lavapipe re-specialises such a pass for the uniforms' values at every
// dispatch, at 2-3 ms each (docs/decisions/integration.md).
@compute @workgroup_size(WORKGROUP)
fn integrate(@builtin(global_invocation_id) gid: vec3<u32>) {
    // the substep's sweeps start at weight 1 (solve.wgsl's sweep_weight)
    if (gid.x == 0u) {
        atomicStore(&status[STATUS_SWEEPS], 0u);
        atomicStore(&status[STATUS_PATHS_AGAIN], 0u);
    }
    let i = listed_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    let p = props_of(i);
    // the last substep's restitution first (none before a step's first substep)
    let s = restituted(i, state_of(i), p, params.substep != 0u);
    let dt = params.dt;
    let wake = params.substep == 0u && (s.pos_low & WAKES) != 0u;
    let wakes = wakes_next(i, s);
    let fault = fault_of(s, p);
    if (fault != NO_FAULT) {
        report_fault(i, fault);
        var at = vec3<f32>(0.0);
        let prev = s.pos - s.disp;
        // the current position's finite coordinates (pos - disp is no better with a NaN)
        let kept = select(vec3<f32>(0.0), s.pos, (bitcast<vec3<u32>>(s.pos) & vec3<u32>(0x7f800000u)) != vec3<u32>(0x7f800000u));
        if (near(s.pos)) {
            at = s.pos;
        } else if (near(prev)) {
            at = prev;
        } else if (near(kept)) {
            at = kept;
        }
        var q = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        if (usable_rotation(s.rot)) {
            q = normalize(s.rot);
        } else if (usable_rotation(s.prev_rot)) {
            q = normalize(s.prev_rot);
        }
        set_state(i, BodyState(at, 0.0, vec3<f32>(0.0), 0u, q, q));
        vel0[i] = Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
        moved();
        return;
    }
    if (is_fixed(p)) {
        set_state(i, BodyState(s.pos, s.rest_time, vec3<f32>(0.0), HELD, s.rot, s.rot));
        vel0[i] = Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
        return;
    }
    // seconds at rest, this substep included (asleep() is false with sleeping off)
    var rest = 0.0;
    // held by a contact, or by its joints (a joint island sleeps as a whole:
    // joint_rest gives its bodies the island's least rest time)
    let jointed = joint_start[i] != joint_start[i + 1u];
    // a kinematic body keeps its velocities: no gravity or damping, no sleep
    let free = !is_kinematic(p);
    let held = ((s.pos_low & HELD) != 0u || jointed) && free;
    let speed = point_speed(s, p);
    let resting = held && speed < SLEEP_SPEED;
    // jitter in place (faster than SLEEP_SPEED now and then, never as fast as
    // what wakes) takes back its time instead of all the rest time, so a body
    // slow more often than not still comes to sleep; not a jointed body, whose
    // island sleeps as one
    let jittering = held && !jointed && speed < WAKE_SPEED;
    if (asleep(s)) {
        if (!wake) {
            rest = s.rest_time;
        }
    } else if (SLEEPING && select(false, resting, params.sleep_after > 0.0)) {
        // a jointed body falls asleep only where its island's rest time was
        // just shared (joint_rest, in a step's first substep alone): in the
        // later substeps its count stops short of sleep_after
        let short = bitcast<f32>(bitcast<u32>(params.sleep_after) - 1u);
        rest = select(s.rest_time + dt, min(s.rest_time + dt, short), jointed && params.substep != 0u);
    } else if (SLEEPING && select(false, jittering, params.sleep_after > 0.0)) {
        rest = max(s.rest_time - dt, 0.0);
    }
    if (SLEEPING && rest >= params.sleep_after && rest > 0.0) {
        // asleep: held still where it is (resting on what pressed it)
        set_state(i, BodyState(s.pos, rest, vec3<f32>(0.0), (s.pos_low & ~WAKES) | HELD | wakes, s.rot, s.rot));
        vel0[i] = Velocity(vec4<f32>(0.0), vec4<f32>(0.0));
        if (wakes != 0u) {
            moved();
        }
        return;
    }
    // eq. 11: the last displacement, rescaled to this step's length
    let ratio = dt / params.dt_prev;
    // eq. 12: damping keeps (1 - beta) of it
    let carry = s.disp * (ratio * (1.0 - select(0.0, params.linear_damping, free)));
    // gravity: a dt (dt + dt_prev) / 2, exact for any pair of steps (eq. 6's a dt^2)
    let accel = select(vec3<f32>(0.0), params.gravity * (dt * 0.5 * (dt + params.dt_prev)), free);
    let disp = carry + accel;
    // pos + disp by Knuth's TwoSum: what the last addition's rounding dropped is
    // added back and what this one drops kept, so the position follows the
    // displacements to about 1/1000 of its f32 spacing
    let add = disp + pos_remainder(s);
    let pos = opaque(s.pos + add);
    let add_part = opaque(pos - s.pos);
    let pos_part = pos - add_part;
    let dropped = (s.pos - pos_part) + (add - add_part);

    // eq. 7 with no torque: repeat the last turn, rescaled and damped towards none
    let last = quat_mul(s.rot, quat_conj(s.prev_rot));
    let keep = ratio * (1.0 - select(0.0, params.angular_damping, free));
    let turn = select(quat_from_rotvec(quat_to_rotvec(last) * keep), last, keep == 1.0);
    let rot = normalize(quat_mul(turn, s.rot));
    let spin = quat_to_rotvec(turn);

    // HELD (a contact pushed it) stays for solve to renew; solve passes over
    // a body with no contacts, so it is cleared here
    let pressed = select(0u, s.pos_low & HELD, pair_meta[i].contacts != 0u);
    set_state(i, BodyState(pos, rest, disp, pack_remainder(dropped, pos, pressed | wakes), rot, s.rot));
    vel0[i] = Velocity(vec4<f32>(disp / dt, 0.0), vec4<f32>(spin / dt, 0.0));
    moved();
}
