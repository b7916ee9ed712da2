//! Craig–Bampton reduction of a linear FE model to the linear two-node
//! superelement of thesis §2.2 / §3.2, in the element frame.
//!
//! * Constraint modes V (2.2): the 12 static responses to unit boundary
//!   coordinates µ̄ = (ū^p, φ̄^p, ū^q, φ̄^q) with rigid interfaces
//!   (u_i = u_b + φ_b × (r_i − r_b), an exact constraint transformation), from
//!   one sparse Cholesky factorization of the interior stiffness and 12
//!   right-hand sides.
//! * Warping modes (3.4)–(3.5): the difference between the twist of an interface
//!   about its outward normal with the interface rigid and with the interface
//!   free in the normal direction (other interface clamped).
//! * Other deformable-interface modes: a prescribed interface displacement
//!   pattern (e.g. the compatible pattern of §3.4.2, see
//!   [`crate::compatible_interface_pattern`]) with its rigid-body part removed
//!   (3.37), other interface clamped.
//! * Fixed-interface normal modes: the k lowest of K_II φ = λ M_II φ, by
//!   shift-invert Krylov–Schur on the same factorization.
//! * S̄ = [Ve W]ᵀ K [Ve W] (3.8), Ve = [V7, V10, V5, V11, V6, V12];
//!   M̄ = [V W]ᵀ M [V W] (3.11).

use crate::model::{cross, dot, norm, sub, FeModel, NodeSelection};
use crate::reduction::{Expansion, ExtOps, MassBlock, Problem};
use crate::Error;
use faer::Mat;
use flexmb_element::{
    frame_from_axis, FeCell, FeMesh, LinearSuperelement, ModeKind, Provenance, Side,
};
use flexmb_linalg::{generalized_eigen, lowest_eigenpairs, Definite};
use nalgebra::{DMatrix, Matrix3};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// A displacement pattern of interface nodes, in global coordinates: the node
/// at `points[i]` moves by `displacements[i]`. Nodes are matched by position.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterfacePattern {
    /// Node positions (m).
    pub points: Vec<[f64; 3]>,
    /// Their displacements.
    pub displacements: Vec<[f64; 3]>,
    /// Matching tolerance (m); default 1e-6 × the model's bounding-box diagonal.
    #[serde(default)]
    pub tolerance: Option<f64>,
}

/// A deformable-interface mode from a prescribed pattern.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterfaceMode {
    /// The interface it deforms.
    pub side: Side,
    /// A name (stored in the mode metadata).
    pub name: String,
    /// The pattern; its rigid-body part is removed (thesis (3.37)).
    pub pattern: InterfacePattern,
}

/// A point mass (optionally with rotary inertia) attached rigidly to nodes.
///
/// * one node: the mass follows that node's translation (no rotary inertia, the
///   position must be the node's);
/// * three or more non-collinear nodes not on an interface: a rigid link (the
///   nodes move rigidly with the mass; it stiffens the part like an RBE2);
/// * nodes that all lie on one interface: the mass moves with that boundary node.
///
/// A zero mass gives a pure rigid link (e.g. to tie parts of a mesh).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointMass {
    /// A name for messages.
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Position of its centre of mass (m) (global).
    pub position: [f64; 3],
    /// Inertia tensor about its centre of mass, global axes (kg m²).
    #[serde(default)]
    pub inertia: Option<[[f64; 3]; 3]>,
    /// The nodes it is attached to.
    pub nodes: NodeSelection,
}

fn default_density_range() -> Option<[f64; 2]> {
    Some([10.0, 30000.0])
}

/// What to build.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildSettings {
    /// Boundary node p (m) (global); the element frame's origin.
    pub p: [f64; 3],
    /// Boundary node q (m); the element x axis points from p to q.
    pub q: [f64; 3],
    /// A vector fixing the element y axis (its component normal to x); default
    /// global y, or global z when x is nearly parallel to y.
    #[serde(default)]
    pub y_axis: Option<[f64; 3]>,
    /// Nodes rigidly attached to p.
    pub interface_p: NodeSelection,
    /// Nodes rigidly attached to q.
    pub interface_q: NodeSelection,
    /// Add the warping mode (3.4) of interface p.
    #[serde(default)]
    pub warping_p: bool,
    /// Add the warping mode (3.4) of interface q.
    #[serde(default)]
    pub warping_q: bool,
    /// Further deformable-interface modes from displacement patterns.
    #[serde(default)]
    pub interface_modes: Vec<InterfaceMode>,
    /// Number of fixed-interface normal modes.
    #[serde(default)]
    pub normal_modes: usize,
    /// Point masses and rigid links.
    #[serde(default)]
    pub point_masses: Vec<PointMass>,
    /// Plausible density range (kg/m³) for the units check (total FE mass over
    /// the mesh volume, when the volume is known); `None` disables it.
    #[serde(default = "default_density_range")]
    pub density_range: Option<[f64; 2]>,
    /// Write the FE mesh and its displacement recovery into the superelement
    /// data ([`flexmb_element::FeMesh`], for drawing the part as its mesh);
    /// default true, false for large meshes.
    #[serde(default = "default_fe_mesh")]
    pub fe_mesh: bool,
}

fn default_fe_mesh() -> bool {
    true
}

impl BuildSettings {
    /// Settings with rigid interfaces only (constraint modes).
    pub fn new(
        p: [f64; 3],
        q: [f64; 3],
        interface_p: NodeSelection,
        interface_q: NodeSelection,
    ) -> Self {
        Self {
            p,
            q,
            y_axis: None,
            interface_p,
            interface_q,
            warping_p: false,
            warping_q: false,
            interface_modes: Vec::new(),
            normal_modes: 0,
            point_masses: Vec::new(),
            density_range: default_density_range(),
            fe_mesh: default_fe_mesh(),
        }
    }
}

/// Figures of a build.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildReport {
    /// FE equations.
    pub n_eq: usize,
    /// Free unknowns of the interior problem.
    pub n_interior: usize,
    /// Nodes on interfaces p and q.
    pub interface_nodes: [usize; 2],
    /// Stored entries of the Cholesky factor of the interior stiffness.
    pub factor_nnz: usize,
    /// Fixed-interface normal-mode frequencies (Hz).
    pub normal_frequencies_hz: Vec<f64>,
    /// Total FE mass (without point masses) (kg).
    pub fe_mass: f64,
    /// Wall time of the phases (s): (name, seconds).
    pub timings: Vec<(String, f64)>,
    /// The material inferred from K and M by linear fields (the units check
    /// of the stiffness, [`crate::wave_speed`]); `None` where a node lacks
    /// a translational DOF (and in reports written before it was added).
    #[serde(default)]
    pub material: Option<crate::wave_speed::InferredMaterial>,
    /// Warnings of the build (e.g. an interface a little off normal to the
    /// p → q axis under a warping mode).
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// The result of a build: the superelement data plus what tests and reports need.
#[derive(Clone, Debug)]
pub struct BuildResult {
    /// The linear superelement data.
    pub data: LinearSuperelement,
    /// The full linear stiffness [V W]ᵀ K [V W] over (µ̄, η̄), (12 + k)²; S̄ is its
    /// principal submatrix on (V7, V10, V5, V11, V6, V12, W).
    pub k_full: DMatrix<f64>,
    /// The mode shapes [V W] in the extended space (FE equations, link-master
    /// DOFs, µ̄), one column per coordinate.
    pub shapes: Mat<f64>,
    /// Figures of the build.
    pub report: BuildReport,
    eq_of_node: Vec<[Option<usize>; 3]>,
}

