//! Mutations of a parsed scene: numbers, chain counts, node positions and
//! sharing, element nodes, kinds and options, roles, DOFs, loads,
//! controllers, initial velocities, outputs and time functions. Most keep the
//! scene well-formed, so that the validator and the dynamics see it.

use super::Rng;
use flexmb_element::VelocityTransform;
use flexmb_model::{
    Component, ControllerSpec, Dimension, DofChoice, ElementEntry, ElementSpec, InitialVelocity,
    LoadSpec, MaterialSpec, NodeSpec, OrientationSpec, OutputSpec, Prescribed, Scene, SectionSpec,
    Select, TimeFunction,
};

/// A number: mostly near `v`, sometimes an unusual one.
pub fn number(rng: &mut Rng, v: f64) -> f64 {
    match rng.below(12) {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => f64::NEG_INFINITY,
        3 => 0.0,
        4 => -v,
        5 => *rng.pick(&[1e308, -1e308, 1e-308, 5e-324, 1e-12, 1e12, -1.0, 1.0]),
        6 => v * 10f64.powi(rng.below(9) as i32 - 4),
        7 => v + (rng.unit() - 0.5) * 1e-6 * (1.0 + v.abs()),
        8 => (rng.unit() - 0.5) * 10f64.powi(rng.below(5) as i32 - 2),
        _ => v * (1.0 + 0.2 * (rng.unit() - 0.5)),
    }
}

fn some_number(rng: &mut Rng) -> f64 {
    let v = rng.unit() * 2.0 - 1.0;
    number(rng, v)
}

/// A vector: usually of the scene's dimension, sometimes of another length.
fn vector(rng: &mut Rng, nd: usize) -> Vec<f64> {
    let len = if rng.chance(0.85) {
        nd
    } else {
        *rng.pick(&[0, 1, 2, 3, 4])
    };
    (0..len)
        .map(|_| {
            if rng.chance(0.3) {
                0.0
            } else {
                some_number(rng)
            }
        })
        .collect()
}

fn chain_count(rng: &mut Rng, n: usize) -> usize {
    match rng.below(10) {
        0 => 0,
        1 => *rng.pick(&[1_000_001, usize::MAX, 300_000, 5_000]),
        2 => n + 1,
        3 => n.saturating_sub(1),
        4 => 2 * n,
        _ => 1 + rng.below(8),
    }
}

fn dim_of(s: &Scene) -> usize {
    match s.dimension {
        Dimension::Planar => 2,
        Dimension::Spatial => 3,
    }
}

/// Node ids, including those a chain helper makes (`ID.n1`) and some that
/// do not exist.
fn node_id(s: &Scene, rng: &mut Rng) -> String {
    let mut ids: Vec<String> = s.nodes.iter().map(|n| n.id.clone()).collect();
    for e in &s.elements {
        ids.push(format!("{}.n1", e.id));
    }
    ids.push("nowhere".into());
    ids.push(String::new());
    if rng.chance(0.9) && !s.nodes.is_empty() {
        s.nodes[rng.below(s.nodes.len())].id.clone()
    } else {
        rng.pick(&ids).clone()
    }
}

fn element_id(s: &Scene, rng: &mut Rng) -> String {
    if rng.chance(0.9) && !s.elements.is_empty() {
        let e = &s.elements[rng.below(s.elements.len())];
        match rng.below(6) {
            0 => format!("{}.1", e.id),
            _ => e.id.clone(),
        }
    } else {
        rng.pick(&["nothing", "", "*"]).to_string()
    }
}

const DEFORMATIONS: &[&str] = &[
    "*",
    "elongation",
    "bending_p",
    "bending_q",
    "torsion",
    "bending_y_p",
    "bending_y_q",
    "bending_z_p",
    "bending_z_q",
    "rotation",
    "bending_y",
    "bending_z",
    "normalization",
    "twist",
];

