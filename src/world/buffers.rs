//! The GPU buffers of a world and the step's bind groups over them.

use std::mem::{offset_of, size_of, size_of_val};

use bytemuck::{Pod, Zeroable};

use super::capacity::{pair_capacities, pool_parts};
use super::encode::MAX_BATCH;
use super::records::{hash_size, JointLists};
use crate::gpu::status::{Status, WALK_DISPATCHES};
use crate::gpu::{types::*, Gpu};
use crate::step::{Buffer, Over, Stage, StepPipelines};

/// The GPU buffers of a world, made at start-up; the pair list and the
/// manifold pool are made again as the contacts a step wants grow or
/// shrink (`World::make_pools`), the rest as an edit needs (`refit`).
pub(super) struct WorldData {
    pub states: [wgpu::Buffer; 2],
    pub params: wgpu::Buffer,
    pub status: wgpu::Buffer,
    /// The pair pipeline (shaders/pairs.wgsl): candidate pairs, the
    /// manifold pool, each body's pair bookkeeping and its pair list.
    pub pairs: wgpu::Buffer,
    /// The manifolds' headers, and their points in up to four parts (see
    /// `pool_parts`).
    pub manifolds: wgpu::Buffer,
    pub points: [wgpu::Buffer; 4],
    /// What each manifold asks of its two bodies in a sweep (two per
    /// manifold slot; solve.wgsl, restitution.wgsl), in up to two parts.
    pub snaps: [wgpu::Buffer; 2],
    pub pair_meta: wgpu::Buffer,
    pub body_pairs: wgpu::Buffer,
    /// The indirect dispatches' sizes (`Dispatches`), copied out of
    /// `status`: a buffer a pass binds as storage cannot also give it its
    /// indirect sizes.
    pub dispatch: wgpu::Buffer,
    /// Each stage's two bind groups, by stage (`step_bind_groups`; always
    /// made, right after the buffers).
    pub bind_groups: Option<Vec<[wgpu::BindGroup; 2]>>,
    /// Shapes, masses and materials (written by the input kernel too).
    pub props: wgpu::Buffer,
    /// What the scene fixed at start-up: the bodies kept out of the grid
    /// (copied into the tail of `sorted`, where the passes read them) and the
    /// joint lists and the hull records (the snapshot's scene hash reads
    /// them all).
    pub statics: [wgpu::Buffer; 4],
    /// Each joint island's two words for `joint_rest` (its least rest time
    /// and whether it is held), emptied before each use.
    pub island_rest: wgpu::Buffer,
    /// `solve_paths`' elimination along the paths it solves directly, a
    /// slot a path joint, written and read within one pass.
    pub path_scratch: wgpu::Buffer,
    /// Working buffers of the passes: vel0, and the grid's cell_count,
    /// cell_start, block_sums, sorted and cell_bounds.
    pub scratch: [wgpu::Buffer; 6],
    /// What a batch of steps starts from (the state and `status`; nothing
    /// else carries over from one step to the next, see snapshot.rs),
    /// copied as each batch begins, so that a batch during which a pool
    /// overflowed is taken again from the same start once the pools have
    /// grown (`World::step_with`).
    pub batch_start: [wgpu::Buffer; 2],
}

/// What a scene fixes at start-up, written into `WorldData::statics`: the
/// bodies kept out of the grid, the hull records and the joint lists.
#[derive(Clone, Copy)]
pub(super) struct Statics<'a> {
    pub large: &'a [u32],
    pub hulls: &'a [[f32; 4]],
    pub joints: &'a JointLists,
}

/// The `dispatch` buffer: each indirect dispatch's size (x, y, z) in a
/// 16-byte slot of its own.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub(super) struct Dispatches {
    pairs: [u32; 3],
    _pad0: u32,
    manifolds: [u32; 3],
    _pad1: u32,
    listed: [u32; 3],
    _pad2: u32,
    touching: [u32; 3],
    _pad3: u32,
    walk: [[u32; 3]; WALK_DISPATCHES],
}

