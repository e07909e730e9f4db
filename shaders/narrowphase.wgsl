// Pass "narrowphase", once per step after the pair list, one invocation per
// candidate pair: the pair's manifold (collide.wgsl) up to a speculative gap
// (how far the pair may close in the step, so fast bodies meet walls), stored
// in the pool in the bodies' frames and listed in both bodies' contact lists.
// Two boxes get only their separating axis here; a face contact is left for
// narrowphase_clip, ground pairs for narrowphase_ground. An awake partner
// moving fast or deep in a sleeper wakes it. See docs/decisions/narrowphase.md.

fn shape_of(i: u32) -> Shape {
    let s = state_of(i);
    let p = props_of(i);
    return Shape(s.pos, s.rot, p.half_extents.xyz, p.shape);
}

fn world_to_local(i: u32, p: vec3<f32>) -> vec3<f32> {
    let s = state_of(i);
    return quat_rotate(quat_conj(s.rot), p - s.pos);
}

// Body i against the ground within `margin`, normal from the body down: a
// sphere's lowest point, a capsule's under each end of its segment, or the
// deepest four box corners within the margin.
fn ground_manifold(i: u32, margin: f32) -> Manifold {
    let s = state_of(i);
    let p = props_of(i);
    let ground = params.ground_height;
    var m = empty_manifold();
    m.normal = vec3<f32>(0.0, -1.0, 0.0);
    if (HAS_ROUND && p.shape == SHAPE_SPHERE) {
        let lowest = s.pos - vec3<f32>(0.0, p.half_extents.x, 0.0);
        if (lowest.y - ground <= margin) {
            m.count = 1u;
            m.on_a[0] = lowest;
            m.on_b[0] = vec3<f32>(lowest.x, ground, lowest.z);
        }
        return m;
    }
    if (HAS_ROUND && p.shape == SHAPE_CAPSULE) {
        return ground_capsule(swept_of(shape_of(i)), ground, margin);
    }
    // heights of the eight corners above the ground
    var height: array<f32, 8>;
    for (var k = 0u; k < 8u; k = k + 1u) {
        height[k] = s.pos.y + quat_rotate(s.rot, corner(k, p.half_extents.xyz)).y - ground;
    }
    // the deepest corners within the margin, four at most
    var chosen = 0u;
    for (var pick = 0u; pick < MAX_POINTS; pick = pick + 1u) {
        var best = 8u;
        var best_h = margin;
        for (var k = 0u; k < 8u; k = k + 1u) {
            if ((chosen & (1u << k)) == 0u && height[k] <= best_h) {
                best = k;
                best_h = height[k];
            }
        }
        if (best < 8u) {
            chosen = chosen | (1u << best);
        }
    }
    // in corner order, each point's place picked by comparison, not by indexing
    // with the count (lavapipe keeps a dynamically indexed array in memory)
    for (var k = 0u; k < 8u; k = k + 1u) {
        let w = s.pos + quat_rotate(s.rot, corner(k, p.half_extents.xyz));
        let on_ground = vec3<f32>(w.x, ground, w.z);
        let picked = (chosen & (1u << k)) != 0u;
        for (var q = 0u; q < MAX_POINTS; q = q + 1u) {
            let here = picked && m.count == q;
            m.on_a[q] = select(m.on_a[q], w, here);
            m.on_b[q] = select(m.on_b[q], on_ground, here);
        }
        m.count = m.count + u32(picked);
    }
    return m;
}

// Corner k (bits: x, y, z positive) of a box of half extents h.
fn corner(k: u32, h: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        select(-1.0, 1.0, (k & 1u) != 0u),
        select(-1.0, 1.0, (k & 2u) != 0u),
        select(-1.0, 1.0, (k & 4u) != 0u),
    ) * h;
}

// Wakes `sleeper` if `other` is awake, moves, and is fast or `gap` deep in it.
fn wake_check(sleeper: u32, other: u32, gap: f32) {
    if (asleep(state_of(sleeper)) && !is_fixed(props_of(other)) && wakes(other, gap)) {
        atomicOr(&pair_meta[sleeper].woken, WOKEN_NOW);
    }
}