fn component(rng: &mut Rng) -> Component {
    match rng.below(7) {
        0 => Component::X,
        1 => Component::Y,
        2 => Component::Z,
        3 => Component::Angle,
        4 => Component::Lambda(*rng.pick(&[0, 1, 2, 3, 4, 255])),
        5 => Component::Position,
        _ => Component::Orientation,
    }
}

fn select(s: &Scene, rng: &mut Rng) -> Select {
    match rng.below(9) {
        0 | 1 => Select::Node(node_id(s, rng)),
        2..=4 => Select::Coord(node_id(s, rng), component(rng)),
        5 => Select::Modes(element_id(s, rng)),
        _ => Select::Def(element_id(s, rng), rng.pick(DEFORMATIONS).to_string()),
    }
}

/// A time function, at most `depth` levels of `Scaled`/`Sum` deep.
pub fn time_function(rng: &mut Rng, depth: usize) -> TimeFunction {
    let k = if depth == 0 {
        rng.below(9)
    } else {
        rng.below(11)
    };
    match k {
        0 => TimeFunction::Constant(some_number(rng)),
        1 => TimeFunction::Ramp {
            t0: number(rng, 0.0),
            t1: number(rng, 1.0),
            v0: some_number(rng),
            v1: some_number(rng),
        },
        2 => TimeFunction::RaisedCosinePulse {
            amplitude: some_number(rng),
            duration: number(rng, 0.5),
        },
        3 => TimeFunction::SpinUp {
            omega: some_number(rng),
            duration: number(rng, 15.0),
        },
        4 => TimeFunction::Sine {
            amplitude: some_number(rng),
            omega: number(rng, 10.0),
            phase: number(rng, 0.0),
        },
        5 => TimeFunction::SkewSineMoves {
            start: some_number(rng),
            moves: (0..rng.below(4))
                .map(|i| (number(rng, i as f64), number(rng, 0.5), some_number(rng)))
                .collect(),
        },
        6 => {
            let pieces = rng.below(4);
            let nb = if rng.chance(0.8) {
                pieces + 1
            } else {
                rng.below(5)
            };
            TimeFunction::PiecewisePolynomial {
                breaks: (0..nb).map(|i| number(rng, i as f64)).collect(),
                coeffs: (0..pieces)
                    .map(|_| (0..rng.below(5)).map(|_| some_number(rng)).collect())
                    .collect(),
                after: some_number(rng),
            }
        }
        7 => {
            let n = rng.below(5);
            let m = if rng.chance(0.8) { n } else { rng.below(5) };
            TimeFunction::Table {
                t: (0..n).map(|i| number(rng, i as f64)).collect(),
                v: (0..m).map(|_| some_number(rng)).collect(),
            }
        }
        8 => {
            let n = rng.below(5);
            let len = |rng: &mut Rng| if rng.chance(0.8) { n } else { rng.below(5) };
            let (nv, nr) = (len(rng), len(rng));
            TimeFunction::Hermite {
                t: (0..n).map(|i| number(rng, i as f64)).collect(),
                value: (0..nv).map(|_| some_number(rng)).collect(),
                rate: (0..nr).map(|_| some_number(rng)).collect(),
            }
        }
        9 => TimeFunction::Scaled {
            scale: some_number(rng),
            f: Box::new(time_function(rng, depth - 1)),
        },
        _ => TimeFunction::Sum(
            (0..rng.below(3))
                .map(|_| time_function(rng, depth - 1))
                .collect(),
        ),
    }
}

