// Contact points of one body against the ground plane y = params.gravity.w.
// A box touches with its corners, a sphere with its lowest point.

// Points closer than this to the ground (m) still count as touching when
// restitution is decided after the solve.
const CONTACT_SLOP: f32 = 0.002;

fn ground_point_count(p: BodyProps) -> u32 {
    if (p.kind.x == SHAPE_SPHERE) {
        return 1u;
    }
    return 8u;
}

// Offset from the centre of mass to contact point k, in world axes.
fn ground_point_offset(p: BodyProps, rot: vec4<f32>, k: u32) -> vec3<f32> {
    if (p.kind.x == SHAPE_SPHERE) {
        return vec3<f32>(0.0, -p.half_extents.x, 0.0);
    }
    let sign = vec3<f32>(
        select(-1.0, 1.0, (k & 1u) != 0u),
        select(-1.0, 1.0, (k & 2u) != 0u),
        select(-1.0, 1.0, (k & 4u) != 0u),
    );
    return quat_rotate(rot, sign * p.half_extents.xyz);
}

// Generalised inverse mass of a body for a unit push along dir at offset r.
fn effective_inv_mass(p: BodyProps, rot: vec4<f32>, r: vec3<f32>, dir: vec3<f32>) -> f32 {
    let rn = cross(r, dir);
    return p.inv_inertia.w + dot(rn, inv_inertia_world(rot, p.inv_inertia.xyz, rn));
}