// Stores manifold m of bodies a and b (b may be GROUND) in `slot`, its points in
// the bodies' own frames, and wakes a sleeper that an awake partner presses or hits.
fn store_manifold(slot: u32, a: u32, b: u32, pair: u32, m: Manifold) {
    var kept: ManifoldPoints;
    var deepest = 3.4e38;
    for (var k = 0u; k < MAX_POINTS; k = k + 1u) {
        if (k < m.count) {
            var local_b = m.on_b[k];
            if (b != GROUND) {
                local_b = world_to_local(b, m.on_b[k]);
            }
            kept.at[k] = ContactPoint(world_to_local(a, m.on_a[k]), 0.0, local_b, 0.0);
            deepest = min(deepest, dot(m.on_b[k] - m.on_a[k], m.normal));
        }
    }
    set_manifold(slot, ContactManifold(m.normal, m.count, a, b, NONE, pair));
    store_points(slot, kept);
    // only an awake partner wakes a sleeper, so one check (of whichever end
    // sleeps) does: one copy of it in the kernel
    if (b != GROUND && m.count > 0u) {
        let a_sleeps = asleep(state_of(a));
        wake_check(select(b, a, a_sleeps), select(a, b, a_sleeps), deepest);
    }
}

// A slot of the manifold pool for bodies a and b (b may be GROUND), listed
// in both bodies' lists (in the order the slots are taken; contact_lists
// sorts them), or NONE when the pool is full (counted in status[STATUS_MANIFOLDS] all the
// same, so the host grows it; contact_lists keeps the most in status[STATUS_MANIFOLDS_MAX]).
// A face contact left for clipping (`to_clip`) takes the next slot from the
// top of the pool, any other the next from the bottom, so narrowphase_clip
// runs over the top run alone; the two never meet, as status[STATUS_MANIFOLDS] hands out
// no more tickets than the pool has slots.
fn new_manifold(a: u32, b: u32, to_clip: bool) -> u32 {
    let ticket = atomicAdd(&status[STATUS_MANIFOLDS], 1u);
    if (ticket >= arrayLength(&manifolds)) {
        return NONE;
    }
    var slot: u32;
    if (to_clip) {
        slot = arrayLength(&manifolds) - 1u - atomicAdd(&status[STATUS_MANIFOLDS_TOP], 1u);
    } else {
        slot = atomicAdd(&status[STATUS_MANIFOLDS_BOTTOM], 1u);
    }
    list_contact(a, contact_ref(slot, false));
    if (b != GROUND) {
        list_contact(b, contact_ref(slot, true));
    }
    return slot;
}

// Appends contact reference r to body i's list (room for all its pairs).
fn list_contact(i: u32, r: u32) {
    let k = pair_meta[i].list_start + atomicAdd(&pair_meta[i].cursor, 1u);
    if (k < arrayLength(&body_pairs)) {
        body_pairs[k] = r;
    }
}

// Whether a joint joins body a to body b. Asked here, once a pair, not in the
// pair walks, where the loop cost every candidate loop trips.
fn joined(a: u32, b: u32) -> bool {
    var found = false;
    let end = joint_start[a + 1u];
    for (var k = joint_start[a]; k < end; k = k + 1u) {
        found = found || joint_refs[k].partner == b;
    }
    return found;
}

@compute @workgroup_size(WORKGROUP)
fn narrowphase(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let p = dispatch_index(gid, groups);
    if (p >= min(atomicLoad(&status[STATUS_PAIRS]), arrayLength(&pairs))) {
        return;
    }
    let pr = pairs[p];
    // ground pairs: narrowphase_ground; joined bodies do not collide
    if (pr.b == GROUND || joined(pr.a, pr.b)) {
        return;
    }
    let a = shape_of(pr.a);
    let b = shape_of(pr.b);
    // pairs with a hull: narrowphase_hull
    if (a.kind == SHAPE_HULL || b.kind == SHAPE_HULL) {
        return;
    }
    let margin = pair_margin(pr.a, pr.b);
    // each step below has one call site, so the kernel holds one copy of it
    // (lavapipe's compile time grows steeply with a kernel's size)
    let boxes = a.kind == SHAPE_BOX && b.kind == SHAPE_BOX;
    var axis = BoxAxis();
    var m = empty_manifold();
    if (boxes) {
        axis = box_box_axis(a.centre, a.rot, a.half, b.centre, b.rot, b.half, margin);
    } else if (HAS_ROUND) {
        m = collide_round(a, b, margin);
    }
    let touches = select(m.count > 0u, axis.kind != AXIS_APART, boxes);
    let to_clip = boxes && axis.kind == AXIS_FACE;
    if (!touches) {
        return;
    }
    let slot = new_manifold(pr.a, pr.b, to_clip);
    if (slot == NONE) {
        return;
    }
    if (to_clip) {
        // pending: what narrowphase_clip needs (the points follow)
        set_manifold(slot, ContactManifold(axis.normal, 0u, pr.a, pr.b, axis.face, p));
        return;
    }
    if (boxes) {
        m = box_box_edge(a.centre, a.rot, a.half, b.centre, b.rot, b.half, axis);
    }
    store_manifold(slot, pr.a, pr.b, p, m);
}

