//! Reading a world back: every body's pose and velocities, and the contact
//! points each body sees. Each is a blocking readback; the step loop never
//! reads anything back but the status record.

use std::mem::size_of;

use super::records::{body_output, from_mass_frame};
use super::World;
use crate::gpu::types::{BodyContact, BodyState, ContactManifold, ManifoldPoints, PairMeta};
use crate::step::Buffer;
use crate::Error;

/// The state of one body as a user sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyOutput {
    pub position: [f32; 3],
    /// Unit quaternion (x, y, z, w).
    pub orientation: [f32; 4],
    /// Velocity at the step's time (m/s), from Verlet's displacement over
    /// the last substep: exact in free fall, 0 at rest.
    pub linear_velocity: [f32; 3],
    /// World frame (rad/s).
    pub angular_velocity: [f32; 3],
    /// Whether the body sleeps (`Settings::sleeping`): held still until
    /// something moving touches it or an input wakes it.
    pub asleep: bool,
}

impl World {
    /// The contact points of every body as it sees them, from the last
    /// step's narrowphase, in its pair order (a blocking readback, for tests
    /// and debugging); local points in each body's own frame.
    pub fn read_contacts(&self) -> Result<Vec<Vec<BodyContact>>, Error> {
        let n = self.body_count as usize;
        if self.skipped {
            return Ok(vec![Vec::new(); n]);
        }
        let read = |b: &wgpu::Buffer| self.gpu.read_buffer(b, b.size());
        let meta: Vec<PairMeta> = bytemuck::pod_collect_to_vec(&read(&self.data.pair_meta)?);
        let lists: Vec<u32> = bytemuck::pod_collect_to_vec(&read(&self.data.body_pairs)?);
        let manifolds: Vec<ContactManifold> = bytemuck::pod_collect_to_vec(&read(&self.data.manifolds)?);
        // the parts in order: every part but the last used is full
        let mut points: Vec<ManifoldPoints> = Vec::new();
        for part in &self.data.points {
            points.extend(bytemuck::pod_collect_to_vec::<u8, ManifoldPoints>(&read(part)?));
        }
        // a point in the frame a body's pose is kept in, into its own
        let own = |body: u32, p: [f32; 3]| match self.scene.bodies.get(body as usize).and_then(|b| b.mass_frame()) {
            Some((centre, axes)) => (centre + axes * glam::DVec3::from_array(p.map(f64::from))).as_vec3().to_array(),
            None => p,
        };
        let mut out = vec![Vec::new(); n];
        for (i, list) in out.iter_mut().enumerate() {
            // contact references (shaders/narrowphase.wgsl's contact_lists)
            let first = meta[i].list_start as usize;
            let entries = lists.get(first..first + meta[i].contacts as usize).unwrap_or(&[]);
            for &r in entries {
                let (Some(m), Some(p)) = (manifolds.get(r as usize / 2), points.get(r as usize / 2)) else { continue };
                let me_a = r % 2 == 0;
                for pt in &p.at[..m.count as usize] {
                    let (local_self, partner, local_partner, sign) =
                        if me_a { (pt.local_a, m.b, pt.local_b, -1.0) } else { (pt.local_b, m.a, pt.local_a, 1.0) };
                    let (local_self, local_partner) = (own(i as u32, local_self), own(partner, local_partner));
                    list.push(BodyContact { local_self, partner, local_partner, normal: m.normal.map(|v| v * sign) });
                }
            }
        }
        Ok(out)
    }

    /// Reads every body's GPU state back as it is stored.
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn read_raw(&self) -> Result<Vec<BodyState>, Error> {
        let size = (self.body_count.max(1) as usize * size_of::<BodyState>()) as u64;
        let bytes = self.gpu.read_buffer(&self.data.states[self.current], size)?;
        let mut states: Vec<BodyState> = bytemuck::pod_collect_to_vec(&bytes);
        states.truncate(self.body_count as usize);
        Ok(states)
    }

    /// Reads every body's state back (a blocking readback). Fails with
    /// `Error::Diverged`, naming the body and the step, once the GPU has
    /// flagged a numerical fault (see [`World::faults`]; after
    /// [`World::clear_faults`] it reads again) or a state is not finite.
    pub fn read_state(&self) -> Result<Vec<BodyOutput>, Error> {
        let dt = self.dt_prev as f64;
        let states = self.read_raw()?;
        if let Some(fault) = self.faults()? {
            return Err(Error::Diverged(fault.to_string()));
        }
        // bodies gravity may not be accelerating: those on joints, kinematic ones
        let mut not_free: Vec<bool> = self.scene.bodies.iter().map(|b| b.kinematic).collect();
        not_free.resize(states.len(), false);
        for j in &self.scene.joints {
            for b in j.bodies {
                if let Some(k) = usize::try_from(b).ok().filter(|&k| k < not_free.len()) {
                    not_free[k] = true;
                }
            }
        }
        let gravity = self.settings.gravity;
        let mut out: Vec<BodyOutput> = states.iter().zip(&not_free).map(|(s, &j)| body_output(s, dt, gravity, j)).collect();
        // a hull's pose as its own frame's, not its centre of mass's and principal axes'
        for (o, b) in out.iter_mut().zip(&self.scene.bodies) {
            if let crate::scene::Shape::Hull(_) = b.shape {
                (o.position, o.orientation) = from_mass_frame(b, o.position, o.orientation);
            }
        }
        if let Some(k) = out.iter().position(|b| !finite_output(b)) {
            return Err(Error::Diverged(format!(
                "body {k} has a non-finite state after step {} (time {:.4} s)",
                self.step, self.time
            )));
        }
        Ok(out)
    }

    /// One of the step's buffers, read back as 32-bit words (tests).
    // For the crate's own tests, not part of the guide.
    #[doc(hidden)]
    pub fn read_words(&self, buffer: Buffer) -> Result<Vec<u32>, Error> {
        let b = self.data.buffer(buffer, self.current);
        Ok(bytemuck::pod_collect_to_vec(&self.gpu.read_buffer(b, b.size())?))
    }
}

fn finite_output(b: &BodyOutput) -> bool {
    b.position.iter().chain(&b.orientation).chain(&b.linear_velocity).chain(&b.angular_velocity).all(|v| v.is_finite())
}
