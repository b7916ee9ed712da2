//! The FE models of the chapter-4 mechanism's members and sheets, and their
//! superelements (thesis §4.2.1–4.2.2), built by flexmb's builder from the
//! built-in 20-node hexahedra.
//!
//! The members' CAD is lost (Fig. 4.2); each is a documented substitute of
//! the kind the text describes (docs/reproduce.md, "Chapter 4"): a
//! thin-walled aluminium box with 1 mm walls and solid steel flexure
//! attachment blocks at its ends, the interfaces; the lower arms with a
//! steel T-profile (torsion release) and notch (out-of-plane bending
//! release) before their end-effector end (Fig. 4.4); the CrossBar a
//! solid steel bar with notches at both ends (Fig. 4.5); the end-effector an
//! aluminium block (a rigid superelement). Point masses on rigid links stand
//! for the actuator coils and encoders. Every part is meshed along x (its
//! length), width along y, height along z, and placed in the mechanism by
//! turning its frame R0 about z ([`placed`]): S̄, M̄ and the FE mesh are in
//! the element frame, so a turned frame is the same part turned.

use super::layout::{cross, unit, HingeKind, Member, V3, Z};
use flexmb_element::{LinearSuperelement, Material};
use flexmb_superelement::solid::{Block, Mesh};
use flexmb_superelement::{BuildSettings, NodeSelection, PointMass};

/// Aluminium (E = 70 GPa, ν = 0.33, ρ = 2700 kg/m³; not given in ch. 4,
/// the values the benchmark specification chooses).
pub fn aluminium() -> Material {
    Material::from_poisson(7.0e10, 0.33, 2700.0)
}

/// Steel as in chapters 2 and 3 (E = 210 GPa, G = 80 GPa, ρ = 7800 kg/m³).
pub fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    }
}

/// The cross-section of a member's box (m): width (in the mechanism plane),
/// height (along z), wall thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxSection {
    /// Outer width (y of the part).
    pub width: f64,
    /// Outer height (z).
    pub height: f64,
    /// Wall thickness.
    pub wall: f64,
}

/// The box of the upper arms: 40 × 70 mm, 1 mm walls.
pub const UPPER_BOX: BoxSection = BoxSection {
    width: 0.040,
    height: 0.070,
    wall: 0.001,
};

/// The box of the lower arms: 30 × 50 mm, 1 mm walls.
pub const LOWER_BOX: BoxSection = BoxSection {
    width: 0.030,
    height: 0.050,
    wall: 0.001,
};

/// Length of the solid steel flexure attachment block at each end (m).
pub const END_BLOCK: f64 = 0.008;

/// The lower arms' releases, from their end-effector end inwards (m):
/// the end block, a notch of this length (a 2 mm plate across the arm's
/// width, compliant in out-of-plane bending), a 5 mm solid spacer, a
/// T-profile of [`T_LENGTH`] (2 mm flange and web, compliant in torsion)
/// and another spacer.
pub const NOTCH_LENGTH: f64 = 0.006;
/// Length of the T-profile torsion release (m).
pub const T_LENGTH: f64 = 0.025;
/// Length of the solid spacers around the releases (m).
pub const SPACER: f64 = 0.005;
/// Thickness of notches, flanges and webs (m).
pub const RELEASE_THICKNESS: f64 = 0.002;

/// The CrossBar's section (m): a solid steel bar 10 mm wide, 20 mm high
/// (its twist about its axis, on the torsion of the wire–sheet hinges'
/// sheets, is the internal mode of §4.1.3, which the thesis finds third).
pub const CROSSBAR_SECTION: [f64; 2] = [0.010, 0.020];

/// The end-effector block (m): 60 mm wide, 20 mm high.
pub const END_EFFECTOR_SECTION: [f64; 2] = [0.060, 0.020];

/// Target element size of the member meshes (m).
pub const MEMBER_MESH: f64 = 0.010;

/// The point masses of a member (thesis §4.2.1: coils, encoders): (name,
/// mass, position along the member as a fraction of its length, height z).
/// Values invented (docs/reproduce.md).
pub fn point_masses(m: Member) -> Vec<(&'static str, f64, f64, f64)> {
    let coil_z = 0.5 * UPPER_BOX.height + 0.015;
    match m {
        Member::UpperArmX1 => vec![
            ("x-actuator coil above", 0.25, 0.65, coil_z),
            ("x-actuator coil below", 0.25, 0.65, -coil_z),
            ("encoder", 0.05, 0.85, 0.0),
        ],
        Member::UpperArmY => vec![
            ("y-actuator coil above", 0.25, 0.65, coil_z),
            ("y-actuator coil below", 0.25, 0.65, -coil_z),
            ("encoder", 0.05, 0.85, 0.0),
        ],
        Member::LowerArmY => vec![("encoder", 0.05, 0.3, 0.0)],
        _ => vec![],
    }
}

fn block(min: V3, max: V3, material: usize) -> Block {
    Block { min, max, material }
}

