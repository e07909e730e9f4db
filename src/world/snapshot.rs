//! Snapshots: a world's whole dynamic state (the current poses with the
//! displacements and turns from their previous poses, the sleepers an awake
//! body woke in the last step, the step counter, the time and the last
//! substep's length),
//! taken and restored through the API or a small binary file.
//!
//! What carries over from one step to the next is exactly this: every pass
//! that writes poses writes the other pose buffer's slot of every body it
//! runs over, so that buffer is overwritten before it is read, and a
//! sleeper the passes leave out (`listed_body` in shaders/bindings.wgsl)
//! holds the same pose in both (restoring writes both); the contact lists
//! are rebuilt by each step's narrowphase (their `pushed` budgets are reset
//! by the restitution pass), and the velocities the restitution pass
//! compares against are written by that step's integration for every body
//! that can move (an end that cannot counts as still).
//! One flag outlives a step: a sleeper the narrowphase found woken wakes at
//! the next step (the pose's `WAKES` bit, see integrate.wgsl). Restoring the
//! poses and `dt_prev` therefore continues bit for bit as the run the
//! snapshot was taken from (tests/gpu/snapshot.rs checks it).
//!
//! A snapshot names the scene it belongs to by a hash of the world's static
//! data (settings, ground, grid, the bodies' shapes, masses and materials,
//! and the joints), and restoring it into another scene is refused.
//!
//! A snapshot is checked as a scene is before anything of it is restored
//! (`Snapshot::problem`): every number finite, every quaternion of unit
//! length within `NORM_TOLERANCE`, positions, speeds and spins within
//! `SNAPSHOT_MARGIN` times the limits the step stops a body at, the last
//! substep within the limits a step's length is held to, the step count and
//! time within `limits::MAX_STEPS` and `limits::MAX_TIME`. Reading a file
//! reads its header first and then no more than the header says the file
//! holds, so a huge or endless file is refused at once.
//!
//! # File format (version 3, little-endian)
//!
//! | offset | size | field |
//! |-------:|-----:|-------|
//! | 0 | 8 | magic `VRLTSNAP` |
//! | 8 | 4 | version (u32) = 3 |
//! | 12 | 4 | body count n (u32) |
//! | 16 | 8 | step counter (u64) |
//! | 24 | 8 | simulated time, s (f64) |
//! | 32 | 4 | last substep's length, s (f32) |
//! | 36 | 4 | reserved, 0 |
//! | 40 | 8 | scene hash (u64) |
//! | 48 | 64 n | poses: `BodyState` as on the GPU |
//! | 48 + 64 n | n | each body's wake flags (0, or a sleeper woken: `WOKEN_LAST`, the pose's `WAKES` bit) |
//! | 48 + 65 n | 8 | FNV-1a 64 of all bytes before it |
//!
//! 56 bytes plus 65 bytes per body.
//!
//! Version 2 is version 3 without the wake flags; it is read with none set
//! (a sleeper woken in the step before it was taken then sleeps on until
//! something wakes it again). Version 1 held each body's previous position
//! (xyz, and w = 1 if a contact pushed it) where version 2 holds `disp` and
//! `pos_low`; it is read and converted: disp = pos - prev_pos (what version
//! 1's velocity was), no rounding remainder, and the flag as it was. Their
//! runs then continue as this build runs them, not bit for bit as the runs
//! they were taken from. The scene hash covers the joint lists as the GPU
//! holds them (the islands and the paths `solve_joints` and `solve_paths`
//! solve among them):
//! a snapshot of a scene with joints taken by a build that listed them
//! otherwise is refused as another scene's.

use std::path::Path;

use super::World;
use crate::gpu::types::{BodyProps, BodyState, PairMeta, HELD, SHAPE_HULL, WAKES, WOKEN_LAST, WOKEN_NOW};
use crate::Error;

const MAGIC: &[u8; 8] = b"VRLTSNAP";
const VERSION: u32 = 3;
/// The previous-position layout, still read (see the module documentation).
const VERSION_PREV_POS: u32 = 1;
const HEADER: usize = 48;
const TRAILER: usize = 8;
const POSE: usize = std::mem::size_of::<BodyState>();
/// The largest snapshot file: one of the most bodies any world holds.
const MAX_BYTES: u64 = (HEADER + TRAILER) as u64 + (POSE as u64 + 1) * crate::scenes::MAX_BODIES;
/// How far from 1 a quaternion's length may be: the GPU keeps them unit to
/// f32 rounding, far within it.
const NORM_TOLERANCE: f64 = 1e-3;
/// A body's position, speed and spin may be this many times the limits the
/// step stops a body at: the solve may push a body a little past them after
/// the step's check (the next step stops it), but no world holds more.
const SNAPSHOT_MARGIN: f64 = 2.0;

