// User input between steps (src/world/input.rs): `apply_inputs`, one thread
// per run of ops on one body (impulses, poses, velocities, fixed/dynamic
// switches), and `explode` and `wind`, one thread per body applying every
// explosion or wind of the op list in order. It binds only
// state_out (the current state, rewritten in place) and its own buffers.
// Verlet's velocity is implicit, so a velocity change rewrites the previous
// pose: v = disp / h and rot * prev_rot^* = exp(w h), h the last substep.

struct InputHeader {
    gravity: vec3<f32>, // settings.gravity (m/s^2)
    substep_dt: f32,    // h, the last substep (s)
    counts: vec4<u32>,  // x = body_count, y = ops in input_ops
}

// One input to one body. 64 bytes. Ops come sorted by body (in call order
// within a body); the first op of each body's run holds the run's length.
struct InputOp {
    body: u32,
    kind: u32, // INPUT_*
    run: u32,  // ops of this body starting here (0: not the first of its run)
    _pad0: u32,
    a: vec4<f32>,
    b: vec4<f32>,
    c: vec4<f32>,
}

// InputOp.kind (the values come from src/world/input.rs, before this file):
// INPUT_IMPULSE: a.xyz = impulse (N s); a.w = 0 at the centre, 1 at world
//   point b.xyz, 2 at body-frame point b.xyz
// INPUT_POSE: a.xyz = position, b = unit orientation; velocities are kept
// INPUT_VELOCITY: a.xyz = linear (m/s), b.xyz = angular (rad/s, world frame)
// INPUT_FIXED: a.x = 1: make fixed; a.x = 0: make dynamic with mass a.y (kg),
//   whose inverse inertia and mass the host worked out as b (a body already
//   dynamic takes it too, keeping its velocities), or if a.y = 0 with the mass
//   kept when it was made fixed (kept_inv_mass), or for a body loaded fixed
//   (none kept) the scene's mass a.z, whose inverse inertia and mass are c
// The explode and wind kernels read their own ops (one per explosion or wind):
// explode: a.xyz = centre (m), a.w = strength, an impulse (N s); b.x = radius
//   (m), b.y = falloff exponent
// wind: a.xyz = wind velocity (m/s), a.w = air density * drag coefficient / 2;
//   b.x = duration (s)

// and bindings.wgsl's state_out (binding 3): the current state buffer
@group(0) @binding(20) var<uniform> input: InputHeader;
@group(0) @binding(21) var<storage, read> input_ops: array<InputOp>;
// the props buffer, writable (switching fixed/dynamic writes it)
@group(0) @binding(22) var<storage, read_write> props_rw: array<BodyProps>;

// World angular velocity the state implies over the substep h.
fn implied_spin(s: BodyState, h: f32) -> vec3<f32> {
    return quat_to_rotvec(quat_mul(s.rot, quat_conj(s.prev_rot))) / h;
}

// The previous orientation that makes the next step turn by w h.
fn prev_rot_for_spin(rot: vec4<f32>, w: vec3<f32>, h: f32) -> vec4<f32> {
    return normalize(quat_mul(quat_conj(quat_from_rotvec(w * h)), rot));
}

// Body-frame principal inverse inertia of the body's shape with mass m.
fn shape_inv_inertia(p: BodyProps, m: f32) -> vec3<f32> {
    let h = p.half_extents.xyz;
    if (p.shape == SHAPE_SPHERE) {
        return vec3<f32>(1.0 / (0.4 * m * h.x * h.x));
    }
    if (p.shape == SHAPE_CAPSULE) {
        // as Shape::inertia_f64: the cylinder, and the caps as one ball
        let r = h.x;
        let cylinder = 2.0 * h.y;
        let ball = 4.0 / 3.0 * r;
        let mc = m * cylinder / (cylinder + ball);
        let ms = m * ball / (cylinder + ball);
        let across = mc * (r * r / 4.0 + h.y * h.y / 3.0) + ms * (0.4 * r * r + h.y * h.y + 0.75 * h.y * r);
        let along = mc * r * r / 2.0 + ms * 0.4 * r * r;
        return vec3<f32>(1.0 / across, 1.0 / along, 1.0 / across);
    }
    let q = h * h;
    return vec3<f32>(3.0 / (m * (q.y + q.z)), 3.0 / (m * (q.x + q.z)), 3.0 / (m * (q.x + q.y)));
}

