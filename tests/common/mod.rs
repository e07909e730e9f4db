//! Shared by the GPU tests: one adapter per test binary, and small helpers.
#![allow(dead_code)]

use std::sync::{Arc, OnceLock};

use verlet::gpu::Gpu;
use verlet::{Scene, World};

/// The shared GPU, or None (after a loud message) when no adapter exists and
/// `CI` is not set. Under CI a missing adapter fails the test.
pub fn gpu() -> Option<Arc<Gpu>> {
    static GPU: OnceLock<Option<Arc<Gpu>>> = OnceLock::new();
    GPU.get_or_init(|| match Gpu::new() {
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

/// A world on the shared GPU, or None when the test must skip.
pub fn world(scene: &Scene) -> Option<World> {
    let gpu = gpu()?;
    Some(World::with_gpu(gpu, scene).expect("scene uploads"))
}

pub fn v3(a: [f32; 3]) -> glam::Vec3 {
    glam::Vec3::from_array(a)
}

pub fn quat(a: [f32; 4]) -> glam::Quat {
    glam::Quat::from_array(a)
}