// Pass "narrowphase_ground", per body: its contact with the ground, if it has
// a ground pair (the first it owns). A pass of its own, so the narrowphase's
// vectors do not run the ground's code beside the boxes' (every branch taken).
@compute @workgroup_size(WORKGROUP)
fn narrowphase_ground(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.body_count) {
        return;
    }
    let p = pair_meta[i].owned_start;
    if (pair_meta[i].owned == 0u || p >= min(atomicLoad(&status[STATUS_PAIRS]), arrayLength(&pairs)) || pairs[p].b != GROUND) {
        return;
    }
    // a hull's: narrowphase_hull
    if (props_of(i).shape == SHAPE_HULL) {
        return;
    }
    let m = ground_manifold(i, CONTACT_MARGIN + pair_meta[i].reach);
    if (m.count > 0u) {
        let slot = new_manifold(i, GROUND, false);
        if (slot != NONE) {
            store_manifold(slot, i, GROUND, p, m);
        }
    }
}

// Pass "narrowphase_hull", after the narrowphase where a body is a hull, one
// invocation per candidate pair: the manifolds of the pairs with a hull,
// ground pairs too (hull.wgsl). A pass of its own, so the narrowphase's
// vectors do not run the hulls' loops beside the boxes'.
@compute @workgroup_size(WORKGROUP)
fn narrowphase_hull(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let p = dispatch_index(gid, groups);
    if (p >= min(atomicLoad(&status[STATUS_PAIRS]), arrayLength(&pairs))) {
        return;
    }
    let pr = pairs[p];
    let ground = pr.b == GROUND;
    let hull = props_of(pr.a).shape == SHAPE_HULL || (!ground && props_of(pr.b).shape == SHAPE_HULL);
    if (!hull || (!ground && joined(pr.a, pr.b))) {
        return;
    }
    var margin = CONTACT_MARGIN + pair_meta[pr.a].reach;
    if (!ground) {
        margin = pair_margin(pr.a, pr.b);
    }
    let m = collide_hull(pr.a, pr.b, margin);
    if (m.count == 0u) {
        return;
    }
    let slot = new_manifold(pr.a, pr.b, false);
    if (slot != NONE) {
        store_manifold(slot, pr.a, pr.b, p, m);
    }
}

// Pass "narrowphase_clip", after contact_lists (which sizes its dispatch), one
// invocation per face contact the narrowphase left pending (the pool's top
// run): its points, so the clipping runs only where boxes touch face-on. A
// face contact whose clipping keeps no point stays, empty: it pushes nothing.
@compute @workgroup_size(WORKGROUP)
fn narrowphase_clip(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let nth = dispatch_index(gid, groups);
    if (nth >= min(atomicLoad(&status[STATUS_MANIFOLDS_TOP]), manifolds_used())) {
        return;
    }
    let k = arrayLength(&manifolds) - 1u - nth;
    let head = manifold_of(k);
    let face = head.clip_face;
    let ia = head.a;
    let ib = head.b;
    let a = shape_of(ia);
    let b = shape_of(ib);
    let m = box_box_face(a.centre, a.rot, a.half, b.centre, b.rot, b.half, head.normal, face, pair_margin(ia, ib));
    store_manifold(k, ia, ib, head.pair, m);
}

