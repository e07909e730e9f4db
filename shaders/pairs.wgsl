// The pair list, once per step after the grid: every candidate pair once,
// in an order that does not depend on thread timing.
//
//   pairs_count   bodies: walk the body's own grid cell and the 13 cells
//                 ahead of it, and the large bodies; count the pairs it
//                 owns, count each into its partner's incoming pairs
//                 (pair_meta's cursor, an integer atomic: the sum does not
//                 depend on the order), and note each partner in the body's
//                 scratch room (a run of body_pairs by grid order, before
//                 the lists fill it)
//   pairs_scan_*  (grid.wgsl's scan_blocks and scan_sums, SCAN_PAIRS)
//                 prefix sums of the owned and of all pairs within blocks
//                 of bodies (where each body's pairs and its contact list
//                 start), the blocks' offsets, the narrowphase's indirect
//                 dispatch
//   pairs_write   bodies: add the block's offset to the body's starts, set
//                 its cursor to 0 again, and copy its owned pairs from the
//                 scratch room to its place, in the order the walk found
//                 them (a body that owns more than its room holds walks
//                 again)
//
// A body's list (body_pairs from list_start, room for all its pairs) is
// filled later, by the narrowphase, with the pairs that have a manifold,
// and sorted by contact_lists (narrowphase.wgsl).
//
// Who owns a pair (see `walk`): of two grid bodies in neighbouring cells,
// the one whose cell is behind the other's (the other's cell is among its
// 13 cells ahead: +x, or the same x and +y, or the same x and y and +z), so
// each walk visits half the neighbourhood; of two in one cell, the lower
// index; but of a sleeper and a body that moves, the one that moves,
// wherever the sleeper lies (a sleeper walks no cells; where any grid body
// sleeps, the bodies that move also walk the 13 cells behind them for
// sleepers). A grid body owns its pairs with every large body (it always
// walks them all); a large body (kept out of the grid) owns only its pairs
// with large bodies of higher index, so it never walks the cells; every
// body owns its pair with the ground. A pair is wanted when the two
// bodies' bounds come within the margin, they are not joined, and one of
// them moves: not fixed and awake, or asleep but woken by the last step's
// narrowphase (pair_meta's MOVES). Only the owner decides, alike in both
// walks (the test reads only what these passes do not write).

// CONTACT_MARGIN (shared with Rust, src/world.rs): the gap (m) kept as
// contact whatever the speed.

// Bodies joined by a joint do not collide: the joint holds them together
// where their shapes meet. Whether the walker is joined to body j: one of
// its own joint ends (read once, in `walk`) has j for partner. Reading the
// lower index's ends instead made every candidate load two joint starts:
// a fifth of pairs_count in a pile with no joints at all.
fn joined_to_walker(j: u32) -> bool {
    for (var k = walker.joints.x; k < walker.joints.y; k = k + 1u) {
        if (joint_refs[k].partner == j) {
            return true;
        }
    }
    return false;
}

// Gap (m) within which pair (lo, hi) gets contacts: the fixed margin plus
// how much nearer they may come within the coming step: their relative
// displacement over the last substep, rescaled to the step, plus what
// gravity adds (to a body against one that stays) and what each one's turn
// moves its points (PairMeta's spin), and never more than how far both may
// move (PairMeta's reach, which the candidate test, `wanted_bounds`, grows
// the bounds by). Bodies that fall or slide together keep
// their gap: in a 10k pile of falling cubes the busiest step's manifolds
// went from 28.4k to 23.0k, and the contact passes took 7-21% less time
// (the reaches' sum made a speculative contact of every pair of
// neighbours falling side by side).
// (Testing the relative reach in `wanted` too cut the candidate pairs by a
// tenth but made the walks half as slow again: a lane's loads per body
// visited are what they cost.)
fn pair_margin(lo: u32, hi: u32) -> f32 {
    let steps = f32(params.substeps);
    let h = params.dt * steps;
    let relative = length(state_in[lo].disp - state_in[hi].disp) * (params.dt / params.dt_prev * steps)
        + length(params.gravity) * h * h + pair_meta[lo].spin + pair_meta[hi].spin;
    return CONTACT_MARGIN + min(relative, pair_meta[lo].reach + pair_meta[hi].reach);
}

