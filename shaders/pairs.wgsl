// The pair list, once per step after the grid: every candidate pair once, in
// an order that does not depend on thread timing.
//   pairs_count   per body, in grid order: walk the own cell, the 13 cells
//                 ahead and the large bodies; count the pairs it owns, count
//                 each into its partner's cursor (an integer atomic) and note
//                 the partners in the body's scratch room of body_pairs
//   pairs_scan_*  grid.wgsl's scan with SCAN_PAIRS: where each body's owned
//                 pairs and contact list start; the narrowphase's dispatch
//   pairs_write   per body: add its block's offset, copy its owned pairs from
//                 the room to their place (walk again if the room overflowed)
// Who owns a pair: of grid bodies in neighbouring cells, the one behind (the
// other's cell among its 13 ahead); in one cell, the lower index; of a sleeper
// and a body that moves, the mover (sleepers walk no cells); of a grid and a
// large body, the grid body; a fast body (`is_fast`) owns all it finds but
// faster ones (`outranks`). Joined bodies are listed; the narrowphase drops them.

// CONTACT_MARGIN (src/limits.rs): the gap (m) kept as contact whatever the speed.

// Gap (m) within which pair (lo, hi) gets contacts: the fixed margin plus how
// much nearer they may come in the coming step (relative displacement,
// gravity, each one's turn: PairMeta's spin), at most both reaches, so bodies
// falling or sliding together keep no speculative contact.
fn pair_margin(lo: u32, hi: u32) -> f32 {
    let steps = f32(params.substeps);
    let h = params.dt * steps;
    let relative = length(state_of(lo).disp - state_of(hi).disp) * (params.dt / params.dt_prev * steps)
        + length(params.gravity) * h * h + pair_meta[lo].spin + pair_meta[hi].spin;
    return CONTACT_MARGIN + min(relative, pair_meta[lo].reach + pair_meta[hi].reach);
}

// Whether the walker and body j come within `margin`: one of them moves and
// their bounding spheres and grown world boxes come that near (the spheres
// cut the boxes' corners). Every sum takes one term of each body, so either
// walk gets the same bits; j's values come from cell_bounds or state.
fn bounds_within(pos_j: vec3<f32>, bound_j: f32, extent_j: vec3<f32>, moves_j: u32, margin: f32) -> bool {
    let d = walker.pos - pos_j;
    let spheres = walker.bound + bound_j + margin;
    let apart = abs(d) - walker.extent - extent_j;
    return (walker.moves || moves_j == MOVES) && dot(d, d) <= spheres * spheres && all(apart <= vec3<f32>(margin));
}

// Whether the walker and body j form a candidate pair: within CONTACT_MARGIN.
fn wanted_bounds(pos_j: vec3<f32>, bound_j: f32, extent_j: vec3<f32>, moves_j: u32) -> bool {
    return bounds_within(pos_j, bound_j, extent_j, moves_j, CONTACT_MARGIN);
}

// Whether this walk looks for pairs near, within keep_margin() more than it
// lists (`pairs_kept`): only where the last walks listed none; after any,
// the list is not kept (pairs_count says so).
var<private> testing_near: bool;

// Notes that this step's walks found a pair near.
fn note_near() {
    if (atomicLoad(&status[STATUS_NEAR_NOW]) == 0u) {
        atomicStore(&status[STATUS_NEAR_NOW], 1u);
    }
}

// Whether body i, its bounds centred at `centre`, moves and comes within `margin` of the ground.
fn ground_within(i: u32, centre: vec3<f32>, margin: f32) -> bool {
    return params.has_ground != 0u && pair_meta[i].moves == MOVES
        && centre.y - pair_meta[i].extent.y - params.ground_height <= margin;
}

// Whether body i, its bounds centred at `centre`, is near enough the ground for a ground pair.
fn wants_ground(i: u32, centre: vec3<f32>) -> bool {
    return ground_within(i, centre, CONTACT_MARGIN);
}

// Whether the walker owns its pair with body j (box size `size_j`) when one is
// fast: the larger box (a fast walk covers partners no larger), then the lower index.
fn outranks(j: u32, size_j: f32) -> bool {
    return walker.size > size_j || (walker.size == size_j && walker.index < j);
}

