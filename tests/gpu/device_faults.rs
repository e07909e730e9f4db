//! Device faults: a device destroyed in the middle of a
//! run makes the library return errors, never panic or hang.

use std::sync::{mpsc, Arc};
use std::time::Duration;

use verlet::gpu::Gpu;
use verlet::{scenes, World};

/// Runs `f` on its own thread; fails if it panics or takes longer than `limit`.
fn within<T: Send + 'static>(limit: Duration, what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(limit) {
        Ok(Ok(v)) => v,
        Ok(Err(p)) => {
            let msg = p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()));
            panic!("{what} panicked: {}", msg.unwrap_or_default())
        }
        Err(_) => panic!("{what} did not return within {limit:?}"),
    }
}

/// A GPU of its own: destroying the shared one would break the other tests.
fn own_gpu() -> Option<Arc<Gpu>> {
    crate::common::gpu()?;
    Some(Arc::new(Gpu::new().expect("a second device on the adapter")))
}

#[test]
fn destroyed_device_gives_errors_not_panics() {
    let Some(gpu) = own_gpu() else { return };
    let scene = scenes::cubes(100, 1);
    let mut world = World::with_gpu(gpu, &scene).unwrap();
    world.step(20).unwrap();
    world.read_state().unwrap();
    let result = within(Duration::from_secs(60), "step/read after destroy", move || {
        world.gpu().device.destroy();
        let stepped = world.step(20);
        let read = world.read_state();
        let raw = world.read_raw();
        let snap = world.snapshot();
        (stepped.err().map(|e| e.to_string()), read.err().map(|e| e.to_string()), raw.is_err(), snap.is_err())
    });
    eprintln!("after destroy: step {:?}, read_state {:?}", result.0, result.1);
    let (step_err, read_err, raw_err, snap_err) = result;
    assert!(step_err.is_some() || read_err.is_some(), "neither step nor read_state reported the lost device");
    let read_err = read_err.expect("read_state must fail on a destroyed device");
    assert!(raw_err && snap_err);
    assert!(!read_err.contains('\n'), "{read_err}");
    assert!(read_err.to_lowercase().contains("lost") || read_err.to_lowercase().contains("destroyed"), "{read_err}");
}

/// Destroyed while a long batch of steps is still in flight.
#[test]
fn device_destroyed_with_work_in_flight() {
    let Some(gpu) = own_gpu() else { return };
    let scene = scenes::cubes(500, 2);
    let mut world = World::with_gpu(gpu, &scene).unwrap();
    let read = within(Duration::from_secs(60), "read after destroy in flight", move || {
        world.step(200).unwrap();
        world.gpu().device.destroy();
        let _ = world.step(10);
        let read = world.read_state().map(|_| ()).map_err(|e| e.to_string());
        // later calls keep failing the same way, and still return
        let again = world.read_state().map(|_| ()).map_err(|e| e.to_string());
        (read, again)
    });
    let (first, again) = read;
    let first = first.expect_err("read_state after destroy");
    assert!(first.starts_with("GPU device lost: "), "{first}");
    assert_eq!(again.expect_err("second read_state"), first);
}

/// A world made on a device already destroyed is refused or fails at its
/// first readback; neither panics.
#[test]
fn world_on_a_destroyed_device_fails_cleanly() {
    let Some(gpu) = own_gpu() else { return };
    gpu.device.destroy();
    let outcome = within(Duration::from_secs(60), "world on a destroyed device", move || {
        match World::with_gpu(gpu.clone(), &scenes::cubes(10, 1)) {
            Err(e) => Err(e.to_string()),
            Ok(mut world) => {
                let _ = world.step(5);
                world.read_state().map(|_| ()).map_err(|e| e.to_string())
            }
        }
    });
    let e = outcome.expect_err("a destroyed device cannot read back");
    assert!(!e.contains('\n'), "{e}");
}
