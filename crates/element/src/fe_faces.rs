//! The faces of the solid cells an FE mesh may hold ([`FeCell`], VTK order),
//! and the boundary of a mesh: the faces that belong to one cell only and
//! the edges around them. The superelement builder integrates over the
//! boundary faces (the centroid of an interface), the drawing code draws
//! their edges (a part's outline without its internal edges).
//!
//! Each face lists its corners wound so that their right-hand normal points
//! out of the cell (VTK's convention, from vtkTetra, vtkHexahedron, vtkWedge
//! and their quadratic forms), then, for the quadratic cells, the midside
//! nodes of its edges in the same order: corner i to corner i + 1 has
//! midside node `corners + i`. A face is a 3- or 6-node triangle or a 4- or
//! 8-node quadrilateral.

use crate::FeCell;
use std::collections::HashMap;

const TETRA: [&[usize]; 4] = [&[0, 1, 3], &[1, 2, 3], &[2, 0, 3], &[0, 2, 1]];
const QUADRATIC_TETRA: [&[usize]; 4] = [
    &[0, 1, 3, 4, 8, 7],
    &[1, 2, 3, 5, 9, 8],
    &[2, 0, 3, 6, 7, 9],
    &[0, 2, 1, 6, 5, 4],
];
const HEXAHEDRON: [&[usize]; 6] = [
    &[0, 4, 7, 3],
    &[1, 2, 6, 5],
    &[0, 1, 5, 4],
    &[3, 7, 6, 2],
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
];
const QUADRATIC_HEXAHEDRON: [&[usize]; 6] = [
    &[0, 4, 7, 3, 16, 15, 19, 11],
    &[1, 2, 6, 5, 9, 18, 13, 17],
    &[0, 1, 5, 4, 8, 17, 12, 16],
    &[3, 7, 6, 2, 19, 14, 18, 10],
    &[0, 3, 2, 1, 11, 10, 9, 8],
    &[4, 5, 6, 7, 12, 13, 14, 15],
];
const WEDGE: [&[usize]; 5] = [
    &[0, 1, 2],
    &[3, 5, 4],
    &[0, 3, 4, 1],
    &[1, 4, 5, 2],
    &[2, 5, 3, 0],
];
const QUADRATIC_WEDGE: [&[usize]; 5] = [
    &[0, 1, 2, 6, 7, 8],
    &[3, 5, 4, 11, 10, 9],
    &[0, 3, 4, 1, 12, 9, 13, 6],
    &[1, 4, 5, 2, 13, 10, 14, 7],
    &[2, 5, 3, 0, 14, 11, 12, 8],
];

/// The number of corners of a face with `n` nodes (3 or 6: a triangle, 4 or
/// 8: a quadrilateral).
pub fn face_corners(n: usize) -> usize {
    match n {
        6 => 3,
        8 => 4,
        n => n,
    }
}

impl FeCell {
    /// The faces of a cell of VTK type `vtk_type` as local node indices
    /// (see the module docs); `None` for a type that is not one of
    /// [`FeCell::node_count`]'s.
    pub fn faces(vtk_type: u8) -> Option<&'static [&'static [usize]]> {
        Some(match vtk_type {
            10 => &TETRA,
            24 => &QUADRATIC_TETRA,
            12 => &HEXAHEDRON,
            25 => &QUADRATIC_HEXAHEDRON,
            13 => &WEDGE,
            26 => &QUADRATIC_WEDGE,
            _ => return None,
        })
    }
}

/// The faces of `cells` that belong to one cell only (the surface of the
/// mesh), as global node indices in the face order of [`FeCell::faces`], in
/// the order of the cells. Two faces are the same face when they have the
/// same corners. Cells of an unknown type are passed over.
pub fn boundary_faces(cells: &[FeCell]) -> Vec<Vec<usize>> {
    let mut count: HashMap<Vec<usize>, usize> = HashMap::new();
    let mut all = Vec::new();
    for cell in cells {
        let Some(faces) = FeCell::faces(cell.vtk_type) else {
            continue;
        };
        if cell.nodes.len() != FeCell::node_count(cell.vtk_type).unwrap_or(0) {
            continue;
        }
        for f in faces {
            let nodes: Vec<usize> = f.iter().map(|&i| cell.nodes[i]).collect();
            let mut key = nodes[..face_corners(nodes.len())].to_vec();
            key.sort_unstable();
            *count.entry(key.clone()).or_insert(0) += 1;
            all.push((key, nodes));
        }
    }
    all.into_iter()
        .filter(|(key, _)| count[key] == 1)
        .map(|(_, nodes)| nodes)
        .collect()
}