/// Indices of Ve in µ̄ (0-based): V7, V10, V5, V11, V6, V12.
pub const VE_INDEX: [usize; 6] = [6, 9, 4, 10, 5, 11];

impl BuildResult {
    /// The global displacement of node index `node` in column `col` of [V W]
    /// (absent DOFs read as zero).
    pub fn node_displacement(&self, col: usize, node: usize) -> [f64; 3] {
        let e = self.eq_of_node[node];
        std::array::from_fn(|d| e[d].map_or(0.0, |r| self.shapes[(r, col)]))
    }

    /// Eigenfrequencies (Hz) of the superelement with the coordinates `keep`
    /// of (µ̄, η̄) free and all others fixed.
    pub fn frequencies(&self, keep: &[usize]) -> Result<Vec<f64>, Error> {
        let m = self.data.m_bar_matrix();
        let n = keep.len();
        let kk = Mat::<f64>::from_fn(n, n, |i, j| self.k_full[(keep[i], keep[j])]);
        let mm = Mat::<f64>::from_fn(n, n, |i, j| m[(keep[i], keep[j])]);
        let lam = generalized_eigen(kk.as_ref(), mm.as_ref(), n, Definite::Either)?.values;
        Ok(to_hz(&lam))
    }

    /// A readable account of the build, for people (the command line prints
    /// it): the part, its coordinates, the FE model, the rigid-body
    /// properties of M̄, the frequencies and where the time went.
    pub fn summary(&self, name: &str) -> String {
        let r = &self.report;
        let d = &self.data;
        let (kp, kq, kf) = d.mode_counts();
        let rb = RigidBodyProperties::from_m_bar(&d.m_bar_matrix(), d.l0);
        let hz = |f: &[f64]| {
            f.iter()
                .map(|x| format!("{x:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let mut out = format!(
            "superelement '{name}': l0 = {:.6} m, {} coordinates (12 interface, {kp} + {kq} deformable-interface, \
             {kf} fixed-interface normal modes); ε has {} components\n",
            d.l0,
            12 + d.n_modes(),
            6 + d.n_modes()
        );
        out.push_str(&format!(
            "FE model: {} equations, {} interior; interface p {} nodes, q {} nodes; interior stiffness factor {} \
             entries\n",
            r.n_eq, r.n_interior, r.interface_nodes[0], r.interface_nodes[1], r.factor_nnz
        ));
        out.push_str(&format!(
            "rigid body (from M̄, element frame from p): mass {:.6e} kg (FE {:.6e} kg), centre of mass ({:.4e}, \
             {:.4e}, {:.4e}) m, inertia diagonal about it ({:.4e}, {:.4e}, {:.4e}) kg m²\n",
            rb.mass, r.fe_mass, rb.com[0], rb.com[1], rb.com[2], rb.inertia[0][0], rb.inertia[1][1], rb.inertia[2][2]
        ));
        if !r.normal_frequencies_hz.is_empty() {
            out.push_str(&format!(
                "fixed-interface normal modes: {} Hz\n",
                hz(&r.normal_frequencies_hz)
            ));
        }
        if let Ok(f) = self.clamped_free_frequencies() {
            let n = f.len().min(6);
            out.push_str(&format!(
                "clamped at p, free at q: {} Hz (lowest {n})\n",
                hz(&f[..n])
            ));
        }
        out.push_str(
            "checked before the reduction: K, M, the DOF list and the mesh against each other, every node attached to \
             p or q, the density where the volume is known (docs/superelement.md)\n",
        );
        if let Some(m) = &r.material {
            out.push_str(&format!(
                "material from linear-field energies of K and M: wave speed √(E/ρ) = {:.4e} m/s (steel, aluminium \
                 and titanium about 5000), ν = {:.3}, E·V = {:.4e} N m (anisotropy {:.1e})\n",
                m.wave_speed, m.poisson, m.young_times_volume, m.anisotropy
            ));
            if let Some(a) = m.advice() {
                out.push_str(&format!("warning: {a}\n"));
            }
        }
        for w in &r.warnings {
            out.push_str(&format!("warning: {w}\n"));
        }
        let t: Vec<String> = r
            .timings
            .iter()
            .map(|(k, v)| format!("{k} {v:.3} s"))
            .collect();
        out.push_str(&format!("time: {}\n", t.join(", ")));
        out
    }

    /// Clamped-free eigenfrequencies (Hz): µ̄p fixed, interface modes fixed
    /// (rigid interfaces), µ̄q and the normal modes free.
    pub fn clamped_free_frequencies(&self) -> Result<Vec<f64>, Error> {
        let (kp, kq, kf) = self.data.mode_counts();
        let mut keep: Vec<usize> = (6..12).collect();
        keep.extend(12 + kp + kq..12 + kp + kq + kf);
        self.frequencies(&keep)
    }
}

/// Rigid-body properties from M̄ (thesis (3.11)): mass, centre of mass and the
/// inertia tensor about it, in the element frame with origin at p.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidBodyProperties {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass (m), element frame, from p.
    pub com: [f64; 3],
    /// Inertia tensor about the centre of mass (kg m²), element frame.
    pub inertia: [[f64; 3]; 3],
}

impl RigidBodyProperties {
    /// From a 6 × 6 rigid-body mass matrix over (translation, rotation about the origin).
    pub fn from_rigid_mass(m6: &DMatrix<f64>) -> Self {
        let mass = (m6[(0, 0)] + m6[(1, 1)] + m6[(2, 2)]) / 3.0;
        // coupling block C = Mtr: T = ½ (mv² + 2 v·(ω × S) + ωᵀJω), S = m c;
        // v·(ω × S) = vᵀ [S×]ᵀ ω → block (t, r) = −[S×]
        let c = m6.view((0, 3), (3, 3)).into_owned();
        let s = [
            0.5 * (c[(1, 2)] - c[(2, 1)]),
            0.5 * (c[(2, 0)] - c[(0, 2)]),
            0.5 * (c[(0, 1)] - c[(1, 0)]),
        ];
        let com = [s[0] / mass, s[1] / mass, s[2] / mass];
        let jo = m6.view((3, 3), (3, 3)).into_owned();
        let cc = Matrix3::from_fn(|i, j| {
            let d = if i == j { dot(com, com) } else { 0.0 };
            mass * (d - com[i] * com[j])
        });
        let jc = jo - nalgebra::DMatrix::from_fn(3, 3, |i, j| cc[(i, j)]);
        Self {
            mass,
            com,
            inertia: std::array::from_fn(|i| std::array::from_fn(|j| jc[(i, j)])),
        }
    }

