//! Named built-in scenes, shared by the command line (`verlet scene NAME`),
//! the tests and the benchmarks: a name means one scene everywhere.

use crate::scene::{Body, Ground, Joint, Scene, Settings, Shape};
use crate::Error;

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

fn scene(bodies: Vec<Body>, joints: Vec<Joint>) -> Scene {
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
    let mut bodies = Vec::new();
    let mut joints = Vec::new();
    // the pile: a 3 x 3 base of boxes with one box on top
    for i in 0..3 {
        for k in 0..3 {
            bodies.push(box_body([0.5; 3], [i as f32 * 1.05 - 1.05, 0.5, k as f32 * 1.05 - 1.05]));
        }
    }
    bodies.push(box_body([0.5; 3], [0.0, 1.5, 0.0]));
    for r in 0..count {
        let base = bodies.len() as i32;
        let (x, y, z) = ((r % 3) as f32 * 0.8 - 0.8, 3.5 + (r / 3) as f32 * 2.5, (r % 2) as f32 * 0.5 - 0.25);
        let mut part = |half: [f32; 3], at: [f32; 3]| {
            bodies.push(box_body(half, [x + at[0], y + at[1], z + at[2]]));
        };
        part([0.2, 0.3, 0.12], [0.0, 0.0, 0.0]); // 0 torso
        part([0.12, 0.12, 0.12], [0.0, 0.45, 0.0]); // 1 head
        for side in [-1.0f32, 1.0] {
            part([0.15, 0.05, 0.05], [side * 0.35, 0.25, 0.0]); // upper arm
            part([0.15, 0.05, 0.05], [side * 0.65, 0.25, 0.0]); // lower arm
            part([0.07, 0.2, 0.07], [side * 0.1, -0.5, 0.0]); // upper leg
            part([0.07, 0.2, 0.07], [side * 0.1, -0.9, 0.0]); // lower leg
        }
        let j = |a: i32, b: i32, pa: [f32; 3], pb: [f32; 3]| Joint { bodies: [base + a, base + b], anchors: [pa, pb] };
        joints.push(j(0, 1, [0.0, 0.33, 0.0], [0.0, -0.12, 0.0])); // neck
        for (s, side) in [(0, -1.0f32), (1, 1.0)] {
            let ua = 2 + s * 4;
            joints.push(j(0, ua, [side * 0.2, 0.25, 0.0], [-side * 0.15, 0.0, 0.0])); // shoulder
            joints.push(j(ua, ua + 1, [side * 0.15, 0.0, 0.0], [-side * 0.15, 0.0, 0.0])); // elbow
            joints.push(j(0, ua + 2, [side * 0.1, -0.3, 0.0], [0.0, 0.2, 0.0])); // hip
            joints.push(j(ua + 2, ua + 3, [0.0, -0.2, 0.0], [0.0, 0.2, 0.0])); // knee
        }
    }
    // Damped like air (the paper's beta = 0.005 per step, as `chain`): on
    // ideal ball joints a limb hanging over the pile's edge swings as a
    // pendulum with nothing to stop it (undamped, the fastest body after
    // 15 s was at 0.1 to 0.6 m/s, measured over solver settings). Each
    // ragdoll sleeps as a whole once all of it is at rest. Measured with
    // these settings, the fastest body after 15 s: 0.04, 0.00, 0.01, 0.02
    // and 0.41 m/s for 8 to 12 ragdolls (12: one tumbles off late).
    let mut s = scene(bodies, joints);
    s.settings.linear_damping = 0.005;
    s.settings.angular_damping = 0.005;
    s
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

/// Box3D's benchmark world, as its `benchmark` program sets it up: gravity
/// 10 m/s^2 (ours is 9.81), friction 0.6 and restitution 0 (its default
/// material), sleeping off (each of its benchmarks turns it off). Its step
/// is 60 Hz, as ours; its solver's 4 substeps are not copied: a scene here
/// keeps our solver's defaults, so that the bench compares the defaults.
fn box3d_world(bodies: Vec<Body>, joints: Vec<Joint>) -> Scene {
    let mut s = scene(bodies, joints);
    s.settings.gravity = [0.0, -10.0, 0.0];
    s.settings.friction = 0.6;
    s.settings.restitution = 0.0;
    s.settings.sleeping = false;
    s
}

/// Box3D's pyramid boxes weigh 100 kg/m^3, a tenth of our default.
const BOX3D_PYRAMID_DENSITY: f32 = 100.0;

/// A pyramid of `rows` rows of unit cubes in the plane z = `z`, the bottom
/// row's first centre at x = `x0`, neighbours in a row touching (no gap)
/// and each row on the one below, shifted half a cube: each cube stands on
/// two. Box3D's pyramids are laid out so; density `BOX3D_PYRAMID_DENSITY`.
fn touching_pyramid(rows: usize, x0: f32, z: f32, bodies: &mut Vec<Body>) {
    for row in 0..rows {
        let first = x0 + 0.5 * row as f32;
        for k in 0..rows - row {
            let mut b = box_body([0.5; 3], [first + k as f32, 0.5 + row as f32, z]);
            b.mass = BOX3D_PYRAMID_DENSITY * b.shape.volume();
            bodies.push(b);
        }
    }
}

/// `large_pyramid`: Box3D's benchmark of that name, a pyramid of `rows`
/// rows (Box3D: 100, 5050 cubes) of unit cubes touching side by side,
/// centred on the origin, on the ground; Box3D's world (`box3d_world`).
pub fn large_pyramid(rows: usize) -> Scene {
    let mut bodies = Vec::with_capacity(rows * (rows + 1) / 2);
    touching_pyramid(rows, -(rows as f32 - 1.0) / 2.0, 0.0, &mut bodies);
    box3d_world(bodies, vec![])
}

/// Rows of each pyramid of `many_pyramids` (Box3D's `baseCount`), and its cubes.
pub const SMALL_PYRAMID_ROWS: usize = 10;
pub const SMALL_PYRAMID_BOXES: usize = SMALL_PYRAMID_ROWS * (SMALL_PYRAMID_ROWS + 1) / 2;

/// `many_pyramids`: Box3D's benchmark of that name, `side` x `side`
/// pyramids (Box3D: 14 x 14 = 196) of `SMALL_PYRAMID_ROWS` rows (55 unit
/// cubes each, touching as in `large_pyramid`) on the ground. As Box3D
/// places them: 11 m apart along x (a pyramid's 10 m base and 1 m between
/// bases), and along z spread evenly over its ground's depth (11.7 m
/// apart at 14), the grid about centred on the origin; Box3D's world.
pub fn many_pyramids(side: usize) -> Scene {
    let pitch = SMALL_PYRAMID_ROWS as f32 + 1.0;
    // Box3D's ground is a square of half-width `ground`; the first base
    // starts a metre in from its corner
    let ground = 0.5 * side as f32 * pitch;
    let z_pitch = if side > 1 { 2.0 * (ground - 1.0) / (side as f32 - 1.0) } else { 0.0 };
    let mut bodies = Vec::with_capacity(side * side * SMALL_PYRAMID_BOXES);
    for row in 0..side {
        for col in 0..side {
            let x0 = -ground + 1.0 + col as f32 * pitch;
            touching_pyramid(SMALL_PYRAMID_ROWS, x0, -ground + 1.0 + row as f32 * z_pitch, &mut bodies);
        }
    }
    box3d_world(bodies, vec![])
}

/// `joint_grid`: Box3D's benchmark of that name, a curtain of `side` x
/// `side` balls (radius 0.4 m, 1000 kg/m^3; Box3D: 100 x 100) 1 m apart in
/// the plane z = 0, hanging from its top row: ball `(column k, row i)` at
/// (k, -i, 0), row 0 fixed, each ball joined to the one above it and to
/// the one to its left by ball joints at the midpoint, 2 side (side - 1)
/// joints (19 800 at 100), the top row's joints between two fixed balls
/// included, as Box3D has them. Box3D's balls do not collide with each
/// other (a collision filter, which our scenes lack); 0.2 m apart, ours
/// touch only if the curtain folds. No ground, as in Box3D; Box3D's world
/// (`box3d_world`). Box3D's joints are spherical joints, as ours.
pub fn joint_grid(side: usize) -> Scene {
    let mut bodies = Vec::with_capacity(side * side);
    let mut joints = Vec::with_capacity(2 * side * side.saturating_sub(1));
    for k in 0..side {
        for i in 0..side {
            let index = bodies.len() as i32;
            let mut b = sphere_body(0.4, [k as f32, 0.0 - i as f32, 0.0]);
            b.fixed = i == 0;
            bodies.push(b);
            if i > 0 {
                joints.push(Joint { bodies: [index - 1, index], anchors: [[0.0, -0.5, 0.0], [0.0, 0.5, 0.0]] });
            }
            if k > 0 {
                joints.push(Joint { bodies: [index - side as i32, index], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] });
            }
        }
    }
    let mut s = box3d_world(bodies, joints);
    s.ground = None;
    s
}