/// Changes one number of a time function (or replaces it).
fn mutate_function(f: &mut TimeFunction, rng: &mut Rng) {
    if rng.chance(0.3) {
        *f = time_function(rng, 2);
        return;
    }
    match f {
        TimeFunction::Constant(v) => *v = number(rng, *v),
        TimeFunction::Ramp { t0, t1, v0, v1 } => {
            let x = [t0, t1, v0, v1];
            let i = rng.below(4);
            let v = x.into_iter().nth(i).unwrap_or_else(|| unreachable!());
            *v = number(rng, *v);
        }
        TimeFunction::RaisedCosinePulse {
            amplitude,
            duration,
        }
        | TimeFunction::SpinUp {
            omega: amplitude,
            duration,
        } => {
            if rng.chance(0.5) {
                *amplitude = number(rng, *amplitude)
            } else {
                *duration = number(rng, *duration)
            }
        }
        TimeFunction::Sine {
            amplitude,
            omega,
            phase,
        } => match rng.below(3) {
            0 => *amplitude = number(rng, *amplitude),
            1 => *omega = number(rng, *omega),
            _ => *phase = number(rng, *phase),
        },
        TimeFunction::SkewSineMoves { start, moves } => {
            if moves.is_empty() || rng.chance(0.2) {
                *start = number(rng, *start);
            } else {
                let i = rng.below(moves.len());
                match rng.below(4) {
                    0 => moves[i].0 = number(rng, moves[i].0),
                    1 => moves[i].1 = number(rng, moves[i].1),
                    2 => moves[i].2 = number(rng, moves[i].2),
                    _ => {
                        let m = moves[i];
                        moves.push(m)
                    }
                }
            }
        }
        TimeFunction::PiecewisePolynomial {
            breaks,
            coeffs,
            after,
        } => match rng.below(5) {
            0 if !breaks.is_empty() => {
                let i = rng.below(breaks.len());
                breaks[i] = number(rng, breaks[i]);
            }
            1 if !coeffs.is_empty() => {
                let i = rng.below(coeffs.len());
                if coeffs[i].is_empty() || rng.chance(0.2) {
                    coeffs[i].push(some_number(rng));
                } else {
                    let k = rng.below(coeffs[i].len());
                    coeffs[i][k] = number(rng, coeffs[i][k]);
                }
            }
            2 => {
                breaks.pop();
            }
            3 => {
                coeffs.pop();
            }
            _ => *after = number(rng, *after),
        },
        TimeFunction::Table { t, v } => match rng.below(4) {
            0 if !t.is_empty() => {
                let i = rng.below(t.len());
                t[i] = number(rng, t[i]);
            }
            1 if !v.is_empty() => {
                let i = rng.below(v.len());
                v[i] = number(rng, v[i]);
            }
            2 => {
                t.pop();
            }
            _ => {
                if let Some(&last) = t.last() {
                    t.push(last);
                    v.push(some_number(rng));
                }
            }
        },
        TimeFunction::Hermite { t, value, rate } => {
            let v = match rng.below(3) {
                0 => t,
                1 => value,
                _ => rate,
            };
            if v.is_empty() || rng.chance(0.2) {
                v.pop();
            } else {
                let i = rng.below(v.len());
                v[i] = number(rng, v[i]);
            }
        }
        TimeFunction::Scaled { scale, f } => {
            if rng.chance(0.5) {
                *scale = number(rng, *scale)
            } else {
                mutate_function(f, rng)
            }
        }
        TimeFunction::Sum(fs) => {
            if fs.is_empty() || rng.chance(0.2) {
                fs.push(time_function(rng, 1));
            } else {
                let i = rng.below(fs.len());
                mutate_function(&mut fs[i], rng);
            }
        }
    }
}

/// Every time function of a scene, for picking one.
fn functions(s: &mut Scene) -> Vec<&mut TimeFunction> {
    let mut out: Vec<&mut TimeFunction> = vec![];
    for p in &mut s.prescribed {
        out.push(&mut p.function);
    }
    for c in &mut s.controllers {
        out.push(&mut c.reference);
    }
    for l in &mut s.loads {
        if let Some(f) = &mut l.function {
            out.push(f);
        }
    }
    out
}