    /// From M̄'s 12 × 12 boundary block and l0: the rigid motions v̄p = t,
    /// ω̄p = ω, v̄q = t + ω × (l0 ē_x), ω̄q = ω.
    pub fn from_m_bar(m_bar: &DMatrix<f64>, l0: f64) -> Self {
        let mut g = DMatrix::<f64>::zeros(12, 6);
        for i in 0..3 {
            g[(i, i)] = 1.0;
            g[(3 + i, 3 + i)] = 1.0;
            g[(6 + i, i)] = 1.0;
            g[(9 + i, 3 + i)] = 1.0;
        }
        // ω × (l0 e_x) = (0, l0 ω_z, −l0 ω_y)
        g[(7, 5)] = l0;
        g[(8, 4)] = -l0;
        let mb = m_bar.view((0, 0), (12, 12)).into_owned();
        let m6 = g.transpose() * mb * g;
        Self::from_rigid_mass(&m6)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Interior,
    Iface(usize),
    Slave(usize),
}

#[derive(Clone, Copy, Debug)]
enum Treat {
    /// Prescribed through g (or zero).
    Fixed,
    /// Rigid, with the boundary node's 6 DOFs free.
    RigidFree,
    /// In-plane prescribed through g, normal displacement free (global normal).
    NormalFree([f64; 3]),
}

#[derive(Clone, Copy, Debug)]
enum FreeLabel {
    Eq(usize),
    Master(usize, usize),
    Boundary(usize, usize),
    Normal(usize),
}

struct Link {
    name: String,
    c: [f64; 3],
}

/// Everything resolved from a model and settings.
struct Ctx<'a> {
    model: &'a FeModel,
    r0: [[f64; 3]; 3],
    l0: f64,
    rb: [[f64; 3]; 2],
    iface: [Vec<usize>; 2],
    role: Vec<Role>,
    links: Vec<Link>,
    n_ext: usize,
    ops: ExtOps<'a>,
}

const SIDE: [&str; 2] = ["p", "q"];

fn skew(a: [f64; 3]) -> [[f64; 3]; 3] {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

impl<'a> Ctx<'a> {
    fn new(model: &'a FeModel, s: &BuildSettings) -> Result<Self, Error> {
        let axis = sub(s.q, s.p);
        let l0 = norm(axis);
        if !(l0.is_finite() && l0 > 0.0) {
            return Err(Error::Spec(format!(
                "boundary nodes p = {:?} and q = {:?} coincide",
                s.p, s.q
            )));
        }
        let up = s.y_axis.unwrap_or_else(|| {
            if (axis[1] / l0).abs() > 0.9 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            }
        });
        let r0 = frame_from_axis(&axis, &up)?;
        let n_nodes = model.n_nodes();
        let mut role = vec![Role::Interior; n_nodes];
        let mut iface: [Vec<usize>; 2] = [Vec::new(), Vec::new()];
        for (side, sel) in [&s.interface_p, &s.interface_q].into_iter().enumerate() {
            let nodes = sel
                .resolve(model, &format!("interface {}", SIDE[side]))
                .map_err(|e| Error::interface(SIDE[side], e.to_string()))?;
            for &i in &nodes {
                if let Role::Iface(o) = role[i] {
                    return Err(Error::interface(
                        SIDE[side],
                        format!(
                            "node {} is on both interfaces ({} and {})",
                            model.node_ids()[i],
                            SIDE[o],
                            SIDE[side]
                        ),
                    ));
                }
                role[i] = Role::Iface(side);
                let eqs = model.dofs().node_eqs(i);
                if let Some(d) = (0..3).find(|&d| eqs[d].is_none()) {
                    return Err(Error::interface(
                        SIDE[side],
                        format!(
                            "node {} has no {} DOF (removed by a boundary condition?); interface nodes must be free \
                             in all three directions",
                            model.node_ids()[i],
                            ["ux", "uy", "uz"][d]
                        ),
                    ));
                }
            }
            check_spread(model, &nodes, SIDE[side])?;
            iface[side] = nodes;
        }
        // point masses and links
        let mut links = Vec::new();
        let mut masses = Vec::new();
        let n_eq = model.n_eq();
        struct Pending {
            idx_kind: usize, // 0 = interface side in `side`, 1 = node, 2 = link
            side: usize,
            node: usize,
            link: usize,
            m: f64,
            c: [f64; 3],
            j: [[f64; 3]; 3],
        }
        let mut pending = Vec::new();
        for pm in &s.point_masses {
            let err = |msg: String| Error::PointMass {
                name: pm.name.clone(),
                msg,
            };
            if !(pm.mass.is_finite() && pm.mass >= 0.0) {
                return Err(err(format!(
                    "mass {} must be finite and non-negative",
                    pm.mass
                )));
            }
            let j = pm.inertia.unwrap_or([[0.0; 3]; 3]);
            if j.iter().flatten().any(|v| !v.is_finite()) {
                return Err(err("inertia has non-finite entries".into()));
            }
            let has_j = j.iter().flatten().any(|v| *v != 0.0);
            let nodes = pm
                .nodes
                .resolve(model, &format!("point mass {}", pm.name))?;
            let sides: Vec<Option<usize>> = nodes
                .iter()
                .map(|&i| match role[i] {
                    Role::Iface(s) => Some(s),
                    _ => None,
                })
                .collect();
            let base = Pending {
                idx_kind: 0,
                side: 0,
                node: 0,
                link: 0,
                m: pm.mass,
                c: pm.position,
                j,
            };
            if sides.iter().all(|s| s.is_some()) {
                let s0 = sides[0].unwrap();
                if sides.iter().any(|s| *s != Some(s0)) {
                    return Err(err("its nodes lie on both interfaces".into()));
                }
                pending.push(Pending { side: s0, ..base });
                continue;
            }
            if sides.iter().any(|s| s.is_some()) {
                return Err(err(format!(
                    "some of its {} nodes are on an interface and some are not; attach it either to interface nodes \
                     only or to interior nodes only",
                    nodes.len()
                )));
            }
            for &i in &nodes {
                if let Role::Slave(l) = role[i] {
                    return Err(err(format!(
                        "node {} is already rigidly linked to '{}'",
                        model.node_ids()[i],
                        links.get(l).map_or("?", |x: &Link| x.name.as_str())
                    )));
                }
            }
            if nodes.len() == 1 {
                let i = nodes[0];
                if has_j {
                    return Err(err(
                        "rotary inertia needs a rigid link to at least 3 non-collinear nodes; one node carries no \
                         rotation"
                            .into(),
                    ));
                }
                let d = norm(sub(model.coords()[i], pm.position));
                let size = bbox_diag(model);
                if d > 1e-9 * size {
                    return Err(err(format!(
                        "its position is {d:.3e} m from its only node {}; attach it to at least 3 non-collinear nodes \
                         for an offset mass",
                        model.node_ids()[i]
                    )));
                }
                if model.dofs().node_eqs(i).iter().any(|e| e.is_none()) {
                    return Err(err(format!("node {} lacks a DOF", model.node_ids()[i])));
                }
                pending.push(Pending {
                    idx_kind: 1,
                    node: i,
                    ..base
                });
                continue;
            }
            check_spread(
                model,
                &nodes,
                &format!("rigid link of point mass '{}'", pm.name),
            )
            .map_err(|e| err(e.to_string()))?;
            let l = links.len();
            links.push(Link {
                name: pm.name.clone(),
                c: pm.position,
            });
            for &i in &nodes {
                role[i] = Role::Slave(l);
            }
            pending.push(Pending {
                idx_kind: 2,
                link: l,
                ..base
            });
        }
        let n_link = 6 * links.len();
        let n_ext = n_eq + n_link + 12;
        let rb = [s.p, s.q];
        for pm in pending {
            let jm = pm.j;
            match pm.idx_kind {
                0 => {
                    // T_c over µ̄_side (6): translation at c and rotation, global
                    let d = sub(pm.c, rb[pm.side]);
                    let t = rigid_rows(&r0, d);
                    let mut blk = vec![0.0; 36];
                    for a in 0..6 {
                        for b in 0..6 {
                            let mut v = 0.0;
                            for r in 0..3 {
                                v += pm.m * t[r][a] * t[r][b];
                            }
                            if a >= 3 && b >= 3 {
                                for r in 0..3 {
                                    for q in 0..3 {
                                        v += r0[r][a - 3] * jm[r][q] * r0[q][b - 3];
                                    }
                                }
                            }
                            blk[a * 6 + b] = v;
                        }
                    }
                    let base = n_eq + n_link + 6 * pm.side;
                    masses.push(MassBlock {
                        idx: (base..base + 6).collect(),
                        m: blk,
                    });
                }
                1 => {
                    let e = model.dofs().node_eqs(pm.node);
                    masses.push(MassBlock {
                        idx: e.iter().map(|x| x.unwrap()).collect(),
                        m: vec![pm.m, 0.0, 0.0, 0.0, pm.m, 0.0, 0.0, 0.0, pm.m],
                    });
                }
                _ => {
                    let base = n_eq + 6 * pm.link;
                    let mut blk = vec![0.0; 36];
                    for a in 0..3 {
                        blk[a * 6 + a] = pm.m;
                        for b in 0..3 {
                            blk[(3 + a) * 6 + 3 + b] = jm[a][b];
                        }
                    }
                    masses.push(MassBlock {
                        idx: (base..base + 6).collect(),
                        m: blk,
                    });
                }
            }
        }
        let ops = ExtOps {
            model,
            n_ext,
            masses,
        };
        Ok(Self {
            model,
            r0,
            l0,
            rb,
            iface,
            role,
            links,
            n_ext,
            ops,
        })
    }

    fn n_eq(&self) -> usize {
        self.model.n_eq()
    }
    fn mu_index(&self, k: usize) -> usize {
        self.n_eq() + 6 * self.links.len() + k
    }

    /// The coefficients (3 × 6) of the global displacement of interface node
    /// `node` on side `side` over µ̄_side (element frame).
    fn iface_rows(&self, side: usize, node: usize) -> [[f64; 6]; 3] {
        rigid_rows(&self.r0, sub(self.model.coords()[node], self.rb[side]))
    }

    fn describe(&self, l: FreeLabel) -> String {
        match l {
            FreeLabel::Eq(e) => self.model.describe_eq(e),
            FreeLabel::Master(li, c) => {
                format!("DOF {c} of the rigid link of '{}'", self.links[li].name)
            }
            FreeLabel::Boundary(s, c) => format!("boundary coordinate {c} of node {}", SIDE[s]),
            FreeLabel::Normal(i) => format!(
                "the normal DOF of interface node {}",
                self.model.node_ids()[i]
            ),
        }
    }

    /// Builds the expansion for the given treatment of the two interfaces.
    fn expansion(&self, treat: [Treat; 2]) -> (Expansion, Vec<FreeLabel>) {
        let n_eq = self.n_eq();
        let mut labels = Vec::new();
        let mut free_of_eq = vec![usize::MAX; n_eq];
        for (e, f) in free_of_eq.iter_mut().enumerate() {
            let (nd, _) = self.model.dofs().dof(e);
            if self.role[nd] == Role::Interior {
                *f = labels.len();
                labels.push(FreeLabel::Eq(e));
            }
        }
        let master0 = labels.len();
        for l in 0..self.links.len() {
            for c in 0..6 {
                labels.push(FreeLabel::Master(l, c));
            }
        }
        let mut bfree = [usize::MAX; 2];
        let mut normal_of_node = std::collections::HashMap::new();
        for s in 0..2 {
            match treat[s] {
                Treat::RigidFree => {
                    bfree[s] = labels.len();
                    for c in 0..6 {
                        labels.push(FreeLabel::Boundary(s, c));
                    }
                }
                Treat::NormalFree(_) => {
                    for &i in &self.iface[s] {
                        normal_of_node.insert(i, labels.len());
                        labels.push(FreeLabel::Normal(i));
                    }
                }
                Treat::Fixed => {}
            }
        }
        let mut e = Expansion::with_capacity(self.n_ext);
        let mut row: Vec<(usize, f64)> = Vec::with_capacity(6);
        for (eq, &f) in free_of_eq.iter().enumerate() {
            row.clear();
            let (nd, d) = self.model.dofs().dof(eq);
            let d = d as usize;
            match self.role[nd] {
                Role::Interior => row.push((f, 1.0)),
                Role::Slave(l) => {
                    let m0 = master0 + 6 * l;
                    row.push((m0 + d, 1.0));
                    let sk = skew(sub(self.model.coords()[nd], self.links[l].c));
                    for m in 0..3 {
                        row.push((m0 + 3 + m, -sk[d][m]));
                    }
                }
                Role::Iface(s) => match treat[s] {
                    Treat::Fixed => {}
                    Treat::RigidFree => {
                        let t = self.iface_rows(s, nd);
                        for c in 0..6 {
                            row.push((bfree[s] + c, t[d][c]));
                        }
                    }
                    Treat::NormalFree(n) => row.push((normal_of_node[&nd], n[d])),
                },
            }
            e.push_row(&row);
        }
        for l in 0..self.links.len() {
            for c in 0..6 {
                e.push_row(&[(master0 + 6 * l + c, 1.0)]);
            }
        }
        for s in 0..2 {
            for c in 0..6 {
                if let Treat::RigidFree = treat[s] {
                    e.push_row(&[(bfree[s] + c, 1.0)]);
                } else {
                    e.push_row(&[]);
                }
            }
        }
        (e, labels)
    }

    fn problem(&self, treat: [Treat; 2]) -> Result<Problem, Error> {
        let (e, labels) = self.expansion(treat);
        Problem::new(e, self.model, &|j| self.describe(labels[j]))
    }

    /// Structural checks before any factorization (after the checks of K and M
    /// against each other and the mesh, [`crate::consistency`]): connectivity
    /// to the interfaces and a plausible density. Returns the FE mass.
    fn checks(&self, s: &BuildSettings) -> Result<f64, Error> {
        let model = self.model;
        let k = model.k();
        let n_eq = model.n_eq();
        // connectivity (union–find over nodes, link masters and the two boundary nodes)
        let n_nodes = model.n_nodes();
        let nl = self.links.len();
        let mut uf = UnionFind::new(n_nodes + nl + 2);
        for j in 0..n_eq {
            let nj = model.dofs().dof(j).0;
            for (&i, &v) in k.row_idx_of_col_raw(j).iter().zip(k.val_of_col(j)) {
                if v != 0.0 {
                    uf.union(model.dofs().dof(i).0, nj);
                }
            }
        }
        for (i, r) in self.role.iter().enumerate() {
            match *r {
                Role::Iface(s) => uf.union(i, n_nodes + nl + s),
                Role::Slave(l) => uf.union(i, n_nodes + l),
                Role::Interior => {}
            }
        }
        let rp = uf.find(n_nodes + nl);
        let rq = uf.find(n_nodes + nl + 1);
        let mut detached: Vec<u64> = Vec::new();
        for i in 0..n_nodes {
            if model.dofs().node_eqs(i).iter().any(|e| e.is_some()) {
                let r = uf.find(i);
                if r != rp && r != rq {
                    detached.push(model.node_ids()[i]);
                }
            }
        }
        if !detached.is_empty() {
            let show: Vec<String> = detached.iter().take(8).map(|x| x.to_string()).collect();
            return Err(Error::NotAttached(format!(
                "{} node(s) are not connected to interface p or q through the stiffness, e.g. node(s) {}",
                detached.len(),
                show.join(", ")
            )));
        }
        // units
        let tm = model.translational_mass();
        let mass = (tm[0] + tm[1] + tm[2]) / 3.0;
        if let (Some([lo, hi]), Some(v)) = (s.density_range, model.volume) {
            let rho = mass / v;
            if !(rho >= lo && rho <= hi) {
                return Err(Error::Units(format!(
                    "model {}: the total mass {mass:.4e} kg over the mesh volume {v:.4e} m³ implies a density of \
                     {rho:.4e} kg/m³, outside {lo}..{hi}{}",
                    model.name,
                    units_advice(rho)
                )));
            }
        }
        Ok(mass)
    }
}

/// What to set in a spec when the FE mass over the mesh volume gives the
/// implausible density `rho` (kg/m³): the unit system whose conversion
/// brings a steel-to-foam density back, or a mass scale.
fn units_advice(rho: f64) -> String {
    // a system fits if its density factor mass/length³ brings rho into the
    // range of real solids (foams to tungsten)
    let fits: Vec<&str> = crate::units::UNIT_SYSTEMS
        .iter()
        .filter(|u| u.name != "SI")
        .filter(|u| {
            let r = rho * u.mass / u.length.powi(3);
            (10.0..=30000.0).contains(&r)
        })
        .map(|u| u.name)
        .collect();
    let systems = if fits.is_empty() {
        String::new()
    } else {
        format!(
            " set `units: Some(\"{}\")` in the spec if the files are in those units, or",
            fits.join("\" or \"")
        )
    };
    format!(
        "; the FE files carry no units:{systems} set `mass_scale:` (and `stiffness_scale:`) to convert them to SI; \
         are the coordinates in mm while the matrices are in SI (or the reverse)?"
    )
}

/// Rows of the rigid map u = R0 ū + (R0 φ̄) × d over (ū, φ̄) (element frame).
fn rigid_rows(r0: &[[f64; 3]; 3], d: [f64; 3]) -> [[f64; 6]; 3] {
    let sk = skew(d);
    let mut t = [[0.0; 6]; 3];
    for (r, row) in t.iter_mut().enumerate() {
        for k in 0..3 {
            row[k] = r0[r][k];
            let mut v = 0.0;
            for (m, skm) in sk[r].iter().enumerate() {
                v -= skm * r0[m][k];
            }
            row[3 + k] = v;
        }
    }
    t
}

/// The six rigid motions (name, translation, rotation) with rotations of
/// 1/size rad, so that the displacements of a part of that size are O(1).
pub(crate) fn rigid_motions(size: f64) -> [(&'static str, [f64; 3], [f64; 3]); 6] {
    let r = 1.0 / size;
    [
        ("translation x", [1.0, 0.0, 0.0], [0.0; 3]),
        ("translation y", [0.0, 1.0, 0.0], [0.0; 3]),
        ("translation z", [0.0, 0.0, 1.0], [0.0; 3]),
        ("rotation about x", [0.0; 3], [r, 0.0, 0.0]),
        ("rotation about y", [0.0; 3], [0.0, r, 0.0]),
        ("rotation about z", [0.0; 3], [0.0, 0.0, r]),
    ]
}

pub(crate) fn centroid(pts: &[[f64; 3]]) -> [f64; 3] {
    let n = pts.len().max(1) as f64;
    let mut c = [0.0; 3];
    for p in pts {
        for d in 0..3 {
            c[d] += p[d] / n;
        }
    }
    c
}

pub(crate) fn bbox_diag(model: &FeModel) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in model.coords() {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let d = norm(sub(hi, lo));
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// Errors unless the nodes span a plane: at least 3 nodes, not collinear.
fn check_spread(model: &FeModel, nodes: &[usize], what: &str) -> Result<(), Error> {
    let pts: Vec<[f64; 3]> = nodes.iter().map(|&i| model.coords()[i]).collect();
    if pts.len() < 3 {
        return Err(Error::interface(
            what,
            format!(
                "{} node(s) {:?}; a rigid connection needs at least 3 non-collinear nodes",
                pts.len(),
                nodes
                    .iter()
                    .map(|&i| model.node_ids()[i])
                    .collect::<Vec<_>>()
            ),
        ));
    }
    let c = centroid(&pts);
    let far = pts
        .iter()
        .copied()
        .max_by(|a, b| norm(sub(*a, c)).total_cmp(&norm(sub(*b, c))))
        .unwrap();
    let a = sub(far, c);
    let la = norm(a);
    let best = pts
        .iter()
        .map(|p| norm(cross(a, sub(*p, c))))
        .fold(0.0, f64::max);
    if la == 0.0 || best <= 1e-8 * la * la {
        return Err(Error::interface(
            what,
            format!(
                "its {} nodes are collinear (or coincide); a rigid connection needs at least 3 non-collinear nodes",
                pts.len()
            ),
        ));
    }
    Ok(())
}

struct UnionFind(Vec<usize>);
impl UnionFind {
    fn new(n: usize) -> Self {
        Self((0..n).collect())
    }
    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra] = rb;
        }
    }
}

