//! Shared by the GPU tests: two devices on the adapter, and small helpers.
#![allow(dead_code)]

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

use verlet::gpu::Gpu;
use verlet::{Scene, World};

/// One of the two shared GPUs, or None (after a loud message) when no
/// adapter exists and `CI` is not set. Under CI a missing adapter fails the
/// test. The test threads take the two in turn and each keeps its own, so
/// two tests running side by side have a queue each and neither's readbacks
/// wait for the other's steps.
pub fn gpu() -> Option<Arc<Gpu>> {
    static GPUS: [OnceLock<Option<Arc<Gpu>>>; 2] = [OnceLock::new(), OnceLock::new()];
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    thread_local! {
        static MINE: usize = NEXT.fetch_add(1, Ordering::Relaxed) % 2;
    }
    let k = MINE.with(|&k| k);
    GPUS[k]
        .get_or_init(|| match Gpu::new() {
            Ok(gpu) => Some(Arc::new(gpu)),
            Err(e) => {
                if std::env::var_os("CI").is_some() {
                    panic!("CI is set but no GPU adapter was found: {e}");
                }
                eprintln!("\n!!!!! SKIPPING GPU TEST: no adapter ({e}) !!!!!\n");
                None
            }
        })
        .clone()
}

/// A world on this test's GPU, or None when the test must skip.
pub fn world(scene: &Scene) -> Option<World> {
    let gpu = gpu()?;
    Some(World::with_gpu(gpu, scene).expect("scene uploads"))
}

/// The settings a scene file that gives `iterations` alone gets: the
/// substeps `Settings::substeps_for` picks, the rest the defaults.
pub fn iterations_alone(iterations: u32) -> verlet::Settings {
    verlet::Settings { iterations, substeps: verlet::Settings::substeps_for(iterations), ..verlet::Settings::default() }
}

/// Steps `w` 30 at a time until at least `asleep` of its bodies sleep,
/// failing past `max_steps`; returns the steps taken.
pub fn step_until_asleep(w: &mut World, asleep: usize, max_steps: u64) -> u64 {
    let mut steps = 0;
    while w.read_state().unwrap().iter().filter(|b| b.asleep).count() < asleep {
        w.step(30).unwrap();
        steps += 30;
        assert!(steps <= max_steps, "fewer than {asleep} bodies asleep after {steps} steps");
    }
    steps
}

pub fn v3(a: [f32; 3]) -> glam::Vec3 {
    glam::Vec3::from_array(a)
}

pub fn quat(a: [f32; 4]) -> glam::Quat {
    glam::Quat::from_array(a)
}

/// A path under the system temp dir unique to this test run (nothing there).
pub fn temp_path(name: &str) -> std::path::PathBuf {
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos());
    let path = std::env::temp_dir().join(format!("verlet-test-{name}-{}-{nanos}", std::process::id()));
    let _ = std::fs::remove_dir_all(&path);
    path
}

/// Runs the `verlet` binary with `args`.
pub fn verlet(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_verlet")).args(args).output().expect("the verlet binary runs")
}

/// True when the run failed only for want of an adapter: a loud skip, or a
/// failure under CI (as `gpu` does for the library tests).
pub fn no_adapter(output: &std::process::Output) -> bool {
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.success() || !stderr.contains("no GPU adapter found") {
        return false;
    }
    if std::env::var_os("CI").is_some() {
        panic!("CI is set but the binary found no GPU adapter: {stderr}");
    }
    eprintln!("\n!!!!! SKIPPING GPU TEST: the binary found no adapter ({}) !!!!!\n", stderr.trim());
    true
}

/// A small deterministic generator (xorshift64) for the tests' random
/// scenes: the same numbers on every machine.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }

    /// A random unit quaternion (not uniform over rotations).
    pub fn quat(&mut self) -> glam::Quat {
        glam::Quat::from_xyzw(self.f() - 0.5, self.f() - 0.5, self.f() - 0.5, self.f() - 0.5).normalize()
    }
}

/// A fixed ramp (a 10 x 0.2 x 4 m slab) tilted 20 degrees about z, rising
/// towards +x, its centre at (0, 3, 0); with its tilt, and the point `lift`
/// above its top face 3.5 m up the slope from the centre (where a body
/// starts resting on it).
pub fn ramp(lift: f32) -> (verlet::Body, glam::Quat, glam::Vec3) {
    let tilt = glam::Quat::from_rotation_z(20f32.to_radians());
    let mut ramp = verlet::scenes::box_body([5.0, 0.1, 2.0], [0.0, 3.0, 0.0]);
    ramp.orientation = tilt.to_array();
    ramp.fixed = true;
    let start = glam::Vec3::new(0.0, 3.0, 0.0) + tilt * glam::Vec3::X * 3.5 + tilt * glam::Vec3::Y * (0.1 + lift);
    (ramp, tilt, start)
}
