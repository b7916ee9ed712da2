//! The readers on real files written by Abaqus and ANSYS
//! (`fixtures/fe-exports/`, with their README and reference frequencies):
//! the same rotor exported by both packages, and a C3D10 block from Abaqus.

use faer::Mat;
use flexmb_superelement::abaqus::read_abaqus;
use flexmb_superelement::ansys::{parse_ansys, read_ansys, AnsysFiles};
use flexmb_superelement::harwell_boeing::write_harwell_boeing;
use flexmb_superelement::{build, BuildSettings, FeModel, NodeSelection, Spec};
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/fe-exports")
}

/// The free-free frequencies of the rotor (README): six rigid modes, then these (Hz).
const ROTOR_HZ: [f64; 6] = [104.6370, 104.6370, 187.8241, 212.3297, 224.5521, 238.6879];

fn ansys_files() -> [PathBuf; 5] {
    let a = dir().join("ansys");
    [
        a.join("rotorAnsysStiffnessMatrixSparse.txt"),
        a.join("rotorAnsysMassMatrixSparse.txt"),
        a.join("rotorAnsysMatrixDofMappingVector.txt"),
        a.join("rotorAnsysNodalCoordinates.txt"),
        a.join("rotorAnsysElements.txt"),
    ]
}

fn ansys_rotor() -> FeModel {
    let p = ansys_files();
    read_ansys(
        "rotor",
        AnsysFiles {
            k: &p[0],
            m: &p[1],
            mapping: &p[2],
            nodes: &p[3],
            elements: Some(&p[4]),
        },
    )
    .unwrap()
}

fn abaqus_rotor() -> FeModel {
    let a = dir().join("abaqus");
    read_abaqus(
        &a.join("rotorDiscTest.inp"),
        &a.join("rotorDiscTestSTIF1.mtx"),
        &a.join("rotorDiscTestMASS1.mtx"),
    )
    .unwrap()
    .0
}

