//! Stepping with readback of body states: a bouncing ball traced step by
//! step, written as CSV.
//!
//! ```sh
//! cargo run --release --example readback -- OUT_DIR
//! ```
//!
//! The `sphere` scene drops a ball of radius 0.5 m (restitution 0.8) from
//! 5 m. Every step is read back (`World::read_state`, one blocking copy of
//! every body's state to the host) and written to `OUT_DIR/ball.csv` (t in
//! s, y in m, vy in m/s, asleep); the tops of the bounces are printed.
//! Reading back every step is for tracing: `World::step(n)` with one
//! readback at the end is far faster.

mod common;

use std::fmt::Write as _;

use verlet::{scenes, World};

/// Steps to trace: 4 s at dt = 1/60 s.
const STEPS: u64 = 240;

fn main() -> std::process::ExitCode {
    common::main(|| {
        let out = common::out_dir("readback")?;
        let mut world = World::new(&scenes::sphere())?;
        let mut csv = String::from("t,y,vy,asleep\n");
        let mut rising = false;
        let mut apexes = Vec::new();
        for _ in 0..STEPS {
            world.step(1)?;
            let ball = world.read_state()?[0];
            let (y, vy) = (ball.position[1], ball.linear_velocity[1]);
            let _ = writeln!(csv, "{:.4},{y:.5},{vy:.5},{}", world.time(), ball.asleep);
            // the top of a bounce: the vertical velocity turns from up to down
            if rising && vy <= 0.0 {
                apexes.push((world.time(), y));
            }
            rising = vy > 0.0;
        }
        let path = out.join("ball.csv");
        common::write(&path, csv)?;
        println!("{STEPS} steps traced to {}", path.display());
        // the ball starts with its bottom 4.5 m up; each bounce keeps about
        // restitution^2 of the height
        let mut height = 4.5;
        for (t, y) in apexes {
            let bottom = y - 0.5;
            let kept = 100.0 * bottom / height;
            println!("top of a bounce at t = {t:.2} s: {bottom:.2} m up ({kept:.0}% of the one before)");
            height = bottom;
        }
        Ok(())
    })
}
