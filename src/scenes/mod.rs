//! Named built-in scenes, shared by the command line (`verlet scene NAME`),
//! the tests and the benchmarks: a name means one scene everywhere.
//!
//! [`SCENES`] has one row per scene (its name, how it is built, its default
//! `count`, its body count, its help line); every lookup by name below is
//! read from it, so a scene is added in one place. The builders themselves
//! are in `build.rs` (ours) and `box3d.rs` (Box3D's benchmarks).

mod box3d;
mod build;

pub use box3d::{joint_grid, large_pyramid, many_pyramids, washer, washer_drum, Drum};
use box3d::{SMALL_PYRAMID_BOXES, WASHER_DRUM_BODIES};
pub use build::{
    blast, blast_track, box_body, bridge, capsule_ragdoll, capsules, chain, convex_pile, cubes, drop, hanging, pile, pyramid,
    ragdoll, sphere, sphere_body, stack,
};

use crate::scene::Scene;
use crate::track::Track;
use crate::Error;

/// How a built-in scene is built from `count` and `seed`.
#[derive(Clone, Copy, Debug)]
pub enum Build {
    /// Takes neither.
    Fixed(fn() -> Scene),
    /// Takes `count`.
    Counted(fn(usize) -> Scene),
    /// Takes `count` and `seed`: a random scene.
    Seeded(fn(usize, u64) -> Scene),
}

/// One built-in scene: a row of [`SCENES`].
#[derive(Clone, Copy, Debug)]
pub struct BuiltIn {
    pub name: &'static str,
    pub build: Build,
    /// The `count` used when none is given; None for a scene that takes none.
    pub default_count: Option<usize>,
    /// The smallest `count` it takes.
    pub min_count: usize,
    /// Its bodies at a count, worked out without building it; saturating,
    /// so any count is safe to ask about.
    pub bodies: fn(u64) -> u64,
    /// The input track `verlet run --builtin NAME` plays unless `--input`
    /// gives another.
    pub track: Option<fn() -> Track>,
    /// A line on it, naming its parameters as `{count}` and `{seed}`
    /// ([`BuiltIn::help_with`] names them).
    pub help: &'static str,
}

impl BuiltIn {
    /// Its help line with its parameters called `count` and `seed` (the
    /// command line passes its flags).
    pub fn help_with(&self, count: &str, seed: &str) -> String {
        self.help.replace("{count}", count).replace("{seed}", seed)
    }

    const fn fixed(name: &'static str, build: fn() -> Scene, help: &'static str) -> BuiltIn {
        BuiltIn { name, build: Build::Fixed(build), default_count: None, min_count: 1, bodies: |_| 1, track: None, help }
    }

    const fn counted(
        name: &'static str,
        build: fn(usize) -> Scene,
        default_count: usize,
        bodies: fn(u64) -> u64,
        help: &'static str,
    ) -> BuiltIn {
        BuiltIn { name, build: Build::Counted(build), default_count: Some(default_count), min_count: 1, bodies, track: None, help }
    }

    const fn seeded(
        name: &'static str,
        build: fn(usize, u64) -> Scene,
        default_count: usize,
        bodies: fn(u64) -> u64,
        help: &'static str,
    ) -> BuiltIn {
        BuiltIn { name, build: Build::Seeded(build), default_count: Some(default_count), min_count: 1, bodies, track: None, help }
    }

    const fn at_least(mut self, min_count: usize) -> BuiltIn {
        self.min_count = min_count;
        self
    }

    const fn with_track(mut self, track: fn() -> Track) -> BuiltIn {
        self.track = Some(track);
        self
    }

    /// The scene at `count` (None: the default); `seed` only where it is random.
    pub fn scene(&self, count: Option<usize>, seed: u64) -> Scene {
        let n = count.or(self.default_count).unwrap_or(0);
        match self.build {
            Build::Fixed(build) => build(),
            Build::Counted(build) => build(n),
            Build::Seeded(build) => build(n, seed),
        }
    }

    /// Its bodies at `count` (None: the default), without building it.
    pub fn body_count(&self, count: Option<usize>) -> u64 {
        (self.bodies)(count.or(self.default_count).unwrap_or(0) as u64)
    }
}

/// rows + (rows - 1) + ... + 1, saturating.
fn triangle(rows: u64) -> u64 {
    rows.saturating_mul(rows.saturating_add(1)) / 2
}

