//! The equations of motion solved in nodal coordinates with multipliers for
//! the constraint deformations: the same q̈ as (D.10), without F,q or Mq.
//!
//! With U the nodal coordinates that move freely (degrees of freedom and
//! dependent ones), C = D_c,x the Jacobian of the rigid and prescribed
//! deformations (Euler-parameter normalizations included) with respect to
//! them, and ẍ_u the known accelerations (prescribed inputs),
//!
//! ```text
//! [ Mx  Cᵀ ] [ ẍ ]   [ f − h − Mx ẍ_u − D,xᵀσ            ]
//! [ C   0  ] [ μ ] = [ ë_c − D_c,xx[ẋ, ẋ] − D_c,x ẍ_u     ]
//! ```
//!
//! (thesis (D.2) before the projection on F,q). Premultiplying the first row
//! by F,qᵀ, whose columns span the null space of C, removes μ and gives
//! (D.10) exactly: F,qᵀMxF,q q̈ = F,qᵀ(f − Mx ẍ0 − h) − E,qᵀσ. The degree-of-
//! freedom deformations carry their stresses σ like every other non-rigid
//! deformation, and q̈ follows from ẍ: a nodal DOF is ẍᵢ itself, a
//! deformation DOF is ε̈ = D,x ẍ + D,xx\[ẋ, ẋ\] (5.8b).
//!
//! The system is solved by its Schur complement. Mx is singular along each
//! Euler parameter vector (and for massless coordinates), so it is first
//! augmented by CᵀWC (W > 0 diagonal) and the first right-hand side by
//! CᵀW(second), which leaves the solution unchanged because Cẍ equals the
//! second right-hand side (the augmented Lagrangian form). Mx + CᵀWC is
//! positive definite whenever Mq = F,qᵀMxF,q is, and has the sparsity of
//! Mx: it is factorized as a skyline after a reverse Cuthill–McKee
//! ordering. Then S = C(Mx + CᵀWC)⁻¹Cᵀ = YᵀY with Y = L⁻¹Cᵀ, μ from S, and ẍ
//! by one more back substitution. For a chain of n bodies the work is
//! O(n b²) for the factor (b the band) and O(n n_c²) for S, against
//! O(n_x n_q²) for forming F,q and Mq.
//!
//! Gravity enters as the uniform acceleration field −g: the consistent
//! gravity force of every element is Mx(x) ẋ_g (see `Element::gravity_force`),
//! so f − Mx(ẍ_u − ẋ_g) − h needs one inertia-force call per element and no
//! separate gravity pass.

use crate::skyline::{reverse_cuthill_mckee, Skyline};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{matmul as tri_matmul, BlockStructure};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use flexmb_kinematics::Kinematics;
use flexmb_model::{Coordinate, ERole, Mechanism, XRole};

/// Why the nodal solve could not produce q̈ (the caller then falls back to
/// (D.10), whose errors name the coordinates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum NodalFailure {
    /// Mx + CᵀWC is not positive definite: some motion has no inertia.
    MassNotDefinite,
    /// The Schur complement is singular: dependent constraint rows.
    ConstraintsDependent,
}

