//! The meshes bodies are drawn from, wound for back-face culling: a unit
//! cube and a unit icosphere, scaled per instance, and each hull's own
//! faceted mesh, in metres.

use bytemuck::{Pod, Zeroable};
use glam::{DQuat, DVec3, Vec3};

use crate::scene::hull::Hull;

/// Subdivisions of the icosahedron for spheres: 1280 triangles, smooth at
/// any size a sphere takes in a frame.
pub(super) const ICOSPHERE_LEVEL: u32 = 3;

/// A vertex of the meshes (24 bytes): position and outward normal.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(super) struct MeshVertex {
    pos: [f32; 3],
    normal: [f32; 3],
}

/// A triangle wound counter-clockwise seen from outside (where its normal
/// points): the winding back-face culling keeps.
fn outward(a: Vec3, b: Vec3, c: Vec3, out: Vec3) -> [Vec3; 3] {
    if (b - a).cross(c - a).dot(out) >= 0.0 {
        [a, b, c]
    } else {
        [a, c, b]
    }
}

/// The cube [-1, 1]^3 as 12 triangles with face normals.
pub(super) fn unit_cube() -> Vec<MeshVertex> {
    let mut v = Vec::with_capacity(36);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let unit = |k: usize| Vec3::AXES[k % 3];
            let (n, u, w) = (sign * unit(axis), unit(axis + 1), unit(axis + 2));
            let corner = |a: f32, b: f32| n + a * u + b * w;
            let quad = [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
            for tri in [[0, 1, 2], [0, 2, 3]] {
                for p in outward(quad[tri[0]], quad[tri[1]], quad[tri[2]], n) {
                    v.push(MeshVertex { pos: p.to_array(), normal: n.to_array() });
                }
            }
        }
    }
    v
}

/// The unit sphere: an icosahedron with each triangle split in four `level`
/// times, pushed out to the sphere, smooth normals.
pub(super) fn icosphere(level: u32) -> Vec<MeshVertex> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let p = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .map(|a| Vec3::from_array(a).normalize());
    let faces = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut tris: Vec<[Vec3; 3]> = faces.iter().map(|f| [p[f[0]], p[f[1]], p[f[2]]]).collect();
    for _ in 0..level {
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let (ab, bc, ca) = ((a + b).normalize(), (b + c).normalize(), (c + a).normalize());
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    tris.into_iter()
        .flat_map(|[a, b, c]| outward(a, b, c, a + b + c))
        .map(|q| MeshVertex { pos: q.to_array(), normal: q.to_array() })
        .collect()
}

/// `hull`'s faces, each fanned into triangles with its own normal (flat
/// shading), in the frame the body's pose is kept in: `frame` is
/// `Body::mass_frame` (its centre and axes in the hull's frame), so a
/// point p is drawn at axes^-1 (p - centre).
pub(super) fn hull_mesh(hull: &Hull, frame: Option<(DVec3, DQuat)>) -> Vec<MeshVertex> {
    let (centre, axes) = frame.unwrap_or((DVec3::ZERO, DQuat::IDENTITY));
    let to_kept = |p: DVec3| (axes.conjugate() * (p - centre)).as_vec3();
    let mut v = Vec::new();
    for face in &hull.faces {
        let n = (axes.conjugate() * face.normal).as_vec3();
        let corner = |k: usize| to_kept(hull.vertices[face.corners[k]]);
        for k in 1..face.corners.len().saturating_sub(1) {
            for p in outward(corner(0), corner(k), corner(k + 1), n) {
                v.push(MeshVertex { pos: p.to_array(), normal: n.to_array() });
            }
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Body, HullShape, Shape};

    /// A box hull off its frame's origin: two triangles a face, each wound
    /// outward with its face's normal, its corners moved into the kept
    /// frame, where they sit about the centre of mass.
    #[test]
    fn a_hull_mesh_is_its_faces_fanned_in_the_kept_frame() {
        let points: Vec<[f32; 3]> =
            (0..8).map(|k| [2.0 + (k & 1) as f32, 1.0 + 0.5 * ((k >> 1) & 1) as f32, 0.25 * ((k >> 2) & 1) as f32]).collect();
        let body = Body::new(Shape::Hull(HullShape::new(points).unwrap()), [0.0; 3]);
        let Shape::Hull(shape) = &body.shape else { unreachable!() };
        let frame = body.mass_frame().unwrap();
        let mesh = hull_mesh(shape.hull(), Some(frame));
        assert_eq!(mesh.len(), 6 * 2 * 3);
        for tri in mesh.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from_array(tri[k].pos));
            let n = Vec3::from_array(tri[0].normal);
            assert!((b - a).cross(c - a).normalize().dot(n) > 0.999, "{tri:?}");
            assert!(tri.iter().all(|v| v.normal == tri[0].normal));
        }
        // each vertex is a corner moved by p' = axes^-1 (p - centre)
        let (centre, axes) = frame;
        for v in &mesh {
            let p = axes * Vec3::from_array(v.pos).as_dvec3() + centre;
            assert!(shape.hull().vertices.iter().any(|c| (*c - p).length() < 1e-5), "{v:?}");
        }
        let mean = mesh.iter().map(|v| Vec3::from_array(v.pos)).sum::<Vec3>() / mesh.len() as f32;
        assert!(mean.length() < 1e-5, "{mean}");
        // in its own frame (a kinematic hull's), the corners as given
        let own = hull_mesh(shape.hull(), None);
        assert!(own.iter().all(|v| v.pos[0] >= 2.0 && v.pos[1] >= 1.0));
    }
}
