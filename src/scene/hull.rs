//! Convex hulls of a few points (4 to 64): their faces, and the mass
//! properties of the solid they bound.
//!
//! The faces are found by their planes: every plane through three of the
//! points with all the points on one side supports the hull, and the points
//! on it, taken in turn around it, are its face. For 64 points that is
//! 41 664 candidate planes, most ruled out by the first few points tried:
//! well under a millisecond a hull. The solid's volume, centre of mass and
//! inertia come from tetrahedra from an inner point to each face's
//! triangles, summed in f64; its principal axes from the inertia tensor by
//! Jacobi rotations.
// The Jacobi rotations index rows and columns by number, as written.
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DQuat, DVec3};

/// The fewest and the most points a hull is given by.
pub const MIN_POINTS: usize = 4;
pub const MAX_POINTS: usize = 64;

/// A face of a hull: its outward unit normal, its plane's offset
/// (`normal . p = offset` on it) and its corners, counter-clockwise seen
/// from outside, as indices into `Hull::vertices`.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    pub normal: DVec3,
    pub offset: f64,
    pub corners: Vec<usize>,
}

/// A convex hull and the solid it bounds, in the frame its points were
/// given in.
#[derive(Clone, Debug, PartialEq)]
pub struct Hull {
    /// The points that are corners of the hull (others are dropped).
    pub vertices: Vec<DVec3>,
    pub faces: Vec<Face>,
    /// The solid's volume (m^3).
    pub volume: f64,
    /// Its centre of mass (uniform density).
    pub centroid: DVec3,
    /// Its inertia tensor about the centroid per unit density (m^5).
    pub inertia: DMat3,
}

impl Hull {
    /// The hull of `points`, or why they make none: fewer than
    /// `MIN_POINTS` or more than `MAX_POINTS`, not finite, or not spanning
    /// a volume (all on one plane, within a millionth of their extent).
    pub fn new(points: &[[f32; 3]]) -> Result<Hull, String> {
        if points.len() < MIN_POINTS || points.len() > MAX_POINTS {
            return Err(format!("must list {MIN_POINTS} to {MAX_POINTS} points, got {}", points.len()));
        }
        if let Some(k) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(format!("point {k} is not finite: {:?}", points[k]));
        }
        let pts: Vec<DVec3> = points.iter().map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)).collect();
        let lo = pts.iter().fold(DVec3::splat(f64::MAX), |a, &p| a.min(p));
        let hi = pts.iter().fold(DVec3::splat(f64::MIN), |a, &p| a.max(p));
        let extent = (hi - lo).max_element();
        // points nearly on a plane of others may be taken on one face and
        // off its neighbour, leaving the faces open: a coarser tolerance
        // then takes them on both
        let mut tolerance = 1e-6;
        loop {
            let eps = tolerance * extent.max(f64::MIN_POSITIVE);
            let hull = Hull::within(&pts, eps, extent)?;
            if hull.closed() {
                return Ok(hull);
            }
            tolerance *= 10.0;
            if tolerance > 1e-3 {
                return Err("are too nearly on common planes to make a closed hull".into());
            }
        }
    }

    /// The hull of `pts` with points within `eps` of a plane taken on it.
    fn within(pts: &[DVec3], eps: f64, extent: f64) -> Result<Hull, String> {
        let planes = supporting_planes(pts, eps);
        if planes.len() < 4 {
            return Err("do not span a volume: they lie on one plane".into());
        }
        let mut vertices: Vec<DVec3> = Vec::new();
        let mut faces = Vec::with_capacity(planes.len());
        for (normal, offset) in planes {
            let on: Vec<DVec3> = pts.iter().copied().filter(|p| (normal.dot(*p) - offset).abs() <= eps).collect();
            let corners = polygon(&on, normal, eps)
                .into_iter()
                .map(|p| match vertices.iter().position(|v| (*v - p).length() <= eps) {
                    Some(k) => k,
                    None => {
                        vertices.push(p);
                        vertices.len() - 1
                    }
                })
                .collect();
            faces.push(Face { normal, offset, corners });
        }
        let (volume, centroid, inertia) = mass_properties(&vertices, &faces);
        if volume.is_nan() || volume <= eps * extent * extent {
            return Err("do not span a volume: they lie on one plane".into());
        }
        Ok(Hull { vertices, faces, volume, centroid, inertia })
    }

    /// Whether every side of every face is a side of one other face, walked
    /// the other way, and every face has three corners at least.
    fn closed(&self) -> bool {
        let sides = |f: &Face| {
            let c = &f.corners;
            (0..c.len()).map(move |k| (c[k], c[(k + 1) % c.len()])).collect::<Vec<_>>()
        };
        let listed: Vec<(usize, usize)> = self.faces.iter().flat_map(sides).collect();
        let all: std::collections::HashSet<(usize, usize)> = listed.iter().copied().collect();
        // each side once, its reverse once, and V - E + F = 2 (Euler)
        self.faces.iter().all(|f| f.corners.len() >= 3)
            && listed.iter().all(|(a, b)| a != b)
            && all.len() == listed.len()
            && all.iter().all(|&(a, b)| all.contains(&(b, a)))
            && self.vertices.len() + self.faces.len() == listed.len() / 2 + 2
    }

    /// The principal moments of inertia (per unit density) and the turn
    /// from the principal axes to the hull's frame: the inertia tensor is
    /// `R diag(moments) R^T` with `R` the turn's matrix.
    pub fn principal(&self) -> ([f64; 3], DQuat) {
        let (moments, axes) = symmetric_eigen(self.inertia);
        // a right-handed frame, so that it is a turn
        let axes = if axes.determinant() < 0.0 { DMat3::from_cols(axes.x_axis, axes.y_axis, -axes.z_axis) } else { axes };
        (moments, DQuat::from_mat3(&axes).normalize())
    }

    /// Each edge once: its two corners, the face that walks it from the
    /// lower corner to the higher, and the face on its other side.
    pub fn edges(&self) -> Vec<[usize; 4]> {
        let mut edges = Vec::new();
        for (f, face) in self.faces.iter().enumerate() {
            let c = &face.corners;
            for k in 0..c.len() {
                let (a, b) = (c[k], c[(k + 1) % c.len()]);
                if a < b {
                    let walks_back =
                        |g: &Face| (0..g.corners.len()).any(|j| g.corners[j] == b && g.corners[(j + 1) % g.corners.len()] == a);
                    // a hull is closed (`new`): every side has a face on its other side
                    let other = self.faces.iter().position(walks_back).unwrap_or(f);
                    edges.push([a, b, f, other]);
                }
            }
        }
        edges
    }

    /// How far the hull reaches from `centre` at most (m).
    pub fn radius_about(&self, centre: DVec3) -> f64 {
        self.vertices.iter().map(|v| (*v - centre).length()).fold(0.0, f64::max)
    }
}

