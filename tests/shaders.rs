//! Every compute pass validates with naga, on any machine, GPU or not.

use verlet::gpu::shaders;

#[test]
fn every_pass_validates_with_naga() {
    assert!(!shaders::PASSES.is_empty());
    for (name, entry, _) in shaders::PASSES {
        let source = shaders::pass_source(name).unwrap();
        let module = shaders::validate(&source).unwrap_or_else(|e| panic!("{name}.wgsl does not validate:\n{e}"));
        assert!(module.entry_points.iter().any(|e| e.name == *entry), "{name}: no entry point {entry}");
    }
}

#[test]
fn a_broken_shader_is_refused() {
    let source = format!("{}{}\nfn broken() -> f32 {{ return vec3<f32>(1.0); }}", shaders::COMMON, shaders::BINDINGS);
    assert!(shaders::validate(&source).is_err());
}

#[test]
fn the_input_kernels_validate() {
    use verlet::world::input;
    let source = input::source();
    let module = shaders::validate(&source).unwrap_or_else(|e| panic!("input.wgsl does not validate:\n{e}"));
    for name in input::ENTRY_POINTS {
        assert!(module.entry_points.iter().any(|e| e.name == name), "input.wgsl: no entry point {name}");
    }
    // the host twins match the WGSL structs' sizes
    for (name, size) in
        [("InputHeader", std::mem::size_of::<input::InputHeader>()), ("InputOp", std::mem::size_of::<input::InputOp>())]
    {
        let ty = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("input.wgsl: no struct {name}"));
        let naga::TypeInner::Struct { span, .. } = ty.1.inner else { panic!("{name} is not a struct") };
        assert_eq!(span as usize, size, "{name}: WGSL size {span}, host size {size}");
    }
}
