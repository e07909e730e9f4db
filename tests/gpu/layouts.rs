//! Every struct shared with WGSL matches its Rust twin member by member:
//! names, byte offsets and size.

use std::mem::{offset_of, size_of};

use naga::TypeInner;
use verlet::gpu::{shaders, types::*};

/// (member name, offset, size) of a WGSL struct's members, and its size.
fn wgsl_struct(source: &str, name: &str) -> (Vec<(String, u32, u32)>, u32) {
    let module = shaders::validate(source).expect("validates");
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, ty)| ty.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("struct {name} not found in the WGSL"));
    let TypeInner::Struct { members, span } = &ty.inner else { panic!("{name} is not a struct") };
    let members =
        members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset, module.types[m.ty].inner.size(module.to_ctx())));
    (members.collect(), *span)
}

/// (member name, offset) of a WGSL struct, and its size.
fn wgsl_layout(source: &str, name: &str) -> (Vec<(String, u32)>, u32) {
    let (members, span) = wgsl_struct(source, name);
    (members.into_iter().map(|(name, offset, _)| (name, offset)).collect(), span)
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
    let common = &format!("{}{}{}", shaders::shared_constants(), shaders::COMMON, shaders::BINDINGS);
    check_layout!(common, BodyState { pos, rest_time, disp, pos_low, rot, prev_rot });
    check_layout!(
        common,
        BodyProps { half_extents, inv_inertia, restitution, friction, shape, flags, kept_inv_mass, speed_limit, grid_class, hull }
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
            speed_limits,
            substeps,
            step_index,
            sleep_after,
            substep,
            opaque_zero,
            island_count,
            path_first,
            path_end,
            path_count,
            second,
            _pad2
        }
    );
    check_layout!(common, JointRef { local_self, partner, local_partner, body });
    check_layout!(common, Pair { a, b });
    check_layout!(common, CellBound { pos, bound, extent, body });
    check_layout!(common, ContactPoint { local_a, pushed, local_b, last_push });
    check_layout!(common, ContactManifold { normal, count, a, b, clip_face, pair });
    check_layout!(common, ManifoldPoints { at });
    check_layout!(common, EndSnap { dx, count, dtheta, flags });
    check_layout!(
        common,
        PairMeta {
            owned,
            total,
            owned_start,
            list_start,
            cursor,
            woken,
            moves,
            contacts,
            extent,
            bound,
            held,
            normal_split,
            reach,
            spin
        }
    );
}

/// The busiest buffers are bound as vec4 words (bindings.wgsl): each words
/// struct spans its twin's bytes in 16-byte members only, and no member of
/// the twin straddles two words, so each accessor's unpacking is a choice
/// of components.
#[test]
fn stored_words_hold_their_structs_bytes() {
    let common = &format!("{}{}{}", shaders::shared_constants(), shaders::COMMON, shaders::BINDINGS);
    for (twin, words) in [
        ("BodyState", "StateWords"),
        ("BodyProps", "PropsWords"),
        ("ContactManifold", "ManifoldWords"),
        ("CellBound", "CellBoundWords"),
        ("ManifoldPoints", "PointsWords"),
        ("EndSnap", "SnapWords"),
    ] {
        let (twin_members, twin_span) = wgsl_struct(common, twin);
        let (words_members, words_span) = wgsl_struct(common, words);
        assert_eq!(words_span, twin_span, "{words} and {twin} differ in size");
        let mut end = 0;
        for (name, offset, size) in words_members {
            assert_eq!(offset, end, "{words}.{name}: not right after the word before");
            assert_eq!(size % 16, 0, "{words}.{name}: not whole vec4s");
            end = offset + size;
        }
        for (name, offset, size) in twin_members {
            if size <= 16 {
                assert_eq!(offset / 16, (offset + size - 1) / 16, "{twin}.{name} straddles two words");
            }
        }
    }
}