// Cells out a fast walker looks along each axis: twice its size and the margin.
fn rings_of(size: f32) -> u32 {
    return u32(ceil(clamp((2.0 * size + CONTACT_MARGIN) / params.cell_size * 1.001, 1.0, MAX_RINGS)));
}

// Beyond this many rings a fast walker takes the whole grid.
const MAX_RINGS: f32 = 500.0;

// The walking body, read once.
struct Walker {
    index: u32,
    pos: vec3<f32>,
    extent: vec3<f32>,
    bound: f32,
    size: f32,
    moves: bool,
    fast: bool,
}

// The walk's state: who walks, whether it writes or counts, its room, pairs so far.
var<private> walker: Walker;
var<private> writing: bool;
var<private> room_start: u32;
var<private> owned: u32;
// The walk's loop trips so far, as the driver counts them (every trip, and the
// one that ends each loop): lavapipe silently ends an invocation's loops at
// LOOP_TRIPS, so a very long walk may have been cut; `note_long_walks` says
// so in status[STATUS_WALKS_CUT].
var<private> trips: u32;

// Partners each body's scratch room holds: body_pairs shared out by grid order
// (the lists have room for every pair twice, so at least twice the mean).
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

// Body j, whose pair with the walker is wanted and owned: written (pairs_write),
// or noted in the room and counted into j's incoming pairs (pairs_count).
fn take(j: u32) {
    if (writing) {
        write_owned(j);
    } else {
        atomicAdd(&pair_meta[j].cursor, 1u); // one more incoming pair of j
        note_owned(j);
    }
    owned = owned + 1u;
}

// Every body at places `first` to `end` of the grid order whose cell is c
// (`any_cell`: any) that the walker owns a pair with: in its own cell (`above`
// its index; NONE elsewhere) those of higher index and the sleepers, in a cell
// behind the sleepers, ahead all, fast ones as `outranks` says. A bucket is
// sorted along x (grid_sort), so the walk stops at the first box beyond reach
// (with slack for rounding); a walk of the whole grid order has no stop.
fn visit_places(first: u32, end: u32, c: vec3<i32>, any_cell: bool, above: u32, behind: bool) {
    // (the near pairs' reach too where they are looked for: the pairs taken are the same)
    let stop = walker.pos.x + walker.extent.x + CONTACT_MARGIN + select(0.0, keep_margin(), testing_near) + 1e-4
        + 1e-5 * abs(walker.pos.x);
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
        // (whether the two are joined is the narrowphase's to say: a loop over
        // joint ends here cost loop trips at every place)
        if (takes && (any_cell || all(cell_of(cb.pos) == c))) {
            if (wanted_bounds(cb.pos, cb.bound, cb.extent, moves_j)) {
                take(j);
            }
            if (testing_near && bounds_within(cb.pos, cb.bound, cb.extent, moves_j, CONTACT_MARGIN + keep_margin())) {
                note_near();
            }
        }
    }
}

// The m-th cell ahead of the walker's (m from 1; `o` the one before it), as an
// offset, for a walk `rings` out: those at +x, then at the same x and +y, then
// at the same x and y and +z (one ring out: the 13 ahead; mirrored, the 13
// behind). Stepped from the cell before: a division by a value unknown at
// compile time is eight divisions on lavapipe.
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

