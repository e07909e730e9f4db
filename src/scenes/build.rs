//! The built-in scenes of our own, and the bodies they are made of; the
//! Box3D benchmarks are in `box3d.rs`, the table naming them all in `mod.rs`.

use glam::{Quat, Vec3};

use crate::scene::{Body, Ground, HullShape, Joint, Scene, Settings, Shape};

/// A box body at rest with density 1000 kg/m^3.
pub fn box_body(half_extents: [f32; 3], position: [f32; 3]) -> Body {
    let h = half_extents;
    Body {
        shape: Shape::Box { half_extents: h },
        position,
        orientation: [0.0, 0.0, 0.0, 1.0],
        linear_velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        mass: 1000.0 * 8.0 * h[0] * h[1] * h[2],
        fixed: false,
        kinematic: false,
        restitution: None,
        friction: None,
    }
}

/// A sphere body at rest with density 1000 kg/m^3.
pub fn sphere_body(radius: f32, position: [f32; 3]) -> Body {
    Body {
        shape: Shape::Sphere { radius },
        mass: 1000.0 * 4.0 / 3.0 * std::f32::consts::PI * radius.powi(3),
        ..box_body([radius; 3], position)
    }
}

/// A scene of these bodies and joints on the ground at height 0, with the
/// default settings.
pub(super) fn scene(bodies: Vec<Body>, joints: Vec<Joint>) -> Scene {
    Scene { settings: Settings::default(), ground: Some(Ground { height: 0.0 }), bodies, joints, camera: None }
}

/// `drop`: one unit box, tilted 25 degrees about z, falling from 3 m.
pub fn drop() -> Scene {
    let mut b = box_body([0.5; 3], [0.0, 3.0, 0.0]);
    let half = 25f32.to_radians() / 2.0;
    b.orientation = [0.0, 0.0, half.sin(), half.cos()];
    scene(vec![b], vec![])
}

/// `sphere`: a ball of radius 0.5 dropped from 5 m with restitution 0.8.
pub fn sphere() -> Scene {
    let mut b = sphere_body(0.5, [0.0, 5.0, 0.0]);
    b.restitution = Some(0.8);
    scene(vec![b], vec![])
}

/// `cubes`: `count` unit cubes at random orientations, 1.5 m apart (with a
/// little jitter) in one layer, centres 1 to 1.3 m up, two thirds of the
/// grid's places filled: they land side by side and seldom on each other,
/// and the density is the same at every count (see `pile` for cubes that
/// land on each other).
pub fn cubes(count: usize, seed: u64) -> Scene {
    let side = ((count as f32 * 1.5).sqrt()).ceil().max(1.0) as usize; // cells per row
    scene(scattered_cubes(count, seed, side, 1.5, 1.5, 0.3), vec![])
}

/// `pile`: `count` unit cubes at random orientations dropped in four
/// layers, 1.2 m apart within a layer (with 0.2 m of jitter) and 1.5 m
/// between layers: they land on each other and pile up three and four deep.
pub fn pile(count: usize, seed: u64) -> Scene {
    let side = ((count.div_ceil(4)) as f32).sqrt().ceil().max(1.0) as usize;
    scene(scattered_cubes(count, seed, side, 1.2, 1.5, 0.2), vec![])
}

/// `count` unit cubes at random orientations on a `side` x `side` square
/// of places `spacing` apart, centred on the origin, filled row by row and
/// layer by layer (layers `rise` apart, the first 1 m up); each place is
/// moved by up to `jitter` / 2 along x and z and up to `jitter` up.
fn scattered_cubes(count: usize, seed: u64, side: usize, spacing: f32, rise: f32, jitter: f32) -> Vec<Body> {
    let mut rng = SplitMix64(seed);
    let mut bodies = Vec::with_capacity(count);
    'fill: for layer in 0.. {
        for row in 0..side {
            for col in 0..side {
                if bodies.len() == count {
                    break 'fill;
                }
                let shift = |r: &mut SplitMix64| (r.next_f32() - 0.5) * jitter;
                let x = (col as f32 - side as f32 / 2.0) * spacing + shift(&mut rng);
                let z = (row as f32 - side as f32 / 2.0) * spacing + shift(&mut rng);
                let y = 1.0 + layer as f32 * rise + rng.next_f32() * jitter;
                let mut b = box_body([0.5; 3], [x, y, z]);
                b.orientation = rng.unit_quaternion();
                bodies.push(b);
            }
        }
    }
    bodies
}

