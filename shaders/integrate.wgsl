// Pass "integrate": the paper's position Verlet, eq. 6 for translation and
// eq. 7 for rotation, time-corrected for a changing dt (eq. 11) and damped
// (eq. 12). Reads state_in, writes each body's own slot of state_out (the
// predicted pose, with the current pose as its previous one) and of vel0.
// In a step's second substep and later, it first applies what the last
// substep's restitution_contacts asked of the body (restitution.wgsl),
// which a pass of its own did before: a dispatch fewer and a read and write
// of every state fewer a substep, the same bits.
//
// Numerical faults: first, every body's state as read here is checked, every
// substep, with no readback. A body whose pose is not finite (an infinity or
// a NaN in pos, disp, rot or prev_rot), lies farther than MAX_DISTANCE
// from the origin, moved faster than MAX_SPEED or turned faster than MAX_SPIN
// (or more than MAX_TURN) over the last substep is
// flagged in status[STATUS_FAULT] and status[STATUS_FAULT_STEP] (the lowest
// such body of the first step that found any, with that step's index) and
// stopped: it is parked at
// rest at its last sane pose (its current one if that is finite and within
// MAX_DISTANCE, else its previous one, pos - disp, which passed this check
// last time unless an input wrote it, else its current one with each
// coordinate that is not finite set to 0, else the origin; its rotation
// likewise, else none) and the step goes on; the next substep integrates it again from
// rest. Nothing else changes, so a run with no fault is bit-identical to one
// without the check. The host reads the flag only on request
// (World::faults, World::read_state), never in the step loop.

// Sleeping (see `asleep` in common.wgsl): a body sleeps once it has moved
// slower than SLEEP_SPEED, at every point, for params.sleep_after seconds
// while touching something (the solve sets HELD in pos_low when a contact
// of the body pushed in the substep); a sleeper wakes when an awake body in
// a pair with it moves faster than WAKE_SPEED at any point or lies more
// than WAKE_DEPTH inside it (`wakes`, found by the narrowphase; the body
// wakes one step later, see `wakes_next`); inputs and
// edits wake every body (input.wgsl's wake_all). Box2D's rule is alike (it
// sleeps whole islands; this sleeps bodies, and a body's awake partners
// treat it as fixed).

// A body wakes in a step's first substep, one step after the narrowphase
// found an awake partner waking it (WOKEN_NOW, moved here to the pose's
// WAKES bit), so that this step's pair list already holds all of its pairs
// (pairs.wgsl lists a woken sleeper's pairs as a mover's). The WAKES bit
// body i's pose carries out of this substep: in the first, the
// narrowphase's finding (cleared for the next step's); in the others, as
// it came in. Only a sleeper can have been found woken (wake_check tests
// the same pose this substep starts from), so an awake body touches no
// flag: two atomics a body every substep, each a loop over the lanes on
// lavapipe.
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
// substep: a body that fell asleep in an earlier one holds still from then
// on. Loaded first, so that after the first store of a step the other
// lanes only read (a store per body every substep cost integrate 15% at
// 10k, an atomic being a loop over the lanes on lavapipe); the substep
// enters the condition by a select, beside the load (see above).
fn moved() {
    if (atomicLoad(&status[STATUS_MOVING]) < select(0u, 1u, params.substep + 1u == params.substeps)) {
        atomicStore(&status[STATUS_MOVING], 1u);
    }
}

// Beyond these a body is absurd (m, m/s, rad/s, rad per substep). A pose
// pair holds less than half a turn per substep (a bigger turn reads as a
// smaller one the other way), so a spin is also absurd where it turns more
// than MAX_TURN in one substep, whatever MAX_SPIN allows.
// MAX_DISTANCE, MAX_SPEED, MAX_SPIN, MAX_TURN (m, m/s, rad/s, rad per
// substep), NO_FAULT (status[STATUS_FAULT_STEP] and status[STATUS_FAULT] before any fault) and what was
// wrong, in the low three bits of status[STATUS_FAULT] (8 * body + FAULT_*):
// FAULT_NON_FINITE, FAULT_FAR, FAULT_FAST, FAULT_SPIN, FAULT_ENERGY; shared
// with Rust (src/world.rs), which decodes them.
//
// A body is also absurd when it moves faster than the scene's energy
// allows (FAULT_ENERGY): all the energy the scene began with, what gravity
// can give down to the ground and what pushing out overlap can add, given
// to this body alone, moves it at BodyProps' speed_limit (twice that speed,
// for the integration's own error; src/world/records.rs: speed_limits). No
// collision, joint or restitution of at most 1 adds energy, so a body
// beyond it was thrown by the solver: fifty boxes placed at one point and
// landing before they had parted were thrown at 349 m/s, a run that then
// looked like a success. The limit holds only while nothing else added
// energy (params.speed_limits: 0 after any input, edit or restore).

