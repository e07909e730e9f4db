// The pair list, once per step after the grid: every candidate pair once,
// in an order that does not depend on thread timing.
//
//   pairs_count   bodies: walk the grid around the body; count the pairs it
//                 owns (the partner's index is higher, or the partner is the
//                 ground) and the pairs it is in
//   scan_*        (grid.wgsl, SCAN_PAIRS) prefix sums of both counts, and the
//                 narrowphase's indirect dispatch
//   pairs_write   bodies: walk again; write the owned pairs at the body's
//                 offset, list each in both bodies' pair lists (an owned
//                 pair at its rank, an incoming one by the partner's cursor)
//   pairs_sort    bodies: sort the incoming part of the body's list by pair
//                 index (the cursor's order depends on thread timing)
//
// A body's list is its incoming pairs (lower pair indices), then its owned
// ones, so sorted it is in pair order: the solve sums in that order, the
// same every run. A pair is wanted when its bounding spheres come within
// the speculative margin, the two are not joined, and one of them moves:
// not fixed and awake, or asleep but woken by the last step's narrowphase.
// Both bodies of a pair decide alike (the test reads only what this pass
// does not write), so counts and lists agree.

// Gap kept as contact whatever the speed (m).
const CONTACT_MARGIN: f32 = 0.02;

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

// Gap (m) within which pair (lo, hi) gets contacts: the fixed margin plus
// how far both may move.
fn pair_margin(lo: u32, hi: u32) -> f32 {
    return CONTACT_MARGIN + pair_meta[lo].reach + pair_meta[hi].reach;
}

// Whether bodies i and j (i != j) form a candidate pair: one of them moves,
// their bounds (grown by their reach) come within CONTACT_MARGIN, and they
// are not joined. Symmetric, and it reads only what grid_count wrote.
fn wanted(i: u32, j: u32) -> bool {
    let lo = min(i, j);
    let hi = max(i, j);
    if (pair_meta[lo].moves == 0u && pair_meta[hi].moves == 0u) {
        return false;
    }
    let apart = abs(state_in[lo].pos.xyz - state_in[hi].pos.xyz) - pair_meta[lo].extent - pair_meta[hi].extent;
    return all(apart <= vec3<f32>(CONTACT_MARGIN)) && !joined(lo, hi);
}

// Whether body i is near enough the ground for a ground pair.
fn wants_ground(i: u32) -> bool {
    return params.has_ground != 0u && pair_meta[i].moves != 0u
        && state_in[i].pos.y - pair_meta[i].extent.y - params.gravity.w <= CONTACT_MARGIN;
}

// The walk's state: which body walks, whether it writes (pairs_write) or
// counts (pairs_count), and what it found so far.
var<private> self_index: u32;
var<private> writing: bool;
var<private> owned: u32;
var<private> incoming: u32;

// Lists owned pair number `owned` of this body: (a, b) = (self_index, j).
fn write_owned(j: u32) {
    let i = self_index;
    let owned_start = pair_meta[i].owned_start;
    let p = owned_start + owned;
    let list_incoming = pair_meta[i + 1u].list_start - pair_meta[i].list_start
        - (pair_meta[i + 1u].owned_start - owned_start);
    var entry = NONE;
    if (p < arrayLength(&pairs)) {
        pairs[p] = Pair(i, j, NONE);
        entry = p;
    }
    list_put(pair_meta[i].list_start + list_incoming + owned, entry);
    if (j != GROUND) {
        list_put(pair_meta[j].list_start + atomicAdd(&pair_meta[j].cursor, 1u), entry);
    }
}

// A pair list entry, unless the lists are full (the pairs are then reported
// too many; see status[0]).
fn list_put(k: u32, entry: u32) {
    if (k < arrayLength(&body_pairs)) {
        body_pairs[k] = entry;
    }
}

fn visit(j: u32) {
    let i = self_index;
    if (j == i || !wanted(i, j)) {
        return;
    }
    if (j > i) {
        if (writing) {
            write_owned(j);
        }
        owned = owned + 1u;
    } else {
        incoming = incoming + 1u;
    }
}

// Every body whose own cell is c (a bucket may also hold other cells).
fn visit_cell(c: vec3<i32>) {
    let h = bucket_of(c);
    let end = cell_start[h + 1u];
    for (var k = cell_start[h]; k < end; k = k + 1u) {
        let j = sorted[k];
        if (all(cell_of(state_in[j].pos.xyz) == c)) {
            visit(j);
        }
    }
}

// Cells a large moving body scans, at most, per axis: beyond it the body
// only meets the bodies of the cells nearest its centre.
const MAX_SCAN_CELLS: i32 = 32;

// The ground, then the grid cells around body i (for a body too large for
// the grid, every cell its reach covers) and the large bodies.
fn walk(i: u32) {
    self_index = i;
    owned = 0u;
    incoming = 0u;
    if (wants_ground(i)) {
        if (writing) {
            write_owned(GROUND);
        }
        owned = owned + 1u;
    }
    let centre = state_in[i].pos.xyz;
    var lo = cell_of(centre) - vec3<i32>(1);
    var hi = cell_of(centre) + vec3<i32>(1);
    if (!in_grid(i)) {
        let r = pair_meta[i].extent + vec3<f32>(params.speculative);
        lo = max(cell_of(centre - r), cell_of(centre) - vec3<i32>(MAX_SCAN_CELLS));
        hi = min(cell_of(centre + r), cell_of(centre) + vec3<i32>(MAX_SCAN_CELLS));
    }
    for (var x = lo.x; x <= hi.x; x = x + 1) {
        for (var y = lo.y; y <= hi.y; y = y + 1) {
            for (var z = lo.z; z <= hi.z; z = z + 1) {
                visit_cell(vec3<i32>(x, y, z));
            }
        }
    }
    for (var k = 0u; k < params.large_count; k = k + 1u) {
        visit(large[k]);
    }
}

@compute @workgroup_size(WORKGROUP)
fn pairs_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    writing = false;
    walk(i);
    pair_meta[i].owned = owned;
    pair_meta[i].total = owned + incoming;
    atomicStore(&pair_meta[i].cursor, 0u);
}

@compute @workgroup_size(WORKGROUP)
fn pairs_write(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    writing = true;
    walk(i);
}

@compute @workgroup_size(WORKGROUP)
fn pairs_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    let start = pair_meta[i].list_start;
    let end = min(start + atomicLoad(&pair_meta[i].cursor), arrayLength(&body_pairs));
    for (var k = start + 1u; k < end; k = k + 1u) {
        let v = body_pairs[k];
        var m = k;
        while (m > start && body_pairs[m - 1u] > v) {
            body_pairs[m] = body_pairs[m - 1u];
            m = m - 1u;
        }
        body_pairs[m] = v;
    }
}
