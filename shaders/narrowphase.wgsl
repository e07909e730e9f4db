// Pass "narrowphase", once per step before integration: each body gathers its
// own contacts. It walks the 27 grid cells around it (or, for a large moving
// body, every cell its box covers) and the large[] list, and for each partner
// near enough computes the pair's manifold in the canonical order (lower
// index first), so both bodies of a pair store the same points, mirrored.
// Contacts are generated up to a speculative gap (the distance the pair can
// close in one step), so fast bodies meet walls instead of passing them.

// Gap kept as contact whatever the speed (m).
const CONTACT_MARGIN: f32 = 0.02;

var<private> self_index: u32;
var<private> self_count: u32;
var<private> wanted: u32;

fn shape_of(i: u32) -> Shape {
    let s = state_in[i];
    let p = props[i];
    return Shape(s.pos.xyz, s.rot, p.half_extents.xyz, p.kind.x);
}

// How far body i may move in the coming step (m): its last displacement,
// rescaled to this dt, plus what gravity adds.
fn reach_of(i: u32) -> f32 {
    let s = state_in[i];
    let ratio = params.dt / params.dt_prev;
    return length(s.pos.xyz - s.prev_pos.xyz) * ratio + length(params.gravity.xyz) * params.dt * params.dt;
}

fn world_to_local(i: u32, p: vec3<f32>) -> vec3<f32> {
    let s = state_in[i];
    return quat_rotate(quat_conj(s.rot), p - s.pos.xyz);
}

fn consider(j: u32) {
    let i = self_index;
    if (j == i) {
        return;
    }
    let pi = props[i];
    let pj = props[j];
    if (is_fixed(pi) && is_fixed(pj)) {
        return;
    }
    // computed in the pair's canonical order, so both bodies decide alike
    let lo = min(i, j);
    let hi = max(i, j);
    let margin = CONTACT_MARGIN + reach_of(lo) + reach_of(hi);
    let gap = distance(state_in[lo].pos.xyz, state_in[hi].pos.xyz) - props[lo].half_extents.w - props[hi].half_extents.w;
    if (gap > margin) {
        return;
    }
    let m = collide(shape_of(lo), shape_of(hi), margin);
    for (var k = 0u; k < m.count; k = k + 1u) {
        wanted = wanted + 1u;
        if (self_count >= MAX_CONTACTS) {
            continue;
        }
        var c: Contact;
        c.partner = j;
        if (i == lo) {
            c.local_self = world_to_local(i, m.on_a[k]);
            c.local_partner = world_to_local(j, m.on_b[k]);
            c.normal = -m.normal;
        } else {
            c.local_self = world_to_local(i, m.on_b[k]);
            c.local_partner = world_to_local(j, m.on_a[k]);
            c.normal = m.normal;
        }
        contacts[i * MAX_CONTACTS + self_count] = c;
        self_count = self_count + 1u;
    }
}

// Every body whose own cell is c (a bucket may also hold other cells).
fn consider_cell(c: vec3<i32>) {
    let h = bucket_of(c);
    let end = cell_start[h + 1u];
    for (var k = cell_start[h]; k < end; k = k + 1u) {
        let j = sorted[k];
        if (all(cell_of(state_in[j].pos.xyz) == c)) {
            consider(j);
        }
    }
}

// Cells a large moving body scans, at most, per axis: beyond it the body
// only meets the bodies of the cells nearest its centre.
const MAX_SCAN_CELLS: i32 = 32;

@compute @workgroup_size(WORKGROUP)
fn narrowphase(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    self_index = i;
    self_count = 0u;
    wanted = 0u;
    let p = props[i];
    // fixed bodies keep no contacts: they never move
    if (!is_fixed(p)) {
        let my_reach = reach_of(i);
        let centre = state_in[i].pos.xyz;
        var lo = cell_of(centre) - vec3<i32>(1);
        var hi = cell_of(centre) + vec3<i32>(1);
        if (!in_grid(i)) {
            let r = vec3<f32>(p.half_extents.w + my_reach + params.speculative);
            lo = max(cell_of(centre - r), cell_of(centre) - vec3<i32>(MAX_SCAN_CELLS));
            hi = min(cell_of(centre + r), cell_of(centre) + vec3<i32>(MAX_SCAN_CELLS));
        }
        for (var x = lo.x; x <= hi.x; x = x + 1) {
            for (var y = lo.y; y <= hi.y; y = y + 1) {
                for (var z = lo.z; z <= hi.z; z = z + 1) {
                    consider_cell(vec3<i32>(x, y, z));
                }
            }
        }
        for (var k = 0u; k < params.large_count; k = k + 1u) {
            consider(large[k]);
        }
    }
    contact_count[i] = self_count;
    atomicMax(&status[0], wanted);
    atomicMax(&status[1], wanted);
}
