//! The superelements of chapter 2, each built by flexmb's superelement
//! builder from a solid FE model (built-in 20-node hexahedra), as the thesis
//! built its own from Ansys models (§2.4): constraint modes only (rigid
//! interfaces, §2.2), thesis (2.17).

use flexmb_element::{LinearSuperelement, Material};
use flexmb_superelement::parts::{self, Part, ShaftHalf};
use flexmb_superelement::{build, spec, BuildResult};
use std::path::Path;

/// The aluminium of the spin-up benchmarks (Kane, Ryan and Banerjee, thesis ref. 45):
/// E = 6.895e10 Pa, ρ = 2766.67 kg/m³, ν = 0.3 (G = E/2.6).
pub fn aluminium() -> Material {
    Material {
        e: 6.895e10,
        g: 6.895e10 / 2.6,
        rho: 2766.67,
    }
}

/// The steel of Table 2.2 (E = 2.1e11 Pa, G = 8.0e10 Pa, ρ = 7800 kg/m³),
/// the same as chapters 3 and 4 use.
pub use crate::ch4::parts::steel;

/// How half of the unbalanced shaft is meshed
/// ([`parts::unbalanced_shaft_half`]): `section` × `section` elements
/// across the cylinder, `rod` along the rod (2 × 2 across it), `cylinder`
/// along the half cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShaftMesh {
    /// Elements across the cylinder's section (each way).
    pub section: usize,
    /// Elements along the rod.
    pub rod: usize,
    /// Elements along the half cylinder.
    pub cylinder: usize,
}

/// How a prismatic segment is meshed: `per_metre` elements per metre along
/// its length (at least 2 per segment), `across` elements across the section
/// (y, z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentMesh {
    /// Elements per metre along x.
    pub per_metre: f64,
    /// Elements across the section along y and z.
    pub across: [usize; 2],
}

impl SegmentMesh {
    /// The elements along a segment of length `l`.
    pub fn along(&self, l: f64) -> usize {
        ((self.per_metre * l).round() as usize).max(2)
    }
}

/// A built superelement with what the report says about its FE model.
pub struct Built {
    /// The superelement data.
    pub data: LinearSuperelement,
    /// Mesh: nodes, elements, equations.
    pub mesh: String,
    /// The FE model's own first clamped-free frequencies (Hz), when computed.
    pub fe_frequencies: Vec<f64>,
    /// Build wall time (s).
    pub seconds: f64,
}

fn finish(part: &Part, name: &str, fe_modes: usize) -> Result<Built, String> {
    let start = std::time::Instant::now();
    let model = part
        .mesh
        .assemble(name)
        .map_err(|e| format!("{name}: {e}"))?;
    let r: BuildResult = build(&model, &part.settings).map_err(|e| format!("{name}: {e}"))?;
    let fe_frequencies = if fe_modes > 0 {
        flexmb_superelement::full_model_clamped_free_frequencies(&model, &part.settings, fe_modes)
            .map_err(|e| format!("{name}: {e}"))?
    } else {
        vec![]
    };
    Ok(Built {
        mesh: format!(
            "{} twenty-node hexahedra, {} nodes, {} equations",
            part.mesh.elements.len(),
            part.mesh.coords.len(),
            model.n_eq()
        ),
        data: r.data,
        fe_frequencies,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// A prismatic beam segment along x of length `l` with a `by` × `bz` section
/// (by along global y), optionally with its direction reversed (p at x = l,
/// thesis Fig. 2.11), and the FE model's first `fe_modes` clamped-free
/// frequencies.
pub fn beam_segment(
    l: f64,
    by: f64,
    bz: f64,
    mesh: SegmentMesh,
    reversed: bool,
    fe_modes: usize,
) -> Result<Built, String> {
    let n = [mesh.along(l), mesh.across[0], mesh.across[1]];
    let part = parts::prismatic_bar(l, by, bz, n, aluminium()).map_err(|e| e.to_string())?;
    let part = if reversed { part.reversed() } else { part };
    finish(&part, "segment", fe_modes)
}

/// Half of the unbalanced shaft of Table 2.2 with a rod of length
/// `rod_len`, built with p at the rod's end and q at the middle or, when
/// `joined_at_p`, the other way round (thesis Fig. 2.16).
pub fn shaft_half(
    half: ShaftHalf,
    rod_len: f64,
    mesh: ShaftMesh,
    joined_at_p: bool,
) -> Result<Built, String> {
    let part = parts::unbalanced_shaft_half(
        half,
        rod_len,
        mesh.section,
        mesh.rod,
        mesh.cylinder,
        steel(),
    )
    .map_err(|e| e.to_string())?;
    let part = if joined_at_p { part.reversed() } else { part };
    finish(&part, "shaft half", 0)
}

/// Writes a superelement file.
pub fn write(dir: &Path, file: &str, se: &LinearSuperelement) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    spec::write_ron(&dir.join(file), se).map_err(|e| format!("{file}: {e}"))
}
