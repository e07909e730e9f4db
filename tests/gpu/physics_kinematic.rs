//! Kinematic bodies: they move by their own velocities alone, exactly, and
//! push what they meet at their own speed, friction included; gravity,
//! contacts and joints never move them; an input changes their velocity.

use crate::common::{v3, world};
use glam::{Quat, Vec3};
use verlet::scenes::{self, box_body};

/// A kinematic paddle sliding along the ground at 2 m/s meets a box and
/// pushes it ahead at its own speed; the paddle keeps its course and speed
/// exactly, whatever it pushes.
#[test]
fn a_kinematic_paddle_pushes_a_box_at_its_own_speed() {
    let speed = 2.0f32;
    let mut scene = scenes::stack(0);
    let mut paddle = box_body([0.1, 0.5, 1.0], [-2.0, 0.55, 0.0]);
    paddle.kinematic = true;
    paddle.linear_velocity = [speed, 0.0, 0.0];
    scene.bodies = vec![paddle, box_body([0.5; 3], [0.0, 0.5, 0.0])];
    let Some(mut w) = world(&scene) else { return };
    w.step(120).unwrap(); // 2 s: the paddle meets the box after about 0.7 s
    let s = w.read_state().unwrap();
    let t = 120.0 * scene.settings.dt;
    let expected = -2.0 + speed * t;
    eprintln!(
        "paddle at {:?} (expected x {expected}), box at {:?} moving {:?}",
        s[0].position, s[1].position, s[1].linear_velocity
    );
    assert!((s[0].position[0] - expected).abs() < 1e-4, "the paddle is at {} instead of {expected}", s[0].position[0]);
    assert!(
        (v3(s[0].position) - Vec3::new(expected, 0.55, 0.0)).length() < 1e-4,
        "the paddle left its course: {:?}",
        s[0].position
    );
    assert!((v3(s[0].linear_velocity) - Vec3::new(speed, 0.0, 0.0)).length() < 1e-4, "{:?}", s[0].linear_velocity);
    assert!(v3(s[0].angular_velocity).length() < 1e-6);
    // the box rides just ahead of the paddle, at its speed
    let ahead = s[1].position[0] - s[0].position[0];
    assert!((ahead - 0.6).abs() < 0.02, "the box is {ahead} m ahead of the paddle's centre (0.6 touching)");
    assert!((s[1].linear_velocity[0] - speed).abs() < 0.05 * speed, "the box moves at {:?}", s[1].linear_velocity);
}

