//! The hulls as the GPU reads them (`hulls` in shaders/bindings.wgsl): one
//! run of 16-byte words per hull shape, in the frame the simulation keeps
//! the body's pose in (`Body::mass_frame`), shared by every body whose shape
//! is the same. The first run is a cube of half extent 1: a box meets a hull
//! as that cube scaled by its half extents. A scene without hulls has no
//! records.
//!
//! A run, from its first word:
//!
//! | words | what |
//! |---|---|
//! | 1 | counts: corners, faces, edges, and the corner indices of all faces (u32 bits) |
//! | corners | each corner (xyz; w 0) |
//! | faces | each face's plane: outward normal (xyz) and offset (w) |
//! | faces | each face's run of corner indices: first, count (u32 bits in x, y) |
//! | indices / 4, rounded up | the faces' corner indices, four to a word (u32 bits) |
//! | edges | each edge: its two corners and its two faces (u32 bits) |
//! | 1 | the sphere about its corners' box: its centre (xyz) and radius (w) |
//!
//! A body's props name its run's first word (`BodyProps::hull`).

use std::collections::HashMap;

use glam::{DQuat, DVec3};

use crate::gpu::types::NO_HULL;
use crate::scene::hull::Hull;
use crate::scene::{Body, HullShape, Shape};

/// The corners of the cube of half extent 1, as a hull's points.
pub(crate) fn unit_cube() -> Hull {
    let points: Vec<[f32; 3]> = (0..8)
        .map(|k| [if k & 1 == 0 { -1.0 } else { 1.0 }, if k & 2 == 0 { -1.0 } else { 1.0 }, if k & 4 == 0 { -1.0 } else { 1.0 }])
        .collect();
    Hull::new(&points).expect("a cube spans a volume")
}

/// How a hull body's points go into the frame its pose is kept in: p' =
/// axes^-1 (p - centre) (the identity where it is the body's own frame).
pub(crate) fn kept_frame(body: &Body) -> (DVec3, DQuat) {
    body.mass_frame().unwrap_or((DVec3::ZERO, DQuat::IDENTITY))
}

/// A hull body's corners in the frame its pose is kept in.
pub(crate) fn kept_corners(body: &Body, shape: &HullShape) -> Vec<DVec3> {
    let (centre, axes) = kept_frame(body);
    shape.hull().vertices.iter().map(|v| axes.conjugate() * (*v - centre)).collect()
}

/// The words of the unit cube and every hull shape of `bodies` and, for
/// each body, the first word of its hull's run (`NO_HULL` for a body with
/// no hull).
pub(crate) fn hull_records(bodies: &[Body]) -> (Vec<[f32; 4]>, Vec<u32>) {
    let mut words: Vec<[f32; 4]> = Vec::new();
    if bodies.iter().any(|b| matches!(b.shape, Shape::Hull(_))) {
        push_run(&mut words, &unit_cube(), DVec3::ZERO, DQuat::IDENTITY);
    }
    let mut firsts = vec![NO_HULL; bodies.len()];
    // bodies of one shape (and mass frame) share a run
    let mut seen: HashMap<Vec<u32>, u32> = HashMap::new();
    for (k, body) in bodies.iter().enumerate() {
        let Shape::Hull(shape) = &body.shape else { continue };
        firsts[k] = *seen.entry(hull_key(body, shape)).or_insert_with(|| {
            let first = words.len() as u32;
            let (centre, axes) = kept_frame(body);
            push_run(&mut words, shape.hull(), centre, axes);
            first
        });
    }
    (words, firsts)
}

/// What makes two hull bodies share a run (and a mesh): the same points,
/// kept in the same kind of frame.
pub(crate) fn hull_key(body: &Body, shape: &HullShape) -> Vec<u32> {
    let mut key: Vec<u32> = shape.points().iter().flatten().map(|v| v.to_bits()).collect();
    key.push(u32::from(body.mass_frame().is_some()));
    key
}

