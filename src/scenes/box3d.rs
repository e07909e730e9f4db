//! Box3D's benchmark scenes, set up as its `benchmark` program sets them
//! up, so that a bench case here and there names the same world.

use super::build::{box_body, scene, sphere_body};
use crate::scene::{Body, HullShape, Joint, Scene, Shape};

/// Box3D's benchmark world, as its `benchmark` program sets it up: gravity
/// 10 m/s^2 (ours is 9.81), friction 0.6 and restitution 0 (its default
/// material), sleeping off (each of its benchmarks turns it off). Its step
/// is 60 Hz, as ours; its solver's 4 substeps are not copied: a scene here
/// keeps our solver's defaults, so that the bench compares the defaults.
fn box3d_world(bodies: Vec<Body>, joints: Vec<Joint>) -> Scene {
    let mut s = scene(bodies, joints);
    s.settings.gravity = [0.0, -10.0, 0.0];
    s.settings.friction = 0.6;
    s.settings.restitution = 0.0;
    s.settings.sleeping = false;
    s
}

/// Box3D's pyramid boxes weigh 100 kg/m^3, a tenth of our default.
const BOX3D_PYRAMID_DENSITY: f32 = 100.0;

/// A pyramid of `rows` rows of unit cubes in the plane z = `z`, the bottom
/// row's first centre at x = `x0`, neighbours in a row touching (no gap)
/// and each row on the one below, shifted half a cube: each cube stands on
/// two. Box3D's pyramids are laid out so; density `BOX3D_PYRAMID_DENSITY`.
fn touching_pyramid(rows: usize, x0: f32, z: f32, bodies: &mut Vec<Body>) {
    for row in 0..rows {
        let first = x0 + 0.5 * row as f32;
        for k in 0..rows - row {
            let mut b = box_body([0.5; 3], [first + k as f32, 0.5 + row as f32, z]);
            b.mass = BOX3D_PYRAMID_DENSITY * b.shape.volume();
            bodies.push(b);
        }
    }
}

/// `large_pyramid`: Box3D's benchmark of that name, a pyramid of `rows`
/// rows (Box3D: 100, 5050 cubes) of unit cubes touching side by side,
/// centred on the origin, on the ground; Box3D's world (`box3d_world`).
pub fn large_pyramid(rows: usize) -> Scene {
    let mut bodies = Vec::with_capacity(rows * (rows + 1) / 2);
    touching_pyramid(rows, -(rows as f32 - 1.0) / 2.0, 0.0, &mut bodies);
    box3d_world(bodies, vec![])
}

/// Rows of each pyramid of `many_pyramids` (Box3D's `baseCount`), and its cubes.
const SMALL_PYRAMID_ROWS: usize = 10;
pub(crate) const SMALL_PYRAMID_BOXES: usize = SMALL_PYRAMID_ROWS * (SMALL_PYRAMID_ROWS + 1) / 2;

/// `many_pyramids`: Box3D's benchmark of that name, `side` x `side`
/// pyramids (Box3D: 14 x 14 = 196) of `SMALL_PYRAMID_ROWS` rows (55 unit
/// cubes each, touching as in `large_pyramid`) on the ground. As Box3D
/// places them: 11 m apart along x (a pyramid's 10 m base and 1 m between
/// bases), and along z spread evenly over its ground's depth (11.7 m
/// apart at 14), the grid about centred on the origin; Box3D's world.
pub fn many_pyramids(side: usize) -> Scene {
    let pitch = SMALL_PYRAMID_ROWS as f32 + 1.0;
    // Box3D's ground is a square of half-width `ground`; the first base
    // starts a metre in from its corner
    let ground = 0.5 * side as f32 * pitch;
    let z_pitch = if side > 1 { 2.0 * (ground - 1.0) / (side as f32 - 1.0) } else { 0.0 };
    let mut bodies = Vec::with_capacity(side * side * SMALL_PYRAMID_BOXES);
    for row in 0..side {
        for col in 0..side {
            let x0 = -ground + 1.0 + col as f32 * pitch;
            touching_pyramid(SMALL_PYRAMID_ROWS, x0, -ground + 1.0 + row as f32 * z_pitch, &mut bodies);
        }
    }
    box3d_world(bodies, vec![])
}