/// Removes the rigid-body part of an interface displacement (thesis (3.37)):
/// u_d = u − U_r U_rᵀ u with U_r the orthonormalized rigid motions of the nodes.
pub(crate) fn remove_rigid_part(points: &[[f64; 3]], u: &mut [[f64; 3]]) {
    let c = centroid(points);
    let n = points.len();
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let size = points
        .iter()
        .map(|p| norm(sub(*p, c)))
        .fold(0.0, f64::max)
        .max(1e-300);
    for (_, t, th) in rigid_motions(size) {
        let mut v: Vec<f64> = Vec::with_capacity(3 * n);
        for p in points {
            let w = cross(th, sub(*p, c));
            for d in 0..3 {
                v.push(t[d] + w[d]);
            }
        }
        for _ in 0..2 {
            for b in &basis {
                let a: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
                for (x, y) in v.iter_mut().zip(b) {
                    *x -= a * y;
                }
            }
        }
        let nv = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        if nv > 1e-10 {
            basis.push(v.iter().map(|x| x / nv).collect());
        }
    }
    let mut flat: Vec<f64> = u.iter().flatten().copied().collect();
    for _ in 0..2 {
        for b in &basis {
            let a: f64 = flat.iter().zip(b).map(|(x, y)| x * y).sum();
            for (x, y) in flat.iter_mut().zip(b) {
                *x -= a * y;
            }
        }
    }
    for (i, ui) in u.iter_mut().enumerate() {
        *ui = [flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]];
    }
}