fn list_op<T: Clone>(
    v: &mut Vec<T>,
    rng: &mut Rng,
    new: impl FnOnce(&mut Rng) -> T,
    what: &str,
) -> String {
    if v.is_empty() || rng.chance(0.4) {
        v.push(new(rng));
        return format!("added a {what}");
    }
    let i = rng.below(v.len());
    match rng.below(3) {
        0 => {
            v.remove(i);
            format!("removed {what} {i}")
        }
        1 => {
            let x = v[i].clone();
            v.push(x);
            format!("duplicated {what} {i}")
        }
        _ => {
            let x = new(rng);
            v[i] = x;
            format!("replaced {what} {i}")
        }
    }
}

fn mutate_material(m: &mut MaterialSpec, rng: &mut Rng) -> &'static str {
    match rng.below(4) {
        0 => {
            m.e = number(rng, m.e);
            "e"
        }
        1 => {
            m.rho = number(rng, m.rho);
            "rho"
        }
        2 => {
            m.nu = if rng.chance(0.2) {
                None
            } else {
                Some(number(rng, m.nu.unwrap_or(0.3)))
            };
            "nu"
        }
        _ => {
            m.g = if rng.chance(0.3) {
                None
            } else {
                Some(number(rng, m.g.unwrap_or(m.e / 2.6)))
            };
            "g"
        }
    }
}

fn mutate_section(sec: &mut SectionSpec, rng: &mut Rng) {
    match sec {
        SectionSpec::Rectangle { by, bz } => {
            if rng.chance(0.5) {
                *by = number(rng, *by)
            } else {
                *bz = number(rng, *bz)
            }
        }
        SectionSpec::Circle { d } => *d = number(rng, *d),
        SectionSpec::Tube { d_outer, d_inner } => {
            if rng.chance(0.5) {
                *d_outer = number(rng, *d_outer)
            } else {
                *d_inner = number(rng, *d_inner)
            }
        }
        SectionSpec::User(p) => {
            let f = [
                &mut p.area,
                &mut p.iy,
                &mut p.iz,
                &mut p.j,
                &mut p.ky,
                &mut p.kz,
            ];
            let i = rng.below(6);
            let v = f.into_iter().nth(i).unwrap_or_else(|| unreachable!());
            *v = number(rng, *v);
        }
    }
    if rng.chance(0.2) {
        *sec = match rng.below(3) {
            0 => SectionSpec::Circle {
                d: number(rng, 0.01),
            },
            1 => SectionSpec::Tube {
                d_outer: number(rng, 0.02),
                d_inner: number(rng, 0.01),
            },
            _ => SectionSpec::Rectangle {
                by: number(rng, 0.01),
                bz: number(rng, 0.02),
            },
        }
    }
}

/// The superelement file of `fixtures/fuzz/`, or one that does not exist.
fn superelement_file(rng: &mut Rng) -> String {
    rng.pick(&[
        "bar.se.ron",
        "bar.se.ron",
        "no-such-superelement.se.ron",
        "",
    ])
    .to_string()
}

/// Mode groups to share (the bar of `fixtures/fuzz/` has only normal modes).
fn share(rng: &mut Rng) -> (Option<String>, Option<String>) {
    let mut one = || match rng.below(3) {
        0 => None,
        1 => Some("w".to_string()),
        _ => Some("se1".to_string()),
    };
    (one(), one())
}

fn pair(s: &Scene, rng: &mut Rng) -> (String, String) {
    (node_id(s, rng), node_id(s, rng))
}