/// `stack`: `count` unit boxes in a column, each resting on the one below.
pub fn stack(count: usize) -> Scene {
    let bodies = (0..count).map(|k| box_body([0.5; 3], [0.0, 0.5 + k as f32, 0.0])).collect();
    scene(bodies, vec![])
}

/// `pyramid`: `rows` rows of unit boxes, the bottom row `rows` wide, with a
/// 0.05 m gap between neighbours of a row.
pub fn pyramid(rows: usize) -> Scene {
    let pitch = 1.05;
    let mut bodies = Vec::new();
    for row in 0..rows {
        let n = rows - row;
        let x0 = -(n as f32 - 1.0) * pitch / 2.0;
        for k in 0..n {
            bodies.push(box_body([0.5; 3], [x0 + k as f32 * pitch, 0.5 + row as f32, 0.0]));
        }
    }
    scene(bodies, vec![])
}

/// `chain`: `count` links (half extents 0.5 x 0.1 x 0.1) laid out along +x,
/// joined end to end, the first end pinned to the world at (0, h, 0). It
/// swings down and, damped like air (the paper's beta = 0.005 per step, as
/// in its Fig. 4), comes to rest hanging within 30 s.
pub fn chain(count: usize) -> Scene {
    let height = count as f32 + 2.0;
    let bodies = (0..count).map(|k| box_body([0.5, 0.1, 0.1], [0.5 + k as f32, height, 0.0])).collect();
    let mut joints = vec![Joint { bodies: [0, -1], anchors: [[-0.5, 0.0, 0.0], [0.0, height, 0.0]] }];
    for k in 1..count {
        joints.push(Joint { bodies: [k as i32 - 1, k as i32], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] });
    }
    let mut s = scene(bodies, joints);
    s.settings.linear_damping = 0.005;
    s.settings.angular_damping = 0.005;
    s
}

/// `hanging`: `count` links (half extents 0.5 x 0.1 x 0.1) hung by both
/// ends from world pins 0.8 x the chain's length apart, starting as a V (with
/// one flat link at the bottom when `count` is odd). Damped like air, it
/// settles into a catenary (the paper's chains settle straight).
pub fn hanging(count: usize) -> Scene {
    let count = count.max(2);
    let length = count as f32;
    let span = 0.8 * length;
    let height = length;
    let (side, middle) = (count / 2, (count % 2) as f32);
    let reach = (span - middle) / 2.0; // horizontal extent of each side of the V
    let slope = (reach / side as f32).clamp(-1.0, 1.0).acos();
    let drop = side as f32 * slope.sin();
    let mut bodies = Vec::with_capacity(count);
    let mut link = |centre: [f32; 2], angle: f32| {
        let mut b = box_body([0.5, 0.1, 0.1], [centre[0], centre[1], 0.0]);
        b.orientation = [0.0, 0.0, (angle / 2.0).sin(), (angle / 2.0).cos()];
        bodies.push(b);
    };
    let left = -span / 2.0;
    for k in 0..side {
        let t = k as f32 + 0.5;
        link([left + t * slope.cos(), height - t * slope.sin()], -slope);
    }
    if middle > 0.0 {
        link([0.0, height - drop], 0.0);
    }
    for k in 0..side {
        let t = k as f32 + 0.5;
        link([left + reach + middle + t * slope.cos(), height - drop + t * slope.sin()], slope);
    }
    let last = count as i32 - 1;
    let mut joints = vec![Joint { bodies: [0, -1], anchors: [[-0.5, 0.0, 0.0], [left, height, 0.0]] }];
    for k in 1..count as i32 {
        joints.push(Joint { bodies: [k - 1, k], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] });
    }
    joints.push(Joint { bodies: [last, -1], anchors: [[0.5, 0.0, 0.0], [-left, height, 0.0]] });
    let mut s = scene(bodies, joints);
    s.settings.linear_damping = 0.02;
    s.settings.angular_damping = 0.02;
    s
}

