//! Adding and removing bodies and joints while a world runs.
//!
//! An edit works in place: the world keeps its compiled passes and every
//! buffer that still holds the edited scene, and makes anew only what must
//! change size (the properties and the statics at their exact sizes; the
//! buffers sized by the body count once they are outgrown, then with room
//! for half as many bodies again). Every remaining body's pose and material
//! comes across unchanged: one readback of the poses and properties, one
//! upload, no compiling. The bodies that stay continue exactly as a world
//! built anew for the edited scene with their poses would; contacts are
//! found afresh on the next step, so a removed body leaves none behind.
//! The contact pools stay as they are and follow the need as always. A
//! recorded fault stays until `World::clear_faults`.

use std::mem::{offset_of, size_of};
use std::ops::Range;

use super::buffers::{Statics, WorldData};
use super::{capacity, initial_state, joint_lists, scene_props, World};
use crate::gpu::status::Status;
use crate::gpu::types::{BodyProps, BodyState};
use crate::limits::NO_FAULT;
use crate::load_error::LoadError;
use crate::scene::{Body, Joint, Scene};
use crate::step::Contents;
use crate::Error;

impl World {
    /// Adds `bodies` at rest (or with their own initial velocities) and
    /// `joints`, whose indices may name old and new bodies alike. Returns the
    /// indices the new bodies got. A bad body or joint is an
    /// [`Error::Input`] naming it as passed (`bodies[1].position[1]`,
    /// `joints[0].bodies[1]`). On an error (a bad body or joint, a scene
    /// beyond the adapter's limits) the world is left as it was.
    pub fn add_bodies(&mut self, bodies: &[Body], joints: &[Joint]) -> Result<Range<usize>, Error> {
        let old = self.body_count();
        let mut scene = self.scene.clone();
        scene.bodies.extend_from_slice(bodies);
        scene.joints.extend_from_slice(joints);
        check_added(&scene, bodies, joints)?;
        let keep: Vec<Option<usize>> = (0..old).map(Some).collect();
        self.edit(scene, &keep, None)?;
        Ok(old..old + bodies.len())
    }

    /// Removes body `index` and every joint that names it. Bodies after it
    /// move down one index, and joints are renumbered to match; so is a
    /// recorded fault of a later body (one of the removed body keeps its
    /// index).
    pub fn remove_body(&mut self, index: usize) -> Result<(), Error> {
        let n = self.body_count();
        if index >= n {
            return Err(Error::Input(format!("index: no body {index} (the world has {n})")));
        }
        let mut scene = self.scene.clone();
        scene.bodies.remove(index);
        let gone = index as i32;
        scene.joints.retain(|j| !j.bodies.contains(&gone));
        for j in &mut scene.joints {
            for b in &mut j.bodies {
                if *b > gone {
                    *b -= 1;
                }
            }
        }
        // the body now at k came from k, or from k + 1 past the removed one
        let keep: Vec<Option<usize>> = (0..n - 1).map(|k| Some(if k < index { k } else { k + 1 })).collect();
        self.edit(scene, &keep, Some(index))
    }

