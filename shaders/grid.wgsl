// Broadphase: a uniform grid rebuilt every step by counting sort. Cells are
// hashed into hash_size buckets, so the grid is unbounded; a bucket may hold
// several cells, told apart by each body's own cell.
//   grid_count    bodies:  count[bucket]++; what the pair walks read (PairMeta)
//   scan_blocks   buckets: exclusive prefix sum within blocks of SCAN_SPAN
//   scan_sums     one workgroup: prefix sum of the block totals
//   scan_add      buckets: add block offsets -> cell_start
//   grid_scatter  bodies:  arrivals[cell_end - count--] = body (counting each
//                 bucket back to 0 for the next step: no clearing pass)
//   grid_sort     bodies:  place in the bucket by the box's low x, then index;
//                 sorted[place] = body, its bounds to cell_bounds
// Large bodies (much bigger than a cell; large_body()) are not in the grid.
// With SCAN_PAIRS the scan passes sum the bodies' pair counts instead
// (pairs.wgsl) and write the narrowphase's dispatch. Choices and their
// measurements: docs/decisions/broadphase.md.

// SCAN_BLOCK, SCAN_RUN and SCAN_SPAN (their product, a block): shared with Rust.

fn cell_of(p: vec3<f32>) -> vec3<i32> {
    return vec3<i32>(floor(p / params.cell_size));
}

// The bucket of cell c. Each block of 8 x 8 x 8 cells takes a run of 512
// consecutive buckets (the run placed by the block's hash, Morton order
// within), so the grid's order follows space and a walk's candidates lie near
// the last walker's. The Morton place is XORed with hash bits so that a
// lattice 8 cells apart does not share every run's first bucket.
fn bucket_of(c: vec3<i32>) -> u32 {
    let u = bitcast<vec3<u32>>(c);
    let block = u >> vec3<u32>(3u);
    let at = u & vec3<u32>(7u);
    let morton = spread_bits3(at.x) | (spread_bits3(at.y) << 1u) | (spread_bits3(at.z) << 2u);
    let h = (block.x * 73856093u) ^ (block.y * 19349663u) ^ (block.z * 83492791u);
    return ((h << 9u) | (morton ^ (h >> 23u))) & (params.hash_size - 1u);
}

// The three low bits of v, two zero bits apart (b2 b1 b0 -> b2 0 0 b1 0 0 b0).
fn spread_bits3(v: u32) -> u32 {
    return (v & 1u) | ((v & 2u) << 2u) | ((v & 4u) << 4u);
}

fn in_grid(i: u32) -> bool {
    return grid_body(props_of(i));
}

fn grid_body(p: BodyProps) -> bool {
    return p.grid_class == GRID_BODY;
}

// How far a body may move in the coming step (m): its last displacement, rescaled, and gravity.
fn reach_of(s: BodyState) -> f32 {
    let steps = f32(params.substeps);
    let ratio = params.dt / params.dt_prev * steps;
    let h = params.dt * steps;
    return length(s.disp) * ratio + length(params.gravity) * h * h;
}

// How far a body's turn moves any of its points in the coming step (m), if it
// keeps the last substep's turn: a quaternion change of d moves a point at r
// by at most 2 d r (d the nearer of q and -q), rescaled as reach_of. A
// sphere turns into itself: 0.
fn spin_reach_of(s: BodyState, p: BodyProps) -> f32 {
    let ratio = params.dt / params.dt_prev * f32(params.substeps);
    let turned = min(length(s.rot - s.prev_rot), length(s.rot + s.prev_rot));
    return select(2.0 * turned * p.half_extents.w * ratio, 0.0, p.shape == SHAPE_SPHERE);
}

