//! `--vtk DIR`: the configurations of a command as VTU files with a PVD
//! collection (crate `flexmb-vtk`), for ParaView or pyvista.

use crate::out::say;
use crate::Failure;
use flexmb_model::Mechanism;
use std::path::Path;

/// Writes `frames` (time, nodal coordinates x) of `mech` as `dir/NAME_….vtu`
/// and `dir/NAME.pvd`.
pub(crate) fn write(
    dir: &Path,
    name: &str,
    mech: &Mechanism,
    frames: &[(f64, &[f64])],
) -> Result<(), Failure> {
    let texts = frames
        .iter()
        .map(|(t, x)| flexmb_vtk::configuration(mech, x, &[]).map(|s| (*t, s)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| Failure::Compute(e.to_string()))?;
    flexmb_vtk::write_series(dir, name, &texts).map_err(|e| Failure::Compute(e.to_string()))?;
    say!(
        "wrote {} ({} VTU file(s))",
        dir.join(format!("{name}.pvd")).display(),
        texts.len()
    );
    Ok(())
}
