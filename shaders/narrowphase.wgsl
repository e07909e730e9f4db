// Pass "narrowphase", once per step before integration: each body gathers its
// own contacts. It walks the 27 grid cells around it (or, for a large moving
// body, every cell its box covers) and the large[] list, and for each partner
// near enough computes the pair's manifold in the canonical order (lower
// index first), so both bodies of a pair store the same points, mirrored.
// Contacts are generated up to a speculative gap (the distance the pair can
// close in one step), so fast bodies meet walls instead of passing them.
// Contacts with the ground come first: a box's corners near it, a sphere's
// lowest point.

// Gap kept as contact whatever the speed (m).
const CONTACT_MARGIN: f32 = 0.02;

var<private> self_index: u32;
var<private> self_count: u32;
var<private> wanted: u32;
// A sleeping body lists only its contacts with awake bodies (pairs of
// sleepers and a sleeper's ground contacts are skipped: neither moves)
// unless one of those awake bodies wakes it (`wakes`: fast, or deep inside);
// then it lists all of them again, since it wakes in this step's first
// substep (integrate's `nudged` decides alike from that list).
var<private> awake_only: bool;
var<private> nudged_by: bool;

fn shape_of(i: u32) -> Shape {
    let s = state_in[i];
    let p = props[i];
    return Shape(s.pos.xyz, s.rot, p.half_extents.xyz, p.kind.x);
}

// How far body i may move in the coming step, all its substeps (m): its last
// displacement, rescaled to this step, plus what gravity adds.
fn reach_of(i: u32) -> f32 {
    let s = state_in[i];
    let steps = f32(params.substeps);
    let ratio = params.dt / params.dt_prev * steps;
    let h = params.dt * steps;
    return length(s.pos.xyz - s.prev_pos.xyz) * ratio + length(params.gravity.xyz) * h * h;
}

// Keeps contact c, whose points are `gap` apart along the normal. A full
// list keeps the closest points: c replaces the kept contact with the widest
// gap if its own is narrower (speculative points go first, touching ones
// stay), and the overflow is reported through `wanted`.
// (The gaps are read back from the list itself: a private array of them
// made this pass twice as slow on lavapipe.)
fn add_contact(c_in: Contact, gap: f32) {
    wanted = wanted + 1u;
    var c = c_in;
    c.gap = gap;
    let first = self_index * MAX_CONTACTS;
    if (self_count < MAX_CONTACTS) {
        contacts[first + self_count] = c;
        self_count = self_count + 1u;
        return;
    }
    var widest = gap;
    var slot = MAX_CONTACTS;
    for (var k = 0u; k < MAX_CONTACTS; k = k + 1u) {
        let g = contacts[first + k].gap;
        if (g > widest) {
            widest = g;
            slot = k;
        }
    }
    if (slot < MAX_CONTACTS) {
        contacts[first + slot] = c;
    }
}

// A box's corners, or a sphere's lowest point, within the margin of the ground.
fn ground_contacts(i: u32, margin: f32) {
    let s = state_in[i];
    let p = props[i];
    let ground = params.gravity.w;
    if (s.pos.y - p.half_extents.w - ground > margin) {
        return;
    }
    var c: Contact;
    c.partner = GROUND;
    c.pushed = 0.0;
    c.normal = vec3<f32>(0.0, 1.0, 0.0);
    if (p.kind.x == SHAPE_SPHERE) {
        let lowest = s.pos.xyz - vec3<f32>(0.0, p.half_extents.x, 0.0);
        c.local_self = quat_rotate(quat_conj(s.rot), lowest - s.pos.xyz);
        c.local_partner = vec3<f32>(lowest.x, ground, lowest.z);
        add_contact(c, lowest.y - ground);
        return;
    }
    for (var k = 0u; k < 8u; k = k + 1u) {
        let corner = vec3<f32>(
            select(-1.0, 1.0, (k & 1u) != 0u),
            select(-1.0, 1.0, (k & 2u) != 0u),
            select(-1.0, 1.0, (k & 4u) != 0u),
        ) * p.half_extents.xyz;
        let w = s.pos.xyz + quat_rotate(s.rot, corner);
        if (w.y - ground <= margin) {
            c.local_self = corner;
            c.local_partner = vec3<f32>(w.x, ground, w.z);
            add_contact(c, w.y - ground);
        }
    }
}

fn world_to_local(i: u32, p: vec3<f32>) -> vec3<f32> {
    let s = state_in[i];
    return quat_rotate(quat_conj(s.rot), p - s.pos.xyz);
}

// Bodies joined by a joint do not collide: the joint holds them together
// where their shapes meet.
fn joined(i: u32, j: u32) -> bool {
    for (var k = joint_start[i]; k < joint_start[i + 1u]; k = k + 1u) {
        if (joint_refs[k].partner == j) {
            return true;
        }
    }
    return false;
}

fn consider(j: u32) {
    let i = self_index;
    if (j == i || joined(i, j)) {
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
    let j_asleep = asleep(state_in[j]);
    if (awake_only && (j_asleep || is_fixed(pj))) {
        return;
    }
    let m = collide(shape_of(lo), shape_of(hi), margin);
    for (var k = 0u; k < m.count; k = k + 1u) {
        let point_gap = dot(m.on_b[k] - m.on_a[k], m.normal);
        nudged_by = nudged_by || wakes(j, point_gap);
        var c: Contact;
        c.partner = j;
        c.pushed = 0.0;
        if (i == lo) {
            c.local_self = world_to_local(i, m.on_a[k]);
            c.local_partner = world_to_local(j, m.on_b[k]);
            c.normal = -m.normal;
        } else {
            c.local_self = world_to_local(i, m.on_b[k]);
            c.local_partner = world_to_local(j, m.on_a[k]);
            c.normal = m.normal;
        }
        add_contact(c, point_gap);
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

// After replacements in a full list a partner's points may lie apart; the
// solve wants each partner's points together (one manifold), so a full list
// is sorted by partner (insertion sort: stable, and only for full lists).
fn regroup(i: u32) {
    let first = i * MAX_CONTACTS;
    for (var k = 1u; k < MAX_CONTACTS; k = k + 1u) {
        let c = contacts[first + k];
        var j = k;
        while (j > 0u && contacts[first + j - 1u].partner > c.partner) {
            contacts[first + j] = contacts[first + j - 1u];
            j = j - 1u;
        }
        contacts[first + j] = c;
    }
}

// Lists body i's contacts: the ground's, then its grid neighbours' and the
// large bodies'.
fn gather(i: u32) {
    let p = props[i];
    let my_reach = reach_of(i);
    if (params.has_ground != 0u && !awake_only) {
        ground_contacts(i, CONTACT_MARGIN + my_reach);
    }
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

@compute @workgroup_size(WORKGROUP)
fn narrowphase(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    self_index = i;
    self_count = 0u;
    wanted = 0u;
    // fixed bodies keep no contacts: they never move
    if (!is_fixed(props[i])) {
        awake_only = asleep(state_in[i]);
        nudged_by = false;
        // one call site (a second would inline the whole pair test again,
        // and lavapipe's compile time grows steeply with kernel size)
        loop {
            gather(i);
            if (!(awake_only && nudged_by)) {
                break;
            }
            awake_only = false;
            self_count = 0u;
            wanted = 0u;
        }
    }
    if (wanted > MAX_CONTACTS) {
        regroup(i);
    }
    contact_count[i] = self_count;
    atomicMax(&status[0], wanted);
    atomicMax(&status[1], wanted);
}