/// Appends the run of `hull` moved into the frame at `centre` with axes `axes`.
fn push_run(words: &mut Vec<[f32; 4]>, hull: &Hull, centre: DVec3, axes: DQuat) {
    let to_kept = |p: DVec3| axes.conjugate() * (p - centre);
    let bits = |v: u32| f32::from_bits(v);
    let indices: Vec<u32> = hull.faces.iter().flat_map(|f| f.corners.iter().map(|&c| c as u32)).collect();
    let edges = hull.edges();
    words.push([
        bits(hull.vertices.len() as u32),
        bits(hull.faces.len() as u32),
        bits(edges.len() as u32),
        bits(indices.len() as u32),
    ]);
    for v in &hull.vertices {
        let p = to_kept(*v);
        words.push([p.x as f32, p.y as f32, p.z as f32, 0.0]);
    }
    for f in &hull.faces {
        let n = axes.conjugate() * f.normal;
        // the plane through the kept frame: n' . p' = offset - n . c
        let offset = f.offset - f.normal.dot(centre);
        words.push([n.x as f32, n.y as f32, n.z as f32, offset as f32]);
    }
    let mut start = 0u32;
    for f in &hull.faces {
        words.push([bits(start), bits(f.corners.len() as u32), 0.0, 0.0]);
        start += f.corners.len() as u32;
    }
    for chunk in indices.chunks(4) {
        let mut word = [0.0f32; 4];
        for (w, &i) in word.iter_mut().zip(chunk) {
            *w = bits(i);
        }
        words.push(word);
    }
    for e in edges {
        words.push(e.map(|v| bits(v as u32)));
    }
    // a kinematic panel's corners lie far from its frame's origin: the sphere
    // about them keeps the narrowphase from testing the pairs it never meets
    let kept: Vec<DVec3> = hull.vertices.iter().map(|v| to_kept(*v)).collect();
    let lo = kept.iter().fold(DVec3::splat(f64::MAX), |a, &p| a.min(p));
    let hi = kept.iter().fold(DVec3::splat(f64::MIN), |a, &p| a.max(p));
    let centre = (lo + hi) * 0.5;
    // rounded up, so that no corner lies outside it
    let radius = kept.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max) * (1.0 + 1e-6) + 1e-6;
    words.push([centre.x as f32, centre.y as f32, centre.z as f32, radius as f32]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::HullShape;

    fn hull_body(points: Vec<[f32; 3]>, at: [f32; 3]) -> Body {
        Body::new(Shape::Hull(HullShape::new(points).unwrap()), at)
    }

    /// A unit cube's run: its counts, its corners about its centre, six
    /// planes half a metre out, their corner runs, and twelve edges with a
    /// face on each side; a second body of the same shape shares the run,
    /// a box none.
    #[test]
    fn a_cube_hull_is_one_run_shared_by_its_bodies() {
        let cube: Vec<[f32; 3]> =
            (0..8).map(|k| [(k & 1) as f32 - 0.5, ((k >> 1) & 1) as f32 - 0.5, ((k >> 2) & 1) as f32 - 0.5]).collect();
        let bodies = vec![
            hull_body(cube.clone(), [0.0; 3]),
            crate::scenes::box_body([0.5; 3], [3.0, 0.0, 0.0]),
            hull_body(cube, [6.0, 0.0, 0.0]),
        ];
        let (words, firsts) = hull_records(&bodies);
        let cube_run = firsts[0] as usize;
        assert_eq!(firsts, vec![firsts[0], NO_HULL, firsts[0]]);
        // the unit cube's run comes first, as long as this one
        assert_eq!(cube_run * 2, words.len());
        let words = &words[cube_run..];
        let counts = words[0].map(f32::to_bits);
        assert_eq!(counts, [8, 6, 12, 24]);
        let corners = &words[1..9];
        assert!(corners.iter().all(|c| c[..3].iter().all(|v| (v.abs() - 0.5).abs() < 1e-6)), "{corners:?}");
        let planes = &words[9..15];
        assert!(planes
            .iter()
            .all(|p| (p[3] - 0.5).abs() < 1e-6 && (glam::Vec3::new(p[0], p[1], p[2]).length() - 1.0).abs() < 1e-6));
        let runs = &words[15..21];
        assert_eq!(runs.iter().map(|r| r[1].to_bits()).sum::<u32>(), 24);
        let index_words = 24usize.div_ceil(4);
        let edges = &words[21 + index_words..words.len() - 1];
        assert_eq!(edges.len(), 12);
        // the sphere about the cube: its centre, reaching every corner
        let sphere = words[words.len() - 1];
        assert!(sphere[..3].iter().all(|v| v.abs() < 1e-6) && (sphere[3] - 0.75f32.sqrt()).abs() < 1e-5, "{sphere:?}");
        assert!(edges.iter().all(|e| e[2].to_bits() != e[3].to_bits()));
        // every face's corners lie on its plane
        let indices: Vec<u32> = words[21..21 + index_words].iter().flat_map(|w| w.map(f32::to_bits)).collect();
        for (p, r) in planes.iter().zip(runs) {
            let (start, n) = (r[0].to_bits() as usize, r[1].to_bits() as usize);
            for &i in &indices[start..start + n] {
                let c = corners[i as usize];
                assert!((p[0] * c[0] + p[1] * c[1] + p[2] * c[2] - p[3]).abs() < 1e-6);
            }
        }
    }
}
