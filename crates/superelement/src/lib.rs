//! # flexmb-superelement
//!
//! The superelement builder of flexmb: from a linear FE model of a part (node
//! coordinates, sparse stiffness K and mass M over translational DOFs) to the
//! data of a non-linear two-node superelement ([`flexmb_element::LinearSuperelement`]):
//! S̄ (thesis (3.8)), M̄ (3.11), l0 and R0, by a Craig–Bampton reduction in the
//! element frame with rigid interfaces, warping and other deformable-interface
//! modes, compatible modes of adjoining parts (§3.4.2) and fixed-interface
//! normal modes.
//!
//! * [`FeModel`]: the linear FE model (faer CSC matrices, a DOF map that allows
//!   absent DOFs); [`NodeSelection`] picks interface nodes by label or geometry.
//! * [`build`] with [`BuildSettings`] → [`BuildResult`] (the superelement data,
//!   the full reduced stiffness, the mode shapes, a report).
//! * [`solid`]: a built-in 20-node hexahedral solid FE and structured mesher,
//!   [`parts`]: the thesis's parts (prismatic bar, short sheet flexure, unbalanced
//!   shaft, thin-walled box arm) and [`parts::axis_bar`], a bar along any
//!   global axis for scenes whose parts do not all run along x.
//! * [`readers`]: Matrix Market and CalculiX (`.sti`, `.mas`, `.dof`, `.inp`),
//!   with truncated files and mismatched equation counts named;
//!   [`consistency`]: the checks of K, M, the DOF list and the mesh against
//!   each other that [`build`] runs first; [`geometry`]: volume moments of
//!   solid elements for its rigid-body check.
//! * [`abaqus`] (`*MATRIX OUTPUT` in all three formats with the `.inp`
//!   deck) and [`ansys`] (APDL Math MMF or `HBMAT` [`harwell_boeing`] with
//!   the DOF mapping and nodal coordinates): the exports of the commercial
//!   packages, with [`units`] for exports not in SI;
//! * [`spec`]: a RON specification and [`build_from_spec`], the function behind
//!   `flexmb build-superelement SPEC.ron`;
//! * [`mesh_file`]: gmsh `.msh`/`.geo` and `.inp` meshes for the built-in FE
//!   (now every solid kind, [`solid::SolidMesh`]) or a CalculiX run;
//!   [`interface`]: where an interface lies (centroid, plane, the check of
//!   warping modes); [`from_mesh`]: one command from a mesh to a
//!   superelement (`flexmb build-superelement --mesh`).
//!
//! The sparse Cholesky factorization, the shift-invert eigensolver and the
//! dense generalized eigensolver are those of `flexmb-linalg`
//! ([`flexmb_linalg::SparseCholesky`], [`flexmb_linalg::lowest_eigenpairs`],
//! [`flexmb_linalg::generalized_eigen`]); their failures arrive as
//! [`Error::Eigen`] and [`Error::Cholesky`].
//!
//! ```
//! use flexmb_element::{Element, Material, VelocityTransform};
//! use flexmb_superelement::{build, parts};
//! let steel = Material { e: 2.1e11, g: 8.0e10, rho: 7800.0 };
//! // a 100 mm bar, 10 mm × 10 mm, 4 × 1 × 1 twenty-node hexahedra
//! let part = parts::prismatic_bar(0.1, 0.01, 0.01, [4, 1, 1], steel).unwrap();
//! let model = part.mesh.assemble("bar").unwrap();
//! let se = build(&model, &part.settings).unwrap();
//! // the elongation stiffness S̄[0][0] is close to EA / l (rigid ends add a few per cent)
//! let ea_l = 2.1e11 * 1e-4 / 0.1;
//! assert!((se.data.s_bar[0][0] / ea_l - 1.0).abs() < 0.03);
//! // the data feed the non-linear superelement directly
//! let element = Element::superelement(&se.data, VelocityTransform::B3).unwrap();
//! assert_eq!(element.n_eps(), 6);
//! ```
#![warn(missing_docs)]
// Index loops mirror the formulas (blocks of K, M, T); negated comparisons are
// deliberate: they also reject NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod abaqus;
pub mod ansys;
mod builder;
pub mod consistency;
mod error;
pub mod from_mesh;
pub mod geometry;
pub mod harwell_boeing;
pub mod interface;
pub mod mesh_file;
mod model;
pub mod parts;
pub mod readers;
pub mod recovery;
mod reduction;
pub mod solid;
pub mod spec;
mod symmetric;
pub mod units;
pub mod wave_speed;

pub use builder::{
    build, compatible_interface_pattern, fixed_interface_eigenvalues_dense,
    fixed_interface_eigenvalues_sparse, full_model_clamped_free_frequencies,
    prescribed_rigid_solve, BuildReport, BuildResult, BuildSettings, InterfaceMode,
    InterfacePattern, PointMass, RigidBodyProperties, RigidMotion, VE_INDEX,
};
pub use error::Error;
pub use mesh_file::{MeshFile, MeshMaterial};
pub use model::{DofMap, FeModel, NodeSelection, NodeSet, ReferenceMass, SolidElements, Sources};
pub use spec::{build_from_spec, build_loaded, BuildOutput, FeSolver, ModelSource, Spec};