/// Every plane through three of the points with all the points on or
/// behind it (within `eps`), outward, each once.
fn supporting_planes(pts: &[DVec3], eps: f64) -> Vec<(DVec3, f64)> {
    let n = pts.len();
    let mut planes: Vec<(DVec3, f64)> = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let normal = (pts[j] - pts[i]).cross(pts[k] - pts[i]);
                let len = normal.length();
                if len <= eps * eps.max((pts[j] - pts[i]).length()) {
                    continue;
                }
                let mut normal = normal / len;
                let mut offset = normal.dot(pts[i]);
                // all points behind the plane, or all in front (then flipped)
                let mut sign = 0.0;
                let supports = pts.iter().all(|p| {
                    let d = normal.dot(*p) - offset;
                    if d.abs() <= eps {
                        return true;
                    }
                    if sign == 0.0 {
                        sign = d.signum();
                    }
                    d.signum() == sign
                });
                if !supports || sign == 0.0 {
                    continue;
                }
                if sign > 0.0 {
                    normal = -normal;
                    offset = -offset;
                }
                // one face once: a plane its three points already lie on (other
                // triples of a face give normals that differ by rounding)
                let known =
                    |(m, o): &(DVec3, f64)| m.dot(normal) > 0.9 && [i, j, k].iter().all(|&q| (m.dot(pts[q]) - o).abs() <= eps);
                if !planes.iter().any(known) {
                    planes.push((normal, offset));
                }
            }
        }
    }
    planes
}