// Fast bodies. The walk of a cell and its neighbours finds every pair whose
// grown boxes (pair_meta's extent) reach at most fast_size() along every axis
// (cells are 2.5 bounding radii: a unit cube at about 12 m/s). A body reaching
// farther (`is_fast`) walks every cell within its reach instead, and grid_sort
// marks its CellBound (FAST_BODY) so that no other walk takes its pairs.
fn fast_size() -> f32 {
    // a thousandth of a cell of slack for the rounding of the cells
    return 0.5 * (0.999 * params.cell_size - CONTACT_MARGIN);
}

// How far a grown box reaches along its longest axis.
fn box_size(extent: vec3<f32>) -> f32 {
    return max(extent.x, max(extent.y, extent.z));
}

// Whether a body of box size `size` is fast. A sleeper never is: it walks no cells.
fn is_fast(size: f32, moves: u32) -> bool {
    return size > fast_size() && moves != SLEEPS;
}

// Counts body i into its bucket and writes what the pair walks read of it
// (PairMeta's moves, extent, bound, reach). Where the last walks found
// nothing near (`pairs_kept`), it takes the bodies in their grid order, so
// that each meets the bounds they saw of it (cell_bounds at the same place)
// and says whether it left them. Invocation 0 also empties the pool's
// counters and the step's flags (the step's first pass).
@compute @workgroup_size(WORKGROUP)
fn grid_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x == 0u) {
        atomicStore(&status[STATUS_MANIFOLDS], 0u);
        atomicStore(&status[STATUS_MANIFOLDS_TOP], 0u);
        atomicStore(&status[STATUS_MANIFOLDS_BOTTOM], 0u);
        atomicStore(&status[STATUS_MOVING], 0u);
        // the bodies kept out of the grid have no place in it to compare with
        atomicMax(&status[STATUS_WALK], u32(params.large_count != 0u));
        // (walking already: the other invocations only ever set it)
        if (atomicLoad(&status[STATUS_WALK]) != 0u) {
            size_walk_passes(true);
        }
    }
    if (gid.x >= params.body_count) {
        return;
    }
    // (the same results in either order; index order reads memory in turn.
    // `near` stays put all step, where `walk` changes in this very pass)
    let keepable = atomicLoad(&status[STATUS_NEAR]) == 0u;
    let i = select(gid.x, sorted[gid.x], keepable);
    let s = state_of(i);
    let p = props_of(i);
    let reach = reach_of(s);
    let spin = spin_reach_of(s, p);
    let fixed = is_fixed(p);
    let moves = !fixed && (!asleep(s) || (s.pos_low & WAKES) != 0u);
    let sleeps = !fixed && !moves;
    let moves_code = select(select(STAYS_FIXED, SLEEPS, sleeps), MOVES, moves);
    let moves_before = pair_meta[i].moves;
    pair_meta[i].moves = moves_code;
    atomicStore(&pair_meta[i].cursor, 0u); // pairs_count counts incoming pairs here
    pair_meta[i].reach = reach + spin;
    pair_meta[i].spin = spin;
    let extent = body_extent(s, p) + vec3<f32>(reach + spin);
    pair_meta[i].extent = extent;
    // the bounding sphere turns into itself: only the centre's move grows it
    let bound = bound_sphere(p).w + reach;
    pair_meta[i].bound = bound;
    if (!grid_body(p)) {
        return;
    }
    if (keepable) {
        // still within half keep_margin() of the bounds the last walks saw?
        let seen = cell_bound_of(gid.x);
        let drift = s.pos - seen.pos;
        let half = 0.5 * keep_margin();
        let within = all(abs(drift) + max(extent - seen.extent, vec3<f32>(0.0)) <= vec3<f32>(half))
            && length(drift) + max(bound - seen.bound, 0.0) <= half;
        let same = (seen.body & BODY_BITS) == i && moves_code == moves_before;
        if (!(within && same) && atomicLoad(&status[STATUS_WALK]) == 0u) {
            atomicStore(&status[STATUS_WALK], 1u);
            size_walk_passes(true);
        }
    }
    // the movers' walks look for sleepers behind them too; one store sets it
    if (sleeps && atomicLoad(&status[STATUS_GRID_SLEEPS]) == 0u) {
        atomicStore(&status[STATUS_GRID_SLEEPS], 1u);
    }
    atomicAdd(&cell_count[bucket_of(cell_of(s.pos))], 1u);
}

