//! The GPU narrowphase gives the CPU reference's manifolds: random pairs of
//! boxes and spheres (thin slabs and needles among them), each pair far from
//! the others, one step, contacts read back and compared point by point;
//! capsules and hulls against every shape, and hulls on the ground.

use crate::common::world;
use crate::common::Rng;
use glam::{Quat, Vec3};
use verlet::limits::CONTACT_MARGIN;
use verlet::reference::collide::{collide, Placed, ShapeKind};
use verlet::reference::hull::ground_hull;
use verlet::scene::HullShape;
use verlet::scenes::{box_body, sphere_body};
use verlet::world::initial_state;
use verlet::{Body, Ground, Scene, Settings, Shape};

fn random_body(rng: &mut Rng, k: usize, at: Vec3) -> Body {
    let mut b = match k % 5 {
        0 => sphere_body(0.2 + 0.5 * rng.f(), at.to_array()),
        1 => box_body([0.4 + rng.f(), 0.01 + 0.02 * rng.f(), 0.4 + rng.f()], at.to_array()), // slab
        2 => box_body([0.4 + rng.f(), 0.01 + 0.02 * rng.f(), 0.01 + 0.02 * rng.f()], at.to_array()), // needle
        _ => box_body([0.1 + 0.6 * rng.f(), 0.1 + 0.6 * rng.f(), 0.1 + 0.6 * rng.f()], at.to_array()),
    };
    b.orientation = rng.quat().to_array();
    b
}

/// A body as the reference places it: a hull in its own frame, as the
/// contacts read back are; any other at the pose the GPU starts from.
fn placed(b: &Body, settings: &Settings) -> Placed {
    let shape = ShapeKind::from(&b.shape);
    if let Shape::Hull(_) = b.shape {
        return Placed { centre: Vec3::from_array(b.position), rot: Quat::from_array(b.orientation).normalize(), shape };
    }
    let s = initial_state(b, settings);
    Placed { centre: Vec3::from_array(s.pos), rot: Quat::from_array(s.rot), shape }
}

/// Pairs from `body(rng, k, at)` (the second placed at random within reach
/// of the first), far apart from each other, stepped once with no gravity:
/// the pairs that touch, and those whose GPU manifold differs from the CPU
/// reference's.
fn compare(seed: u64, pairs: usize, body: impl Fn(&mut Rng, usize, Vec3) -> Body) -> Option<(usize, Vec<String>)> {
    let settings = Settings { gravity: [0.0; 3], ..Settings::default() };
    let mut rng = Rng(seed);
    let mut bodies = Vec::new();
    for k in 0..pairs {
        let origin = Vec3::new((k % 20) as f32 * 20.0, 10.0, (k / 20) as f32 * 20.0);
        let a = body(&mut rng, k, origin);
        let reach = a.bounding_radius() + 0.8;
        let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Y);
        let at = origin + dir * reach * rng.f();
        let b = body(&mut rng, k / 5 + k, at);
        bodies.push(a);
        bodies.push(b);
    }
    let scene = Scene { settings, ground: None, bodies, joints: vec![], camera: None };
    let mut w = world(&scene)?;
    w.step(1).unwrap();
    let contacts = w.read_contacts().unwrap();
    let tol = 2e-3;
    let (mut touching, mut mismatched) = (0, Vec::new());
    for k in 0..pairs {
        let (i, j) = (2 * k, 2 * k + 1);
        let (pa, pb) = (placed(&scene.bodies[i], &settings), placed(&scene.bodies[j], &settings));
        // at rest, no gravity: the speculative margin is the fixed contact margin
        let cpu = collide(&pa, &pb, CONTACT_MARGIN);
        let gpu = &contacts[i];
        assert!(gpu.iter().all(|c| c.partner == j as u32), "pair {k}: contact with a body of another pair");
        assert_eq!(contacts[j].len(), gpu.len(), "pair {k}: the two bodies hold different counts");
        let Some(m) = cpu else {
            if !gpu.is_empty() {
                mismatched.push(format!("pair {k}: GPU found {} points, CPU none", gpu.len()));
            }
            continue;
        };
        touching += 1;
        let same_count = gpu.len() == m.points.len();
        let to_world = |p: &Placed, l: [f32; 3]| p.centre + p.rot * Vec3::from(l);
        let all_found = gpu.iter().all(|c| {
            let (on_a, on_b) = (to_world(&pa, c.local_self), to_world(&pb, c.local_partner));
            (Vec3::from(c.normal) + m.normal).length() < tol
                && m.points.iter().any(|q| (q.on_a - on_a).length() < tol && (q.on_b - on_b).length() < tol)
        });
        if !(same_count && all_found) {
            mismatched.push(format!("pair {k}: GPU {} points, CPU {}", gpu.len(), m.points.len()));
        }
    }
    eprintln!("{touching} touching pairs of {pairs}; {} differ: {mismatched:?}", mismatched.len());
    Some((touching, mismatched))
}

#[test]
fn gpu_manifolds_match_the_cpu_reference() {
    let Some((touching, mismatched)) = compare(0x5eed_1234_abcd_0001, 400, random_body) else { return };
    assert!(touching > 150, "too few touching pairs to compare: {touching}");
    // f32 on two processors: a pair at a near tie between a face and an edge
    // axis may pick differently; anything beyond such rare ties is a bug
    assert!(mismatched.len() <= 4, "{} of 400 pairs differ from the reference", mismatched.len());
}

