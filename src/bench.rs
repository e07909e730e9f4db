//! The benchmark's workloads, shared by `verlet bench` (the harness, in
//! the binary: src/bin/verlet/bench/) and criterion's `benches/step.rs`: the named
//! cases, each a built-in scene at a size, and a memory-bound copy of the
//! state, the physical floor of a pass over the bodies. The library holds
//! no peer engine; the harness runs rapier3d beside these.

use std::time::Instant;

use crate::gpu::{types::*, Gpu};
use crate::scene::Scene;
use crate::{scenes, Error};

/// Seed of every random case, so a case name means one scene.
pub const SEED: u64 = 1;

/// The named cases: (name, built-in scene, count; `None`: the scene's
/// default). `cubes-1m` runs at the adapter's maximum when 1M does not fit.
/// `pile-*` are cubes dropped in four layers that land on each other and
/// heap up three and four deep (`verlet scene pile`); `capsules-*` the same
/// with capsules of random sizes (`verlet scene capsules`), `hulls-*` with
/// convex rocks (`verlet scene convex_pile`). `large_pyramid`,
/// `many_pyramids`, `joint_grid` and `washer` (8000 cubes in a drum of
/// kinematic hulls) are Box3D's benchmarks of those names at Box3D's sizes.
pub const CASES: &[(&str, &str, Option<usize>)] = &[
    ("cubes-1k", "cubes", Some(1_000)),
    ("cubes-10k", "cubes", Some(10_000)),
    ("cubes-100k", "cubes", Some(100_000)),
    ("cubes-1m", "cubes", Some(1_000_000)),
    ("pile-1k", "pile", Some(1_000)),
    ("pile-10k", "pile", Some(10_000)),
    ("pile-100k", "pile", Some(100_000)),
    ("pile-1m", "pile", Some(1_000_000)),
    ("capsules-1k", "capsules", Some(1_000)),
    ("capsules-10k", "capsules", Some(10_000)),
    ("hulls-1k", "convex_pile", Some(1_000)),
    ("hulls-10k", "convex_pile", Some(10_000)),
    ("pyramid", "pyramid", Some(20)),
    ("chain", "chain", Some(21)),
    ("large_pyramid", "large_pyramid", Some(100)),
    ("many_pyramids", "many_pyramids", Some(14)),
    ("joint_grid", "joint_grid", Some(100)),
    ("washer", "washer", Some(20)),
];

/// The cases `--quick` runs.
pub const QUICK_CASES: &[&str] = &["cubes-1k", "cubes-10k", "pyramid", "chain"];

/// One benchmark case: a built-in scene at a size.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Case {
    pub name: String,
    pub scene: String,
    pub count: Option<usize>,
}

impl Case {
    /// A named case (`CASES`) or `SCENE:COUNT` (`cubes:50000`, `pyramid:30`);
    /// a bad one is an [`Error::Argument`] named `spec`.
    pub fn parse(spec: &str) -> Result<Case, Error> {
        if let Some(&(name, scene, count)) = CASES.iter().find(|c| c.0 == spec) {
            return Ok(Case { name: name.into(), scene: scene.into(), count });
        }
        let (scene, count) = match spec.split_once(':') {
            Some((s, c)) => {
                let n: usize = c
                    .parse()
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| case_error(format!("{spec:?}: the count must be a positive integer")))?;
                (s, Some(n))
            }
            None => (spec, None),
        };
        if !scenes::NAMES.contains(&scene) {
            let named: Vec<&str> = CASES.iter().map(|c| c.0).collect();
            let known = scenes::NAMES;
            let all: Vec<&str> = named.iter().chain(known).copied().collect();
            let guess = scenes::closest(spec, &all).map_or(String::new(), |g| format!(" (did you mean {g}?)"));
            return Err(case_error(format!(
                "unknown case {spec:?}{guess}; named cases: {}; or SCENE[:COUNT] with SCENE one of {}",
                named.join(", "),
                known.join(", ")
            )));
        }
        // a count the scene takes no count of (`drop:5`) named a case of
        // one body "drop-5"
        if count.is_some() && scenes::default_count(scene).is_none() {
            return Err(case_error(format!("{spec:?}: the {scene} scene takes no count; give {scene:?}")));
        }
        // the count is checked before anything is built (a case of a
        // billion boxes would take the machine's memory): any adapter's
        // bound here, the adapter's own in `run_case`
        scenes::check(scene, count, scenes::MAX_BODIES).map_err(|e| case_error(format!("{spec:?}: {e}")))?;
        let name = match count {
            Some(n) => format!("{scene}-{n}"),
            None => scene.to_string(),
        };
        Ok(Case { name, scene: scene.into(), count })
    }

    /// The case's scene.
    pub fn scene(&self) -> Scene {
        scenes::by_name(&self.scene, self.count, SEED).expect("Case::parse checked the scene name")
    }
}

/// A named case by name (for `benches/step.rs` and tests); panics on an
/// unknown name.
pub fn case(name: &str) -> Case {
    Case::parse(name).unwrap_or_else(|e| panic!("{e}"))
}

// ---------------------------------------------------------------------------
// The memory-bound limit
// ---------------------------------------------------------------------------