/// Where an indirect dispatch over `over` takes its size: its place in the
/// `dispatch` buffer and the status words its kernel wrote it into (bytes);
/// `None` for a dispatch the host sizes.
pub(super) fn indirect(over: Over) -> Option<(u64, u64)> {
    let (slot, words) = match over {
        Over::Pairs => (offset_of!(Dispatches, pairs), offset_of!(Status, pairs_dispatch)),
        Over::Manifolds => (offset_of!(Dispatches, manifolds), offset_of!(Status, manifolds_dispatch)),
        Over::Listed => (offset_of!(Dispatches, listed), offset_of!(Status, listed_dispatch)),
        Over::Touching => (offset_of!(Dispatches, touching), offset_of!(Status, touching_dispatch)),
        _ => {
            let k = over.walk()?;
            let size = size_of::<[u32; 3]>();
            (offset_of!(Dispatches, walk) + k * size, offset_of!(Status, walk_dispatches) + k * size)
        }
    };
    Some((slot as u64, words as u64))
}

/// Bytes of one indirect dispatch's size.
pub(super) const DISPATCH_BYTES: u64 = size_of::<[u32; 3]>() as u64;

impl WorldData {
    /// Makes and fills the buffers of a scene of `n` bodies (`props`,
    /// `states`, the bodies kept out of the grid `large`, `joints`), with
    /// room for exactly those bodies.
    pub(crate) fn new(
        gpu: &Gpu,
        n: usize,
        props: &[BodyProps],
        states: &[BodyState],
        statics: &Statics,
        substeps: u32,
    ) -> WorldData {
        let Statics { joints, .. } = *statics;
        let device = &gpu.device;
        let storage = |label: &str, size: u64| storage_buffer(device, label, size);
        let room = n.max(1); // wgpu buffers may not be empty
        let BodyBuffers { states: state_bufs, batch_state, scratch, pair_meta } = BodyBuffers::new(device, room);
        let (pair_capacity, manifold_capacity) = pair_capacities(gpu, room as u64);
        let pairs = storage("pairs", pair_capacity * size_of::<Pair>() as u64);
        let (heads, point_parts, snap_parts) = pool_parts(gpu, manifold_capacity);
        let manifolds = storage("manifolds", heads);
        let points = point_parts.map(|size| storage("manifolds/points", size));
        let snaps = snap_parts.map(|size| storage("manifolds/snaps", size));
        let body_pairs = storage("pairs/body_lists", 2 * pair_capacity * 4);
        let status = storage("status", Status::BYTES);
        gpu.queue.write_buffer(&status, 0, bytemuck::bytes_of(&Status::INIT));
        let dispatch = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("indirect dispatches"),
            size: size_of::<Dispatches>() as u64,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let data = WorldData {
            states: state_bufs,
            params: params_buffer(device, substeps, joints),
            status,
            pairs,
            manifolds,
            points,
            snaps,
            pair_meta,
            body_pairs,
            dispatch,
            bind_groups: None,
            props: props_buffer(device, n),
            statics: statics_buffers(device, statics),
            island_rest: island_rest_buffer(device, joints),
            path_scratch: path_scratch_buffer(device, joints),
            scratch,
            batch_start: [batch_state, storage("batch start/status", Status::BYTES)],
        };
        data.upload(gpu, props, states, statics);
        data
    }