fn mode_name(k: usize) -> String {
    const N: [&str; 12] = [
        "ū^p_x", "ū^p_y", "ū^p_z", "φ̄^p_x", "φ̄^p_y", "φ̄^p_z", "ū^q_x", "ū^q_y", "ū^q_z", "φ̄^q_x",
        "φ̄^q_y", "φ̄^q_z",
    ];
    format!("constraint mode V{} ({})", k + 1, N[k])
}

/// Checks that a Gram matrix has full rank; names the first column that
/// depends on the earlier ones.
fn check_independent(g: &DMatrix<f64>, names: &[String], what: &str) -> Result<(), Error> {
    let n = g.nrows();
    for i in 0..n {
        if !(g[(i, i)] > 0.0) {
            return Err(Error::DependentModes(format!(
                "{} has zero {what} ({:e}); it is a zero or rigid-body displacement field",
                names[i],
                g[(i, i)]
            )));
        }
    }
    let s = DMatrix::from_fn(n, n, |i, j| g[(i, j)] / (g[(i, i)] * g[(j, j)]).sqrt());
    // Cholesky in column order; a collapsing pivot names the dependent column
    let mut l = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        let mut d = s[(j, j)];
        for k in 0..j {
            d -= l[(j, k)] * l[(j, k)];
        }
        if !(d > 1e-10) {
            return Err(Error::DependentModes(format!(
                "{} is (nearly) a combination of the modes before it in the {what} matrix (pivot {d:.1e}); remove it or \
                 change its pattern",
                names[j]
            )));
        }
        let dj = d.sqrt();
        l[(j, j)] = dj;
        for i in j + 1..n {
            let mut v = s[(i, j)];
            for k in 0..j {
                v -= l[(i, k)] * l[(j, k)];
            }
            l[(i, j)] = v / dj;
        }
    }
    Ok(())
}

