//! The library under careless and hostile use, as the command line's
//! hostile corpus tries the binary: each call refused with an error naming
//! the argument and why, nothing applied, nothing read or allocated beyond a
//! bound checked first, no panic and no hang.

use std::sync::Arc;

use crate::common::{gpu, temp_path, world};
use verlet::gpu::Gpu;
use verlet::limits::MAX_STEPS;
use verlet::render::Renderer;
use verlet::scene::Camera;
use verlet::scenes::{self, box_body};
use verlet::{Action, Body, Error, Event, Scene, Settings, Snapshot, Track, Wind, World};

fn free_scene(bodies: Vec<Body>) -> Scene {
    let settings = Settings { gravity: [0.0; 3], linear_damping: 0.0, angular_damping: 0.0, ..Settings::default() };
    Scene { settings, ground: None, bodies, joints: vec![], camera: None }
}

/// The message of an `Error::Input`, failing on any other outcome.
fn input_error(r: Result<(), Error>) -> String {
    match r {
        Err(Error::Input(msg)) => msg,
        other => panic!("expected Error::Input, got {other:?}"),
    }
}

fn assert_names(r: Result<(), Error>, name: &str) -> String {
    let msg = input_error(r);
    assert!(msg.starts_with(&format!("{name}:")), "error {msg:?} does not name {name:?}");
    msg
}

/// FNV-1a 64, the snapshot file's checksum.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// `bytes` (a snapshot file) with `edit` applied and the checksum made good.
fn crafted(bytes: &[u8], edit: impl Fn(&mut [u8])) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let end = out.len() - 8;
    edit(&mut out[..end]);
    let sum = fnv1a(&out[..end]);
    out[end..].copy_from_slice(&sum.to_le_bytes());
    out
}

#[test]
fn a_renderer_refuses_a_world_on_another_gpu() {
    let Some(first) = gpu() else { return };
    // a second Gpu of its own instance: wgpu's devices of the two compare equal
    let second = Arc::new(Gpu::new().expect("a second Gpu opens where the first did"));
    let scene = scenes::stack(2);
    let w = World::with_gpu(second, &scene).unwrap();
    let mut renderer = Renderer::new(&first, &scene, 64, 48).unwrap();
    let msg = input_error(renderer.render(&w).map(|_| ()));
    assert!(msg.contains("another Gpu"), "{msg}");
    // on its own Gpu it draws
    let mut own = Renderer::new(w.gpu(), &scene, 64, 48).unwrap();
    assert_eq!(own.render(&w).unwrap().dimensions(), (64, 48));
}