/// Set-up (ordering, profile, row lists) and work memory of the nodal solve.
pub(crate) struct NodalEom {
    /// Position of each nodal coordinate among the unknowns (ordered), if unknown.
    slot: Vec<Option<usize>>,
    /// Constraint rows as (element, local deformation, global deformation),
    /// sorted by their first unknown.
    rows: Vec<(usize, usize, usize)>,
    /// Number of rows whose first unknown is at or before each unknown.
    active: Vec<usize>,
    /// Deformation degrees of freedom: (index in q, element, local deformation).
    dof_defs: Vec<(usize, usize, usize)>,
    /// Nodal degrees of freedom: (index in q, nodal coordinate).
    dof_nodes: Vec<(usize, usize)>,
    /// Input index of each nodal coordinate that is prescribed.
    input_of_x: Vec<Option<usize>>,
    /// The gravity component acting on each nodal coordinate (positions only).
    gravity_axis: Vec<Option<usize>>,
    /// Per element: its unknowns as (local index, slot), and the lower
    /// pairs of them as (row-major local index a·n + b, profile position).
    unknowns: Vec<Vec<(usize, usize)>>,
    pairs: Vec<Vec<(usize, usize)>>,
    mass: Skyline,
    /// Cᵀ, then Y = L⁻¹Cᵀ: row-major (unknowns × rows).
    y: Vec<f64>,
    s: Mat<f64>,
    s_mem: MemBuffer,
    /// Right-hand sides over the unknowns and the rows.
    r: Vec<f64>,
    c: Vec<f64>,
    mu: Vec<f64>,
    weights: Vec<f64>,
    /// Nodal accelerations and forces over all nodal coordinates.
    xdd: Vec<f64>,
    fx: Vec<f64>,
    neg_sigma: Vec<f64>,
    me: Vec<f64>,
}

impl NodalEom {
    pub fn new(mech: &Mechanism) -> Self {
        let n_x = mech.n_x();
        let unknown: Vec<usize> = (0..n_x)
            .filter(|&i| matches!(mech.x_roles[i], XRole::Dof(_) | XRole::Dependent(_)))
            .collect();
        let mut local = vec![None; n_x];
        for (k, &i) in unknown.iter().enumerate() {
            local[i] = Some(k);
        }
        // every element couples its unknowns in Mx or in CᵀWC
        let is_row = |j: usize| matches!(mech.e_roles[j], ERole::Rigid | ERole::Input(_));
        let mut adj = vec![vec![]; unknown.len()];
        for e in &mech.elements {
            let has_row = (0..e.element.n_eps()).any(|a| is_row(e.eps_offset + a));
            if !e.element.has_inertia() && !has_row {
                continue;
            }
            let us: Vec<usize> = e.x_index.iter().filter_map(|i| local[*i]).collect();
            for &a in &us {
                for &b in &us {
                    if a != b {
                        adj[a].push(b);
                    }
                }
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        let perm = reverse_cuthill_mckee(&adj);
        let mut slot = vec![None; n_x];
        for (new, old) in perm.iter().enumerate() {
            slot[unknown[*old]] = Some(new);
        }
        let mut pos = vec![0; unknown.len()];
        for (new, old) in perm.iter().enumerate() {
            pos[*old] = new;
        }
        let couplings = adj
            .iter()
            .enumerate()
            .flat_map(|(a, ns)| ns.iter().map(move |b| (a, *b)));
        let mass = Skyline::new(unknown.len(), couplings.map(|(a, b)| (pos[a], pos[b])));
        let unknowns: Vec<Vec<(usize, usize)>> = mech
            .elements
            .iter()
            .map(|e| {
                e.x_index
                    .iter()
                    .enumerate()
                    .filter_map(|(a, i)| slot[*i].map(|s| (a, s)))
                    .collect()
            })
            .collect();
        let pairs = mech
            .elements
            .iter()
            .zip(&unknowns)
            .map(|(e, us)| {
                let has_row = (0..e.element.n_eps()).any(|a| is_row(e.eps_offset + a));
                if !e.element.has_inertia() && !has_row {
                    return vec![];
                }
                let n = e.x_index.len();
                let mut p = vec![];
                for &(a, sa) in us {
                    for &(b, sb) in us {
                        if sb <= sa {
                            p.push((a * n + b, mass.position(sa, sb)));
                        }
                    }
                }
                p
            })
            .collect();
        // constraint rows with at least one unknown, by first unknown
        let mut rows: Vec<(usize, (usize, usize, usize))> = vec![];
        let mut owner = vec![(0, 0); mech.n_eps()];
        for (ei, e) in mech.elements.iter().enumerate() {
            let first = e.x_index.iter().filter_map(|i| slot[*i]).min();
            for a in 0..e.element.n_eps() {
                let j = e.eps_offset + a;
                owner[j] = (ei, a);
                if let (true, Some(f)) = (is_row(j), first) {
                    rows.push((f, (ei, a, j)));
                }
            }
        }
        rows.sort_by_key(|(f, (_, _, j))| (*f, *j));
        let active = (0..unknown.len())
            .map(|i| rows.partition_point(|(f, _)| *f <= i))
            .collect();
        let rows: Vec<(usize, usize, usize)> = rows.into_iter().map(|(_, r)| r).collect();
        let mut dof_defs = vec![];
        let mut dof_nodes = vec![];
        for (k, c) in mech.dofs.iter().enumerate() {
            match c {
                Coordinate::Node(i) => dof_nodes.push((k, *i)),
                Coordinate::Def(j) => dof_defs.push((k, owner[*j].0, owner[*j].1)),
            }
        }
        let mut input_of_x = vec![None; n_x];
        for (i, r) in mech.x_roles.iter().enumerate() {
            if let XRole::Input(k) = r {
                input_of_x[i] = Some(*k);
            }
        }
        let mut gravity_axis = vec![None; n_x];
        for n in &mech.nodes {
            for (axis, i) in n.position.iter().enumerate() {
                gravity_axis[*i] = Some(axis);
            }
        }
        let n_max = mech
            .elements
            .iter()
            .map(|e| e.x_index.len())
            .max()
            .unwrap_or(0);
        let (n_a, n_k) = (unknown.len(), rows.len());
        Self {
            slot,
            rows,
            active,
            dof_defs,
            dof_nodes,
            input_of_x,
            gravity_axis,
            unknowns,
            pairs,
            mass,
            y: vec![0.0; n_a * n_k],
            s: Mat::zeros(n_k, n_k),
            s_mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                n_k,
                Par::Seq,
                Default::default(),
            )),
            r: vec![0.0; n_a],
            c: vec![0.0; n_k],
            mu: vec![0.0; n_k],
            weights: vec![0.0; n_k],
            xdd: vec![0.0; n_x],
            fx: vec![0.0; n_x],
            neg_sigma: vec![0.0; mech.n_eps()],
            me: vec![0.0; n_max * n_max],
        }
    }