fn new_element(s: &Scene, rng: &mut Rng) -> ElementSpec {
    let nd = dim_of(s);
    match rng.below(6) {
        0 => {
            if let Some(b) = s.elements.iter().find_map(|e| match &e.kind {
                ElementSpec::Beam(b) => Some(b),
                _ => None,
            }) {
                let mut b = b.clone();
                b.nodes = pair(s, rng);
                b.n = chain_count(rng, b.n);
                ElementSpec::Beam(b)
            } else {
                ElementSpec::PointMass {
                    node: node_id(s, rng),
                    mass: number(rng, 1.0),
                    inertia: None,
                }
            }
        }
        1 => ElementSpec::Truss {
            nodes: pair(s, rng),
            ea: number(rng, 1e6),
            mass_per_length: number(rng, 0.1),
            n: chain_count(rng, 1),
        },
        2 => ElementSpec::Hinge {
            nodes: pair(s, rng),
            axis: rng.chance(0.5).then(|| vector(rng, 3)),
            stiffness: number(rng, 1.0),
            bending_stiffness: number(rng, 0.0),
        },
        3 => ElementSpec::PointMass {
            node: node_id(s, rng),
            mass: number(rng, 1.0),
            inertia: rng.chance(0.5).then(|| number(rng, 0.01)),
        },
        4 => ElementSpec::RigidBody {
            node: node_id(s, rng),
            mass: number(rng, 1.0),
            com: rng.chance(0.5).then(|| vector(rng, nd)),
            inertia: {
                let n = if rng.chance(0.8) { 3 } else { rng.below(5) };
                (0..n)
                    .map(|i| {
                        (0..3)
                            .map(|j| {
                                if i == j {
                                    number(rng, 0.01)
                                } else if rng.chance(0.7) {
                                    0.0
                                } else {
                                    number(rng, 0.001)
                                }
                            })
                            .collect()
                    })
                    .collect()
            },
        },
        _ => ElementSpec::Superelement {
            nodes: pair(s, rng),
            file: superelement_file(rng),
            transform: VelocityTransform::B3,
            share: share(rng),
        },
    }
}

fn mutate_element(s: &Scene, e: &mut ElementEntry, rng: &mut Rng) -> String {
    let nd = dim_of(s);
    match &mut e.kind {
        ElementSpec::Beam(b) => match rng.below(8) {
            0 | 1 => {
                b.n = chain_count(rng, b.n);
                format!("n = {}", b.n)
            }
            2 => {
                b.nodes = pair(s, rng);
                format!("nodes {:?}", b.nodes)
            }
            3 => {
                b.up = if rng.chance(0.2) {
                    None
                } else {
                    Some(vector(rng, 3))
                };
                format!("up {:?}", b.up)
            }
            4 => {
                b.timoshenko = !b.timoshenko;
                "timoshenko toggled".into()
            }
            5 => {
                b.shortening = !b.shortening;
                b.mass = rng.chance(0.5);
                "shortening toggled, mass changed".into()
            }
            6 => {
                b.transform = *rng.pick(&[
                    VelocityTransform::B1,
                    VelocityTransform::B2,
                    VelocityTransform::B3,
                ]);
                format!("transform {:?}", b.transform)
            }
            _ => {
                let ids: Vec<&String> = s.materials.keys().chain(s.sections.keys()).collect();
                if rng.chance(0.5) {
                    b.material = ids
                        .get(rng.below(ids.len()))
                        .map(|x| x.to_string())
                        .unwrap_or_default();
                } else {
                    b.section = ids
                        .get(rng.below(ids.len()))
                        .map(|x| x.to_string())
                        .unwrap_or_default();
                }
                format!("material {:?}, section {:?}", b.material, b.section)
            }
        },
        ElementSpec::Truss {
            nodes,
            ea,
            mass_per_length,
            n,
        } => match rng.below(4) {
            0 => {
                *n = chain_count(rng, *n);
                format!("n = {n}")
            }
            1 => {
                *ea = number(rng, *ea);
                format!("ea = {ea}")
            }
            2 => {
                *mass_per_length = number(rng, *mass_per_length);
                format!("mass per length = {mass_per_length}")
            }
            _ => {
                *nodes = pair(s, rng);
                format!("nodes {nodes:?}")
            }
        },
        ElementSpec::Hinge {
            nodes,
            axis,
            stiffness,
            bending_stiffness,
        } => match rng.below(4) {
            0 => {
                *axis = if rng.chance(0.2) {
                    None
                } else {
                    Some(vector(rng, 3))
                };
                format!("axis {axis:?}")
            }
            1 => {
                *stiffness = number(rng, *stiffness);
                format!("stiffness = {stiffness}")
            }
            2 => {
                *bending_stiffness = number(rng, *bending_stiffness);
                format!("bending stiffness = {bending_stiffness}")
            }
            _ => {
                *nodes = pair(s, rng);
                format!("nodes {nodes:?}")
            }
        },
        ElementSpec::PointMass {
            node,
            mass,
            inertia,
        } => match rng.below(3) {
            0 => {
                *mass = number(rng, *mass);
                format!("mass = {mass}")
            }
            1 => {
                *inertia = rng
                    .chance(0.7)
                    .then(|| number(rng, inertia.unwrap_or(0.01)));
                format!("inertia = {inertia:?}")
            }
            _ => {
                *node = node_id(s, rng);
                format!("node {node:?}")
            }
        },
        ElementSpec::RigidBody {
            node,
            mass,
            com,
            inertia,
        } => match rng.below(4) {
            0 => {
                *mass = number(rng, *mass);
                format!("mass = {mass}")
            }
            1 => {
                *com = rng.chance(0.8).then(|| vector(rng, nd));
                format!("com = {com:?}")
            }
            2 => {
                if let Some(row) = inertia.get_mut(rng.below(3)) {
                    if !row.is_empty() {
                        let k = rng.below(row.len());
                        row[k] = number(rng, row[k]);
                    }
                }
                format!("inertia = {inertia:?}")
            }
            _ => {
                *node = node_id(s, rng);
                format!("node {node:?}")
            }
        },
        ElementSpec::Superelement {
            nodes,
            file,
            transform,
            share: sh,
        } => match rng.below(4) {
            0 => {
                *file = superelement_file(rng);
                format!("file {file:?}")
            }
            1 => {
                *sh = share(rng);
                format!("share {sh:?}")
            }
            2 => {
                *transform = *rng.pick(&[
                    VelocityTransform::B1,
                    VelocityTransform::B2,
                    VelocityTransform::B3,
                ]);
                format!("transform {transform:?}")
            }
            _ => {
                *nodes = pair(s, rng);
                format!("nodes {nodes:?}")
            }
        },
    }
}