    /// This world's buffers made over for an edited scene of `n` bodies
    /// (`large` of them kept out of the grid, `joints`), nothing written
    /// yet: those sized by the body count where they hold `n` (else all of
    /// them anew, with room for `room`), the properties and the statics
    /// anew at their exact sizes (the scene hash reads them whole), the
    /// Params slots where the joint paths' colours need more, the rest (the
    /// contact pools, which follow the need) as they are. Takes the same
    /// handles, so nothing of this world changes until the caller writes.
    pub(super) fn refit(&self, gpu: &Gpu, n: usize, room: usize, statics: &Statics, substeps: u32) -> WorldData {
        let Statics { joints, .. } = *statics;
        let device = &gpu.device;
        let (states, batch_state, scratch, pair_meta) = if self.body_room() >= n.max(1) {
            (self.states.clone(), self.batch_start[0].clone(), self.scratch.clone(), self.pair_meta.clone())
        } else {
            let BodyBuffers { states, batch_state, scratch, pair_meta } = BodyBuffers::new(device, room.max(n).max(1));
            (states, batch_state, scratch, pair_meta)
        };
        let params = if self.params.size() >= params_bytes(substeps, joints) {
            self.params.clone()
        } else {
            params_buffer(device, substeps, joints)
        };
        WorldData {
            states,
            params,
            status: self.status.clone(),
            pairs: self.pairs.clone(),
            manifolds: self.manifolds.clone(),
            points: self.points.clone(),
            snaps: self.snaps.clone(),
            pair_meta,
            body_pairs: self.body_pairs.clone(),
            dispatch: self.dispatch.clone(),
            bind_groups: None,
            props: props_buffer(device, n),
            statics: statics_buffers(device, statics),
            island_rest: if self.island_rest.size() >= island_rest_bytes(joints) {
                self.island_rest.clone()
            } else {
                island_rest_buffer(device, joints)
            },
            path_scratch: if self.path_scratch.size() >= path_scratch_bytes(joints) {
                self.path_scratch.clone()
            } else {
                path_scratch_buffer(device, joints)
            },
            scratch,
            batch_start: [batch_state, self.batch_start[1].clone()],
        }
    }

    /// Writes a scene's records: the properties, the poses (into both
    /// state buffers: a body the step leaves as it is is read from either,
    /// `listed_body` in bindings.wgsl), the statics, and the bodies kept
    /// out of the grid into the tail of the grid's part of `sorted`, where
    /// the passes read them.
    pub(super) fn upload(&self, gpu: &Gpu, props: &[BodyProps], states: &[BodyState], statics: &Statics) {
        let Statics { large, hulls, joints } = *statics;
        let queue = &gpu.queue;
        let write = |buffer: &wgpu::Buffer, at: u64, bytes: &[u8]| {
            if !bytes.is_empty() {
                queue.write_buffer(buffer, at, bytes);
            }
        };
        write(&self.props, 0, bytemuck::cast_slice(props));
        for to in &self.states {
            write(to, 0, bytemuck::cast_slice(states));
        }
        let [large_buf, joint_start, joint_refs, hull_buf] = &self.statics;
        write(large_buf, 0, bytemuck::cast_slice(large));
        write(hull_buf, 0, bytemuck::cast_slice(hulls));
        write(joint_start, 0, bytemuck::cast_slice(&joints.starts));
        write(joint_refs, 0, bytemuck::cast_slice(&joints.refs));
        // the grid's part of `sorted` holds the other bodies, n - large of them
        // (grid_count reads the grid's order only once a walk has written it:
        // `status.near` is 1 until then)
        write(self.sorted(), 4 * (states.len() - large.len()) as u64, bytemuck::cast_slice(large));
    }

    /// Bodies the buffers sized by the body count hold.
    pub(super) fn body_room(&self) -> usize {
        (self.states[0].size() / size_of::<BodyState>() as u64) as usize
    }

    /// `sorted`: the grid's order, then the bodies the step's body passes
    /// run over, then those of them with contacts (`solve`'s).
    pub(crate) fn sorted(&self) -> &wgpu::Buffer {
        &self.scratch[4]
    }

