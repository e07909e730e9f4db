//! The CPU capsule reference on thousands of random pose pairs (capsules
//! against capsules, spheres and boxes, long and short, thin slabs and
//! needles among the boxes): no contact where the shapes are apart by more
//! than the margin, a contact wherever they overlap, no point deeper than the
//! true overlap, every point on or inside its shape; and the manifolds of
//! known placements (lying on a face, side by side, crossed, upright).

use crate::common::Rng;
use glam::{Quat, Vec3};
use verlet::reference::capsule::{box_capsule, ground_capsule, round_round, Swept};
use verlet::reference::collide::{Manifold, EDGE_BIAS};

const MARGIN: f32 = 0.02;
/// Slack for f32 and for the brute-force measures below (a segment sampled
/// 2000 times, directions a few thousand).
const TOL: f32 = 2e-3;

/// Distance from p to the segment.
fn to_segment(s: &Swept, p: Vec3) -> f32 {
    let t = (p - s.centre).dot(s.dir).clamp(-s.half_length, s.half_length);
    (p - (s.centre + s.dir * t)).length()
}

/// Distance from p to the box (0 inside).
fn to_box(c: Vec3, q: Quat, h: Vec3, p: Vec3) -> f32 {
    let l = q.conjugate() * (p - c);
    (l.abs() - h).max(Vec3::ZERO).length()
}

/// Points along a segment, its ends included.
fn samples(s: &Swept) -> impl Iterator<Item = Vec3> + '_ {
    (0..=2000).map(move |k| s.centre + s.dir * s.half_length * (k as f32 / 1000.0 - 1.0))
}