    /// Stored entries of the profile of Mx + CᵀWC and the number of
    /// constraint rows (for reports).
    pub fn size(&self) -> (usize, usize, usize) {
        (self.mass.n(), self.mass.nnz(), self.rows.len())
    }

    /// q̈ at the state of `kin` (configuration, velocities and convective
    /// terms D,xx\[ẋ, ẋ\] evaluated), for nodal forces `f` without gravity,
    /// stresses `sigma` (zero on rigid and prescribed deformations) and
    /// gravity `g` (already scaled), at time `t`.
    pub fn accelerations(
        &mut self,
        kin: &Kinematics,
        mech: &Mechanism,
        t: f64,
        f: &[f64],
        sigma: &[f64],
        g: Option<[f64; 3]>,
        qdd: &mut [f64],
    ) -> Result<(), NodalFailure> {
        let (x, xd) = (kin.x(), kin.xd());
        let dxx = kin.convective();
        // known accelerations: prescribed inputs (fixed coordinates: zero)
        for (i, k) in self.input_of_x.iter().enumerate() {
            self.xdd[i] = match k {
                Some(k) => mech.inputs[*k].function.eval(t).2,
                None => 0.0,
            };
        }
        // nodal forces f − h − Mx(ẍ_u − ẋ_g) − D,xᵀσ, and Mx on the unknowns
        self.fx.copy_from_slice(f);
        for (ns, s) in self.neg_sigma.iter_mut().zip(sigma) {
            *ns = -s;
        }
        kin.add_deformation_forces(&self.neg_sigma, &mut self.fx);
        self.mass.clear();
        let mut xl = [0.0; 64];
        let mut vl = [0.0; 64];
        let mut al = [0.0; 64];
        let mut fl = [0.0; 64];
        for (ei, e) in mech.elements.iter().enumerate() {
            if !e.element.has_inertia() {
                continue;
            }
            let n = e.x_index.len();
            for (k, gi) in e.x_index.iter().enumerate() {
                xl[k] = x[*gi];
                vl[k] = xd[*gi];
                al[k] = self.xdd[*gi] - self.gravity_axis[*gi].zip(g).map_or(0.0, |(a, g)| g[a]);
            }
            e.element
                .inertia_force(&xl[..n], &vl[..n], &al[..n], &mut fl[..n]);
            for (k, gi) in e.x_index.iter().enumerate() {
                self.fx[*gi] -= fl[k];
            }
            e.element.mass_matrix(&xl[..n], &mut self.me[..n * n]);
            for &(m, p) in &self.pairs[ei] {
                self.mass.add_at(p, self.me[m]);
            }
        }
        for (i, s) in self.slot.iter().enumerate() {
            if let Some(s) = s {
                self.r[*s] = self.fx[i];
            }
        }
        // constraint rows: Cᵀ into Y, the acceleration right-hand side, and
        // the augmentation CᵀWC with weights that make each row's term of the
        // size of the mass it touches
        let n_k = self.rows.len();
        self.y.fill(0.0);
        let mean_diag = {
            let n = self.mass.n().max(1);
            (0..self.mass.n()).map(|i| self.mass.get(i, i)).sum::<f64>() / n as f64
        };
        for (k, &(ei, a, j)) in self.rows.iter().enumerate() {
            let e = &mech.elements[ei];
            let nx = e.x_index.len();
            let jl = &kin.element_jacobian(ei)[a * nx..(a + 1) * nx];
            let mut ck = match mech.e_roles[j] {
                ERole::Input(u) => mech.inputs[u].function.eval(t).2,
                _ => 0.0,
            } - dxx[j];
            let (mut g2, mut gm) = (0.0, 0.0);
            for (c, gi) in e.x_index.iter().enumerate() {
                match self.slot[*gi] {
                    Some(s) => {
                        self.y[s * n_k + k] += jl[c];
                        g2 += jl[c] * jl[c];
                        gm += jl[c] * jl[c] * self.mass.get(s, s);
                    }
                    None => ck -= jl[c] * self.xdd[*gi],
                }
            }
            self.c[k] = ck;
            let w = if gm > 0.0 { gm / (g2 * g2) } else { mean_diag / g2 };
            self.weights[k] = if w.is_finite() { w } else { 0.0 };
        }
        for (k, &(ei, a, _)) in self.rows.iter().enumerate() {
            let nx = mech.elements[ei].x_index.len();
            let jl = &kin.element_jacobian(ei)[a * nx..(a + 1) * nx];
            let w = self.weights[k];
            for &(c, s) in &self.unknowns[ei] {
                self.r[s] += w * jl[c] * self.c[k];
            }
            for &(m, p) in &self.pairs[ei] {
                self.mass.add_at(p, w * jl[m / nx] * jl[m % nx]);
            }
        }
        self.mass
            .factor()
            .map_err(|_| NodalFailure::MassNotDefinite)?;
        // z = L⁻¹ r, Y = L⁻¹ Cᵀ, S = YᵀY, S μ = Yᵀz − c
        self.mass.solve_lower(&mut self.r);
        self.mass.solve_lower_rows(&mut self.y, n_k, &self.active);
        if n_k > 0 {
            let n_a = self.mass.n();
            // Yᵀ is column-major n_k × n_a
            let yt = MatRef::from_column_major_slice(&self.y, n_k, n_a);
            tri_matmul(
                self.s.as_mut(),
                BlockStructure::TriangularLower,
                Accum::Replace,
                yt,
                BlockStructure::Rectangular,
                yt.transpose(),
                BlockStructure::Rectangular,
                1.0,
                Par::Seq,
            );
            for (m, c) in self.mu.iter_mut().zip(&self.c) {
                *m = -c;
            }
            matmul(
                MatMut::from_column_major_slice_mut(&mut self.mu, n_k, 1),
                Accum::Add,
                yt,
                MatRef::from_column_major_slice(&self.r, n_a, 1),
                1.0,
                Par::Seq,
            );
            cholesky_in_place(
                self.s.as_mut(),
                Default::default(),
                Par::Seq,
                MemStack::new(&mut self.s_mem),
                Default::default(),
            )
            .map_err(|_| NodalFailure::ConstraintsDependent)?;
            faer::linalg::cholesky::llt::solve::solve_in_place(
                self.s.as_ref(),
                MatMut::from_column_major_slice_mut(&mut self.mu, n_k, 1),
                Par::Seq,
                MemStack::new(&mut self.s_mem),
            );
            // z − Y μ
            for (i, &p) in self.active.iter().enumerate() {
                let yi = &self.y[i * n_k..i * n_k + p];
                self.r[i] -= yi.iter().zip(&self.mu).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        self.mass.solve_upper(&mut self.r);
        for (i, s) in self.slot.iter().enumerate() {
            if let Some(s) = s {
                self.xdd[i] = self.r[*s];
            }
        }
        // q̈: nodal DOFs directly, deformation DOFs by (5.8b)
        for &(k, i) in &self.dof_nodes {
            qdd[k] = self.xdd[i];
        }
        for &(k, ei, a) in &self.dof_defs {
            let e = &mech.elements[ei];
            let nx = e.x_index.len();
            let jl = &kin.element_jacobian(ei)[a * nx..(a + 1) * nx];
            qdd[k] = dxx[e.eps_offset + a]
                + e.x_index
                    .iter()
                    .zip(jl)
                    .map(|(gi, d)| d * self.xdd[*gi])
                    .sum::<f64>();
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::Dynamics;
    use flexmb_model::Scene;
    use std::path::Path;
    use std::sync::Arc;

    fn fixture(name: &str) -> Scene {
        let p = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/scenes")
            .join(name);
        Scene::load(&p).unwrap()
    }

    /// q̈ by the nodal solve and by the projection (D.10) at a perturbed,
    /// moving state; returns the largest difference relative to max |q̈|.
    fn compare(scene: Scene, t: f64) -> f64 {
        let mech = Arc::new(scene.build(None).unwrap());
        let mut dy = Dynamics::new(mech.clone());
        let n = dy.n_q();
        let q: Vec<f64> = mech
            .q0()
            .iter()
            .enumerate()
            .map(|(i, v)| v + 1e-3 * ((i % 7) as f64 - 3.0))
            .collect();
        let qd: Vec<f64> = (0..n).map(|i| 0.1 * ((i % 5) as f64 - 2.0)).collect();
        let mut fast = vec![0.0; n];
        let mut reference = vec![0.0; n];
        assert!(
            dy.nodal_accelerations(t, &q, &qd, &mut fast).unwrap(),
            "{}: the nodal solve failed",
            mech.name
        );
        dy.accelerations_by_projection(t, &q, &qd, &mut reference)
            .unwrap();
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        fast.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs() / scale)
            .fold(0.0, f64::max)
    }

    #[test]
    fn nodal_solve_gives_the_accelerations_of_the_projection() {
        for name in [
            "straight_guidance_spatial.ron",
            "straight_guidance_planar.ron",
            "manipulator_planar.ron",
            "spin_up_planar.ron",
            "spin_up_spatial_planar.ron",
            "spin_up_universal_joint.ron",
            "tumbling_beam.ron",
            "flexible_pendulum.ron",
        ] {
            let d = compare(fixture(name), 0.37);
            assert!(d < 1e-8, "{name}: relative difference {d:.2e}");
        }
    }
}
