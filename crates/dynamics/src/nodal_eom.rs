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
//! The system is solved by its Schur complement. Mx (of the free nodal
//! coordinates, in skyline storage after a reverse Cuthill–McKee ordering)
//! is factorized as it is first. Only when that factorization fails (Mx is
//! singular along an Euler parameter vector that carries no rotational
//! inertia, or for massless coordinates) is it augmented by CᵀWC (W > 0
//! diagonal) and the first right-hand side by CᵀW(second), which leaves the
//! solution unchanged because Cẍ equals the second right-hand side (the
//! augmented Lagrangian form), and factorized again; `augmented` records
//! which happened. Mx + CᵀWC is positive definite whenever
//! Mq = F,qᵀMxF,q is, and has the sparsity of Mx. Then S = C(Mx + CᵀWC)⁻¹Cᵀ = YᵀY with Y = L⁻¹Cᵀ, μ from S, and ẍ
//! by one more back substitution. For a chain of n bodies the work is
//! O(n b²) for the factor (b the band) and O(n n_c²) for S, against
//! O(n_x n_q²) for forming F,q and Mq.
//!
//! Gravity enters as the uniform acceleration field −g: the consistent
//! gravity force of every element is Mx(x) ẋ_g (see `Element::gravity_force`),
//! so f − Mx(ẍ_u − ẋ_g) − h needs one inertia-force call per element and no
//! separate gravity pass.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{matmul as tri_matmul, BlockStructure};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use flexmb_kinematics::Kinematics;
use flexmb_linalg::skyline::{reverse_cuthill_mckee, Skyline};
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

/// How a nodal coordinate enters the unknowns.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Unknown {
    /// Fixed or prescribed: its acceleration is known.
    Known,
    /// Its own unknown (a position, a planar angle, a mode amplitude, an
    /// Euler parameter of a node that is not eliminated).
    Plain(usize),
    /// Euler parameter `m` of eliminated orientation `o`.
    Quat { o: usize, m: usize },
}

/// An orientation whose normalization is eliminated node-wise: its four
/// Euler parameters all move freely and λ̈ = Λᵀ(λ) a + λ β with three
/// unknowns a (Λλ = 0, ΛΛᵀ = |λ|² I), β from the normalization's
/// acceleration equation g λ̈ = −D,λλ\[λ̇, λ̇\] (g ∥ λᵀ, so g Λᵀ = 0).
#[derive(Clone, Copy, Debug)]
struct Orientation {
    lambda: [usize; 4],
    /// The normalization element and its deformation.
    element: usize,
    eps: usize,
    /// Its three unknowns (after ordering; not necessarily adjacent).
    slots: [usize; 3],
}

/// How a local coordinate of an element enters its local unknowns.
#[derive(Clone, Copy, Debug)]
enum Local {
    Known,
    Plain(usize),
    /// Local unknowns l..l+3 of orientation o, Euler parameter m.
    Quat {
        l: usize,
        o: usize,
        m: usize,
    },
}

