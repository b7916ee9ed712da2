//! Readers, the RON spec path and the catalogue of bad inputs (each gives an
//! error naming the culprit, never a panic).

use faer::sparse::{SparseColMat, Triplet};
use flexmb_element::{Material, Side};
use flexmb_superelement::readers::{
    parse_calculix, parse_calculix_dof, parse_inp, parse_matrix_market, read_calculix, read_inp,
    read_matrix_market_model, write_matrix_market, write_nodes,
};
use flexmb_superelement::solid::{Block, Mesh};
use flexmb_superelement::spec::read_ron;
use flexmb_superelement::{
    build, build_from_spec, parts, BuildSettings, DofMap, Error, FeModel, InterfaceMode,
    InterfacePattern, ModelSource, NodeSelection, PointMass, Spec,
};

fn steel() -> Material {
    Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    }
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-se-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn small_bar() -> (FeModel, BuildSettings) {
    let part = parts::prismatic_bar(0.05, 0.01, 0.006, [4, 2, 1], steel()).unwrap();
    (part.mesh.assemble("small").unwrap(), part.settings)
}

/// K, M and nodes written as Matrix Market + node file and read back give the
/// same matrices (17 significant digits) and the same superelement; a spec
/// pointing at them builds, writes RON with provenance, and reads back.
#[test]
fn matrix_market_round_trip_and_spec() {
    let (model, settings) = small_bar();
    let dir = tmp("mm");
    write_matrix_market(&dir.join("k.mtx"), model.k()).unwrap();
    write_matrix_market(&dir.join("m.mtx"), model.m()).unwrap();
    write_nodes(&dir.join("nodes.txt"), model.node_ids(), model.coords()).unwrap();
    let back = read_matrix_market_model(
        "small",
        &dir.join("k.mtx"),
        &dir.join("m.mtx"),
        &dir.join("nodes.txt"),
        None,
    )
    .unwrap();
    assert_eq!(back.n_eq(), model.n_eq());
    let (a, b) = (model.k().to_dense(), back.k().to_dense());
    assert!((&a - &b).norm_l2() <= 1e-15 * a.norm_l2());
    let se1 = build(&model, &settings).unwrap();
    let se2 = build(&back, &settings).unwrap();
    for i in 0..6 {
        for j in 0..6 {
            let (x, y) = (se1.data.s_bar[i][j], se2.data.s_bar[i][j]);
            assert!((x - y).abs() <= 1e-10 * se1.data.s_bar[i][i].abs());
        }
    }
    let spec = Spec {
        name: "small".into(),
        model: ModelSource::MatrixMarket {
            k: "k.mtx".into(),
            m: "m.mtx".into(),
            nodes: "nodes.txt".into(),
            dofs: None,
            volume: Some(0.05 * 0.01 * 0.006),
            density: None,
        },
        units: None,
        stiffness_scale: None,
        mass_scale: None,
        settings: settings.clone(),
        output: "small.se.ron".into(),
        m_bar_matrix_market: Some("m_bar.mtx".into()),
    };
    // the spec itself survives RON
    let text = ron::ser::to_string_pretty(&spec, Default::default()).unwrap();
    assert_eq!(Spec::from_ron(&text, "spec").unwrap(), spec);
    let out = build_from_spec(&spec, &dir).unwrap();
    assert_eq!(out.written.len(), 2);
    let data = read_ron(&dir.join("small.se.ron")).unwrap();
    assert_eq!(data, out.result.data);
    assert!(data
        .provenance
        .sources
        .iter()
        .any(|s| s.starts_with("k.mtx") && s.contains("fnv1a64")));
    data.validate().unwrap();
}

