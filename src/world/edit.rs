//! Adding and removing bodies and joints while a world runs.
//!
//! The GPU buffers are sized for the bodies a world holds, so an edit builds
//! the world anew for the edited scene (new buffers, grid and joint lists,
//! checked against the adapter's limits before anything is allocated) and
//! carries every remaining body's pose and material across unchanged: one
//! readback of the poses and properties, one upload. The bodies that stay
//! continue exactly as they would have; contacts are found afresh on the
//! next step, so a removed body leaves none behind.

use std::ops::Range;

use super::{initial_state, scene_props, World};
use crate::gpu::types::{BodyProps, BodyState};
use crate::scene::{Body, Joint};
use crate::Error;

impl World {
    /// Adds `bodies` at rest (or with their own initial velocities) and
    /// `joints`, whose indices may name old and new bodies alike. Returns the
    /// indices the new bodies got. On an error (a bad body or joint, a scene
    /// beyond the adapter's limits) the world is left as it was.
    pub fn add_bodies(&mut self, bodies: &[Body], joints: &[Joint]) -> Result<Range<usize>, Error> {
        let old = self.body_count();
        let mut scene = self.scene.clone();
        scene.bodies.extend_from_slice(bodies);
        scene.joints.extend_from_slice(joints);
        let keep: Vec<Option<usize>> = (0..old).map(Some).collect();
        self.rebuild(scene, &keep)?;
        Ok(old..old + bodies.len())
    }

    /// Removes body `index` and every joint that names it. Bodies after it
    /// move down one index, and joints are renumbered to match.
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
        self.rebuild(scene, &keep)
    }

    /// Builds the world for `scene`, whose body `k` is the old body
    /// `keep[k]` for `k < keep.len()` and new beyond that.
    fn rebuild(&mut self, scene: crate::Scene, keep: &[Option<usize>]) -> Result<(), Error> {
        scene.validate()?;
        let old_states = self.read_raw()?;
        let props_bytes = self.gpu.read_buffer(&self.data.props, (self.body_count().max(1) * size_of::<BodyProps>()) as u64)?;
        let old_props: Vec<BodyProps> = bytemuck::pod_collect_to_vec(&props_bytes);
        let mut world = World::with_gpu(self.gpu.clone(), &scene)?;
        // what with_gpu uploaded, then the kept bodies put back over it
        let (mut props, _, _) = scene_props(&scene);
        let mut states: Vec<BodyState> = scene.bodies.iter().map(|b| initial_state(b, &scene.settings)).collect();
        for (k, from) in keep.iter().enumerate() {
            if let Some(from) = *from {
                states[k] = old_states[from];
                // an edit wakes every body (see `asleep` in common.wgsl)
                states[k].rest_time = 0.0;
                // mass, material and the fixed flag as the user last set them;
                // whether it sits in the grid is the new world's choice
                let grid_class = props[k].grid_class;
                props[k] = old_props[from];
                props[k].grid_class = grid_class;
            }
        }
        let queue = &world.gpu.queue;
        // both state buffers, as a world is made (`listed_body` in bindings.wgsl)
        for to in &world.data.states {
            queue.write_buffer(to, 0, bytemuck::cast_slice::<BodyState, u8>(&states));
        }
        queue.write_buffer(&world.data.props, 0, bytemuck::cast_slice::<BodyProps, u8>(&props));
        world.gpu.check()?;
        world.step = self.step;
        world.time = self.time;
        world.dt_prev = self.dt_prev;
        // the kept bodies' energy is not the scene's
        world.speed_limits = false;
        *self = world;
        Ok(())
    }
}