/// The dynamic state of a world at one step.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    step: u64,
    time: f64,
    dt_prev: f32,
    scene_hash: u64,
    states: Vec<BodyState>,
    /// Every body's wake flags: `WOKEN_LAST` for a sleeper woken in the
    /// last step, which wakes in the next (the pose's `WAKES` bit, also in
    /// `states`); `WOKEN_NOW`, which no step leaves, is read and restored
    /// too.
    woken: Vec<u8>,
}

impl Snapshot {
    /// Steps the world had taken.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Simulated time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Length of the last substep taken (s).
    pub fn dt_prev(&self) -> f32 {
        self.dt_prev
    }

    pub fn body_count(&self) -> usize {
        self.states.len()
    }

    /// The hash of the static data of the scene this snapshot belongs to.
    pub fn scene_hash(&self) -> u64 {
        self.scene_hash
    }

    /// The poses, as `World::read_raw` gives them.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn states(&self) -> &[BodyState] {
        &self.states
    }

    /// Every body's wake flags: not 0 for a sleeper woken in the last step,
    /// which wakes in the next.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn woken(&self) -> &[u8] {
        &self.woken
    }

    /// The file format of the module documentation.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER + (POSE + 1) * self.states.len() + TRAILER);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(self.states.len() as u32).to_le_bytes());
        out.extend_from_slice(&self.step.to_le_bytes());
        out.extend_from_slice(&self.time.to_le_bytes());
        out.extend_from_slice(&self.dt_prev.to_le_bytes());
        out.extend_from_slice(&0u32.to_le_bytes());
        out.extend_from_slice(&self.scene_hash.to_le_bytes());
        for s in &self.states {
            out.extend_from_slice(bytemuck::bytes_of(s));
        }
        out.extend_from_slice(&self.woken);
        let sum = fnv1a(FNV_OFFSET, &out);
        out.extend_from_slice(&sum.to_le_bytes());
        out
    }

    /// Parses the file format; anything else is refused with the reason.
    pub fn from_bytes(bytes: &[u8]) -> Result<Snapshot, String> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err("not a verlet snapshot (no VRLTSNAP header)".into());
        }
        if bytes.len() < HEADER + TRAILER {
            return Err(format!("truncated snapshot: {} bytes, a header alone takes {}", bytes.len(), HEADER + TRAILER));
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap());
        let f32_at = |at: usize| f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap());
        let version = u32_at(8);
        if !(VERSION_PREV_POS..=VERSION).contains(&version) {
            return Err(format!(
                "snapshot version {version} is not supported (this build reads versions {VERSION_PREV_POS} to {VERSION})"
            ));
        }
        let n = u32_at(12) as usize;
        let per_body = if version == VERSION { POSE + 1 } else { POSE };
        let expected = n.checked_mul(per_body).and_then(|p| p.checked_add(HEADER + TRAILER));
        if expected != Some(bytes.len()) {
            return Err(format!(
                "snapshot of {n} bodies should be {} bytes but is {} (truncated or padded)",
                expected.map_or("too many".to_string(), |e| e.to_string()),
                bytes.len()
            ));
        }
        if n as u64 > crate::scenes::MAX_BODIES {
            return Err(format!("snapshot of {n} bodies: no world holds more than {}", crate::scenes::MAX_BODIES));
        }
        let body_end = bytes.len() - TRAILER;
        let stored = u64_at(body_end);
        let actual = fnv1a(FNV_OFFSET, &bytes[..body_end]);
        if stored != actual {
            return Err(format!("snapshot is corrupt: checksum {stored:016x} stored, {actual:016x} computed"));
        }
        let step = u64_at(16);
        let time = f64::from_bits(u64_at(24));
        let dt_prev = f32_at(32);
        let scene_hash = u64_at(40);
        let states = (0..n)
            .map(|i| {
                let at = HEADER + i * POSE;
                let v4 = |k: usize| -> [f32; 4] { std::array::from_fn(|c| f32_at(at + 16 * k + 4 * c)) };
                let first = v4(0);
                let (pos, rest_time) = ([first[0], first[1], first[2]], first[3]);
                if version == VERSION_PREV_POS {
                    let prev = v4(1);
                    return BodyState {
                        pos,
                        rest_time,
                        disp: std::array::from_fn(|c| pos[c] - prev[c]),
                        pos_low: if prev[3] > 0.0 { HELD } else { 0 },
                        rot: v4(2),
                        prev_rot: v4(3),
                    };
                }
                let second = v4(1);
                BodyState {
                    pos,
                    rest_time,
                    disp: [second[0], second[1], second[2]],
                    pos_low: u32_at(at + 28),
                    rot: v4(2),
                    prev_rot: v4(3),
                }
            })
            .collect();
        let woken = if version == VERSION { bytes[HEADER + n * POSE..HEADER + n * (POSE + 1)].to_vec() } else { vec![0; n] };
        let snapshot = Snapshot { step, time, dt_prev, scene_hash, states, woken };
        match snapshot.problem() {
            Some(why) => Err(why),
            None => Ok(snapshot),
        }
    }

    /// What is absurd in the snapshot, if anything (see the module
    /// documentation): what a world cannot hold, whatever its scene.
    fn problem(&self) -> Option<String> {
        use crate::limits::{MAX_DISTANCE, MAX_DT, MAX_SPEED, MAX_SPIN, MAX_STEPS, MAX_TIME, MIN_SUBSTEP};
        if self.step > MAX_STEPS {
            return Some(format!("snapshot step {} is past {MAX_STEPS}, the most steps a world counts", self.step));
        }
        let time = self.time;
        if !(time.is_finite() && (0.0..=MAX_TIME).contains(&time)) {
            return Some(format!("snapshot time {time} is not a finite number of seconds from 0 to {MAX_TIME:e}"));
        }
        let h = self.dt_prev;
        // the substep of the shortest and the longest step a world takes
        let shortest = MIN_SUBSTEP as f64 * (1.0 - 1e-6);
        if !(h.is_finite() && h as f64 >= shortest && h <= MAX_DT) {
            return Some(format!("snapshot dt_prev {h} is not a substep a world takes (from {MIN_SUBSTEP:e} to {MAX_DT} s)"));
        }
        let margin = SNAPSHOT_MARGIN;
        let length = |v: &[f32]| v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
        for (i, (s, &w)) in self.states.iter().zip(&self.woken).enumerate() {
            let at = |field: &str| format!("snapshot body {i}: {field}");
            let words = [&s.pos[..], &s.disp[..], &s.rot[..], &s.prev_rot[..], &[s.rest_time][..]];
            if words.iter().any(|v| v.iter().any(|x| !x.is_finite())) {
                return Some(at("a non-finite number in its state"));
            }
            if s.rest_time < 0.0 {
                return Some(at(&format!("time at rest {} is negative", s.rest_time)));
            }
            let distance = length(&s.pos);
            if distance > margin * MAX_DISTANCE as f64 {
                return Some(at(&format!("lies {distance:.4e} m from the origin, beyond {MAX_DISTANCE:e} m")));
            }
            for (name, q) in [("orientation", s.rot), ("previous orientation", s.prev_rot)] {
                let norm = length(&q);
                if (norm - 1.0).abs() > NORM_TOLERANCE {
                    return Some(at(&format!("{name} {q:?} is not a unit quaternion (length {norm:.6})")));
                }
            }
            let speed = length(&s.disp) / h as f64;
            if speed > margin * MAX_SPEED as f64 {
                return Some(at(&format!("moves at {speed:.4e} m/s, beyond {MAX_SPEED:e} m/s")));
            }
            // the turn over the last substep, from the pose pair
            let dot = s.rot.iter().zip(&s.prev_rot).map(|(&a, &b)| a as f64 * b as f64).sum::<f64>();
            let turn = 2.0 * (dot.abs() / (length(&s.rot) * length(&s.prev_rot))).min(1.0).acos();
            let spin = turn / h as f64;
            if spin > margin * MAX_SPIN as f64 {
                return Some(at(&format!("spins at {spin:.4e} rad/s, beyond {MAX_SPIN:e} rad/s")));
            }
            if u32::from(w) > WOKEN_NOW | WOKEN_LAST {
                return Some(at(&format!("wake flags {w} are not 0 to 3")));
            }
        }
        None
    }

    /// Writes the snapshot to `path`.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), Error> {
        let path = path.as_ref();
        std::fs::write(path, self.to_bytes()).map_err(|source| Error::Io { path: path.display().to_string(), source })
    }

    /// Reads a snapshot written by `write`; a file that is not one, or is
    /// truncated or corrupt, is refused with the reason.
    /// Reads no more than the header says the file holds, and refuses a
    /// file larger than a snapshot of the most bodies any world holds before
    /// reading it.
    pub fn read(path: impl AsRef<Path>) -> Result<Snapshot, Error> {
        use std::io::Read;
        let path = path.as_ref();
        let io = |source| Error::Io { path: path.display().to_string(), source };
        let refuse = |why: String| Error::Input(format!("{}: {why}", path.display()));
        let file = std::fs::File::open(path).map_err(io)?;
        // a regular file's length is known before reading it (a device or a
        // pipe's is not: those are read with the bound alone)
        let known = file.metadata().ok().filter(|m| m.is_file()).map(|m| m.len());
        if let Some(len) = known.filter(|&len| len > MAX_BYTES) {
            return Err(refuse(format!(
                "{len} bytes is larger than a snapshot of the most bodies any world holds ({MAX_BYTES} bytes)"
            )));
        }
        let mut reader = file.take(MAX_BYTES + 1);
        let mut bytes = Vec::with_capacity(HEADER);
        (&mut reader).take(HEADER as u64).read_to_end(&mut bytes).map_err(io)?;
        // the header says how long the file is: read one byte more, to tell padding
        let (n, expected) = Snapshot::expected_len(&bytes).map_err(refuse)?;
        if expected > MAX_BYTES {
            return Err(refuse(format!(
                "snapshot of {n} bodies should be {expected} bytes, more than a snapshot of the most bodies any world \
                 holds ({MAX_BYTES} bytes)"
            )));
        }
        if let Some(len) = known.filter(|&len| len != expected) {
            return Err(refuse(format!("snapshot of {n} bodies should be {expected} bytes but is {len} (truncated or padded)")));
        }
        bytes.reserve((expected as usize).saturating_sub(HEADER));
        reader.take(expected + 1 - HEADER as u64).read_to_end(&mut bytes).map_err(io)?;
        Snapshot::from_bytes(&bytes).map_err(refuse)
    }

    /// The body count and the length of the file whose first bytes are
    /// `header`, from its version, or why those are not a snapshot's.
    fn expected_len(header: &[u8]) -> Result<(u64, u64), String> {
        if header.len() < MAGIC.len() || &header[..MAGIC.len()] != MAGIC {
            return Err("not a verlet snapshot (no VRLTSNAP header)".into());
        }
        if header.len() < HEADER {
            return Err(format!("truncated snapshot: {} bytes, a header alone takes {}", header.len(), HEADER + TRAILER));
        }
        let version = u32::from_le_bytes(header[8..12].try_into().expect("4 bytes"));
        let n = u32::from_le_bytes(header[12..16].try_into().expect("4 bytes")) as u64;
        if !(VERSION_PREV_POS..=VERSION).contains(&version) {
            return Err(format!(
                "snapshot version {version} is not supported (this build reads versions {VERSION_PREV_POS} to {VERSION})"
            ));
        }
        let per_body = if version == VERSION { POSE + 1 } else { POSE } as u64;
        Ok((n, (HEADER + TRAILER) as u64 + n * per_body))
    }
}

