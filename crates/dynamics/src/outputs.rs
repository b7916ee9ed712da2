//! The outputs a scene asks for (node positions, rotations and their rates,
//! deformations, stress resultants, energies, momentum, support reactions,
//! DOFs), as named columns of a table.

use crate::{Dynamics, DynamicsError};
use flexmb_model::{Coordinate, OutputSpec};
use flexmb_rotation::EulerParameters;

enum Column {
    X(usize),
    Eps(usize),
    Sigma(usize),
    RotVec(usize, [usize; 4]),
    Kinetic,
    Elastic,
    Gravitational,
    ExternalWork,
    Q(usize),
    /// ẋ at a nodal coordinate.
    Xd(usize),
    /// Component k of ω = 2Λ(λ)λ̇ (global axes) of a node's Euler parameters.
    Omega(usize, [usize; 4]),
    /// Component k of the linear (k < 3) or angular (3 + k) momentum about a point.
    Momentum(usize, [f64; 3]),
    /// Component k of the force (k < 3) or moment (3 + k) of the supports on node i.
    Reaction(usize, usize),
}

/// The components (index into `names`, name) of a planar (x, y and the
/// z moment) or spatial (all six) force/moment or momentum pair.
fn plane_or_space(
    m: &flexmb_model::Mechanism,
    names: [&'static str; 6],
) -> Vec<(usize, &'static str)> {
    let keep: &[usize] = match m.dimension {
        flexmb_model::Dimension::Planar => &[0, 1, 5],
        flexmb_model::Dimension::Spatial => &[0, 1, 2, 3, 4, 5],
    };
    keep.iter().map(|&k| (k, names[k])).collect()
}

/// A recorder of the requested outputs.
pub struct OutputTable {
    columns: Vec<Column>,
    /// Column names.
    pub header: Vec<String>,
    /// (t, external power, external work) of the previous row: the work is
    /// the trapezoidal integral of the power over the rows.
    work: std::cell::Cell<Option<(f64, f64, f64)>>,
    /// The DOFs of the mechanism the table was made for: `Dofs` columns are
    /// read from x and ε, so a row is the same in any chart of the
    /// orientations (a dynamics whose free nodes switched charts).
    dofs: Vec<Coordinate>,
}

impl OutputTable {
    /// The columns for the mechanism's requested outputs (DOFs if none are requested).
    pub fn new(dy: &Dynamics) -> Result<Self, DynamicsError> {
        let m = dy.mechanism().clone();
        let mut columns = vec![];
        let mut header = vec![];
        let mut specs = m.outputs.clone();
        if specs.is_empty() {
            specs.push(OutputSpec::Dofs);
        }
        let unknown =
            |what: &str, id: &str| DynamicsError::Invalid(format!("output: unknown {what} '{id}'"));
        for s in &specs {
            match s {
                OutputSpec::Position(id) => {
                    let n = m.node(id).ok_or_else(|| unknown("node", id))?;
                    for (k, i) in n.position.iter().enumerate() {
                        columns.push(Column::X(*i));
                        header.push(format!("{id}.{}", ["x", "y", "z"][k]));
                    }
                }
                OutputSpec::Rotation(id) => {
                    let n = m.node(id).ok_or_else(|| unknown("node", id))?;
                    match &n.orientation {
                        Some(o) if o.len() == 1 => {
                            columns.push(Column::X(o[0]));
                            header.push(format!("{id}.angle"));
                        }
                        Some(o) => {
                            for k in 0..3 {
                                columns.push(Column::RotVec(k, [o[0], o[1], o[2], o[3]]));
                                header.push(format!("{id}.rotvec_{}", ["x", "y", "z"][k]));
                            }
                        }
                        None => {
                            return Err(DynamicsError::Invalid(format!(
                                "output: node '{id}' has no rotation"
                            )))
                        }
                    }
                }
                OutputSpec::Deformation(eid, name) | OutputSpec::Stress(eid, name) => {
                    let stress = matches!(s, OutputSpec::Stress(..));
                    let mut found = false;
                    for e in m
                        .elements
                        .iter()
                        .filter(|e| e.id == *eid || e.group == *eid)
                    {
                        for (k, n) in e.element.deformation_names().iter().enumerate() {
                            if name == "*" || n == name {
                                found = true;
                                let j = e.eps_offset + k;
                                columns.push(if stress {
                                    Column::Sigma(j)
                                } else {
                                    Column::Eps(j)
                                });
                                header.push(format!(
                                    "{}{}",
                                    if stress { "sigma:" } else { "" },
                                    m.eps_names[j]
                                ));
                            }
                        }
                    }
                    if !found {
                        return Err(DynamicsError::Invalid(format!(
                            "output: no deformation '{name}' in element '{eid}'"
                        )));
                    }
                }
                OutputSpec::Energies => {
                    columns.extend([
                        Column::Kinetic,
                        Column::Elastic,
                        Column::Gravitational,
                        Column::ExternalWork,
                    ]);
                    header.extend([
                        "kinetic".to_string(),
                        "elastic".into(),
                        "gravitational".into(),
                        "external_work".into(),
                    ]);
                }
                OutputSpec::Dofs => {
                    for (k, c) in m.dofs.iter().enumerate() {
                        columns.push(Column::Q(k));
                        header.push(format!("q:{}", m.coordinate_name(*c)));
                    }
                }
                OutputSpec::Velocity(id) => {
                    let n = m.node(id).ok_or_else(|| unknown("node", id))?;
                    for (k, i) in n.position.iter().enumerate() {
                        columns.push(Column::Xd(*i));
                        header.push(format!("{id}.v{}", ["x", "y", "z"][k]));
                    }
                }
                OutputSpec::AngularVelocity(id) => {
                    let n = m.node(id).ok_or_else(|| unknown("node", id))?;
                    match n.orientation.as_deref() {
                        Some([phi]) => {
                            columns.push(Column::Xd(*phi));
                            header.push(format!("{id}.omega_z"));
                        }
                        Some([a, b, c, d]) => {
                            for k in 0..3 {
                                columns.push(Column::Omega(k, [*a, *b, *c, *d]));
                                header.push(format!("{id}.omega_{}", ["x", "y", "z"][k]));
                            }
                        }
                        _ => {
                            return Err(DynamicsError::Invalid(format!(
                                "output: node '{id}' has no rotation"
                            )))
                        }
                    }
                }
                OutputSpec::Momentum(point) => {
                    let mut about = [0.0; 3];
                    for (a, p) in about.iter_mut().zip(point) {
                        *a = *p;
                    }
                    for (k, name) in plane_or_space(&m, ["L_x", "L_y", "L_z", "H_x", "H_y", "H_z"])
                    {
                        columns.push(Column::Momentum(k, about));
                        header.push(name.to_string());
                    }
                }
                OutputSpec::Reaction(id) => {
                    let i = m
                        .nodes
                        .iter()
                        .position(|n| n.id == *id)
                        .ok_or_else(|| unknown("node", id))?;
                    let has_moment = m.nodes[i].orientation.is_some();
                    for (k, name) in plane_or_space(&m, ["R_x", "R_y", "R_z", "M_x", "M_y", "M_z"])
                    {
                        if k >= 3 && !has_moment {
                            continue;
                        }
                        columns.push(Column::Reaction(k, i));
                        header.push(format!("{id}.{name}"));
                    }
                }
            }
        }
        Ok(Self {
            columns,
            header,
            work: std::cell::Cell::new(None),
            dofs: m.dofs.clone(),
        })
    }

    /// One row at (t, q, q̇) (q and q̇ of `dy`'s chart, which may differ from
    /// the table's, see [`Dynamics::simulate_with`]), with `x` the configuration of the trajectory at
    /// that point ([`Trajectory::x`](crate::Trajectory::x)): the position
    /// solve starts there, so that the row is on the branch of the motion
    /// and does not depend on what `dy` solved before (e.g. the end of a
    /// long run). Rows must come in time order: the external
    /// work column is the work of loads, gravity and controllers since the
    /// first row, integrated over the rows by the trapezoidal rule (error
    /// O(Δt²) in the output interval), so that kinetic + elastic − external
    /// work stays constant up to that error (gravity's work is −Δ gravitational).
    pub fn row(
        &self,
        dy: &mut Dynamics,
        t: f64,
        q: &[f64],
        qd: &[f64],
        x: &[f64],
    ) -> Result<Vec<f64>, DynamicsError> {
        if x.len() != dy.kin.x().len() {
            return Err(DynamicsError::Invalid(format!(
                "output row at t = {t}: a configuration of {} coordinates for {} nodal coordinates",
                x.len(),
                dy.kin.x().len()
            )));
        }
        dy.kin.set_guess(x);
        let needs_energy = self
            .columns
            .iter()
            .any(|c| matches!(c, Column::Kinetic | Column::Elastic | Column::Gravitational));
        let en = if needs_energy {
            Some(dy.energies(t, q, qd)?)
        } else {
            None
        };
        let work = if self
            .columns
            .iter()
            .any(|c| matches!(c, Column::ExternalWork))
        {
            let p = dy.external_power(t, q, qd)?;
            let w = match self.work.get() {
                Some((t0, p0, w0)) => w0 + 0.5 * (t - t0) * (p + p0),
                None => 0.0,
            };
            self.work.set(Some((t, p, w)));
            w
        } else {
            0.0
        };
        let reactions = if self
            .columns
            .iter()
            .any(|c| matches!(c, Column::Reaction(..)))
        {
            let mut qdd = vec![0.0; q.len()];
            dy.accelerations_by_projection(t, q, qd, &mut qdd)?;
            let r = dy.nodal_reactions(t, q, qd, &qdd)?;
            let nodes = self.columns.iter().filter_map(|c| match c {
                Column::Reaction(_, i) => Some(*i),
                _ => None,
            });
            nodes.map(|i| (i, dy.node_reaction(&r, i))).collect()
        } else {
            vec![]
        };
        dy.kinematics_at(t, q, Some(qd))?;
        let momenta: Vec<([f64; 3], crate::Momentum)> = self
            .columns
            .iter()
            .filter_map(|c| match c {
                Column::Momentum(_, a) => Some(*a),
                _ => None,
            })
            .map(|a| (a, dy.momentum_here(a)))
            .collect();
        dy.forces(t, true);
        let x = dy.kin.x();
        let xd = dy.kin.xd();
        let eps = dy.kin.eps();
        Ok(self
            .columns
            .iter()
            .map(|c| match c {
                Column::X(i) => x[*i],
                Column::Eps(j) => eps[*j],
                Column::Sigma(j) => dy.sigma[*j],
                Column::RotVec(k, o) => {
                    EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]).to_rotation_vector()[*k]
                }
                Column::Kinetic => en.map_or(0.0, |e| e.kinetic),
                Column::Elastic => en.map_or(0.0, |e| e.elastic),
                Column::Gravitational => en.map_or(0.0, |e| e.gravitational),
                Column::ExternalWork => work,
                Column::Q(k) => match self.dofs[*k] {
                    Coordinate::Node(i) => x[i],
                    Coordinate::Def(j) => eps[j],
                },
                Column::Xd(i) => xd[*i],
                Column::Omega(k, o) => {
                    let l = EulerParameters([x[o[0]], x[o[1]], x[o[2]], x[o[3]]]);
                    l.omega(&[xd[o[0]], xd[o[1]], xd[o[2]], xd[o[3]]])[*k]
                }
                Column::Momentum(k, a) => {
                    let p = momenta.iter().find(|(b, _)| b == a).map(|(_, p)| p);
                    p.map_or(f64::NAN, |p| {
                        if *k < 3 {
                            p.linear[*k]
                        } else {
                            p.angular[*k - 3]
                        }
                    })
                }
                Column::Reaction(k, i) => {
                    let r = reactions.iter().find(|(j, _)| j == i).map(|(_, r)| r);
                    r.map_or(f64::NAN, |(f, m)| if *k < 3 { f[*k] } else { m[*k - 3] })
                }
            })
            .collect())
    }
}