// Pass "contact_lists", once after the narrowphase, per body: sorts the
// contact references the narrowphase listed (in the order slots were taken,
// which depends on thread timing) into pair order (list_order), the order the
// solve and restitution sum in. Counts them (`contacts`), those with an end
// that stays (`held`) and the normal pushes' split (`normal_split`), and lists
// the body for the body passes. Invocation 0 also writes the contact passes'
// indirect dispatch, over the manifolds
// the pool holds (status[STATUS_MANIFOLDS_DISPATCH]).
@compute @workgroup_size(WORKGROUP)
fn contact_lists(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i == 0u) {
        // the most manifolds any step wanted (status[STATUS_MANIFOLDS] counts the slots
        // the pool could not give too)
        atomicMax(&status[STATUS_MANIFOLDS_MAX], atomicLoad(&status[STATUS_MANIFOLDS]));
        write_dispatch(STATUS_MANIFOLDS_DISPATCH, manifolds_used());
        // the pair walks are done: grid_count sets it again next step
        atomicStore(&status[STATUS_GRID_SLEEPS], 0u);
        // what the walks found near, where they walked, stands until they walk
        // again; the next step walks if it found some (`pairs_kept`), or if
        // grid_count finds a body that moved
        if (!pairs_kept()) {
            atomicStore(&status[STATUS_NEAR], atomicLoad(&status[STATUS_NEAR_NOW]));
            atomicStore(&status[STATUS_NEAR_NOW], 0u);
        }
        atomicStore(&status[STATUS_WALK], atomicLoad(&status[STATUS_NEAR]));
        // the walk's passes are sized anew by the next grid_count
        size_walk_passes(false);
        if (!SLEEPING) {
            // every body, listed by index (`listed_body`)
            atomicStore(&status[STATUS_LISTED], params.body_count);
            atomicStore(&status[STATUS_LISTED_DISPATCH], (params.body_count + WORKGROUP - 1u) / WORKGROUP);
        }
    }
    // a step that keeps the last walks' list, empty, keeps what this pass
    // made of it then: no body touches, and the body lists stand (a body
    // that falls asleep or wakes changes its `moves`, and the step walks)
    if (i >= params.body_count || atomicLoad(&status[STATUS_KEPT]) != 0u) {
        return;
    }
    let first = pair_meta[i].list_start;
    let end = min(first + atomicLoad(&pair_meta[i].cursor), arrayLength(&body_pairs));
    list_trips = 0u;
    if (end - first <= SHORT_LIST) {
        sort_short_list(first, end - first);
    } else {
        sort_long_list(first, end - first);
    }
    note_long_lists(end - first);
    pair_meta[i].contacts = end - first;
    var held = 0u;
    var movers = 0.0;
    // a manifold narrowphase_clip still has to clip, with a partner that
    // moves, may wake the body; so may one its list lost, where it overflowed
    var may_wake = first + atomicLoad(&pair_meta[i].cursor) > arrayLength(&body_pairs);
    let w = props_of(i).inv_inertia.w;
    for (var k = first; k < end; k = k + 1u) {
        let r = body_pairs[k];
        let head = manifold_of(r >> 1u);
        let partner = select(head.b, head.a, (r & 1u) != 0u);
        let stays = partner == GROUND || !contact_end_moves(partner);
        held = held + u32(stays);
        if (!stays) {
            movers = movers + w / max(w + props_of(partner).inv_inertia.w, 1e-30);
            may_wake = may_wake || head.clip_face != NONE;
        }
    }
    pair_meta[i].held = held;
    let jointed = is_jointed(i);
    pair_meta[i].normal_split = select(1.0, max(1.0, params.relaxation * (f32(held) + movers)), held > 0u && !jointed);
    // the bodies the step may change, for the body passes (`listed_body`): all
    // but the sleepers held still that nothing woke or may wake (listing one
    // changes nothing: integrate holds it, restitution copies it), and of
    // them those with contacts for `solve`; where none can sleep, every body
    // (invocation 0 counts them) and no sleeper's state is read
    if (!SLEEPING || !sleeps_held(i) || atomicLoad(&pair_meta[i].woken) != 0u || may_wake) {
        if (SLEEPING) {
            list_in_run(LISTED_RUN, STATUS_LISTED, STATUS_LISTED_DISPATCH, i);
        }
        if (end > first) {
            list_in_run(TOUCHING_RUN, STATUS_TOUCHING, STATUS_TOUCHING_DISPATCH, i);
        }
    }
}

// The loop trips of this body's sort so far, as the driver counts them (see
// `trips` in pairs.wgsl).
var<private> list_trips: u32;

// Sets status[STATUS_LISTS_CUT] if this body's sort may have been cut short: a list
// left out of order sums its snaps in an order that may change from run to
// run. The driver counts the trips of the 8 invocations side by side once, as
// many as the longest takes, so a long list is cut where its own count
// reaches the limit, and that is tested. `n`: the list's length, walked again.
fn note_long_lists(n: u32) {
    if (list_trips + n + 1u >= LOOP_TRIPS) {
        atomicStore(&status[STATUS_LISTS_CUT], 1u);
    }
}

// The longest list sorted in registers (a pile's bodies have 2 to 6 manifolds).
const SHORT_LIST: u32 = 8u;

