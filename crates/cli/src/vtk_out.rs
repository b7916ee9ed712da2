//! `--vtk DIR`: the configurations of a command as VTU files with a PVD
//! collection (crate `flexmb-vtk`), for ParaView or pyvista; the modes of
//! `eig` as animated series and those of `sweep` as point data.

use crate::out::say;
use crate::Failure;
use faer::Mat;
use flexmb_dynamics::Dynamics;
use flexmb_model::Mechanism;
use flexmb_vtk::{Beams, Drawing, Superelements};
use std::path::Path;

/// How `--vtk` draws superelements and beams (the options of every command
/// that has `--vtk`).
#[derive(clap::Args, Clone, Copy)]
pub(crate) struct VtkStyle {
    /// With --vtk: draw superelements as the chord between their nodes,
    /// not as their FE mesh (smaller files for large meshes).
    #[arg(long, requires = "vtk")]
    vtk_chords: bool,
    /// With --vtk: draw beams as boxes of their section swept along their
    /// centre line (hexahedra), not as lines (their section is cell data
    /// either way).
    #[arg(long, requires = "vtk")]
    vtk_boxes: bool,
}

/// Where `--vtk` writes and how it draws superelements (`--vtk-chords`)
/// and beams (`--vtk-boxes`).
#[derive(Clone, Copy)]
pub(crate) struct VtkOut<'a> {
    /// The directory.
    pub dir: &'a Path,
    /// Superelements as their FE mesh or as chords.
    pub style: Superelements,
    /// Beams as lines or boxes.
    pub beams: Beams,
}

impl<'a> VtkOut<'a> {
    /// `--vtk DIR` drawn as `style` says.
    pub(crate) fn new(dir: &'a Path, style: VtkStyle) -> Self {
        Self {
            dir,
            style: if style.vtk_chords {
                Superelements::Chord
            } else {
                Superelements::Mesh
            },
            beams: if style.vtk_boxes {
                Beams::Boxes
            } else {
                Beams::Lines
            },
        }
    }

    fn drawing<'m>(&self, mech: &'m Mechanism) -> Result<Drawing<'m>, Failure> {
        Drawing::with_beams(mech, self.style, self.beams).map_err(vtk_err)
    }
}

/// Named point data: one 3-vector per node.
type PointData = Vec<(String, Vec<[f64; 3]>)>;

/// Frames of a series each with its point data: (time, nodal coordinates x,
/// point data).
type Frames = [(f64, Vec<f64>, PointData)];

fn vtk_err(e: flexmb_vtk::VtkError) -> Failure {
    Failure::Compute(e.to_string())
}