/// `bridge`: `count` planks (half extents 0.5 x 0.05 x 1) on ball joints at
/// both edges of each end, between two fixed posts.
pub fn bridge(count: usize) -> Scene {
    let height = 3.0;
    let span = count as f32;
    let post = |x: f32| {
        let mut b = box_body([0.5, height / 2.0, 1.0], [x, height / 2.0, 0.0]);
        b.fixed = true;
        b
    };
    let mut bodies = vec![post(-0.5), post(span + 0.5)];
    for k in 0..count {
        bodies.push(box_body([0.5, 0.05, 1.0], [k as f32 + 0.5, height - 0.05, 0.0]));
    }
    let mut joints = Vec::new();
    for z in [-0.9f32, 0.9] {
        for k in 0..=count {
            // joint between plank k-1 (or the left post) and plank k (or the right post)
            let left = if k == 0 { 0 } else { k as i32 + 1 };
            let right = if k == count { 1 } else { k as i32 + 2 };
            let left_anchor = if k == 0 { [0.5, height / 2.0 - 0.05, z] } else { [0.5, 0.0, z] };
            let right_anchor = if k == count { [-0.5, height / 2.0 - 0.05, z] } else { [-0.5, 0.0, z] };
            joints.push(Joint { bodies: [left, right], anchors: [left_anchor, right_anchor] });
        }
    }
    scene(bodies, joints)
}

/// `ragdoll`: `count` ragdolls (head, torso, upper and lower arms and legs on
/// ball joints) dropped in a row onto a pile of boxes.
pub fn ragdoll(count: usize) -> Scene {
    ragdolls(count, false)
}

/// `capsule_ragdoll`: the `ragdoll` scene with capsules for limbs (as long
/// and as thick as the boxes they replace) and a ball for a head.
pub fn capsule_ragdoll(count: usize) -> Scene {
    ragdolls(count, true)
}

fn ragdolls(count: usize, capsules: bool) -> Scene {
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    // the pile: a 3 x 3 base of boxes with one box on top
    for i in 0..3 {
        for k in 0..3 {
            bodies.push(box_body([0.5; 3], [i as f32 * 1.05 - 1.05, 0.5, k as f32 * 1.05 - 1.05]));
        }
    }
    bodies.push(box_body([0.5; 3], [0.0, 1.5, 0.0]));
    // a limb lying along x, as a capsule: its segment (the body's y) turned onto x
    let onto_x = Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2);
    for r in 0..count {
        let base = bodies.len();
        let (x, y, z) = ((r % 3) as f32 * 0.8 - 0.8, 3.5 + (r / 3) as f32 * 2.5, (r % 2) as f32 * 0.5 - 0.25);
        let mut part = |half: [f32; 3], at: [f32; 3]| {
            let mut b = box_body(half, [x + at[0], y + at[1], z + at[2]]);
            // a limb: long along x or y, square across (the torso stays a box)
            let long = if half[0] > half[1] { 0 } else { 1 };
            if capsules && half[2] < half[long] && half[2] == half[1 - long] {
                let radius = half[2];
                b = Body::new(Shape::Capsule { radius, half_height: half[long] - radius }, b.position);
                if long == 0 {
                    b.orientation = onto_x.to_array();
                }
            } else if capsules && half == [half[0]; 3] {
                b = Body::new(Shape::Sphere { radius: half[0] }, b.position);
            }
            bodies.push(b);
        };
        part([0.2, 0.3, 0.12], [0.0, 0.0, 0.0]); // 0 torso
        part([0.12, 0.12, 0.12], [0.0, 0.45, 0.0]); // 1 head
        for side in [-1.0f32, 1.0] {
            part([0.15, 0.05, 0.05], [side * 0.35, 0.25, 0.0]); // upper arm
            part([0.15, 0.05, 0.05], [side * 0.65, 0.25, 0.0]); // lower arm
            part([0.07, 0.2, 0.07], [side * 0.1, -0.5, 0.0]); // upper leg
            part([0.07, 0.2, 0.07], [side * 0.1, -0.9, 0.0]); // lower leg
        }
        // anchors as offsets along the world's axes, into each part's frame
        let local = |part: usize, offset: [f32; 3]| {
            (Quat::from_array(bodies[base + part].orientation).conjugate() * Vec3::from(offset)).to_array()
        };
        let mut j = |a: usize, b: usize, pa: [f32; 3], pb: [f32; 3]| {
            joints.push(Joint { bodies: [(base + a) as i32, (base + b) as i32], anchors: [local(a, pa), local(b, pb)] });
        };
        j(0, 1, [0.0, 0.33, 0.0], [0.0, -0.12, 0.0]); // neck
        for (s, side) in [(0, -1.0f32), (1, 1.0)] {
            let ua = 2 + s * 4;
            j(0, ua, [side * 0.2, 0.25, 0.0], [-side * 0.15, 0.0, 0.0]); // shoulder
            j(ua, ua + 1, [side * 0.15, 0.0, 0.0], [-side * 0.15, 0.0, 0.0]); // elbow
            j(0, ua + 2, [side * 0.1, -0.3, 0.0], [0.0, 0.2, 0.0]); // hip
            j(ua + 2, ua + 3, [0.0, -0.2, 0.0], [0.0, 0.2, 0.0]); // knee
        }
    }
    // Damped like air (the paper's beta = 0.005 per step, as `chain`): on
    // ideal ball joints a limb hanging over the pile's edge swings as a
    // pendulum with nothing to stop it; each ragdoll sleeps as a whole once
    // all of it is at rest (docs/defaults.md has the numbers).
    let mut s = scene(bodies, joints);
    s.settings.linear_damping = 0.005;
    s.settings.angular_damping = 0.005;
    s
}