/// Set-up (ordering, profile, row lists) and work memory of the nodal solve.
pub(crate) struct NodalEom {
    unknown: Vec<Unknown>,
    orientations: Vec<Orientation>,
    /// Λᵀ(λ) (4 × 3, row-major) and β of each eliminated orientation.
    basis: Vec<([[f64; 3]; 4], f64)>,
    /// Per element: its unknowns (slots, local order) and how each local
    /// coordinate maps onto them.
    slots: Vec<Vec<usize>>,
    locals: Vec<Vec<Local>>,
    /// Per element: the lower pairs of its unknowns as (l1 · n_l + l2,
    /// profile position).
    pairs: Vec<Vec<(usize, usize)>>,
    /// Per element with co-rotational spatial inertia, how its mass enters
    /// in the reduced coordinates; `None`: T_eᵀ M_e T_e by `transform_mass`.
    reduced_mass: Vec<Option<ReducedMass>>,
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
    mass: Skyline,
    /// The assembled mass before its factorization (for a retry with CᵀWC).
    mass_copy: Skyline,
    /// Cᵀ, then Y = L⁻¹Cᵀ: row-major (unknowns × rows).
    y: Vec<f64>,
    s: Mat<f64>,
    s_mem: MemBuffer,
    /// Right-hand sides over the unknowns and the rows.
    r: Vec<f64>,
    c: Vec<f64>,
    mu: Vec<f64>,
    /// Nodal accelerations (known parts first) and forces over all nodal coordinates.
    xdd: Vec<f64>,
    fx: Vec<f64>,
    neg_sigma: Vec<f64>,
    /// Element work: mass matrix, its transform to the local unknowns, one row of C.
    me: Vec<f64>,
    mt: Vec<f64>,
    ae: Vec<f64>,
    ge: Vec<f64>,
    /// Whether the last evaluation needed the augmentation CᵀWC.
    pub augmented: bool,
}

/// An element's mass matrix in the coordinates with eliminated orientations,
/// as `Element::mass_matrix_with_bases` returns it.
struct ReducedMass {
    /// The eliminated orientation held by each orientation slot (`None`:
    /// kept as four coordinates).
    orient: Vec<Option<usize>>,
    /// The lower pairs of the element's unknowns as (position in the
    /// row-major reduced matrix, profile position).
    pairs: Vec<(usize, usize)>,
}

/// The reduced-mass layout of element `e`, if it has co-rotational spatial
/// inertia (at most two orientation slots).
fn reduced_mass_layout(
    e: &flexmb_model::MechElement,
    x0: &[f64],
    unknown: &[Unknown],
    orientations: &[Orientation],
    mass: &Skyline,
) -> Option<ReducedMass> {
    use flexmb_element::Slot;
    let n_orient = e
        .element
        .slots()
        .iter()
        .filter(|s| **s == Slot::Orientation)
        .count();
    let xl: Vec<f64> = e.x_index.iter().map(|i| x0[*i]).collect();
    let mut probe = vec![0.0; xl.len() * xl.len()];
    if n_orient > 2
        || e.element
            .mass_matrix_with_bases(&xl, &vec![None; n_orient], &mut probe)
            .is_none()
    {
        return None;
    }
    let mut orient = vec![];
    // (unknown, reduced index) of the element's unknowns
    let mut um: Vec<(usize, usize)> = vec![];
    let (mut c, mut r) = (0, 0);
    for sl in e.element.slots() {
        let idx = &e.x_index[c..c + sl.len()];
        c += sl.len();
        if *sl == Slot::Orientation {
            if let Unknown::Quat { o, .. } = unknown[idx[0]] {
                if idx
                    .iter()
                    .enumerate()
                    .all(|(m, i)| unknown[*i] == Unknown::Quat { o, m })
                {
                    orient.push(Some(o));
                    um.extend(
                        orientations[o]
                            .slots
                            .iter()
                            .enumerate()
                            .map(|(k, s)| (*s, r + k)),
                    );
                    r += 3;
                    continue;
                }
            }
            orient.push(None);
        }
        for i in idx {
            match unknown[*i] {
                Unknown::Known => {}
                Unknown::Plain(s) => um.push((s, r)),
                // an eliminated orientation's parameters in another layout
                Unknown::Quat { .. } => return None,
            }
            r += 1;
        }
    }
    let mut pairs = vec![];
    for &(s1, r1) in &um {
        for &(s2, r2) in &um {
            if s2 <= s1 {
                pairs.push((r1 * r + r2, mass.position(s1, s2)));
            }
        }
    }
    Some(ReducedMass { orient, pairs })
}