impl World {
    /// The world's dynamic state (a blocking readback of the current poses).
    pub fn snapshot(&self) -> Result<Snapshot, Error> {
        let states = self.read_raw()?;
        let now = self.read_pair_meta()?;
        let woken = states
            .iter()
            .zip(&now)
            .map(|(s, m)| (if s.pos_low & WAKES != 0 { WOKEN_LAST } else { 0 } | m.woken & WOKEN_NOW) as u8)
            .collect();
        Ok(Snapshot { step: self.step, time: self.time, dt_prev: self.dt_prev, scene_hash: self.scene_hash()?, states, woken })
    }

    /// Puts the world back in the state of `snapshot`, which must have been
    /// taken from a world of the same scene; stepping on from here gives
    /// bit for bit what the original world gave.
    pub fn restore(&mut self, snapshot: &Snapshot) -> Result<(), Error> {
        if let Some(why) = snapshot.problem() {
            return Err(Error::Input(why));
        }
        if snapshot.states.len() != self.body_count as usize {
            return Err(Error::Input(format!(
                "snapshot has {} bodies but this world has {}: it belongs to another scene",
                snapshot.states.len(),
                self.body_count
            )));
        }
        let hash = self.scene_hash()?;
        if snapshot.scene_hash != hash {
            return Err(Error::Input(format!(
                "snapshot belongs to another scene (scene hash {:016x}, this world's {hash:016x})",
                snapshot.scene_hash
            )));
        }
        if !snapshot.states.is_empty() {
            // the wake flags as the pose's bit (version 2 and older, and
            // older builds, kept them apart)
            let states: Vec<BodyState> = snapshot
                .states
                .iter()
                .zip(&snapshot.woken)
                .map(|(s, &w)| {
                    let wakes = if u32::from(w) & WOKEN_LAST != 0 { WAKES } else { 0 };
                    BodyState { pos_low: (s.pos_low & !WAKES) | wakes, ..*s }
                })
                .collect();
            // both state buffers: a sleeper the next step leaves as it is is
            // read from either (`listed_body` in bindings.wgsl)
            for to in &self.data.states {
                self.gpu.queue.write_buffer(to, 0, bytemuck::cast_slice(&states));
            }
            let mut meta = self.read_pair_meta()?;
            for (m, &w) in meta.iter_mut().zip(&snapshot.woken) {
                m.woken = u32::from(w) & WOKEN_NOW;
            }
            self.gpu.queue.write_buffer(&self.data.pair_meta, 0, bytemuck::cast_slice(&meta));
        }
        self.gpu.check()?;
        self.step = snapshot.step;
        self.time = snapshot.time;
        self.dt_prev = snapshot.dt_prev;
        // a snapshot may hold energy the scene did not begin with (inputs)
        self.speed_limits = false;
        self.at_rest = false;
        Ok(())
    }