// Whether the walking body and body j (not the walker) form a candidate
// pair: one of them moves, their bounds (bounding spheres and world boxes,
// grown by their reach) come within CONTACT_MARGIN, and they are not
// joined. The spheres cut the corners of the boxes: in a 10k pile of
// tumbling cubes they cut the candidate pairs of the busiest step from
// 81.9k to 44.6k, and by 8-17% once the pile has landed. (Every sum here is
// of one term of each body, so it is the same bits whichever body walks.)
// `wanted_bounds` is all but the joints, on j's centre, bounds and moves
// as given (from cell_bounds, or from state_in and pair_meta: the same
// values).
fn wanted_bounds(pos_j: vec3<f32>, bound_j: f32, extent_j: vec3<f32>, moves_j: u32) -> bool {
    if (!walker.moves && moves_j != MOVES) {
        return false;
    }
    let d = walker.pos - pos_j;
    let spheres = walker.bound + bound_j + CONTACT_MARGIN;
    if (dot(d, d) > spheres * spheres) {
        return false;
    }
    let apart = abs(d) - walker.extent - extent_j;
    return all(apart <= vec3<f32>(CONTACT_MARGIN));
}

// Whether body i is near enough the ground for a ground pair.
fn wants_ground(i: u32) -> bool {
    return params.has_ground != 0u && pair_meta[i].moves == MOVES
        && state_in[i].pos.y - pair_meta[i].extent.y - params.ground_height <= CONTACT_MARGIN;
}

// The walking body, read once: its index, centre, bounds, whether it moves
// and where its joint ends lie in joint_refs (start, end).
struct Walker {
    index: u32,
    pos: vec3<f32>,
    extent: vec3<f32>,
    bound: f32,
    moves: bool,
    joints: vec2<u32>,
}

// The walk's state: who walks, whether it writes (pairs_write) or counts
// (pairs_count), where its scratch room starts, and how many pairs it found
// so far.
var<private> walker: Walker;
var<private> writing: bool;
var<private> room_start: u32;
var<private> owned: u32;

// Partners each body's scratch room holds: body_pairs shared out by grid
// order (the lists have room for every pair twice, so at least twice the
// mean per body).
fn scratch_room() -> u32 {
    return arrayLength(&body_pairs) / max(params.body_count, 1u);
}

// Notes partner j of owned pair number `owned` in the walker's room.
fn note_owned(j: u32) {
    if (owned < scratch_room()) {
        body_pairs[room_start + owned] = j;
    }
}

// Writes owned pair number `owned` of the walker: (a, b) = (walker, j).
fn write_owned(j: u32) {
    let p = pair_meta[walker.index].owned_start + owned;
    if (p < arrayLength(&pairs)) {
        pairs[p] = Pair(walker.index, j);
    }
}

// Body j, whose pair with this body the walk owns, once wanted: written
// (pairs_write), or noted in the room and counted into j's incoming pairs
// (pairs_count).
fn take(j: u32) {
    if (writing) {
        write_owned(j);
    } else {
        atomicAdd(&pair_meta[j].cursor, 1u); // one more incoming pair of j
        note_owned(j);
    }
    owned = owned + 1u;
}

// Every body whose own cell is c (a bucket may also hold other cells) that
// the walk owns a pair with: in the walker's own cell (`above` the
// walker's index; NONE for another cell) those of higher index and the
// sleepers, in a cell behind the walker's (`behind`) the sleepers only,
// in one ahead of it every body; up to the first whose box begins beyond
// the walker's along x by more than the margin: a bucket is sorted by
// where its boxes begin (grid_sort), so no later one can be wanted either.
// (`wanted_bounds` decides, with its own roundings; the stop keeps a
// slack of 1e-4 m and 1e-5 of the position.) The candidates' bounds come
// from cell_bounds, by their place in the grid (grid_sort).
fn visit_cell(c: vec3<i32>, above: u32, behind: bool) {
    let h = bucket_of(c);
    let end = cell_start[h + 1u];
    let stop = walker.pos.x + walker.extent.x + CONTACT_MARGIN + 1e-4 + 1e-5 * abs(walker.pos.x);
    for (var k = cell_start[h]; k < end; k = k + 1u) {
        let cb = cell_bounds[k];
        if (cb.pos.x - cb.extent.x > stop) {
            break;
        }
        let j = cb.body & BODY_BITS;
        let moves_j = cb.body >> MOVES_SHIFT;
        // a cell ahead: every body; the own cell: those of higher index, and
        // of the others the sleepers; a cell behind: the sleepers
        var takes = above == NONE || j > above;
        if (!takes || behind) {
            takes = moves_j == SLEEPS;
        }
        if (takes && all(cell_of(cb.pos) == c) && wanted_bounds(cb.pos, cb.bound, cb.extent, moves_j) && !joined_to_walker(j)) {
            take(j);
        }
    }
}