/// The constants WGSL shares with Rust are written once, from the Rust values
/// (shaders::shared_constants): every module sees them with those values.
#[test]
fn constants_match() {
    let integrate = verlet::step::Stage::Integrate.source();
    let module = shaders::validate(&integrate).unwrap();
    let constant = |name: &str| {
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
        module.global_expressions[c.init].clone()
    };
    let word = |name: &str| match constant(name) {
        naga::Expression::Literal(naga::Literal::U32(v)) => v,
        e => panic!("{name}: unexpected {e:?}"),
    };
    let float = |name: &str| match constant(name) {
        naga::Expression::Literal(naga::Literal::F32(v)) => v,
        e => panic!("{name}: unexpected {e:?}"),
    };
    use verlet::limits::{FaultKind, CONTACT_MARGIN, MAX_DISTANCE, MAX_SPEED, MAX_SPIN, MAX_TURN, NO_FAULT};
    for (name, value) in [
        ("SHAPE_BOX", SHAPE_BOX),
        ("SHAPE_SPHERE", SHAPE_SPHERE),
        ("FLAG_FIXED", FLAG_FIXED),
        ("GRID_BODY", GRID_BODY),
        ("LARGE_BODY", LARGE_BODY),
        ("WORKGROUP", WORKGROUP),
        ("SCAN_BLOCK", SCAN_BLOCK),
        ("SCAN_RUN", SCAN_RUN),
        ("SCAN_SPAN", SCAN_SPAN),
        ("WOKEN_NOW", WOKEN_NOW),
        ("BODY_BITS", BODY_BITS),
        ("MOVES_SHIFT", MOVES_SHIFT),
        ("FAST_BODY", FAST_BODY),
        ("MAX_POINTS", MAX_POINTS),
        ("NONE", NONE),
        ("GROUND", GROUND),
        ("WORLD", WORLD),
        ("HELD", HELD),
        ("WAKES", WAKES),
        ("NO_FAULT", NO_FAULT),
        ("FAULT_NON_FINITE", FaultKind::NonFinite as u32),
        ("FAULT_FAR", FaultKind::TooFar as u32),
        ("FAULT_FAST", FaultKind::TooFast as u32),
        ("FAULT_SPIN", FaultKind::SpinsTooFast as u32),
    ] {
        assert_eq!(word(name), value, "{name}");
    }
    for (name, value) in [
        ("MAX_SPEED", MAX_SPEED),
        ("MAX_DISTANCE", MAX_DISTANCE),
        ("MAX_SPIN", MAX_SPIN),
        ("MAX_TURN", MAX_TURN),
        ("CONTACT_MARGIN", CONTACT_MARGIN),
    ] {
        assert_eq!(float(name).to_bits(), value.to_bits(), "{name}");
    }
    // an awkward value survives the round trip exactly
    let awkward = shaders::wgsl_f32("X", 0.1 + f32::EPSILON);
    let module = shaders::validate(&awkward).unwrap();
    let (_, c) = module.constants.iter().next().unwrap();
    assert!(
        matches!(module.global_expressions[c.init], naga::Expression::Literal(naga::Literal::F32(v)) if v == 0.1 + f32::EPSILON)
    );
}

/// The status record's word constants (`STATUS_*`), as every module sees
/// them, are its fields' places in the Rust struct, member by member, and
/// the fields named here tile the struct (none left out, none overlapping).
#[test]
fn status_words_match_the_struct() {
    use verlet::gpu::status::{Status, DISPATCH_Y, DISPATCH_Z};
    let module = shaders::validate(&verlet::step::Stage::Integrate.source()).unwrap();
    let word = |name: &str| {
        let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).expect(name);
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::U32(v)) => v as usize,
            ref e => panic!("{name}: unexpected {e:?}"),
        }
    };
    macro_rules! check_words {
        ($($field:ident => $name:literal),* $(,)?) => {{
            let status = Status::INIT;
            let mut end = 0;
            $(
                assert_eq!(offset_of!(Status, $field), end, "Status.{}: not right after the field before", stringify!($field));
                assert_eq!(4 * word($name), offset_of!(Status, $field), "{} differs from Status.{}", $name, stringify!($field));
                end += std::mem::size_of_val(&status.$field);
            )*
            assert_eq!(end, size_of::<Status>(), "Status: fields left out here");
            assert_eq!(Status::WORDS.len(), [$($name),*].len(), "Status::WORDS: names not checked here");
        }};
    }
    check_words!(
        pairs => "STATUS_PAIRS",
        pairs_max => "STATUS_PAIRS_MAX",
        fault => "STATUS_FAULT",
        fault_step => "STATUS_FAULT_STEP",
        manifolds => "STATUS_MANIFOLDS",
        manifolds_max => "STATUS_MANIFOLDS_MAX",
        manifolds_top => "STATUS_MANIFOLDS_TOP",
        manifolds_bottom => "STATUS_MANIFOLDS_BOTTOM",
        pairs_dispatch => "STATUS_PAIRS_DISPATCH",
        grid_sleeps => "STATUS_GRID_SLEEPS",
        manifolds_dispatch => "STATUS_MANIFOLDS_DISPATCH",
        moving => "STATUS_MOVING",
        listed => "STATUS_LISTED",
        listed_dispatch => "STATUS_LISTED_DISPATCH",
        touching => "STATUS_TOUCHING",
        touching_dispatch => "STATUS_TOUCHING_DISPATCH",
        near => "STATUS_NEAR",
        near_now => "STATUS_NEAR_NOW",
        walk => "STATUS_WALK",
        walk_dispatches => "STATUS_WALK_DISPATCHES",
        walks_cut => "STATUS_WALKS_CUT",
        lists_cut => "STATUS_LISTS_CUT",
        sweeps => "STATUS_SWEEPS",
        paths_again => "STATUS_PATHS_AGAIN",
        kept => "STATUS_KEPT",
    );
    assert_eq!(Status::BYTES as usize, size_of::<Status>());
    // a dispatch's three words as wgpu reads them: x, y, z
    assert_eq!((word("DISPATCH_Y"), word("DISPATCH_Z")), (DISPATCH_Y as usize, DISPATCH_Z as usize));
    assert_eq!((DISPATCH_Y, DISPATCH_Z), (1, 2));
}

/// common.wgsl holds types and maths only: with the shared constants it is a
/// module of its own, binding nothing (the renderer includes it).
#[test]
fn common_wgsl_binds_nothing() {
    let module = shaders::validate(&(shaders::shared_constants() + shaders::COMMON)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(module.global_variables.len(), 0, "common.wgsl declares a binding");
}
