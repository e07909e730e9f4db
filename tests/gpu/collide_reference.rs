//! The CPU box-box reference on thousands of random pose pairs, including
//! thin slabs, needles and nearly parallel faces: no contact where the boxes
//! are apart, no point deeper than the true overlap, every point on or inside
//! both boxes, at most 8 points sharing one normal.

use crate::common::Rng;
use glam::{Quat, Vec3};
use verlet::reference::collide::{box_box, Manifold, EDGE_BIAS, FACE_BIAS};

#[derive(Clone, Copy)]
struct Obb {
    c: Vec3,
    q: Quat,
    h: Vec3,
}

impl Obb {
    fn vertices(&self) -> Vec<Vec3> {
        (0..8)
            .map(|k| {
                let s = Vec3::new(
                    if k & 1 == 0 { -1.0 } else { 1.0 },
                    if k & 2 == 0 { -1.0 } else { 1.0 },
                    if k & 4 == 0 { -1.0 } else { 1.0 },
                );
                self.c + self.q * (s * self.h)
            })
            .collect()
    }
    /// How far p lies outside the box (0 inside).
    fn outside(&self, p: Vec3) -> f32 {
        let l = self.q.conjugate() * (p - self.c);
        (l.abs() - self.h).max(Vec3::ZERO).length()
    }
    fn axes(&self) -> [Vec3; 3] {
        [self.q * Vec3::X, self.q * Vec3::Y, self.q * Vec3::Z]
    }
}

/// How far the boxes must move apart along axis l to separate: the smaller
/// of the two pushes (negative: a gap).
fn overlap_on(a: &Obb, b: &Obb, l: Vec3) -> f32 {
    let span = |o: &Obb| {
        let p: Vec<f32> = o.vertices().iter().map(|v| v.dot(l)).collect();
        (p.iter().cloned().fold(f32::MAX, f32::min), p.iter().cloned().fold(f32::MIN, f32::max))
    };
    let (a0, a1) = span(a);
    let (b0, b1) = span(b);
    (a1 - b0).min(b1 - a0)
}

/// The true penetration depth (minimum over the 15 candidate axes, by brute
/// force over vertices), negative when some axis separates them.
fn true_overlap(a: &Obb, b: &Obb) -> f32 {
    let mut axes: Vec<Vec3> = a.axes().into_iter().chain(b.axes()).collect();
    for x in a.axes() {
        for y in b.axes() {
            let c = x.cross(y);
            if c.length() > 1e-5 {
                axes.push(c.normalize());
            }
        }
    }
    axes.iter().map(|&l| overlap_on(a, b, l)).fold(f32::MAX, f32::min)
}

fn random_half(rng: &mut Rng, case: usize) -> Vec3 {
    match case % 4 {
        0 => Vec3::new(rng.range(0.1, 1.0), rng.range(0.1, 1.0), rng.range(0.1, 1.0)),
        1 => Vec3::new(rng.range(0.5, 2.0), rng.range(0.005, 0.03), rng.range(0.5, 2.0)), // thin slab
        2 => Vec3::new(rng.range(0.5, 2.0), rng.range(0.005, 0.03), rng.range(0.005, 0.03)), // needle
        _ => Vec3::splat(0.5),
    }
}

