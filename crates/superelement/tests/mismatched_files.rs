//! Issue 14 item 2: K, M, the DOF list and the mesh are checked against each
//! other before a build, and the message names the file at fault. Real
//! CalculiX exports (gmsh meshes of one steel bar, `ccx` with
//! `*FREQUENCY, SOLVER=MATRIXSTORAGE`), then damaged or mixed up the way a
//! user would: truncated files, swapped files, a `.mas` or `.dof` from
//! another mesh of the same part, a bad diagonal.
//!
//! Like `calculix_e2e.rs`, these tests need `gmsh` and `ccx` (Debian
//! packages `gmsh` and `calculix-ccx`) and fail, never skip, without them.

use flexmb_superelement::consistency::RIGID_BODY_TOLERANCE;
use flexmb_superelement::readers::read_calculix;
use flexmb_superelement::{build, BuildSettings, Error, NodeSelection};
use std::path::{Path, PathBuf};
use std::process::Command;

const L: f64 = 0.1;
const B: f64 = 0.01;

/// A work directory under the system temp directory, removed when the test
/// passes and kept when it fails.
struct WorkDir(PathBuf);

impl WorkDir {
    fn new(name: &str) -> Self {
        let d =
            std::env::temp_dir().join(format!("flexmb-se-mismatch-{}-{name}", std::process::id()));
        if d.exists() {
            std::fs::remove_dir_all(&d).unwrap();
        }
        std::fs::create_dir_all(&d).unwrap();
        WorkDir(d)
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("work files kept in {}", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Runs `program args` in `dir`; fails the test if it is missing or fails.
fn run(program: &str, args: &[&str], dir: &Path) {
    let out = match Command::new(program).args(args).current_dir(dir).output() {
        Ok(o) => o,
        Err(e) => panic!(
            "cannot run `{program}` ({e}); these tests need gmsh and CalculiX: \
             `apt-get install -y calculix-ccx gmsh`"
        ),
    };
    assert!(
        out.status.success(),
        "`{program} {}` failed: {}{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// An unstructured C3D10 mesh of the bar with element size `h`.
fn tet_geo(h: f64) -> String {
    format!(
        "SetFactory(\"OpenCASCADE\");\n\
         Box(1) = {{0, {y0}, {y0}, {L}, {B}, {B}}};\n\
         Mesh.CharacteristicLengthMax = {h};\n\
         Physical Volume(\"BAR\") = {{1}};\n",
        y0 = -0.5 * B
    )
}

/// A structured C3D20 mesh of the bar, 10 × 2 × 2 elements, with the element
/// lengths along x growing by the factor `progression` (1: uniform): the same
/// nodes, numbering and connectivity for every progression, only the x
/// coordinates differ.
fn hex_geo(progression: f64) -> String {
    hex_grid_geo([10, 2, 2], progression)
}

/// A structured C3D20 mesh of the bar with `n` elements along x, y, z, the
/// lengths along x growing by the factor `progression`. The grids 10 × 2 × 2
/// and 2 × 10 × 2 have the same number of nodes (321), numbered alike, but
/// different elements.
fn hex_grid_geo(n: [usize; 3], progression: f64) -> String {
    let w: Vec<f64> = (0..n[0]).map(|k| progression.powi(k as i32)).collect();
    let total: f64 = w.iter().sum();
    let mut acc = 0.0;
    let heights: Vec<String> = w
        .iter()
        .map(|x| {
            acc += x / total;
            format!("{acc}")
        })
        .collect();
    format!(
        "Point(1) = {{0, {y0}, {y0}, 1}};\n\
         l[] = Extrude {{0, {B}, 0}} {{ Point{{1}}; Layers{{{}}}; }};\n\
         s[] = Extrude {{0, 0, {B}}} {{ Line{{l[1]}}; Layers{{{}}}; Recombine; }};\n\
         v[] = Extrude {{{L}, 0, 0}} {{ Surface{{s[1]}}; Layers{{ {{{}}}, {{{}}} }}; Recombine; }};\n\
         Physical Volume(\"BAR\") = {{v[1]}};\n\
         Mesh.SecondOrderIncomplete = 1;\n",
        n[1],
        n[2],
        vec!["1"; n[0]].join(", "),
        heights.join(", "),
        y0 = -0.5 * B
    )
}

/// Meshes `geo` with gmsh and exports K and M with ccx as job `job` in `dir`
/// (steel, density 7800, no boundary conditions).
fn export(dir: &Path, job: &str, geo: &str) {
    std::fs::write(dir.join(format!("{job}_mesh.geo")), geo).unwrap();
    let mesh = format!("{job}_mesh.inp");
    run(
        "gmsh",
        &[
            &format!("{job}_mesh.geo"),
            "-3",
            "-order",
            "2",
            "-format",
            "inp",
            "-o",
            &mesh,
        ],
        dir,
    );
    let deck = format!(
        "*INCLUDE, INPUT={mesh}\n*MATERIAL, NAME=STEEL\n*ELASTIC\n2.1e11, 0.3125\n*DENSITY\n7800.\n\
         *SOLID SECTION, ELSET=BAR, MATERIAL=STEEL\n*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n"
    );
    std::fs::write(dir.join(format!("{job}.inp")), deck).unwrap();
    run("ccx", &["-i", job], dir);
}

/// Makes job `to` in `dir` from the files of job `from`, with the files named
/// in `replace` ((extension, file in `dir`)) taken instead; the deck is
/// `from`'s.
fn compose(dir: &Path, to: &str, from: &str, replace: &[(&str, &str)]) {
    for ext in ["sti", "mas", "dof", "inp"] {
        let src = replace
            .iter()
            .find(|(e, _)| *e == ext)
            .map(|(_, f)| f.to_string())
            .unwrap_or(format!("{from}.{ext}"));
        std::fs::copy(dir.join(src), dir.join(format!("{to}.{ext}"))).unwrap();
    }
}

/// Job `to`: job `from` with the file `ext` replaced by `text`.
fn compose_text(dir: &Path, to: &str, from: &str, ext: &str, text: &str) {
    let tmp = format!("{to}.{ext}.new");
    std::fs::write(dir.join(&tmp), text).unwrap();
    compose(dir, to, from, &[(ext, &tmp)]);
}

fn text(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap()
}

/// The first `n` lines of `t`, each with its end of line.
fn head(t: &str, n: usize) -> String {
    t.lines().take(n).map(|l| format!("{l}\n")).collect()
}

/// Rigid interfaces on the end planes, 2 normal modes.
fn settings() -> BuildSettings {
    let plane = |x: f64| NodeSelection::NearPlane {
        point: [x, 0.0, 0.0],
        normal: [1.0, 0.0, 0.0],
        tolerance: 1e-9,
    };
    let mut s = BuildSettings::new([0.0; 3], [L, 0.0, 0.0], plane(0.0), plane(L));
    s.normal_modes = 2;
    s
}

/// Reads job `job` and builds it; the fixed-interface frequencies (Hz).
fn read_and_build(dir: &Path, job: &str) -> Result<Vec<f64>, Error> {
    let (model, _) = read_calculix(&dir.join(job), None)?;
    Ok(build(&model, &settings())?.report.normal_frequencies_hz)
}

/// The error message, which must contain every one of `words`; the error
/// must be an input error (exit code 2 on the command line).
fn expect_err<T>(r: Result<T, Error>, words: &[&str]) -> String {
    let Err(e) = r else {
        panic!("an error was expected (mentioning {words:?})")
    };
    let msg = e.to_string();
    for w in words {
        assert!(msg.contains(w), "'{msg}' should mention '{w}'");
    }
    assert!(e.is_input(), "an input error: {msg}");
    println!("{msg}\n");
    msg
}

/// The (node label, direction 1–3) of equation `e` (from 1) in a `.dof` text.
fn dof_of(dof: &str, e: usize) -> (u64, usize) {
    let l = dof.lines().nth(e - 1).unwrap().trim();
    let (n, d) = l.split_once('.').unwrap();
    (n.parse().unwrap(), d.parse().unwrap())
}

const DIR: [&str; 3] = ["ux", "uy", "uz"];

/// A truncated `.sti` used to be reported as "1277 node(s) are not connected"
/// (cut at a line boundary) or read as if complete (cut inside the last
/// value). Each cut is now "truncated or incomplete" with the file and line:
/// at a line boundary mid-file, inside a line, and inside the last column
/// just before its diagonal; the same for `.mas`.
#[test]
fn truncated_sti_and_mas_are_reported_as_truncated() {
    let work = WorkDir::new("truncated");
    let dir = work.0.as_path();
    export(dir, "a", &tet_geo(B / 2.0));
    let freqs = read_and_build(dir, "a").unwrap();
    println!("complete export: fixed-interface frequencies {freqs:?} Hz");
    for ext in ["sti", "mas"] {
        let full = text(dir, &format!("a.{ext}"));
        let n_lines = full.lines().count();
        // at a line boundary, 60 % of the way
        let keep = n_lines * 3 / 5;
        let job = format!("cut_{ext}");
        compose_text(dir, &job, "a", ext, &head(&full, keep));
        let last = full.lines().nth(keep - 1).unwrap();
        let (i, j) = {
            let f: Vec<&str> = last.split_whitespace().collect();
            (f[0], f[1])
        };
        expect_err(
            read_and_build(dir, &job),
            &[
                &format!("{job}.{ext}:{keep}: truncated or incomplete"),
                &format!("ends with the entry ({i}, {j})"),
                &format!("{job}.dof lists"),
            ],
        );
        // inside the last line: 5 characters of the value cut off (what is
        // left of the value is still a number)
        let job = format!("cutline_{ext}");
        compose_text(dir, &job, "a", ext, &full[..full.len() - 6]);
        expect_err(
            read_and_build(dir, &job),
            &[
                &format!("{job}.{ext}:{n_lines}: truncated or incomplete"),
                "has no end of line: the file was cut off",
            ],
        );
        // the last line (the diagonal of the last equation) missing
        let job = format!("nodiag_{ext}");
        compose_text(dir, &job, "a", ext, &head(&full, n_lines - 1));
        let n_eq = text(dir, "a.dof").lines().count();
        expect_err(
            read_and_build(dir, &job),
            &[
                &format!("{job}.{ext}:{}: truncated or incomplete", n_lines - 1),
                &format!("inside the column of equation {n_eq} before its diagonal entry ({n_eq}, {n_eq})"),
            ],
        );
    }
}

/// Swapped K and M used to be reported as a units error ("density ... mm"):
/// now "K and M look swapped", naming both files.
#[test]
fn swapped_k_and_m_are_reported_as_swapped() {
    let work = WorkDir::new("swapped");
    let dir = work.0.as_path();
    export(dir, "a", &tet_geo(B / 2.0));
    compose(dir, "sw", "a", &[("sti", "a.mas"), ("mas", "a.sti")]);
    let msg = expect_err(
        read_and_build(dir, "sw"),
        &[
            "K and M look swapped",
            "sw.mas",
            "sw.sti",
            "exchange the two files",
        ],
    );
    assert!(!msg.contains("units"), "{msg}");
}

/// A `.mas` from another mesh of the same part: from a coarser mesh (it fits
/// inside the equations and used to be accepted with wrong frequencies and
/// exit code 0), from a finer one, from a mesh with the same nodes and
/// elements but other x coordinates (graded), and from a grid with as many
/// nodes but other elements. Each names the `.mas`; a `.sti` from the graded mesh
/// is blamed on the `.sti`.
#[test]
fn a_mas_from_another_mesh_is_caught() {
    let work = WorkDir::new("other_mesh");
    let dir = work.0.as_path();
    export(dir, "a", &tet_geo(B / 2.0));
    export(dir, "coarse", &tet_geo(B / 1.5));
    export(dir, "fine", &tet_geo(B / 2.5));
    let n = |job: &str| text(dir, &format!("{job}.dof")).lines().count();
    let (na, nc, nf) = (n("a"), n("coarse"), n("fine"));
    assert!(nc < na && na < nf, "{nc} {na} {nf}");
    compose(dir, "a_coarse", "a", &[("mas", "coarse.mas")]);
    expect_err(
        read_and_build(dir, "a_coarse"),
        &[
            &format!("a_coarse.mas holds a matrix of {nc} equations"),
            &format!("a_coarse.dof lists {na} equations"),
            "a_coarse.mas is from another model with fewer equations",
        ],
    );
    compose(dir, "a_fine", "a", &[("mas", "fine.mas")]);
    expect_err(
        read_and_build(dir, "a_fine"),
        &[
            "a_fine.mas:",
            &format!("lists {na} equations"),
            "a_fine.mas is from another model with more equations",
        ],
    );
    // same nodes, numbering and elements; x coordinates graded by 1.2
    export(dir, "hex", &hex_geo(1.0));
    export(dir, "graded", &hex_geo(1.2));
    export(dir, "other_grid", &hex_grid_geo([2, 10, 2], 1.0));
    assert_eq!(text(dir, "hex.dof"), text(dir, "graded.dof"));
    assert_eq!(text(dir, "hex.dof"), text(dir, "other_grid.dof"));
    let f_hex = read_and_build(dir, "hex").unwrap();
    let f_graded = read_and_build(dir, "graded").unwrap();
    read_and_build(dir, "other_grid").unwrap();
    println!("hex {f_hex:?} Hz, graded {f_graded:?} Hz");
    compose(dir, "hex_graded_mas", "hex", &[("mas", "graded.mas")]);
    expect_err(
        read_and_build(dir, "hex_graded_mas"),
        &[
            "M (",
            "hex_graded_mas.mas) does not fit the elements of the mesh (",
            "centre of mass",
            "K (",
            "hex_graded_mas.sti) fits these coordinates",
        ],
    );
    let (model, _) = read_calculix(&dir.join("hex_graded_mas"), None).unwrap();
    let cmp = model.compare_rigid_body().unwrap();
    println!(
        "graded .mas on the uniform mesh: relative differences {:?}",
        cmp.difference
    );
    assert!(cmp.worst() > 10.0 * RIGID_BODY_TOLERANCE, "{cmp:?}");
    // the .sti of the graded mesh: K's rigid rotations store energy, M fits
    compose(dir, "hex_graded_sti", "hex", &[("sti", "graded.sti")]);
    expect_err(
        read_and_build(dir, "hex_graded_sti"),
        &[
            "hex_graded_sti.sti) does not fit the node coordinates of the mesh (",
            "rigid rotation about",
            "hex_graded_sti.mas) fits the node coordinates",
            "hex_graded_sti.sti) is from another mesh",
        ],
    );
    // a grid of 2 × 10 × 2 elements, as many nodes: M couples nodes of other elements
    compose(
        dir,
        "hex_other_grid_mas",
        "hex",
        &[("mas", "other_grid.mas")],
    );
    expect_err(
        read_and_build(dir, "hex_other_grid_mas"),
        &[
            "hex_other_grid_mas.mas) couples equation",
            "which share no solid element of the mesh (",
            "M is from another mesh",
        ],
    );
}

/// A `.dof` list from another mesh (fewer equations than both matrices) and
/// a truncated one name the `.dof`.
#[test]
fn a_dof_list_from_another_mesh_or_truncated_is_caught() {
    let work = WorkDir::new("dof");
    let dir = work.0.as_path();
    export(dir, "a", &tet_geo(B / 2.0));
    export(dir, "coarse", &tet_geo(B / 1.5));
    let na = text(dir, "a.dof").lines().count();
    let nc = text(dir, "coarse.dof").lines().count();
    compose(dir, "a_coarse_dof", "a", &[("dof", "coarse.dof")]);
    expect_err(
        read_and_build(dir, "a_coarse_dof"),
        &[
            &format!("a_coarse_dof.dof lists {nc} equations"),
            &format!("both have entries up to equation {na}"),
            "a_coarse_dof.dof is from another model",
        ],
    );
    // cut inside the last line ("123.2" → "123.")
    let full = text(dir, "a.dof");
    compose_text(dir, "cut_dof", "a", "dof", &full[..full.len() - 2]);
    expect_err(
        read_and_build(dir, "cut_dof"),
        &[
            &format!("cut_dof.dof:{na}: truncated or incomplete"),
            "is cut off",
        ],
    );
    // cut at a line boundary: both matrices have more equations
    compose_text(dir, "short_dof", "a", "dof", &head(&full, na / 2));
    expect_err(
        read_and_build(dir, "short_dof"),
        &[
            &format!("short_dof.dof lists {} equations", na / 2),
            "short_dof.dof is from another model (or truncated)",
        ],
    );
}

/// A negative stiffness diagonal and a zero mass diagonal name the file, the
/// equation, the node and the direction.
#[test]
fn non_positive_diagonals_name_file_equation_node_and_direction() {
    let work = WorkDir::new("diagonal");
    let dir = work.0.as_path();
    export(dir, "a", &tet_geo(B / 2.0));
    let dof = text(dir, "a.dof");
    let e = 100;
    let (node, d) = dof_of(&dof, e);
    let set_diagonal = |t: &str, v: &str| -> String {
        t.lines()
            .map(|l| {
                let f: Vec<&str> = l.split_whitespace().collect();
                if f[0] == e.to_string() && f[1] == e.to_string() {
                    format!("{e} {e} {v}\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect()
    };
    let sti = set_diagonal(&text(dir, "a.sti"), "-1.0e+08");
    compose_text(dir, "neg_k", "a", "sti", &sti);
    expect_err(
        read_and_build(dir, "neg_k"),
        &[
            "K (",
            "neg_k.sti): ",
            &format!("equation {e} (node {node} {})", DIR[d - 1]),
            "K_ii = -1e8",
            "not positive semi-definite",
        ],
    );
    let mas = set_diagonal(&text(dir, "a.mas"), "0.0");
    compose_text(dir, "zero_m", "a", "mas", &mas);
    expect_err(
        read_and_build(dir, "zero_m"),
        &[
            "M (",
            "zero_m.mas): ",
            &format!("equation {e} (node {node} {})", DIR[d - 1]),
            "M_ii = 0",
            "positive mass",
        ],
    );
}

/// The rigid-body check must not refuse curved meshes, whose M the exporter
/// integrates with its own quadrature: coarse gmsh cylinders (C3D10 and
/// C3D20) and the built-in shaft stay below a tenth of the tolerance
/// (measured 9.5e-5, 2.0e-7 and 2.0e-5) and build.
#[test]
fn curved_meshes_pass_the_rigid_body_check() {
    use flexmb_element::Material;
    let steel = Material {
        e: 2.1e11,
        g: 8.0e10,
        rho: 7800.0,
    };
    let part = flexmb_superelement::parts::unbalanced_shaft_half(
        flexmb_superelement::parts::ShaftHalf::First,
        0.05,
        2,
        10,
        4,
        steel,
    )
    .unwrap();
    let shaft = part.mesh.assemble("shaft").unwrap();
    let mut worst = vec![(
        "built-in shaft",
        shaft.compare_rigid_body().unwrap().worst(),
    )];
    shaft.check_consistency().unwrap();
    let work = WorkDir::new("curved");
    let dir = work.0.as_path();
    let tet = "SetFactory(\"OpenCASCADE\");\nCylinder(1) = {0, 0, 0, 0.1, 0, 0, 0.02};\n\
               Mesh.CharacteristicLengthMax = 0.02;\nPhysical Volume(\"BAR\") = {1};\n";
    let hex = "SetFactory(\"OpenCASCADE\");\nDisk(1) = {0, 0, 0, 0.02};\n\
               Rotate {{0, 1, 0}, {0, 0, 0}, Pi/2} { Surface{1}; }\nMesh.CharacteristicLengthMax = 0.02;\n\
               Mesh.RecombineAll = 1;\nv[] = Extrude {0.1, 0, 0} { Surface{1}; Layers{10}; Recombine; };\n\
               Physical Volume(\"BAR\") = {v[1]};\nMesh.SecondOrderIncomplete = 1;\n";
    for (job, geo, what) in [
        ("tet", tet, "C3D10 cylinder"),
        ("hex", hex, "C3D20 cylinder"),
    ] {
        export(dir, job, geo);
        let (model, _) = read_calculix(&dir.join(job), None).unwrap();
        worst.push((what, model.compare_rigid_body().unwrap().worst()));
        model.check_consistency().unwrap();
    }
    println!("rigid-body differences of curved meshes: {worst:?}");
    for (what, w) in worst {
        assert!(w < 0.1 * RIGID_BODY_TOLERANCE, "{what}: {w:e}");
    }
}