// Sorts the `n` (at most SHORT_LIST) contact references from body_pairs[first]
// by list_order in registers: read once, sorted by odd-even transposition
// (fixed loops unroll, every index a constant), written back once.
fn sort_short_list(first: u32, n: u32) {
    var refs: array<u32, SHORT_LIST>;
    var keys: array<u32, SHORT_LIST>;
    for (var k = 0u; k < SHORT_LIST; k = k + 1u) {
        keys[k] = 0xffffffffu;
        if (k < n) {
            refs[k] = body_pairs[first + k];
            keys[k] = list_order(refs[k]);
        }
    }
    for (var round = 0u; round < SHORT_LIST; round = round + 1u) {
        for (var j = 0u; j < SHORT_LIST - 1u; j = j + 1u) {
            if ((j & 1u) == (round & 1u) && keys[j] > keys[j + 1u]) {
                let key = keys[j];
                keys[j] = keys[j + 1u];
                keys[j + 1u] = key;
                let r = refs[j];
                refs[j] = refs[j + 1u];
                refs[j + 1u] = r;
            }
        }
    }
    for (var k = 0u; k < SHORT_LIST; k = k + 1u) {
        if (k < n) {
            body_pairs[first + k] = refs[k];
        }
    }
}

// Sorts the `n` (more than SHORT_LIST) contact references from
// body_pairs[first] by list_order, in place. An insertion sort takes as many
// trips as the list has inversions (n^2/4 in random order, past lavapipe's
// loop limit), so it stops after INSERTION_TRIPS and a heap sort (about
// 1.5 n log2 n trips) finishes: the same order either way, the keys unique.
const INSERTION_TRIPS: u32 = 8192u;

fn sort_long_list(first: u32, n: u32) {
    var trips = 0u;
    var sorted_to = 1u; // body_pairs[first ..][..sorted_to] is in order
    for (var k = 1u; k < n; k = k + 1u) {
        if (trips >= INSERTION_TRIPS) {
            break;
        }
        let r = body_pairs[first + k];
        let key = list_order(r);
        var m = first + k;
        while (m > first && list_order(body_pairs[m - 1u]) > key) {
            body_pairs[m] = body_pairs[m - 1u];
            m = m - 1u;
            trips = trips + 1u;
        }
        body_pairs[m] = r;
        trips = trips + 1u;
        sorted_to = k + 1u;
    }
    // each outer trip, and the end of each loop
    list_trips = trips + sorted_to + 2u;
    if (sorted_to == n) {
        return;
    }
    // a max-heap of the list (n / 2 sifts), then its largest moved to the end
    // n - 1 times, each followed by a sift (one loop: one copy of sift_down)
    let heaped = n / 2u;
    for (var t = 0u; t < heaped + n - 1u; t = t + 1u) {
        var root = 0u;
        var size = n;
        if (t < heaped) {
            root = heaped - 1u - t;
        } else {
            size = n - 1u - (t - heaped);
            let r = body_pairs[first];
            body_pairs[first] = body_pairs[first + size];
            body_pairs[first + size] = r;
        }
        sift_down(first, root, size);
        list_trips = list_trips + 1u;
    }
    list_trips = list_trips + 1u;
}

// Sifts the reference at `root` of the heap of `n` from body_pairs[first] down.
fn sift_down(first: u32, root_in: u32, n: u32) {
    var root = root_in;
    let r = body_pairs[first + root];
    let key = list_order(r);
    // a heap of fewer than 2^32 entries is less than 32 levels deep
    for (var depth = 0u; depth < 32u; depth = depth + 1u) {
        list_trips = list_trips + 1u;
        var child = 2u * root + 1u;
        if (child >= n) {
            break;
        }
        var child_key = list_order(body_pairs[first + child]);
        if (child + 1u < n) {
            let right_key = list_order(body_pairs[first + child + 1u]);
            if (right_key > child_key) {
                child = child + 1u;
                child_key = right_key;
            }
        }
        if (child_key <= key) {
            break;
        }
        body_pairs[first + root] = body_pairs[first + child];
        root = child;
    }
    body_pairs[first + root] = r;
}

// Whether body i is a sleeper the step leaves as it is unless something wakes
// it: SLEEPS, held as integrate holds a sleeper (no displacement or turn, HELD;
// bit for bit), so every pass would copy it; sane (else integrate must see its
// fault); not on a joint (joint_rest writes rest times in place).
fn sleeps_held(i: u32) -> bool {
    let s = state_of(i);
    let still = all(bitcast<vec3<u32>>(s.disp) == vec3<u32>(0u)) && all(bitcast<vec4<u32>>(s.prev_rot) == bitcast<vec4<u32>>(s.rot));
    let held = still && (s.pos_low & HELD) != 0u && near(s.pos) && all_finite(s.rot);
    return pair_meta[i].moves == SLEEPS && held && !is_jointed(i);
}

// Where contact reference r goes in its body's list: pairs the body does not
// own (it is end b) first, then owned ones, each by pair index (the owner
// writes them in walk order; a pair index stays below 2^31: pair_capacities).
fn list_order(r: u32) -> u32 {
    return manifold_of(r >> 1u).pair | select(0x80000000u, 0u, (r & 1u) != 0u);
}