/// `capsules`: `count` capsules of random sizes (radius 0.15 to 0.35 m,
/// segment 0.2 to 1.2 m long) at random orientations, dropped in layers as
/// `pile` drops its cubes: they heap up.
pub fn capsules(count: usize, seed: u64) -> Scene {
    let side = ((count.div_ceil(4)) as f32).sqrt().ceil().max(1.0) as usize;
    let mut rng = SplitMix64(seed ^ 0xca95_0000);
    let bodies = scattered_cubes(count, seed, side, 1.6, 1.8, 0.2)
        .into_iter()
        .map(|cube| {
            let radius = 0.15 + 0.2 * rng.next_f32();
            let half_height = 0.1 + 0.5 * rng.next_f32();
            Body { orientation: cube.orientation, ..Body::new(Shape::Capsule { radius, half_height }, cube.position) }
        })
        .collect();
    scene(bodies, vec![])
}

/// Distinct rock shapes of a `convex_pile` (per seed).
pub(crate) const ROCK_SHAPES: usize = 16;
/// The fewest and the most points a rock of `convex_pile` is the hull of.
pub(crate) const ROCK_POINTS: (usize, usize) = (8, 24);
/// The shortest and the longest semi-axis of a rock's ellipsoid (m).
pub(crate) const ROCK_AXES: (f32, f32) = (0.4, 0.6);
/// How far in, at most, a rock's point is pulled from its ellipsoid (a
/// fraction of the way to the centre): facets come out uneven.
pub(crate) const ROCK_PULL: f32 = 0.3;

