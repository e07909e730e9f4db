//! `verlet scene NAME`, and the warnings it shares with `verlet run
//! --builtin NAME` about flags a built-in scene does not use.

use verlet::{scenes, Error};

/// The seed of the random built-in scenes when `--seed` is not given.
pub const DEFAULT_SEED: u64 = 1;

/// Warns when `--seed` is given to a built-in scene that is not random.
pub fn warn_unused_seed(name: &str, seed: Option<u64>) {
    if seed.is_some() && scenes::body_count(name, None).is_some() && !scenes::RANDOM.contains(&name) {
        eprintln!("warning: --seed: the {name} scene is not random (the random ones: {}); ignored", scenes::RANDOM.join(", "));
    }
}

/// Warns when `--count` is given to a built-in scene that takes none.
pub fn warn_unused_count(name: &str, count: Option<usize>) {
    if count.is_some() && scenes::body_count(name, None).is_some() && scenes::default_count(name).is_none() {
        eprintln!("warning: --count: the {name} scene takes no count; ignored");
    }
}

/// Prints the built-in scene `name` as JSON.
pub fn print(name: &str, count: Option<usize>, seed: Option<u64>) -> Result<(), Error> {
    // bounded before it is built: any adapter's limit (`verlet run` checks this one's)
    let scene = scenes::checked(name, count, seed.unwrap_or(DEFAULT_SEED), scenes::MAX_BODIES).map_err(count_flag)?;
    warn_unused_count(name, count);
    warn_unused_seed(name, seed);
    outln!("{}", scene.to_json())?;
    Ok(())
}

/// A built-in scene's `count` refused, named as the `--count` flag.
pub fn count_flag(e: Error) -> Error {
    e.for_flag("count", "--count")
}
