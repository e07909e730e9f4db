//! Every compute pass validates with naga, on any machine, GPU or not.

use verlet::gpu::shaders;

#[test]
fn every_pass_validates_with_naga() {
    for stage in verlet::step::Stage::ALL {
        let (name, entry) = (stage.name(), stage.entry_point());
        let module = shaders::validate(&stage.source()).unwrap_or_else(|e| panic!("{name} does not validate:\n{e}"));
        assert!(module.entry_points.iter().any(|e| e.name == entry), "{name}: no entry point {entry}");
    }
}

#[test]
fn a_broken_shader_is_refused() {
    let source = format!(
        "{}{}{}\nfn broken() -> f32 {{ return vec3<f32>(1.0); }}",
        shaders::shared_constants(),
        shaders::COMMON,
        shaders::BINDINGS
    );
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

/// Every stage's declared reads and writes (`Stage::reads`, `Stage::writes`)
/// are what naga finds its entry point doing with the step's buffers, and the
/// buffers no stage writes are the ones bindings.wgsl declares read-only
/// (the layout derives its read-only flags from the declarations).
#[test]
fn every_stage_declares_the_buffers_it_reads_and_writes() {
    use verlet::step::{Buffer, Stage};
    let bindings = |list: &[Buffer]| {
        let mut b: Vec<u32> = list.iter().map(|b| b.binding()).collect();
        b.sort();
        b
    };
    for stage in Stage::ALL {
        let uses = shaders::buffer_uses(&stage.source(), stage.entry_point()).unwrap();
        let reads: Vec<u32> = uses.iter().filter(|u| u.1).map(|u| u.0).collect();
        let writes: Vec<u32> = uses.iter().filter(|u| u.2).map(|u| u.0).collect();
        assert_eq!(bindings(stage.reads()), reads, "{}: the bindings it reads", stage.name());
        assert_eq!(bindings(stage.writes()), writes, "{}: the bindings it writes", stage.name());
    }
    let source = verlet::step::Stage::Integrate.source();
    let module = shaders::validate(&source).unwrap();
    for buffer in &Buffer::ALL[1..] {
        let (_, var) = module
            .global_variables
            .iter()
            .find(|(_, v)| v.binding.as_ref().is_some_and(|b| b.binding == buffer.binding()))
            .unwrap_or_else(|| panic!("bindings.wgsl declares no binding {}", buffer.binding()));
        let naga::AddressSpace::Storage { access } = var.space else { panic!("{buffer:?} is not a storage buffer") };
        let declared_read_only = !access.contains(naga::StorageAccess::STORE);
        assert_eq!(buffer.read_only(), declared_read_only, "{buffer:?} ({:?}): read-only in the layout", var.name);
    }
}