/// The names `verlet scene` knows, with a line on each.
pub const NAMES: &[(&str, &str)] = &[
    ("drop", "one unit box falling tilted from 3 m onto the ground"),
    ("sphere", "one ball (restitution 0.8) dropped from 5 m"),
    ("cubes", "--count random unit cubes falling side by side (--seed)"),
    ("pile", "--count random unit cubes dropped in four layers: they pile up (--seed)"),
    ("stack", "--count unit boxes in a column"),
    ("pyramid", "--count rows of unit boxes"),
    ("chain", "--count links on ball joints, pinned at one end, laid out horizontally"),
    ("hanging", "--count links on ball joints hung by both ends: settles into a catenary"),
    ("bridge", "--count planks on ball joints between two fixed posts"),
    ("ragdoll", "--count ragdolls dropped onto a pile of boxes"),
    ("blast", "a wall of --count x 6 boxes, blown apart at t = 1 s by its default input track"),
    ("large_pyramid", "Box3D's benchmark: a pyramid of --count rows (100) of unit cubes touching side by side"),
    ("many_pyramids", "Box3D's benchmark: --count x --count pyramids (14 x 14) of 10 rows of unit cubes"),
    ("joint_grid", "Box3D's benchmark: --count x --count balls (100 x 100) on ball joints, hung by the top row"),
];

