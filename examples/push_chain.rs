//! A chain pushed by input: scripted (an input track, replayable with
//! `verlet run --input`) and direct (a call between steps, as a game's
//! loop would make it).
//!
//! ```sh
//! cargo run --release --example push_chain -- OUT_DIR
//! ```
//!
//! A 12-link chain hangs by both ends in the x-y plane. At t = 1 s the track
//! kicks its middle link along +z (out of the plane), at t = 2 s a direct
//! call kicks it back; the example prints the link's z as it swings and
//! writes the track to `OUT_DIR/push.json`.

mod common;

use verlet::track::{Action, Event, Track};
use verlet::{scenes, World};

fn main() -> std::process::ExitCode {
    common::main(|| {
        let out = common::out_dir("push_chain")?;
        let scene = scenes::hanging(12);
        let middle = scene.bodies.len() / 2;
        // N s: 3 m/s to the link alone; its neighbours share it through the joints
        let kick = scene.bodies[middle].mass * 3.0;

        // Scripted input: the same events `verlet run --input push.json` reads.
        let track =
            Track::new(vec![Event { t: 1.0, action: Action::Impulse { body: middle, impulse: [0.0, 0.0, kick], point: None } }])?;
        track.check(scene.bodies.len())?; // body indices against the scene, before anything runs
        let path = out.join("push.json");
        common::write(&path, track.to_json())?;

        let mut world = World::new(&scene)?;
        let dt = world.settings().dt;
        let steps = (3.0 / dt).round() as u64;
        let push_back = (2.0 / dt).round() as u64;
        println!("   t (s)   z of link {middle} (m)");
        while world.step_count() < steps {
            // the track's inputs due before this step (a no-op on most steps)
            track.apply(&mut world)?;
            if world.step_count() == push_back {
                // direct input: applied on the GPU before the next step, no readback
                world.apply_impulse(middle, [0.0, 0.0, -kick], None)?;
            }
            world.step(1)?;
            if world.step_count() % 15 == 0 {
                // one blocking readback of every body, a quarter-second apart
                let z = world.read_state()?[middle].position[2];
                println!("{:8.2} {z:18.3}", world.time());
            }
        }
        println!("replay it: verlet run --builtin hanging --count 12 --steps {steps} --input {}", path.display());
        Ok(())
    })
}