fn dense(a: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Mat<f64> {
    // the model stores the upper triangle
    let n = a.nrows();
    let mut d = Mat::zeros(n, n);
    for j in 0..n {
        for p in a.col_range(j) {
            let i = a.symbolic().row_idx()[p];
            d[(i, j)] = a.val()[p];
            d[(j, i)] = a.val()[p];
        }
    }
    d
}

/// Free-free frequencies (Hz), signed: a negative eigenvalue gives −√|λ|/2π.
fn frequencies(model: &FeModel) -> Vec<f64> {
    let n = model.n_eq();
    let (k, m) = (dense(model.k()), dense(model.m()));
    let l =
        flexmb_linalg::generalized_eigen(k.as_ref(), m.as_ref(), n, flexmb_linalg::Definite::Mass)
            .unwrap()
            .values;
    l.iter()
        .map(|&x| x.signum() * x.abs().sqrt() / (2.0 * std::f64::consts::PI))
        .collect()
}

/// Six rigid modes below `rigid` Hz, then the reference × `factor`.
fn assert_rotor_frequencies(f: &[f64], factor: f64, rigid: f64, what: &str) {
    assert_eq!(f.len(), 345, "{what}");
    for (k, x) in f[..6].iter().enumerate() {
        assert!(x.abs() < rigid, "{what}: rigid mode {k} at {x} Hz");
    }
    for (k, (x, r)) in f[6..12].iter().zip(ROTOR_HZ).enumerate() {
        assert!(
            (x - factor * r).abs() < 1e-4 * factor,
            "{what}: f{} = {x} Hz, reference {} Hz",
            k + 7,
            factor * r
        );
    }
}

#[test]
fn the_ansys_rotor_has_the_reference_frequencies() {
    let model = ansys_rotor();
    assert_eq!((model.n_nodes(), model.n_eq()), (115, 345));
    assert_rotor_frequencies(&frequencies(&model), 1.0, 1e-3, "ANSYS rotor");
    // the element list gives the volume: 8 × 0.1 × 0.1 × 0.5 shaft + discs, and steel
    let v = model.volume.unwrap();
    let mass = model.translational_mass()[0];
    assert!(
        (mass / v - 7850.0).abs() < 1.0,
        "density {} from M over the Hex8 volume {v}",
        mass / v
    );
}

#[test]
fn the_abaqus_rotor_has_ten_times_the_frequencies_and_the_ansys_ones_scaled() {
    let mut model = abaqus_rotor();
    assert_eq!((model.n_nodes(), model.n_eq()), (115, 345));
    // Abaqus's K carries single-precision-level noise (off-diagonal entries of
    // 2⁻²³ = 1.19e-7 where the ANSYS K has zeros): its rigid modes come out
    // at up to 0.81 Hz, 8e-4 of the first flexible one
    assert_rotor_frequencies(&frequencies(&model), 10.0, 1.0, "Abaqus rotor, E = 2.1e11");
    // its mass is the deck's volume × density
    let rb = model
        .compare_rigid_body()
        .expect("elements and densities are known");
    assert!(
        (rb.from_m.mass / rb.from_mesh.mass - 1.0).abs() < 1e-6,
        "{rb:?}"
    );
    model.rescale(1.0, 1e-2, 1.0).unwrap();
    assert_rotor_frequencies(&frequencies(&model), 1.0, 0.1, "Abaqus rotor × 1e-2");
}

/// Interfaces at the shaft ends z = 0 and z = 0.5 m.
fn rotor_settings() -> BuildSettings {
    let plane = |z: f64| NodeSelection::NearPlane {
        point: [0.0, 0.0, z],
        normal: [0.0, 0.0, 1.0],
        tolerance: 1e-6,
    };
    BuildSettings::new([0.0, 0.0, 0.0], [0.0, 0.0, 0.5], plane(0.0), plane(0.5))
}

/// The reduced matrices with constraint modes agree to 1e-6; with normal
/// modes, their frequencies do (the modes themselves are scaled to a unit
/// largest displacement, which is arbitrary within the rotor's degenerate
/// bending pairs, so their S̄ and M̄ entries are not comparable one by one).
#[test]
fn superelements_built_from_either_export_agree() {
    let a = ansys_rotor();
    let mut b = abaqus_rotor();
    b.rescale(1.0, 1e-2, 1.0).unwrap();
    let s = rotor_settings();
    let (sa, sb) = (build(&a, &s).unwrap(), build(&b, &s).unwrap());
    let rel = |x: &nalgebra::DMatrix<f64>, y: &nalgebra::DMatrix<f64>| {
        (x - y).abs().max() / x.abs().max()
    };
    let to_na = |v: &[Vec<f64>]| nalgebra::DMatrix::from_fn(v.len(), v.len(), |i, j| v[i][j]);
    let e = rel(&to_na(&sa.data.s_bar), &to_na(&sb.data.s_bar));
    assert!(
        e < 1e-6,
        "S̄ differs by {e:e} (relative to its largest entry)"
    );
    let e = rel(&sa.data.m_bar_matrix(), &sb.data.m_bar_matrix());
    assert!(e < 1e-6, "M̄ differs by {e:e}");
    assert!((sa.data.l0 - 0.5).abs() < 1e-12);
    let mut s4 = s.clone();
    s4.normal_modes = 4;
    let (fa, fb) = (
        build(&a, &s4).unwrap().report,
        build(&b, &s4).unwrap().report,
    );
    assert_eq!(fa.normal_frequencies_hz.len(), 4);
    for (x, y) in fa
        .normal_frequencies_hz
        .iter()
        .zip(&fb.normal_frequencies_hz)
    {
        assert!(
            (x / y - 1.0).abs() < 1e-6,
            "fixed-interface frequencies {:?} and {:?}",
            fa.normal_frequencies_hz,
            fb.normal_frequencies_hz
        );
    }
}

#[test]
fn the_abaqus_block_reads_and_its_mass_is_volume_times_density() {
    let a = dir().join("abaqus");
    let (model, mesh) = read_abaqus(
        &a.join("blockC3D10.inp"),
        &a.join("blockC3D10_STIF1.mtx"),
        &a.join("blockC3D10_MASS1.mtx"),
    )
    .unwrap();
    assert_eq!((model.n_nodes(), model.n_eq()), (257, 771));
    // a 4 × 1 × 1 block of C3D10, density 2900
    let v = mesh.volume().unwrap();
    assert!((v - 4.0).abs() < 1e-9, "volume {v}");
    for m in model.translational_mass() {
        assert!(
            (m / (v * 2900.0) - 1.0).abs() < 1e-9,
            "mass {m} against {}",
            v * 2900.0
        );
    }
    model.check_consistency().unwrap();
}

/// The built-in FE on the Abaqus block's own mesh (the deck read as a mesh
/// by `ModelSource::Mesh`, E = 2e11 Pa, ν = 0.3, ρ = 2900 kg/m³ as in the
/// deck) against the matrices Abaqus exported for it, an independent code:
/// K equal to rounding (both integrate C3D10 at 4 points), so the
/// superelements with constraint modes have the same S̄; Abaqus integrates
/// the mass with more points, which moves M̄ but not the rigid-body mass,
/// centre of mass and inertia (exact for straight-edged elements in both).
#[test]
fn the_builtin_fe_on_the_abaqus_block_mesh_gives_abaqus_stiffness() {
    let a = dir().join("abaqus");
    let (abaqus, _) = read_abaqus(
        &a.join("blockC3D10.inp"),
        &a.join("blockC3D10_STIF1.mtx"),
        &a.join("blockC3D10_MASS1.mtx"),
    )
    .unwrap();
    let spec = Spec::from_ron(
        r#"(name: "block", model: Mesh(file: "abaqus/blockC3D10.inp", material: (e: 2e11, nu: 0.3, rho: 2900.0)),
            settings: (p: (0.0, 0.5, 0.5), q: (4.0, 0.5, 0.5),
                       interface_p: NearPlane(point: (0.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-6),
                       interface_q: NearPlane(point: (4.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-6)),
            output: "unused.se.ron")"#,
        "block.spec.ron",
    )
    .unwrap();
    let (own, files) = flexmb_superelement::spec::load_model(&spec, &dir()).unwrap();
    assert_eq!(files, vec![a.join("blockC3D10.inp")]);
    assert_eq!((own.n_nodes(), own.n_eq()), (257, 771));
    // K entry by entry, nodes matched by label
    let (ka, ko) = (dense(abaqus.k()), dense(own.k()));
    let eq =
        |m: &FeModel, label: u64, d: usize| m.dofs().eq(m.node_index(label).unwrap(), d).unwrap();
    let (mut diff, mut scale) = (0.0f64, 0.0f64);
    for &li in abaqus.node_ids() {
        for &lj in abaqus.node_ids() {
            for di in 0..3 {
                for dj in 0..3 {
                    let x = ka[(eq(&abaqus, li, di), eq(&abaqus, lj, dj))];
                    let y = ko[(eq(&own, li, di), eq(&own, lj, dj))];
                    diff = diff.max((x - y).abs());
                    scale = scale.max(x.abs());
                }
            }
        }
    }
    println!(
        "K: largest difference {:.2e} of the largest entry",
        diff / scale
    );
    assert!(
        diff < 1e-13 * scale,
        "K differs by {:e} of its largest entry",
        diff / scale
    );
    let (x, y) = (
        build(&abaqus, &spec.settings).unwrap(),
        build(&own, &spec.settings).unwrap(),
    );
    let (sa, so) = (x.data.s_bar_matrix(), y.data.s_bar_matrix());
    let w = (0..6)
        .flat_map(|i| (0..6).map(move |j| (i, j)))
        .map(|(i, j)| (sa[(i, j)] - so[(i, j)]).abs() / (sa[(i, i)] * sa[(j, j)]).sqrt())
        .fold(0.0f64, f64::max);
    println!("S̄: largest difference {w:.2e} (scaled by the diagonal)");
    assert!(w < 1e-10, "S̄ differs by {w:e}");
    let rb = |r: &flexmb_superelement::BuildResult| {
        flexmb_superelement::RigidBodyProperties::from_m_bar(&r.data.m_bar_matrix(), r.data.l0)
    };
    let (ra, ro) = (rb(&x), rb(&y));
    assert!(
        (ra.mass / ro.mass - 1.0).abs() < 1e-12,
        "{} {}",
        ra.mass,
        ro.mass
    );
    for d in 0..3 {
        assert!(
            (ra.com[d] - ro.com[d]).abs() < 1e-12,
            "{:?} {:?}",
            ra.com,
            ro.com
        );
        for e in 0..3 {
            assert!((ra.inertia[d][e] - ro.inertia[d][e]).abs() < 1e-9 * ra.inertia[0][0]);
        }
    }
}

#[test]
fn files_that_do_not_belong_together_are_named() {
    let a = dir().join("abaqus");
    // the block's mass with the rotor's deck and stiffness
    let e = read_abaqus(
        &a.join("rotorDiscTest.inp"),
        &a.join("rotorDiscTestSTIF1.mtx"),
        &a.join("blockC3D10_MASS1.mtx"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("blockC3D10_MASS1.mtx has 771 equations") && e.contains("another model"),
        "{e}"
    );
    // the rotor's matrices with the block's deck
    let e = read_abaqus(
        &a.join("blockC3D10.inp"),
        &a.join("rotorDiscTestSTIF1.mtx"),
        &a.join("rotorDiscTestMASS1.mtx"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("257 nodes") && e.contains("FORMAT=LABELS"),
        "{e}"
    );
    // an ANSYS mapping vector cut short
    let p = ansys_files();
    let text = |i: usize| std::fs::read_to_string(&p[i]).unwrap();
    let map = text(2);
    let short = map.replacen("115 1", "114 1", 1);
    let short: String = short
        .lines()
        .take(short.lines().count() - 1)
        .map(|l| format!("{l}\n"))
        .collect();
    let e = parse_ansys(
        "rotor",
        [
            (&text(0), "k.txt"),
            (&text(1), "m.txt"),
            (&short, "map.txt"),
            (&text(3), "nodes.txt"),
        ],
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("map.txt maps 114 nodes") && e.contains("345 equations"),
        "{e}"
    );
}

/// The node label of each equation and the triplets of a model's matrix.
fn labelled(model: &FeModel, upper: bool) -> (String, Vec<(usize, usize, f64)>) {
    let a = if upper { model.k() } else { model.m() };
    let mut text = String::new();
    let mut entries = Vec::new();
    for j in 0..a.ncols() {
        for p in a.col_range(j) {
            let i = a.symbolic().row_idx()[p];
            let (ni, di) = model.dofs().dof(i);
            let (nj, dj) = model.dofs().dof(j);
            let (li, lj) = (model.node_ids()[ni], model.node_ids()[nj]);
            text.push_str(&format!(
                "ROTOR-1.{li}, {}, ROTOR-1.{lj}, {}, {:e}\n",
                di + 1,
                dj + 1,
                a.val()[p]
            ));
            entries.push((i, j, a.val()[p]));
        }
    }
    (text, entries)
}

#[test]
fn labels_and_harwell_boeing_exports_of_the_rotor_give_the_same_model() {
    let model = abaqus_rotor();
    let dir = std::env::temp_dir().join(format!("flexmb-fe-exports-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // FORMAT=LABELS (one triangle, instance-qualified labels)
    let (k, ke) = labelled(&model, true);
    let (m, me) = labelled(&model, false);
    std::fs::write(dir.join("K.mtx"), &k).unwrap();
    std::fs::write(dir.join("M.mtx"), &m).unwrap();
    let inp = super_dir().join("abaqus/rotorDiscTest.inp");
    let (l, _) = read_abaqus(&inp, &dir.join("K.mtx"), &dir.join("M.mtx")).unwrap();
    assert_eq!(l.node_ids(), model.node_ids());
    assert_eq!(dense(l.k()), dense(model.k()));
    assert_eq!(dense(l.m()), dense(model.m()));
    // Harwell–Boeing with a .mapping file, as ANSYS's HBMAT writes them
    std::fs::write(
        dir.join("K.hb"),
        write_harwell_boeing(model.n_eq(), &ke, "rotor K"),
    )
    .unwrap();
    std::fs::write(
        dir.join("M.hb"),
        write_harwell_boeing(model.n_eq(), &me, "rotor M"),
    )
    .unwrap();
    let mut mapping = String::from(" Matrix Eqn   Node   DOF\n");
    for e in 0..model.n_eq() {
        let (n, d) = model.dofs().dof(e);
        mapping.push_str(&format!(
            "{:>8} {:>8}     {}\n",
            e + 1,
            model.node_ids()[n],
            ["UX", "UY", "UZ"][d as usize]
        ));
    }
    std::fs::write(dir.join("K.mapping"), mapping).unwrap();
    let mut nodes = String::from("Knotennummer\tX\tY\tZ\n");
    for (id, x) in model.node_ids().iter().zip(model.coords()) {
        nodes.push_str(&format!("{id}\t{}\t{}\t{}\n", x[0], x[1], x[2]).replace('.', ","));
    }
    std::fs::write(dir.join("nodes.txt"), nodes).unwrap();
    let h = read_ansys(
        "rotor",
        AnsysFiles {
            k: &dir.join("K.hb"),
            m: &dir.join("M.hb"),
            mapping: &dir.join("K.mapping"),
            nodes: &dir.join("nodes.txt"),
            elements: None,
        },
    )
    .unwrap();
    let (dh, dm) = (dense(h.k()), dense(model.k()));
    let max = (0..345)
        .flat_map(|i| (0..345).map(move |j| (i, j)))
        .fold(0.0f64, |m, (i, j)| {
            m.max((dh[(i, j)] - dm[(i, j)]).abs() / dm[(i, i)].abs())
        });
    assert!(max < 1e-15, "Harwell–Boeing K differs by {max:e}");
    assert_eq!(h.coords(), model.coords());
    std::fs::remove_dir_all(&dir).ok();
}

fn super_dir() -> PathBuf {
    dir()
}

#[test]
fn a_spec_sets_the_units_and_the_stiffness_scale() {
    let base = dir().join("abaqus");
    let spec = |extra: &str| {
        Spec::from_ron(
            &format!(
                r#"(
                name: "rotor",
                model: Abaqus(inp: "rotorDiscTest.inp", k: "rotorDiscTestSTIF1.mtx", m: "rotorDiscTestMASS1.mtx"),
                {extra}
                settings: (p: (0.0, 0.0, 0.0), q: (0.0, 0.0, 0.5),
                    interface_p: NearPlane(point: (0.0, 0.0, 0.0), normal: (0.0, 0.0, 1.0), tolerance: 1e-6),
                    interface_q: NearPlane(point: (0.0, 0.0, 0.5), normal: (0.0, 0.0, 1.0), tolerance: 1e-6)),
                output: "unused.se.ron",
            )"#
            ),
            "spec.ron",
        )
        .unwrap()
    };
    let (m, _) =
        flexmb_superelement::spec::load_model(&spec("stiffness_scale: Some(1e-2),"), &base)
            .unwrap();
    assert_rotor_frequencies(&frequencies(&m), 1.0, 0.1, "spec with stiffness_scale 1e-2");
    // read as mm-t-s, the same numbers are a 0.5 mm rotor of 7.85e12 kg/m³
    let (m, _) =
        flexmb_superelement::spec::load_model(&spec("units: Some(\"mm-t-s\"),"), &base).unwrap();
    assert!(
        (m.coords()[32][2] - 0.5e-3).abs() < 1e-12,
        "{:?}",
        m.coords()[32]
    );
    let e = flexmb_superelement::spec::load_model(&spec("units: Some(\"mm-ton-s\"),"), &base)
        .unwrap_err()
        .to_string();
    assert!(e.contains("did you mean \"mm-t-s\""), "{e}");
    let e = flexmb_superelement::spec::load_model(&spec("stiffness_scale: Some(-1.0),"), &base)
        .unwrap_err()
        .to_string();
    assert!(e.contains("stiffness scale of -1"), "{e}");
}

/// The same rotor written in mm–t–s (coordinates in mm, M in t, K in N/mm)
/// and read as SI: the density check names the unit system to set, and with
/// it the build agrees with the SI one.
#[test]
fn a_model_in_mm_t_s_read_as_si_is_refused_with_the_units_to_set() {
    let si = ansys_rotor();
    let mut mm = si.clone();
    mm.rescale(1e3, 1e-3, 1e-3).unwrap();
    let s = rotor_settings();
    let plane = |z: f64| NodeSelection::NearPlane {
        point: [0.0, 0.0, z],
        normal: [0.0, 0.0, 1.0],
        tolerance: 1e-3,
    };
    let s_mm = BuildSettings::new([0.0; 3], [0.0, 0.0, 500.0], plane(0.0), plane(500.0));
    let e = build(&mm, &s_mm).unwrap_err().to_string();
    assert!(e.contains("units: Some(\"mm-t-s\")"), "{e}");
    let u = flexmb_superelement::units::UnitSystem::named("mm-t-s").unwrap();
    let (l, k, m) = u.to_si(1.0, 1.0);
    mm.rescale(l, k, m).unwrap();
    let (a, b) = (build(&si, &s).unwrap(), build(&mm, &s).unwrap());
    let d = (0..6)
        .map(|i| (a.data.s_bar[i][i] / b.data.s_bar[i][i] - 1.0).abs())
        .fold(0.0f64, f64::max);
    assert!(d < 1e-12, "{d:e}");
}

/// The material inferred from K and M by linear fields
/// ([`flexmb_superelement::wave_speed`]) against the decks' materials:
/// the Abaqus rotor (steel, E = 2.1e11, ρ = 7850, ν = 0.3), the ANSYS rotor
/// (E = 2.1e9, its README), the C3D10 block (E = 2e11, ρ = 2900, ν = 0.3).
/// The ANSYS rotor's wave speed (517 m/s) is implausible and the advice
/// names the stiffness scale of 100 that makes it steel; the others pass.
#[test]
fn the_linear_field_energies_give_the_decks_material_and_tell_the_stiffness_scale() {
    use flexmb_superelement::wave_speed::infer_material;
    let a = dir().join("abaqus");
    let block = read_abaqus(
        &a.join("blockC3D10.inp"),
        &a.join("blockC3D10_STIF1.mtx"),
        &a.join("blockC3D10_MASS1.mtx"),
    )
    .unwrap()
    .0;
    for (name, model, e, rho) in [
        ("Abaqus rotor", abaqus_rotor(), 2.1e11, 7850.0_f64),
        ("ANSYS rotor", ansys_rotor(), 2.1e9, 7850.0),
        ("C3D10 block", block, 2e11, 2900.0),
    ] {
        let m = infer_material(&model).unwrap_or_else(|| panic!("{name}: no material"));
        let c = (e / rho).sqrt();
        assert!(
            (m.wave_speed / c - 1.0).abs() < 1e-6,
            "{name}: {m:?}, want c = {c}"
        );
        assert!((m.poisson - 0.3).abs() < 1e-6, "{name}: {m:?}");
        assert!(m.anisotropy < 1e-6, "{name}: {m:?}");
        // the mass over the density is the volume
        let young = m.young(m.mass / rho);
        assert!((young / e - 1.0).abs() < 1e-6, "{name}: E = {young}");
        match m.advice() {
            None => assert!(e > 1e10, "{name}: no advice for {m:?}"),
            Some(s) => {
                assert_eq!(name, "ANSYS rotor", "{s}");
                assert!(s.contains("stiffness_scale: Some(1e2)"), "{s}");
            }
        }
    }
    // the build report says it, and warns for the ANSYS rotor only
    let s = rotor_settings();
    let steel = build(&abaqus_rotor(), &s).unwrap().summary("steel");
    assert!(
        steel.contains("wave speed √(E/ρ) = 5.1722e3 m/s"),
        "{steel}"
    );
    assert!(!steel.contains("warning"), "{steel}");
    let soft = build(&ansys_rotor(), &s).unwrap().summary("soft");
    assert!(soft.contains("wave speed √(E/ρ) = 5.1722e2 m/s"), "{soft}");
    assert!(
        soft.contains("warning: ") && soft.contains("Some(1e2)"),
        "{soft}"
    );
}