fn to_na(m: &Mat<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    DMatrix::from_fn(n, m.ncols(), |i, j| 0.5 * (m[(i, j)] + m[(j, i)]))
}

/// Builds the linear two-node superelement of `model` (see the module docs).
pub fn build(model: &FeModel, s: &BuildSettings) -> Result<BuildResult, Error> {
    let mut timings = Vec::new();
    let t0 = Instant::now();
    crate::consistency::check_model(model)?;
    let ctx = Ctx::new(model, s)?;
    let fe_mass = ctx.checks(s)?;
    let mut warnings = Vec::new();
    let axis = sub(s.q, s.p);
    for (side, want) in [s.warping_p, s.warping_q].into_iter().enumerate() {
        if want {
            let g = crate::interface::interface_geometry(model, &ctx.iface[side]);
            warnings.extend(crate::interface::check_warping_plane(SIDE[side], &g, axis)?);
        }
    }
    timings.push(("checks".to_string(), t0.elapsed().as_secs_f64()));

    // main problem: both interfaces prescribed
    let t1 = Instant::now();
    let main = ctx.problem([Treat::Fixed, Treat::Fixed])?;
    timings.push(("factorization".to_string(), t1.elapsed().as_secs_f64()));

    // constraint modes
    let t2 = Instant::now();
    let n_ext = ctx.n_ext;
    let mut g = Mat::<f64>::zeros(n_ext, 12);
    for side in 0..2 {
        for &i in &ctx.iface[side] {
            let t = ctx.iface_rows(side, i);
            let eqs = model.dofs().node_eqs(i);
            for d in 0..3 {
                let e = eqs[d].unwrap();
                for c in 0..6 {
                    g[(e, 6 * side + c)] = t[d][c];
                }
            }
        }
        for c in 0..6 {
            g[(ctx.mu_index(6 * side + c), 6 * side + c)] = 1.0;
        }
    }
    let v = main.solve(&ctx.ops, g.as_ref());
    timings.push(("constraint modes".to_string(), t2.elapsed().as_secs_f64()));

    // interface modes, p side then q side
    let t3 = Instant::now();
    let mut w_cols: Vec<Mat<f64>> = Vec::new();
    let mut kinds: Vec<ModeKind> = Vec::new();
    let mut names: Vec<String> = (0..12).map(mode_name).collect();
    for side in 0..2 {
        let (want, sd) = if side == 0 {
            (s.warping_p, Side::P)
        } else {
            (s.warping_q, Side::Q)
        };
        if want {
            w_cols.push(warping_mode(&ctx, side, &v)?);
            kinds.push(ModeKind::Warping(sd));
            names.push(format!("warping mode of interface {}", SIDE[side]));
        }
        for im in s.interface_modes.iter().filter(|m| m.side == sd) {
            w_cols.push(pattern_mode(&ctx, &main, side, im)?);
            kinds.push(ModeKind::DeformableInterface {
                side: sd,
                name: im.name.clone(),
            });
            names.push(format!(
                "deformable-interface mode '{}' of interface {}",
                im.name, SIDE[side]
            ));
        }
    }
    timings.push(("interface modes".to_string(), t3.elapsed().as_secs_f64()));

    // normal modes
    let t4 = Instant::now();
    let mut freqs = Vec::new();
    if s.normal_modes > 0 {
        let (lam, phi) = normal_modes(&ctx, &main, s.normal_modes)?;
        freqs = to_hz(&lam);
        let u = main.e.expand(phi.as_ref());
        for (c, f) in freqs.iter().enumerate() {
            let amax = (0..model.n_eq())
                .map(|r| u[(r, c)].abs())
                .fold(0.0, f64::max);
            let col = Mat::<f64>::from_fn(n_ext, 1, |r, _| u[(r, c)] / amax);
            w_cols.push(col);
            kinds.push(ModeKind::Normal { frequency_hz: *f });
            names.push(format!("normal mode {} ({f:.4} Hz)", c + 1));
        }
    }
    timings.push(("normal modes".to_string(), t4.elapsed().as_secs_f64()));

    // reduced matrices
    let t5 = Instant::now();
    let k = w_cols.len();
    let mut shapes = Mat::<f64>::zeros(n_ext, 12 + k);
    shapes.as_mut().subcols_mut(0, 12).copy_from(v.as_ref());
    for (c, w) in w_cols.iter().enumerate() {
        shapes.as_mut().col_mut(12 + c).copy_from(w.col(0));
    }
    let k_full = to_na(&ctx.ops.k_form(shapes.as_ref(), shapes.as_ref()));
    let m_bar = to_na(&ctx.ops.m_form(shapes.as_ref(), shapes.as_ref()));
    let sel: Vec<usize> = VE_INDEX.iter().copied().chain(12..12 + k).collect();
    let s_bar = DMatrix::from_fn(sel.len(), sel.len(), |i, j| k_full[(sel[i], sel[j])]);
    let s_names: Vec<String> = sel.iter().map(|&i| names[i].clone()).collect();
    check_independent(&m_bar, &names, "mass")?;
    check_independent(&s_bar, &s_names, "stiffness")?;
    let ev = s_bar.clone().symmetric_eigen();
    if ev.eigenvalues.iter().any(|&x| x < 0.0) {
        return Err(Error::NotPositiveSemiDefinite(format!(
            "S̄ has a negative eigenvalue {:e}",
            ev.eigenvalues.min()
        )));
    }
    timings.push(("reduced matrices".to_string(), t5.elapsed().as_secs_f64()));

    let mut data = LinearSuperelement::from_matrices(ctx.l0, ctx.r0, &s_bar, &m_bar, kinds);
    data.provenance = Provenance {
        sources: vec![format!(
            "model {} ({} nodes, {} equations)",
            model.name,
            model.n_nodes(),
            model.n_eq()
        )],
        settings: settings_text(s, &ctx, &freqs),
    };
    let eq_of_node: Vec<[Option<usize>; 3]> = (0..model.n_nodes())
        .map(|i| model.dofs().node_eqs(i))
        .collect();
    if s.fe_mesh {
        data.fe_mesh = Some(fe_mesh(&ctx, &shapes, &sel, &eq_of_node));
    }
    data.validate()?;
    let report = BuildReport {
        n_eq: model.n_eq(),
        n_interior: main.e.n_free,
        interface_nodes: [ctx.iface[0].len(), ctx.iface[1].len()],
        factor_nnz: main.llt.factor_nnz(),
        normal_frequencies_hz: freqs,
        fe_mass,
        timings,
        material: crate::wave_speed::infer_material(model),
        warnings,
    };
    Ok(BuildResult {
        data,
        k_full,
        shapes,
        report,
        eq_of_node,
    })
}