fn apply_op(op: InputOp, s_in: BodyState, p_in: ptr<function, BodyProps>) -> BodyState {
    var s = s_in;
    let p = *p_in;
    let h = input.substep_dt;
    let fixed = is_fixed(p);
    switch op.kind {
        case INPUT_IMPULSE: {
            if (fixed) {
                return s;
            }
            let j = op.a.xyz;
            s.disp = s.disp + j * (p.inv_inertia.w * h);
            var r = vec3<f32>(0.0);
            if (op.a.w == 1.0) {
                r = op.b.xyz - s.pos;
            } else if (op.a.w == 2.0) {
                r = quat_rotate(s.rot, op.b.xyz);
            }
            let dw = inv_inertia_world(s.rot, p.inv_inertia.xyz, cross(r, j));
            if (any(dw != vec3<f32>(0.0))) {
                s.prev_rot = prev_rot_for_spin(s.rot, implied_spin(s, h) + dw, h);
            }
        }
        case INPUT_POSE: {
            let turn = quat_mul(s.rot, quat_conj(s.prev_rot));
            let q = op.b;
            s.pos = op.a.xyz;
            s.pos_low = s.pos_low & HELD; // the new position is exact
            s.rot = q;
            if (fixed) {
                s.disp = vec3<f32>(0.0);
                s.prev_rot = q;
            } else {
                s.prev_rot = normalize(quat_mul(quat_conj(turn), q));
            }
        }
        case INPUT_VELOCITY: {
            if (fixed) {
                return s;
            }
            // as the scene loader does: the next steps follow x + v t + g t^2 / 2 and
            // the velocity reads back as v (the host adds the half substep of gravity
            // disp / h lags by, for a body no contact pressed)
            let v = op.a.xyz;
            // a kinematic body has no gravity to lag behind
            s.disp = v * h - 0.5 * select(input.gravity, vec3<f32>(0.0), is_kinematic(p)) * (h * h);
            s.pos_low = s.pos_low & ~HELD;
            s.prev_rot = prev_rot_for_spin(s.rot, op.b.xyz, h);
        }
        case INPUT_FIXED: {
            var np = p;
            if (op.a.x == 1.0) {
                if (!fixed) {
                    // kept for a later switch back; none where it is the scene's
                    // mass (c), which that switch falls back to: a body made fixed
                    // and dynamic again, or dynamic and fixed again, is as it was
                    np.kept_inv_mass = select(p.inv_inertia.w, 0.0, p.inv_inertia.w == op.c.w);
                }
                np.flags = p.flags | FLAG_FIXED;
                np.inv_inertia = vec4<f32>(0.0);
                s.disp = vec3<f32>(0.0);
                s.pos_low = s.pos_low | HELD;
                s.prev_rot = s.rot;
            } else if (fixed) {
                // the mass given, else the one kept when made fixed, else the
                // scene's: the host's figures where it has them, so that a body
                // made fixed and dynamic again has its properties back bit for bit
                if (op.a.y > 0.0) {
                    np.inv_inertia = op.b;
                } else if (np.kept_inv_mass > 0.0 && np.kept_inv_mass != op.c.w) {
                    let kept = np.kept_inv_mass;
                    np.inv_inertia = vec4<f32>(shape_inv_inertia(p, 1.0 / kept), kept);
                    if (p.shape == SHAPE_HULL) {
                        // a hull's inertia scales with its mass: the scene's, rescaled
                        np.inv_inertia = vec4<f32>(op.c.xyz * (kept / op.c.w), kept);
                    }
                } else {
                    np.inv_inertia = op.c;
                }
                np.flags = p.flags & ~FLAG_FIXED;
                np.kept_inv_mass = 0.0;
                // at rest, as the scene loader starts a body: x + g t^2 / 2 follows
                s.disp = -0.5 * input.gravity * (h * h);
                s.pos_low = s.pos_low & ~HELD;
                s.prev_rot = s.rot;
            } else if (op.a.y > 0.0) {
                // already dynamic: the mass given, its velocities kept
                np.inv_inertia = op.b;
            }
            *p_in = np;
        }
        default: {}
    }
    return s;
}

