//! Edits through the library: adding and removing bodies in place, with
//! the device's compiled kernels kept; an edited world steps as one built
//! for its scene; a bad added body or joint is named as the caller passed
//! it; a recorded fault stays across edits until it is cleared.

use crate::common::{gpu, world};
use verlet::gpu::types::BodyState;
use verlet::scenes::{self, box_body};
use verlet::{Body, Error, Fault, FaultKind, Joint, Scene, Shape, World};

/// Five unit boxes on the ground, 10 m apart: they never touch.
fn row() -> Scene {
    let mut scene = scenes::stack(0);
    scene.bodies = (0..5).map(|k| box_body([0.5; 3], [10.0 * k as f32, 0.5, 0.0])).collect();
    scene
}

fn raw_bytes(w: &World) -> Vec<u8> {
    bytemuck::cast_slice::<BodyState, u8>(&w.read_raw().unwrap()).to_vec()
}

/// `scene` as `World::remove_body(index)` leaves it: the body and its
/// joints gone, later bodies one down.
fn without(scene: &Scene, index: usize) -> Scene {
    let mut scene = scene.clone();
    scene.bodies.remove(index);
    let gone = index as i32;
    scene.joints.retain(|j| !j.bodies.contains(&gone));
    for b in scene.joints.iter_mut().flat_map(|j| j.bodies.iter_mut()) {
        if *b > gone {
            *b -= 1;
        }
    }
    scene
}

/// Adds, removes and adds again on a pile with joints, growing the
/// buffers past their room and then within it: a world built for the
/// edited scene that restores the edited world's snapshot (the same scene
/// hash: properties, grid, out-of-grid bodies and joint lists alike) steps
/// on bit for bit as the edited world does.
#[test]
fn an_edited_world_steps_as_one_built_for_its_scene() {
    let mut scene = scenes::cubes(40, 4);
    let Some(mut w) = world(&scene) else { return };
    w.step(30).unwrap();
    // 30 more bodies: past the room of a world made for 40
    let added: Vec<Body> = (0..30).map(|k| box_body([0.4; 3], [(k % 6) as f32 - 3.0, 9.0 + (k / 6) as f32, 0.2])).collect();
    let joints = [
        Joint { bodies: [41, 42], anchors: [[0.4, 0.0, 0.0], [-0.4, 0.0, 0.0]] },
        Joint { bodies: [3, 40], anchors: [[0.0, 0.5, 0.0], [0.0, -0.4, 0.0]] },
    ];
    assert_eq!(w.add_bodies(&added, &joints).unwrap(), 40..70);
    scene.bodies.extend(added);
    scene.joints.extend(joints);
    w.step(20).unwrap();
    // within the room now: a removal, then a wide box kept out of the grid
    w.remove_body(3).unwrap();
    scene = without(&scene, 3);
    let wide = box_body([3.0, 0.2, 3.0], [0.0, 14.0, 0.0]);
    assert_eq!(w.add_bodies(std::slice::from_ref(&wide), &[]).unwrap(), 69..70);
    scene.bodies.push(wide);
    assert_eq!(w.body_count(), scene.bodies.len());

    let mut fresh = world(&scene).unwrap();
    fresh.restore(&w.snapshot().unwrap()).expect("the edited world's snapshot belongs to its scene");
    for steps in [1, 60] {
        w.step(steps).unwrap();
        fresh.step(steps).unwrap();
        assert!(raw_bytes(&w) == raw_bytes(&fresh), "the edited world parted from one built for its scene");
    }
    assert_eq!(w.faults().unwrap(), None);
}

/// A world outgrows its buffers once, then edits within their room take
/// the same buffers: nothing is made anew for the poses.
#[test]
fn edits_within_the_room_keep_the_worlds_buffers() {
    let Some(mut w) = world(&scenes::cubes(100, 4)) else { return };
    w.step(10).unwrap();
    w.add_bodies(&[box_body([0.5; 3], [0.0, 12.0, 0.0])], &[]).unwrap();
    let poses = w.current_state_buffer().clone();
    w.step(5).unwrap();
    w.remove_body(100).unwrap();
    assert!(&poses == w.current_state_buffer(), "a removal made new state buffers");
    let spawned: Vec<Body> = (0..20).map(|k| box_body([0.5; 3], [k as f32 * 1.2 - 12.0, 12.0, 0.0])).collect();
    w.add_bodies(&spawned, &[]).unwrap();
    assert!(&poses == w.current_state_buffer(), "an addition within the room made new state buffers");
    w.step(30).unwrap();
    assert_eq!(w.body_count(), 120);
    assert!(w.read_state().is_ok());
}