    /// The buffer bound at `buffer`'s binding while `states[from]` is the
    /// current state (state_in) and the other the next (state_out).
    pub(crate) fn buffer(&self, buffer: Buffer, from: usize) -> &wgpu::Buffer {
        let [vel0, cell_count, cell_start, block_sums, sorted, cell_bounds] = &self.scratch;
        let [_, joint_start, joint_refs, hulls] = &self.statics;
        match buffer {
            Buffer::Params => &self.params,
            Buffer::Props => &self.props,
            Buffer::StateIn => &self.states[from],
            Buffer::StateOut => &self.states[1 - from],
            Buffer::Vel0 => vel0,
            Buffer::CellCount => cell_count,
            Buffer::CellStart => cell_start,
            Buffer::BlockSums => block_sums,
            Buffer::Sorted => sorted,
            Buffer::Snaps => &self.snaps[0],
            Buffer::Snaps1 => &self.snaps[1],
            Buffer::Points => &self.points[0],
            Buffer::Points1 => &self.points[1],
            Buffer::Points2 => &self.points[2],
            Buffer::Points3 => &self.points[3],
            Buffer::Pairs => &self.pairs,
            Buffer::Manifolds => &self.manifolds,
            Buffer::Status => &self.status,
            Buffer::JointStart => joint_start,
            Buffer::JointRefs => joint_refs,
            Buffer::PairMeta => &self.pair_meta,
            Buffer::BodyPairs => &self.body_pairs,
            Buffer::CellBounds => cell_bounds,
            Buffer::IslandRest => &self.island_rest,
            Buffer::PathScratch => &self.path_scratch,
            Buffer::Hulls => hulls,
        }
    }

    /// Every stage's two bind groups (its buffers, `Stage::buffers`), by
    /// stage: `[k]` reads `states[k]` and writes `states[1 - k]`.
    pub(crate) fn step_bind_groups(&self, device: &wgpu::Device, pipelines: &StepPipelines) -> Vec<[wgpu::BindGroup; 2]> {
        let group = |stage: Stage, from: usize| {
            let entries: Vec<wgpu::BindGroupEntry> = stage
                .buffers()
                .into_iter()
                .map(|buffer| {
                    let b = self.buffer(buffer, from);
                    // Params: one substep's slot, chosen by the dynamic offset
                    let size = (buffer == Buffer::Params).then_some(size_of::<Params>() as u64);
                    let resource = wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: b,
                        offset: 0,
                        size: size.and_then(wgpu::BufferSize::new),
                    });
                    wgpu::BindGroupEntry { binding: buffer.binding(), resource }
                })
                .collect();
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(stage.name()),
                layout: pipelines.layout(stage),
                entries: &entries,
            })
        };
        Stage::ALL.iter().map(|&stage| [group(stage, 0), group(stage, 1)]).collect()
    }

    /// Bytes of GPU memory the buffers hold now.
    pub(crate) fn bytes(&self) -> u64 {
        let buffers = [
            &self.params,
            &self.status,
            &self.pairs,
            &self.manifolds,
            &self.pair_meta,
            &self.body_pairs,
            &self.dispatch,
            &self.props,
            &self.island_rest,
            &self.path_scratch,
        ];
        buffers.iter().map(|b| b.size()).sum::<u64>()
            + self.states.iter().chain(&self.statics).chain(&self.scratch).chain(&self.batch_start).map(|b| b.size()).sum::<u64>()
            + self.points.iter().chain(&self.snaps).map(|b| b.size()).sum::<u64>()
    }
}

