//! Over- and under-constraint diagnosis at the reference configuration, in
//! the spirit of the SVD method of the thesis's exact-constraint design
//! (§4.1.3): which closed loops of elements are over-constrained, in which
//! direction, and which coordinates nothing determines.
//!
//! The constraint Jacobian C has one row per equation the scene states:
//! every rigid or prescribed deformation ε = D(x) (thesis (6.4)), the
//! Euler-parameter normalizations λᵀλ − 1 = 0 of the orientation nodes, and a
//! unit row per fixed or prescribed nodal coordinate; its columns are all
//! nodal coordinates. Rows are scaled to unit norm.
//!
//! - **Over-constraints** are the left null space of C: combinations yᵀC = 0
//!   of equations, i.e. self-stress states (generalized stresses that are in
//!   equilibrium without any load, the constraint forces a redundant
//!   equation would carry). Their number is m − rank C. Each is reported as
//!   the equations with their weights y (largest |y| = 1), the loop of
//!   elements they belong to, the deformation kind that carries most of
//!   Σ y², and the direction of the self-stress's nodal forces and moments
//!   (relative to the plane of the loop when it is planar).
//! - **Under-constraints** exist only when the scene lists its degrees of
//!   freedom explicitly (`dofs: Explicit`); otherwise every motion the
//!   equations leave free becomes a degree of freedom. They are the null
//!   space of the equations plus the chosen deformation DOFs, restricted to
//!   the coordinates that are neither fixed, prescribed nor chosen as DOFs:
//!   motions nothing determines. Each is reported as the coordinates of its
//!   mode with weights.
//!
//! The null-space bases are localized (made sparse) as described in
//! `constraints/null.rs`: rows private to one column are peeled off,
//! the rest splits into connected blocks with one dense SVD each, and each
//! block's basis is brought to reduced row echelon form and then pairwise
//! reduced in support, so that independent loops come out separately.
//!
//! Unlike [`Scene::build`], the diagnosis does not need the roles to be
//! assignable: it is what to run when the build reports an over- or
//! under-constrained mechanism.

mod describe;
mod null;

use crate::build::assemble;
use crate::mechanism::Coordinate;
use crate::roles::{mark, resolve, sparse_jacobian, R};
use crate::scene::{DofChoice, Scene};
use crate::ModelError;
use std::path::Path;

pub use describe::Direction;

/// An equation or coordinate with its weight in a null vector.
#[derive(Clone, Debug, PartialEq)]
pub struct Weighted {
    /// Its name: a deformation (`ELEMENT.NAME`), an Euler-parameter
    /// normalization (`NODE.normalization`) or a nodal coordinate
    /// (`NODE.x`, with ` (fixed)` or ` (prescribed)` for an equation).
    pub name: String,
    /// Its weight; the largest |weight| of a vector is 1.
    pub weight: f64,
}

/// One over-constraint: a self-stress of the constraint equations.
#[derive(Clone, Debug, PartialEq)]
pub struct OverConstraint {
    /// The equations taking part, by decreasing |weight|.
    pub equations: Vec<Weighted>,
    /// The closed loop: declared element ids (chains once) in the order a
    /// walk along shared nodes meets them, `ground` where it runs through the
    /// supports.
    pub loop_elements: Vec<String>,
    /// The deformation kind (element type and deformation name) with the
    /// largest share of Σ weight², and that share (0…1).
    pub dominant: (String, f64),
    /// The direction of the self-stress.
    pub direction: Direction,
}

/// One under-constraint: a motion that nothing determines.
#[derive(Clone, Debug, PartialEq)]
pub struct UnderConstraint {
    /// The coordinates of the mode, by decreasing |weight|.
    pub coordinates: Vec<Weighted>,
}

/// The diagnosis of a scene's constraints ([`Scene::diagnose_constraints`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintDiagnosis {
    /// Equations: rigid and prescribed deformations, normalizations, fixed
    /// and prescribed coordinates.
    pub n_equations: usize,
    /// Nodal coordinates.
    pub n_coordinates: usize,
    /// Motions the equations leave free (n_coordinates − rank C): the
    /// mobility, the number of degrees of freedom an automatic choice takes.
    pub mobility: usize,
    /// The over-constraints (m − rank C of them).
    pub over: Vec<OverConstraint>,
    /// The under-constraints (only with explicit degrees of freedom).
    pub under: Vec<UnderConstraint>,
    /// Whether under-constraints were looked for (explicit DOFs).
    pub under_checked: bool,
    /// Equations left after peeling (those in closed loops).
    pub core_equations: usize,
    /// Rows of the largest block decomposed by a dense SVD.
    pub largest_block: usize,
}

impl ConstraintDiagnosis {
    /// No over- and no under-constraints.
    pub fn is_exact(&self) -> bool {
        self.over.is_empty() && self.under.is_empty()
    }
}

/// An equation of the constraint Jacobian.
#[derive(Clone, Copy, Debug)]
enum Equation {
    Def(usize),
    Coord(usize, R),
}

