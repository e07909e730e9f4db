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

/// Every loop of every compute kernel ends: the kernels are built without
/// wgpu's loop bounding (`Gpu::compute_pipelines`), which is only sound
/// for loops that cannot run forever. A loop here is a `for` whose
/// counter (declared in its header) steps up by 1, or doubles up to a
/// constant, towards a bound the loop's body does not assign, which the
/// body does not assign either; or a `while` that steps a counter down by
/// 1 towards a bound (an insertion sort's inner loop). No `loop {}`.
#[test]
fn every_loop_counts_to_a_bound() {
    use verlet::world::input;
    let sources = [
        ("common.wgsl", shaders::COMMON.to_string()),
        ("bindings.wgsl", shaders::BINDINGS.to_string()),
        ("grid.wgsl", shaders::GRID.to_string()),
        ("pairs.wgsl", shaders::PAIRS.to_string()),
        ("collide.wgsl", shaders::COLLIDE.to_string()),
        ("capsule.wgsl", shaders::CAPSULE.to_string()),
        ("hull.wgsl", shaders::HULL.to_string()),
        ("narrowphase.wgsl", shaders::NARROWPHASE.to_string()),
        ("integrate.wgsl", shaders::INTEGRATE.to_string()),
        ("solve.wgsl", shaders::SOLVE.to_string()),
        ("restitution.wgsl", shaders::RESTITUTION.to_string()),
        ("input.wgsl", input::source()),
    ];
    let mut loops = 0;
    for (name, source) in &sources {
        let code = without_comments(source);
        let words: Vec<&str> = code.split(|c: char| !(c.is_alphanumeric() || c == '_')).collect();
        assert!(!words.contains(&"loop"), "{name}: a `loop` statement (use a counted `for`)");
        for (at, _) in code.match_indices("for (") {
            let (header, body) = header_and_body(&code, at + "for ".len());
            let clauses: Vec<&str> = header.split(';').map(str::trim).collect();
            assert_eq!(clauses.len(), 3, "{name}: for ({header})");
            let counter = clauses[0]
                .strip_prefix("var ")
                .and_then(|c| c.split('=').next())
                .map(str::trim)
                .unwrap_or_else(|| panic!("{name}: for ({header}): the counter is not declared in the header"));
            let bound = clauses[1]
                .strip_prefix(&format!("{counter} < "))
                .unwrap_or_else(|| panic!("{name}: for ({header}): not `{counter} < bound`"));
            let step = clauses[2]
                .strip_prefix(&format!("{counter} = {counter} "))
                .unwrap_or_else(|| panic!("{name}: for ({header}): the counter does not step"));
            let constant_bound = bound.chars().all(|c| c.is_ascii_uppercase() || c == '_');
            assert!(
                ["+ 1u", "+ 1"].contains(&step) || (step == "* 2u" && constant_bound),
                "{name}: for ({header}): steps by `{step}`"
            );
            assert!(!assigns(body, counter), "{name}: for ({header}): the body assigns `{counter}`");
            let names = bound.split(|c: char| !(c.is_alphanumeric() || c == '_'));
            for word in names.filter(|w| w.starts_with(|c: char| c.is_alphabetic() || c == '_')) {
                assert!(!assigns(body, word), "{name}: for ({header}): the body assigns `{word}` of the bound");
            }
            loops += 1;
        }
        for (at, _) in code.match_indices("while (") {
            let (header, body) = header_and_body(&code, at + "while ".len());
            let counter = header.split(" > ").next().unwrap_or("").trim();
            let ok = !counter.is_empty()
                && counter.chars().all(|c| c.is_alphanumeric() || c == '_')
                && body.contains(&format!("{counter} = {counter} - 1u;"))
                && body.matches(&format!("{counter} =")).count() == 1;
            assert!(ok, "{name}: while ({header}): not a counter stepped down by 1 towards a bound");
            loops += 1;
        }
    }
    assert!(loops > 30, "found only {loops} loops: the scan missed them");
}

/// The WGSL without its `//` comments.
fn without_comments(source: &str) -> String {
    source.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// The text between the parenthesis at `open` and its match, and the block
/// that follows it (between its braces).
fn header_and_body(code: &str, open: usize) -> (&str, &str) {
    let matching = |from: usize, (l, r): (u8, u8)| {
        let bytes = code.as_bytes();
        let mut depth = 0;
        for (k, &b) in bytes.iter().enumerate().skip(from) {
            if b == l {
                depth += 1;
            } else if b == r {
                depth -= 1;
                if depth == 0 {
                    return k;
                }
            }
        }
        panic!("unbalanced {} at {from}", l as char);
    };
    let close = matching(open, (b'(', b')'));
    let brace = open + code[open..].find('{').expect("a loop's body");
    let end = matching(brace, (b'{', b'}'));
    (&code[open + 1..close], &code[brace + 1..end])
}

/// Whether `body` assigns variable `name` (`name = `, `name += `, ...; not `==`).
fn assigns(body: &str, name: &str) -> bool {
    body.match_indices(name).any(|(at, _)| {
        let before = body[..at].chars().next_back().is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '.');
        let after = body[at + name.len()..].trim_start();
        let op = after.starts_with('=') && !after.starts_with("==")
            || ["+=", "-=", "*=", "/=", "++", "--"].iter().any(|o| after.starts_with(o));
        !before && op
    })
}