@compute @workgroup_size(WORKGROUP)
fn apply_inputs(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if (k >= input.counts.y) {
        return;
    }
    let first = input_ops[k];
    if (first.run == 0u || first.body >= input.counts.x) {
        return;
    }
    let i = first.body;
    var s = out_state(i);
    var p = props_rw[i];
    let p0 = p;
    for (var j = k; j < k + first.run; j = j + 1u) {
        s = apply_op(input_ops[j], s, &p);
    }
    set_state(i, s);
    if (p.flags != p0.flags || any(p.inv_inertia != p0.inv_inertia) || p.kept_inv_mass != p0.kept_inv_mass) {
        props_rw[i] = p;
    }
}

// Every body wakes after any input (`asleep` in bindings.wgsl): run after each input kernel.
@compute @workgroup_size(WORKGROUP)
fn wake_all(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i < input.counts.x && out_state(i).rest_time != 0.0) {
        set_rest_time(i, 0.0);
    }
}

// Radial impulses, one per op in order: op.a.w (N s) on every dynamic body
// within op.b.x of op.a.xyz, scaled by (1 - d / radius) ^ falloff (op.b.y),
// away from the centre (up at the centre). They change velocity only, by
// J / m; a body no explosion reaches is not written.
@compute @workgroup_size(WORKGROUP)
fn explode(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= input.counts.x) {
        return;
    }
    let p = props_rw[i];
    if (is_fixed(p)) {
        return;
    }
    var s = out_state(i);
    var reached = false;
    for (var k = 0u; k < input.counts.y; k = k + 1u) {
        let op = input_ops[k];
        let d = s.pos - op.a.xyz;
        let dist = length(d);
        let radius = op.b.x;
        if (!(dist < radius)) {
            continue;
        }
        var dir = vec3<f32>(0.0, 1.0, 0.0);
        if (dist > 0.0) {
            dir = d / dist;
        }
        let base = 1.0 - dist / radius;
        var scale = 1.0; // pow(x, 0) is undefined at x = 0 in WGSL
        if (op.b.y == 1.0) {
            scale = base;
        } else if (op.b.y != 0.0) {
            scale = pow(base, op.b.y);
        }
        let dv = dir * (op.a.w * scale * p.inv_inertia.w);
        s.disp = s.disp + dv * input.substep_dt;
        reached = true;
    }
    if (reached) {
        set_state(i, s);
    }
}

// Area (m^2) of the body's shape seen along the unit world direction u; a
// hull's, that of the box about its frame's origin that holds it.
fn projected_area(p: BodyProps, rot: vec4<f32>, u: vec3<f32>) -> f32 {
    let h = p.half_extents.xyz;
    if (p.shape == SHAPE_SPHERE) {
        return 3.14159265 * h.x * h.x;
    }
    if (p.shape == SHAPE_CAPSULE) {
        // a disc, and the segment's shadow swept by the radius
        let along = quat_rotate(rot, vec3<f32>(0.0, 1.0, 0.0));
        let c = dot(along, u);
        return 3.14159265 * h.x * h.x + 4.0 * h.x * h.y * sqrt(max(1.0 - c * c, 0.0));
    }
    let l = abs(quat_rotate(quat_conj(rot), u));
    return 4.0 * (h.y * h.z * l.x + h.x * h.z * l.y + h.x * h.y * l.z);
}

// Quadratic drag of uniform winds, one per op in order, each over op.b.x
// seconds: the velocity relative to the wind (op.a.xyz), u, decays as
// du/dt = -k |u| u with k = rho Cd A / 2m (op.a.w = rho Cd / 2), whose exact
// solution over t is u / (1 + k |u| t): never past the wind.
@compute @workgroup_size(WORKGROUP)
fn wind(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= input.counts.x) {
        return;
    }
    let p = props_rw[i];
    if (is_fixed(p)) {
        return;
    }
    var s = out_state(i);
    let h = input.substep_dt;
    var blown = false;
    for (var k = 0u; k < input.counts.y; k = k + 1u) {
        let op = input_ops[k];
        let v = s.disp / h;
        let rel = op.a.xyz - v; // wind relative to the body
        let speed = length(rel);
        if (speed == 0.0) {
            continue;
        }
        let drag = op.a.w * projected_area(p, s.rot, rel / speed) * p.inv_inertia.w;
        let left = rel / (1.0 + drag * speed * op.b.x);
        let dv = rel - left;
        s.disp = s.disp + dv * h;
        blown = true;
    }
    if (blown) {
        set_state(i, s);
    }
}