/// A capsule, long or short, or any body of `random_body`: pairs with a
/// capsule at one end at least.
fn random_with_capsule(rng: &mut Rng, k: usize, at: Vec3) -> Body {
    if k % 4 == 3 {
        return random_body(rng, k, at);
    }
    let (radius, half_height) =
        if k.is_multiple_of(2) { (0.05 + 0.3 * rng.f(), 0.3 + rng.f()) } else { (0.1 + 0.4 * rng.f(), 0.02 + 0.2 * rng.f()) };
    let mut b = Body::new(Shape::Capsule { radius, half_height }, at.to_array());
    b.orientation = rng.quat().to_array();
    b
}

#[test]
fn gpu_capsule_manifolds_match_the_cpu_reference() {
    let Some((touching, mismatched)) = compare(0x5eed_ca95_0000_0002, 400, random_with_capsule) else { return };
    assert!(touching > 150, "too few touching pairs to compare: {touching}");
    // f32 on two processors: a near tie (a face or an edge, one point or
    // two, the end of a golden-section search on a flat least) may go
    // either way; anything beyond such rare ties is a bug
    assert!(mismatched.len() <= 4, "{} of 400 pairs differ from the reference", mismatched.len());
}

/// A hull of 4 to 32 random points in a box of random size, its points
/// off centre so that its frame is not its centre of mass.
pub fn random_hull(rng: &mut Rng, at: Vec3) -> Body {
    let scale = Vec3::new(0.3 + 0.7 * rng.f(), 0.3 + 0.7 * rng.f(), 0.3 + 0.7 * rng.f());
    let off = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * 0.3;
    let n = 4 + (rng.f() * 28.0) as usize;
    let points = (0..n).map(|_| (Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * scale + off).to_array()).collect();
    let mut b = Body::new(Shape::Hull(HullShape::new(points).unwrap()), at.to_array());
    b.orientation = rng.quat().to_array();
    b
}

/// A hull, or a body of `random_with_capsule` (a capsule, sphere or box).
fn random_with_hull(rng: &mut Rng, k: usize, at: Vec3) -> Body {
    if k.is_multiple_of(3) {
        return random_with_capsule(rng, k, at);
    }
    random_hull(rng, at)
}

#[test]
fn gpu_hull_manifolds_match_the_cpu_reference() {
    let Some((touching, mismatched)) = compare(0x5eed_4011_0000_0003, 400, random_with_hull) else { return };
    assert!(touching > 150, "too few touching pairs to compare: {touching}");
    // f32 on two processors: a near tie (a face or an edge, which corner is
    // deepest, the end of a golden-section search) may go either way
    assert!(mismatched.len() <= 4, "{} of 400 pairs differ from the reference", mismatched.len());
}

/// Hulls at random turns just above, on and in the ground: the GPU's ground
/// points are the reference's.
#[test]
fn gpu_hull_ground_manifolds_match_the_cpu_reference() {
    let settings = Settings { gravity: [0.0; 3], ..Settings::default() };
    let mut rng = Rng(0x5eed_4011_0000_0004);
    let mut bodies = Vec::new();
    for k in 0..200 {
        let mut b = random_hull(&mut rng, Vec3::new((k % 20) as f32 * 5.0, 0.0, (k / 20) as f32 * 5.0));
        let p = placed(&b, &settings).polytope().unwrap();
        let lowest = p.vertices.iter().map(|v| v.y).fold(f32::MAX, f32::min);
        b.position[1] += rng.f() * 0.07 - 0.05 - lowest;
        bodies.push(b);
    }
    let scene = Scene { settings, ground: Some(Ground { height: 0.0 }), bodies, joints: vec![], camera: None };
    let Some(mut w) = world(&scene) else { return };
    w.step(1).unwrap();
    let contacts = w.read_contacts().unwrap();
    let (mut touching, mut mismatched) = (0, Vec::new());
    for (k, b) in scene.bodies.iter().enumerate() {
        let pa = placed(b, &settings);
        let cpu = ground_hull(&pa.polytope().unwrap(), 0.0, CONTACT_MARGIN);
        let gpu = &contacts[k];
        let Some(m) = cpu else {
            if !gpu.is_empty() {
                mismatched.push(format!("hull {k}: GPU {} points, CPU none", gpu.len()));
            }
            continue;
        };
        touching += 1;
        let found = gpu.iter().all(|c| {
            let on_a = pa.centre + pa.rot * Vec3::from(c.local_self);
            m.points.iter().any(|q| (q.on_a - on_a).length() < 2e-3)
        });
        if gpu.len() != m.points.len() || !found {
            mismatched.push(format!("hull {k}: GPU {} points, CPU {}", gpu.len(), m.points.len()));
        }
    }
    assert!(touching > 100, "too few touching: {touching}");
    assert!(mismatched.len() <= 2, "{} of 200 differ: {mismatched:?}", mismatched.len());
}

/// A hull of the most points a hull may have (64, on a sphere: 124
/// triangles and 186 edges), or a box: the edge pairs' loop of two such
/// hulls is the longest a pair takes, and lavapipe ends an invocation's loops
/// past 65 535 trips in all; the manifolds still match the reference.
fn largest_hull_or_box(rng: &mut Rng, k: usize, at: Vec3) -> Body {
    if k % 4 == 3 {
        return random_body(rng, k, at);
    }
    let r = 0.4 + 0.4 * rng.f();
    let points =
        (0..64).map(|_| (Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Y) * r).to_array()).collect();
    let mut b = Body::new(Shape::Hull(HullShape::new(points).unwrap()), at.to_array());
    b.orientation = rng.quat().to_array();
    b
}

#[test]
fn gpu_manifolds_of_the_largest_hulls_match_the_cpu_reference() {
    let Some((touching, mismatched)) = compare(0x5eed_4011_0000_0064, 100, largest_hull_or_box) else { return };
    assert!(touching > 30, "too few touching pairs to compare: {touching}");
    assert!(mismatched.len() <= 2, "{} of 100 pairs differ from the reference", mismatched.len());
}
