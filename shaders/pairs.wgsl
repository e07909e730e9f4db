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
// cell within its reach instead (or the whole grid, where that is
// shorter), and owns its pairs with all it finds there but the faster
// bodies (`outranks`); no other walk takes a pair with it. A pair is
// wanted when the two bodies' bounds come within the margin and one of
// them moves: not fixed and awake, or asleep but woken by the last step's
// narrowphase (pair_meta's MOVES). Only the owner decides, alike in both
// walks (the test reads only what these passes do not write). Bodies
// joined by a joint are listed too, and the narrowphase drops their pair
// (see `visit_places`).

// CONTACT_MARGIN (shared with Rust, src/world.rs): the gap (m) kept as
// contact whatever the speed.

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
// grown by their reach) come within CONTACT_MARGIN. The spheres cut the
// corners of the boxes: in a 10k pile of tumbling cubes they cut the
// candidate pairs of the busiest step from 81.9k to 44.6k, and by 8-17%
// once the pile has landed. (Every sum here is
// of one term of each body, so it is the same bits whichever body walks.)
// It takes j's centre, bounds and moves as given (from cell_bounds, or
// from state_in and pair_meta: the same values).
fn wanted_bounds(pos_j: vec3<f32>, bound_j: f32, extent_j: vec3<f32>, moves_j: u32) -> bool {
    let d = walker.pos - pos_j;
    let spheres = walker.bound + bound_j + CONTACT_MARGIN;
    let apart = abs(d) - walker.extent - extent_j;
    return (walker.moves || moves_j == MOVES) && dot(d, d) <= spheres * spheres && all(apart <= vec3<f32>(CONTACT_MARGIN));
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

// Beyond this many rings a fast walker takes the whole grid (the grid has
// fewer than (2 MAX_RINGS + 1)^3).
const MAX_RINGS: f32 = 500.0;

// The walking body, read once: its index, centre, bounds (and the box's
// size), whether it moves and whether it is fast.
struct Walker {
    index: u32,
    pos: vec3<f32>,
    extent: vec3<f32>,
    bound: f32,
    size: f32,
    moves: bool,
    fast: bool,
}

// The walk's state: who walks, whether it writes (pairs_write) or counts
// (pairs_count), where its scratch room starts, and how many pairs it found
// so far.
var<private> walker: Walker;
var<private> writing: bool;
var<private> room_start: u32;
var<private> owned: u32;
// The walk's loop trips so far, as the driver counts them: each trip of
// each loop (cells, places, large bodies), and the trip that ends each
// loop. Where the driver ends an invocation's loops once they reach
// LOOP_TRIPS (lavapipe: 65535, counted over the invocations it runs side
// by side), a long walk may have been cut short, silently: a fast body's
// walk over a grid of about 65 000 bodies or more. `note_long_walks` says
// so in status[STATUS_WALKS_CUT].
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

// Every body of a bucket (its places in the grid order, `first` to `end`)
// whose own cell is c (a bucket may also hold other cells; `any_cell`:
// whatever its cell) that the walk owns a pair with: in the walker's own
// cell (`above` the walker's index; NONE for another cell) those of higher
// index and the sleepers, in a cell behind the walker's (`behind`) the
// sleepers only, in one ahead of it every body, and where the walker or
// the body is fast, as `outranks` says; up to the
// first whose box begins beyond the walker's along x by more than the
// margin: a bucket is sorted by where its boxes begin (grid_sort), so no
// later one can be wanted either. (`wanted_bounds` decides, with its own
// roundings; the stop keeps a slack of 1e-4 m and 1e-5 of the position.)
// The candidates' bounds come from cell_bounds, by their place in the grid
// (grid_sort).
//
// A walk of the whole grid (`any_cell`) visits the grid order at once
// instead, from place `first` to `end`, without the stop (the places
// are sorted along x only within a bucket): the same bodies in the same
// order, in as many loop trips as the grid has bodies, where a loop over
// the buckets took one more for each of them (65 536 in a grid of 16 384
// bodies or more: lavapipe ended such walks part way, see `trips`).
fn visit_places(first: u32, end: u32, c: vec3<i32>, any_cell: bool, above: u32, behind: bool) {
    let stop = walker.pos.x + walker.extent.x + CONTACT_MARGIN + 1e-4 + 1e-5 * abs(walker.pos.x);
    for (var k = first; k < end; k = k + 1u) {
        trips = trips + 1u;
        let cb = cell_bound_of(k);
        if (!any_cell && cb.pos.x - cb.extent.x > stop) {
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
        // (whether the two are joined is the narrowphase's to say: lavapipe
        // entered a loop over the walker's joint ends here at every place,
        // in a branch no lane took as well, and counts a loop it enters
        // against its limit even when it takes no trip: every place cost
        // two counts, and a fast walk was cut after half the grid)
        if (takes && (any_cell || all(cell_of(cb.pos) == c)) && wanted_bounds(cb.pos, cb.bound, cb.extent, moves_j)) {
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
                    grid && is_fast(size, pair_meta[i].moves));
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
    // and behind, or the whole grid order at once (`visit_places`) where
    // that is the shorter walk (a cell costs two trips: its own and the end
    // of its places' loop) or the grid has fewer buckets than it has cells
    let rings = select(1u, rings_of(size), walker.fast);
    let side = 2u * rings + 1u;
    let ahead = (side * side * side - 1u) / 2u;
    let both = walker.fast || (walker.moves && atomicLoad(&status[STATUS_GRID_SLEEPS]) != 0u);
    var cells = select(select(1u + ahead, 1u + 2u * ahead, both), 0u, sleeps || !grid);
    let cube = f32(side) * f32(side) * f32(side);
    let every = walker.fast && (cube >= f32(params.hash_size) || 2.0 * cube >= f32(cell_start[params.hash_size]));
    cells = select(cells, 1u, every);
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
        let h = bucket_of(c);
        let first = select(cell_start[h], 0u, every);
        let end = select(cell_start[h + 1u], cell_start[params.hash_size], every);
        visit_places(first, end, c, every, select(NONE, i, n == 0u), behind);
        trips = trips + 1u; // the places' loop's end
    }
    trips = trips + 2u; // the ends of the cells' loop and the large bodies'
    for (var k = 0u; k < params.large_count; k = k + 1u) {
        trips = trips + 1u;
        let j = large_body(k);
        if ((grid || j > i) && wanted_bounds(state_of(j).pos, pair_meta[j].bound, pair_meta[j].extent, pair_meta[j].moves)) {
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
    if (gid.x < params.body_count) {
        let i = sorted[gid.x];
        // the grid's arrivals are done with: the body list starts empty
        // (`listed_body` in bindings.wgsl; contact_lists fills it)
        sorted[params.body_count + gid.x] = NONE;
        writing = false;
        room_start = gid.x * scratch_room();
        walk(i);
        pair_meta[i].owned = owned;
        note_long_walks();
    }
}

// The loop trips of the workgroup's walks, summed (an integer sum: the same
// whatever the order).
var<workgroup> group_trips: atomic<u32>;

// Sets status[STATUS_WALKS_CUT] if a walk of the workgroup may have been cut short.
// Lavapipe runs 8 invocations side by side (a vector) and counts a loop's
// trips once for them all, as many as the longest takes; nested loops and
// loops one after the other add up. So the trips a vector's loops take
// count at most the sum of its invocations' trips, and at most the sum of
// the workgroup's, which this tests: a ball at 3000 m/s walking the 20 164
// bodies of its grid beside 63 short walks sums to about 21 500, within the
// limit, and is not reported (each walk tested against an eighth of the
// limit, as before, reported it). Each walk adds its trips and tests the
// sum so far: the last to add tests the whole sum, whatever the order.
fn note_long_walks() {
    if (atomicAdd(&group_trips, trips) + trips >= LOOP_TRIPS) {
        atomicStore(&status[STATUS_WALKS_CUT], 1u);
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
