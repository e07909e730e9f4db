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
        "pyramid" => n.saturating_mul(n.saturating_add(1)) / 2,
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
    use super::closest;

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