/// After a change of dimension: positions, gravity, forces, moments and
/// velocities to the new number of components (a planar moment becomes one
/// about z and back), and an axis for the hinges of a spatial scene.
fn convert_vectors(s: &mut Scene) {
    let nd = dim_of(s);
    let fit = |v: &mut Vec<f64>| v.resize(nd, 0.0);
    for n in &mut s.nodes {
        if !n.at.is_empty() {
            fit(&mut n.at);
        }
    }
    if let Some(g) = &mut s.gravity {
        fit(g);
    }
    for l in &mut s.loads {
        if let Some(f) = &mut l.force {
            fit(f);
        }
        if let Some(m) = &mut l.moment {
            *m = if nd == 2 {
                vec![m.last().copied().unwrap_or(0.0)]
            } else {
                vec![0.0, 0.0, m.first().copied().unwrap_or(0.0)]
            };
        }
    }
    for v in &mut s.initial_velocity {
        for x in [&mut v.v, &mut v.about].into_iter().flatten() {
            fit(x);
        }
    }
    for e in &mut s.elements {
        if let ElementSpec::Hinge { axis, .. } = &mut e.kind {
            *axis = (nd == 3).then(|| vec![0.0, 0.0, 1.0]);
        }
    }
}

/// A node orientation: mostly valid forms of the scene's dimension, some of
/// the other one, some degenerate (zero axis, non-unit, wrong length).
fn orientation(rng: &mut Rng, nd: usize) -> Option<OrientationSpec> {
    Some(match rng.below(6) {
        0 => return None,
        1 => OrientationSpec::AxisAngle {
            axis: if rng.chance(0.1) {
                vec![0.0; nd]
            } else {
                vector(rng, nd)
            },
            angle: number(rng, 1.0),
        },
        2 => OrientationSpec::RotationVector(vector(rng, nd)),
        3 => {
            let len = if rng.chance(0.9) { 4 } else { nd };
            let mut l = vector(rng, len);
            if rng.chance(0.7) {
                let n = l.iter().map(|v| v * v).sum::<f64>().sqrt();
                if n > 0.0 {
                    l.iter_mut().for_each(|v| *v /= n);
                }
            }
            OrientationSpec::EulerParameters(l)
        }
        _ => OrientationSpec::Angle(number(rng, 1.0)),
    })
}