// The n-th cell a walk visits, as an offset from the walker's own (n = 0):
// the 13 ahead of it (n = 1..13, cell_ahead), then the same 13 behind it,
// mirrored (n = 14..26).
fn walk_cell(n: u32) -> vec3<i32> {
    let behind = n > 13u;
    let c = cell_ahead(select(n, n - 13u, behind));
    return select(c, -c, behind);
}

// Cell n of the 13 ahead of the walker's own (n = 0 is its own): the 9 at
// +x (y, then z, from -1 to 1), the 3 at the same x and +y (z from -1 to
// 1), the one at the same x and y and +z.
fn cell_ahead(n: u32) -> vec3<i32> {
    let m = i32(n) - 1;
    if (n == 0u) {
        return vec3<i32>(0);
    }
    if (n <= 9u) {
        return vec3<i32>(1, m / 3 - 1, m % 3 - 1);
    }
    if (n <= 12u) {
        return vec3<i32>(0, 1, m - 10);
    }
    return vec3<i32>(0, 0, 1);
}

// The ground, then (for a body in the grid) its own cell and the 13 cells
// ahead of it, and the 13 behind it for sleepers where any grid body
// sleeps, then the large bodies it owns pairs with. A sleeper walks no
// cells: pairs of sleepers are not wanted, and a body that moves owns its
// pairs with sleepers wherever they lie (a resting pile of sleepers made
// pairs_count the largest pass of its step, every sleeper walking 14 cells
// for nothing).
fn walk(i: u32) {
    walker = Walker(i, state_in[i].pos, pair_meta[i].extent, pair_meta[i].bound, pair_meta[i].moves == MOVES,
                    vec2<u32>(joint_start[i], joint_start[i + 1u]));
    owned = 0u;
    if (wants_ground(i)) {
        if (writing) {
            write_owned(GROUND);
        } else {
            note_owned(GROUND);
        }
        owned = owned + 1u;
    }
    let grid = in_grid(i);
    let sleeps = pair_meta[i].moves == SLEEPS;
    let cells = select(select(14u, 27u, walker.moves && atomicLoad(&status[11]) != 0u), 0u, sleeps || !grid);
    let centre = cell_of(walker.pos);
    // one loop, one call site: the kernel holds one copy of the cell's walk
    // (lavapipe's compile time grows steeply with a kernel's size)
    for (var n = 0u; n < cells; n = n + 1u) {
        visit_cell(centre + walk_cell(n), select(NONE, i, n == 0u), n > 13u);
    }
    for (var k = 0u; k < params.large_count; k = k + 1u) {
        let j = large_body(k);
        if ((grid || j > i) && wanted_bounds(state_in[j].pos, pair_meta[j].bound, pair_meta[j].extent, pair_meta[j].moves)
            && !joined_to_walker(j)) {
            take(j);
        }
    }
}

// Both walks take the bodies in grid order (sorted: by cell, then the large
// bodies), so the invocations packed into one vector walk the same cells
// and their loops run the same number of times; what each body finds, and
// where it is written, does not depend on which invocation walks it.
@compute @workgroup_size(WORKGROUP)
fn pairs_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.body_count) {
        return;
    }
    let i = sorted[gid.x];
    writing = false;
    room_start = gid.x * scratch_room();
    walk(i);
    pair_meta[i].owned = owned;
}

@compute @workgroup_size(WORKGROUP)
fn pairs_write(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x >= params.body_count) {
        return;
    }
    let i = sorted[gid.x];
    // the scan left the body's starts within its block of SCAN_SPAN
    // bodies: add the block's offset; the narrowphase lists contacts by the
    // cursor from 0
    let offset = block_sums[i / SCAN_SPAN];
    pair_meta[i].owned_start = pair_meta[i].owned_start + offset.x;
    pair_meta[i].list_start = pair_meta[i].list_start + offset.y;
    atomicStore(&pair_meta[i].cursor, 0u);
    let count = pair_meta[i].owned;
    if (count > scratch_room()) {
        writing = true;
        walk(i);
        return;
    }
    let start = gid.x * scratch_room();
    let first = pair_meta[i].owned_start;
    for (var k = 0u; k < count; k = k + 1u) {
        if (first + k < arrayLength(&pairs)) {
            pairs[first + k] = Pair(i, body_pairs[start + k]);
        }
    }
}
