//! Timing the step stage by stage (`verlet run --profile`, the bench).

use super::World;
use crate::step::Stage;
use crate::Error;

/// Time per step spent in each stage (ms), from `World::profile`.
#[derive(Clone, Debug)]
pub struct StageTimes {
    pub ms_per_step: Vec<(Stage, f64)>,
    /// True: GPU timestamp queries; false: wall clock around each pass.
    pub gpu_timestamps: bool,
}

impl World {
    /// Takes `steps` steps of `settings.dt` one at a time, timing every pass:
    /// with GPU timestamp queries where the adapter has them, else by the
    /// wall clock around each pass submitted and waited for alone (which
    /// adds the submission's overhead to every pass).
    pub fn profile(&mut self, steps: u64) -> Result<StageTimes, Error> {
        let plan = self.step_plan();
        let substeps = self.settings.substeps as usize;
        let passes = plan.len();
        let mut totals = [0.0f64; Stage::ALL.len()];
        let gpu = self.gpu.clone();
        let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let timer = timestamps.then(|| crate::gpu::PassTimer::new(&gpu, "profile", passes));
        let mut step = 0;
        while step < steps {
            self.skipped = false;
            self.shrink_pools()?;
            let start = self.batch_start();
            let before = totals;
            let dt = [self.settings.dt];
            self.write_params(&dt, substeps);
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            self.copy_batch_start(&mut encoder);
            for (k, &(stage, slot)) in plan.iter().enumerate() {
                match &timer {
                    Some(timer) => self.encode_pass(&mut encoder, stage, slot, Some(timer.writes(k))),
                    None => {
                        gpu.submit(encoder.finish());
                        gpu.wait()?;
                        let started = std::time::Instant::now();
                        encoder = gpu.device.create_command_encoder(&Default::default());
                        self.encode_pass(&mut encoder, stage, slot, None);
                        gpu.submit(encoder.finish());
                        gpu.wait()?;
                        totals[stage as usize] += started.elapsed().as_secs_f64() * 1e3;
                        encoder = gpu.device.create_command_encoder(&Default::default());
                    }
                }
            }
            if let Some(timer) = &timer {
                timer.resolve(&mut encoder);
            }
            gpu.submit(encoder.finish());
            if let Some(timer) = &timer {
                for ((stage, _), ms) in plan.iter().zip(timer.read_ms(&gpu)?) {
                    totals[*stage as usize] += ms;
                }
            }
            self.finish_steps(&dt, substeps);
            if self.fit_pools(1)? {
                // a pool overflowed: the step is taken again (as step_with
                // does), its first timing dropped
                self.restore_batch_start(start);
                totals = before;
                continue;
            }
            step += 1;
        }
        let n = steps.max(1) as f64;
        Ok(StageTimes {
            ms_per_step: Stage::ALL.iter().map(|&s| (s, totals[s as usize] / n)).collect(),
            gpu_timestamps: timestamps,
        })
    }
}