/// `convex_pile`: `count` rocks at random orientations dropped in layers as
/// `pile` drops its cubes (1.4 m apart within a layer, with 0.2 m of jitter,
/// and 1.5 m between layers, so that no two touch as placed). After Box3D's
/// benchmark of that name, a heap of convex hulls, with rocks 0.8 to 1.2 m
/// across at most (`pile`'s cubes are 1 m) and of several shapes (Box3D's is
/// a tower of 8 x 8 x 80 copies of one hull of 32 points on a sphere of
/// radius 2 m, 320 m tall).
/// Rocks roll where cubes do not: they land on each other and spread, most
/// of them one deep (in rapier3d 1000 come to rest with their frames at
/// most 1 m up, `pile`'s cubes at 4 m).
///
/// A rock is one of [`ROCK_SHAPES`] shapes drawn for the seed, as a game
/// draws its rocks from a few meshes (on the GPU the bodies of one shape
/// share its record): the hull of 8 to 24 points on an ellipsoid whose
/// semi-axes are 0.4 to 0.6 m, each point pulled in by up to 30% so that
/// facets come out uneven, rounder rocks and more angular ones. Points are
/// rounded to the millimetre, which keeps a body's JSON within the 1 KiB a
/// body that the loader's size limit allows at the most bodies a built-in
/// scene has. Density 1000 kg/m^3: at seed 1 a rock weighs 45 to 230 kg,
/// 127 on average.
pub fn convex_pile(count: usize, seed: u64) -> Scene {
    let side = ((count.div_ceil(4)) as f32).sqrt().ceil().max(1.0) as usize;
    let mut rng = SplitMix64(seed ^ 0xc04e_0000);
    let shapes: Vec<HullShape> = (0..ROCK_SHAPES).map(|_| rock(&mut rng)).collect();
    let bodies = scattered_cubes(count, seed, side, 1.4, 1.5, 0.2)
        .into_iter()
        .map(|cube| {
            let shape = shapes[(rng.next_u64() % ROCK_SHAPES as u64) as usize].clone();
            Body { orientation: cube.orientation, ..Body::new(Shape::Hull(shape), cube.position) }
        })
        .collect();
    scene(bodies, vec![])
}

/// A rock of `convex_pile`: the hull of `ROCK_POINTS` points on an
/// ellipsoid of semi-axes within `ROCK_AXES` along the frame's axes, each
/// pulled towards the centre by up to `ROCK_PULL`, rounded to the millimetre.
fn rock(rng: &mut SplitMix64) -> HullShape {
    let (lo, hi) = ROCK_AXES;
    let (fewest, most) = ROCK_POINTS;
    loop {
        let axes = [0; 3].map(|_| lo + (hi - lo) * rng.next_f32());
        let n = fewest + (rng.next_u64() % (most - fewest + 1) as u64) as usize;
        let points = (0..n)
            .map(|_| {
                let (d, r) = (rng.unit_vector(), 1.0 - ROCK_PULL * rng.next_f32());
                [0, 1, 2].map(|k| (d[k] * axes[k] * r * 1000.0).round() / 1000.0)
            })
            .collect();
        // eight points on an ellipsoid span a volume but for a fluke of
        // measure zero; draw again rather than fail
        if let Ok(shape) = HullShape::new(points) {
            return shape;
        }
    }
}

/// `blast`: a wall of `columns` x 6 boxes of 0.5 m (5 cm apart along the
/// wall, as in `pyramid`, rows resting on each other) standing on the ground in the plane
/// z = 0, centred on x = 0. Its companion track, [`blast_track`], sets off
/// an explosion in front of its foot at t = 1 s; `verlet run --builtin
/// blast` plays that track unless `--input` gives another.
pub fn blast(columns: usize) -> Scene {
    let (size, rows, gap) = (0.5f32, 6, 0.05f32);
    let pitch = size + gap;
    let x0 = -(columns as f32 - 1.0) * pitch / 2.0;
    let mut bodies = Vec::with_capacity(columns * rows);
    for row in 0..rows {
        for col in 0..columns {
            bodies.push(box_body([size / 2.0; 3], [x0 + col as f32 * pitch, size / 2.0 + row as f32 * size, 0.0]));
        }
    }
    scene(bodies, vec![])
}

/// The input track of [`blast`]: at t = 1 s an explosion 1 m in front of
/// the wall (at z = -1) and 1 m up, of strength 1500 N s (12 m/s to a 125 kg
/// box at its centre), radius 6 m, linear falloff.
pub fn blast_track() -> crate::track::Track {
    use crate::track::{Action, Event, Track};
    let explode = Action::Explode { centre: [0.0, 1.0, -1.0], strength: 1500.0, radius: 6.0, falloff: 1.0 };
    Track::new(vec![Event { t: 1.0, action: explode }]).expect("a valid track")
}

