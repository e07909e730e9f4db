//! Every struct shared with WGSL matches its Rust twin member by member:
//! names, byte offsets and size.

use std::mem::{offset_of, size_of};

use naga::TypeInner;
use verlet::gpu::{shaders, types::*};

/// (member name, offset) of a WGSL struct, and its size.
fn wgsl_layout(source: &str, name: &str) -> (Vec<(String, u32)>, u32) {
    let module = shaders::validate(source).expect("validates");
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let TypeInner::Struct { members, span } = &ty.inner {
                let m = members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect();
                return (m, *span);
            }
        }
    }
    panic!("struct {name} not found in the WGSL");
}

macro_rules! check_layout {
    ($source:expr, $ty:ident { $($field:ident),* $(,)? }) => {{
        let rust: Vec<(String, u32)> = vec![$((stringify!($field).to_string(), offset_of!($ty, $field) as u32)),*];
        let (wgsl, span) = wgsl_layout($source, stringify!($ty));
        assert_eq!(wgsl, rust, "{}: members (name, offset) differ between WGSL and Rust", stringify!($ty));
        assert_eq!(span as usize, size_of::<$ty>(), "{}: size differs", stringify!($ty));
    }};
}

#[test]
fn shared_structs_match_member_by_member() {
    let common = &format!("{}{}", shaders::COMMON, shaders::BINDINGS);
    check_layout!(common, BodyState { pos, rest_time, disp, pos_low, rot, prev_rot });
    check_layout!(
        common,
        BodyProps { half_extents, inv_inertia, restitution, friction, kept_inv_mass, _pad0, shape, flags, grid_class, _pad1 }
    );
    check_layout!(common, Velocity { linear, angular });
    check_layout!(
        common,
        Params {
            gravity,
            ground_height,
            dt,
            dt_prev,
            relaxation,
            linear_damping,
            angular_damping,
            body_count,
            has_ground,
            ground_restitution,
            ground_friction,
            cell_size,
            hash_size,
            large_count,
            speculative,
            substeps,
            step_index,
            sleep_after,
            substep,
            opaque_zero,
            _pad4,
            _pad5
        }
    );
    check_layout!(common, JointRef { local_self, partner, local_partner, _pad0 });
    check_layout!(common, Pair { a, b });
    check_layout!(common, ContactPoint { local_a, pushed, local_b, _pad0 });
    check_layout!(common, ContactManifold { normal, count, a, b, clip_face, pair, points });
    check_layout!(common, EndSnap { dx, count, dtheta, pressed });
    check_layout!(common, ManifoldSnaps { a, b });
    check_layout!(common, PairMeta { owned, total, owned_start, list_start, cursor, woken, moves, contacts, extent, reach });
}

#[test]
fn constants_match() {
    let module = shaders::validate(&format!("{}{}", shaders::COMMON, shaders::BINDINGS)).unwrap();
    let find = |name: &str| {
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("{name}: unexpected {e:?}"),
        }
    };
    assert_eq!(find("SHAPE_BOX"), SHAPE_BOX);
    assert_eq!(find("SHAPE_SPHERE"), SHAPE_SPHERE);
    assert_eq!(find("FLAG_FIXED"), FLAG_FIXED);
    assert_eq!(find("GRID_BODY"), GRID_BODY);
    assert_eq!(find("LARGE_BODY"), LARGE_BODY);
    assert_eq!(find("WORKGROUP"), WORKGROUP);
    assert_eq!(find("MAX_POINTS"), MAX_POINTS);
    assert_eq!(find("NONE"), NONE);
    assert_eq!(find("GROUND"), GROUND);
    assert_eq!(find("WORLD"), WORLD);
    // the numerical-fault codes the host decodes (src/world.rs)
    let integrate = verlet::gpu::shaders::pass_source("integrate").unwrap();
    let module = shaders::validate(&integrate).unwrap();
    let constant = |name: &str| {
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
        module.global_expressions[c.init].clone()
    };
    assert!(matches!(constant("NO_FAULT"), naga::Expression::Literal(naga::Literal::U32(verlet::world::NO_FAULT))));
    assert!(matches!(constant("MAX_SPEED"), naga::Expression::Literal(naga::Literal::F32(v)) if v == verlet::world::MAX_SPEED));
    assert!(
        matches!(constant("MAX_DISTANCE"), naga::Expression::Literal(naga::Literal::F32(v)) if v == verlet::world::MAX_DISTANCE)
    );
    assert!(matches!(constant("MAX_SPIN"), naga::Expression::Literal(naga::Literal::F32(v)) if v == verlet::world::MAX_SPIN));
    assert!(matches!(constant("MAX_TURN"), naga::Expression::Literal(naga::Literal::F32(v)) if v == verlet::world::MAX_TURN));
    for (name, code) in [("FAULT_NON_FINITE", 0u32), ("FAULT_FAR", 1), ("FAULT_FAST", 2), ("FAULT_SPIN", 3)] {
        assert!(matches!(constant(name), naga::Expression::Literal(naga::Literal::U32(v)) if v == code), "{name}");
    }
    let grid = format!("{}{}{}", shaders::COMMON, shaders::BINDINGS, shaders::GRID);
    let module = shaders::validate(&grid).unwrap();
    let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some("SCAN_BLOCK")).unwrap();
    assert!(matches!(module.global_expressions[c.init], naga::Expression::Literal(naga::Literal::U32(SCAN_BLOCK))));
}