/// The most bodies a built-in scene is built with (`verlet scene`,
/// `verlet run --builtin`, `verlet bench` cases), on any adapter: 2^20. No
/// adapter holds more, since a pass dispatches at most 65 535 workgroups of
/// 64 per dimension and the hash table has up to four buckets per body
/// (`world::max_bodies`); `verlet run` also checks the adapter's own limit.
pub const MAX_BODIES: u64 = 1 << 20;

/// The built-in scenes that `--seed` changes.
pub const RANDOM: &[&str] = &["cubes", "pile"];

/// The default `--count` of a scene that takes one; None for one that
/// takes none (`drop`, `sphere`) or an unknown name.
pub fn default_count(name: &str) -> Option<usize> {
    Some(match name {
        "cubes" | "pile" => 1000,
        "stack" | "pyramid" | "blast" | "ragdoll" => 10,
        "chain" => 21,
        "hanging" | "bridge" => 20,
        // Box3D's sizes
        "large_pyramid" | "joint_grid" => 100,
        "many_pyramids" => 14,
        _ => return None,
    })
}

/// The smallest `--count` a scene takes: `hanging` needs two links.
fn min_count(name: &str) -> usize {
    if name == "hanging" {
        2
    } else {
        1
    }
}

/// The bodies the named scene has at `count` (None: its default), worked
/// out without building it (saturating, so any count is safe to ask
/// about); None for an unknown name.
pub fn body_count(name: &str, count: Option<usize>) -> Option<u64> {
    let n = count.or_else(|| default_count(name)).unwrap_or(0) as u64;
    Some(match name {
        "drop" | "sphere" => 1,
        "cubes" | "pile" | "stack" | "chain" => n,
        "hanging" => n.max(2),
        // rows + (rows - 1) + ... + 1
        "pyramid" | "large_pyramid" => n.saturating_mul(n.saturating_add(1)) / 2,
        "many_pyramids" => n.saturating_mul(n).saturating_mul(SMALL_PYRAMID_BOXES as u64),
        "joint_grid" => n.saturating_mul(n),
        "bridge" => n.saturating_add(2),
        // a pile of 10 boxes, then 10 parts per ragdoll
        "ragdoll" => n.saturating_mul(10).saturating_add(10),
        "blast" => n.saturating_mul(6),
        _ => return None,
    })
}

