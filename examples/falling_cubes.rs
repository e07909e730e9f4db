//! Falling cubes rendered off-screen to PNG frames: no window, no display
//! needed (a software adapter such as lavapipe will do).
//!
//! ```sh
//! cargo run --release --example falling_cubes -- OUT_DIR
//! ```
//!
//! Drops 64 unit cubes in four layers (the `pile` scene), steps 2.5 s and
//! writes a 480 x 320 frame every 1/6 s to `OUT_DIR/frame_000000.png`, ...
//! (the names `verlet run --frames` gives).

mod common;

use verlet::render::{self, Renderer};
use verlet::{scenes, World};

/// Steps between frames: at dt = 1/60 s, six frames a second.
const EVERY: u64 = 10;
/// Steps in all: 2.5 s, enough for the top layer to land.
const STEPS: u64 = 150;

fn main() -> std::process::ExitCode {
    common::main(|| {
        let out = common::out_dir("falling_cubes")?;
        let scene = scenes::pile(64, 7);
        let mut world = World::new(&scene)?;
        // The renderer draws on the world's own device, straight from its
        // state buffer: no readback of the bodies, one of the image.
        let mut renderer = Renderer::new(world.gpu(), &scene, 480, 320)?;
        loop {
            let frame = world.step_count() / EVERY;
            let path = out.join(verlet::output::frame_name(frame));
            render::write_png(&renderer.render(&world)?, &path)?;
            if world.step_count() >= STEPS {
                break;
            }
            // several steps go to the GPU at once; nothing is read back
            world.step(EVERY)?;
        }
        let lowest = world.read_state()?.iter().map(|b| b.position[1]).fold(f32::INFINITY, f32::min);
        println!(
            "{} frames of {} cubes over {:.1} s in {} (lowest centre at y = {lowest:.2} m)",
            STEPS / EVERY + 1,
            world.body_count(),
            world.time(),
            out.display()
        );
        Ok(())
    })
}