/// A general (full) Matrix Market file with both triangles is accepted; an
/// unsymmetric one is rejected naming the entry.
#[test]
fn matrix_market_general_and_unsymmetric() {
    let full = "%%MatrixMarket matrix coordinate real general\n3 3 5\n1 1 2.0\n1 2 -1.0\n2 1 -1.0\n2 2 2.0\n3 3 1.0\n";
    let a = parse_matrix_market(full, "full.mtx").unwrap();
    assert_eq!(a.compute_nnz(), 5);
    let ids = vec![1];
    let k = a.as_ref();
    let model = FeModel::new("one", ids.clone(), vec![[0.0; 3]], DofMap::full(1), k, k).unwrap();
    assert_eq!(model.k().compute_nnz(), 4);
    let bad = "%%MatrixMarket matrix coordinate real general\n3 3 5\n1 1 2.0\n1 2 -1.0\n2 1 -1.5\n2 2 2.0\n3 3 1.0\n";
    let a = parse_matrix_market(bad, "bad.mtx").unwrap();
    let e = FeModel::new(
        "one",
        ids,
        vec![[0.0; 3]],
        DofMap::full(1),
        a.as_ref(),
        a.as_ref(),
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::NotSymmetric(_))
            && msg.contains("node 1 ux")
            && msg.contains("node 1 uy"),
        "{msg}"
    );
    let e = parse_matrix_market("%%MatrixMarket matrix array real general\n2 2\n", "arr.mtx")
        .unwrap_err();
    assert!(e.to_string().contains("arr.mtx:1") && e.to_string().contains("coordinate"));
}

/// A hand-written CalculiX set: nodes 1, 2, 3, 10 (a tetrahedron), with node
/// 10's uz removed by a boundary condition (absent from .dof/.sti/.mas), "10.1"
/// and "1.1" distinct, exact zeros in .sti, upper triangle column by column.
#[test]
fn calculix_hand_written_set() {
    let inp = "** written by hand\n*NODE, NSET=Nall\n1, 0.0, 0.0, 0.0\n2, 1.0, 0.0, 0.0\n3, 0.0, 1.0, 0.0\n10, \
               0.0, 0.0, 1.0\n*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3, 10\n*NSET, NSET=TOP\n10\n";
    // equations: 1.1 1.2 1.3 2.1 2.2 2.3 3.1 3.2 3.3 10.1 10.2 (10.3 absent)
    let dof = "1.1\n1.2\n1.3\n2.1\n2.2\n2.3\n3.1\n3.2\n3.3\n10.1\n10.2\n";
    let mut sti = String::new();
    let mut mas = String::new();
    for j in 1..=11 {
        for i in 1..=j {
            let v = if i == j {
                4.0 + j as f64
            } else if j - i == 1 {
                -1.0
            } else {
                0.0
            };
            sti.push_str(&format!("{i} {j} {v:.6e}\n"));
            if i == j {
                mas.push_str(&format!("{i} {j} 1.0e-3\n"));
            }
        }
    }
    let (model, mesh) = parse_calculix(&sti, &mas, dof, inp, "hand").unwrap();
    assert_eq!(model.n_eq(), 11);
    let n10 = model.node_index(10).unwrap();
    let n1 = model.node_index(1).unwrap();
    assert_eq!(model.dofs().eq(n10, 0), Some(9));
    assert_eq!(model.dofs().eq(n10, 1), Some(10));
    assert_eq!(
        model.dofs().eq(n10, 2),
        None,
        "10.3 removed by a boundary condition"
    );
    assert_eq!(model.dofs().eq(n1, 0), Some(0));
    // zeros are dropped: 11 diagonal + 10 off-diagonal
    assert_eq!(model.k().compute_nnz(), 21);
    let k = model.k().to_dense();
    assert_eq!(k[(9, 10)], -1.0);
    assert_eq!(k[(10, 10)], 15.0);
    assert!((mesh.volume().unwrap() - 1.0 / 6.0).abs() < 1e-15);
    assert_eq!(mesh.nsets["TOP"], vec![10]);
    // "1.10" is node 1, direction 10, not "1.1"
    let e = parse_calculix_dof("1.1\n1.10\n", "job.dof")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("job.dof:2") && e.contains("'1.10'") && e.contains("direction 10"),
        "{e}"
    );
    // "10.1" and "1.10" differ too: a duplicate "1.1" is caught by the DOF map
    // (with matrices of the same two equations, so that the equation counts agree)
    let two = "1 1 2.0\n1 2 -1.0\n2 2 2.0\n";
    let e = parse_calculix(two, two, "1.1\n1.1\n", inp, "dup")
        .unwrap_err()
        .to_string();
    assert!(e.contains("two equations"), "{e}");
}

