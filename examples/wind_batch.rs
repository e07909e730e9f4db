//! Times a track whose 100k wind events are all due before the first step.
use std::time::Instant;
use verlet::{scenes, Action, Event, Track, Wind, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = scenes::stack(5);
    let mut world = World::new(&scene)?;
    let wind = Wind { velocity: [3.0, 0.0, 0.0], gust: 0.2, ..Wind::default() };
    let events: Vec<Event> =
        (0..100_000).map(|_| Event { t: 0.0, action: Action::Wind { wind, duration: 0.01 } }).collect();
    let track = Track::new(events)?;
    let start = Instant::now();
    let n = track.apply(&mut world)?;
    world.step(1)?;
    let s = world.read_state()?;
    println!("{n} events applied and a step taken in {:.2} s; body 4 at {:?} m/s", start.elapsed().as_secs_f64(), s[4].linear_velocity);
    Ok(())
}