/// Writes `frames` (time, nodal coordinates x) of `mech` as `dir/NAME_….vtu`
/// and `dir/NAME.pvd`.
pub(crate) fn write(
    out: VtkOut<'_>,
    name: &str,
    mech: &Mechanism,
    frames: &[(f64, &[f64])],
) -> Result<(), Failure> {
    let mut drawing = out.drawing(mech)?;
    let texts = frames
        .iter()
        .map(|(t, x)| drawing.configuration(x, &[], &[]).map(|s| (*t, s)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(vtk_err)?;
    write_texts(out.dir, name, &texts)
}

/// Writes VTU texts as a series and says so.
fn write_texts(dir: &Path, name: &str, texts: &[(f64, String)]) -> Result<(), Failure> {
    flexmb_vtk::write_series(dir, name, texts).map_err(vtk_err)?;
    say!(
        "wrote {} ({} VTU file(s))",
        dir.join(format!("{name}.pvd")).display(),
        texts.len()
    );
    Ok(())
}

/// Writes frames with point data as `dir/NAME_….vtu` and `dir/NAME.pvd`.
fn write_with_data(
    dir: &Path,
    name: &str,
    drawing: &mut Drawing<'_>,
    frames: &Frames,
) -> Result<(), Failure> {
    let texts = frames
        .iter()
        .map(|(t, x, data)| {
            let data: Vec<(&str, Vec<[f64; 3]>)> =
                data.iter().map(|(n, v)| (n.as_str(), v.clone())).collect();
            drawing.configuration(x, &data, &[]).map(|s| (*t, s))
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(vtk_err)?;
    write_texts(dir, name, &texts)
}

/// The largest node displacement a drawn mode gets: a tenth of the largest
/// extent of the nodes' reference positions (0.1 m for a single point).
pub(crate) fn mode_size(mech: &Mechanism) -> f64 {
    let extent = (0..3)
        .map(|d| {
            let c = mech
                .nodes
                .iter()
                .map(|n| n.at.get(d).copied().unwrap_or(0.0));
            c.clone().fold(f64::NEG_INFINITY, f64::max) - c.fold(f64::INFINITY, f64::min)
        })
        .filter(|e| e.is_finite())
        .fold(0.0, f64::max);
    if extent > 0.0 {
        0.1 * extent
    } else {
        0.1
    }
}

/// The nodal coordinates x at the DOFs `q` (loads and inputs at `t`) and
/// the mode shapes `vectors` (in q, one a column) in nodal coordinates,
/// F,q V ([`flexmb_linearize::nodal_mode_shapes`]), solved by `dy`'s own
/// kinematics from its current configuration (a sweep's previous point).
pub(crate) fn nodal_modes(
    dy: &mut Dynamics,
    t: f64,
    q: &[f64],
    vectors: &Mat<f64>,
) -> Result<(Vec<f64>, Mat<f64>), Failure> {
    dy.kinematics_mut()
        .solve(q, t)
        .map_err(|e| Failure::Compute(format!("--vtk: the configuration of the modes: {e}")))?;
    let x = dy.kinematics().x().to_vec();
    let shapes = flexmb_linearize::nodal_mode_shapes(dy, vectors);
    Ok((x, shapes))
}

/// Mode `j` of `shapes` (n_x × k) with the sign that makes its largest
/// entry positive, so that a mode keeps its sign along a sweep where it
/// changes little.
fn signed_mode(shapes: &Mat<f64>, j: usize) -> Vec<f64> {
    let v: Vec<f64> = (0..shapes.nrows()).map(|i| shapes[(i, j)]).collect();
    let big = v
        .iter()
        .copied()
        .fold(0.0f64, |a, b| if b.abs() > a.abs() { b } else { a });
    if big < 0.0 {
        v.iter().map(|c| -c).collect()
    } else {
        v
    }
}

/// The point displacements of each mode in `shapes` at `x`, as point data
/// `mode_1`, `mode_2`, …, each scaled to the largest node displacement
/// `size` (FE nodes of superelement meshes: recovered at that amplitude,
/// [`Drawing::displacements`]).
fn mode_fields(
    drawing: &mut Drawing<'_>,
    mech: &Mechanism,
    x: &[f64],
    shapes: &Mat<f64>,
    size: f64,
) -> Result<PointData, Failure> {
    (0..shapes.ncols())
        .map(|j| {
            let v = signed_mode(shapes, j);
            let d = flexmb_vtk::node_vectors(mech, &v).map_err(vtk_err)?;
            let max = flexmb_vtk::largest_length(&d);
            let a = if max > 0.0 { size / max } else { 0.0 };
            Ok((
                format!("mode_{}", j + 1),
                drawing.displacements(x, &v, a).map_err(vtk_err)?,
            ))
        })
        .collect()
}

/// Frames per period of an animated mode.
const MODE_FRAMES: usize = 24;

/// `eig --vtk`: the configuration x at time `t` (`eig.pvd`, with the modes
/// as point data `mode_1`, …) and each mode K as an animated series over
/// one period (`mode_K.pvd`, point data `mode_shape`, field data
/// `frequency_hz`).
pub(crate) fn write_eig(
    out: VtkOut<'_>,
    mech: &Mechanism,
    t: f64,
    x: &[f64],
    shapes: &Mat<f64>,
    frequencies_hz: &[f64],
) -> Result<(), Failure> {
    let size = mode_size(mech);
    let mut drawing = out.drawing(mech)?;
    let fields = mode_fields(&mut drawing, mech, x, shapes, size)?;
    write_with_data(out.dir, "eig", &mut drawing, &[(t, x.to_vec(), fields)])?;
    for (j, f) in frequencies_hz.iter().enumerate() {
        let name = format!("mode_{}", j + 1);
        let texts = drawing
            .mode_frames(
                x,
                &signed_mode(shapes, j),
                size,
                MODE_FRAMES,
                &[("frequency_hz", *f)],
            )
            .map_err(vtk_err)?;
        write_texts(out.dir, &name, &texts)?;
    }
    Ok(())
}

/// `sweep --vtk`: the equilibrium at each sweep point (parameter value s, x,
/// modes in nodal coordinates) as one series `sweep.pvd` with the
/// parameter as the time value and the modes as point data `mode_1`, ….
pub(crate) fn write_sweep(
    out: VtkOut<'_>,
    mech: &Mechanism,
    points: &[(f64, Vec<f64>, Mat<f64>)],
) -> Result<(), Failure> {
    let size = mode_size(mech);
    let mut drawing = out.drawing(mech)?;
    let frames = points
        .iter()
        .map(|(s, x, shapes)| {
            Ok((
                *s,
                x.clone(),
                mode_fields(&mut drawing, mech, x, shapes, size)?,
            ))
        })
        .collect::<Result<Vec<_>, Failure>>()?;
    write_with_data(out.dir, "sweep", &mut drawing, &frames)
}

/// `sweep --vtk` of the unreduced model: [`write_sweep`] of the points of
/// `flexmb_linearize::sweep_until` (modes kept), each configuration solved
/// from the previous one's (loads and inputs at `t`).
pub(crate) fn write_sweep_points(
    out: VtkOut<'_>,
    mech: &std::sync::Arc<Mechanism>,
    t: f64,
    points: &[flexmb_linearize::SweepPoint],
) -> Result<(), Failure> {
    let mut dy = Dynamics::new(mech.clone());
    let frames = points
        .iter()
        .map(|p| {
            let v = p.modes.as_ref().ok_or_else(|| {
                Failure::Compute("--vtk: the sweep did not keep its mode shapes".into())
            })?;
            let (x, shapes) = nodal_modes(&mut dy, t, &p.q, v)?;
            Ok((p.s, x, shapes))
        })
        .collect::<Result<Vec<_>, Failure>>()?;
    write_sweep(out, mech, &frames)
}

/// `sweep --reduced --vtk`: at each reduced equilibrium (load scale λ, z,
/// x), the lowest `count` modes of the reduced rest linearization (F.7)
/// (M_z, the symmetric part of K_z), taken to q by q̇ = G,z ż
/// ([`MechanicalModel::full_state`](flexmb_reduction::MechanicalModel::full_state))
/// and to nodal coordinates by F,q; then [`write_sweep`].
pub(crate) fn write_reduced_sweep(
    out: VtkOut<'_>,
    model: &mut dyn flexmb_reduction::MechanicalModel,
    t: f64,
    count: usize,
    points: &[flexmb_reduction::SweepPoint],
) -> Result<(), Failure> {
    let fail = |e: String| Failure::Compute(format!("--vtk: the reduced modes: {e}"));
    let mut frames = Vec::with_capacity(points.len());
    for p in points {
        let z = &p.equilibrium.coordinates;
        model.set_load_scale(p.load_scale);
        model
            .dynamics_mut()
            .kinematics_mut()
            .set_guess(&p.equilibrium.x);
        let (m, k) = model.rest_matrices(t, z).map_err(|e| fail(e.to_string()))?;
        let k = Mat::from_fn(k.nrows(), k.ncols(), |i, j| 0.5 * (k[(i, j)] + k[(j, i)]));
        let modes = flexmb_linearize::generalized_symmetric(&k, &m, count)
            .map_err(|e| fail(e.to_string()))?;
        let (q, _) = model.full_state(z, &vec![0.0; z.len()]);
        let columns: Vec<Vec<f64>> = (0..modes.vectors.ncols())
            .map(|j| {
                let zd: Vec<f64> = (0..z.len()).map(|i| modes.vectors[(i, j)]).collect();
                model.full_state(z, &zd).1
            })
            .collect();
        let vq = Mat::from_fn(q.len(), columns.len(), |i, j| columns[j][i]);
        let dy = model.dynamics_mut();
        dy.kinematics_mut().set_guess(&p.equilibrium.x);
        let (x, shapes) = nodal_modes(dy, t, &q, &vq)?;
        frames.push((p.load_scale, x, shapes));
    }
    write_sweep(out, model.mechanism(), &frames)
}