fn expect_err(r: Result<impl std::fmt::Debug, Error>, words: &[&str]) -> String {
    let e = r.expect_err("an error was expected");
    let msg = e.to_string();
    for w in words {
        assert!(msg.contains(w), "'{msg}' should mention '{w}'");
    }
    println!("{msg}");
    msg
}

/// Each class of bad input gives a clear error naming the culprit.
#[test]
fn bad_input_catalogue() {
    let (model, settings) = small_bar();
    // mismatched sizes
    let k = SparseColMat::<usize, f64>::try_new_from_triplets(9, 9, &[Triplet::new(0, 0, 1.0)])
        .unwrap();
    expect_err(
        FeModel::new(
            "m",
            vec![1, 2, 3, 4],
            vec![[0.0; 3]; 4],
            DofMap::full(4),
            k.as_ref(),
            k.as_ref(),
        ),
        &["stiffness K is 9 × 9", "12 equations"],
    );
    // interface with fewer than 3 nodes / collinear nodes
    let mut s = settings.clone();
    s.interface_p = NodeSelection::Ids(vec![1, 2]);
    expect_err(
        build(&model, &s),
        &["interface p", "2 node(s)", "3 non-collinear"],
    );
    let line: Vec<u64> = (0..model.n_nodes())
        .filter(|&i| {
            let c = model.coords()[i];
            c[0] == 0.0 && c[2] == -0.003
        })
        .map(|i| model.node_ids()[i])
        .collect();
    s.interface_p = NodeSelection::Ids(line);
    expect_err(build(&model, &s), &["interface p", "collinear"]);
    // unknown node label
    s.interface_p = NodeSelection::Ids(vec![1, 2, 999_999]);
    expect_err(build(&model, &s), &["999999"]);
    // a part not attached: a second, separate box
    let two = Mesh::boxes(
        &[
            Block {
                min: [0.0, -0.005, -0.003],
                max: [0.05, 0.005, 0.003],
                material: 0,
            },
            Block {
                min: [0.1, -0.005, -0.003],
                max: [0.11, 0.005, 0.003],
                material: 0,
            },
        ],
        &[steel()],
        [0.0125, 0.005, 0.006],
    )
    .unwrap()
    .assemble("two pieces")
    .unwrap();
    expect_err(
        build(&two, &settings),
        &["not attached", "not connected to interface p or q"],
    );
    // K not positive semi-definite
    let kk = model.k();
    let trip: Vec<Triplet<usize, usize, f64>> = (0..kk.ncols())
        .flat_map(|j| {
            kk.row_idx_of_col_raw(j)
                .iter()
                .zip(kk.val_of_col(j))
                .map(move |(&i, &v)| Triplet::new(i, j, -v))
        })
        .collect();
    let kneg =
        SparseColMat::<usize, f64>::try_new_from_triplets(kk.nrows(), kk.ncols(), &trip).unwrap();
    let neg = FeModel::new(
        "negated",
        model.node_ids().to_vec(),
        model.coords().to_vec(),
        model.dofs().clone(),
        kneg.as_ref(),
        model.m(),
    )
    .unwrap();
    expect_err(
        build(&neg, &settings),
        &["not positive semi-definite", "node 1 ux"],
    );
    // units: coordinates in mm with SI matrices
    let mut mm = model.clone();
    mm.volume = Some(0.05 * 0.01 * 0.006 * 1e9);
    expect_err(build(&mm, &settings), &["units", "density", "mm"]);
    // linearly dependent modes: the same pattern twice
    let nodes = NodeSelection::NearPlane {
        point: [0.05, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: 1e-9,
    }
    .resolve(&model, "q")
    .unwrap();
    let pts: Vec<[f64; 3]> = nodes.iter().map(|&i| model.coords()[i]).collect();
    let pattern = InterfacePattern {
        displacements: pts.iter().map(|p| [1e-3 * p[1] * p[1], 0.0, 0.0]).collect(),
        points: pts.clone(),
        tolerance: None,
    };
    let mut s = settings.clone();
    for name in ["bulge", "bulge again"] {
        s.interface_modes.push(InterfaceMode {
            side: Side::Q,
            name: name.into(),
            pattern: pattern.clone(),
        });
    }
    expect_err(build(&model, &s), &["linearly dependent", "'bulge again'"]);
    // a rigid-body pattern
    let mut s = settings.clone();
    s.interface_modes.push(InterfaceMode {
        side: Side::Q,
        name: "shift".into(),
        pattern: InterfacePattern {
            displacements: vec![[1e-3, 0.0, 0.0]; pts.len()],
            points: pts.clone(),
            tolerance: None,
        },
    });
    expect_err(build(&model, &s), &["shift", "rigid-body motion"]);
    // point masses: rotary inertia on one node, two nodes
    let inner: Vec<usize> = (0..model.n_nodes())
        .filter(|&i| model.coords()[i][0] > 0.01 && model.coords()[i][0] < 0.04)
        .collect();
    let (n40, n41) = (inner[0], inner[1]);
    let mut s = settings.clone();
    s.point_masses.push(PointMass {
        name: "coil".into(),
        mass: 0.01,
        position: model.coords()[n40],
        inertia: Some([[1e-6, 0.0, 0.0], [0.0, 1e-6, 0.0], [0.0, 0.0, 1e-6]]),
        nodes: NodeSelection::Ids(vec![model.node_ids()[n40]]),
    });
    expect_err(build(&model, &s), &["coil", "rotary inertia"]);
    s.point_masses[0].nodes =
        NodeSelection::Ids(vec![model.node_ids()[n40], model.node_ids()[n41]]);
    expect_err(build(&model, &s), &["coil", "3 non-collinear"]);
    // a parse error names file and line
    let e = parse_calculix(
        "1 1 x\n",
        "1 1 1.0\n",
        "1.1\n",
        "*NODE\n1, 0, 0, 0\n",
        "job",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("job.sti:1") && e.contains("bad value 'x'"),
        "{e}"
    );
}

/// The `.inp` reader on what gmsh and a CalculiX deck look like: the deck
/// `*INCLUDE`s the mesh (relative to the including file, nested), C3D20 lines
/// wrapped after 16 entries with a trailing comma, line and face elements
/// (written by gmsh without physical groups) skipped, a node in no solid
/// element and without equations left out of the model. Includes in text, a
/// missing INPUT=, a missing file and an include cycle give errors.
#[test]
fn inp_includes_and_gmsh_layout() {
    let dir = tmp("inp");
    std::fs::create_dir_all(dir.join("mesh")).unwrap();
    // a unit cube as one C3D20 (gmsh layout), node 99 a stray geometry point
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let edges = [
        (0, 1),
        (1, 2),
        (2, 3),
        (3, 0),
        (4, 5),
        (5, 6),
        (6, 7),
        (7, 4),
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),
    ];
    let mut nodes = String::from("*Heading\n mesh.inp\n*NODE\n");
    let mut c: Vec<[f64; 3]> = corners.to_vec();
    for &(a, b) in &edges {
        c.push(std::array::from_fn(|d| {
            0.5 * (corners[a][d] + corners[b][d])
        }));
    }
    for (i, x) in c.iter().enumerate() {
        nodes.push_str(&format!("{}, {}, {}, {}\n", i + 1, x[0], x[1], x[2]));
    }
    nodes.push_str("99, 5, 5, 5\n");
    let mesh = format!(
        "{nodes}******* E L E M E N T S *************\n\
         *ELEMENT, type=T3D3, ELSET=Line1\n1, 1, 2, 9\n\
         *ELEMENT, type=CPS8, ELSET=Surface1\n2, 1, 2, 3, 4, 9, 10, 11, 12\n\
         *ELEMENT, type=C3D20, ELSET=Volume1\n\
         3, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, \n16, 17, 18, 19, 20\n\
         *ELSET,ELSET=BAR\n3, \n"
    );
    std::fs::write(dir.join("mesh/part.inp"), mesh).unwrap();
    std::fs::write(dir.join("mesh/all.inp"), "*INCLUDE, INPUT=part.inp\n").unwrap();
    let deck = "*INCLUDE, INPUT=mesh/all.inp\n*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3\n\
                *SOLID SECTION, ELSET=BAR, MATERIAL=STEEL\n*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n";
    std::fs::write(dir.join("job.inp"), deck).unwrap();
    // K = M = identity over the 60 equations of nodes 1..20
    let mut dof = String::new();
    let mut diag = String::new();
    for n in 1..=20 {
        for d in 1..=3 {
            dof.push_str(&format!("{n}.{d}\n"));
            let e = 3 * (n - 1) + d;
            diag.push_str(&format!("{e} {e} 1.0\n"));
        }
    }
    for ext in ["sti", "mas"] {
        std::fs::write(dir.join(format!("job.{ext}")), &diag).unwrap();
    }
    std::fs::write(dir.join("job.dof"), &dof).unwrap();
    let (model, mesh) = read_calculix(&dir.join("job"), None).unwrap();
    assert_eq!(
        mesh.files,
        vec![
            dir.join("job.inp"),
            dir.join("mesh/all.inp"),
            dir.join("mesh/part.inp")
        ]
    );
    assert_eq!(mesh.ids.len(), 21);
    assert_eq!(mesh.elements.len(), 1, "only the solid element");
    assert_eq!(mesh.elements[0].0, "C3D20");
    assert_eq!(mesh.elements[0].1, (1..=20).collect::<Vec<u64>>());
    assert_eq!(model.n_nodes(), 20, "the stray node 99 is left out");
    assert!(model.node_index(99).is_none());
    assert_eq!(model.n_eq(), 60);
    assert!((model.volume.unwrap() - 1.0).abs() < 1e-15);
    // the spec path records every file read, the included ones too
    let (_, files) = flexmb_superelement::spec::load_model(
        &Spec {
            name: "cube".into(),
            model: ModelSource::CalculiX {
                job: "job".into(),
                inp: None,
                density: None,
            },
            units: None,
            stiffness_scale: None,
            mass_scale: None,
            settings: BuildSettings::new(
                [0.0; 3],
                [1.0, 0.0, 0.0],
                NodeSelection::Ids(vec![1]),
                NodeSelection::Ids(vec![2]),
            ),
            output: "cube.se.ron".into(),
            m_bar_matrix_market: None,
        },
        &dir,
    )
    .unwrap();
    assert!(files.contains(&dir.join("mesh/part.inp")) && files.len() == 6);
    // errors
    expect_err(read_inp(&dir.join("nowhere.inp")), &["nowhere.inp"]);
    expect_err(
        parse_inp("*INCLUDE, INPUT=mesh.inp\n", "deck.inp"),
        &["deck.inp:1", "only when reading a file"],
    );
    std::fs::write(dir.join("noinput.inp"), "*NODE\n1, 0, 0, 0\n*INCLUDE\n").unwrap();
    expect_err(
        read_inp(&dir.join("noinput.inp")),
        &["noinput.inp:3", "no INPUT="],
    );
    std::fs::write(dir.join("missing.inp"), "*INCLUDE, INPUT=gone.inp\n").unwrap();
    expect_err(read_inp(&dir.join("missing.inp")), &["gone.inp"]);
    std::fs::write(dir.join("cycle.inp"), "*INCLUDE, INPUT=cycle.inp\n").unwrap();
    expect_err(
        read_inp(&dir.join("cycle.inp")),
        &["cycle.inp:1", "nested more than 16 deep"],
    );
    std::fs::write(
        dir.join("short.inp"),
        "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=C3D10\n1, 1, 2, 3,\n*NSET, NSET=A\n1\n",
    )
    .unwrap();
    expect_err(
        read_inp(&dir.join("short.inp")),
        &["short.inp:4", "continues past the block"],
    );
}