/// The FE mesh in the element frame (origin p, axes R0) with the recovery
/// R0ᵀ [Ve W] of every node's translations over the S̄ coordinates `sel`.
fn fe_mesh(
    ctx: &Ctx<'_>,
    shapes: &Mat<f64>,
    sel: &[usize],
    eq_of_node: &[[Option<usize>; 3]],
) -> FeMesh {
    let r0 = &ctx.r0;
    let local = |g: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|a| (0..3).map(|r| r0[r][a] * g[r]).sum())
    };
    let nodes = ctx
        .model
        .coords()
        .iter()
        .map(|&x| local(sub(x, ctx.rb[0])))
        .collect();
    let recovery = eq_of_node
        .iter()
        .map(|e| {
            sel.iter()
                .flat_map(|&c| {
                    local(std::array::from_fn(|d| {
                        e[d].map_or(0.0, |r| shapes[(r, c)])
                    }))
                })
                .collect()
        })
        .collect();
    let cells = ctx.model.solid.as_ref().map_or_else(Vec::new, |sol| {
        sol.kinds
            .iter()
            .zip(&sol.nodes)
            .map(|(k, n)| FeCell {
                vtk_type: k.vtk_type(),
                nodes: k
                    .vtk_order()
                    .iter()
                    .filter_map(|&i| n.get(i).copied())
                    .collect(),
            })
            .collect()
    });
    FeMesh {
        nodes,
        cells,
        recovery,
    }
}

fn settings_text(s: &BuildSettings, ctx: &Ctx<'_>, freqs: &[f64]) -> Vec<String> {
    vec![
        format!("builder: flexmb-superelement {}", env!("CARGO_PKG_VERSION")),
        format!("p = {:?}, q = {:?}, y_axis = {:?}", s.p, s.q, s.y_axis),
        format!(
            "rigid interfaces: p {} nodes, q {} nodes",
            ctx.iface[0].len(),
            ctx.iface[1].len()
        ),
        format!("warping modes: p {}, q {}", s.warping_p, s.warping_q),
        format!(
            "deformable-interface modes: {:?}",
            s.interface_modes
                .iter()
                .map(|m| (&m.name, m.side))
                .collect::<Vec<_>>()
        ),
        format!(
            "fixed-interface normal modes: {} at {:?} Hz",
            s.normal_modes, freqs
        ),
        format!(
            "point masses: {:?}",
            s.point_masses
                .iter()
                .map(|m| (&m.name, m.mass))
                .collect::<Vec<_>>()
        ),
        "sparse Cholesky: faer supernodal, AMD ordering; eigen: shift-invert Krylov–Schur"
            .to_string(),
        "normal modes scaled to a unit largest displacement component".to_string(),
    ]
}