/// The four walls of a box section from x0 to x1.
fn box_walls(x0: f64, x1: f64, s: BoxSection, material: usize) -> Vec<Block> {
    let (y0, y1, z0, z1) = (
        -0.5 * s.width,
        0.5 * s.width,
        -0.5 * s.height,
        0.5 * s.height,
    );
    let w = s.wall;
    vec![
        block([x0, y0, z0], [x1, y1, z0 + w], material),
        block([x0, y0, z1 - w], [x1, y1, z1], material),
        block([x0, y0, z0 + w], [x1, y0 + w, z1 - w], material),
        block([x0, y1 - w, z0 + w], [x1, y1, z1 - w], material),
    ]
}

/// A solid block of the full `width` × `height` section from x0 to x1.
fn solid(x0: f64, x1: f64, width: f64, height: f64, material: usize) -> Block {
    block(
        [x0, -0.5 * width, -0.5 * height],
        [x1, 0.5 * width, 0.5 * height],
        material,
    )
}

/// The blocks of member `m` of length `l` (material 0 aluminium, 1 steel).
pub fn member_blocks(m: Member, l: f64) -> Vec<Block> {
    const AL: usize = 0;
    const ST: usize = 1;
    match m {
        Member::UpperArmX1 | Member::UpperArmX2 | Member::UpperArmY => {
            let s = UPPER_BOX;
            let mut b = box_walls(END_BLOCK, l - END_BLOCK, s, AL);
            b.push(solid(0.0, END_BLOCK, s.width, s.height, ST));
            b.push(solid(l - END_BLOCK, l, s.width, s.height, ST));
            b
        }
        Member::LowerArmX1 | Member::LowerArmX2 | Member::LowerArmY => {
            let s = LOWER_BOX;
            let t = RELEASE_THICKNESS;
            // from the end-effector end (x = l) inwards
            let x_end = l - END_BLOCK;
            let x_notch = x_end - NOTCH_LENGTH;
            let x_sp2 = x_notch - SPACER;
            let x_t = x_sp2 - T_LENGTH;
            let x_sp1 = x_t - SPACER;
            let (hw, hh) = (0.5 * s.width, 0.5 * s.height);
            let mut b = box_walls(END_BLOCK, x_sp1, s, AL);
            b.push(solid(0.0, END_BLOCK, s.width, s.height, ST));
            b.push(solid(x_sp1, x_t, s.width, s.height, ST));
            // T-profile: a flange on top, a web down the middle
            b.push(block([x_t, -hw, hh - t], [x_sp2, hw, hh], ST));
            b.push(block([x_t, -0.5 * t, -hh], [x_sp2, 0.5 * t, hh - t], ST));
            b.push(solid(x_sp2, x_notch, s.width, s.height, ST));
            // notch: a plate across the width, thin in z
            b.push(block([x_notch, -hw, -0.5 * t], [x_end, hw, 0.5 * t], ST));
            b.push(solid(x_end, l, s.width, s.height, ST));
            b
        }
        Member::CrossBar => {
            let [w, h] = CROSSBAR_SECTION;
            let t = RELEASE_THICKNESS;
            let n0 = END_BLOCK;
            let n1 = END_BLOCK + NOTCH_LENGTH;
            vec![
                solid(0.0, n0, w, h, ST),
                block([n0, -0.5 * w, -0.5 * t], [n1, 0.5 * w, 0.5 * t], ST),
                solid(n1, l - n1, w, h, ST),
                block([l - n1, -0.5 * w, -0.5 * t], [l - n0, 0.5 * w, 0.5 * t], ST),
                solid(l - n0, l, w, h, ST),
            ]
        }
        Member::EndEffector => {
            let [w, h] = END_EFFECTOR_SECTION;
            vec![solid(0.0, l, w, h, AL)]
        }
    }
}

/// The mesh of member `m`: its blocks on one tensor grid with elements of
/// at most [`MEMBER_MESH`] along the length and 5 mm across.
pub fn member_mesh(m: Member) -> Result<Mesh, String> {
    let l = m.length();
    Mesh::boxes(
        &member_blocks(m, l),
        &[aluminium(), steel()],
        [MEMBER_MESH, 0.005, 0.005],
    )
    .map_err(|e| format!("{}: {e}", m.name()))
}

fn plane_x(x: f64) -> NodeSelection {
    NodeSelection::NearPlane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: 1e-9,
    }
}

/// The build settings of member `m` (built along x from 0 to its length):
/// boundary nodes at its end faces' centres, the end faces rigid
/// interfaces, constraint modes only (thesis §4.2.1), its point masses on
/// rigid links to the nodes of a 30 mm stretch of the box around them (of
/// its upper or lower half for a mass above or below it).
pub fn member_settings(m: Member) -> BuildSettings {
    let l = m.length();
    let mut s = BuildSettings::new([0.0; 3], [l, 0.0, 0.0], plane_x(0.0), plane_x(l));
    // the members' meshes are large: the recovery of their FE shape is left
    // out of the files (drawn as chords)
    s.fe_mesh = false;
    for (name, mass, at, z) in point_masses(m) {
        let x = at * l;
        s.point_masses.push(PointMass {
            name: name.into(),
            mass,
            position: [x, 0.0, z],
            inertia: None,
            // a mass above (below) the arm on the upper (lower) half's
            // nodes, one on the arm's axis on all of them
            nodes: NodeSelection::InBox {
                min: [x - 0.015, -1.0, if z > 0.0 { 1e-6 } else { -1.0 }],
                max: [x + 0.015, 1.0, if z < 0.0 { -1e-6 } else { 1.0 }],
            },
        });
    }
    s
}