/// Checks a built-in scene's name and `--count` before anything is built:
/// the name is known, the count is one the scene takes (at least 1; 2 for
/// `hanging`), and the scene has at most `max_bodies` bodies (and
/// [`MAX_BODIES`]). Returns the scene's body count. Errors name `--count`.
pub fn check(name: &str, count: Option<usize>, max_bodies: u64) -> Result<u64, Error> {
    let Some(bodies) = body_count(name, count) else {
        let names: Vec<&str> = NAMES.iter().map(|(n, _)| *n).collect();
        let guess = closest(name, &names).map_or(String::new(), |g| format!("; did you mean {g}?"));
        return Err(Error::Input(format!("unknown scene {name:?}{guess} (known: {})", names.join(", "))));
    };
    if let Some(count) = count {
        let min = min_count(name);
        if default_count(name).is_some() && count < min {
            return Err(Error::Input(format!("--count: the {name} scene takes at least {min}, got {count}")));
        }
    }
    let max = max_bodies.min(MAX_BODIES);
    if bodies > max {
        let what = match count {
            Some(count) => format!("--count {count}"),
            None => "its default count".to_string(),
        };
        let limit = if max < MAX_BODIES {
            format!("this adapter holds at most {max} (see `verlet info`)")
        } else {
            format!("built-in scenes have at most {max} (scenes::MAX_BODIES, more than any adapter holds)")
        };
        // a count the sum saturated on has no honest figure (a pyramid of
        // 4294967297 rows read as 9223372036854775807 bodies)
        let has = if bodies >= u64::MAX / 4 { format!("more than {max} bodies") } else { format!("{bodies} bodies") };
        return Err(Error::Capacity(format!("--count: the {name} scene with {what} has {has}, but {limit}")));
    }
    Ok(bodies)
}

/// The one of `known` nearest to a mistyped `word`: within two edits
/// (insert, delete, replace, or swap two neighbours), ignoring case, and
/// nearer than any other. `None` when nothing is that near or two tie.
pub fn closest<'a>(word: &str, known: &[&'a str]) -> Option<&'a str> {
    let word: Vec<char> = word.to_lowercase().chars().collect();
    let mut scored: Vec<(usize, &str)> =
        known.iter().map(|k| (edits(&word, &k.to_lowercase().chars().collect::<Vec<_>>()), *k)).collect();
    scored.sort_by_key(|s| s.0);
    match scored.as_slice() {
        [(d, best), rest @ ..] if *d <= 2 && rest.first().is_none_or(|next| next.0 > *d) => Some(best),
        _ => None,
    }
}

