// The bind group every pass of the step shares (src/step/mod.rs builds its
// layout). Two bind groups of it exist, A->B and B->A, built once; they
// differ only in which state buffer is state_in and which state_out.
@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> props: array<BodyProps>;
@group(0) @binding(2) var<storage, read> state_in: array<BodyState>;
@group(0) @binding(3) var<storage, read_write> state_out: array<BodyState>;
@group(0) @binding(4) var<storage, read_write> vel0: array<Velocity>;
// broadphase grid: bodies counted per hash bucket, then sorted by bucket
@group(0) @binding(5) var<storage, read_write> cell_count: array<atomic<u32>>;  // hash_size
@group(0) @binding(6) var<storage, read_write> cell_start: array<u32>;          // hash_size + 1
@group(0) @binding(7) var<storage, read_write> block_sums: array<u32>;          // hash_size / SCAN_BLOCK
@group(0) @binding(8) var<storage, read_write> sorted: array<u32>;              // body_count
@group(0) @binding(9) var<storage, read> large: array<u32>;                     // large_count
// contacts: MAX_CONTACTS slots per body, filled by the body itself
@group(0) @binding(10) var<storage, read_write> contacts: array<Contact>;
@group(0) @binding(11) var<storage, read_write> contact_count: array<u32>;
// status[0]: most contact points any body wanted this step, status[1]: in any
// step so far (a full contact list when either exceeds MAX_CONTACTS), both
// atomicMax-ed from 0; status[2], status[3]: the first numerical fault (see
// integrate.wgsl): 4 * body + FAULT_* of the lowest body found bad in the
// first step that found any, and that step's step_index, both atomicMin-ed
// from NO_FAULT (0xffffffff, written when the buffer is made); 8 words
@group(0) @binding(12) var<storage, read_write> status: array<atomic<u32>>;
// ball joints: body i's ends are joint_refs[joint_start[i] .. joint_start[i + 1]]
@group(0) @binding(13) var<storage, read> joint_start: array<u32>;              // body_count + 1
@group(0) @binding(14) var<storage, read> joint_refs: array<JointRef>;          // 2 per joint