// (all_finite and near: common.wgsl)

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

// No branch here depends on the per-substep parameters alone (selects
// instead): lavapipe re-specialises a pass whose branch conditions read only
// uniforms for the uniforms' values at every dispatch, and here that cost
// 2-3 ms a dispatch (a 10-cube step went from 3.2 to 12 ms).
@compute @workgroup_size(WORKGROUP)
fn integrate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = listed_body(gid.x);
    if (i >= params.body_count) {
        return;
    }
    let p = props_of(i);
    // the last substep's restitution first (restitution.wgsl's body half,
    // `restituted`; none before a step's first substep, which follows the
    // pass "restitution")
    let s = restituted(i, state_of(i), p, params.substep != 0u);
    let dt = params.dt;
    let wake = params.substep == 0u && (s.pos_low & WAKES) != 0u;
    let wakes = wakes_next(i, s);
    let fault = fault_of(s, p);
    if (fault != NO_FAULT) {
        report_fault(i, fault);
        var at = vec3<f32>(0.0);
        let prev = s.pos - s.disp;
        // the current position's finite coordinates (a NaN in one of them
        // leaves pos - disp no better)
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
    // seconds at rest, this substep included (asleep() is false with
    // sleeping off)
    var rest = 0.0;
    // held by a contact, or by its joints: a joint island sleeps and wakes
    // as a whole (solve_joints gives every body of it the island's least
    // rest time)
    let jointed = joint_start[i] != joint_start[i + 1u];
    let resting = ((s.pos_low & HELD) != 0u || jointed) && point_speed(s, p) < SLEEP_SPEED;
    if (asleep(s)) {
        if (!wake) {
            rest = s.rest_time;
        }
    } else if (select(false, resting, params.sleep_after > 0.0)) {
        rest = s.rest_time + dt;
    }
    if (rest >= params.sleep_after && rest > 0.0) {
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
    let carry = s.disp * (ratio * (1.0 - params.linear_damping));
    // constant acceleration: a dt (dt + dt_prev) / 2 is exact for any pair of
    // steps and equals eq. 6's a dt^2 when dt does not change
    let accel = params.gravity * (dt * 0.5 * (dt + params.dt_prev));
    let disp = carry + accel;
    // pos + disp, with what the last addition's rounding dropped added back
    // and what this one drops kept (Knuth's TwoSum, exact under
    // round-to-nearest): the position then follows the displacements to
    // about 1/1000 of its f32 spacing instead of losing up to half a
    // spacing every substep
    let add = disp + pos_remainder(s);
    let pos = opaque(s.pos + add);
    let add_part = opaque(pos - s.pos);
    let pos_part = pos - add_part;
    let dropped = (s.pos - pos_part) + (add - add_part);

    // eq. 7 with no torque: repeat the last rotation q_n q_{n-1}^*, scaled by
    // the step ratio and damped by interpolation towards no rotation
    let last = quat_mul(s.rot, quat_conj(s.prev_rot));
    let keep = ratio * (1.0 - params.angular_damping);
    let turn = select(quat_from_rotvec(quat_to_rotvec(last) * keep), last, keep == 1.0);
    let rot = normalize(quat_mul(turn, s.rot));
    let spin = quat_to_rotvec(turn);

    set_state(i, BodyState(pos, rest, disp, pack_remainder(dropped, pos, (s.pos_low & HELD) | wakes), rot, s.rot));
    vel0[i] = Velocity(vec4<f32>(disp / dt, 0.0), vec4<f32>(spin / dt, 0.0));
    moved();
}