// Which prefix sum the scan passes compute (set per pipeline, see above).
override SCAN_PAIRS: bool = false;

fn scan_len() -> u32 {
    if (SCAN_PAIRS) {
        return params.body_count;
    }
    return params.hash_size;
}

fn scan_read(k: u32) -> vec2<u32> {
    if (SCAN_PAIRS) {
        // owned, and all: owned plus those counted in by their owners
        return vec2<u32>(pair_meta[k].owned, pair_meta[k].owned + atomicLoad(&pair_meta[k].cursor));
    }
    return vec2<u32>(atomicLoad(&cell_count[k]), 0u);
}

fn scan_write(k: u32, v: vec2<u32>) {
    if (SCAN_PAIRS) {
        pair_meta[k].owned_start = v.x;
        pair_meta[k].list_start = v.y;
    } else {
        cell_start[k] = v.x;
    }
}

var<workgroup> scan_tmp: array<vec2<u32>, SCAN_BLOCK>;

// Inclusive Hillis-Steele scan of scan_tmp; every invocation must call it.
fn scan_workgroup(lid: u32) {
    for (var offset = 1u; offset < SCAN_BLOCK; offset = offset * 2u) {
        workgroupBarrier();
        var add = vec2<u32>(0u);
        if (lid >= offset) {
            add = scan_tmp[lid - offset];
        }
        workgroupBarrier();
        scan_tmp[lid] = scan_tmp[lid] + add;
    }
    workgroupBarrier();
}

fn scan_written(k: u32) -> vec2<u32> {
    if (SCAN_PAIRS) {
        return vec2<u32>(pair_meta[k].owned_start, pair_meta[k].list_start);
    }
    return vec2<u32>(cell_start[k], 0u);
}

// A block is SCAN_SPAN = SCAN_BLOCK x SCAN_RUN elements: each invocation sums
// a run of SCAN_RUN in turn, then the workgroup scans the runs' totals (its
// barriers, not the sums, are what such a pass costs on lavapipe).
@compute @workgroup_size(SCAN_BLOCK)
fn scan_blocks(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let first = wid.x * SCAN_SPAN + lid.x * SCAN_RUN;
    let end = min(first + SCAN_RUN, scan_len());
    var total = vec2<u32>(0u);
    for (var h = first; h < end; h = h + 1u) {
        let v = scan_read(h);
        scan_write(h, total); // exclusive within the run
        if (SCAN_PAIRS) {
            pair_meta[h].total = v.y;
        }
        total = total + v;
    }
    scan_tmp[lid.x] = total;
    scan_workgroup(lid.x);
    let before = scan_tmp[lid.x] - total;
    for (var h = first; h < end; h = h + 1u) {
        scan_write(h, scan_written(h) + before); // exclusive within the block
    }
    // one block is the whole scan: its offset is 0 and it finishes the scan
    // itself, so scan_sums and scan_add need not run (`World::step_plan`)
    let whole = scan_len() <= SCAN_SPAN;
    if (lid.x == SCAN_BLOCK - 1u) {
        block_sums[wid.x] = select(scan_tmp[lid.x], vec2<u32>(0u), whole);
    }
    if ((lid.x == SCAN_BLOCK - 1u) & whole) {
        finish_scan(scan_tmp[lid.x]);
    }
}

// Writes the total `sum` past the last entry and, for the pairs, their count and dispatch.
fn finish_scan(sum: vec2<u32>) {
    scan_write(scan_len(), sum);
    if (SCAN_PAIRS) {
        // the narrowphase runs over the pairs that fit the list
        let listed = min(sum.x, arrayLength(&pairs));
        atomicStore(&status[STATUS_PAIRS], sum.x);
        atomicMax(&status[STATUS_PAIRS_MAX], sum.x);
        write_dispatch(STATUS_PAIRS_DISPATCH, listed);
    }
}

