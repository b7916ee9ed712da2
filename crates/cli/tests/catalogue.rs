//! The bad-input catalogue through the command line (issue 14, "Done
//! when"): every row is a bad scene, option, file or model, run through the
//! `flexmb` binary, with the exit code it must give (2 invalid input, unless
//! said otherwise) and the words of the message that name the culprit: the
//! field, id, option or file. Scenes are variants of
//! fixtures/scenes/straight_guidance_planar.ron written to a temporary
//! directory. No row may panic. The rows fail before any long computation,
//! so the whole table runs in a few seconds.

mod common;
use common::fixture;

use std::path::PathBuf;
use std::process::Command;

/// One bad input.
struct Case {
    /// What is wrong, for the failure message.
    what: &'static str,
    /// The arguments after `flexmb`.
    args: Vec<String>,
    /// The exit code.
    code: i32,
    /// Substrings of stderr that name the culprit.
    culprit: Vec<String>,
}

/// The table and the files its rows use.
struct Catalogue {
    dir: PathBuf,
    /// The planar straight guidance (17 DOF), the base of every scene.
    planar: String,
    cases: Vec<Case>,
}

impl Catalogue {
    fn new() -> Self {
        let dir = std::env::temp_dir().join(format!("flexmb-catalogue-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let planar = std::fs::read_to_string(fixture("straight_guidance_planar.ron")).unwrap();
        Self {
            dir,
            planar,
            cases: vec![],
        }
    }

    /// Writes `contents` to `name` in the directory; returns its path.
    fn file(&self, name: &str, contents: &str) -> String {
        let p = self.dir.join(name);
        std::fs::write(&p, contents).unwrap();
        p.display().to_string()
    }

    /// A path in the directory (not created).
    fn path(&self, name: &str) -> String {
        self.dir.join(name).display().to_string()
    }

    /// The planar guidance with the first `from` replaced by `to`, written
    /// to `name`; returns its path.
    fn scene(&self, name: &str, from: &str, to: &str) -> String {
        assert!(self.planar.contains(from), "the fixture has no {from:?}");
        self.file(name, &self.planar.replacen(from, to, 1))
    }

    /// The unchanged planar guidance.
    fn good(&self) -> String {
        fixture("straight_guidance_planar.ron")
            .display()
            .to_string()
    }

    /// Adds a row.
    fn case(&mut self, what: &'static str, code: i32, culprit: &[&str], args: &[&str]) {
        self.cases.push(Case {
            what,
            args: args.iter().map(|s| s.to_string()).collect(),
            code,
            culprit: culprit.iter().map(|s| s.to_string()).collect(),
        });
    }

    /// Adds a row running `flexmb info` on a scene variant.
    fn info(&mut self, what: &'static str, culprit: &[&str], name: &str, from: &str, to: &str) {
        let scene = self.scene(name, from, to);
        let mut culprit: Vec<&str> = culprit.to_vec();
        culprit.push(name);
        let culprit: Vec<String> = culprit.iter().map(|s| s.to_string()).collect();
        self.cases.push(Case {
            what,
            args: vec!["info".into(), scene],
            code: 2,
            culprit,
        });
    }

    /// Runs every row; returns the descriptions of the rows that failed.
    fn run(&self) -> Vec<String> {
        let mut failed = vec![];
        for c in &self.cases {
            let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
                .args(&c.args)
                .current_dir(&self.dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            let out = String::from_utf8_lossy(&o.stdout);
            let missing: Vec<&String> = c.culprit.iter().filter(|s| !err.contains(*s)).collect();
            if o.status.code() != Some(c.code) || !missing.is_empty() || err.contains("panicked") {
                failed.push(format!(
                    "{}: flexmb {}\n  exit code {:?} (want {}), missing {missing:?}\n  stderr: {err}  stdout: {out}",
                    c.what,
                    c.args.join(" "),
                    o.status.code(),
                    c.code
                ));
            }
        }
        failed
    }
}

/// The rows on the scene file: reading it, then building the mechanism.
fn scene_rows(k: &mut Catalogue) {
    k.case(
        "missing scene file",
        2,
        &["/no/such/scene.ron"],
        &["info", "/no/such/scene.ron"],
    );
    let dir = k.dir.display().to_string();
    k.case(
        "a directory as the scene",
        2,
        &["cannot read", &dir],
        &["info", &dir],
    );
    let empty = k.file("empty.ron", "");
    k.case(
        "empty scene file",
        2,
        &["empty.ron", "line 1"],
        &["info", &empty],
    );
    let half = &k.planar[..k.planar.len() / 2];
    let truncated = k.file("truncated.ron", half);
    k.case(
        "truncated scene file",
        2,
        &["truncated.ron", "line "],
        &["info", &truncated],
    );
    // malformed RON: the line of the missing parenthesis
    let from = r#"(id: "A", at: [0.0, 0.0]),"#;
    let line = k.planar[..k.planar.find(from).unwrap()].lines().count() + 1;
    let at = format!("line {line}");
    k.info(
        "malformed RON",
        &[&at],
        "malformed.ron",
        from,
        r#"(id: "A", at: [0.0, 0.0],"#,
    );
    // misspelt fields and variants, with the nearest valid name
    k.info(
        "misspelt scene field",
        &["`gravityy`", "did you mean `gravity`?"],
        "gravityy.ron",
        "dimension: Planar,",
        "dimension: Planar, gravityy: Some([0.0, -9.81]),",
    );
    k.info(
        "misspelt beam option",
        &["`timoshenkoo`", "did you mean `timoshenko`?"],
        "timoshenkoo.ron",
        "timoshenko: false",
        "timoshenkoo: false",
    );
    k.info(
        "misspelt material field",
        &["`rhoo`", "did you mean `rho`?"],
        "rhoo.ron",
        "rho: 7600.0",
        "rhoo: 7600.0",
    );
    k.info(
        "misspelt section field",
        &["`bzz`", "did you mean `bz`?"],
        "bzz.ron",
        "bz: 0.03)",
        "bzz: 0.03)",
    );
    k.info(
        "misspelt load field",
        &["`forse`", "did you mean `force`?"],
        "forse.ron",
        "force: Some",
        "forse: Some",
    );
    k.info(
        "unknown section type",
        &["`Rectangel`", "did you mean `Rectangle`?"],
        "rectangel.ron",
        "Rectangle(by: 0.001",
        "Rectangel(by: 0.001",
    );
    k.info(
        "unknown time function",
        &["`RaisedCosinPulse`", "did you mean `RaisedCosinePulse`?"],
        "pulse_name.ron",
        "RaisedCosinePulse(",
        "RaisedCosinPulse(",
    );
    k.info(
        "unknown DOF choice",
        &["`Deformation`", "did you mean `Deformations`?"],
        "dofs.ron",
        "dofs: Deformations",
        "dofs: Deformation",
    );
    k.info(
        "unknown dimension",
        &["`Flat`", "`Planar`"],
        "flat.ron",
        "dimension: Planar",
        "dimension: Flat",
    );
    // repeated keys and ids
    k.info(
        "duplicate material key",
        &["duplicate material id 'steel'"],
        "dup_material.ron",
        r#""steel": (e: 2.1e11, nu: 0.3, rho: 7600.0),"#,
        r#""steel": (e: 2.1e11, nu: 0.3, rho: 7600.0), "steel": (e: 2.1e9, nu: 0.3, rho: 7600.0),"#,
    );
    k.info(
        "duplicate section key",
        &["duplicate section id 'body'"],
        "dup_section.ron",
        r#""body": Rectangle(by: 0.03, bz: 0.03),"#,
        r#""body": Rectangle(by: 0.03, bz: 0.03), "body": Rectangle(by: 0.02, bz: 0.03),"#,
    );
    k.case(
        "duplicate node id",
        2,
        &["duplicate node id 'S'"],
        &[
            "info",
            &k.scene(
                "dup_node.ron",
                r#"(id: "S", at: [0.1, 0.2]),"#,
                r#"(id: "S", at: [0.1, 0.2]), (id: "S", at: [0.1, 0.3]),"#,
            ),
        ],
    );
    k.case(
        "duplicate element id",
        2,
        &["duplicate element id 'body1'"],
        &[
            "info",
            &k.scene("dup_element.ron", r#"(id: "body2","#, r#"(id: "body1","#),
        ],
    );
    // unknown ids and names, with a suggestion where there is one
    let rows: [(&'static str, &[&str], &str, &str, &str); 7] = [
        (
            "unknown node of an element",
            &[
                "element 'flexure2'",
                "unknown node 'DD'",
                "did you mean 'D'?",
            ],
            "unknown_node.ron",
            r#"nodes: ("C", "D")"#,
            r#"nodes: ("C", "DD")"#,
        ),
        (
            "unknown material",
            &[
                "element 'body1'",
                "unknown material 'steal'",
                "did you mean 'steel'?",
            ],
            "unknown_material.ron",
            r#"material: "steel", section: "body"))),"#,
            r#"material: "steal", section: "body"))),"#,
        ),
        (
            "unknown section",
            &["element 'flexure1'", "unknown section 'flexur'"],
            "unknown_section.ron",
            r#"section: "flexure", n: 5"#,
            r#"section: "flexur", n: 5"#,
        ),
        (
            "unknown node of a load",
            &["load 0", "unknown node 'T'"],
            "unknown_load_node.ron",
            r#"(node: "S", force"#,
            r#"(node: "T", force"#,
        ),
        (
            "unknown node in fixed",
            &["fixed", "unknown node 'X'"],
            "unknown_fixed.ron",
            r#"fixed: [Node("A"), Node("C")]"#,
            r#"fixed: [Node("A"), Node("X")]"#,
        ),
        (
            "unknown element in rigid",
            &["rigid", "unknown element 'body3'"],
            "unknown_rigid.ron",
            r#"Def("body2", "*")"#,
            r#"Def("body3", "*")"#,
        ),
        (
            "unknown deformation name",
            &["flexure1", "no deformation 'elongate'"],
            "unknown_deformation.ron",
            r#"Def("flexure1", "elongation")"#,
            r#"Def("flexure1", "elongate")"#,
        ),
    ];
    for (what, culprit, name, from, to) in rows {
        let scene = k.scene(name, from, to);
        k.case(what, 2, culprit, &["info", &scene]);
    }
    // unphysical or inconsistent data
    let rows: [(&'static str, &[&str], &str, &str, &str); 12] = [
        (
            "negative Young's modulus",
            &["material 'steel'", "e (Young's modulus)"],
            "negative_e.ron",
            "e: 2.1e11",
            "e: -2.1e11",
        ),
        (
            "Poisson's ratio out of range",
            &["material 'steel'", "nu (Poisson's ratio) = 0.7"],
            "nu.ron",
            "nu: 0.3",
            "nu: 0.7",
        ),
        (
            "negative density",
            &["material 'steel'", "rho (density)"],
            "negative_rho.ron",
            "rho: 7600.0",
            "rho: -1.0",
        ),
        (
            "negative section side",
            &["section 'flexure'", "`by`"],
            "negative_by.ron",
            "by: 0.001",
            "by: -0.001",
        ),
        (
            "zero-length element",
            &["element 'body1'", "length"],
            "zero_length.ron",
            r#"(id: "S", at: [0.1, 0.2]),"#,
            r#"(id: "S", at: [0.0, 0.2]),"#,
        ),
        (
            "non-finite node position",
            &["node 'D'", "non-finite"],
            "inf_node.ron",
            r#"(id: "D", at: [0.2, 0.2])"#,
            r#"(id: "D", at: [0.2, inf])"#,
        ),
        (
            "chain of zero elements",
            &["element 'flexure1'", "n must be at least 1"],
            "n_zero.ron",
            "n: 5",
            "n: 0",
        ),
        (
            "a chain too long for the chain helper (issue 14 item 6)",
            &[
                "element 'flexure1'",
                "1000000000 elements in one chain",
                "allows",
            ],
            "n_huge.ron",
            "n: 5",
            "n: 1000000000",
        ),
        (
            "spatial node in a planar scene",
            &["node 'A'", "3 components"],
            "node_3d.ron",
            r#"(id: "A", at: [0.0, 0.0])"#,
            r#"(id: "A", at: [0.0, 0.0, 0.0])"#,
        ),
        (
            "spatial force in a planar scene",
            &["load 0 on node 'S'", "force"],
            "force_3d.ron",
            "force: Some([1.0, 0.0])",
            "force: Some([1.0, 0.0, 0.0])",
        ),
        (
            "pulse of negative duration",
            &["load 0 on node 'S'", "duration"],
            "pulse.ron",
            "duration: 0.1",
            "duration: -0.1",
        ),
        (
            "fixed deformation",
            &["flexure1.1.elongation", "cannot be fixed"],
            "fixed_deformation.ron",
            r#"fixed: [Node("A"), Node("C")]"#,
            r#"fixed: [Node("A"), Node("C"), Def("flexure1", "elongation")]"#,
        ),
    ];
    for (what, culprit, name, from, to) in rows {
        let scene = k.scene(name, from, to);
        k.case(what, 2, culprit, &["info", &scene]);
    }
    // an output of an unknown node (`info` does not build the output table
    // yet, `simulate` refuses it before integrating)
    let scene = k.scene(
        "unknown_output.ron",
        r#"outputs: [Position("S")]"#,
        r#"outputs: [Position("Z")]"#,
    );
    let out = k.path("out_unknown_output");
    k.case(
        "output of an unknown node",
        2,
        &["output", "unknown node 'Z'"],
        &["simulate", &scene, "--t-end", "0.01", "--out", &out],
    );
}

/// The rows on command-line options: ranges, negative numbers, names.
fn option_rows(k: &mut Catalogue) {
    let g = k.good();
    let out = k.path("out_options");
    let rows: [(&'static str, &[&str], &[&str]); 24] = [
        (
            "unknown integrator",
            &["unknown integrator 'euler'"],
            &["simulate", &g, "--integrator", "euler"],
        ),
        (
            "negative --rtol",
            &["--rtol", "-1"],
            &["simulate", &g, "--rtol", "-1"],
        ),
        (
            "zero --rtol",
            &["--rtol", "positive"],
            &["simulate", &g, "--rtol", "0"],
        ),
        (
            "negative --atol in exponent form",
            &["--atol", "positive"],
            &["simulate", &g, "--atol", "-1e-6"],
        ),
        (
            "negative --t-end",
            &["--t-end", "-1"],
            &["simulate", &g, "--t-end", "-1"],
        ),
        (
            "NaN --t-end",
            &["--t-end", "NaN"],
            &["simulate", &g, "--t-end", "nan"],
        ),
        (
            "--outputs 0",
            &["--outputs must be at least 2", "got 0"],
            &["simulate", &g, "--outputs", "0"],
        ),
        (
            "--outputs 1",
            &["--outputs must be at least 2", "got 1"],
            &["simulate", &g, "--outputs", "1"],
        ),
        (
            "negative --outputs",
            &["'--outputs <OUTPUTS>'", "-5"],
            &["simulate", &g, "--outputs", "-5"],
        ),
        (
            "--steps 0",
            &["--steps must be at least 1"],
            &["static", &g, "--steps", "0"],
        ),
        (
            "non-finite --time",
            &["--time", "inf"],
            &["static", &g, "--time", "inf"],
        ),
        (
            "eig --modes 0",
            &["--modes must be at least 1"],
            &["eig", &g, "--modes", "0"],
        ),
        (
            "eig --modes beyond the DOFs",
            &["--modes 18", "17 degrees of freedom"],
            &["eig", &g, "--modes", "18"],
        ),
        (
            "negative eig --modes",
            &["'--modes <MODES>'", "-1"],
            &["eig", &g, "--modes", "-1"],
        ),
        (
            "sweep --modes 0",
            &["--modes must be at least 1"],
            &[
                "sweep", &g, "--over", "load", "--from", "0", "--to", "1", "--modes", "0", "--out",
                &out,
            ],
        ),
        (
            "sweep --n 0",
            &["--n must be at least 2", "got 0"],
            &[
                "sweep", &g, "--over", "load", "--from", "0", "--to", "1", "--n", "0", "--out",
                &out,
            ],
        ),
        (
            "sweep --n 1",
            &["--n must be at least 2", "got 1"],
            &[
                "sweep", &g, "--over", "load", "--from", "0", "--to", "1", "--n", "1", "--out",
                &out,
            ],
        ),
        (
            "sweep --from equal to --to",
            &["--from and --to must differ", "0.5"],
            &[
                "sweep", &g, "--over", "load", "--from", "0.5", "--to", "0.5", "--out", &out,
            ],
        ),
        (
            "sweep --t-load NaN",
            &["--t-load", "NaN"],
            &[
                "sweep", &g, "--over", "load", "--from", "0", "--to", "1", "--t-load", "nan",
                "--out", &out,
            ],
        ),
        (
            "unknown --over name",
            &["'S.q'", "flexmb info"],
            &[
                "sweep", &g, "--over", "S.q", "--from", "0", "--to", "1", "--out", &out,
            ],
        ),
        (
            "--over path without --path",
            &["--path PATH.csv"],
            &[
                "sweep", &g, "--over", "path", "--from", "0", "--to", "1", "--out", &out,
            ],
        ),
        (
            "missing required --from",
            &["--from <FROM>"],
            &["sweep", &g, "--over", "load", "--to", "1"],
        ),
        ("unknown subcommand", &["'frobnicate'"], &["frobnicate"]),
        (
            "unknown option",
            &["'--verbose'"],
            &["info", &g, "--verbose"],
        ),
    ];
    for (what, culprit, args) in rows {
        k.case(what, 2, culprit, args);
    }
}

/// The rows of `flexmb draw`: modes, views, amplitudes, phases, state
/// files and figure names.
fn draw_rows(k: &mut Catalogue) {
    let g = k.good();
    let fig = k.path("fig.svg");
    let unknown_column = k.file("state_bad.csv", "t,S.q\n0,1\n");
    let not_a_dof = k.file("state_not_dof.csv", "S.x\n0.1\n");
    let no_rows = k.file("state_empty.csv", "flexure1.1.bending_p\n");
    let dev_null = "/dev/null/fig.png".to_string();
    let rows: [(&'static str, &[&str], &[&str]); 11] = [
        (
            "draw --mode beyond the modes",
            &["--mode 18", "17 modes", "numbered 1 to 17"],
            &["draw", &g, "--mode", "18", "--out", &fig],
        ),
        (
            "draw --mode 0",
            &["--mode must be at least 1"],
            &["draw", &g, "--mode", "0", "--out", &fig],
        ),
        (
            "draw unknown --view",
            &["--view", "'top'", "iso, xy, xz or yz"],
            &["draw", &g, "--view", "top", "--out", &fig],
        ),
        (
            "draw --out with another extension",
            &["fig.pdf", ".svg or .png"],
            &["draw", &g, "--out", "fig.pdf"],
        ),
        (
            "draw --out without an extension",
            &["--out", "fig", ".svg or .png"],
            &["draw", &g, "--out", "fig"],
        ),
        (
            "draw --out in an unwritable place",
            &["--out", "/dev/null/fig.png", "cannot write there"],
            &["draw", &g, "--out", &dev_null],
        ),
        (
            "draw --amplitude negative",
            &["--amplitude", "positive", "-0.01"],
            &[
                "draw",
                &g,
                "--mode",
                "1",
                "--amplitude",
                "-0.01",
                "--out",
                &fig,
            ],
        ),
        (
            "draw --phases 0",
            &["--phases must be at least 1"],
            &["draw", &g, "--mode", "1", "--phases", "0", "--out", &fig],
        ),
        (
            "draw --state with an unknown column",
            &["state_bad.csv", "'S.q'", "flexmb info"],
            &["draw", &g, "--state", &unknown_column, "--out", &fig],
        ),
        (
            "draw --state with a coordinate that is no DOF",
            &[
                "state_not_dof.csv",
                "'S.x'",
                "not one of its degrees of freedom",
            ],
            &["draw", &g, "--state", &not_a_dof, "--out", &fig],
        ),
        (
            "draw --state without values",
            &["state_empty.csv", "no row of values"],
            &["draw", &g, "--state", &no_rows, "--out", &fig],
        ),
    ];
    for (what, culprit, args) in rows {
        k.case(what, 2, culprit, args);
    }
}

/// The rows of `flexmb reduce` options.
fn reduce_rows(k: &mut Catalogue) {
    let g = k.good();
    let m = k.path("reduce_model.ron");
    let load = [
        "--over", "load", "--from", "-1", "--to", "1", "--t-load", "0.05",
    ];
    let svd = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = [
            "reduce",
            &g,
            "--method",
            "svd-modal",
            "--modes",
            "2",
            "--out",
            &m,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        a.extend(load.iter().map(|s| s.to_string()));
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let svd_rows: [(&'static str, &[&str], &[&str]); 3] = [
        (
            "reduce --threshold out of (0, 1)",
            &["--threshold", "(0, 1)", "1.5"],
            &["--threshold", "1.5"],
        ),
        ("reduce --n 1", &["--n must be at least 2"], &["--n", "1"]),
        (
            "reduce --final-threshold with svd-modal",
            &["--final-threshold (fbm-svd only)"],
            &["--final-threshold", "0.1"],
        ),
    ];
    for (what, culprit, extra) in svd_rows {
        let args = svd(extra);
        let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
        k.case(what, 2, culprit, &args);
    }
    let dir = k.dir.display().to_string();
    let rows: [(&'static str, &[&str], &[&str]); 10] = [
        (
            "reduce --modes 0",
            &["--modes must be at least 1"],
            &[
                "reduce", &g, "--method", "modal", "--modes", "0", "--out", &m,
            ],
        ),
        (
            "reduce --modes beyond the DOFs",
            &["--modes 18", "17 degrees of freedom"],
            &[
                "reduce", &g, "--method", "modal", "--modes", "18", "--out", &m,
            ],
        ),
        (
            "unknown --method",
            &["'pod'", "--method"],
            &["reduce", &g, "--method", "pod", "--modes", "2", "--out", &m],
        ),
        (
            "a sweep for the modal method",
            &["--over", "--method modal"],
            &[
                "reduce", &g, "--method", "modal", "--modes", "2", "--over", "load", "--out", &m,
            ],
        ),
        (
            "reduce --from equal to --to",
            &["--from and --to", "differ"],
            &[
                "reduce",
                &g,
                "--method",
                "svd-modal",
                "--modes",
                "2",
                "--over",
                "load",
                "--from",
                "1",
                "--to",
                "1",
                "--t-load",
                "0.05",
                "--out",
                &m,
            ],
        ),
        (
            "a load sweep with no load at --t-load",
            &["--t-load", "zero at t = 0"],
            &[
                "reduce",
                &g,
                "--method",
                "svd-modal",
                "--modes",
                "2",
                "--over",
                "load",
                "--from",
                "0",
                "--to",
                "1",
                "--out",
                &m,
            ],
        ),
        (
            "an interpolated basis over the load",
            &["--method ibm-msi", "--over COORD"],
            &[
                "reduce", &g, "--method", "ibm-msi", "--modes", "1", "--over", "load", "--from",
                "0", "--to", "1", "--out", &m,
            ],
        ),
        (
            "unknown --keep coordinate",
            &["--keep", "'Q.x'"],
            &[
                "reduce", &g, "--method", "modal", "--modes", "2", "--keep", "Q.x", "--out", &m,
            ],
        ),
        (
            "--keep twice",
            &["--keep lists 'flexure1.1.bending_p' twice"],
            &[
                "reduce",
                &g,
                "--method",
                "modal",
                "--modes",
                "2",
                "--keep",
                "flexure1.1.bending_p,flexure1.1.bending_p",
                "--out",
                &m,
            ],
        ),
        (
            "reduce --out a directory",
            &["--out", &dir, "is a directory"],
            &[
                "reduce", &g, "--method", "modal", "--modes", "2", "--out", &dir,
            ],
        ),
    ];
    for (what, culprit, args) in rows {
        k.case(what, 2, culprit, args);
    }
}

/// The rows on output locations and other input files: path CSVs, saved
/// reduced models, superelement specifications.
fn file_rows(k: &mut Catalogue) {
    let g = k.good();
    // a regular file where a directory must be: unwritable even for root
    let blocker = k.file("blocker", "a file, not a directory\n");
    let under = format!("{blocker}/out");
    let m = format!("{blocker}/model.ron");
    let rows: [(&'static str, &[&str], Vec<&str>); 4] = [
        (
            "unwritable simulate --out",
            &["--out", &under, "cannot write"],
            vec!["simulate", &g, "--out", &under],
        ),
        (
            "unwritable static --out",
            &["--out", &under, "cannot write"],
            vec!["static", &g, "--out", &under],
        ),
        (
            "unwritable sweep --out",
            &["--out", &under, "cannot write"],
            vec![
                "sweep", &g, "--over", "load", "--from", "0", "--to", "1", "--out", &under,
            ],
        ),
        (
            "unwritable reduce --out",
            &["--out", &m, "not a directory"],
            vec![
                "reduce", &g, "--method", "modal", "--modes", "2", "--out", &m,
            ],
        ),
    ];
    for (what, culprit, args) in rows {
        k.case(what, 2, culprit, &args);
    }
    // path files of `sweep --over path`
    let out = k.path("out_path");
    let paths = [
        (
            "bad path header",
            "x,y\n0,1\n1,2\n",
            vec!["bad_header.csv", "`s,NAME,...`"],
        ),
        (
            "path s not increasing",
            "s,flexure1.1.bending_p\n0,0\n0,0.1\n",
            vec!["not_increasing.csv", "s must increase"],
        ),
        (
            "unknown path column",
            "s,Q.x\n0,0\n1,0.1\n",
            vec!["path column 'Q.x'"],
        ),
    ];
    for (i, (what, text, culprit)) in paths.into_iter().enumerate() {
        let name = ["bad_header.csv", "not_increasing.csv", "unknown_column.csv"][i];
        let p = k.file(name, text);
        k.case(
            what,
            2,
            &culprit,
            &[
                "sweep", &g, "--over", "path", "--path", &p, "--from", "0", "--to", "1", "--out",
                &out,
            ],
        );
    }
    let p = k.path("no_such_path.csv");
    k.case(
        "missing path file",
        2,
        &["no_such_path.csv"],
        &[
            "sweep", &g, "--over", "path", "--path", &p, "--from", "0", "--to", "1", "--out", &out,
        ],
    );
    // saved reduced models
    let model = k.path("modal2.ron");
    let o = Command::new(env!("CARGO_BIN_EXE_flexmb"))
        .args([
            "reduce", &g, "--method", "modal", "--modes", "2", "--out", &model,
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let saved = std::fs::read_to_string(&model).unwrap();
    let nodal = k.scene("nodal.ron", "dofs: Deformations", "dofs: NodalCoordinates");
    let spatial = fixture("straight_guidance_spatial.ron")
        .display()
        .to_string();
    let typo = k.file("typo_model.ron", &saved.replacen("vectors", "vectorz", 1));
    let missing = k.path("no_such_model.ron");
    let out = k.path("out_reduced");
    let rows: [(&'static str, &[&str], Vec<&str>); 6] = [
        (
            "a reduced model of other DOFs",
            &[
                "modal2.ron",
                "other degrees of freedom",
                "DOF 1",
                "`B.x` in the scene",
            ],
            vec!["simulate", &nodal, "--reduced", &model, "--out", &out],
        ),
        (
            "a reduced model of another scene",
            &["modal2.ron", "the model has 17 DOFs, the scene 44"],
            vec!["simulate", &spatial, "--reduced", &model, "--out", &out],
        ),
        (
            "a reduced model with a misspelt field",
            &["typo_model.ron", "`vectorz`", "did you mean `vectors`?"],
            vec!["simulate", &g, "--reduced", &typo, "--out", &out],
        ),
        (
            "missing reduced model",
            &["no_such_model.ron"],
            vec!["simulate", &g, "--reduced", &missing, "--out", &out],
        ),
        (
            "a reduced model with genalpha",
            &["--integrator dopri5 or adams", "genalpha"],
            vec![
                "simulate",
                &g,
                "--reduced",
                &model,
                "--integrator",
                "genalpha",
                "--out",
                &out,
            ],
        ),
        (
            "a reduced sweep over a coordinate",
            &["--reduced sweeps over `load` only", "--over S.x"],
            vec![
                "sweep",
                &g,
                "--reduced",
                &model,
                "--over",
                "S.x",
                "--from",
                "0",
                "--to",
                "1",
                "--out",
                &out,
            ],
        ),
    ];
    for (what, culprit, args) in rows {
        k.case(what, 2, culprit, &args);
    }
    // superelement build specifications
    let spec = k.file(
        "spec.ron",
        r#"(
    name: "flexure",
    model: CalculiX(job: "flexure"),
    settings: (
        p: (0.0, 0.0, 0.0),
        q: (0.04, 0.0, 0.0),
        interface_p: NearPlane(point: (0.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
        interface_q: NearPlane(point: (0.04, 0.0, 0.0), normal: (1.0, 0.0, 0.0), tolerance: 1e-7),
        normal_mode: 6,
    ),
    output: "flexure.se.ron",
)
"#,
    );
    k.case(
        "misspelt superelement spec field",
        2,
        &[
            "spec.ron:9",
            "`normal_mode`",
            "did you mean `normal_modes`?",
        ],
        &["build-superelement", &spec],
    );
    let p = k.path("no_such_spec.ron");
    k.case(
        "missing superelement spec",
        2,
        &["no_such_spec.ron"],
        &["build-superelement", &p],
    );
    // a scene whose superelement file is missing
    let se = std::fs::read_to_string(&spatial).unwrap();
    let beam = r#"type: Beam((nodes: ("A", "B"), material: "steel", section: "flexure", up: Some([0.0, 0.0, 1.0]), n: 5))"#;
    assert!(se.contains(beam));
    let scene = k.file(
        "superelement.ron",
        &se.replacen(
            beam,
            r#"type: Superelement(nodes: ("A", "B"), file: "missing.se.ron")"#,
            1,
        ),
    );
    k.case(
        "missing superelement file",
        2,
        &["missing.se.ron"],
        &["info", &scene],
    );
}

#[test]
fn every_bad_input_gives_its_exit_code_and_names_the_culprit() {
    let start = std::time::Instant::now();
    let mut k = Catalogue::new();
    scene_rows(&mut k);
    option_rows(&mut k);
    reduce_rows(&mut k);
    draw_rows(&mut k);
    file_rows(&mut k);
    let n = k.cases.len();
    assert!(n >= 40, "{n} rows");
    let failed = k.run();
    let _ = std::fs::remove_dir_all(&k.dir);
    assert!(
        failed.is_empty(),
        "{} of {n} rows failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
    eprintln!("{n} bad inputs in {:.2} s", start.elapsed().as_secs_f64());
}