/// Every built-in scene, in the order `verlet scene` lists them.
pub const SCENES: &[BuiltIn] = &[
    BuiltIn::fixed("drop", drop, "one unit box falling tilted from 3 m onto the ground"),
    BuiltIn::fixed("sphere", sphere, "one ball (restitution 0.8) dropped from 5 m"),
    BuiltIn::seeded("cubes", cubes, 1000, |n| n, "{count} random unit cubes falling side by side ({seed})"),
    BuiltIn::seeded("pile", pile, 1000, |n| n, "{count} random unit cubes dropped in four layers: they pile up ({seed})"),
    BuiltIn::counted("stack", stack, 10, |n| n, "{count} unit boxes in a column"),
    BuiltIn::counted("pyramid", pyramid, 10, triangle, "{count} rows of unit boxes"),
    BuiltIn::counted("chain", chain, 21, |n| n, "{count} links on ball joints, pinned at one end, laid out horizontally"),
    BuiltIn::counted(
        "hanging",
        hanging,
        20,
        |n| n.max(2),
        "{count} links on ball joints hung by both ends: settles into a catenary",
    )
    .at_least(2),
    BuiltIn::counted("bridge", bridge, 20, |n| n.saturating_add(2), "{count} planks on ball joints between two fixed posts"),
    // a pile of 10 boxes, then 10 parts per ragdoll
    BuiltIn::counted(
        "ragdoll",
        ragdoll,
        10,
        |n| n.saturating_mul(10).saturating_add(10),
        "{count} ragdolls dropped onto a pile of boxes",
    ),
    BuiltIn::counted(
        "capsule_ragdoll",
        capsule_ragdoll,
        10,
        |n| n.saturating_mul(10).saturating_add(10),
        "{count} ragdolls with capsule limbs and ball heads dropped onto a pile of boxes",
    ),
    BuiltIn::seeded("capsules", capsules, 1000, |n| n, "{count} random capsules dropped in four layers: they heap up ({seed})"),
    BuiltIn::seeded(
        "convex_pile",
        convex_pile,
        1000,
        |n| n,
        "{count} random convex rocks (hulls) dropped in four layers onto each other, after Box3D's benchmark ({seed})",
    ),
    BuiltIn::counted(
        "blast",
        blast,
        10,
        |n| n.saturating_mul(6),
        "a wall of {count} x 6 boxes, blown apart at t = 1 s by its default input track",
    )
    .with_track(blast_track),
    // Box3D's benchmarks, at Box3D's sizes by default
    BuiltIn::counted(
        "large_pyramid",
        large_pyramid,
        100,
        triangle,
        "Box3D's benchmark: a pyramid of {count} rows (100) of unit cubes touching side by side",
    ),
    BuiltIn::counted(
        "many_pyramids",
        many_pyramids,
        14,
        |n| n.saturating_mul(n).saturating_mul(SMALL_PYRAMID_BOXES as u64),
        "Box3D's benchmark: {count} x {count} pyramids (14 x 14) of 10 rows of unit cubes",
    ),
    BuiltIn::counted(
        "joint_grid",
        joint_grid,
        100,
        |n| n.saturating_mul(n),
        "Box3D's benchmark: {count} x {count} balls (100 x 100) on ball joints, hung by the top row",
    ),
    BuiltIn::counted(
        "washer",
        washer,
        20,
        |n| n.saturating_mul(n).saturating_mul(n).saturating_add(WASHER_DRUM_BODIES as u64),
        "Box3D's benchmark: {count} x {count} x {count} cubes (20 x 20 x 20) tumbled in a drum of kinematic hull panels, \
         closed by fixed end walls",
    ),
];

/// The row of the built-in scene called `name`.
pub fn find(name: &str) -> Option<&'static BuiltIn> {
    SCENES.iter().find(|s| s.name == name)
}

/// The built-in scenes' names, in [`SCENES`]' order, as a constant.
pub const NAMES: &[&str] = &{
    let mut names = [""; SCENES.len()];
    let mut k = 0;
    while k < SCENES.len() {
        names[k] = SCENES[k].name;
        k += 1;
    }
    names
};

/// How many built-in scenes are random.
const RANDOM_COUNT: usize = {
    let (mut count, mut k) = (0, 0);
    while k < SCENES.len() {
        if matches!(SCENES[k].build, Build::Seeded(_)) {
            count += 1;
        }
        k += 1;
    }
    count
};