fn check(a: &Obb, b: &Obb, margin: f32, m: Option<Manifold>, stats: &mut [usize; 3]) {
    let overlap = true_overlap(a, b);
    let tol = 2e-3 * (1.0 + a.h.max_element().max(b.h.max_element()));
    let Some(m) = m else {
        // no manifold: the boxes must be apart by more than the margin
        assert!(overlap < -margin + tol, "missed contact: true overlap {overlap}");
        stats[0] += 1;
        return;
    };
    assert!(overlap > -margin - tol, "contact reported but boxes are {} apart", -overlap);
    assert!(!m.points.is_empty() && m.points.len() <= 8, "{} points", m.points.len());
    assert!((m.normal.length() - 1.0).abs() < 1e-4);
    assert!(m.normal.dot(b.c - a.c) >= -tol, "normal points from b to a");
    for p in &m.points {
        let depth = -p.separation(m.normal);
        // faces are preferred to edges by EDGE_BIAS (and the first box's
        // faces to the second's by the smaller FACE_BIAS), which bounds the excess
        assert!(
            depth <= overlap.max(0.0) + EDGE_BIAS + tol,
            "depth {depth} > true overlap {overlap}; {} points, n {:?}, a {:?} {:?} {:?} b {:?} {:?} {:?}",
            m.points.len(),
            m.normal,
            a.c,
            a.q,
            a.h,
            b.c,
            b.q,
            b.h
        );
        assert!(depth <= overlap_on(a, b, m.normal) + tol, "depth {depth} beyond the overlap along the normal");
        // each point lies on its own box
        assert!(a.outside(p.on_a) < tol, "on_a off box a by {}", a.outside(p.on_a));
        assert!(b.outside(p.on_b) < tol, "on_b off box b by {}", b.outside(p.on_b));
        // A penetrating contact has a point on or inside both boxes: the
        // incident vertex (or, edge against edge, both closest points); its
        // partner is that point projected onto the reference face. Only while
        // the depth is under the thinner box's thickness: a slab pushed
        // deeper than it is thick has no overlap region that holds both the
        // point and the push that separates them.
        let thinnest = 2.0 * a.h.min_element().min(b.h.min_element());
        if depth > tol && depth < thinnest {
            let inside_both = b.outside(p.on_a).min(a.outside(p.on_b));
            assert!(inside_both < tol, "contact point outside the other box by {inside_both}; depth {depth} overlap {overlap} {} points; a {:?} {:?} {:?} b {:?} {:?} {:?}", m.points.len(), a.c, a.q, a.h, b.c, b.q, b.h);
        }
    }
    stats[if overlap > 0.0 { 1 } else { 2 }] += 1;
}

#[test]
fn random_box_pairs_give_sound_manifolds() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let margin = 0.02;
    let mut stats = [0usize; 3]; // apart, overlapping, speculative
    for case in 0..6000 {
        let a = Obb { c: Vec3::ZERO, q: rng.quat(), h: random_half(&mut rng, case) };
        let hb = random_half(&mut rng, case / 4);
        let qb = if case % 5 == 0 {
            // nearly parallel faces
            a.q * Quat::from_scaled_axis(Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * 1e-3)
        } else {
            rng.quat()
        };
        let reach = a.h.length() + hb.length();
        let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::X);
        let b = Obb { c: dir * rng.range(0.0, 1.1) * reach, q: qb, h: hb };
        let m = box_box(a.c, a.q, a.h, b.c, b.q, b.h, margin);
        check(&a, &b, margin, m, &mut stats);
    }
    eprintln!("apart {}, overlapping {}, within the margin {}", stats[0], stats[1], stats[2]);
    assert!(stats[0] > 1000 && stats[1] > 1000 && stats[2] > 50, "the cases do not cover every kind: {stats:?}");
}

#[test]
fn box_resting_flat_on_box_gives_four_points() {
    let h = Vec3::splat(0.5);
    let m = box_box(Vec3::ZERO, Quat::IDENTITY, h, Vec3::new(0.1, 0.99, 0.05), Quat::IDENTITY, h, 0.02).unwrap();
    assert_eq!(m.points.len(), 4);
    assert!((m.normal - Vec3::Y).length() < 1e-5);
    for p in &m.points {
        assert!((p.separation(m.normal) + 0.01).abs() < 1e-5);
    }
}

/// Nearly parallel faces: the second box's face becomes the reference face
/// only when it beats the first's by FACE_BIAS, so a box lying tilted on
/// another does not switch between two different manifolds from step to step.
#[test]
fn the_first_boxs_face_is_kept_unless_the_seconds_beats_it_by_face_bias() {
    let cube = Vec3::splat(0.5);
    let slab = Vec3::new(2.0, 0.5, 2.0);
    // the cube (first), turned by `tilt` about z, 1 mm into the slab below it
    // (second): the slab's face separates them less than the cube's by
    // about (2 - 0.5) tilt
    let normal_for = |tilt: f32| {
        let q = Quat::from_rotation_z(tilt);
        let c = Vec3::new(0.0, 0.5 + 0.5 * (tilt.cos() + tilt.sin()) - 0.001, 0.0);
        (box_box(c, q, cube, Vec3::ZERO, Quat::IDENTITY, slab, 0.02).unwrap().normal, q)
    };
    const { assert!(1.5 * 0.001 < FACE_BIAS && FACE_BIAS < 1.5 * 0.003) };
    let (n, q) = normal_for(0.001);
    assert!((n + q * Vec3::Y).length() < 1e-5, "1.5 mm better: the cube's face is kept, got normal {n:?}");
    let (n, _) = normal_for(0.003);
    assert!((n + Vec3::Y).length() < 1e-5, "4.5 mm better: the slab's face, got normal {n:?}");
}