/// The last body removed leaves an empty world that steps; bodies added to
/// it then fall as in a world made with them.
#[test]
fn a_world_emptied_and_filled_again_steps_as_one_made_full() {
    let Some(mut w) = world(&scenes::stack(1)) else { return };
    w.step(10).unwrap();
    w.remove_body(0).unwrap();
    assert_eq!(w.body_count(), 0);
    w.step(10).unwrap();
    assert!(w.read_state().unwrap().is_empty());
    let scene = scenes::stack(3);
    assert_eq!(w.add_bodies(&scene.bodies, &[]).unwrap(), 0..3);
    let mut made = world(&scene).unwrap();
    made.restore(&w.snapshot().unwrap()).expect("the same scene");
    w.step(40).unwrap();
    made.step(40).unwrap();
    assert!(raw_bytes(&w) == raw_bytes(&made), "the refilled world parted from one made full");
}

/// The step's kernels are compiled once per device: the same source,
/// entry point, layouts and constants give the same pipeline, and the same
/// entries the same bind group layout.
#[test]
fn kernels_are_compiled_once_per_device() {
    let Some(gpu) = gpu() else { return };
    let source = "override SCALE: u32 = 1u;\n\
                  @group(0) @binding(0) var<storage, read_write> out: array<u32>;\n\
                  @compute @workgroup_size(1) fn main() { out[0] = SCALE; }\n";
    let entries = [wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }];
    let layout = gpu.bind_group_layout("test", &entries);
    assert!(layout == gpu.bind_group_layout("another label", &entries), "a second layout for the same entries");
    let compile = |scale: f64| gpu.compute_pipelines("test", source, &["main"], Some(&[&layout]), &[("SCALE", scale)]).remove(0);
    let first = compile(2.0);
    assert!(first == compile(2.0), "compiled again");
    assert!(first != compile(3.0), "another constant, the same pipeline");
    // two worlds and an edit on the device find the step's passes compiled
    let mut a = world(&scenes::stack(2)).unwrap();
    let _b = world(&scenes::cubes(10, 1)).unwrap();
    a.add_bodies(&[box_body([0.5; 3], [3.0, 0.5, 0.0])], &[]).unwrap();
    a.step(2).unwrap();
    gpu.check().unwrap();
}

/// A bad body is an input error naming it as passed (`bodies[1]`), not
/// the merged scene's body it would have become, and nothing changes.
#[test]
fn a_bad_added_body_is_named_as_passed_and_changes_nothing() {
    let Some(mut w) = world(&scenes::stack(3)) else { return };
    w.step(5).unwrap();
    let before = raw_bytes(&w);
    let good = box_body([0.5; 3], [3.0, 4.0, 0.0]);
    let mut nan = box_body([0.5; 3], [0.0, 9.0, 0.0]);
    nan.position[1] = f32::NAN;
    let flat = box_body([0.5, -1.0, 0.5], [0.0, 9.0, 0.0]);
    for (bad, field) in [(nan, "bodies[1].position[1]: "), (flat, "bodies[1].shape.half_extents[1]: ")] {
        match w.add_bodies(&[good.clone(), bad], &[]) {
            Err(Error::Input(why)) => assert!(why.starts_with(field), "{why}"),
            other => panic!("a bad body: {other:?}"),
        }
    }
    // a body too small for the world's settings (gravity of 1000 m/s^2
    // presses a 2 cm sphere a tenth of its radius into the ground)
    let mut heavy = scenes::stack(2);
    heavy.settings.gravity = [0.0, -1000.0, 0.0];
    let mut h = world(&heavy).unwrap();
    let tiny = Body::new(Shape::Sphere { radius: 0.02 }, [2.0, 1.0, 0.0]);
    match h.add_bodies(&[good.clone(), tiny], &[]) {
        Err(Error::Input(why)) => assert!(why.starts_with("bodies[1].shape: ") && why.contains("inside the ground"), "{why}"),
        other => panic!("a body too small for the settings: {other:?}"),
    }
    assert_eq!(h.body_count(), 2);
    assert_eq!(w.body_count(), 3);
    assert!(raw_bytes(&w) == before, "a refused edit moved the bodies");
    w.step(5).unwrap();
    assert!(w.read_state().is_ok());
}