/// Edits from `a` to `b` (optimal string alignment distance).
fn edits(a: &[char], b: &[char]) -> usize {
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

/// The named scene, after [`check`] against `max_bodies`.
pub fn checked(name: &str, count: Option<usize>, seed: u64, max_bodies: u64) -> Result<Scene, Error> {
    check(name, count, max_bodies)?;
    by_name(name, count, seed).ok_or_else(|| Error::Input(format!("unknown scene {name:?}")))
}

/// The named scene; `count` defaults per scene when `None`. Builds what
/// it is asked: see [`check`] for a count from a user.
pub fn by_name(name: &str, count: Option<usize>, seed: u64) -> Option<Scene> {
    let n = count.or_else(|| default_count(name)).unwrap_or(0);
    Some(match name {
        "drop" => drop(),
        "sphere" => sphere(),
        "cubes" => cubes(n, seed),
        "pile" => pile(n, seed),
        "stack" => stack(n),
        "pyramid" => pyramid(n),
        "chain" => chain(n),
        "hanging" => hanging(n),
        "bridge" => bridge(n),
        "ragdoll" => ragdoll(n),
        "blast" => blast(n),
        "large_pyramid" => large_pyramid(n),
        "many_pyramids" => many_pyramids(n),
        "joint_grid" => joint_grid(n),
        _ => return None,
    })
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

    fn centre(b: &Body) -> glam::Vec3 {
        glam::Vec3::from(b.position)
    }

    /// Asserts that the unit cubes of `s` stand as a pyramid's should: upright,
    /// none overlapping another, neighbours in a row touching, and each on
    /// the ground or on exactly two cubes of the row below, half a cube
    /// to either side.
    fn assert_stacked(s: &Scene) {
        let b = &s.bodies;
        for (n, x) in b.iter().enumerate() {
            assert_eq!(x.shape, Shape::Box { half_extents: [0.5; 3] }, "cube {n}");
            assert_eq!(x.orientation, [0.0, 0.0, 0.0, 1.0], "cube {n}");
            assert!((x.mass - 100.0).abs() < 1e-3, "cube {n} weighs {} kg, Box3D's 100 kg/m^3 makes 100", x.mass);
            let p = centre(x);
            let mut under = 0;
            for (m, y) in b.iter().enumerate().filter(|&(m, _)| m != n) {
                let d = centre(y) - p;
                // unit cubes overlap where every axis is nearer than 1 m
                assert!(d.abs().max_element() >= 1.0 - 1e-5, "cubes {n} and {m} overlap: {d}");
                if d.z == 0.0 && d.y == -1.0 && (d.x.abs() - 0.5).abs() < 1e-5 {
                    under += 1;
                }
            }
            let row = p.y - 0.5;
            assert_eq!(row, row.round(), "cube {n} at height {}: rows are 1 m apart from the ground up", p.y);
            assert_eq!(under, if row == 0.0 { 0 } else { 2 }, "cube {n} at {p} rests on {under} cubes");
            if row == 0.0 {
                assert_eq!(p.y, 0.5, "cube {n} stands on the ground");
            }
        }
    }

    #[test]
    fn large_pyramid_is_box3ds_at_its_default_size() {
        let s = by_name("large_pyramid", None, 1).unwrap();
        assert_eq!(s.bodies.len(), 5050);
        assert_eq!(body_count("large_pyramid", None), Some(5050));
        assert!(s.joints.is_empty());
        assert_eq!(s.ground, Some(Ground { height: 0.0 }));
        assert_eq!((s.settings.gravity, s.settings.friction, s.settings.sleeping), ([0.0, -10.0, 0.0], 0.6, false));
        s.validate().unwrap();
        // centred, the bottom row 100 cubes touching side by side
        let bottom: Vec<f32> = s.bodies.iter().filter(|b| b.position[1] == 0.5).map(|b| b.position[0]).collect();
        assert_eq!(bottom.len(), 100);
        assert_eq!((bottom[0], bottom[99]), (-49.5, 49.5));
        let top = s.bodies.iter().map(|b| b.position[1]).fold(0.0, f32::max);
        assert_eq!(top, 99.5);
    }

    #[test]
    fn the_cubes_of_a_large_pyramid_touch_without_overlapping() {
        for rows in [1, 2, 7, 30] {
            let s = large_pyramid(rows);
            assert_eq!(s.bodies.len(), rows * (rows + 1) / 2);
            assert_stacked(&s);
        }
    }

    #[test]
    fn many_pyramids_is_box3ds_at_its_default_size() {
        let s = by_name("many_pyramids", None, 1).unwrap();
        assert_eq!(s.bodies.len(), 196 * 55);
        assert_eq!(body_count("many_pyramids", None), Some(10_780));
        s.validate().unwrap();
        // on Box3D's ground, a square of half-width 77 m, about centred
        let (lo, hi) = s.bodies.iter().fold((f32::MAX, f32::MIN), |(lo, hi), b| {
            (lo.min(b.position[0] - 0.5).min(b.position[2]), hi.max(b.position[0] + 0.5).max(b.position[2]))
        });
        assert!(lo >= -77.0 && hi <= 77.0 && (lo + hi).abs() < 1.0, "the pyramids span {lo} to {hi} m");
        // 14 rows of pyramids along z, 14 pyramid bases along x
        let mut zs: Vec<f32> = s.bodies.iter().map(|b| b.position[2]).collect();
        zs.dedup();
        zs.sort_by(f32::total_cmp);
        zs.dedup();
        assert_eq!(zs.len(), 14);
        assert!((zs[1] - zs[0] - 152.0 / 13.0).abs() < 1e-3, "rows of pyramids {} m apart", zs[1] - zs[0]);
        assert_eq!(s.bodies.iter().filter(|b| b.position[1] == 0.5 && b.position[2] == zs[0]).count(), 140);
    }

    #[test]
    fn the_cubes_of_many_pyramids_touch_without_overlapping() {
        for side in [1, 2, 3] {
            let s = many_pyramids(side);
            assert_eq!(s.bodies.len(), side * side * SMALL_PYRAMID_BOXES);
            assert_eq!(body_count("many_pyramids", Some(side)), Some(s.bodies.len() as u64));
            assert_stacked(&s);
        }
        // a metre between one pyramid's base and the next along x
        let s = many_pyramids(2);
        let bottom: Vec<f32> = s.bodies.iter().filter(|b| b.position[1] == 0.5).map(|b| b.position[0]).collect();
        let gaps: Vec<f32> = bottom.windows(2).map(|w| w[1] - w[0]).filter(|&d| d != 1.0).collect();
        assert!(gaps.iter().all(|&d| d == 2.0 || d < 0.0), "bases' centres {gaps:?} apart where they are not neighbours");
    }

    #[test]
    fn joint_grid_is_box3ds_at_its_default_size() {
        let s = by_name("joint_grid", None, 1).unwrap();
        assert_eq!((s.bodies.len(), s.joints.len()), (10_000, 19_800));
        assert_eq!(body_count("joint_grid", None), Some(10_000));
        assert_eq!(s.bodies.iter().filter(|b| b.fixed).count(), 100);
        assert_eq!(s.ground, None);
        s.validate().unwrap();
    }

    #[test]
    fn joint_grid_joins_neighbours_at_matching_anchors() {
        for side in [1, 2, 5, 10] {
            let s = joint_grid(side);
            assert_eq!((s.bodies.len(), s.joints.len()), (side * side, 2 * side * (side - 1)));
            let mut pairs = std::collections::HashSet::new();
            for (n, j) in s.joints.iter().enumerate() {
                let [a, b] = j.bodies.map(|i| &s.bodies[i as usize]);
                // the anchors meet halfway between neighbours 1 m apart
                let (pa, pb) = (centre(a) + glam::Vec3::from(j.anchors[0]), centre(b) + glam::Vec3::from(j.anchors[1]));
                assert_eq!(pa, pb, "joint {n}: its anchors are apart at the start");
                assert_eq!((centre(a) - centre(b)).length(), 1.0, "joint {n} joins bodies that are not neighbours");
                assert_eq!((pa - centre(a)).length(), 0.5, "joint {n}");
                assert!(pairs.insert(j.bodies), "joint {n} repeats another");
            }
            // the top row hangs from nothing else: it is fixed, the rest move
            for b in &s.bodies {
                assert_eq!(b.fixed, b.position[1] == 0.0);
                assert_eq!(b.shape, Shape::Sphere { radius: 0.4 });
            }
            s.validate().unwrap();
        }
    }

    #[test]
    fn a_mistyped_name_finds_the_one_meant() {
        let names: Vec<&str> = super::NAMES.iter().map(|(n, _)| *n).collect();
        assert_eq!(closest("pyramd", &names), Some("pyramid"));
        assert_eq!(closest("Stakc", &names), Some("stack"));
        assert_eq!(closest("ragdol", &names), Some("ragdoll"));
        assert_eq!(closest("teapot", &names), None, "nothing near");
        assert_eq!(closest("ab", &["ax", "ay"]), None, "two as near: no guess");
    }
}
