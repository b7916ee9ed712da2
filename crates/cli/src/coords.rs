//! Coordinates and deformations by the names `flexmb info` prints (`S.x`,
//! `flexure1.3.bending_z_p`).

use crate::Failure;
use flexmb_model::{Component, Mechanism, Select};

/// The scene selection (`Coord(..)` or `Def(..)`, as written in a scene's
/// `dofs_first`) of the nodal coordinate or deformation called `name`, or
/// `None` if the scene has no such coordinate.
pub(crate) fn selection(mech: &Mechanism, name: &str) -> Result<Option<Select>, Failure> {
    let bad = || Failure::Input(format!("bad coordinate '{name}'"));
    if mech.x_names.iter().any(|x| x == name) {
        let (node, comp) = name.rsplit_once('.').ok_or_else(bad)?;
        let c = match comp {
            "x" => Component::X,
            "y" => Component::Y,
            "z" => Component::Z,
            "angle" => Component::Angle,
            l if l.starts_with('l') => Component::Lambda(l[1..].parse().map_err(|_| bad())?),
            _ => return Err(bad()),
        };
        return Ok(Some(Select::Coord(node.to_string(), c)));
    }
    if let Some(j) = mech.eps_names.iter().position(|x| x == name) {
        let e = mech
            .elements
            .iter()
            .find(|e| e.eps_offset <= j && j < e.eps_offset + e.element.n_eps())
            .ok_or_else(bad)?;
        return Ok(Some(Select::Def(
            e.id.clone(),
            e.element.deformation_names()[j - e.eps_offset].clone(),
        )));
    }
    Ok(None)
}

/// The index of the degree of freedom called `name`. `option` names the
/// command-line option it came from, for the message. A coordinate of the
/// scene that is not a degree of freedom gets the `dofs_first` entry that
/// makes it one; an unknown name points to `flexmb info`.
pub(crate) fn dof_index(mech: &Mechanism, name: &str, option: &str) -> Result<usize, Failure> {
    if let Some(k) = mech
        .dofs
        .iter()
        .position(|c| mech.coordinate_name(*c) == name)
    {
        return Ok(k);
    }
    Err(Failure::Input(match selection(mech, name)? {
        Some(sel) => format!(
            "{option} '{name}' is a coordinate of the scene but not one of its degrees of freedom; \
             make it one by adding `dofs_first: [{sel:?}]` to the scene (for an interpolated basis \
             the thesis also uses `dofs: NodalCoordinates`), then build the model from that scene"
        ),
        None => format!(
            "{option}: unknown coordinate '{name}' (`flexmb info SCENE` lists the degrees of freedom)"
        ),
    }))
}