/// A bad joint is an input error naming it as passed (`joints[0]`), though
/// the world has joints of its own; a joint to a new body is good.
#[test]
fn a_bad_added_joint_is_named_as_passed() {
    let scene = scenes::chain(3);
    let Some(mut w) = world(&scene) else { return };
    let link = box_body([0.5, 0.1, 0.1], [3.5, 5.0, 0.0]);
    let to_new = Joint { bodies: [2, 3], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] };
    let missing = Joint { bodies: [0, 9], anchors: [[0.0; 3], [0.0; 3]] };
    match w.add_bodies(std::slice::from_ref(&link), &[missing, to_new.clone()]) {
        Err(Error::Input(why)) => {
            assert!(why.starts_with("joints[0].bodies[1]: names body 9, but the scene has 4 bodies"), "{why}")
        }
        other => panic!("a joint to a missing body: {other:?}"),
    }
    let good = Joint { bodies: [0, 2], anchors: [[0.0; 3], [0.0; 3]] };
    let itself = Joint { bodies: [1, 1], anchors: [[0.0; 3], [0.0; 3]] };
    match w.add_bodies(&[], &[good, itself]) {
        Err(Error::Input(why)) => assert!(why.starts_with("joints[1].bodies: joins body 1 to itself"), "{why}"),
        other => panic!("a joint of a body to itself: {other:?}"),
    }
    assert_eq!(w.body_count(), 3);
    assert_eq!(w.add_bodies(&[link], &[to_new]).unwrap(), 3..4);
    w.step(30).unwrap();
    assert!(w.read_state().is_ok());
}

/// Poisons body `k`'s position in the state buffer (no input may).
fn poison(w: &World, k: usize) {
    let mut s = w.read_raw().unwrap()[k];
    s.pos[1] = f32::NAN;
    let at = (k * std::mem::size_of::<BodyState>()) as u64;
    w.gpu().queue.write_buffer(w.current_state_buffer(), at, bytemuck::bytes_of(&s));
}

/// A recorded fault is the caller's to clear: an edit, even one that adds
/// nothing, keeps it (a later body's renumbered when one before it goes).
#[test]
fn a_recorded_fault_stays_across_edits_until_cleared() {
    let Some(mut w) = world(&row()) else { return };
    w.step(5).unwrap();
    poison(&w, 3);
    w.step(5).unwrap();
    let fault = Fault { body: 3, step: 5, kind: FaultKind::NonFinite };
    assert_eq!(w.faults().unwrap(), Some(fault));
    w.add_bodies(&[], &[]).unwrap();
    assert_eq!(w.faults().unwrap(), Some(fault), "an empty edit cleared the fault");
    w.add_bodies(&[box_body([0.5; 3], [60.0, 0.5, 0.0])], &[]).unwrap();
    assert_eq!(w.faults().unwrap(), Some(fault), "an addition cleared the fault");
    w.remove_body(5).unwrap(); // a body after it: the fault keeps its index
    assert_eq!(w.faults().unwrap(), Some(fault));
    w.remove_body(1).unwrap(); // one before it: one down
    assert_eq!(w.faults().unwrap(), Some(Fault { body: 2, ..fault }));
    w.step(3).unwrap();
    match w.read_state() {
        Err(Error::Diverged(why)) => assert!(why.contains("body 2") && why.contains("step 5"), "{why}"),
        other => panic!("read_state with a fault recorded: {other:?}"),
    }
    w.clear_faults().unwrap();
    assert_eq!(w.faults().unwrap(), None);
    w.step(3).unwrap();
    assert_eq!(w.faults().unwrap(), None);
    assert!(w.read_state().is_ok());
}
