//! Every compute pass validates with naga, on any machine, GPU or not.

use verlet::gpu::shaders;

#[test]
fn every_pass_validates_with_naga() {
    assert!(!shaders::PASSES.is_empty());
    for (name, _) in shaders::PASSES {
        let source = shaders::pass_source(name).unwrap();
        let module = shaders::validate(&source).unwrap_or_else(|e| panic!("{name}.wgsl does not validate:\n{e}"));
        assert!(
            module.entry_points.iter().any(|e| e.name == *name),
            "{name}: no entry point named like the pass"
        );
    }
}

#[test]
fn a_broken_shader_is_refused() {
    let source = format!("{}{}\nfn broken() -> f32 {{ return vec3<f32>(1.0); }}", shaders::COMMON, shaders::BINDINGS);
    assert!(shaders::validate(&source).is_err());
}