    /// Every body's `PairMeta` (a blocking readback; the last entry, the
    /// scan's total, left out).
    fn read_pair_meta(&self) -> Result<Vec<PairMeta>, Error> {
        let bytes = self.gpu.read_buffer(&self.data.pair_meta, self.body_count as u64 * std::mem::size_of::<PairMeta>() as u64)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }

    /// FNV-1a 64 of what a world never changes after start-up: settings,
    /// ground, grid, and the GPU's copies of the body properties, the
    /// out-of-grid list and the joint lists (read back).
    fn scene_hash(&self) -> Result<u64, Error> {
        let s = &self.settings;
        let mut h = FNV_OFFSET;
        let mut put = |bytes: &[u8]| h = fnv1a(h, bytes);
        put(&self.body_count.to_le_bytes());
        for v in [
            s.dt,
            s.gravity[0],
            s.gravity[1],
            s.gravity[2],
            s.relaxation,
            s.linear_damping,
            s.angular_damping,
            s.restitution,
            s.friction,
        ] {
            put(&v.to_bits().to_le_bytes());
        }
        put(&s.iterations.to_le_bytes());
        put(&s.substeps.to_le_bytes());
        match self.ground {
            Some(g) => put(&[&[1u8][..], &g.to_bits().to_le_bytes()].concat()),
            None => put(&[0u8]),
        }
        put(&self.grid.cell_size.to_bits().to_le_bytes());
        put(&self.grid.hash_size.to_le_bytes());
        put(&self.grid.speculative.to_bits().to_le_bytes());
        put(&self.large_count.to_le_bytes());
        let props: Vec<BodyProps> = bytemuck::pod_collect_to_vec(&self.gpu.read_buffer(&self.data.props, self.data.props.size())?);
        for p in &props {
            put(&hashed_props(p));
        }
        // the hull records where there are hulls (a scene without keeps the hash it had)
        let hulls = props.iter().any(|p| p.shape == SHAPE_HULL);
        for buf in &self.data.statics[..if hulls { 4 } else { 3 }] {
            put(&self.gpu.read_buffer(buf, buf.size())?);
        }
        Ok(h)
    }
}

/// A body's properties as the scene hash reads them: the bytes BodyProps
/// had before the material, shape and flags were moved together (for the
/// contact passes, which read them in one load), so that snapshots from
/// before still belong; the speed limit zeroed, as it follows from the rest
/// (and was padding before it was added).
fn hashed_props(p: &BodyProps) -> [u8; 64] {
    let words: [u32; 16] = [
        p.half_extents[0].to_bits(),
        p.half_extents[1].to_bits(),
        p.half_extents[2].to_bits(),
        p.half_extents[3].to_bits(),
        p.inv_inertia[0].to_bits(),
        p.inv_inertia[1].to_bits(),
        p.inv_inertia[2].to_bits(),
        p.inv_inertia[3].to_bits(),
        p.restitution.to_bits(),
        p.friction.to_bits(),
        p.kept_inv_mass.to_bits(),
        0,
        p.shape,
        p.flags,
        p.grid_class,
        // what this word held before hulls, for a body that is not one
        if p.shape == SHAPE_HULL { p.hull } else { 0 },
    ];
    let mut bytes = [0u8; 64];
    for (out, w) in bytes.chunks_exact_mut(4).zip(words) {
        out.copy_from_slice(&w.to_le_bytes());
    }
    bytes
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;

fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