/// The edges around the boundary faces of `cells`, each once: a straight
/// edge as its two corners `[a, b]`, a quadratic one as `[a, m, b]` with its
/// midside node m. Internal edges (of no boundary face) are not among them.
pub fn boundary_edges(cells: &[FeCell]) -> Vec<Vec<usize>> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for face in boundary_faces(cells) {
        let c = face_corners(face.len());
        for i in 0..c {
            let (a, b) = (face[i], face[(i + 1) % c]);
            if !seen.insert((a.min(b), a.max(b))) {
                continue;
            }
            if face.len() > c {
                out.push(vec![a, face[c + i], b]);
            } else {
                out.push(vec![a, b]);
            }
        }
    }
    out
}

/// The feature edges of `cells` with nodes at `x`: the edges around the
/// boundary faces (as [`boundary_edges`] gives them) where the two
/// boundary faces that meet turn by more than `angle` (radians) against
/// each other, and edges of one boundary face only. A mesh's outline: the
/// edges of a box-shaped part, not the grid lines on its flat faces. The
/// normals are those of the faces' corners (Newell's).
pub fn feature_edges(cells: &[FeCell], x: &[[f64; 3]], angle: f64) -> Vec<Vec<usize>> {
    let faces = boundary_faces(cells);
    let normals: Vec<[f64; 3]> = faces
        .iter()
        .map(|f| {
            let n = newell(f[..face_corners(f.len())].iter().map(|&i| x[i]));
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if l > 0.0 {
                n.map(|v| v / l)
            } else {
                n
            }
        })
        .collect();
    let mut of_edge: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (k, f) in faces.iter().enumerate() {
        let c = face_corners(f.len());
        for i in 0..c {
            let (a, b) = (f[i], f[(i + 1) % c]);
            of_edge.entry((a.min(b), a.max(b))).or_default().push(k);
        }
    }
    let cos = angle.cos();
    boundary_edges(cells)
        .into_iter()
        .filter(|e| {
            let (a, b) = (e[0], e[e.len() - 1]);
            match of_edge[&(a.min(b), a.max(b))].as_slice() {
                [f, g] => {
                    let (n, m) = (normals[*f], normals[*g]);
                    n[0] * m[0] + n[1] * m[1] + n[2] * m[2] < cos
                }
                _ => true,
            }
        })
        .collect()
}