// One workgroup turns the block totals into exclusive block offsets, each
// invocation scanning a run of blocks first (none for a scan of one block).
@compute @workgroup_size(SCAN_BLOCK)
fn scan_sums(@builtin(local_invocation_id) lid: vec3<u32>) {
    if (scan_len() <= SCAN_SPAN) {
        return;
    }
    let blocks = (scan_len() + SCAN_SPAN - 1u) / SCAN_SPAN;
    let run = (blocks + SCAN_BLOCK - 1u) / SCAN_BLOCK;
    let first = lid.x * run;
    var total = vec2<u32>(0u);
    for (var k = 0u; k < run; k = k + 1u) {
        if (first + k < blocks) {
            let v = block_sums[first + k];
            block_sums[first + k] = total; // exclusive within the run
            total = total + v;
        }
    }
    scan_tmp[lid.x] = total;
    scan_workgroup(lid.x);
    let before = scan_tmp[lid.x] - total;
    for (var k = 0u; k < run; k = k + 1u) {
        if (first + k < blocks) {
            block_sums[first + k] = block_sums[first + k] + before;
        }
    }
    if (lid.x == SCAN_BLOCK - 1u) {
        finish_scan(scan_tmp[lid.x]);
    }
}

// (The grid's: the counts stay, the scatter counts them down.)
@compute @workgroup_size(WORKGROUP)
fn scan_add(@builtin(global_invocation_id) gid: vec3<u32>) {
    let h = gid.x;
    if (h < scan_len()) {
        cell_start[h] = cell_start[h] + block_sums[h / SCAN_SPAN].x;
    }
}

@compute @workgroup_size(WORKGROUP)
fn grid_scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count || !in_grid(i)) {
        return;
    }
    let h = bucket_of(cell_of(state_of(i).pos));
    // from the bucket's start as the count goes down, in arrival order
    sorted[params.body_count + cell_start[h + 1u] - atomicSub(&cell_count[h], 1u)] = i;
}

// A grid body's key in its bucket: the low x side of its grown world box.
fn grid_key(i: u32) -> f32 {
    return state_of(i).pos.x - pair_meta[i].extent.x;
}

// Each bucket's bodies placed by key, then index: the same order every run
// (the scatter's depends on thread timing), and a walk may stop at the first
// box beyond its reach along x. Each body counts those before it, a loop as
// long as its bucket (an insertion sort's n^2/4 trips pass lavapipe's loop
// limit). The bounds go to cell_bounds in that order, a cell's side by side.
@compute @workgroup_size(WORKGROUP)
fn grid_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    // the bounds of the bodies kept out of the grid go after the grid's, in
    // their order (`large_body`): every walk reads them, once each here
    if (i < params.large_count) {
        let j = large_body(i);
        let bound = CellBound(large_centre(j), pair_meta[j].bound, pair_meta[j].extent, j | (pair_meta[j].moves << MOVES_SHIFT));
        set_cell_bound(params.body_count - params.large_count + i, bound);
    }
    if (i >= params.body_count || !in_grid(i)) {
        return;
    }
    let pos = state_of(i).pos;
    let extent = pair_meta[i].extent;
    let key = pos.x - extent.x; // grid_key(i)
    let h = bucket_of(cell_of(pos));
    let start = cell_start[h];
    let end = cell_start[h + 1u];
    var place = start;
    for (var k = start; k < end; k = k + 1u) {
        let j = sorted[params.body_count + k];
        let key_j = grid_key(j);
        place = place + u32(key_j < key || (key_j == key && j < i));
    }
    sorted[place] = i;
    let moves = pair_meta[i].moves;
    let fast = select(0u, FAST_BODY, is_fast(box_size(extent), moves));
    set_cell_bound(place, CellBound(pos, pair_meta[i].bound, extent, i | fast | (moves << MOVES_SHIFT)));
}