/// SplitMix64: a tiny generator whose sequence for a seed is fixed forever,
/// so `cubes --seed S` names the same scene in every version of this crate
/// (a general-purpose RNG crate may change its streams between releases).
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn next_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A uniformly random unit vector (a point of the ball, by rejection,
    /// pushed out to the sphere).
    fn unit_vector(&mut self) -> [f32; 3] {
        loop {
            let p = [0; 3].map(|_| 2.0 * self.next_f32() - 1.0);
            let length = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            if length > 1e-3 && length <= 1.0 {
                return p.map(|x| x / length);
            }
        }
    }

    /// A uniformly random rotation (Shoemake's method).
    fn unit_quaternion(&mut self) -> [f32; 4] {
        let (u1, u2, u3) = (self.next_f32(), self.next_f32(), self.next_f32());
        let tau = std::f32::consts::TAU;
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        [a * (tau * u2).sin(), a * (tau * u2).cos(), b * (tau * u3).sin(), b * (tau * u3).cos()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::{body_count, by_name};

    /// How far a hull body reaches from its `position` (its frame's origin).
    fn reach(b: &Body) -> f32 {
        let Shape::Hull(shape) = &b.shape else { panic!("not a hull: {:?}", b.shape) };
        shape.points().iter().map(|p| glam::Vec3::from(*p).length()).fold(0.0, f32::max)
    }

    #[test]
    fn a_convex_pile_is_rocks_of_a_few_shapes_apart_above_the_ground() {
        for count in [1, 2, 7, 300] {
            let s = convex_pile(count, 9);
            assert_eq!(s.bodies.len(), count);
            assert_eq!(body_count("convex_pile", Some(count)), Some(count as u64));
            let mut shapes: Vec<&[[f32; 3]]> = Vec::new();
            for (n, b) in s.bodies.iter().enumerate() {
                let Shape::Hull(shape) = &b.shape else { panic!("rock {n} is not a hull") };
                assert!(b.is_dynamic(), "rock {n}");
                let points = shape.points();
                assert!((ROCK_POINTS.0..=ROCK_POINTS.1).contains(&points.len()), "rock {n} of {} points", points.len());
                // on the millimetre
                assert!(points.iter().flatten().all(|&x| (x * 1000.0 - (x * 1000.0).round()).abs() < 1e-3), "rock {n}");
                let r = reach(b);
                assert!(((1.0 - ROCK_PULL) * ROCK_AXES.0..=ROCK_AXES.1 + 1e-6).contains(&r), "rock {n} reaches {r} m");
                assert!(b.position[1] - r > 0.3, "rock {n} at {:?} reaches the ground", b.position);
                // 45 to 230 kg at 1000 kg/m^3 at seed 1
                assert!((20.0..500.0).contains(&b.mass), "rock {n} weighs {} kg", b.mass);
                if !shapes.contains(&points) {
                    shapes.push(points);
                }
            }
            assert!(shapes.len() <= ROCK_SHAPES, "{} shapes", shapes.len());
            if count == 300 {
                assert!(shapes.len() > ROCK_SHAPES / 2, "only {} shapes of {ROCK_SHAPES} drawn", shapes.len());
            }
            // as placed, no two reach each other
            for (i, a) in s.bodies.iter().enumerate() {
                for (j, b) in s.bodies.iter().enumerate().skip(i + 1) {
                    let apart = (glam::Vec3::from(a.position) - glam::Vec3::from(b.position)).length();
                    assert!(apart >= reach(a) + reach(b), "rocks {i} and {j} overlap: {apart} m apart");
                }
            }
            s.validate().unwrap();
        }
    }

    #[test]
    fn a_convex_pile_is_the_same_for_a_seed_and_another_for_another() {
        assert_eq!(convex_pile(50, 3), convex_pile(50, 3));
        assert_ne!(convex_pile(50, 3), convex_pile(50, 4));
        assert_eq!(by_name("convex_pile", None, 1).map(|s| s.bodies.len()), Some(1000));
    }

    /// A body's JSON within 1 KiB, what the loader's size limit allows a body
    /// at the most bodies a built-in scene has.
    #[test]
    fn a_convex_piles_json_takes_under_a_kibibyte_a_body() {
        let s = convex_pile(400, 5);
        let bytes = s.to_json().len() / s.bodies.len();
        assert!(bytes < 1024, "{bytes} bytes a body");
        let back = crate::scene::Scene::from_json_str(&s.to_json()).unwrap();
        for (a, b) in back.bodies.iter().zip(&s.bodies) {
            assert_eq!((&a.shape, a.position, a.mass), (&b.shape, b.position, b.mass));
        }
    }
}