/// Newell's normal of a polygon (twice its area along its right-hand
/// normal, for a planar one).
fn newell(corners: impl Iterator<Item = [f64; 3]> + Clone) -> [f64; 3] {
    let first = corners.clone().next();
    let next = corners.clone().skip(1).chain(first);
    let mut n = [0.0; 3];
    for (a, b) in corners.zip(next) {
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference cells with the nodes at their VTK positions (midside nodes
    /// at the middle of their edges): every face is planar there, points
    /// out of the cell (Newell normal against the centroid), and each of its
    /// midside nodes is the middle of its corners i, i + 1.
    #[test]
    fn faces_point_outwards_and_midside_nodes_sit_on_their_edges() {
        let tet = vec![[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
        let hex = vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
        ];
        // VTK's wedge: the base triangle turns about −z (away from the top)
        let wedge = vec![
            [0., 0., 0.],
            [0., 1., 0.],
            [1., 0., 0.],
            [0., 0., 1.],
            [0., 1., 1.],
            [1., 0., 1.],
        ];
        let with_mids = |c: &Vec<[f64; 3]>, edges: &[(usize, usize)]| {
            let mut x = c.clone();
            for &(a, b) in edges {
                x.push(std::array::from_fn(|d| 0.5 * (c[a][d] + c[b][d])));
            }
            x
        };
        let cases = [
            (10u8, tet.clone()),
            (
                24,
                with_mids(&tet, &[(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]),
            ),
            (12, hex.clone()),
            (
                25,
                with_mids(
                    &hex,
                    &[
                        (0, 1),
                        (1, 2),
                        (2, 3),
                        (3, 0),
                        (4, 5),
                        (5, 6),
                        (6, 7),
                        (7, 4),
                        (0, 4),
                        (1, 5),
                        (2, 6),
                        (3, 7),
                    ],
                ),
            ),
            (13, wedge.clone()),
            (
                26,
                with_mids(
                    &wedge,
                    &[
                        (0, 1),
                        (1, 2),
                        (2, 0),
                        (3, 4),
                        (4, 5),
                        (5, 3),
                        (0, 3),
                        (1, 4),
                        (2, 5),
                    ],
                ),
            ),
        ];
        for (t, x) in cases {
            assert_eq!(FeCell::node_count(t), Some(x.len()));
            let corners = match x.len() {
                4 | 10 => 4,
                6 | 15 => 6,
                _ => 8,
            };
            let centre: [f64; 3] = std::array::from_fn(|d| {
                x[..corners].iter().map(|p| p[d]).sum::<f64>() / corners as f64
            });
            let faces = FeCell::faces(t).unwrap();
            let mut used = vec![false; x.len()];
            for f in faces {
                let c = face_corners(f.len());
                let p: Vec<[f64; 3]> = f[..c].iter().map(|&i| x[i]).collect();
                let n = newell(p.iter().copied());
                let mid: [f64; 3] =
                    std::array::from_fn(|d| p.iter().map(|q| q[d]).sum::<f64>() / c as f64);
                let out: f64 = (0..3).map(|d| n[d] * (mid[d] - centre[d])).sum();
                assert!(out > 0.0, "type {t}: face {f:?} points inwards");
                for i in 0..f.len() - c {
                    let (a, b, m) = (x[f[i]], x[f[(i + 1) % c]], x[f[c + i]]);
                    for d in 0..3 {
                        assert_eq!(
                            m[d],
                            0.5 * (a[d] + b[d]),
                            "type {t}: face {f:?} midside {i}"
                        );
                    }
                }
                for &i in f.iter() {
                    used[i] = true;
                }
            }
            assert!(used.iter().all(|u| *u), "type {t}: a node on no face");
        }
    }

    /// Two hexahedra sharing a face: 10 boundary faces (the shared one
    /// drops out), and the 20 edges of the box they make, each once
    /// (the 4 edges of the shared face are on side faces too).
    #[test]
    fn two_cells_share_a_face_that_is_not_on_the_boundary() {
        let cells = vec![
            FeCell {
                vtk_type: 12,
                nodes: vec![0, 1, 2, 3, 4, 5, 6, 7],
            },
            FeCell {
                vtk_type: 12,
                nodes: vec![1, 8, 9, 2, 5, 10, 11, 6],
            },
        ];
        let faces = boundary_faces(&cells);
        assert_eq!(faces.len(), 10);
        assert!(!faces.iter().any(|f| {
            let mut s = f.clone();
            s.sort_unstable();
            s == vec![1, 2, 5, 6]
        }));
        let edges = boundary_edges(&cells);
        assert_eq!(edges.len(), 20);
        assert!(edges.iter().all(|e| e.len() == 2));
        // the box 2 × 1 × 1: its 12 edges, the 4 along x in two pieces (the
        // 4 around the shared face lie in flat faces, 0° apart), for any
        // angle below 90°
        let x: Vec<[f64; 3]> = vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [1., 1., 0.],
            [0., 1., 0.],
            [0., 0., 1.],
            [1., 0., 1.],
            [1., 1., 1.],
            [0., 1., 1.],
            [2., 0., 0.],
            [2., 1., 0.],
            [2., 0., 1.],
            [2., 1., 1.],
        ];
        for deg in [1.0f64, 30.0, 89.0] {
            let f = feature_edges(&cells, &x, deg.to_radians());
            assert_eq!(f.len(), 16, "{deg}°: {f:?}");
            for e in &f {
                let (a, b) = (x[e[0]], x[e[1]]);
                let along = (0..3).filter(|&d| a[d] != b[d]).count();
                assert_eq!(along, 1);
                assert!(
                    !(a[0] == 1.0 && b[0] == 1.0),
                    "an edge of the shared face: {e:?}"
                );
            }
        }
        assert_eq!(feature_edges(&cells, &x, 91f64.to_radians()).len(), 0);
    }
}