impl NodalEom {
    pub fn new(mech: &Mechanism) -> Self {
        let n_x = mech.n_x();
        let free = |i: usize| matches!(mech.x_roles[i], XRole::Dof(_) | XRole::Dependent(_));
        let is_row = |j: usize| matches!(mech.e_roles[j], ERole::Rigid | ERole::Input(_));
        // orientations whose normalization is eliminated; numbering of the
        // unknowns before ordering: plain coordinates one each, orientations three
        let mut unknown = vec![Unknown::Known; n_x];
        let mut orientations = vec![];
        let mut n_u = 0;
        for (ei, e) in mech.elements.iter().enumerate() {
            let j = e.eps_offset;
            if e.element.is_normalization()
                && e.x_index.len() == 4
                && mech.e_roles[j] == ERole::Rigid
                && e.x_index.iter().all(|i| free(*i))
                && e.x_index.iter().all(|i| unknown[*i] == Unknown::Known)
            {
                let o = orientations.len();
                for (m, i) in e.x_index.iter().enumerate() {
                    unknown[*i] = Unknown::Quat { o, m };
                }
                orientations.push(Orientation {
                    lambda: [e.x_index[0], e.x_index[1], e.x_index[2], e.x_index[3]],
                    element: ei,
                    eps: j,
                    slots: [n_u, n_u + 1, n_u + 2],
                });
                n_u += 3;
            }
        }
        for (i, u) in unknown.iter_mut().enumerate() {
            if *u == Unknown::Known && free(i) {
                *u = Unknown::Plain(n_u);
                n_u += 1;
            }
        }
        let mut is_eliminated = vec![false; mech.elements.len()];
        for o in &orientations {
            is_eliminated[o.element] = true;
        }
        let eliminated = |ei: usize| is_eliminated[ei];
        let element_unknowns =
            |unknown: &[Unknown], orientations: &[Orientation], e: &flexmb_model::MechElement| {
                let mut us = vec![];
                for i in &e.x_index {
                    match unknown[*i] {
                        Unknown::Known => {}
                        Unknown::Plain(s) => us.push(s),
                        Unknown::Quat { o, .. } => us.extend(orientations[o].slots),
                    }
                }
                us.sort_unstable();
                us.dedup();
                us
            };
        // an element couples its unknowns in Mx or in CᵀWC
        let coupling = |ei: usize, e: &flexmb_model::MechElement| {
            !eliminated(ei)
                && (e.element.has_inertia()
                    || (0..e.element.n_eps()).any(|a| is_row(e.eps_offset + a)))
        };
        let mut adj = vec![vec![]; n_u];
        for (ei, e) in mech.elements.iter().enumerate() {
            if !coupling(ei, e) {
                continue;
            }
            let us = element_unknowns(&unknown, &orientations, e);
            for &a in &us {
                adj[a].extend(us.iter().copied().filter(|b| *b != a));
            }
        }
        for o in &orientations {
            for a in o.slots {
                adj[a].extend(o.slots.iter().copied().filter(|b| *b != a));
            }
        }
        for a in &mut adj {
            a.sort_unstable();
            a.dedup();
        }
        // renumber by reverse Cuthill–McKee
        let perm = reverse_cuthill_mckee(&adj);
        let mut pos = vec![0; n_u];
        for (new, old) in perm.iter().enumerate() {
            pos[*old] = new;
        }
        for u in &mut unknown {
            if let Unknown::Plain(s) = u {
                *s = pos[*s];
            }
        }
        let couplings = adj
            .iter()
            .enumerate()
            .flat_map(|(a, ns)| ns.iter().map(move |b| (a, *b)));
        let mass = Skyline::new(n_u, couplings.map(|(a, b)| (pos[a], pos[b])));
        for o in &mut orientations {
            o.slots = o.slots.map(|s| pos[s]);
        }
        let mut slots = vec![];
        let mut locals = vec![];
        let mut pairs = vec![];
        for (ei, e) in mech.elements.iter().enumerate() {
            let mut sl: Vec<usize> = vec![];
            let mut lo = vec![];
            for i in &e.x_index {
                lo.push(match unknown[*i] {
                    Unknown::Known => Local::Known,
                    Unknown::Plain(s) => {
                        sl.push(s);
                        Local::Plain(sl.len() - 1)
                    }
                    Unknown::Quat { o, m } => {
                        let l = match sl.iter().position(|s| *s == orientations[o].slots[0]) {
                            Some(l) => l,
                            None => {
                                sl.extend(orientations[o].slots);
                                sl.len() - 3
                            }
                        };
                        Local::Quat { l, o, m }
                    }
                });
            }
            let mut p = vec![];
            if coupling(ei, e) {
                let nl = sl.len();
                for (l1, s1) in sl.iter().enumerate() {
                    for (l2, s2) in sl.iter().enumerate() {
                        if s2 <= s1 {
                            p.push((l1 * nl + l2, mass.position(*s1, *s2)));
                        }
                    }
                }
            }
            slots.push(sl);
            locals.push(lo);
            pairs.push(p);
        }
        let reduced_mass = mech
            .elements
            .iter()
            .map(|e| reduced_mass_layout(e, &mech.x0, &unknown, &orientations, &mass))
            .collect();
        // constraint rows with at least one unknown, by first unknown
        let mut rows: Vec<(usize, (usize, usize, usize))> = vec![];
        let mut owner = vec![(0, 0); mech.n_eps()];
        for (ei, e) in mech.elements.iter().enumerate() {
            let first = slots[ei].iter().min().copied();
            for a in 0..e.element.n_eps() {
                let j = e.eps_offset + a;
                owner[j] = (ei, a);
                if let (true, false, Some(f)) = (is_row(j), eliminated(ei), first) {
                    rows.push((f, (ei, a, j)));
                }
            }
        }
        rows.sort_by_key(|(f, (_, _, j))| (*f, *j));
        let active = (0..n_u)
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
        let l_max = slots.iter().map(|s| s.len()).max().unwrap_or(0);
        let n_k = rows.len();
        Self {
            unknown,
            basis: vec![([[0.0; 3]; 4], 0.0); orientations.len()],
            orientations,
            slots,
            locals,
            pairs,
            reduced_mass,
            rows,
            active,
            dof_defs,
            dof_nodes,
            input_of_x,
            gravity_axis,
            mass_copy: mass.clone(),
            mass,
            y: vec![0.0; n_u * n_k],
            s: Mat::zeros(n_k, n_k),
            s_mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                n_k,
                Par::Seq,
                Default::default(),
            )),
            r: vec![0.0; n_u],
            c: vec![0.0; n_k],
            mu: vec![0.0; n_k],
            xdd: vec![0.0; n_x],
            fx: vec![0.0; n_x],
            neg_sigma: vec![0.0; mech.n_eps()],
            me: vec![0.0; n_max * n_max],
            mt: vec![0.0; n_max * l_max],
            ae: vec![0.0; l_max * l_max],
            ge: vec![0.0; l_max],
            augmented: false,
        }
    }

    /// Unknowns, stored entries of the profile of the mass matrix and
    /// constraint rows.
    #[cfg(test)]
    pub fn size(&self) -> (usize, usize, usize) {
        (self.mass.n(), self.mass.nnz(), self.rows.len())
    }

    /// Row `a` of element `ei`'s Jacobian times its local transform, T_eᵀ gᵀ,
    /// into `ge` (local unknowns); returns g · ẍ_known over the coordinates
    /// that are not unknowns (and the λβ parts of eliminated orientations).
    fn transformed_row(&mut self, kin: &Kinematics, mech: &Mechanism, ei: usize, a: usize) -> f64 {
        let e = &mech.elements[ei];
        let nx = e.x_index.len();
        let g = &kin.element_jacobian(ei)[a * nx..(a + 1) * nx];
        let nl = self.slots[ei].len();
        self.ge[..nl].fill(0.0);
        let mut known = 0.0;
        for (c, (loc, gi)) in self.locals[ei].iter().zip(&e.x_index).enumerate() {
            match *loc {
                Local::Known => known += g[c] * self.xdd[*gi],
                Local::Plain(l) => self.ge[l] += g[c],
                Local::Quat { l, o, m } => {
                    known += g[c] * self.xdd[*gi];
                    let p = &self.basis[o].0[m];
                    for k in 0..3 {
                        self.ge[l + k] += g[c] * p[k];
                    }
                }
            }
        }
        known
    }

    /// q̈ at the state of `kin` (configuration, velocities and convective
    /// terms D,xx\[ẋ, ẋ\] evaluated), for nodal forces `f` without gravity,
    /// stresses `sigma` (zero on rigid and prescribed deformations) and
    /// gravity `g` (already scaled), at time `t`.
    #[allow(clippy::too_many_arguments)]
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
        // known accelerations: prescribed inputs (fixed coordinates: zero),
        // and λβ of the eliminated orientations
        for (i, k) in self.input_of_x.iter().enumerate() {
            self.xdd[i] = match k {
                Some(k) => mech.inputs[*k].function.eval(t).2,
                None => 0.0,
            };
        }
        for (o, b) in self.orientations.iter().zip(&mut self.basis) {
            let l = o.lambda.map(|i| x[i]);
            let lm = flexmb_rotation::generic::lambda_mat(&l);
            for m in 0..4 {
                b.0[m] = [lm[0][m], lm[1][m], lm[2][m]];
            }
            let gn = kin.element_jacobian(o.element);
            let gl: f64 = (0..4).map(|m| gn[m] * l[m]).sum();
            b.1 = -dxx[o.eps] / gl;
            for m in 0..4 {
                self.xdd[o.lambda[m]] = l[m] * b.1;
            }
        }
        // nodal forces f − h − Mx(ẍ_u − ẋ_g) − D,xᵀσ, and T_eᵀ M_e T_e
        self.fx.copy_from_slice(f);
        for (ns, s) in self.neg_sigma.iter_mut().zip(sigma) {
            *ns = -s;
        }
        kin.add_deformation_forces(&self.neg_sigma, &mut self.fx);
        self.mass.clear();
        let mut xl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut vl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut al = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        let mut fl = [0.0; flexmb_element::MAX_ELEMENT_COORDS];
        for (ei, e) in mech.elements.iter().enumerate() {
            if !e.element.has_inertia() {
                continue;
            }
            let n = e.x_index.len();
            e.gather(x, &mut xl[..n]);
            e.gather(xd, &mut vl[..n]);
            for (k, gi) in e.x_index.iter().enumerate() {
                al[k] = self.xdd[*gi] - self.gravity_axis[*gi].zip(g).map_or(0.0, |(a, g)| g[a]);
            }
            e.element
                .inertia_force(&xl[..n], &vl[..n], &al[..n], &mut fl[..n]);
            e.scatter_add(&fl[..n], -1.0, &mut self.fx);
            if let Some(rm) = &self.reduced_mass[ei] {
                let mut bases = [None; 2];
                for (b, o) in bases.iter_mut().zip(&rm.orient) {
                    *b = o.map(|o| self.basis[o].0);
                }
                e.element
                    .mass_matrix_with_bases(&xl[..n], &bases[..rm.orient.len()], &mut self.me);
                for &(m, p) in &rm.pairs {
                    self.mass.add_at(p, self.me[m]);
                }
            } else {
                e.element.mass_matrix(&xl[..n], &mut self.me[..n * n]);
                self.transform_mass(ei, n);
                for &(m, p) in &self.pairs[ei] {
                    self.mass.add_at(p, self.ae[m]);
                }
            }
        }
        // r = T ᵀ fx
        self.r.fill(0.0);
        for (i, u) in self.unknown.iter().enumerate() {
            match *u {
                Unknown::Known => {}
                Unknown::Plain(s) => self.r[s] += self.fx[i],
                Unknown::Quat { o, m } => {
                    let (sl, p) = (self.orientations[o].slots, self.basis[o].0[m]);
                    for k in 0..3 {
                        self.r[sl[k]] += p[k] * self.fx[i];
                    }
                }
            }
        }
        // constraint rows: Cᵀ into Y and the acceleration right-hand side
        let n_k = self.rows.len();
        self.y.fill(0.0);
        for k in 0..n_k {
            let (ei, a, j) = self.rows[k];
            let known = self.transformed_row(kin, mech, ei, a);
            self.c[k] = match mech.e_roles[j] {
                ERole::Input(u) => mech.inputs[u].function.eval(t).2,
                _ => 0.0,
            } - dxx[j]
                - known;
            for (l, s) in self.slots[ei].iter().enumerate() {
                self.y[s * n_k + k] = self.ge[l];
            }
        }
        // factorize; if the mass alone is not definite (massless motions),
        // again with the augmentation CᵀWC
        self.mass_copy.clone_from(&self.mass);
        self.augmented = false;
        if self.mass.factor().is_err() {
            self.augmented = true;
            self.mass.clone_from(&self.mass_copy);
            self.augment(kin, mech);
            self.mass
                .factor()
                .map_err(|_| NodalFailure::MassNotDefinite)?;
        }
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
        // ẍ = T a + ẍ_known
        for (i, u) in self.unknown.iter().enumerate() {
            match *u {
                Unknown::Known => {}
                Unknown::Plain(s) => self.xdd[i] = self.r[s],
                Unknown::Quat { o, m } => {
                    let (sl, p) = (self.orientations[o].slots, self.basis[o].0[m]);
                    self.xdd[i] +=
                        p[0] * self.r[sl[0]] + p[1] * self.r[sl[1]] + p[2] * self.r[sl[2]];
                }
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

    /// ae = T_eᵀ M_e T_e (local unknowns) from `me` (n × n, row-major); T_e
    /// has one entry per plain coordinate and three per Euler parameter.
    fn transform_mass(&mut self, ei: usize, n: usize) {
        let nl = self.slots[ei].len();
        let locals = &self.locals[ei];
        // mt = M_e T_e (n × nl)
        self.mt[..n * nl].fill(0.0);
        for (c, loc) in locals.iter().enumerate() {
            match *loc {
                Local::Known => {}
                Local::Plain(l) => {
                    for r in 0..n {
                        self.mt[r * nl + l] += self.me[r * n + c];
                    }
                }
                Local::Quat { l, o, m } => {
                    let p = self.basis[o].0[m];
                    for r in 0..n {
                        let v = self.me[r * n + c];
                        let row = &mut self.mt[r * nl + l..r * nl + l + 3];
                        for k in 0..3 {
                            row[k] += v * p[k];
                        }
                    }
                }
            }
        }
        // ae = T_eᵀ mt
        self.ae[..nl * nl].fill(0.0);
        for (c, loc) in locals.iter().enumerate() {
            let mrow = &self.mt[c * nl..(c + 1) * nl];
            match *loc {
                Local::Known => {}
                Local::Plain(l) => {
                    for (a, m) in self.ae[l * nl..(l + 1) * nl].iter_mut().zip(mrow) {
                        *a += m;
                    }
                }
                Local::Quat { l, o, m } => {
                    let p = self.basis[o].0[m];
                    for k in 0..3 {
                        for (a, v) in self.ae[(l + k) * nl..(l + k + 1) * nl].iter_mut().zip(mrow) {
                            *a += p[k] * v;
                        }
                    }
                }
            }
        }
    }

    /// Adds CᵀWC to the mass and CᵀWc to r, with weights that make each
    /// row's term of the size of the mass it touches (the augmented
    /// Lagrangian form: the solution does not change).
    fn augment(&mut self, kin: &Kinematics, mech: &Mechanism) {
        let n = self.mass.n().max(1);
        let mean_diag = (0..self.mass.n()).map(|i| self.mass.get(i, i)).sum::<f64>() / n as f64;
        for k in 0..self.rows.len() {
            let (ei, a, _) = self.rows[k];
            self.transformed_row(kin, mech, ei, a);
            let nl = self.slots[ei].len();
            let (mut g2, mut gm) = (0.0, 0.0);
            for (l, s) in self.slots[ei].iter().enumerate() {
                g2 += self.ge[l] * self.ge[l];
                gm += self.ge[l] * self.ge[l] * self.mass.get(*s, *s);
            }
            let w = if gm > 0.0 {
                gm / (g2 * g2)
            } else {
                mean_diag / g2
            };
            let w = if w.is_finite() && w > 0.0 { w } else { 1.0 };
            for (l, s) in self.slots[ei].iter().enumerate() {
                self.r[*s] += w * self.ge[l] * self.c[k];
            }
            for &(m, p) in &self.pairs[ei] {
                self.mass.add_at(p, w * self.ge[m / nl] * self.ge[m % nl]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{fixture, Dynamics};
    use flexmb_model::Scene;
    use std::sync::Arc;

    /// q̈ by the nodal solve and by the projection (D.10) at a perturbed,
    /// moving state; returns the largest difference relative to max |q̈|.
    fn compare(scene: Scene, t: f64, augmented: &mut Vec<bool>) -> f64 {
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
        augmented.push(dy.nodal.augmented);
        dy.accelerations_by_projection(t, &q, &qd, &mut reference)
            .unwrap();
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        fast.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs() / scale)
            .fold(0.0, f64::max)
    }

    /// The spatial guidance: every orientation is eliminated (11 nodes, 33
    /// unknowns of 77 coordinates left 66), only the 22 rigid deformations
    /// remain as rows, and all 12 beams take their mass in the reduced
    /// coordinates directly.
    #[test]
    fn the_spatial_guidance_eliminates_every_normalization() {
        let mech = Arc::new(
            fixture("straight_guidance_spatial.ron")
                .build(None)
                .unwrap(),
        );
        let dy = Dynamics::new(mech.clone());
        assert_eq!(dy.nodal.orientations.len(), 11);
        assert_eq!(dy.nodal.size().0, 66);
        assert_eq!(dy.nodal.size().2, 22);
        let beams = mech
            .elements
            .iter()
            .filter(|e| e.element.has_inertia())
            .count();
        assert_eq!(beams, 12);
        assert_eq!(
            dy.nodal.reduced_mass.iter().filter(|r| r.is_some()).count(),
            beams
        );
    }

    /// A rigid massless link on a PD-controlled hinge with a tip mass under
    /// gravity: the nodal mass matrix has no inertia on the angles, so the
    /// solve needs the augmentation CᵀWC, and q̈ is the pendulum's
    /// θ̈ = −(m g L cos θ + kp θ + kd θ̇)/(m L²).
    #[test]
    fn a_mass_matrix_without_rotary_inertia_is_augmented_and_exact() {
        let (m, l, g, kp, kd): (f64, f64, f64, f64, f64) = (2.0, 0.5, 9.81, 40.0, 3.0);
        let scene = Scene::from_ron_str(&format!(
            r#"(
            dimension: Planar,
            gravity: Some([0.0, -{g}]),
            materials: {{ "s": (e: 2.0e11, rho: 0.0) }},
            sections: {{ "b": Circle(d: 0.01) }},
            nodes: [ (id: "G", at: [0.0, 0.0]), (id: "O", position_of: Some("G")), (id: "T", at: [{l}, 0.0]) ],
            elements: [
                (id: "hinge", type: Hinge(nodes: ("G", "O"))),
                (id: "link", type: Beam((nodes: ("O", "T"), material: "s", section: "b", mass: false))),
                (id: "mass", type: PointMass(node: "T", mass: {m})),
            ],
            fixed: [ Node("G") ],
            rigid: [ Def("link", "*") ],
            controllers: [ (on: Def("hinge", "rotation"), kp: {kp}, kd: {kd}, reference: Constant(0.0)) ],
        )"#
        ))
        .unwrap();
        let mut dy = Dynamics::new(Arc::new(scene.build(None).unwrap()));
        assert_eq!(dy.n_q(), 1);
        let (theta, omega) = (0.3, 0.7);
        let mut qdd = [0.0];
        assert!(dy
            .nodal_accelerations(0.0, &[theta], &[omega], &mut qdd)
            .unwrap());
        assert!(dy.nodal.augmented, "Mx alone is singular here");
        let expected = -(m * g * l * theta.cos() + kp * theta + kd * omega) / (m * l * l);
        assert!(
            (qdd[0] - expected).abs() <= 1e-11 * expected.abs(),
            "{} vs {expected}",
            qdd[0]
        );
    }

    #[test]
    fn nodal_solve_gives_the_accelerations_of_the_projection() {
        let mut augmented = vec![];
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
            let d = compare(fixture(name), 0.37, &mut augmented);
            assert!(d < 1e-8, "{name}: relative difference {d:.2e}");
        }
        // beams with rotary inertia: the mass alone is definite once the
        // normalizations are eliminated (no augmentation in the guidances)
        assert_eq!(&augmented[..2], &[false, false]);
    }

    /// DOPRI5 at tight tolerances through the response of the planar and the
    /// spatial guidance to the force pulse: the trajectories with q̈ from the
    /// nodal solve and from the projection agree to the integration
    /// tolerance (the two differ by rounding, which steers the step sizes).
    #[test]
    fn trajectories_of_the_nodal_solve_and_the_projection_agree() {
        use flexmb_ode::{Dopri5, Dopri5Options, OdeSystem, Output, RhsError, Tolerance};
        struct Rhs(Dynamics, bool);
        impl OdeSystem for Rhs {
            fn dim(&self) -> usize {
                2 * self.0.n_q()
            }
            fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), RhsError> {
                let n = self.0.n_q();
                let (q, qd) = y.split_at(n);
                let (head, tail) = dy.split_at_mut(n);
                head.copy_from_slice(qd);
                let r = if self.1 {
                    self.0.accelerations(t, q, qd, tail)
                } else {
                    self.0.accelerations_by_projection(t, q, qd, tail)
                };
                r.map_err(|e| RhsError::recoverable(e.to_string()))
            }
        }
        for (name, t_end) in [
            ("straight_guidance_planar.ron", 0.02),
            ("straight_guidance_spatial.ron", 0.004),
        ] {
            let mech = Arc::new(fixture(name).build(None).unwrap());
            let n = mech.n_dof();
            let mut y0 = mech.q0();
            y0.extend(vec![0.0; n]);
            let times: Vec<f64> = (1..=4).map(|i| t_end * i as f64 / 4.0).collect();
            let run = |nodal: bool| {
                let o = Dopri5Options {
                    rtol: 1e-9,
                    atol: Tolerance::Scalar(1e-12),
                    ..Default::default()
                };
                Dopri5::new(o)
                    .solve(
                        &mut Rhs(Dynamics::new(mech.clone()), nodal),
                        0.0,
                        &y0,
                        t_end,
                        &Output::Times(times.clone()),
                    )
                    .unwrap()
            };
            let (a, b) = (run(true), run(false));
            let mut scale = 0.0f64;
            let mut worst = 0.0f64;
            for i in 0..a.len() {
                for k in 0..n {
                    scale = scale.max(b.y(i)[k].abs());
                    worst = worst.max((a.y(i)[k] - b.y(i)[k]).abs());
                }
            }
            assert!(scale > 0.0);
            assert!(
                worst <= 1e-7 * scale,
                "{name}: q differs by {:.2e} of max |q|",
                worst / scale
            );
        }
    }
}
