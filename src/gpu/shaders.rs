//! WGSL sources, assembled per pass from shared pieces. WGSL has no
//! `#include`, so each pass's module is its pieces concatenated in order.

pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
pub const BINDINGS: &str = include_str!("../../shaders/bindings.wgsl");
pub const GRID: &str = include_str!("../../shaders/grid.wgsl");
pub const COLLIDE: &str = include_str!("../../shaders/collide.wgsl");
pub const NARROWPHASE: &str = include_str!("../../shaders/narrowphase.wgsl");
pub const INTEGRATE: &str = include_str!("../../shaders/integrate.wgsl");
pub const SOLVE: &str = include_str!("../../shaders/solve.wgsl");
pub const RESTITUTION: &str = include_str!("../../shaders/restitution.wgsl");

const GRID_PASS: &[&str] = &[COMMON, BINDINGS, GRID];

/// Every compute pass: its entry point (named like the pass; grid passes
/// live together in grid.wgsl) and the pieces of its module, in order.
pub const PASSES: &[(&str, &[&str])] = &[
    ("grid_clear", GRID_PASS),
    ("grid_count", GRID_PASS),
    ("grid_scan_blocks", GRID_PASS),
    ("grid_scan_sums", GRID_PASS),
    ("grid_scan_add", GRID_PASS),
    ("grid_scatter", GRID_PASS),
    ("grid_sort", GRID_PASS),
    ("narrowphase", &[COMMON, BINDINGS, GRID, COLLIDE, NARROWPHASE]),
    ("integrate", &[COMMON, BINDINGS, INTEGRATE]),
    ("solve", &[COMMON, BINDINGS, SOLVE]),
    ("restitution", &[COMMON, BINDINGS, RESTITUTION]),
];

/// The assembled source of the named pass.
pub fn pass_source(name: &str) -> Option<String> {
    PASSES.iter().find(|(n, _)| *n == name).map(|(_, parts)| parts.concat())
}

/// Parses and validates WGSL with naga, as the device would.
pub fn validate(source: &str) -> Result<naga::Module, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .map_err(|e| e.emit_to_string(source))?;
    Ok(module)
}