fn unit_rows(rows: Vec<Vec<(usize, f64)>>) -> Vec<Vec<(usize, f64)>> {
    rows.into_iter()
        .map(|r| {
            let n = r.iter().map(|(_, v)| v * v).sum::<f64>().sqrt();
            if n > 0.0 {
                r.into_iter().map(|(c, v)| (c, v / n)).collect()
            } else {
                vec![]
            }
        })
        .collect()
}

impl Scene {
    /// Diagnoses the scene's over- and under-constraints at the reference
    /// configuration (see the [module documentation](crate::constraints)
    /// for the method). Works on scenes whose build fails for being over- or
    /// under-constrained; other errors of the scene (unknown ids, bad
    /// values) are reported as by [`Scene::build`].
    pub fn diagnose_constraints(
        &self,
        base_dir: Option<&Path>,
    ) -> Result<ConstraintDiagnosis, ModelError> {
        let (mut mech, roles_scene) = assemble(self, base_dir, &[], &mut |_| {})?;
        let (xr, er) = mark(&roles_scene, &mut mech)?;
        let jac = sparse_jacobian(&mech, &mech.x0);
        let n_x = mech.n_x();
        let mut eqs: Vec<Equation> = (0..mech.n_eps())
            .filter(|j| matches!(er[*j], R::Rigid | R::Input))
            .map(Equation::Def)
            .collect();
        eqs.extend(
            (0..n_x)
                .filter(|i| matches!(xr[*i], R::Fixed | R::Input))
                .map(|i| Equation::Coord(i, xr[i])),
        );
        let rows = unit_rows(
            eqs.iter()
                .map(|e| match e {
                    Equation::Def(j) => jac[*j].clone(),
                    Equation::Coord(i, _) => vec![(*i, 1.0)],
                })
                .collect(),
        );
        // the units of localization: an equation's element, or its coordinate
        let owner = describe::owners(&mech);
        let units: Vec<usize> = eqs
            .iter()
            .map(|e| match e {
                Equation::Def(j) => owner[*j],
                Equation::Coord(i, _) => mech.elements.len() + i,
            })
            .collect();
        let ns = null::left_null_space(&rows, &units, n_x, "the constraint Jacobian")?;
        let rank = eqs.len() - ns.vectors.len();
        let over = ns
            .vectors
            .iter()
            .map(|v| describe::over_constraint(&mech, &eqs, &rows, v))
            .collect();
        let (under, under_checked) = match &roles_scene.dofs {
            DofChoice::Explicit(list) => {
                let chosen: Vec<Coordinate> = roles_scene
                    .dofs_first
                    .iter()
                    .chain(list)
                    .map(|s| resolve(&mech, s, "dofs"))
                    .collect::<Result<Vec<_>, _>>()?
                    .into_iter()
                    .flatten()
                    .collect();
                (under_constraints(&mech, &xr, &eqs, &jac, &chosen)?, true)
            }
            _ => (vec![], false),
        };
        Ok(ConstraintDiagnosis {
            n_equations: eqs.len(),
            n_coordinates: n_x,
            mobility: n_x - rank,
            over,
            under,
            under_checked,
            core_equations: ns.core_rows,
            largest_block: ns.largest_block,
        })
    }
}

/// The null space of the equations and the chosen deformation DOFs over the
/// coordinates that are free and not chosen: the left null space of its
/// transpose.
fn under_constraints(
    mech: &crate::Mechanism,
    xr: &[R],
    eqs: &[Equation],
    jac: &[Vec<(usize, f64)>],
    chosen: &[Coordinate],
) -> Result<Vec<UnderConstraint>, ModelError> {
    let mut col = vec![usize::MAX; mech.n_x()];
    let mut cols = vec![];
    for i in 0..mech.n_x() {
        if xr[i] == R::Free && !chosen.contains(&Coordinate::Node(i)) {
            col[i] = cols.len();
            cols.push(i);
        }
    }
    let defs = eqs
        .iter()
        .filter_map(|e| match e {
            Equation::Def(j) => Some(*j),
            Equation::Coord(..) => None,
        })
        .chain(chosen.iter().filter_map(|c| match c {
            Coordinate::Def(j) => Some(*j),
            Coordinate::Node(_) => None,
        }));
    let rows = unit_rows(
        defs.map(|j| {
            jac[j]
                .iter()
                .filter(|(i, _)| col[*i] != usize::MAX)
                .map(|(i, v)| (col[*i], *v))
                .collect()
        })
        .collect(),
    );
    let mut transposed: Vec<Vec<(usize, f64)>> = vec![vec![]; cols.len()];
    for (r, row) in rows.iter().enumerate() {
        for (c, v) in row {
            transposed[*c].push((r, *v));
        }
    }
    let units: Vec<usize> = (0..transposed.len()).collect();
    let ns = null::left_null_space(
        &transposed,
        &units,
        rows.len(),
        "the Jacobian on the undetermined coordinates",
    )?;
    Ok(ns
        .vectors
        .into_iter()
        .map(|v| UnderConstraint {
            coordinates: v
                .into_iter()
                .map(|(c, w)| Weighted {
                    name: mech.x_names[cols[c]].clone(),
                    weight: w,
                })
                .collect(),
        })
        .collect())
}