/// `joint_grid`: Box3D's benchmark of that name, a curtain of `side` x
/// `side` balls (radius 0.4 m, 1000 kg/m^3; Box3D: 100 x 100) 1 m apart in
/// the plane z = 0, hanging from its top row: ball `(column k, row i)` at
/// (k, -i, 0), row 0 fixed, each ball joined to the one above it and to
/// the one to its left by ball joints at the midpoint, 2 side (side - 1)
/// joints (19 800 at 100), the top row's joints between two fixed balls
/// included, as Box3D has them. Box3D's balls do not collide with each
/// other (a collision filter, which our scenes lack); 0.2 m apart, ours
/// touch only if the curtain folds. No ground, as in Box3D; Box3D's world
/// (`box3d_world`). Box3D's joints are spherical joints, as ours.
pub fn joint_grid(side: usize) -> Scene {
    let mut bodies = Vec::with_capacity(side * side);
    let mut joints = Vec::with_capacity(2 * side * side.saturating_sub(1));
    for k in 0..side {
        for i in 0..side {
            let index = bodies.len() as i32;
            let mut b = sphere_body(0.4, [k as f32, 0.0 - i as f32, 0.0]);
            b.fixed = i == 0;
            bodies.push(b);
            if i > 0 {
                joints.push(Joint { bodies: [index - 1, index], anchors: [[0.0, -0.5, 0.0], [0.0, 0.5, 0.0]] });
            }
            if k > 0 {
                joints.push(Joint { bodies: [index - side as i32, index], anchors: [[0.5, 0.0, 0.0], [-0.5, 0.0, 0.0]] });
            }
        }
    }
    let mut s = box3d_world(bodies, joints);
    s.ground = None;
    s
}

/// The drum of [`washer`]: where it is, how large, how fast it turns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drum {
    /// The middle of its axis, which runs along z (m); every panel's and
    /// baffle's `position`, the point its frame turns about.
    pub centre: [f32; 3],
    /// The panels' inner radius (m): the drum's room is within it and
    /// between the end walls.
    pub inner_radius: f32,
    /// The panels' outer radius (m).
    pub outer_radius: f32,
    /// How far in the baffles reach from the axis (m).
    pub baffle_radius: f32,
    /// Half its length (m): the end walls' inner faces are at `centre` z
    /// plus and minus this, where the panels end.
    pub half_length: f32,
    /// Its turn about +z (rad/s), every panel's and baffle's.
    pub spin: f32,
}

/// The panels around a `washer`'s drum (Box3D's), each spanning 10 degrees.
pub(crate) const WASHER_PANELS: usize = 36;
/// The baffles: one on every ninth panel.
pub(crate) const WASHER_BAFFLES: usize = WASHER_PANELS / 9;
/// The drum's bodies: its panels, its baffles and its two end walls.
pub(crate) const WASHER_DRUM_BODIES: usize = WASHER_PANELS + WASHER_BAFFLES + 2;
/// A `washer` cube's half extent and the lattice's pitch (m), Box3D's.
const WASHER_CUBE: f32 = 0.2;
const WASHER_PITCH: f32 = 4.0 * WASHER_CUBE;

/// The drum of `washer` for `side` x `side` x `side` cubes: Box3D's (axis
/// 21 m up, panels from 16 to 18 m out, baffles to 14 m in, 20 m long,
/// turning at 25 degrees a second) while it holds the cubes' lattice with
/// 0.5 m to spare (up to 24 a side), else Box3D's scaled by as much as it
/// takes, turning slower by the square root of the scale so that it lifts
/// and drops the cubes as Box3D's does (the same omega^2 r / g).
pub fn washer_drum(side: usize) -> Drum {
    // the lattice's half width, from the axis to its cubes' far faces
    let half = WASHER_PITCH * side.saturating_sub(1) as f32 / 2.0 + WASHER_CUBE;
    let room = 0.5;
    let scale = 1f32.max((half * std::f32::consts::SQRT_2 + room) / 14.0).max((half + room) / 10.0);
    Drum {
        centre: [0.0, 21.0 * scale, 0.0],
        inner_radius: 16.0 * scale,
        outer_radius: 18.0 * scale,
        baffle_radius: 14.0 * scale,
        half_length: 10.0 * scale,
        spin: 25f32.to_radians() / scale.sqrt(),
    }
}

