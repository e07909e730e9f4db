//! The CPU hull reference on random pairs of random hulls, boxes, spheres
//! and capsules at random poses: no contact where they are more than the
//! margin apart, a contact wherever they overlap, no point deeper than the
//! true overlap (beyond `EDGE_BIAS`), every point on or in its shape, at
//! most four; and a hull on the ground.

use crate::common::Rng;
use glam::Vec3;
use verlet::reference::capsule::Swept;
use verlet::reference::collide::{ContactPoint, Manifold, EDGE_BIAS};
use verlet::reference::hull::{ground_hull, hull_hull, hull_round, Polytope};
use verlet::scene::hull::Hull;

const MARGIN: f32 = 0.02;
const TOL: f32 = 2e-3;

/// Distance from p to segment s-e.
fn to_segment(p: Vec3, s: Vec3, e: Vec3) -> f32 {
    let d = e - s;
    let t = ((p - s).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (p - (s + d * t)).length()
}

/// Distance from p to the polytope (0 inside): to its nearest face's
/// polygon (the plane where p's foot falls inside it, else the polygon's sides).
fn to_polytope(p: Vec3, q: &Polytope) -> f32 {
    if q.faces.iter().all(|(n, d, _)| n.dot(p) - d <= 0.0) {
        return 0.0;
    }
    let mut best = f32::MAX;
    for (n, d, corners) in &q.faces {
        let h = n.dot(p) - d;
        let foot = p - *n * h;
        let inside = (0..corners.len()).all(|k| {
            let (a, b) = (q.vertices[corners[k]], q.vertices[corners[(k + 1) % corners.len()]]);
            (b - a).cross(foot - a).dot(*n) >= 0.0
        });
        if inside {
            best = best.min(h.abs());
        }
        for k in 0..corners.len() {
            best = best.min(to_segment(p, q.vertices[corners[k]], q.vertices[corners[(k + 1) % corners.len()]]));
        }
    }
    best
}

/// The true gap (positive) or overlap (negative): apart, the least distance
/// over corner-face and edge-edge pairs; overlapping, minus the least push
/// over every face normal and every pair of edge directions.
fn true_gap(a: &Polytope, b: &Polytope) -> f32 {
    let overlap_along = |l: Vec3| {
        let span =
            |q: &Polytope| q.vertices.iter().map(|v| v.dot(l)).fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let ((a0, a1), (b0, b1)) = (span(a), span(b));
        (a1 - b0).min(b1 - a0)
    };
    let mut axes: Vec<Vec3> = a.faces.iter().chain(&b.faces).map(|f| f.0).collect();
    for &(i, j, _, _) in &a.edges {
        for &(k, l, _, _) in &b.edges {
            let c = (a.vertices[j] - a.vertices[i]).cross(b.vertices[l] - b.vertices[k]);
            if c.length() > 1e-6 {
                axes.push(c.normalize());
            }
        }
    }
    let push = axes.iter().map(|&l| overlap_along(l)).fold(f32::MAX, f32::min);
    if push > 0.0 {
        return -push;
    }
    let mut best = f32::MAX;
    for v in &a.vertices {
        best = best.min(to_polytope(*v, b));
    }
    for v in &b.vertices {
        best = best.min(to_polytope(*v, a));
    }
    for &(i, j, _, _) in &a.edges {
        for &(k, l, _, _) in &b.edges {
            best = best.min(segments_apart(a.vertices[i], a.vertices[j], b.vertices[k], b.vertices[l]));
        }
    }
    best
}

/// The least distance between segments p0-p1 and q0-q1: the least of a
/// fine search along the first (the distance to the second is convex along
/// it), refined by golden sections.
fn segments_apart(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> f32 {
    let at = |t: f32| to_segment(p0.lerp(p1, t), q0, q1);
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..60 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if at(m1) <= at(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    at(0.5 * (lo + hi)).min(at(0.0)).min(at(1.0))
}

fn random_polytope(rng: &mut Rng, k: usize) -> Polytope {
    if k.is_multiple_of(3) {
        let h = Vec3::new(rng.range(0.1, 0.7), rng.range(0.05, 0.7), rng.range(0.1, 0.7));
        return Polytope::from_box(h, Vec3::ZERO, rng.quat());
    }
    let scale = Vec3::new(rng.range(0.3, 1.0), rng.range(0.3, 1.0), rng.range(0.3, 1.0));
    let n = 4 + (rng.f() * 28.0) as usize;
    let points: Vec<[f32; 3]> =
        (0..n).map(|_| (Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5) * scale).to_array()).collect();
    Polytope::from_hull(&Hull::new(&points).unwrap(), Vec3::ZERO, rng.quat())
}

#[test]
fn hulls_keep_to_the_true_gap() {
    let mut rng = Rng(0x4011_5eed_0000_0001);
    let (mut touching, mut faults) = (0, Vec::new());
    for k in 0..3000 {
        let a = random_polytope(&mut rng, k);
        let b = random_polytope(&mut rng, k + 1);
        let reach = |p: &Polytope| p.vertices.iter().map(|v| (*v - p.centre).length()).fold(0.0, f32::max);
        let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Y);
        let b = b.moved(a.centre - b.centre + dir * (reach(&a) + reach(&b)) * rng.range(0.0, 0.9));
        let gap = true_gap(&a, &b);
        let off = |p: &ContactPoint| (to_polytope(p.on_a, &a), to_polytope(p.on_b, &b));
        touching += usize::from(check_manifold(k, gap, hull_hull(&a, &b, MARGIN), 4, off, &mut faults));
    }
    assert!(faults.is_empty(), "{} faults: {:?}", faults.len(), &faults[..faults.len().min(10)]);
    assert!(touching > 1500, "too few touching pairs: {touching}");
}

#[test]
fn a_box_resting_on_a_hull_face_touches_at_its_four_corners() {
    // a flat slab of eight points as a hull, a unit box resting on it 1 cm in
    let slab: Vec<[f32; 3]> = (0..8)
        .map(|k| [if k & 1 == 0 { -2.0 } else { 2.0 }, if k & 2 == 0 { -0.2 } else { 0.0 }, if k & 4 == 0 { -2.0 } else { 2.0 }])
        .collect();
    let floor = Polytope::from_hull(&Hull::new(&slab).unwrap(), Vec3::ZERO, glam::Quat::IDENTITY);
    let cube = Polytope::from_box(Vec3::splat(0.5), Vec3::new(0.3, 0.49, -0.2), glam::Quat::IDENTITY);
    let m = hull_hull(&floor, &cube, MARGIN).unwrap();
    assert!((m.normal - Vec3::Y).length() < 1e-5, "{m:?}");
    assert_eq!(m.points.len(), 4, "{m:?}");
    for p in &m.points {
        assert!((p.separation(m.normal) + 0.01).abs() < 1e-5 && p.on_a.y.abs() < 1e-5, "{p:?}");
    }
}

/// Distance from p to the segment of a swept shape.
fn to_core(p: Vec3, s: &Swept) -> f32 {
    to_segment(p, s.centre - s.dir * s.half_length, s.centre + s.dir * (s.half_length + 1e-9))
}

/// The true gap (positive) or overlap (negative) of a polytope and a round
/// shape: apart at its core, the least distance of the segment to the
/// polytope less the radius; else minus the least push over the polytope's
/// face normals, its edges crossed with the segment, and 4000 directions.
fn true_round_gap(a: &Polytope, s: &Swept) -> f32 {
    let (p0, p1) = (s.centre - s.dir * s.half_length, s.centre + s.dir * s.half_length);
    let at = |t: f32| to_polytope(p0.lerp(p1, t), a);
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..60 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if at(m1) <= at(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let core = at(0.5 * (lo + hi)).min(at(0.0)).min(at(1.0));
    // the search may stop a rounding's width outside a segment that pierces it
    if core > 1e-5 {
        return core - s.radius;
    }
    let push = |l: Vec3| {
        let (lo, hi) = a.vertices.iter().map(|v| v.dot(l)).fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let (e0, e1) = (p0.dot(l), p1.dot(l));
        let (s0, s1) = (e0.min(e1) - s.radius, e0.max(e1) + s.radius);
        (hi - s0).min(s1 - lo)
    };
    let mut axes: Vec<Vec3> = a.faces.iter().map(|f| f.0).collect();
    for &(i, j, _, _) in &a.edges {
        let c = (a.vertices[j] - a.vertices[i]).cross(s.dir);
        if c.length() > 1e-6 {
            axes.push(c.normalize());
        }
    }
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    axes.extend((0..4000).map(|k| {
        let y = 1.0 - 2.0 * (k as f32 + 0.5) / 4000.0;
        let r = (1.0 - y * y).sqrt();
        Vec3::new(r * (golden * k as f32).cos(), y, r * (golden * k as f32).sin())
    }));
    -axes.iter().map(|&l| push(l)).fold(f32::MAX, f32::min)
}

fn random_round(rng: &mut Rng, k: usize, at: Vec3) -> Swept {
    let radius = rng.range(0.05, 0.5);
    if k.is_multiple_of(2) {
        Swept::sphere(at, radius)
    } else {
        Swept::capsule(at, rng.quat(), radius, rng.range(0.05, 0.8))
    }
}

#[test]
fn hulls_and_round_shapes_keep_to_the_true_gap() {
    let mut rng = Rng(0x4011_5eed_0000_0002);
    let (mut touching, mut faults) = (0, Vec::new());
    for k in 0..3000 {
        // hulls only: a box meets a round shape in capsule.rs
        let a = random_polytope(&mut rng, 3 * k + 1);
        let reach = a.vertices.iter().map(|v| (*v - a.centre).length()).fold(0.0, f32::max);
        let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Y);
        let at = a.centre + dir * (reach + 0.5) * rng.range(0.0, 1.2);
        let s = random_round(&mut rng, k, at);
        let gap = true_round_gap(&a, &s);
        let off = |p: &ContactPoint| (to_polytope(p.on_a, &a), to_core(p.on_b, &s) - s.radius);
        touching += usize::from(check_manifold(k, gap, hull_round(&a, &s, MARGIN), 2, off, &mut faults));
    }
    assert!(faults.is_empty(), "{} faults: {:?}", faults.len(), &faults[..faults.len().min(10)]);
    assert!(touching > 1200, "too few touching pairs: {touching}");
}

/// A hull on the ground: its corners within the margin, the deepest kept,
/// each point on the ground under its corner; none where it is higher.
#[test]
fn a_hull_meets_the_ground_at_its_lowest_corners() {
    let mut rng = Rng(0x4011_5eed_0000_0003);
    for k in 0..500 {
        let a = random_polytope(&mut rng, 3 * k + 1);
        let lowest = a.vertices.iter().map(|v| v.y).fold(f32::MAX, f32::min);
        let ground = lowest + rng.range(-0.1, 0.05);
        let m = ground_hull(&a, ground, MARGIN);
        let near = a.vertices.iter().filter(|v| v.y - ground <= MARGIN).count();
        let Some(m) = m else {
            assert_eq!(near, 0, "hull {k}: corners within the margin but no contact");
            continue;
        };
        assert!(m.points.len() <= near.min(4) && m.points.len() >= near.min(2), "hull {k}: {} of {near}", m.points.len());
        assert!(m.points.iter().any(|p| (p.on_a.y - lowest).abs() < 1e-6), "hull {k}: the deepest corner is not kept");
        for p in &m.points {
            assert!(a.vertices.iter().any(|v| (*v - p.on_a).length() < 1e-5), "hull {k}: not a corner");
            assert!((p.on_b.y - ground).abs() < 1e-6 && (p.on_b - p.on_a).with_y(0.0).length() < 1e-6);
        }
    }
}

/// Checks pair `k`'s manifold `m` against the shapes' true gap: a contact
/// wherever they overlap, none beyond the margin, 1 to `most` points under a
/// unit normal, none deeper than the overlap, each on its shape (`off`: how
/// far each end lies outside its shape). Whether the pair touched.
fn check_manifold(
    k: usize,
    gap: f32,
    m: Option<Manifold>,
    most: usize,
    off: impl Fn(&ContactPoint) -> (f32, f32),
    faults: &mut Vec<String>,
) -> bool {
    let Some(m) = m else {
        if gap < -TOL {
            faults.push(format!("pair {k}: overlap {gap} but no contact"));
        }
        return false;
    };
    if gap > MARGIN + TOL {
        faults.push(format!("pair {k}: {gap} apart but {} points", m.points.len()));
    }
    if m.points.is_empty() || m.points.len() > most || (m.normal.length() - 1.0).abs() > 1e-4 {
        faults.push(format!("pair {k}: {} points, normal {:?}", m.points.len(), m.normal));
    }
    for p in &m.points {
        let sep = p.separation(m.normal);
        if sep < gap.min(0.0) - EDGE_BIAS - TOL {
            faults.push(format!("pair {k}: a point {sep} deep where the overlap is {gap}"));
        }
        let (off_a, off_b) = off(p);
        if off_a > TOL || off_b > TOL {
            faults.push(format!("pair {k}: a point off its shape by {off_a} / {off_b}"));
        }
    }
    true
}