/// The warping mode (3.4) of `side`: twist about the outward normal with the
/// interface free in the normal direction, minus the rigid twist.
fn warping_mode(ctx: &Ctx<'_>, side: usize, v: &Mat<f64>) -> Result<Mat<f64>, Error> {
    let nbar = if side == 0 {
        [-1.0, 0.0, 0.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let n: [f64; 3] = std::array::from_fn(|r| (0..3).map(|k| ctx.r0[r][k] * nbar[k]).sum());
    let mut treat = [Treat::Fixed, Treat::Fixed];
    treat[side] = Treat::NormalFree(n);
    let prob = ctx.problem(treat)?;
    let mut g = Mat::<f64>::zeros(ctx.n_ext, 1);
    for &i in &ctx.iface[side] {
        let d = sub(ctx.model.coords()[i], ctx.rb[side]);
        let w = cross(n, d);
        let eqs = ctx.model.dofs().node_eqs(i);
        for dd in 0..3 {
            g[(eqs[dd].unwrap(), 0)] = w[dd];
        }
    }
    for c in 0..3 {
        g[(ctx.mu_index(6 * side + 3 + c), 0)] = nbar[c];
    }
    let b = prob.solve(&ctx.ops, g.as_ref());
    let mut w = b.clone();
    for c in 0..3 {
        for r in 0..ctx.n_ext {
            w[(r, 0)] -= nbar[c] * v[(r, 6 * side + 3 + c)];
        }
    }
    let nb = b.col(0).norm_l2();
    let nw = w.col(0).norm_l2();
    if !(nw > 1e-8 * nb) {
        return Err(Error::DependentModes(format!(
            "the warping mode of interface {} is zero (|W| / |twist| = {:.1e}): the cross-section does not warp \
             (e.g. a circular section); drop warping_{}",
            SIDE[side],
            nw / nb,
            SIDE[side]
        )));
    }
    Ok(w)
}

/// A deformable-interface mode from a prescribed pattern (rigid part removed),
/// other interface clamped; uses the main factorization.
fn pattern_mode(
    ctx: &Ctx<'_>,
    main: &Problem,
    side: usize,
    im: &InterfaceMode,
) -> Result<Mat<f64>, Error> {
    let perr = |msg: String| Error::Pattern {
        name: im.name.clone(),
        msg,
    };
    let pat = &im.pattern;
    if pat.points.len() != pat.displacements.len() {
        return Err(perr(format!(
            "{} points but {} displacements",
            pat.points.len(),
            pat.displacements.len()
        )));
    }
    let tol = pat.tolerance.unwrap_or(1e-6 * bbox_diag(ctx.model));
    let nodes = &ctx.iface[side];
    let pts: Vec<[f64; 3]> = nodes.iter().map(|&i| ctx.model.coords()[i]).collect();
    let mut u = Vec::with_capacity(nodes.len());
    for (k, p) in pts.iter().enumerate() {
        let (best, dist) = pat
            .points
            .iter()
            .enumerate()
            .map(|(j, q)| (j, norm(sub(*p, *q))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .ok_or_else(|| perr("it has no points".into()))?;
        if dist > tol {
            return Err(perr(format!(
                "interface {} node {} at {:?} has no pattern point within {tol:.2e} m (nearest at {dist:.2e} m)",
                SIDE[side],
                ctx.model.node_ids()[nodes[k]],
                p
            )));
        }
        u.push(pat.displacements[best]);
    }
    let before: f64 = u.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    remove_rigid_part(&pts, &mut u);
    let after: f64 = u.iter().flatten().map(|x| x * x).sum::<f64>().sqrt();
    if !(after > 1e-8 * before) {
        return Err(perr(format!(
            "it is a rigid-body motion of interface {} (nothing is left after removing the rigid part); a rigid \
             motion is already described by the constraint modes",
            SIDE[side]
        )));
    }
    let mut g = Mat::<f64>::zeros(ctx.n_ext, 1);
    for (k, &i) in nodes.iter().enumerate() {
        let eqs = ctx.model.dofs().node_eqs(i);
        for d in 0..3 {
            g[(eqs[d].unwrap(), 0)] = u[k][d];
        }
    }
    Ok(main.solve(&ctx.ops, g.as_ref()))
}

fn normal_modes(ctx: &Ctx<'_>, prob: &Problem, nev: usize) -> Result<(Vec<f64>, Mat<f64>), Error> {
    let e = &prob.e;
    let apply_m = |x: faer::MatRef<'_, f64>, mut out: faer::MatMut<'_, f64>| {
        let u = e.expand(x);
        let mut mu = Mat::<f64>::zeros(ctx.n_ext, x.ncols());
        ctx.ops.apply_m(u.as_ref(), mu.as_mut());
        out.copy_from(e.restrict(mu.as_ref()));
    };
    let n = prob.llt.n();
    if nev > n {
        return Err(Error::Spec(format!(
            "{nev} normal modes requested but the interior has only {n} DOFs"
        )));
    }
    Ok(lowest_eigenpairs(&prob.llt, apply_m, nev)?)
}

/// Frequencies (Hz) from eigenvalues ω².
fn to_hz(lam: &[f64]) -> Vec<f64> {
    lam.iter()
        .map(|&l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
        .collect()
}

/// Eigenfrequencies (Hz) of the full FE model with interface p clamped and
/// interface q rigid and free (the reference a clamped-free superelement is
/// compared with), the `n` lowest, by shift-invert on a sparse factorization.
pub fn full_model_clamped_free_frequencies(
    model: &FeModel,
    s: &BuildSettings,
    n: usize,
) -> Result<Vec<f64>, Error> {
    let ctx = Ctx::new(model, s)?;
    let prob = ctx.problem([Treat::Fixed, Treat::RigidFree])?;
    let (lam, _) = normal_modes(&ctx, &prob, n)?;
    Ok(to_hz(&lam))
}

/// Fixed-interface normal-mode eigenvalues ω² [rad²/s²] of the model by the
/// dense generalized eigensolver (for small models; a check of the sparse path).
pub fn fixed_interface_eigenvalues_dense(
    model: &FeModel,
    s: &BuildSettings,
) -> Result<Vec<f64>, Error> {
    let ctx = Ctx::new(model, s)?;
    let prob = ctx.problem([Treat::Fixed, Treat::Fixed])?;
    let nf = prob.e.n_free;
    let kd = {
        let mut k = Mat::<f64>::zeros(nf, nf);
        let a = prob.k_ff.as_ref();
        for j in 0..nf {
            for (&i, &v) in a.row_idx_of_col_raw(j).iter().zip(a.val_of_col(j)) {
                k[(i, j)] = v;
                k[(j, i)] = v;
            }
        }
        k
    };
    let id = Mat::<f64>::identity(nf, nf);
    let u = prob.e.expand(id.as_ref());
    let mut mu = Mat::<f64>::zeros(ctx.n_ext, nf);
    ctx.ops.apply_m(u.as_ref(), mu.as_mut());
    let md = prob.e.restrict(mu.as_ref());
    Ok(generalized_eigen(kd.as_ref(), md.as_ref(), nf, Definite::Either)?.values)
}

/// The same eigenvalues by the sparse shift-invert path (the `nev` lowest).
pub fn fixed_interface_eigenvalues_sparse(
    model: &FeModel,
    s: &BuildSettings,
    nev: usize,
) -> Result<Vec<f64>, Error> {
    let ctx = Ctx::new(model, s)?;
    let prob = ctx.problem([Treat::Fixed, Treat::Fixed])?;
    Ok(normal_modes(&ctx, &prob, nev)?.0)
}

/// A rigid motion: translation plus a small rotation about a point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidMotion {
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation vector (rad).
    pub rotation: [f64; 3],
    /// Point the rotation is about (m).
    pub about: [f64; 3],
}

/// Static solution of the FE model with the `clamped` nodes fixed and the
/// `moved` nodes given a rigid motion (all other DOFs free); returns the
/// displacement over the equations and the energy ½ uᵀ K u.
pub fn prescribed_rigid_solve(
    model: &FeModel,
    clamped: &NodeSelection,
    moved: &NodeSelection,
    motion: &RigidMotion,
) -> Result<(Vec<f64>, f64), Error> {
    let cl = clamped.resolve(model, "clamped nodes")?;
    let mv = moved.resolve(model, "moved nodes")?;
    let n_eq = model.n_eq();
    let mut fixed = vec![false; model.n_nodes()];
    let mut g = Mat::<f64>::zeros(n_eq, 1);
    for &i in &cl {
        fixed[i] = true;
    }
    for &i in &mv {
        if fixed[i] {
            return Err(Error::Selection(format!(
                "node {} is both clamped and moved",
                model.node_ids()[i]
            )));
        }
        fixed[i] = true;
        let w = cross(motion.rotation, sub(model.coords()[i], motion.about));
        for d in 0..3 {
            if let Some(e) = model.dofs().eq(i, d) {
                g[(e, 0)] = motion.translation[d] + w[d];
            }
        }
    }
    let mut e = Expansion::with_capacity(n_eq);
    let mut labels = Vec::new();
    for eq in 0..n_eq {
        if fixed[model.dofs().dof(eq).0] {
            e.push_row(&[]);
        } else {
            e.push_row(&[(labels.len(), 1.0)]);
            labels.push(eq);
        }
    }
    let prob = Problem::new(e, model, &|j| model.describe_eq(labels[j]))?;
    let ops = ExtOps {
        model,
        n_ext: n_eq,
        masses: Vec::new(),
    };
    let u = prob.solve(&ops, g.as_ref());
    let uv: Vec<f64> = (0..n_eq).map(|r| u[(r, 0)]).collect();
    let energy = 0.5 * crate::model::sym_quad(model.k(), &uv, &uv);
    Ok((uv, energy))
}

/// The compatible deformable-interface pattern of thesis §3.4.2: solve the FE
/// model of two adjoining parts with one end clamped and a rigid motion (e.g. a
/// twist) prescribed on the other end (step 1), take the displacements of the
/// shared interface nodes (step 2) and remove their rigid-body part (3.37, step
/// 3). Prescribing the result on both parts (steps 4–5, [`InterfaceMode`])
/// gives modes that coincide on the shared interface.
pub fn compatible_interface_pattern(
    model_ab: &FeModel,
    clamped: &NodeSelection,
    moved: &NodeSelection,
    motion: &RigidMotion,
    interface: &NodeSelection,
) -> Result<InterfacePattern, Error> {
    let (u, _) = prescribed_rigid_solve(model_ab, clamped, moved, motion)?;
    let nodes = interface.resolve(model_ab, "shared interface")?;
    let points: Vec<[f64; 3]> = nodes.iter().map(|&i| model_ab.coords()[i]).collect();
    let mut disp: Vec<[f64; 3]> = nodes
        .iter()
        .map(|&i| std::array::from_fn(|d| model_ab.dofs().eq(i, d).map_or(0.0, |e| u[e])))
        .collect();
    remove_rigid_part(&points, &mut disp);
    Ok(InterfacePattern {
        points,
        displacements: disp,
        tolerance: None,
    })
}