const COPY_WGSL: &str = r#"
struct BodyState { pos: vec3<f32>, rest_time: f32, disp: vec3<f32>, pos_low: u32, rot: vec4<f32>, prev_rot: vec4<f32> }
struct Count { n: u32 }
@group(0) @binding(0) var<storage, read> src: array<BodyState>;
@group(0) @binding(1) var<storage, read_write> dst: array<BodyState>;
@group(0) @binding(2) var<uniform> count: Count;

@compute @workgroup_size(64)
fn copy_state(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i < count.n) {
        dst[i] = src[i];
    }
}
"#;

/// A trivial kernel copying `n` body states (64 bytes each) from one buffer
/// to another, one invocation per body in workgroups of 64 as the step's
/// passes are: the memory-bound floor of the integration pass.
pub struct CopyKernel {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    n: u32,
    _buffers: Vec<wgpu::Buffer>,
}

impl CopyKernel {
    pub fn new(gpu: &Gpu, n: usize) -> Result<CopyKernel, Error> {
        let device = &gpu.device;
        let bytes = (n.max(1) * std::mem::size_of::<BodyState>()) as u64;
        if bytes > gpu.limits.max_storage_buffer_binding_size.min(gpu.limits.max_buffer_size) {
            return Err(Error::Capacity(format!("copy kernel: {n} states do not fit one storage binding")));
        }
        let storage = |label: &str| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        let (src, dst) = (storage("copy/src"), storage("copy/dst"));
        let count = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("copy/count"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&count, 0, bytemuck::cast_slice(&[n as u32, 0, 0, 0]));
        let pipeline = gpu.compute_pipelines("copy_state", COPY_WGSL, &["copy_state"], None, &[]).remove(0);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("copy_state"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: src.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: dst.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: count.as_entire_binding() },
            ],
        });
        gpu.check()?;
        Ok(CopyKernel { pipeline, bind_group, n: n as u32, _buffers: vec![src, dst, count] })
    }

    /// Bytes one pass moves (read and written).
    pub fn bytes_per_pass(&self) -> u64 {
        2 * self.n as u64 * std::mem::size_of::<BodyState>() as u64
    }

    /// Times `passes` passes (ms each), as `World::profile` times the step's:
    /// GPU timestamps around each pass where the adapter has them, else each
    /// pass submitted and waited for alone under the wall clock.
    pub fn time(&self, gpu: &Gpu, passes: usize) -> Result<Vec<f64>, Error> {
        // a query set holds at most 4096 queries
        let mut out = Vec::with_capacity(passes.max(1));
        while out.len() < passes.max(1) {
            out.extend(self.time_some(gpu, (passes.max(1) - out.len()).min(1024))?);
        }
        Ok(out)
    }

    fn time_some(&self, gpu: &Gpu, passes: usize) -> Result<Vec<f64>, Error> {
        let passes = passes.max(1);
        let groups = self.n.div_ceil(WORKGROUP).max(1);
        let timestamps = gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let encode = |enc: &mut wgpu::CommandEncoder, writes: Option<wgpu::ComputePassTimestampWrites<'_>>| {
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("copy_state"), timestamp_writes: writes });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(groups, 1, 1);
        };
        if timestamps {
            let timer = crate::gpu::PassTimer::new(gpu, "copy_state", passes);
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            for k in 0..passes {
                encode(&mut enc, Some(timer.writes(k)));
            }
            timer.resolve(&mut enc);
            gpu.submit(enc.finish());
            Ok(timer.read_ms(gpu)?)
        } else {
            let mut out = Vec::with_capacity(passes);
            for _ in 0..passes {
                gpu.wait()?;
                let started = Instant::now();
                let mut enc = gpu.device.create_command_encoder(&Default::default());
                encode(&mut enc, None);
                gpu.submit(enc.finish());
                gpu.wait()?;
                out.push(started.elapsed().as_secs_f64() * 1e3);
            }
            Ok(out)
        }
    }
}

/// A case spec refused, naming the argument.
fn case_error(reason: String) -> Error {
    Error::Argument { name: "spec", reason }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_cases_parse_and_build() {
        for (name, scene, count) in CASES {
            let c = Case::parse(name).unwrap();
            assert_eq!(c.name, *name);
            if !name.ends_with("-1m") && !name.ends_with("-100k") {
                assert_eq!(Some(c.scene().bodies.len() as u64), scenes::body_count(scene, *count), "{name}");
            }
        }
        assert_eq!(case("many_pyramids").scene().bodies.len(), 10_780);
        assert_eq!(case("joint_grid").scene().joints.len(), 19_800);
        assert_eq!(case("washer").scene().bodies.len(), 8042);
        assert_eq!(case("hulls-1k").scene().bodies.len(), 1000);
        let c = Case::parse("cubes:2000").unwrap();
        assert_eq!((c.name.as_str(), c.count), ("cubes-2000", Some(2000)));
        assert!(Case::parse("nope").is_err());
        assert!(Case::parse("cubes:0").is_err());
        // a scene that takes no count
        let err = Case::parse("drop:5").unwrap_err().to_string();
        assert!(err.contains("the drop scene takes no count"), "{err}");
        assert_eq!(Case::parse("drop").unwrap().count, None);
    }
}