#[test]
fn snapshot_files_are_read_within_a_bound() {
    // endless: refused by its first bytes
    let msg = match Snapshot::read("/dev/zero") {
        Err(Error::Input(msg)) => msg,
        other => panic!("expected Error::Input, got {other:?}"),
    };
    assert!(msg.contains("not a verlet snapshot"), "{msg}");
    let dir = temp_path("hostile-snapshots");
    std::fs::create_dir_all(&dir).unwrap();
    // a valid header for one body (version 3), then far more than 121 bytes
    let mut header = b"VRLTSNAP".to_vec();
    header.extend_from_slice(&3u32.to_le_bytes());
    header.extend_from_slice(&1u32.to_le_bytes());
    header.resize(48, 0);
    for (name, len) in [("padded.snap", 10_000_000u64), ("huge.snap", 2 << 30)] {
        let path = dir.join(name);
        let file = std::fs::File::create(&path).unwrap();
        std::io::Write::write_all(&mut &file, &header).unwrap();
        file.set_len(len).unwrap(); // sparse: nothing written
        let msg = match Snapshot::read(&path) {
            Err(Error::Input(msg)) => msg,
            other => panic!("{name}: expected Error::Input, got {other:?}"),
        };
        let why = if len > 100_000_000 { "larger than a snapshot of the most bodies" } else { "1 bodies should be 121 bytes" };
        assert!(msg.contains(why), "{name}: {msg}");
    }
    // a header claiming more bodies than any world holds
    let mut many = header.clone();
    many[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(dir.join("many.snap"), &many).unwrap();
    let msg = format!("{:?}", Snapshot::read(dir.join("many.snap")).unwrap_err());
    assert!(msg.contains("more than a snapshot of the most bodies"), "{msg}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn step_counts_past_the_limits_are_refused_and_nothing_overflows() {
    let mut ground = box_body([0.5; 3], [0.0, 0.5, 0.0]);
    ground.fixed = true;
    let Some(mut w) = world(&Scene { bodies: vec![ground], ..scenes::stack(0) }) else { return };
    w.step(2).unwrap();
    assert!(w.at_rest(), "a world of a fixed body is at rest");
    let msg = assert_names(w.step(u64::MAX), "steps");
    assert!(msg.contains(&MAX_STEPS.to_string()), "{msg}");
    assert_eq!(w.step_count(), 2, "refused steps were counted");
    // past the latest time, though within the count
    assert_names(w.step(MAX_STEPS / 2), "steps");
    assert_names(w.step_with(&[1.0 / 60.0; 2]).and_then(|_| w.step(MAX_STEPS - 4)), "steps");
    assert_eq!(w.step_count(), 4);
    // what follows a refusal works
    w.apply_impulse(0, [0.0, 1.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    assert_eq!(w.step_count(), 5);
}

#[test]
fn step_with_checks_each_dt_as_the_scene_loader_does() {
    let Some(mut w) = world(&scenes::stack(3)) else { return };
    let raw = w.read_raw().unwrap();
    // a scene's dt of 10 is refused: its bodies would rest inside the ground
    let msg = assert_names(w.step_with(&[10.0; 5]), "dts[0]");
    assert!(msg.contains("inside the ground"), "{msg}");
    assert_names(w.step_with(&[1.0 / 60.0, 1e30]), "dts[1]");
    assert_names(w.step_with(&[1.0 / 60.0, 1.0 / 60.0, f32::NAN]), "dts[2]");
    assert_eq!((w.step_count(), w.read_raw().unwrap()), (0, raw), "a refused step_with stepped");
    // without a ground, the longest step a world takes
    let Some(mut free) = world(&free_scene(vec![box_body([0.5; 3], [0.0; 3])])) else { return };
    let msg = assert_names(free.step_with(&[0.5, 5.0]), "dts[1]");
    assert!(msg.contains("longer than 1 s"), "{msg}");
    let mut scene = free_scene(vec![box_body([0.5; 3], [0.0; 3])]);
    scene.settings.dt = 5.0;
    let err = scene.validate().unwrap_err();
    assert_eq!(err.field(), Some("settings.dt"), "{err}");
}

#[test]
fn absurd_impulses_forces_explosions_and_winds_are_refused() {
    let Some(mut w) = world(&scenes::stack(5)) else { return };
    let raw = w.read_raw().unwrap();
    let wind = Wind::steady([3.0, 0.0, 0.0]);
    type Call = Box<dyn Fn(&mut World) -> Result<(), Error>>;
    let cases: Vec<(Call, &str)> = vec![
        (Box::new(|w| w.apply_impulse(4, [1e30, 0.0, 0.0], None)), "impulse"),
        (Box::new(|w| w.apply_impulse_local(4, [0.0, -2e10, 0.0], [0.1; 3])), "impulse"),
        // the argument actually wrong, not the impulse made of them
        (Box::new(|w| w.apply_force(0, [1e30, 0.0, 0.0], None, 1e30)), "force"),
        (Box::new(|w| w.apply_force(0, [1.0, 0.0, 0.0], None, 1e30)), "duration"),
        (Box::new(|w| w.explode([0.0, 1.0, 0.0], 1e30, 6.0, 1.0)), "strength"),
        (Box::new(|w| w.explode([0.0, 1.0, 0.0], -1e30, 6.0, 1.0)), "strength"),
        (Box::new(|w| w.explode([0.0, 1.0, 0.0], 10.0, 1e30, 1.0)), "radius"),
        (Box::new(|w| w.explode([0.0, 1e7, 0.0], 10.0, 6.0, 1.0)), "centre"),
        (Box::new(move |w| w.apply_wind(&Wind { gust: 1e6, ..wind }, 0.1)), "wind.gust"),
        (Box::new(move |w| w.apply_wind(&Wind { air_density: 1e30, ..wind }, 0.1)), "wind.air_density"),
        (Box::new(move |w| w.apply_wind(&Wind { drag: 1e30, ..wind }, 0.1)), "wind.drag"),
        (Box::new(move |w| w.apply_wind(&wind, 1e30)), "duration"),
        (Box::new(move |w| w.apply_winds(&[(wind, 0.1), (Wind { gust: 1e6, ..wind }, 0.1)])), "winds[1].wind.gust"),
        (Box::new(move |w| w.apply_winds(&[(wind, 0.1), (wind, -1.0)])), "winds[1].duration"),
        (
            Box::new(|w| {
                w.apply_inputs(&[
                    verlet::BodyInput::Velocity { body: 0, linear: [1.0, 0.0, 0.0], angular: [0.0; 3] },
                    verlet::BodyInput::Impulse { body: 1, impulse: [0.0, 0.0, 1e30], point: verlet::Point::Centre },
                ])
            }),
            "inputs[1].impulse",
        ),
    ];
    for (call, name) in cases {
        let msg = assert_names(call(&mut w), name);
        assert!(msg.contains("sane") || msg.contains("longer than") || msg.contains(">= 0"), "{msg}");
    }
    assert_eq!(w.read_raw().unwrap(), raw, "a refused input was applied");
    // the largest sane impulse is taken, and a light body it throws is a fault, not a wreck
    w.apply_impulse(4, [verlet::limits::MAX_IMPULSE, 0.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    assert!(w.faults().unwrap().is_some(), "a body thrown past the limits was not stopped");
    assert!(w.read_raw().unwrap().iter().all(|s| s.pos.iter().chain(&s.disp).all(|x| x.is_finite())));
    // a track's events are held to the same limits
    let event = |action| Track::new(vec![Event { t: 0.0, action }]).unwrap_err().to_string();
    let msg = event(Action::Impulse { body: 0, impulse: [1e30, 0.0, 0.0], point: None });
    assert!(msg.starts_with("events[0].impulse.impulse: "), "{msg}");
    let msg = event(Action::Explode { centre: [0.0; 3], strength: 1e30, radius: 6.0, falloff: 1.0 });
    assert!(msg.starts_with("events[0].explode.strength: "), "{msg}");
    let msg = event(Action::Wind { wind: Wind { gust: 1e6, ..wind }, duration: 1.0 });
    assert!(msg.starts_with("events[0].wind.gust: "), "{msg}");
}

#[test]
fn track_events_at_absurd_times_are_refused_and_far_ones_do_not_overflow() {
    let kick = Action::Impulse { body: 0, impulse: [0.0, 1.0, 0.0], point: None };
    let err = Track::new(vec![Event { t: 1e300, action: kick.clone() }]).unwrap_err();
    assert_eq!(err.field(), Some("events[0].t"), "{err}");
    let far = Track::new(vec![Event { t: verlet::limits::MAX_TIME, action: kick }]).unwrap();
    // any dt a caller passes, however short: counted without overflow
    for dt in [1.0 / 60.0, 1e-5, 1e-30, f32::MIN_POSITIVE] {
        let next = far.next_input_step(0, dt).unwrap();
        assert!(next >= Track::step_of(1e12, 1.0), "dt {dt}: step {next}");
        assert!(far.acting_before(0..=u64::MAX, dt).len() == 1, "dt {dt}");
    }
    let Some(mut w) = world(&scenes::stack(1)) else { return };
    assert_eq!(far.apply(&mut w).unwrap(), 0, "an event a trillion seconds away acted now");
}

#[test]
fn crafted_snapshots_are_refused_before_anything_is_restored() {
    let Some(mut w) = world(&scenes::stack(3)) else { return };
    w.step(10).unwrap();
    let good = w.snapshot().unwrap().to_bytes();
    w.step(5).unwrap();
    let (raw, step) = (w.read_raw().unwrap(), w.step_count());
    // body k's pose begins at 48 + 64 k: pos, rest_time, disp, pos_low, rot, prev_rot
    let f32_at = |b: &mut [u8], at: usize, v: f32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
    let pose = |k: usize| 48 + 64 * k;
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (crafted(&good, |b| b[16..24].copy_from_slice(&u64::MAX.to_le_bytes())), "step"),
        (crafted(&good, |b| b[24..32].copy_from_slice(&1e300f64.to_le_bytes())), "time"),
        (crafted(&good, |b| f32_at(b, 32, 1e-30)), "dt_prev"),
        (crafted(&good, |b| f32_at(b, 32, 10.0)), "dt_prev"),
        (crafted(&good, |b| f32_at(b, pose(1), f32::NAN)), "non-finite"),
        (crafted(&good, |b| f32_at(b, pose(1) + 4, 3e6)), "from the origin"),
        (crafted(&good, |b| (0..4).for_each(|c| f32_at(b, pose(2) + 32 + 4 * c, 0.0))), "unit quaternion"),
        (crafted(&good, |b| f32_at(b, pose(0) + 16, 1e3)), "m/s"),
        (crafted(&good, |b| f32_at(b, pose(0) + 12, -1.0)), "negative"),
    ];
    let dir = temp_path("hostile-crafted");
    std::fs::create_dir_all(&dir).unwrap();
    for (bytes, why) in cases {
        let msg = Snapshot::from_bytes(&bytes).unwrap_err();
        assert!(msg.contains(why), "{why}: {msg}");
        let path = dir.join("crafted.snap");
        std::fs::write(&path, &bytes).unwrap();
        let err = Snapshot::read(&path).unwrap_err();
        assert!(matches!(&err, Error::Input(m) if m.contains(why)), "{why}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!((w.read_raw().unwrap(), w.step_count()), (raw, step), "the world changed");
    // the good one restores
    w.restore(&Snapshot::from_bytes(&good).unwrap()).unwrap();
    assert_eq!(w.step_count(), 10);
}

#[test]
fn set_dynamic_on_a_dynamic_body_sets_its_mass() {
    let Some(mut w) = world(&free_scene(vec![box_body([0.5; 3], [0.0; 3])])) else { return };
    w.set_velocity(0, [1.0, 0.0, 0.0], [0.0; 3]).unwrap();
    w.set_dynamic(0, 5.0).unwrap();
    let kept = w.read_state().unwrap()[0].linear_velocity;
    assert!((kept[0] - 1.0).abs() < 1e-4, "set_dynamic on a moving body changed its velocity: {kept:?}");
    w.apply_impulse(0, [10.0, 0.0, 0.0], None).unwrap();
    w.step(1).unwrap();
    let v = w.read_state().unwrap()[0].linear_velocity;
    assert!((v[0] - 3.0).abs() < 1e-3, "10 N s on 5 kg moving at 1 m/s gave {v:?}, not 3 m/s");
}

#[test]
fn a_worlds_own_snapshot_restores_after_fixed_and_back() {
    let mut scene = scenes::stack(3);
    scene.bodies[0].fixed = true; // loaded fixed: dynamic and back too
    let Some(mut w) = world(&scene) else { return };
    w.step(20).unwrap();
    let snapshot = w.snapshot().unwrap();
    w.set_fixed(2, true).unwrap();
    w.set_fixed(2, false).unwrap();
    w.set_fixed(0, false).unwrap();
    w.set_fixed(0, true).unwrap();
    w.set_dynamic(1, scene.bodies[1].mass).unwrap(); // the mass it has
    w.step(3).unwrap();
    w.restore(&snapshot).unwrap();
    w.step(30).unwrap();
    // as a world that never switched, restored from the same snapshot
    let mut plain = world(&scene).unwrap();
    plain.restore(&snapshot).unwrap();
    plain.step(30).unwrap();
    assert!(w.read_raw().unwrap() == plain.read_raw().unwrap(), "the switched world runs otherwise");
    // a mass it did not have is another scene
    w.set_dynamic(1, 2.0 * scene.bodies[1].mass).unwrap();
    let msg = input_error(w.restore(&snapshot));
    assert!(msg.contains("another scene"), "{msg}");
}

#[test]
fn a_camera_too_near_or_too_far_is_refused() {
    let Some(gpu) = gpu() else { return };
    let look = |position: [f32; 3], target: [f32; 3]| {
        let camera = Camera { position, target, fov_y: 0.8 };
        let scene = Scene { camera: Some(camera), ..scenes::stack(2) };
        Renderer::new(&gpu, &scene, 64, 48).err().map(|e| e.to_string())
    };
    let msg = look([1e-30, 1.0, 0.0], [0.0, 1.0, 0.0]).expect("a camera 1e-30 m from its target is refused");
    assert!(msg.starts_with("camera.target: "), "{msg}");
    let msg = look([1e30, 1.0, 0.0], [0.0, 1.0, 0.0]).expect("a camera 1e30 m away is refused");
    assert!(msg.starts_with("camera.position: "), "{msg}");
    assert_eq!(look([0.0, 2.0, 8.0], [0.0, 1.0, 0.0]), None);
}

#[test]
fn renderer_sizes_and_colours_name_their_argument() {
    let Some(gpu) = gpu() else { return };
    let scene = scenes::stack(2);
    for ((width, height), name) in [((0, 48), "width"), ((64, 0), "height"), ((1 << 30, 48), "width")] {
        match Renderer::new(&gpu, &scene, width, height) {
            Err(Error::Argument { name: n, reason }) => assert_eq!(n, name, "{reason}"),
            other => panic!("{width} x {height}: expected Error::Argument, got {:?}", other.err()),
        }
    }
    let w = World::with_gpu(gpu.clone(), &scene).unwrap();
    let mut renderer = Renderer::new(&gpu, &scene, 64, 48).unwrap();
    let before = renderer.render(&w).unwrap();
    assert_names(renderer.set_body_color(0, [0.5, f32::NAN, 0.5]), "srgb[1]");
    assert_names(renderer.set_body_color(1, [2.0, 0.5, 0.5]), "srgb[0]");
    assert_names(renderer.set_body_color(1, [0.5, 0.5, -0.1]), "srgb[2]");
    assert_names(renderer.set_body_color(7, [0.5; 3]), "index");
    assert!(renderer.render(&w).unwrap() == before, "a refused colour was painted");
}

#[test]
fn winds_and_explosions_given_together_act_as_one_by_one() {
    let scene = scenes::pile(40, 3);
    let (Some(mut together), Some(mut apart)) = (world(&scene), world(&scene)) else { return };
    let winds: Vec<(Wind, f32)> =
        (0..50).map(|k| (Wind { velocity: [3.0 + 0.1 * k as f32, 0.0, -1.0], gust: 0.3, ..Wind::default() }, 1.0 / 60.0)).collect();
    let blasts = [([0.0, 0.5, 0.0], 40.0, 4.0, 1.0), ([1.0, 0.0, 0.0], -25.0, 3.0, 2.0), ([0.0; 3], 10.0, 6.0, 0.0)];
    together.apply_winds(&winds).unwrap();
    for (wind, d) in &winds {
        apart.apply_wind(wind, *d).unwrap();
    }
    let events: Vec<Event> = blasts
        .iter()
        .map(|&(centre, strength, radius, falloff)| Event { t: 0.0, action: Action::Explode { centre, strength, radius, falloff } })
        .collect();
    Track::new(events).unwrap().apply(&mut together).unwrap();
    for (centre, strength, radius, falloff) in blasts {
        apart.explode(centre, strength, radius, falloff).unwrap();
    }
    let (a, b) = (together.read_raw().unwrap(), apart.read_raw().unwrap());
    assert!(a != w_at_start(&scene), "the winds did nothing");
    assert!(a == b, "inputs given together differ from the same given one by one");
    together.step(5).unwrap();
    apart.step(5).unwrap();
    assert!(together.read_raw().unwrap() == apart.read_raw().unwrap());
}

/// The poses a world of `scene` starts with.
fn w_at_start(scene: &Scene) -> Vec<verlet::gpu::types::BodyState> {
    world(scene).unwrap().read_raw().unwrap()
}