/// Unit directions spread over the sphere (a Fibonacci lattice).
fn directions() -> Vec<Vec3> {
    let n = 4000;
    (0..n)
        .map(|k| {
            let y = 1.0 - 2.0 * (k as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).sqrt();
            let phi = k as f32 * 2.399_963;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// How far the supports of two convex shapes overlap along u (negative: a gap).
fn overlap_along(support_a: &dyn Fn(Vec3) -> f32, support_b: &dyn Fn(Vec3) -> f32, u: Vec3) -> f32 {
    support_a(u) + support_b(-u)
}

fn capsule_support(s: &Swept) -> impl Fn(Vec3) -> f32 + '_ {
    move |u: Vec3| s.centre.dot(u) + s.half_length * s.dir.dot(u).abs() + s.radius
}

fn box_support(c: Vec3, q: Quat, h: Vec3) -> impl Fn(Vec3) -> f32 {
    move |u: Vec3| c.dot(u) + (q.conjugate() * u).abs().dot(h)
}

/// The true gap (positive) or overlap (negative) of two convex shapes: the
/// closest distance where apart, else minus the least push that parts them
/// (over the sampled directions: never smaller than the true one).
fn true_gap(distance: f32, a: &dyn Fn(Vec3) -> f32, b: &dyn Fn(Vec3) -> f32, dirs: &[Vec3]) -> f32 {
    if distance > 0.0 {
        return distance;
    }
    -dirs.iter().map(|&u| overlap_along(a, b, u)).fold(f32::MAX, f32::min)
}

/// A random point up to 1.1 `reach` from the origin, in a random direction.
fn within(rng: &mut Rng, reach: f32) -> Vec3 {
    let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Y);
    dir * reach * rng.range(0.0, 1.1)
}

fn random_capsule(rng: &mut Rng, at: Vec3) -> Swept {
    let long = rng.f() < 0.5;
    let radius = rng.range(0.05, 0.5);
    let half = if long { rng.range(0.3, 1.5) } else { rng.range(0.01, 0.3) };
    Swept::capsule(at, rng.quat(), radius, half)
}

fn random_box(rng: &mut Rng) -> Vec3 {
    match (rng.f() * 3.0) as u32 {
        0 => Vec3::new(rng.range(0.4, 1.4), rng.range(0.01, 0.03), rng.range(0.4, 1.4)),
        1 => Vec3::new(rng.range(0.4, 1.4), rng.range(0.01, 0.03), rng.range(0.01, 0.03)),
        _ => Vec3::new(rng.range(0.1, 0.7), rng.range(0.1, 0.7), rng.range(0.1, 0.7)),
    }
}

/// Checks one manifold against the true gap, and its points against the
/// shapes (`inside_a`, `inside_b`: how far a point lies outside each); a
/// point may be `bias` deeper than the true overlap (a face preferred to an
/// edge).
fn check(
    what: &str,
    m: Option<Manifold>,
    gap: f32,
    bias: f32,
    inside_a: &dyn Fn(Vec3) -> f32,
    inside_b: &dyn Fn(Vec3) -> f32,
    faults: &mut Vec<String>,
) -> bool {
    let Some(m) = m else {
        if gap < -TOL {
            faults.push(format!("{what}: overlap {gap} but no contact"));
        }
        return false;
    };
    if gap > MARGIN + TOL {
        faults.push(format!("{what}: {gap} apart but {} points", m.points.len()));
    }
    if m.points.is_empty() || m.points.len() > 2 || (m.normal.length() - 1.0).abs() > 1e-4 {
        faults.push(format!("{what}: {} points, normal {:?}", m.points.len(), m.normal));
    }
    for p in &m.points {
        let sep = p.separation(m.normal);
        if sep < gap.min(0.0) - bias - TOL {
            faults.push(format!("{what}: a point {sep} deep where the overlap is {gap}"));
        }
        if inside_a(p.on_a) > TOL || inside_b(p.on_b) > TOL {
            faults.push(format!("{what}: a point off its shape by {} / {}", inside_a(p.on_a), inside_b(p.on_b)));
        }
    }
    true
}

#[test]
fn capsules_against_round_shapes_keep_to_the_true_gap() {
    let dirs = directions();
    let mut rng = Rng(0x0ca9_5013_0000_0001);
    let (mut touching, mut faults) = (0, Vec::new());
    for k in 0..3000 {
        let a = random_capsule(&mut rng, Vec3::ZERO);
        let b = if k % 3 == 0 { Swept::sphere(Vec3::ZERO, rng.range(0.05, 0.6)) } else { random_capsule(&mut rng, Vec3::ZERO) };
        let b = Swept { centre: within(&mut rng, a.half_length + a.radius + b.half_length + b.radius), ..b };
        let closest = samples(&a).map(|p| to_segment(&b, p)).fold(f32::MAX, f32::min);
        // segments apart: the gap is their distance less the radii, overlap
        // or not; crossed: the least push over the directions
        let gap = if closest > 1e-3 {
            closest - a.radius - b.radius
        } else {
            true_gap(0.0, &capsule_support(&a), &capsule_support(&b), &dirs)
        };
        let on_a = |p: Vec3| (to_segment(&a, p) - a.radius).max(0.0);
        let on_b = |p: Vec3| (to_segment(&b, p) - b.radius).max(0.0);
        touching += check(&format!("pair {k}"), round_round(&a, &b, MARGIN), gap, 0.0, &on_a, &on_b, &mut faults) as usize;
    }
    assert!(faults.is_empty(), "{} faults: {:?}", faults.len(), &faults[..faults.len().min(10)]);
    assert!(touching > 1000, "too few touching pairs: {touching}");
}

#[test]
fn capsules_against_boxes_keep_to_the_true_gap() {
    let dirs = directions();
    let mut rng = Rng(0x0b0c_a95e_0000_0002);
    let (mut touching, mut faults) = (0, Vec::new());
    for k in 0..3000 {
        let (bc, bq, h) = (Vec3::ZERO, rng.quat(), random_box(&mut rng));
        let capsule = random_capsule(&mut rng, Vec3::ZERO);
        let capsule = Swept { centre: within(&mut rng, h.length() + capsule.half_length + capsule.radius), ..capsule };
        let closest = samples(&capsule).map(|p| to_box(bc, bq, h, p)).fold(f32::MAX, f32::min);
        let distance = (closest - capsule.radius).max(0.0);
        let gap = true_gap(distance, &box_support(bc, bq, h), &capsule_support(&capsule), &dirs);
        let on_box = |p: Vec3| to_box(bc, bq, h, p);
        let on_capsule = |p: Vec3| (to_segment(&capsule, p) - capsule.radius).max(0.0);
        let m = box_capsule(bc, bq, h, &capsule, MARGIN);
        touching += check(&format!("pair {k}"), m, gap, EDGE_BIAS, &on_box, &on_capsule, &mut faults) as usize;
    }
    assert!(faults.is_empty(), "{} faults: {:?}", faults.len(), &faults[..faults.len().min(10)]);
    assert!(touching > 1000, "too few touching pairs: {touching}");
}

fn lying(centre: Vec3, radius: f32, half_height: f32) -> Swept {
    // the body's y axis turned onto x
    Swept::capsule(centre, Quat::from_rotation_z(std::f32::consts::FRAC_PI_2), radius, half_height)
}

#[test]
fn a_capsule_lying_on_a_box_rests_on_both_ends_of_its_segment() {
    let capsule = lying(Vec3::new(0.1, 0.5 + 0.2 - 0.01, 0.0), 0.2, 0.6);
    let m = box_capsule(Vec3::ZERO, Quat::IDENTITY, Vec3::splat(0.5), &capsule, MARGIN).unwrap();
    assert!((m.normal - Vec3::Y).length() < 1e-5, "{:?}", m.normal);
    let mut xs: Vec<f32> = m.points.iter().map(|p| p.on_a.x).collect();
    xs.sort_by(f32::total_cmp);
    // the segment (-0.5 .. 0.7 in x) clipped to the face (-0.5 .. 0.5)
    assert_eq!(xs.len(), 2, "{m:?}");
    assert!((xs[0] + 0.5).abs() < 1e-4 && (xs[1] - 0.5).abs() < 1e-4, "{xs:?}");
    for p in &m.points {
        assert!((p.separation(m.normal) + 0.01).abs() < 1e-4, "{m:?}");
        assert!((p.on_a.y - 0.5).abs() < 1e-5);
    }
    // lifted a little off the face, still two points (speculative)
    let capsule = lying(Vec3::new(0.0, 0.5 + 0.2 + 0.01, 0.0), 0.2, 0.3);
    let m = box_capsule(Vec3::ZERO, Quat::IDENTITY, Vec3::splat(0.5), &capsule, MARGIN).unwrap();
    assert_eq!(m.points.len(), 2, "{m:?}");
    // standing on its end: one point under the segment's lower end
    let upright = Swept::capsule(Vec3::new(0.2, 0.5 + 0.2 + 0.3 - 0.01, 0.1), Quat::IDENTITY, 0.2, 0.3);
    let m = box_capsule(Vec3::ZERO, Quat::IDENTITY, Vec3::splat(0.5), &upright, MARGIN).unwrap();
    assert_eq!(m.points.len(), 1, "{m:?}");
    assert!((m.points[0].on_b - Vec3::new(0.2, 0.49, 0.1)).length() < 1e-4, "{m:?}");
}

#[test]
fn capsules_side_by_side_touch_at_two_points_and_crossed_at_one() {
    let a = lying(Vec3::ZERO, 0.2, 0.5);
    let b = lying(Vec3::new(0.3, 0.39, 0.0), 0.2, 0.5);
    let m = round_round(&a, &b, MARGIN).unwrap();
    assert_eq!(m.points.len(), 2, "{m:?}");
    assert!((m.normal - Vec3::Y).length() < 1e-5);
    let mut xs: Vec<f32> = m.points.iter().map(|p| p.on_a.x).collect();
    xs.sort_by(f32::total_cmp);
    assert!((xs[0] + 0.2).abs() < 1e-4 && (xs[1] - 0.5).abs() < 1e-4, "{xs:?}");
    let crossed = Swept::capsule(Vec3::new(0.0, 0.39, 0.0), Quat::from_rotation_x(std::f32::consts::FRAC_PI_2), 0.2, 0.5);
    let m = round_round(&a, &crossed, MARGIN).unwrap();
    assert_eq!(m.points.len(), 1, "{m:?}");
    assert!((m.points[0].separation(m.normal) + 0.01).abs() < 1e-4);
}

#[test]
fn a_capsule_meets_the_ground_under_each_end_within_the_margin() {
    let flat = lying(Vec3::new(0.0, 0.19, 0.0), 0.2, 0.5);
    let m = ground_capsule(&flat, 0.0, MARGIN).unwrap();
    assert_eq!(m.points.len(), 2);
    assert!(m.points.iter().all(|p| (p.on_a.y + 0.01).abs() < 1e-5 && p.on_b.y == 0.0));
    let upright = Swept::capsule(Vec3::new(0.0, 0.69, 0.0), Quat::IDENTITY, 0.2, 0.5);
    assert_eq!(ground_capsule(&upright, 0.0, MARGIN).unwrap().points.len(), 1);
    assert!(ground_capsule(&Swept { centre: Vec3::new(0.0, 0.75, 0.0), ..upright }, 0.0, MARGIN).is_none());
}
