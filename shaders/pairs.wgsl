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
// body owns its pair with the ground. A fast body (`is_fast`) walks every
// cell within its reach instead, and owns its pairs with all it finds
// there but the faster bodies (`outranks`); no other walk takes a pair
// with it. A pair is wanted when the two bodies' bounds come within the
// margin, they are not joined, and one of them moves: not fixed and awake,
// or asleep but woken by the last step's narrowphase (pair_meta's MOVES).
// Only the owner decides, alike in both walks (the test reads only what
// these passes do not write).

// CONTACT_MARGIN (shared with Rust, src/world.rs): the gap (m) kept as
// contact whatever the speed.

// Bodies joined by a joint do not collide: the joint holds them together
// where their shapes meet. Whether the walker is joined to body j: one of
// its own joint ends (read once, in `walk`) has j for partner. Reading the
// lower index's ends instead made every candidate load two joint starts:
// a fifth of pairs_count in a pile with no joints at all.
fn joined_to_walker(j: u32) -> bool {
    for (var k = walker.joints.x; k < walker.joints.y; k = k + 1u) {
        trips = trips + 1u;
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
    let relative = length(state_of(lo).disp - state_of(hi).disp) * (params.dt / params.dt_prev * steps)
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
        && state_of(i).pos.y - pair_meta[i].extent.y - params.ground_height <= CONTACT_MARGIN;
}

// Whether the walker owns its pair with body j (box size `size_j`) when one
// of them is fast: the larger box owns it (a fast body's walk covers any
// partner with a box no larger than its own), then the lower index.
fn outranks(j: u32, size_j: f32) -> bool {
    return walker.size > size_j || (walker.size == size_j && walker.index < j);
}

// How many cells out a fast walker looks along each axis: its pairs are
// with boxes no larger than its own, so within twice its size and the
// margin of its centre.
fn rings_of(size: f32) -> u32 {
    return u32(ceil(clamp((2.0 * size + CONTACT_MARGIN) / params.cell_size * 1.001, 1.0, MAX_RINGS)));
}

// Beyond this many rings a fast walker visits every bucket (the grid has
// fewer than (2 MAX_RINGS + 1)^3).
const MAX_RINGS: f32 = 500.0;

// The walking body, read once: its index, centre, bounds (and the box's
// size), whether it moves, whether it is fast and where its joint ends lie
// in joint_refs (start, end).
struct Walker {
    index: u32,
    pos: vec3<f32>,
    extent: vec3<f32>,
    bound: f32,
    size: f32,
    moves: bool,
    fast: bool,
    joints: vec2<u32>,
}

// The walk's state: who walks, whether it writes (pairs_write) or counts
// (pairs_count), where its scratch room starts, and how many pairs it found
// so far.
var<private> walker: Walker;
var<private> writing: bool;
var<private> room_start: u32;
var<private> owned: u32;
// The walk's loop trips so far (cells, candidates, large bodies, joint
// ends). Where the driver ends an invocation's loops past LOOP_TRIPS
// (lavapipe: 65535, summed over the 8 invocations it runs side by side), a
// walk of more than an eighth of that may have been cut short, silently: a
// fast body's walk in a large grid (every bucket), or a body with
// thousands of joints. `note_long_walk` says so in status[20].
var<private> trips: u32;

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

// Every body of bucket h whose own cell is c (a bucket may also hold
// other cells; `any_cell`: whatever its cell) that the walk owns a pair
// with: in the walker's own cell (`above` the walker's index; NONE for
// another cell) those of higher index and the sleepers, in a cell behind
// the walker's (`behind`) the sleepers only, in one ahead of it every body,
// and where the walker or the body is fast, as `outranks` says; up to the
// first whose box begins beyond the walker's along x by more than the
// margin: a bucket is sorted by where its boxes begin (grid_sort), so no
// later one can be wanted either. (`wanted_bounds` decides, with its own
// roundings; the stop keeps a slack of 1e-4 m and 1e-5 of the position.)
// The candidates' bounds come from cell_bounds, by their place in the grid
// (grid_sort).
fn visit_bucket(h: u32, c: vec3<i32>, any_cell: bool, above: u32, behind: bool) {
    let end = cell_start[h + 1u];
    let stop = walker.pos.x + walker.extent.x + CONTACT_MARGIN + 1e-4 + 1e-5 * abs(walker.pos.x);
    for (var k = cell_start[h]; k < end; k = k + 1u) {
        trips = trips + 1u;
        let cb = cell_bound_of(k);
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
        if (walker.fast || (cb.body & FAST_BODY) != 0u) {
            takes = j != walker.index && outranks(j, box_size(cb.extent));
        }
        if (takes && (any_cell || all(cell_of(cb.pos) == c)) && wanted_bounds(cb.pos, cb.bound, cb.extent, moves_j) && !joined_to_walker(j)) {
            take(j);
        }
    }
}

// The m-th cell ahead of the walker's (m from 1; after `o`, the one
// before it), as an offset from the walker's, for a walk `rings` cells
// out: those at +x (x from 1, then y, then z, each from -rings), then
// those at the same x and +y, then those at the same x and y and +z. One
// ring out these are the 13 cells ahead (9 + 3 + 1); mirrored, they are
// the 13 behind. (Stepping from the cell before instead of working the
// cell out from m: a division by a number not known when the kernel is
// compiled is eight divisions on lavapipe.)
fn next_cell(o: vec3<i32>, m: u32, rings: u32) -> vec3<i32> {
    let r = i32(rings);
    let side = 2u * rings + 1u;
    let plus_x = rings * side * side;
    let plus_y = rings * side;
    if (m == 1u) {
        return vec3<i32>(1, -r, -r);
    }
    if (m == 1u + plus_x) {
        return vec3<i32>(0, 1, -r);
    }
    if (m == 1u + plus_x + plus_y) {
        return vec3<i32>(0, 0, 1);
    }
    var c = o + vec3<i32>(0, 0, 1);
    if (c.z > r) {
        c = vec3<i32>(c.x, c.y + 1, -r);
    }
    if (c.y > r) {
        c = vec3<i32>(c.x + 1, -r, c.z);
    }
    return c;
}

// The ground, then (for a body in the grid) its own cell and the 13 cells
// ahead of it, and the 13 behind it for sleepers where any grid body
// sleeps (a fast body: every cell within its reach), then the large
// bodies it owns pairs with. A sleeper walks no cells: pairs of sleepers
// are not wanted, and a body that moves owns its pairs with sleepers
// wherever they lie (a resting pile of sleepers made pairs_count the
// largest pass of its step, every sleeper walking 14 cells for nothing).
fn walk(i: u32) {
    let extent = pair_meta[i].extent;
    let size = box_size(extent);
    let grid = in_grid(i);
    let sleeps = pair_meta[i].moves == SLEEPS;
    walker = Walker(i, state_of(i).pos, extent, pair_meta[i].bound, size, pair_meta[i].moves == MOVES,
                    grid && is_fast(size, pair_meta[i].moves), vec2<u32>(joint_start[i], joint_start[i + 1u]));
    owned = 0u;
    trips = 0u;
    if (wants_ground(i)) {
        if (writing) {
            write_owned(GROUND);
        } else {
            note_owned(GROUND);
        }
        owned = owned + 1u;
    }
    // one ring out: the own cell and the 13 ahead (and the 13 behind for
    // sleepers); a fast walker: the own cell and the cubes' halves ahead
    // and behind, or every bucket when the grid has fewer
    let rings = select(1u, rings_of(size), walker.fast);
    let side = 2u * rings + 1u;
    let ahead = (side * side * side - 1u) / 2u;
    let both = walker.fast || (walker.moves && atomicLoad(&status[11]) != 0u);
    var cells = select(select(1u + ahead, 1u + 2u * ahead, both), 0u, sleeps || !grid);
    let every = walker.fast && f32(side) * f32(side) * f32(side) >= f32(params.hash_size);
    cells = select(cells, params.hash_size, every);
    let centre = cell_of(walker.pos);
    // one loop, one call site: the kernel holds one copy of the cell's walk
    // (lavapipe's compile time grows steeply with a kernel's size)
    var o = vec3<i32>(0);
    for (var n = 0u; n < cells; n = n + 1u) {
        trips = trips + 1u;
        // the own cell, the cells ahead, then the same cells behind
        let behind = n > ahead;
        if (n != 0u) {
            o = next_cell(o, select(n, n - ahead, behind), rings);
        }
        let c = centre + select(o, -o, behind);
        visit_bucket(select(bucket_of(c), n, every), c, every, select(NONE, i, n == 0u), behind);
    }
    for (var k = 0u; k < params.large_count; k = k + 1u) {
        trips = trips + 1u;
        let j = large_body(k);
        if ((grid || j > i) && wanted_bounds(state_of(j).pos, pair_meta[j].bound, pair_meta[j].extent, pair_meta[j].moves)
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
    // the grid's arrivals are done with: the body list starts empty
    // (`listed_body` in bindings.wgsl; contact_lists fills it)
    sorted[params.body_count + gid.x] = NONE;
    writing = false;
    room_start = gid.x * scratch_room();
    walk(i);
    note_long_walk();
    pair_meta[i].owned = owned;
}

// Sets status[20] if this walk may have been cut short (see `trips`).
fn note_long_walk() {
    if (trips > LOOP_TRIPS / 8u) {
        atomicStore(&status[20], 1u);
    }
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
