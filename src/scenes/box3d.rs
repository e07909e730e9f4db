//! Box3D's benchmark scenes, set up as its `benchmark` program sets them
//! up, so that a bench case here and there names the same world.

use super::build::{box_body, scene, sphere_body};
use crate::scene::{Body, Joint, Scene};

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
}