/// The built-in scenes that `seed` changes: [`SCENES`]' random ones.
pub const RANDOM: &[&str] = &{
    let mut names = [""; RANDOM_COUNT];
    let (mut k, mut at) = (0, 0);
    while k < SCENES.len() {
        if matches!(SCENES[k].build, Build::Seeded(_)) {
            names[at] = SCENES[k].name;
            at += 1;
        }
        k += 1;
    }
    names
};

/// The most bodies a built-in scene is built with (`verlet scene`,
/// `verlet run --builtin`, `verlet bench` cases), on any adapter: 2^20. No
/// adapter holds more, since a pass dispatches at most 65 535 workgroups of
/// 64 per dimension and the hash table has up to four buckets per body
/// (`world::max_bodies`); `verlet run` also checks the adapter's own limit.
pub const MAX_BODIES: u64 = 1 << 20;

// The file size limit allows 1 KiB a body for as many bodies as this.
const _: () = assert!(crate::load_error::MAX_FILE_BYTES == 1024 * MAX_BODIES);

/// The default `count` of a scene that takes one; None for one that
/// takes none (`drop`, `sphere`) or an unknown name.
pub fn default_count(name: &str) -> Option<usize> {
    find(name)?.default_count
}

/// The bodies the named scene has at `count` (None: its default), worked
/// out without building it (saturating, so any count is safe to ask
/// about); None for an unknown name.
pub fn body_count(name: &str, count: Option<usize>) -> Option<u64> {
    Some(find(name)?.body_count(count))
}

/// The input track the named scene plays by default: `blast`'s explosion.
pub fn default_track(name: &str) -> Option<Track> {
    Some((find(name)?.track?)())
}

/// Checks a built-in scene's name and `count` before anything is built:
/// the name is known, the count is one the scene takes (at least 1; 2 for
/// `hanging`), and the scene has at most `max_bodies` bodies (and
/// [`MAX_BODIES`]). Returns the scene's body count. A bad count is an [`Error::Argument`] named `count`.
pub fn check(name: &str, count: Option<usize>, max_bodies: u64) -> Result<u64, Error> {
    let Some(scene) = find(name) else {
        let names: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
        let guess = closest(name, &names).map_or(String::new(), |g| format!("; did you mean {g}?"));
        return Err(Error::Input(format!("unknown scene {name:?}{guess} (known: {})", names.join(", "))));
    };
    let bodies = scene.body_count(count);
    if let Some(count) = count {
        let min = scene.min_count;
        if scene.default_count.is_some() && count < min {
            return Err(Error::Argument { name: "count", reason: format!("the {name} scene takes at least {min}, got {count}") });
        }
    }
    let max = max_bodies.min(MAX_BODIES);
    if bodies > max {
        let what = match count {
            Some(count) => format!("a count of {count}"),
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
        return Err(Error::Argument {
            name: "count",
            reason: format!("the {name} scene with {what} is too large: it has {has}, but {limit}"),
        });
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
    Some(find(name)?.scene(count, seed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mistyped_name_finds_the_one_meant() {
        let names: Vec<&str> = super::NAMES.to_vec();
        assert_eq!(closest("pyramd", &names), Some("pyramid"));
        assert_eq!(closest("Stakc", &names), Some("stack"));
        assert_eq!(closest("ragdol", &names), Some("ragdoll"));
        assert_eq!(closest("teapot", &names), None, "nothing near");
        assert_eq!(closest("ab", &["ax", "ay"]), None, "two as near: no guess");
    }

    #[test]
    fn the_derived_lists_follow_the_table() {
        let names: Vec<&str> = SCENES.iter().map(|s| s.name).collect();
        assert_eq!(NAMES.to_vec(), names);
        assert_eq!(RANDOM, ["cubes", "pile", "capsules", "convex_pile"]);
        let mut unique = names.clone();
        unique.sort();
        unique.dedup();
        assert_eq!(unique.len(), names.len(), "a name names one scene");
        assert_eq!(default_count("drop"), None);
        assert_eq!(default_count("chain"), Some(21));
        assert!(default_track("blast").is_some() && default_track("stack").is_none());
    }

    #[test]
    fn every_row_counts_the_bodies_it_builds() {
        for s in SCENES {
            for count in [None, Some(1), Some(2), Some(3)] {
                let built = s.scene(count, 7).bodies.len() as u64;
                assert_eq!(built, s.body_count(count), "{} at {count:?}", s.name);
            }
        }
    }
}
