//! WGSL sources, assembled per pass from shared pieces. WGSL has no
//! `#include`, so each pass's module is its pieces concatenated in order.

pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
pub const BINDINGS: &str = include_str!("../../shaders/bindings.wgsl");
pub const GRID: &str = include_str!("../../shaders/grid.wgsl");
pub const PAIRS: &str = include_str!("../../shaders/pairs.wgsl");
pub const COLLIDE: &str = include_str!("../../shaders/collide.wgsl");
pub const CAPSULE: &str = include_str!("../../shaders/capsule.wgsl");
pub const HULL: &str = include_str!("../../shaders/hull.wgsl");
pub const NARROWPHASE: &str = include_str!("../../shaders/narrowphase.wgsl");
pub const INTEGRATE: &str = include_str!("../../shaders/integrate.wgsl");
pub const SOLVE: &str = include_str!("../../shaders/solve.wgsl");
pub const RESTITUTION: &str = include_str!("../../shaders/restitution.wgsl");

/// The constants the WGSL shares with Rust, written once: from the Rust
/// values, as WGSL `const` declarations that go first in every module (the
/// step's passes, the input kernels, the renderer).
pub fn shared_constants() -> String {
    use crate::gpu::status::{Status, DISPATCH_Y, DISPATCH_Z};
    use crate::gpu::types::*;
    use crate::limits::{
        FaultKind, CONTACT_MARGIN, CONTACT_SLOP, MAX_DEPENETRATION_SPEED, MAX_DISTANCE, MAX_SPEED, MAX_SPIN, MAX_TURN, NO_FAULT,
    };
    let mut out = String::from("// Shared with Rust: written by src/gpu/shaders.rs from the Rust constants.\n");
    let words = [
        ("NONE", NONE),
        ("GROUND", GROUND),
        ("WORLD", WORLD),
        ("HELD", HELD),
        ("WAKES", WAKES),
        ("MAX_POINTS", MAX_POINTS),
        ("SHAPE_BOX", SHAPE_BOX),
        ("SHAPE_SPHERE", SHAPE_SPHERE),
        ("SHAPE_CAPSULE", SHAPE_CAPSULE),
        ("SHAPE_HULL", SHAPE_HULL),
        ("FLAG_FIXED", FLAG_FIXED),
        ("FLAG_KINEMATIC", FLAG_KINEMATIC),
        ("GRID_BODY", GRID_BODY),
        ("LARGE_BODY", LARGE_BODY),
        ("WORKGROUP", WORKGROUP),
        ("PATH_WORKGROUP", PATH_WORKGROUP),
        ("PATH_SLOT", PATH_SLOT),
        ("SCAN_BLOCK", SCAN_BLOCK),
        ("SCAN_RUN", SCAN_RUN),
        ("SCAN_SPAN", SCAN_SPAN),
        ("WOKEN_NOW", WOKEN_NOW),
        ("BODY_BITS", BODY_BITS),
        ("MOVES_SHIFT", MOVES_SHIFT),
        ("FAST_BODY", FAST_BODY),
        ("NO_FAULT", NO_FAULT),
        ("FAULT_NON_FINITE", FaultKind::NonFinite as u32),
        ("FAULT_FAR", FaultKind::TooFar as u32),
        ("FAULT_FAST", FaultKind::TooFast as u32),
        ("FAULT_SPIN", FaultKind::SpinsTooFast as u32),
        ("FAULT_ENERGY", FaultKind::FasterThanItsEnergy as u32),
        ("DISPATCH_Y", DISPATCH_Y),
        ("DISPATCH_Z", DISPATCH_Z),
    ];
    for (name, value) in words.into_iter().chain(Status::WORDS) {
        out += &wgsl_u32(name, value);
    }
    for (name, value) in [
        ("MAX_DISTANCE", MAX_DISTANCE),
        ("MAX_SPEED", MAX_SPEED),
        ("MAX_SPIN", MAX_SPIN),
        ("MAX_TURN", MAX_TURN),
        ("MAX_DEPENETRATION_SPEED", MAX_DEPENETRATION_SPEED),
        ("CONTACT_MARGIN", CONTACT_MARGIN),
        ("CONTACT_SLOP", CONTACT_SLOP),
    ] {
        out += &wgsl_f32(name, value);
    }
    out
}

/// `const NAME: u32 = value;` in WGSL.
pub(crate) fn wgsl_u32(name: &str, value: u32) -> String {
    format!("const {name}: u32 = {value}u;\n")
}

/// `const NAME: f32 = value;` in WGSL, the value exactly (Rust's shortest
/// round-trip form always has a point or an exponent).
pub fn wgsl_f32(name: &str, value: f32) -> String {
    format!("const {name}: f32 = {value:?};\n")
}

/// The pieces of the step's passes' modules, in order (see `Stage::pieces`).
pub(crate) const GRID_PASS: &[&str] = &[COMMON, BINDINGS, GRID];
pub(crate) const PAIRS_PASS: &[&str] = &[COMMON, BINDINGS, GRID, PAIRS];
pub(crate) const NARROWPHASE_PASS: &[&str] = &[COMMON, BINDINGS, GRID, PAIRS, COLLIDE, CAPSULE, HULL, NARROWPHASE];
pub(crate) const INTEGRATE_PASS: &[&str] = &[COMMON, BINDINGS, RESTITUTION, INTEGRATE];
pub(crate) const SOLVE_PASS: &[&str] = &[COMMON, BINDINGS, SOLVE];
pub(crate) const RESTITUTION_PASS: &[&str] = &[COMMON, BINDINGS, RESTITUTION];

/// Parses and validates WGSL with naga, as the device would.
pub fn validate(source: &str) -> Result<naga::Module, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .map_err(|e| e.emit_to_string(source))?;
    Ok(module)
}

/// What entry point `entry` of the WGSL `source` does with each buffer it
/// binds, as naga's analysis finds it: (binding, reads, writes), in binding
/// order, for every buffer it touches. `arrayLength` (the binding's size)
/// counts as a read: the buffer must be bound all the same.
pub fn buffer_uses(source: &str, entry: &str) -> Result<Vec<(u32, bool, bool)>, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .map_err(|e| e.emit_to_string(source))?;
    let index = module.entry_points.iter().position(|e| e.name == entry).ok_or_else(|| format!("no entry point {entry}"))?;
    let uses = info.get_entry_point(index);
    let mut out: Vec<(u32, bool, bool)> = module
        .global_variables
        .iter()
        .filter_map(|(handle, var)| {
            let binding = var.binding.as_ref()?.binding;
            let used = uses[handle];
            // arrayLength reads the binding's size (a query): it must be bound
            let reads = used.intersects(naga::valid::GlobalUse::READ | naga::valid::GlobalUse::QUERY);
            let writes = used.contains(naga::valid::GlobalUse::WRITE);
            (reads || writes).then_some((binding, reads, writes))
        })
        .collect();
    out.sort();
    Ok(out)
}