/// A storage buffer of the step (copied to and from), of at least one
/// element of the largest struct a binding holds: an empty list still binds
/// a buffer as large as the shader's element.
pub(super) fn storage_buffer(device: &wgpu::Device, label: &str, size: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size.max(64),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The buffers whose size follows the body count, for `room` bodies: the
/// poses, the batch's copy of them, the passes' working buffers (the
/// grid's hash table at the size `plan_grid` gives that many bodies) and
/// each body's pair bookkeeping.
struct BodyBuffers {
    states: [wgpu::Buffer; 2],
    batch_state: wgpu::Buffer,
    scratch: [wgpu::Buffer; 6],
    pair_meta: wgpu::Buffer,
}

impl BodyBuffers {
    fn new(device: &wgpu::Device, room: usize) -> BodyBuffers {
        let storage = |label: &str, size: u64| storage_buffer(device, label, size);
        let count = room as u64;
        let hash = hash_size(room) as u64;
        let state_bytes = count * size_of::<BodyState>() as u64;
        let vel0 = storage("vel0", count * size_of::<Velocity>() as u64);
        let cell_count = storage("grid/cell_count", 4 * hash);
        let cell_start = storage("grid/cell_start", 4 * (hash + 1));
        // block totals of the grid's scan and the pairs' (xy)
        let block_sums = storage("scan/block_sums", 8 * hash.max(count).div_ceil(SCAN_SPAN as u64));
        // the grid's order, then the step's listed bodies and those of them with
        // contacts (`listed_body`, `touching_body` in bindings.wgsl)
        let sorted = storage("grid/sorted", 12 * count);
        // the grid bodies' bounds in the grid's order (grid_sort, for the pair walks)
        let cell_bounds = storage("grid/cell_bounds", count * size_of::<CellBound>() as u64);
        BodyBuffers {
            states: [storage("state A", state_bytes), storage("state B", state_bytes)],
            batch_state: storage("batch start/state", state_bytes),
            scratch: [vel0, cell_count, cell_start, block_sums, sorted, cell_bounds],
            // one more: the pair scan's total
            pair_meta: storage("pairs/meta", (count + 1) * size_of::<PairMeta>() as u64),
        }
    }
}

/// The bodies' properties, exactly `n` of them (at least one element).
fn props_buffer(device: &wgpu::Device, n: usize) -> wgpu::Buffer {
    storage_buffer(device, "props", (n * size_of::<BodyProps>()) as u64)
}

/// Bytes of `WorldData::island_rest`: two words an island, at least one island's.
fn island_rest_bytes(joints: &JointLists) -> u64 {
    8 * u64::from(joints.islands.max(1))
}

fn island_rest_buffer(device: &wgpu::Device, joints: &JointLists) -> wgpu::Buffer {
    storage_buffer(device, "joints/island_rest", island_rest_bytes(joints))
}

/// Bytes of `WorldData::path_scratch`: where some paths are solved
/// directly, a slot for every joint of the paths (a path's slots follow its
/// place among them); else one.
fn path_scratch_bytes(joints: &JointLists) -> u64 {
    let (_, direct) = joints.path_kinds();
    16 * u64::from(PATH_SLOT) * if direct { u64::from(joints.path_joints().max(1)) } else { 1 }
}

fn path_scratch_buffer(device: &wgpu::Device, joints: &JointLists) -> wgpu::Buffer {
    storage_buffer(device, "joints/path_scratch", path_scratch_bytes(joints))
}

/// The statics (`WorldData::statics`), exactly as large as their lists.
fn statics_buffers(device: &wgpu::Device, statics: &Statics) -> [wgpu::Buffer; 4] {
    let Statics { large, hulls, joints } = *statics;
    [
        storage_buffer(device, "grid/large", (4 * large.len()) as u64),
        storage_buffer(device, "joints/start", (4 * joints.starts.len()) as u64),
        storage_buffer(device, "joints/refs", (joints.refs.len() * size_of::<JointRef>()) as u64),
        storage_buffer(device, "hulls", size_of_val(hulls) as u64),
    ]
}

/// Bytes of the Params slots of a batch: its substeps', each substep's own
/// and one per colour of joint paths.
fn params_bytes(substeps: u32, joints: &JointLists) -> u64 {
    let slots = MAX_BATCH.max(substeps as usize * (1 + joints.colour_count() as usize));
    PARAMS_STRIDE * slots as u64
}

/// The Params slots of a batch (`params_bytes`).
fn params_buffer(device: &wgpu::Device, substeps: u32, joints: &JointLists) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("params"),
        size: params_bytes(substeps, joints),
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}