/// Issue 14.1: a misspelt field in a spec (`normal_mode: 6` used to build 0
/// normal modes) or in a superelement file is refused with its line, column
/// and the nearest valid name; so is a misspelt field of a struct variant.
#[test]
fn misspelt_fields_in_specs_and_superelement_files_are_refused() {
    let (model, settings) = small_bar();
    let spec = Spec {
        name: "small".into(),
        model: ModelSource::CalculiX {
            job: "job".into(),
            inp: None,
            density: None,
        },
        units: None,
        stiffness_scale: None,
        mass_scale: None,
        settings: BuildSettings {
            normal_modes: 6,
            ..settings.clone()
        },
        output: "small.se.ron".into(),
        m_bar_matrix_market: None,
    };
    let text = ron::ser::to_string_pretty(&spec, Default::default()).unwrap();
    assert_eq!(Spec::from_ron(&text, "spec.ron").unwrap(), spec);
    let line_of = |t: &str, what: &str| t.lines().position(|l| l.contains(what)).unwrap() + 1;
    let bad = text.replacen("normal_modes:", "normal_mode:", 1);
    let e = expect_err(
        Spec::from_ron(&bad, "spec.ron"),
        &["`normal_mode`", "did you mean `normal_modes`?"],
    );
    assert!(
        e.starts_with(&format!(
            "spec.ron:{}: column ",
            line_of(&bad, "normal_mode:")
        )),
        "{e}"
    );
    let bad = text.replacen("job:", "jbo:", 1);
    expect_err(Spec::from_ron(&bad, "spec.ron"), &["did you mean `job`?"]);
    // a superelement file
    let dir = tmp("typo");
    let data = build(&model, &settings).unwrap().data;
    let p = dir.join("small.se.ron");
    flexmb_superelement::spec::write_ron(&p, &data).unwrap();
    assert_eq!(read_ron(&p).unwrap(), data);
    let text = std::fs::read_to_string(&p).unwrap();
    std::fs::write(&p, text.replacen("m_bar:", "mbar:", 1)).unwrap();
    expect_err(
        read_ron(&p),
        &["small.se.ron:", "`mbar`", "did you mean `m_bar`?"],
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 14.2: a Matrix Market file with fewer entries than its size line
/// declares is truncated (file and last line), one with more names the
/// first extra line, and a last line without an end of line is cut off (a
/// value cut short still reads as a number). K and M of different sizes name
/// the file that disagrees with the DOF list.
#[test]
fn matrix_market_truncation_and_sizes() {
    let full = "%%MatrixMarket matrix coordinate real symmetric\n3 3 4\n1 1 2.0\n2 1 -1.0\n2 2 2.0\n3 3 1.5\n";
    parse_matrix_market(full, "k.mtx").unwrap();
    let short: String = full.lines().take(5).map(|l| format!("{l}\n")).collect();
    expect_err(
        parse_matrix_market(&short, "k.mtx"),
        &[
            "k.mtx:5: truncated or incomplete",
            "declares 4 entries",
            "ends after 3",
        ],
    );
    expect_err(
        parse_matrix_market(&format!("{full}3 2 0.5\n"), "k.mtx"),
        &["k.mtx:7", "more entries than the 4"],
    );
    expect_err(
        parse_matrix_market(&full[..full.len() - 2], "k.mtx"),
        &[
            "k.mtx:6: truncated or incomplete",
            "'3 3 1.'",
            "no end of line",
        ],
    );
    // K of the small bar against an M with fewer equations, through files
    let (model, _) = small_bar();
    let dir = tmp("mm-sizes");
    write_matrix_market(&dir.join("k.mtx"), model.k()).unwrap();
    write_nodes(&dir.join("nodes.txt"), model.node_ids(), model.coords()).unwrap();
    let small = parts::prismatic_bar(0.05, 0.01, 0.006, [2, 2, 1], steel())
        .unwrap()
        .mesh
        .assemble("smaller")
        .unwrap();
    write_matrix_market(&dir.join("m_small.mtx"), small.m()).unwrap();
    let n = model.n_eq();
    expect_err(
        read_matrix_market_model(
            "mixed",
            &dir.join("k.mtx"),
            &dir.join("m_small.mtx"),
            &dir.join("nodes.txt"),
            None,
        ),
        &[
            "m_small.mtx is",
            &format!("k.mtx is {n} × {n}"),
            "m_small.mtx is from another model",
        ],
    );
}

/// The deck data behind the rigid-body check: *ELSET (labels, GENERATE, sets
/// named in sets, the ELSET= of *ELEMENT), *SOLID SECTION and *DENSITY (one
/// data line; a temperature table gives no single density), and the
/// keywords that couple nodes outside the elements.
#[test]
fn inp_densities_element_sets_and_couplings() {
    let tet = |id: u64| format!("{id}, 1, 2, 3, 4\n");
    let inp = format!(
        "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n\
         *ELEMENT, TYPE=C3D4, ELSET=E1\n{}{}\
         *ELEMENT, TYPE=C3D4\n{}{}{}\
         *ELSET, ELSET=GEN, GENERATE\n3, 5, 2\n\
         *ELSET, ELSET=ALL\nGEN, E1\n\
         *MATERIAL, NAME=Steel\n*ELASTIC\n2.1e11, 0.3\n*DENSITY\n7800.\n\
         *MATERIAL, NAME=HOT\n*DENSITY\n2700., 293.\n2650., 400.\n\
         *SOLID SECTION, ELSET=ALL, MATERIAL=STEEL\n\
         *SOLID SECTION, ELSET=GEN, MATERIAL=hot\n\
         *EQUATION\n2\n1, 1, 1.0, 2, 1, -1.0\n",
        tet(1),
        tet(2),
        tet(3),
        tet(4),
        tet(5)
    );
    let mesh = parse_inp(&inp, "deck.inp").unwrap();
    assert_eq!(mesh.element_ids, vec![1, 2, 3, 4, 5]);
    assert_eq!(mesh.elsets["GEN"], vec![3, 5]);
    let mut all = mesh.elsets["ALL"].clone();
    all.sort_unstable();
    assert_eq!(all, vec![1, 2, 3, 5]);
    assert_eq!(mesh.densities["STEEL"], vec![7800.0]);
    assert_eq!(mesh.densities["HOT"], vec![2700.0, 2650.0]);
    // elements 3 and 5: the later section (a temperature table: unknown); 4: none
    assert_eq!(
        mesh.element_densities(),
        vec![Some(7800.0), Some(7800.0), None, None, None]
    );
    assert_eq!(mesh.couplings.len(), 1);
    assert!(mesh.couplings[0].starts_with("*EQUATION at deck.inp:"));
    assert!((mesh.volume().unwrap() - 5.0 / 6.0).abs() < 1e-15);
}

/// The sparsity check (issue 14.2): the M of another built-in grid with as
/// many nodes (4 × 2 × 1 and 2 × 4 × 1 elements, 89 nodes each) couples
/// nodes that share no element of this mesh; with a coupling keyword in the
/// deck (or no elements known) it is checked against K's pattern instead.
/// Both name M.
#[test]
fn mass_from_another_grid_is_refused_by_the_sparsity_check() {
    let bar = |n| {
        parts::prismatic_bar(0.05, 0.01, 0.006, n, steel())
            .unwrap()
            .mesh
            .assemble("bar")
            .unwrap()
    };
    let (a, b) = (bar([4, 2, 1]), bar([2, 4, 1]));
    assert_eq!(a.n_eq(), b.n_eq());
    a.check_consistency().unwrap();
    let mut mixed = FeModel::new(
        "mixed",
        a.node_ids().to_vec(),
        a.coords().to_vec(),
        a.dofs().clone(),
        a.k(),
        b.m(),
    )
    .unwrap();
    mixed.solid = a.solid.clone();
    expect_err(
        mixed.check_consistency(),
        &[
            "M couples equation",
            "which share no solid element of the mesh",
            "M is from another mesh",
        ],
    );
    let mut with_coupling = mixed.clone();
    if let Some(s) = &mut with_coupling.solid {
        s.couplings.push("*TIE at deck.inp:9".into());
    }
    expect_err(
        with_coupling.check_consistency(),
        &["M couples equation", "between which K has no entry"],
    );
    mixed.solid = None;
    expect_err(
        mixed.check_consistency(),
        &["M couples equation", "between which K has no entry"],
    );
}

/// GENERATE lines of *NSET and *ELSET: a range, and errors (not a panic, not
/// an allocation until memory runs out) for an empty line, a reversed range,
/// a zero step and a range of 10^12 labels.
#[test]
fn generate_ranges_are_checked() {
    let base = "*NODE\n1, 0, 0, 0\n";
    let mesh = parse_inp(
        &format!("{base}*NSET, NSET=A, GENERATE\n1, 9, 4\n"),
        "g.inp",
    )
    .unwrap();
    assert_eq!(mesh.nsets["A"], vec![1, 5, 9]);
    for kw in ["*NSET, NSET=A", "*ELSET, ELSET=A"] {
        for (line, words) in [
            (",", "first, last"),
            ("9, 1", "first ≤ last"),
            ("1, 9, 0", "step ≥ 1"),
            ("1, 1000000000000", "at most 10000000 labels"),
        ] {
            expect_err(
                parse_inp(&format!("{base}{kw}, GENERATE\n{line}\n"), "g.inp"),
                &["g.inp:4", words],
            );
        }
    }
}