// The ground, then (a grid body) its own cell and the 13 ahead, and the 13
// behind for sleepers where any grid body sleeps (a fast body: every cell
// within its reach), then the large bodies it owns pairs with. A sleeper walks
// no cells: the bodies that move own its pairs.
fn walk(i: u32) {
    let extent = pair_meta[i].extent;
    let size = box_size(extent);
    let grid = in_grid(i);
    let sleeps = pair_meta[i].moves == SLEEPS;
    var centre_i = state_of(i).pos;
    if (!grid) {
        centre_i = large_centre(i);
    }
    walker = Walker(i, centre_i, extent, pair_meta[i].bound, size, pair_meta[i].moves == MOVES,
                    grid && is_fast(size, pair_meta[i].moves));
    owned = 0u;
    trips = 0u;
    // a fast walker, or a body near the ground, keeps the list from being kept
    if (testing_near && (walker.fast || ground_within(i, walker.pos, CONTACT_MARGIN + keep_margin()))) {
        note_near();
    }
    if (wants_ground(i, walker.pos)) {
        if (writing) {
            write_owned(GROUND);
        } else {
            note_owned(GROUND);
        }
        owned = owned + 1u;
    }
    // a fast walker walks the cells within its reach, or the whole grid order
    // at once (`visit_places`) where that is shorter (a cell costs two trips)
    // or the grid has fewer buckets than that has cells
    let rings = select(1u, rings_of(size), walker.fast);
    let side = 2u * rings + 1u;
    let ahead = (side * side * side - 1u) / 2u;
    let both = walker.fast || (walker.moves && atomicLoad(&status[STATUS_GRID_SLEEPS]) != 0u);
    var cells = select(select(1u + ahead, 1u + 2u * ahead, both), 0u, sleeps || !grid);
    let cube = f32(side) * f32(side) * f32(side);
    let every = walker.fast && (cube >= f32(params.hash_size) || 2.0 * cube >= f32(cell_start[params.hash_size]));
    cells = select(cells, 1u, every);
    let centre = cell_of(walker.pos);
    // one loop, one call site: one copy of the cell's walk in the kernel
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
        let cb = cell_bound_of(params.body_count - params.large_count + k);
        if ((grid || j > i) && wanted_bounds(cb.pos, cb.bound, cb.extent, cb.body >> MOVES_SHIFT)) {
            take(j);
        }
    }
}

// Both walks take the bodies in grid order, so the invocations of one vector
// walk the same cells and their loops run alike; what each body finds, and
// where it goes, does not depend on which invocation walks it.
@compute @workgroup_size(WORKGROUP)
fn pairs_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    // (grid_count has decided: `walk` stands until contact_lists)
    let kept = pairs_kept();
    if (gid.x == 0u) {
        atomicStore(&status[STATUS_KEPT], u32(kept));
        if (!kept) {
            // contact_lists lists the bodies anew and counts their workgroups
            atomicStore(&status[STATUS_LISTED], 0u);
            atomicStore(&status[STATUS_LISTED_DISPATCH], 0u);
            atomicStore(&status[STATUS_TOUCHING], 0u);
            atomicStore(&status[STATUS_TOUCHING_DISPATCH], 0u);
        }
    }
    if (gid.x < params.body_count) {
        let i = sorted[gid.x];
        if (kept) {
            // (dispatched at one workgroup) the last walks' list, empty,
            // stands, and so do the grid (its scans, scatter and sort do not
            // run) and the body lists made from it (`listed_body`; none touches)
            return;
        }
        // the grid's arrivals are done with: the body lists start empty
        // (`listed_body`, `touching_body`; where no body can sleep, every body
        // is listed by its index and the listed run is not read)
        if (SLEEPING) {
            sorted[LISTED_RUN * params.body_count + gid.x] = NONE;
        }
        sorted[TOUCHING_RUN * params.body_count + gid.x] = NONE;
        // (the pairs the last walks counted: the scan has not yet written this step's)
        let listed_none = atomicLoad(&status[STATUS_PAIRS]) == 0u;
        if (gid.x == 0u && !listed_none) {
            atomicStore(&status[STATUS_NEAR_NOW], 1u);
        }
        testing_near = listed_none;
        writing = false;
        room_start = gid.x * scratch_room();
        walk(i);
        pair_meta[i].owned = owned;
        note_long_walks();
    }
}

// The loop trips of the workgroup's walks, summed (in any order).
var<workgroup> group_trips: atomic<u32>;

// Sets status[STATUS_WALKS_CUT] if a walk of the workgroup may have been cut short.
// Lavapipe counts a loop's trips once for the 8 invocations it runs side by
// side, as many as the longest takes, so a vector's trips are at most the sum
// of its invocations', and at most the workgroup's sum, tested here: the last
// walk to add tests the whole sum, whatever the order.
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
    // the scan left the body's starts within its block of SCAN_SPAN bodies; the
    // narrowphase lists contacts by the cursor from 0
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