/// The superelement of member `m` as built along x (R0 the identity), with
/// the FE model's element count and the mass (FE and point masses, kg).
pub fn build_member(m: Member) -> Result<(LinearSuperelement, usize, f64), String> {
    let mesh = member_mesh(m)?;
    let model = mesh
        .assemble(m.name())
        .map_err(|e| format!("{}: {e}", m.name()))?;
    let settings = member_settings(m);
    let r =
        flexmb_superelement::build(&model, &settings).map_err(|e| format!("{}: {e}", m.name()))?;
    let mass = r.report.fe_mass + settings.point_masses.iter().map(|p| p.mass).sum::<f64>();
    Ok((r.data, mesh.elements.len(), mass))
}

/// The mesh of one third of a superelement sheet: length, height (y of the
/// part), thickness (z of the part), 4 × 16 × 2 hexahedra as the chapter-3
/// curves (`crate::ch3::CURVE_MESH`).
pub const SHEET_MESH: [usize; 3] = [4, 16, 2];

/// The superelement of one third of the main sheet of a `kind` hinge, with
/// the warping modes (3.4) of both interfaces (thesis §4.2.2), built along
/// x (R0 the identity), with its mass (kg).
pub fn build_sheet_third(kind: HingeKind) -> Result<(LinearSuperelement, f64), String> {
    let s = kind.sheets();
    let mut part = flexmb_superelement::parts::sheet_segment(
        0.0,
        s.length / 3.0,
        s.main,
        s.thickness,
        SHEET_MESH,
        steel(),
    )
    .map_err(|e| format!("{} sheet: {e}", kind.tag()))?;
    part.settings.warping_p = true;
    part.settings.warping_q = true;
    part.settings.fe_mesh = false;
    let model = part
        .mesh
        .assemble(kind.tag())
        .map_err(|e| format!("{} sheet: {e}", kind.tag()))?;
    let r = flexmb_superelement::build(&model, &part.settings)
        .map_err(|e| format!("{} sheet: {e}", kind.tag()))?;
    Ok((r.data, r.report.fe_mass))
}

/// `se` (built along x) placed with its x axis along `x` and its y axis
/// along `y` (global, orthonormal): R0' = [x, y, x × y] R0.
pub fn placed(mut se: LinearSuperelement, x: V3, y: V3) -> LinearSuperelement {
    let z = cross(x, y);
    let rot = [x, y, z];
    let r0 = se.r0;
    // R0'[i][j] = Σ_k rot_col_k[i] r0[k][j]
    se.r0 = std::array::from_fn(|i| {
        std::array::from_fn(|j| (0..3).map(|k| rot[k][i] * r0[k][j]).sum())
    });
    se
}

/// A member placed along the in-plane direction `u`: its width (part y)
/// across the arm in the plane (z × u), its height along global z.
pub fn placed_in_plane(se: LinearSuperelement, u: V3) -> LinearSuperelement {
    let u = unit(u);
    placed(se, u, cross(Z, u))
}

/// A sheet placed along the in-plane direction `s`: its height (part y)
/// along global z, its thickness (part z) in the plane.
pub fn placed_sheet(se: LinearSuperelement, s: V3) -> LinearSuperelement {
    placed(se, unit(s), Z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The placement turns the frame and nothing else: R0' is orthonormal,
    /// its x axis the given direction; S̄ and M̄ are unchanged.
    #[test]
    fn placement_turns_the_frame_only() {
        let part =
            flexmb_superelement::parts::prismatic_bar(0.1, 0.01, 0.02, [2, 1, 1], steel()).unwrap();
        let model = part.mesh.assemble("bar").unwrap();
        let se = flexmb_superelement::build(&model, &part.settings)
            .unwrap()
            .data;
        let u = unit([-1.0, 2.0, 0.0]);
        let p = placed_in_plane(se.clone(), u);
        for i in 0..3 {
            assert!((p.r0[i][0] - u[i]).abs() < 1e-15);
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| p.r0[k][i] * p.r0[k][j]).sum();
                assert!((dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-15);
            }
        }
        assert_eq!(p.s_bar, se.s_bar);
        assert_eq!(p.m_bar, se.m_bar);
        let sh = placed_sheet(se, u);
        assert_eq!([sh.r0[0][1], sh.r0[1][1], sh.r0[2][1]], Z);
    }

    /// Every member's blocks mesh, and the lower arms' and CrossBar's
    /// releases are inside their length.
    #[test]
    fn member_blocks_fit_their_lengths() {
        for m in Member::ALL {
            let l = m.length();
            for b in member_blocks(m, l) {
                assert!(b.min[0] >= -1e-15 && b.max[0] <= l + 1e-15, "{}", m.name());
                assert!(b.max[0] > b.min[0]);
            }
        }
    }
}