    /// Makes the world hold `scene`, whose body `k` is the old body
    /// `keep[k]` for `k < keep.len()` and new beyond that (`removed`: the
    /// body taken out, if one was). Everything that can fail (the
    /// adapter's limits, the readback, the allocations) comes before the
    /// world changes at all.
    fn edit(&mut self, scene: Scene, keep: &[Option<usize>], removed: Option<usize>) -> Result<(), Error> {
        let n = scene.bodies.len();
        capacity::check_capacity(&self.gpu, n)?;
        let joints = joint_lists(&scene);
        if scene.settings.sleeping {
            capacity::check_islands(&self.gpu, &joints, n)?;
        }
        self.gpu.check()?;

        // what the GPU holds of the bodies: poses, properties as the user
        // last set them, and the status record's fault
        let old_n = self.body_count().max(1);
        let read = self.gpu.read_buffers(&[
            (&self.data.states[self.current], (old_n * size_of::<BodyState>()) as u64),
            (&self.data.props, (old_n * size_of::<BodyProps>()) as u64),
            (&self.data.status, Status::BYTES),
        ])?;
        let old_states: Vec<BodyState> = bytemuck::pod_collect_to_vec(&read[0]);
        let old_props: Vec<BodyProps> = bytemuck::pod_collect_to_vec(&read[1]);
        let status: Status = bytemuck::pod_read_unaligned(&read[2]);

        // the records of a world made for the scene, the kept bodies put back over them
        let (mut props, large, grid, hulls) = scene_props(&scene);
        let mut states: Vec<BodyState> = Vec::with_capacity(n);
        for (k, body) in scene.bodies.iter().enumerate() {
            match keep.get(k).copied().flatten() {
                Some(from) => {
                    // an edit wakes every body (see `asleep` in common.wgsl)
                    states.push(BodyState { rest_time: 0.0, ..old_states[from] });
                    // mass, material and the fixed flag as the user last set
                    // them; whether it sits in the grid is the edited scene's choice
                    props[k] = BodyProps { grid_class: props[k].grid_class, hull: props[k].hull, ..old_props[from] };
                }
                None => states.push(initial_state(body, &scene.settings)),
            }
        }

        // outgrown buffers are made with room for half as many bodies again
        // (within what the adapter holds, checked above for n)
        let room = n.saturating_add(n / 2).min(capacity::max_bodies(&self.gpu) as usize).max(n);
        let statics = Statics { large: &large, hulls: &hulls, joints: &joints };
        let mut data = self.refit(n, room, &statics)?;

        // from here on nothing fails but a lost device
        data.upload(&self.gpu, &props, &states, &statics);
        self.reset_status(&data, &status, removed);
        let mut encoder = self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("edit") });
        // no body has woken another yet (`PairMeta::woken`), and no contacts
        encoder.clear_buffer(&data.pair_meta, 0, None);
        self.gpu.submit(encoder.finish());
        self.pipelines.hold(&self.gpu, Contents::of(&scene));
        data.bind_groups = Some(data.step_bind_groups(&self.gpu.device, &self.pipelines));
        self.gpu.check()?;

        // the input kernels' bind groups name the old property buffer: they
        // are made again on the next input (their kernels are kept)
        self.input = None;
        self.data = data;
        self.grid = grid;
        self.large_count = large.len() as u32;
        self.body_count = n as u32;
        self.island_count = joints.islands;
        self.island_joints = joints.island_joints(n);
        self.path_kinds = joints.path_kinds();
        self.path_colours = joints.colours;
        self.scene = scene;
        // both state buffers hold the poses
        self.current = 0;
        // the kept bodies' energy is not the scene's
        self.speed_limits = false;
        self.at_rest = false;
        self.skipped = false;
        Ok(())
    }

    /// The world's buffers made over for `n` bodies (`WorldData::refit`),
    /// or why they could not be had: the allocations run in an error scope
    /// of their own, so that a refusal leaves the world and its device as
    /// they were.
    fn refit(&self, n: usize, room: usize, statics: &Statics) -> Result<WorldData, Error> {
        let device = &self.gpu.device;
        let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let data = self.data.refit(&self.gpu, n, room, statics, self.settings.substeps);
        let errors = [pollster::block_on(validation.pop()), pollster::block_on(memory.pop())];
        match errors.into_iter().flatten().next() {
            Some(e) => Err(Error::Capacity(format!(
                "the edited scene's {n} bodies: the GPU refused their buffers: {}",
                e.to_string().replace('\n', " ")
            ))),
            None => Ok(data),
        }
    }

    /// The status record as a world made anew has it, but for what the
    /// caller has not yet been told or cleared: the recorded fault (a later
    /// body's renumbered past `removed`) and the flags no step clears.
    fn reset_status(&self, data: &WorldData, status: &Status, removed: Option<usize>) {
        let init = bytemuck::bytes_of(&Status::INIT);
        let words = |from: usize, to: usize| (from, &init[from..to]);
        let fault = offset_of!(Status, fault);
        let after_fault = offset_of!(Status, manifolds);
        for (at, bytes) in [words(0, fault), words(after_fault, offset_of!(Status, walks_cut))] {
            self.gpu.queue.write_buffer(&data.status, at as u64, bytes);
        }
        let body = (status.fault / 8) as usize;
        if removed.is_some_and(|gone| status.fault != NO_FAULT && body > gone) {
            // 8 x body + kind (`Status::fault`): one body down
            self.gpu.queue.write_buffer(&data.status, fault as u64, bytemuck::bytes_of(&(status.fault - 8)));
        }
    }
}

/// Refuses a bad added body or joint, naming it as the caller passed it:
/// `scene` is the world's scene with `bodies` and `joints` appended.
fn check_added(scene: &Scene, bodies: &[Body], joints: &[Joint]) -> Result<(), Error> {
    let input = |e: LoadError| Error::Input(e.to_string());
    for (k, body) in bodies.iter().enumerate() {
        crate::scene::validate_body(body, &format!("bodies[{k}]"), &scene.settings).map_err(input)?;
    }
    for (k, joint) in joints.iter().enumerate() {
        crate::scene::validate_joint(joint, scene.bodies.len(), &format!("joints[{k}]")).map_err(input)?;
    }
    if scene.ground.is_some() {
        if let Err(e) = crate::scene::check_sink(&scene.settings, &scene.bodies) {
            let why = match e {
                LoadError::Invalid { message, .. } => message,
                e => e.to_string(),
            };
            // the world's own bodies passed: the smallest new movable body is to blame
            let smallest = (0..bodies.len())
                .filter(|&k| bodies[k].is_dynamic())
                .min_by(|&a, &b| bodies[a].bounding_radius().total_cmp(&bodies[b].bounding_radius()))
                .unwrap_or(0);
            return Err(Error::Input(format!("bodies[{smallest}].shape: too small for the world's settings: {why}")));
        }
    }
    Ok(())
}