/// `washer`: Box3D's benchmark of that name, `side` x `side` x `side`
/// cubes of 0.4 m (Box3D: 20 x 20 x 20 = 8000; 1000 kg/m^3, Box3D's
/// water) tumbled in a drum turning about a horizontal axis ([`washer_drum`]).
/// Box3D's drum is one kinematic body of 40 hulls; here each is a body of
/// its own, a kinematic hull whose `position` is the drum's axis (a
/// kinematic body turns about its frame's origin), all with the drum's
/// spin:
///
/// - 36 panels, each the hull of 8 points: the annular sector from the
///   inner to the outer radius over its 10 degrees widened by 1 degree on
///   either side (as Box3D's), so that neighbours overlap and no gap opens
///   between them;
/// - on every ninth panel a baffle, the sector of its 10 degrees from the
///   baffle radius out to the inner radius, which lifts the cubes.
///
/// Box3D's drum is open at its ends; here two fixed boxes 1 m thick close
/// them, their inner faces where the panels end, and as wide and tall as the
/// drum. Box3D's lattice (0.8 m pitch) starts in the drum's lower half,
/// its lowest cubes inside the panels; here it is as low as it fits within
/// the baffles' reach with 0.5 m to spare, centred on the axis along x and
/// z (at Box3D's size its lowest cubes start 5 m above the panels). On the
/// ground, as Box3D's; Box3D's world (`box3d_world`).
pub fn washer(side: usize) -> Scene {
    let drum = washer_drum(side);
    let (r0, r1, r2, h) = (drum.baffle_radius, drum.inner_radius, drum.outer_radius, drum.half_length);
    let step = std::f32::consts::TAU / WASHER_PANELS as f32;
    let widen = 0.1 * step;
    // the hull of the sector from radius `inner` to `outer` between two
    // angles, the drum's length long, in the drum's frame
    let sector = |inner: f32, outer: f32, from: f32, to: f32| {
        let mut points = Vec::with_capacity(8);
        for z in [-h, h] {
            for r in [inner, outer] {
                for a in [from, to] {
                    points.push([r * a.cos(), r * a.sin(), z]);
                }
            }
        }
        let shape = HullShape::new(points).expect("a sector of a ring spans a volume");
        Body { angular_velocity: [0.0, 0.0, drum.spin], kinematic: true, ..Body::new(Shape::Hull(shape), drum.centre) }
    };
    let mut bodies = Vec::with_capacity(WASHER_DRUM_BODIES + side.saturating_mul(side).saturating_mul(side));
    for i in 0..WASHER_PANELS {
        let a = i as f32 * step;
        bodies.push(sector(r1, r2, a - widen, a + step + widen));
    }
    for i in (0..WASHER_PANELS).step_by(WASHER_PANELS / WASHER_BAFFLES) {
        let a = i as f32 * step;
        bodies.push(sector(r0, r1, a, a + step));
    }
    let [x, y, z] = drum.centre;
    for end in [-1.0f32, 1.0] {
        let mut wall = box_body([r2, r2, 0.5], [x, y, z + end * (h + 0.5)]);
        wall.fixed = true;
        bodies.push(wall);
    }
    // the lattice centred on the axis along x and z, and as low as its
    // lowest edges stay within the baffles' reach with 0.5 m to spare
    // (`washer_drum` leaves room), so that the cubes fall no farther than
    // they must
    let half = WASHER_PITCH * side.saturating_sub(1) as f32 / 2.0 + WASHER_CUBE;
    let low = half - ((r0 - 0.5).powi(2) - half * half).max(0.0).sqrt();
    let at = |k: usize| WASHER_PITCH * k as f32 - half + WASHER_CUBE;
    for i in 0..side {
        for j in 0..side {
            for k in 0..side {
                bodies.push(box_body([WASHER_CUBE; 3], [x + at(i), y + low + at(j), z + at(k)]));
            }
        }
    }
    box3d_world(bodies, vec![])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Ground, Shape};
    use crate::scenes::{body_count, by_name};

    fn centre(b: &Body) -> glam::Vec3 {
        glam::Vec3::from(b.position)
    }

    /// Asserts that the unit cubes of `s` stand as a pyramid's should: upright,
    /// none overlapping another, neighbours in a row touching, and each on
    /// the ground or on exactly two cubes of the row below, half a cube
    /// to either side.
    fn assert_stacked(s: &Scene) {
        let b = &s.bodies;
        for (n, x) in b.iter().enumerate() {
            assert_eq!(x.shape, Shape::Box { half_extents: [0.5; 3] }, "cube {n}");
            assert_eq!(x.orientation, [0.0, 0.0, 0.0, 1.0], "cube {n}");
            assert!((x.mass - 100.0).abs() < 1e-3, "cube {n} weighs {} kg, Box3D's 100 kg/m^3 makes 100", x.mass);
            let p = centre(x);
            let mut under = 0;
            for (m, y) in b.iter().enumerate().filter(|&(m, _)| m != n) {
                let d = centre(y) - p;
                // unit cubes overlap where every axis is nearer than 1 m
                assert!(d.abs().max_element() >= 1.0 - 1e-5, "cubes {n} and {m} overlap: {d}");
                if d.z == 0.0 && d.y == -1.0 && (d.x.abs() - 0.5).abs() < 1e-5 {
                    under += 1;
                }
            }
            let row = p.y - 0.5;
            assert_eq!(row, row.round(), "cube {n} at height {}: rows are 1 m apart from the ground up", p.y);
            assert_eq!(under, if row == 0.0 { 0 } else { 2 }, "cube {n} at {p} rests on {under} cubes");
            if row == 0.0 {
                assert_eq!(p.y, 0.5, "cube {n} stands on the ground");
            }
        }
    }

    #[test]
    fn large_pyramid_is_box3ds_at_its_default_size() {
        let s = by_name("large_pyramid", None, 1).unwrap();
        assert_eq!(s.bodies.len(), 5050);
        assert_eq!(body_count("large_pyramid", None), Some(5050));
        assert!(s.joints.is_empty());
        assert_eq!(s.ground, Some(Ground { height: 0.0 }));
        assert_eq!((s.settings.gravity, s.settings.friction, s.settings.sleeping), ([0.0, -10.0, 0.0], 0.6, false));
        s.validate().unwrap();
        // centred, the bottom row 100 cubes touching side by side
        let bottom: Vec<f32> = s.bodies.iter().filter(|b| b.position[1] == 0.5).map(|b| b.position[0]).collect();
        assert_eq!(bottom.len(), 100);
        assert_eq!((bottom[0], bottom[99]), (-49.5, 49.5));
        let top = s.bodies.iter().map(|b| b.position[1]).fold(0.0, f32::max);
        assert_eq!(top, 99.5);
    }

    #[test]
    fn the_cubes_of_a_large_pyramid_touch_without_overlapping() {
        for rows in [1, 2, 7, 30] {
            let s = large_pyramid(rows);
            assert_eq!(s.bodies.len(), rows * (rows + 1) / 2);
            assert_stacked(&s);
        }
    }

    #[test]
    fn many_pyramids_is_box3ds_at_its_default_size() {
        let s = by_name("many_pyramids", None, 1).unwrap();
        assert_eq!(s.bodies.len(), 196 * 55);
        assert_eq!(body_count("many_pyramids", None), Some(10_780));
        s.validate().unwrap();
        // on Box3D's ground, a square of half-width 77 m, about centred
        let (lo, hi) = s.bodies.iter().fold((f32::MAX, f32::MIN), |(lo, hi), b| {
            (lo.min(b.position[0] - 0.5).min(b.position[2]), hi.max(b.position[0] + 0.5).max(b.position[2]))
        });
        assert!(lo >= -77.0 && hi <= 77.0 && (lo + hi).abs() < 1.0, "the pyramids span {lo} to {hi} m");
        // 14 rows of pyramids along z, 14 pyramid bases along x
        let mut zs: Vec<f32> = s.bodies.iter().map(|b| b.position[2]).collect();
        zs.dedup();
        zs.sort_by(f32::total_cmp);
        zs.dedup();
        assert_eq!(zs.len(), 14);
        assert!((zs[1] - zs[0] - 152.0 / 13.0).abs() < 1e-3, "rows of pyramids {} m apart", zs[1] - zs[0]);
        assert_eq!(s.bodies.iter().filter(|b| b.position[1] == 0.5 && b.position[2] == zs[0]).count(), 140);
    }

    #[test]
    fn the_cubes_of_many_pyramids_touch_without_overlapping() {
        for side in [1, 2, 3] {
            let s = many_pyramids(side);
            assert_eq!(s.bodies.len(), side * side * SMALL_PYRAMID_BOXES);
            assert_eq!(body_count("many_pyramids", Some(side)), Some(s.bodies.len() as u64));
            assert_stacked(&s);
        }
        // a metre between one pyramid's base and the next along x
        let s = many_pyramids(2);
        let bottom: Vec<f32> = s.bodies.iter().filter(|b| b.position[1] == 0.5).map(|b| b.position[0]).collect();
        let gaps: Vec<f32> = bottom.windows(2).map(|w| w[1] - w[0]).filter(|&d| d != 1.0).collect();
        assert!(gaps.iter().all(|&d| d == 2.0 || d < 0.0), "bases' centres {gaps:?} apart where they are not neighbours");
    }

    #[test]
    fn joint_grid_is_box3ds_at_its_default_size() {
        let s = by_name("joint_grid", None, 1).unwrap();
        assert_eq!((s.bodies.len(), s.joints.len()), (10_000, 19_800));
        assert_eq!(body_count("joint_grid", None), Some(10_000));
        assert_eq!(s.bodies.iter().filter(|b| b.fixed).count(), 100);
        assert_eq!(s.ground, None);
        s.validate().unwrap();
    }

    #[test]
    fn joint_grid_joins_neighbours_at_matching_anchors() {
        for side in [1, 2, 5, 10] {
            let s = joint_grid(side);
            assert_eq!((s.bodies.len(), s.joints.len()), (side * side, 2 * side * (side - 1)));
            let mut pairs = std::collections::HashSet::new();
            for (n, j) in s.joints.iter().enumerate() {
                let [a, b] = j.bodies.map(|i| &s.bodies[i as usize]);
                // the anchors meet halfway between neighbours 1 m apart
                let (pa, pb) = (centre(a) + glam::Vec3::from(j.anchors[0]), centre(b) + glam::Vec3::from(j.anchors[1]));
                assert_eq!(pa, pb, "joint {n}: its anchors are apart at the start");
                assert_eq!((centre(a) - centre(b)).length(), 1.0, "joint {n} joins bodies that are not neighbours");
                assert_eq!((pa - centre(a)).length(), 0.5, "joint {n}");
                assert!(pairs.insert(j.bodies), "joint {n} repeats another");
            }
            // the top row hangs from nothing else: it is fixed, the rest move
            for b in &s.bodies {
                assert_eq!(b.fixed, b.position[1] == 0.0);
                assert_eq!(b.shape, Shape::Sphere { radius: 0.4 });
            }
            s.validate().unwrap();
        }
    }

    /// The angle of `p` about the z axis, in [0, 2 pi).
    fn angle(p: glam::Vec3) -> f32 {
        p.y.atan2(p.x).rem_euclid(std::f32::consts::TAU)
    }

    /// Asserts that `s` is a washer of `side` cubes a side in `drum`: its
    /// drum's bodies first, then the cubes; the panels and baffles
    /// kinematic hulls at the axis with the drum's spin, the panels closing
    /// the ring (each overlapping the next), the baffles within it, the end
    /// walls fixed boxes covering the ends where the panels stop, and every
    /// cube inside the baffles' reach and between the walls, none touching
    /// another.
    fn assert_washer(s: &Scene, side: usize, drum: &Drum) {
        let centre = glam::Vec3::from(drum.centre);
        assert_eq!(s.bodies.len(), WASHER_DRUM_BODIES + side * side * side);
        let (hulls, rest) = s.bodies.split_at(WASHER_PANELS + WASHER_BAFFLES);
        let mut spans = Vec::new();
        for (n, b) in hulls.iter().enumerate() {
            let Shape::Hull(shape) = &b.shape else { panic!("body {n} is not a hull: {:?}", b.shape) };
            assert!(b.kinematic && !b.fixed && b.mass_frame().is_none(), "body {n}");
            assert_eq!((b.position, b.orientation), (drum.centre, [0.0, 0.0, 0.0, 1.0]), "body {n} turns about the axis");
            assert_eq!((b.angular_velocity, b.linear_velocity), ([0.0, 0.0, drum.spin], [0.0; 3]), "body {n}");
            let points: Vec<glam::Vec3> = shape.points().iter().map(|&p| glam::Vec3::from(p)).collect();
            assert_eq!((points.len(), shape.hull().vertices.len()), (8, 8), "body {n}: a sector of 8 corners");
            let (inner, outer) =
                if n < WASHER_PANELS { (drum.inner_radius, drum.outer_radius) } else { (drum.baffle_radius, drum.inner_radius) };
            for p in &points {
                let r = p.truncate().length();
                assert!((r - inner).abs() < 1e-3 * inner || (r - outer).abs() < 1e-3 * outer, "body {n}: a corner {r} m out");
                assert!((p.z.abs() - drum.half_length).abs() < 1e-5, "body {n}: a corner at z = {}", p.z);
            }
            // its angles about its first corner's, within half a turn (a
            // panel crosses 0): where it starts and how wide it is
            let pi = std::f32::consts::PI;
            let first = angle(points[0]);
            let about = points.iter().map(|&p| (angle(p) - first + pi).rem_euclid(std::f32::consts::TAU) - pi);
            let (lo, hi) = about.fold((f32::MAX, f32::MIN), |(lo, hi), d| (lo.min(d), hi.max(d)));
            spans.push((n, first + lo, hi - lo));
        }
        let step = std::f32::consts::TAU / WASHER_PANELS as f32;
        for &(n, start, width) in &spans[..WASHER_PANELS] {
            assert!((width - 1.2 * step).abs() < 1e-4, "panel {n} spans {width} rad");
            // the next panel starts before this one ends: no gap between them
            let next = spans[(n + 1) % WASHER_PANELS].1;
            let overlap = (start + width - next).rem_euclid(std::f32::consts::TAU);
            assert!((overlap - 0.2 * step).abs() < 1e-4, "panels {n} and the next overlap by {overlap} rad");
        }
        for &(n, _, width) in &spans[WASHER_PANELS..] {
            assert!((width - step).abs() < 1e-4, "baffle {n} spans {width} rad");
        }
        let (walls, cubes) = rest.split_at(2);
        for (end, w) in [-1.0f32, 1.0].into_iter().zip(walls) {
            let Shape::Box { half_extents: h } = w.shape else { panic!("an end wall is not a box") };
            assert!(w.fixed && !w.kinematic);
            assert!(h[0] >= drum.outer_radius && h[1] >= drum.outer_radius, "an end wall of half extents {h:?}");
            let inner_face = (w.position[2] - h[2] * end - centre.z) * end;
            assert!((inner_face - drum.half_length).abs() < 1e-5, "an end wall's inner face {inner_face} m along the axis");
            assert_eq!((w.position[0], w.position[1]), (centre.x, centre.y));
            assert!(w.position[1] - h[1] > 0.0, "an end wall stands on nothing: it is above the ground");
        }
        for (n, c) in cubes.iter().enumerate() {
            assert_eq!(c.shape, Shape::Box { half_extents: [0.2; 3] }, "cube {n}");
            assert!(c.is_dynamic() && (c.mass - 64.0).abs() < 1e-3, "cube {n}");
            let p = glam::Vec3::from(c.position) - centre;
            // its bounding sphere inside the baffles and the walls
            let reach = c.bounding_radius();
            assert!(p.truncate().length() + reach < drum.baffle_radius - 0.1, "cube {n} at {p} from the axis's middle");
            assert!(p.z.abs() + reach < drum.half_length, "cube {n} at {p} from the axis's middle");
        }
        // a lattice 0.8 m apart: cubes of 0.4 m do not touch
        let mut gaps = cubes.windows(2).map(|w| (glam::Vec3::from(w[1].position) - glam::Vec3::from(w[0].position)).length());
        assert!(gaps.all(|d| d >= 0.8 - 1e-4), "neighbouring cubes nearer than 0.8 m");
        s.validate().unwrap();
    }

    #[test]
    fn washer_is_box3ds_at_its_default_size() {
        let s = by_name("washer", None, 1).unwrap();
        assert_eq!(s.bodies.len(), 8042);
        assert_eq!(body_count("washer", None), Some(8042));
        assert_eq!(s.ground, Some(Ground { height: 0.0 }));
        assert_eq!((s.settings.gravity, s.settings.friction, s.settings.sleeping), ([0.0, -10.0, 0.0], 0.6, false));
        let drum = washer_drum(20);
        let spin = 25f32.to_radians();
        assert_eq!(
            drum,
            Drum { centre: [0.0, 21.0, 0.0], inner_radius: 16.0, outer_radius: 18.0, baffle_radius: 14.0, half_length: 10.0, spin }
        );
        assert_washer(&s, 20, &drum);
    }

    #[test]
    fn a_washer_holds_its_cubes_at_any_count() {
        for side in [0, 1, 2, 5, 24, 25, 40] {
            let s = washer(side);
            let drum = washer_drum(side);
            assert_eq!(body_count("washer", Some(side)), Some(s.bodies.len() as u64));
            assert_washer(&s, side, &drum);
            if side <= 24 {
                assert_eq!(drum, washer_drum(20), "{side} a side fit Box3D's drum");
            } else {
                // scaled up, turning slower: omega^2 r as at Box3D's size
                let scale = drum.inner_radius / 16.0;
                assert!(scale > 1.0 && (drum.spin * drum.spin * scale - 25f32.to_radians().powi(2)).abs() < 1e-6);
            }
        }
    }
}
