//! WGSL sources, assembled per pass from shared pieces. WGSL has no
//! `#include`, so each pass's module is its pieces concatenated in order.

pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
pub const BINDINGS: &str = include_str!("../../shaders/bindings.wgsl");
pub const GROUND: &str = include_str!("../../shaders/ground.wgsl");
pub const INTEGRATE: &str = include_str!("../../shaders/integrate.wgsl");
pub const SOLVE: &str = include_str!("../../shaders/solve.wgsl");
pub const RESTITUTION: &str = include_str!("../../shaders/restitution.wgsl");

/// Every compute pass: its entry point (named like the pass and its file)
/// and the pieces of its module, in order.
pub const PASSES: &[(&str, &[&str])] = &[
    ("integrate", &[COMMON, BINDINGS, INTEGRATE]),
    ("solve", &[COMMON, BINDINGS, GROUND, SOLVE]),
    ("restitution", &[COMMON, BINDINGS, GROUND, RESTITUTION]),
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
