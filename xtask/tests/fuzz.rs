//! The fuzz harness (`cargo xtask fuzz`, issue 14 item 8): a short run of
//! fixed seed through both targets finds no panic and no hang, and the
//! driver does catch a panic or a hang and writes the input that caused it.

use std::sync::Arc;
use std::time::Duration;
use xtask::fuzz::harness::{self, drive, Limits, Options, Outcome, Problem, Target};
use xtask::fuzz::{corpus, generate, Case};

fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("flexmb-fuzz-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn options(seed: u64, cases: u64, target: Target, dir: &str) -> Options {
    Options {
        seed,
        duration: Duration::from_secs(600),
        max_cases: Some(cases),
        // generous: CI machines are shared; the slowest case here takes 0.5 s
        case_timeout: Duration::from_secs(30),
        out_dir: temp_dir(dir),
        target,
        limits: Limits::default(),
        base_dir: harness::base_dir(&xtask::workspace_root()),
    }
}

/// 300 cases of each target with a fixed seed: no panic, no hang, and the
/// cases reach every stage (so the run is not vacuous: parse errors, build
/// errors, built mechanisms and evaluated equations of motion).
#[test]
fn a_short_fuzz_run_of_fixed_seed_finds_no_panic_and_no_hang() {
    let root = xtask::workspace_root();
    let c = corpus(&root).unwrap();
    assert!(c.len() >= 14, "fixtures/scenes and fixtures/fuzz");
    for (target, seed) in [(Target::Parse, 14), (Target::Dynamics, 15)] {
        let o = options(seed, 300, target, &format!("{target:?}"));
        let r = harness::fuzz(c.clone(), &o);
        println!("{target:?}: {}", r.summary());
        assert!(r.failures.is_empty(), "{}", r.summary());
        assert_eq!(r.cases, 300);
        let frac = |o: Outcome| r.count(o) as f64 / r.cases as f64;
        assert!(frac(Outcome::ParseError) > 0.1, "{}", r.summary());
        assert!(frac(Outcome::BuildError) > 0.1, "{}", r.summary());
        match target {
            Target::Parse => assert!(frac(Outcome::Built) > 0.1, "{}", r.summary()),
            Target::Dynamics => {
                assert!(frac(Outcome::EomOk) > 0.05, "{}", r.summary());
                assert!(r.count(Outcome::EomError) + r.count(Outcome::PerturbedError) > 0);
            }
        }
    }
}

/// A target that panics on some inputs: every such case is reported with its
/// message and location, its input is written to a file, the run goes on,
/// and the seed makes the same case again.
#[test]
fn a_panic_is_caught_and_its_input_written() {
    let root = xtask::workspace_root();
    let c = Arc::new(corpus(&root).unwrap());
    let o = options(7, 60, Target::Parse, "panic");
    let r = drive(c.clone(), &o, |case: &Case| {
        harness::catching(|| {
            if case.text.contains("Hinge") {
                panic!("a hinge in case {:#x}", case.seed);
            }
            Outcome::Built
        })
    });
    assert_eq!(r.cases, 60, "the run goes on after a panic");
    assert!(!r.failures.is_empty());
    assert_eq!(r.count(Outcome::Built) + r.failures.len() as u64, 60);
    for f in &r.failures {
        let Problem::Panic(m) = &f.problem else {
            panic!("{:?}", f.problem)
        };
        assert!(
            m.contains(&format!("a hinge in case {:#x}", f.case.seed)) && m.contains("fuzz.rs"),
            "message and location: {m}"
        );
        let written = std::fs::read_to_string(&f.file).unwrap();
        assert!(written.ends_with(&f.case.text), "{}", f.file.display());
        assert!(written.contains(&format!("--case {:#018x}", f.case.seed)));
        assert_eq!(
            generate(&c, f.case.seed, Target::Parse.structural_share()),
            f.case,
            "reproducible from its seed"
        );
    }
    assert!(r.summary().contains("FAILED case"));
    assert!(
        !o.out_dir.join(harness::CURRENT).exists(),
        "the running case's file is removed at the end"
    );
}

/// A case that does not finish within the case timeout ends the run as a
/// hang, with its input written.
#[test]
fn a_hang_is_reported_with_its_input() {
    let root = xtask::workspace_root();
    let c = Arc::new(corpus(&root).unwrap());
    let mut o = options(8, 50, Target::Parse, "hang");
    o.case_timeout = Duration::from_millis(300);
    let third = generate(
        &c,
        xtask::fuzz::case_seed(8, 2),
        Target::Parse.structural_share(),
    );
    let r = drive(c, &o, move |case: &Case| {
        if case.seed == third.seed {
            std::thread::sleep(Duration::from_secs(3));
        }
        Ok(Outcome::Built)
    });
    assert_eq!(r.cases, 3, "stops at the hang");
    assert_eq!(r.failures.len(), 1);
    let f = &r.failures[0];
    assert_eq!(f.problem, Problem::Hang(Duration::from_millis(300)));
    assert!(std::fs::read_to_string(&f.file)
        .unwrap()
        .ends_with(&f.case.text));
}

/// The structure-aware mutations start from the scene written back by
/// `Scene::to_ron`: that must be the same scene.
#[test]
fn every_seed_scene_survives_writing_back() {
    let root = xtask::workspace_root();
    for s in corpus(&root).unwrap() {
        let a = flexmb_model::Scene::from_ron_str(&s.text).unwrap();
        let b = flexmb_model::Scene::from_ron_str(&a.to_ron()).unwrap();
        assert_eq!(a, b, "{}", s.name);
        let m = a.build(Some(&harness::base_dir(&root)));
        assert!(m.is_ok(), "{}: {:?}", s.name, m.err());
    }
}

/// Models above the limits are skipped, except chain counts that `build`
/// refuses before expanding anything.
#[test]
fn huge_chains_are_skipped_or_refused_at_once() {
    let scene = |n: &str| {
        format!(
            r#"(
        dimension: Planar,
        materials: {{ "al": (e: 7.0e10, rho: 2700.0) }},
        sections: {{ "bar": Rectangle(by: 0.01, bz: 0.02) }},
        nodes: [ (id: "A", at: [0.0, 0.0]), (id: "B", at: [1.0, 0.0]) ],
        elements: [ (id: "ab", type: Beam((nodes: ("A", "B"), material: "al", section: "bar", n: {n}))) ],
        fixed: [ Node("A") ],
    )"#
        )
    };
    let l = Limits::default();
    let dir = harness::base_dir(&xtask::workspace_root());
    let run = |n: &str| harness::run_text(&scene(n), Target::Dynamics, &l, &dir, 0).unwrap();
    assert_eq!(run("3"), Outcome::EomOk);
    assert_eq!(run("251"), Outcome::TooLarge);
    assert_eq!(run("300000"), Outcome::TooLarge);
    assert_eq!(run("18446744073709551615"), Outcome::BuildError);
    assert_eq!(run("0"), Outcome::BuildError);
}