/// A kinematic box held in the air (no velocity) is not pulled by gravity
/// nor pushed by a box dropped on it, which comes to rest on top.
#[test]
fn a_kinematic_body_at_rest_holds_what_lands_on_it() {
    let mut scene = scenes::stack(0);
    let mut shelf = box_body([1.0, 0.1, 1.0], [0.0, 2.0, 0.0]);
    shelf.kinematic = true;
    scene.bodies = vec![shelf, box_body([0.3; 3], [0.1, 3.0, 0.0])];
    let Some(mut w) = world(&scene) else { return };
    w.step(240).unwrap();
    let s = w.read_state().unwrap();
    // to the position's rounding
    assert!((v3(s[0].position) - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-6, "the shelf moved: {:?}", s[0].position);
    assert_eq!(s[0].orientation, [0.0, 0.0, 0.0, 1.0], "the shelf turned");
    let top = s[1].position[1] - 0.3;
    assert!((top - 2.1).abs() < 0.01, "the box rests at {top} m, the shelf's top is at 2.1 m");
    assert!(v3(s[1].linear_velocity).length() < 0.01);
}

/// A kinematic turntable spinning at 1 rad/s carries a box on it round by
/// friction (it needs 1 m/s^2 towards the axis, friction gives up to 4.9):
/// started turning with the table, after a quarter turn the box has gone
/// a quarter of the way round the axis and turned with it.
#[test]
fn a_turning_kinematic_table_carries_a_box_round() {
    let w_spin = 1.0f32;
    let mut scene = scenes::stack(0);
    let mut table = box_body([2.0, 0.1, 2.0], [0.0, 0.5, 0.0]);
    table.kinematic = true;
    table.angular_velocity = [0.0, w_spin, 0.0];
    let mut carried = box_body([0.25; 3], [1.0, 0.85, 0.0]);
    carried.linear_velocity = [0.0, 0.0, -w_spin];
    carried.angular_velocity = [0.0, w_spin, 0.0];
    scene.bodies = vec![table, carried];
    let Some(mut w) = world(&scene) else { return };
    let steps = (std::f32::consts::FRAC_PI_2 / w_spin / scene.settings.dt).round() as u64;
    w.step(steps).unwrap();
    let s = w.read_state().unwrap();
    let turned = Quat::from_array(s[0].orientation).to_scaled_axis();
    let angle = steps as f32 * scene.settings.dt * w_spin;
    assert!((turned.y - angle).abs() < 1e-3 && turned.x.abs() < 1e-6 && turned.z.abs() < 1e-6, "the table turned {turned:?}");
    assert!((v3(s[0].position) - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-6, "the table moved: {:?}", s[0].position);
    // the box: carried round to -z (turning +y takes +x to -z), its own heading turned as far
    let at = v3(s[1].position);
    let round = (-at.z).atan2(at.x);
    let heading = Quat::from_array(s[1].orientation).to_scaled_axis().y;
    eprintln!("box at {at:?}: {round} rad round, heading {heading} rad; the table turned {angle} rad");
    assert!((Vec3::new(at.x, 0.0, at.z).length() - 1.0).abs() < 0.03, "the box slid off its circle: {at:?}");
    assert!((round - angle).abs() < 0.02 && (heading - angle).abs() < 0.02, "the box lags: {round} round, {heading} turned");
}

/// Setting a kinematic body's velocity changes its course from there on,
/// with no gravity; making it fixed or dynamic is refused naming the body.
#[test]
fn an_input_sets_a_kinematic_bodys_velocity() {
    let mut scene = scenes::stack(0);
    let mut lift = box_body([0.5; 3], [0.0, 3.0, 0.0]);
    lift.kinematic = true;
    scene.bodies = vec![lift];
    let Some(mut w) = world(&scene) else { return };
    w.step(30).unwrap();
    assert!((v3(w.read_state().unwrap()[0].position) - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-6);
    w.set_velocity(0, [0.0, 1.0, 0.0], [0.0; 3]).unwrap();
    assert!((v3(w.read_state().unwrap()[0].linear_velocity) - Vec3::Y).length() < 1e-5);
    w.step(60).unwrap();
    let s = w.read_state().unwrap()[0];
    assert!((s.position[1] - 4.0).abs() < 1e-4, "rose to {} m, 1 m/s for 1 s says 4", s.position[1]);
    let e = w.set_fixed(0, true).unwrap_err().to_string();
    assert!(e.contains("kinematic"), "{e}");
    assert!(w.set_dynamic(0, 5.0).is_err());
}

/// A ball hung on a ball joint from a kinematic body that moves at a steady
/// 1 m/s, started moving with it, hangs still below it as seen from the
/// body (Galilean invariance): the joint carries it along, and nothing it
/// does moves the kinematic body.
#[test]
fn a_ball_hung_from_a_moving_kinematic_body_is_carried_along() {
    let mut scene = scenes::stack(0);
    let mut carrier = box_body([0.2; 3], [0.0, 5.0, 0.0]);
    carrier.kinematic = true;
    carrier.linear_velocity = [1.0, 0.0, 0.0];
    let mut ball = verlet::Body::new(verlet::Shape::Sphere { radius: 0.2 }, [0.0, 3.6, 0.0]);
    ball.linear_velocity = [1.0, 0.0, 0.0];
    scene.bodies = vec![carrier, ball];
    scene.joints = vec![verlet::Joint { bodies: [0, 1], anchors: [[0.0, -0.2, 0.0], [0.0, 1.2, 0.0]] }];
    let Some(mut w) = world(&scene) else { return };
    w.step(300).unwrap();
    let s = w.read_state().unwrap();
    let below = v3(s[1].position) - v3(s[0].position);
    eprintln!("after 5 s the ball hangs at {below:?} from the carrier, moving {:?}", s[1].linear_velocity);
    assert!(
        (s[0].position[0] - 5.0).abs() < 1e-3 && (s[0].position[1] - 5.0).abs() < 1e-5,
        "the carrier strayed: {:?}",
        s[0].position
    );
    assert!((below - Vec3::new(0.0, -1.4, 0.0)).length() < 0.01, "the ball hangs at {below:?}");
    assert!((v3(s[1].linear_velocity) - Vec3::X).length() < 0.01, "the ball moves at {:?}", s[1].linear_velocity);
}