/// The corners of the convex polygon of `on` (points on one plane of
/// outward normal `normal`), counter-clockwise seen from outside; points
/// on its sides between corners are left out.
fn polygon(on: &[DVec3], normal: DVec3, eps: f64) -> Vec<DVec3> {
    // a frame in the plane
    let u = normal.any_orthonormal_vector();
    let v = normal.cross(u);
    let flat: Vec<(f64, f64, DVec3)> = on.iter().map(|p| (p.dot(u), p.dot(v), *p)).collect();
    // Andrew's monotone chain on the plane's coordinates
    // each point once: none within eps of one kept before it
    let mut sorted: Vec<(f64, f64, DVec3)> = Vec::new();
    for p in flat {
        if !sorted.iter().any(|q| (q.2 - p.2).length() <= eps) {
            sorted.push(p);
        }
    }
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let cross =
        |o: &(f64, f64, DVec3), a: &(f64, f64, DVec3), b: &(f64, f64, DVec3)| (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0);
    let mut hull: Vec<(f64, f64, DVec3)> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64, DVec3)>> =
            if pass == 0 { Box::new(sorted.iter()) } else { Box::new(sorted.iter().rev()) };
        for p in iter {
            // a point within eps of the line through its neighbours is on a side
            while hull.len() >= start + 2 && {
                let (o, a) = (&hull[hull.len() - 2], &hull[hull.len() - 1]);
                cross(o, a, p) <= eps * ((p.0 - o.0).hypot(p.1 - o.1))
            } {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    // counter-clockwise about u x v = normal: seen from outside
    hull.into_iter().map(|(_, _, p)| p).collect()
}

/// Volume, centroid and inertia tensor about the centroid (per unit
/// density) of the solid bounded by `faces`: tetrahedra from the vertices'
/// mean to each face's fan of triangles.
fn mass_properties(vertices: &[DVec3], faces: &[Face]) -> (f64, DVec3, DMat3) {
    let inner = vertices.iter().copied().sum::<DVec3>() / vertices.len() as f64;
    let mut volume = 0.0;
    let mut first = DVec3::ZERO;
    // the second moments about `inner`: integral of r r^T dV
    let mut second = DMat3::ZERO;
    for face in faces {
        let c = &face.corners;
        for t in 1..c.len().saturating_sub(1) {
            let (a, b, d) = (vertices[c[0]] - inner, vertices[c[t]] - inner, vertices[c[t + 1]] - inner);
            let v = a.dot(b.cross(d)) / 6.0;
            volume += v;
            first += v * (a + b + d) / 4.0;
            // a tetrahedron with a corner at the origin: V/20 (sum r r^T + (sum r)(sum r)^T)
            let s = a + b + d;
            let outer = |x: DVec3, y: DVec3| DMat3::from_cols(x * y.x, x * y.y, x * y.z);
            second += (outer(a, a) + outer(b, b) + outer(d, d) + outer(s, s)) * (v / 20.0);
        }
    }
    let centroid_rel = first / volume;
    // about the centroid: less V c c^T
    let cov = second
        - DMat3::from_cols(centroid_rel * centroid_rel.x, centroid_rel * centroid_rel.y, centroid_rel * centroid_rel.z) * volume;
    let trace = cov.x_axis.x + cov.y_axis.y + cov.z_axis.z;
    let inertia = DMat3::from_diagonal(DVec3::splat(trace)) - cov;
    (volume, inner + centroid_rel, inertia)
}

/// The eigenvalues of a symmetric matrix and its eigenvectors as the
/// columns of a rotation-like matrix, by cyclic Jacobi rotations.
fn symmetric_eigen(m: DMat3) -> ([f64; 3], DMat3) {
    let mut a = [m.x_axis.to_array(), m.y_axis.to_array(), m.z_axis.to_array()];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-15 * (a[0][0].abs() + a[1][1].abs() + a[2][2].abs()) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < f64::MIN_POSITIVE {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A' = J^T A J with J the rotation in the (p, q) plane
            for k in 0..3 {
                let (akp, akq) = (a[k][p], a[k][q]);
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    // columns of `v` (stored as rows of the transposed) are the eigenvectors
    let axes = DMat3::from_cols(
        DVec3::new(v[0][0], v[1][0], v[2][0]),
        DVec3::new(v[0][1], v[1][1], v[2][1]),
        DVec3::new(v[0][2], v[1][2], v[2][2]),
    );
    ([a[0][0], a[1][1], a[2][2]], axes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(h: f32) -> Vec<[f32; 3]> {
        (0..8)
            .map(|k| [if k & 1 == 0 { -h } else { h }, if k & 2 == 0 { -h } else { h }, if k & 4 == 0 { -h } else { h }])
            .collect()
    }

    #[test]
    fn a_cube_of_points_is_a_cube() {
        let mut points = cube(0.5);
        // points inside and on faces and edges are not corners
        points.extend([[0.0, 0.0, 0.0], [0.5, 0.1, 0.2], [0.5, 0.5, 0.0], [0.1, -0.2, 0.3]]);
        let hull = Hull::new(&points).unwrap();
        assert_eq!(hull.vertices.len(), 8);
        assert_eq!(hull.faces.len(), 6);
        assert!(hull.faces.iter().all(|f| f.corners.len() == 4 && (f.offset - 0.5).abs() < 1e-12));
        assert!((hull.volume - 1.0).abs() < 1e-12);
        assert!(hull.centroid.length() < 1e-12);
        // a unit cube: I = m (1 + 1) / 12 about each axis, m = 1 per unit density
        let i = hull.inertia;
        for (k, col) in [i.x_axis, i.y_axis, i.z_axis].into_iter().enumerate() {
            for (j, x) in col.to_array().into_iter().enumerate() {
                let want = if j == k { 1.0 / 6.0 } else { 0.0 };
                assert!((x - want).abs() < 1e-12, "I[{k}][{j}] = {x}");
            }
        }
        // every face counter-clockwise seen from outside
        for f in &hull.faces {
            let c: Vec<DVec3> = f.corners.iter().map(|&k| hull.vertices[k]).collect();
            let n = (c[1] - c[0]).cross(c[2] - c[1]);
            assert!(n.dot(f.normal) > 0.0, "{f:?}");
        }
    }

    #[test]
    fn a_tetrahedron_has_the_known_volume_centroid_and_inertia() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let hull = Hull::new(&points).unwrap();
        assert_eq!((hull.vertices.len(), hull.faces.len()), (4, 4));
        assert!((hull.volume - 1.0 / 6.0).abs() < 1e-12);
        assert!((hull.centroid - DVec3::splat(0.25)).length() < 1e-12);
        // the corner tetrahedron of unit legs about its centroid: Ixx = (3/80) m (1 + 1)
        // with m = V; the product of inertia -(integral of xy - V cx cy) = -(1/120 - 1/96)
        let want_diag = 3.0 / 80.0 * (1.0 / 6.0) * 2.0;
        let want_off = 1.0 / 120.0 - (1.0 / 6.0) * 0.0625;
        let i = hull.inertia;
        assert!((i.x_axis.x - want_diag).abs() < 1e-12, "{i:?}");
        assert!((i.x_axis.y + want_off).abs() < 1e-12, "{i:?}");
        let (moments, turn) = hull.principal();
        // the tensor is R diag(moments) R^T
        let r = DMat3::from_quat(turn);
        let back = r * DMat3::from_diagonal(DVec3::from_array(moments)) * r.transpose();
        for (a, b) in [(back.x_axis, i.x_axis), (back.y_axis, i.y_axis), (back.z_axis, i.z_axis)] {
            assert!((a - b).length() < 1e-12, "{back:?} against {i:?}");
        }
    }

    #[test]
    fn points_that_make_no_solid_are_refused() {
        let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.5, 0.0, 0.5]];
        assert!(Hull::new(&flat).unwrap_err().contains("span a volume"));
        assert!(Hull::new(&flat[..3]).unwrap_err().contains("4 to 64"));
        assert!(Hull::new(&vec![[0.0; 3]; 65]).unwrap_err().contains("4 to 64"));
        let mut bad = cube(1.0);
        bad[3] = [f32::NAN, 0.0, 0.0];
        assert!(Hull::new(&bad).unwrap_err().contains("point 3"));
    }

    #[test]
    fn a_random_cloud_makes_a_closed_hull_holding_every_point() {
        let mut seed = 0x1234_5678_9abc_def0_u64;
        let mut f = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        let mut built = 0;
        for k in 0..400 {
            // some clouds on a coarse grid, nudged by less than the tolerance:
            // many points nearly on common planes
            let grid = |v: f32| if k % 2 == 1 { (v * 4.0).round() / 4.0 + v * 1e-7 } else { v };
            let points: Vec<[f32; 3]> = (0..32).map(|_| [grid(f()), grid(0.5 * f()), grid(2.0 * f())]).collect();
            // a random cloud always makes a hull; one nearly on a grid may be
            // refused, but is never left open
            let Ok(hull) = Hull::new(&points) else {
                assert!(k % 2 == 1, "a random cloud made no hull");
                continue;
            };
            built += 1;
            // every point behind every face
            for p in &points {
                let p = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                assert!(hull.faces.iter().all(|face| face.normal.dot(p) - face.offset <= 1e-3));
            }
            // closed: Euler's V - E + F = 2, each edge shared by two faces
            let mut edges = std::collections::HashMap::new();
            for face in &hull.faces {
                for k in 0..face.corners.len() {
                    let (a, b) = (face.corners[k], face.corners[(k + 1) % face.corners.len()]);
                    *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                }
            }
            assert!(edges.values().all(|&n| n == 2));
            assert_eq!(hull.vertices.len() + hull.faces.len(), edges.len() + 2);
            // the centroid inside
            assert!(hull.faces.iter().all(|face| face.normal.dot(hull.centroid) < face.offset));
        }
        assert!(built >= 200, "{built} of 400 clouds made a hull");
    }
}