/// Applies one mutation to the scene and describes it.
pub fn mutate(s: &mut Scene, rng: &mut Rng) -> String {
    let nd = dim_of(s);
    match rng.below(25) {
        0 => {
            s.dimension = match s.dimension {
                Dimension::Planar => Dimension::Spatial,
                Dimension::Spatial => Dimension::Planar,
            };
            let converted = rng.chance(0.8);
            if converted {
                convert_vectors(s);
            }
            format!(
                "dimension {:?}{}",
                s.dimension,
                if converted { ", vectors converted" } else { "" }
            )
        }
        1 => {
            s.gravity = if rng.chance(0.2) {
                None
            } else {
                Some(vector(rng, nd))
            };
            format!("gravity {:?}", s.gravity)
        }
        2 => {
            let keys: Vec<String> = s.materials.keys().cloned().collect();
            if keys.is_empty() || rng.chance(0.1) {
                s.materials.insert(
                    "new material".into(),
                    MaterialSpec {
                        e: number(rng, 7e10),
                        g: None,
                        nu: None,
                        rho: number(rng, 2700.0),
                    },
                );
                return "added a material".into();
            }
            let k = rng.pick(&keys).clone();
            if rng.chance(0.1) {
                s.materials.remove(&k);
                return format!("removed material {k:?}");
            }
            let m = s.materials.get_mut(&k).unwrap_or_else(|| unreachable!());
            let f = mutate_material(m, rng);
            format!("material {k:?} {f} changed: {m:?}")
        }
        3 => {
            let keys: Vec<String> = s.sections.keys().cloned().collect();
            if keys.is_empty() {
                return "no section".into();
            }
            let k = rng.pick(&keys).clone();
            if rng.chance(0.1) {
                s.sections.remove(&k);
                return format!("removed section {k:?}");
            }
            let sec = s.sections.get_mut(&k).unwrap_or_else(|| unreachable!());
            mutate_section(sec, rng);
            format!("section {k:?} -> {sec:?}")
        }
        4 | 5 => {
            if s.nodes.is_empty() {
                return "no node".into();
            }
            let i = rng.below(s.nodes.len());
            let n = &mut s.nodes[i];
            if n.at.is_empty() || rng.chance(0.15) {
                n.at = vector(rng, nd);
            } else {
                let k = rng.below(n.at.len());
                n.at[k] = number(rng, n.at[k]);
            }
            format!("node {:?} at {:?}", n.id, n.at)
        }
        6 => {
            if s.nodes.is_empty() {
                return "no node".into();
            }
            let i = rng.below(s.nodes.len());
            let other = node_id(s, rng);
            let n = &mut s.nodes[i];
            n.position_of = if rng.chance(0.2) { None } else { Some(other) };
            if rng.chance(0.7) {
                n.at.clear();
            }
            format!("node {:?} position_of {:?}", n.id, n.position_of)
        }
        7 => {
            let id = node_id(s, rng);
            let at = vector(rng, nd);
            list_op(
                &mut s.nodes,
                rng,
                |rng| NodeSpec {
                    id: if rng.chance(0.5) { id } else { "N".into() },
                    at,
                    position_of: None,
                    orientation: None,
                },
                "node",
            )
        }
        8 => {
            if s.nodes.len() < 2 {
                return "fewer than two nodes".into();
            }
            let (i, j) = (rng.below(s.nodes.len()), rng.below(s.nodes.len()));
            s.nodes.swap(i, j);
            format!("nodes {i} and {j} swapped")
        }
        9..=11 => {
            if s.elements.is_empty() {
                return "no element".into();
            }
            let i = rng.below(s.elements.len());
            let snapshot = s.clone();
            let e = &mut s.elements[i];
            let what = mutate_element(&snapshot, e, rng);
            format!("element {:?}: {what}", e.id)
        }
        12 => {
            let kind = new_element(s, rng);
            let id = if rng.chance(0.8) {
                format!("fz{}", rng.below(100))
            } else {
                element_id(s, rng)
            };
            list_op(
                &mut s.elements,
                rng,
                |_| ElementEntry { id, kind },
                "element",
            )
        }
        13 => {
            let x = select(s, rng);
            list_op(&mut s.fixed, rng, |_| x, "fixed entry")
        }
        14 => {
            let x = select(s, rng);
            list_op(&mut s.rigid, rng, |_| x, "rigid entry")
        }
        15 => {
            let what = select(s, rng);
            let function = time_function(rng, 2);
            list_op(
                &mut s.prescribed,
                rng,
                |_| Prescribed { what, function },
                "prescribed entry",
            )
        }
        16 => {
            s.dofs = match rng.below(3) {
                0 => DofChoice::Deformations,
                1 => DofChoice::NodalCoordinates,
                _ => DofChoice::Explicit((0..rng.below(6)).map(|_| select(s, rng)).collect()),
            };
            format!("dofs {:?}", s.dofs)
        }
        17 => {
            let x = select(s, rng);
            list_op(&mut s.dofs_first, rng, |_| x, "dofs_first entry")
        }
        18 => {
            let node = node_id(s, rng);
            let force = rng.chance(0.7).then(|| vector(rng, nd));
            let moment = rng
                .chance(0.4)
                .then(|| vector(rng, if nd == 2 { 1 } else { 3 }));
            let function = rng.chance(0.5).then(|| time_function(rng, 1));
            list_op(
                &mut s.loads,
                rng,
                |_| LoadSpec {
                    node,
                    force,
                    moment,
                    function,
                },
                "load",
            )
        }
        19 => {
            let on = select(s, rng);
            let (kp, kd) = (number(rng, 1e3), number(rng, 10.0));
            let reference = time_function(rng, 1);
            list_op(
                &mut s.controllers,
                rng,
                |_| ControllerSpec {
                    on,
                    kp,
                    kd,
                    reference,
                },
                "controller",
            )
        }
        20 => {
            let nodes: Vec<String> = (0..rng.below(3)).map(|_| node_id(s, rng)).collect();
            let v = rng.chance(0.6).then(|| vector(rng, nd));
            let omega = rng.chance(0.6).then(|| vector(rng, 3));
            let about = rng.chance(0.4).then(|| vector(rng, nd));
            list_op(
                &mut s.initial_velocity,
                rng,
                |_| InitialVelocity {
                    nodes,
                    v,
                    omega,
                    about,
                },
                "initial velocity",
            )
        }
        21 => {
            let o = match rng.below(6) {
                0 => OutputSpec::Position(node_id(s, rng)),
                1 => OutputSpec::Rotation(node_id(s, rng)),
                2 => {
                    OutputSpec::Deformation(element_id(s, rng), rng.pick(DEFORMATIONS).to_string())
                }
                3 => OutputSpec::Stress(element_id(s, rng), rng.pick(DEFORMATIONS).to_string()),
                4 => OutputSpec::Energies,
                _ => OutputSpec::Dofs,
            };
            list_op(&mut s.outputs, rng, |_| o, "output")
        }
        22 => {
            if s.nodes.is_empty() {
                return "no node".into();
            }
            let i = rng.below(s.nodes.len());
            let o = orientation(rng, nd);
            let n = &mut s.nodes[i];
            n.orientation = o;
            format!("node {:?} orientation {:?}", n.id, n.orientation)
        }
        _ => {
            let mut fs = functions(s);
            if fs.is_empty() {
                return "no time function".into();
            }
            let i = rng.below(fs.len());
            mutate_function(fs[i], rng);
            format!("time function {i} -> {:?}", fs[i])
        }
    }
}
