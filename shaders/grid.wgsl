// Broadphase: a uniform grid rebuilt every step by counting sort into
// preallocated buffers. Cells are hashed into hash_size buckets, so the grid
// is unbounded; a bucket may hold bodies of several cells, which the
// narrowphase tells apart by each body's own cell.
//
//   grid_clear        buckets: count = 0
//   grid_count        bodies:  count[bucket of body]++
//   grid_scan_blocks  buckets: exclusive prefix sum within blocks of SCAN_BLOCK
//   grid_scan_sums    one workgroup: prefix sum of the block totals
//   grid_scan_add     buckets: add block offsets -> cell_start; count = 0 again
//   grid_scatter      bodies:  sorted[cell_start + count++] = body
//   grid_sort         buckets: sort each bucket's bodies by index (determinism)
//
// Bodies in large[] (much bigger than a cell) are not in the grid.

const SCAN_BLOCK: u32 = 256u;

fn cell_of(p: vec3<f32>) -> vec3<i32> {
    return vec3<i32>(floor(p / params.cell_size));
}

fn bucket_of(c: vec3<i32>) -> u32 {
    let h = (u32(c.x) * 73856093u) ^ (u32(c.y) * 19349663u) ^ (u32(c.z) * 83492791u);
    return h & (params.hash_size - 1u);
}

fn in_grid(i: u32) -> bool {
    return props[i].kind.z == 0u; // kind.z = 1 marks a large body
}

@compute @workgroup_size(WORKGROUP)
fn grid_clear(@builtin(global_invocation_id) gid: vec3<u32>) {
    if (gid.x < params.hash_size) {
        atomicStore(&cell_count[gid.x], 0u);
    }
    if (gid.x == 0u) {
        atomicStore(&status[0], 0u);
    }
}

@compute @workgroup_size(WORKGROUP)
fn grid_count(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count || !in_grid(i)) {
        return;
    }
    atomicAdd(&cell_count[bucket_of(cell_of(state_in[i].pos.xyz))], 1u);
}

var<workgroup> scan_tmp: array<u32, SCAN_BLOCK>;

// Inclusive Hillis-Steele scan of scan_tmp; every invocation must call it.
fn scan_workgroup(lid: u32) {
    for (var offset = 1u; offset < SCAN_BLOCK; offset = offset * 2u) {
        workgroupBarrier();
        var add = 0u;
        if (lid >= offset) {
            add = scan_tmp[lid - offset];
        }
        workgroupBarrier();
        scan_tmp[lid] = scan_tmp[lid] + add;
    }
    workgroupBarrier();
}

@compute @workgroup_size(SCAN_BLOCK)
fn grid_scan_blocks(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>,
                    @builtin(workgroup_id) wid: vec3<u32>) {
    let h = gid.x;
    var v = 0u;
    if (h < params.hash_size) {
        v = atomicLoad(&cell_count[h]);
    }
    scan_tmp[lid.x] = v;
    scan_workgroup(lid.x);
    if (h < params.hash_size) {
        cell_start[h] = scan_tmp[lid.x] - v; // exclusive
    }
    if (lid.x == SCAN_BLOCK - 1u) {
        block_sums[wid.x] = scan_tmp[lid.x];
    }
}

// One workgroup turns the block totals into exclusive block offsets, each
// invocation scanning a run of consecutive blocks first.
@compute @workgroup_size(SCAN_BLOCK)
fn grid_scan_sums(@builtin(local_invocation_id) lid: vec3<u32>) {
    let blocks = (params.hash_size + SCAN_BLOCK - 1u) / SCAN_BLOCK;
    let run = (blocks + SCAN_BLOCK - 1u) / SCAN_BLOCK;
    let first = lid.x * run;
    var total = 0u;
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
        cell_start[params.hash_size] = scan_tmp[lid.x];
    }
}

@compute @workgroup_size(WORKGROUP)
fn grid_scan_add(@builtin(global_invocation_id) gid: vec3<u32>) {
    let h = gid.x;
    if (h < params.hash_size) {
        cell_start[h] = cell_start[h] + block_sums[h / SCAN_BLOCK];
        atomicStore(&cell_count[h], 0u);
    }
}

@compute @workgroup_size(WORKGROUP)
fn grid_scatter(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count || !in_grid(i)) {
        return;
    }
    let h = bucket_of(cell_of(state_in[i].pos.xyz));
    sorted[cell_start[h] + atomicAdd(&cell_count[h], 1u)] = i;
}

// The scatter's order within a bucket depends on thread timing; sorting each
// bucket by body index makes every later pass see the same order every run.
@compute @workgroup_size(WORKGROUP)
fn grid_sort(@builtin(global_invocation_id) gid: vec3<u32>) {
    let h = gid.x;
    if (h >= params.hash_size) {
        return;
    }
    let start = cell_start[h];
    let end = cell_start[h + 1u];
    for (var k = start + 1u; k < end; k = k + 1u) {
        let v = sorted[k];
        var m = k;
        while (m > start && sorted[m - 1u] > v) {
            sorted[m] = sorted[m - 1u];
            m = m - 1u;
        }
        sorted[m] = v;
    }
}
