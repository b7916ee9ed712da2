//! The fuzz targets and the driver that runs cases for a bounded time,
//! catching panics and hangs.
//!
//! Target 1 ([`parse_and_validate`]): `Scene::from_ron_str`, then
//! `Scene::build`; either may fail, neither may panic or hang. Target 2
//! ([`with_dynamics`]) then also prepares `Dynamics` and evaluates q̈ at
//! t = 0 from q0 with q̇ = `initial_qd` (finite or an error; zeros when it
//! fails), and once
//! more at a configuration and velocity perturbed by the case's seed: each
//! call returns finite accelerations or an error (the energies at t = 0 as
//! well: finite or an error).

use super::{case_seed, generate, Case, Rng, SeedScene};
use flexmb_dynamics::Dynamics;
use flexmb_model::{ElementSpec, Scene};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Bounds on the models a case may build, so that a case that asks for a
/// huge model (the chain helper's `n`) is skipped rather than left to take
/// minutes and gigabytes. The default is twice the largest fixture (the
/// 720-DOF flexure chain has 120 beams): an invalid scene has its error
/// worded by the dense SVD of the whole model, cubic in its size (the
/// choice of DOFs itself is linear in a chain, with or without supports).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Most elements after chain expansion (the sum of `n`).
    pub max_elements: usize,
    /// Most nodes.
    pub max_nodes: usize,
    /// Most degrees of freedom for which the equations of motion are
    /// evaluated (the mass matrix is dense).
    pub max_dofs: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_elements: 250,
            max_nodes: 1000,
            max_dofs: 400,
        }
    }
}

/// How far a case got.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Outcome {
    /// The text is not a scene (a parse error).
    ParseError,
    /// The scene asks for a model above the [`Limits`]; not built.
    TooLarge,
    /// `build` returned an error.
    BuildError,
    /// Built (target 1), or built but above `max_dofs` (target 2).
    Built,
    /// The evaluation at q0 returned an error.
    EomError,
    /// The evaluation at q0 returned finite accelerations, the one at the
    /// perturbed state an error.
    PerturbedError,
    /// Both evaluations returned finite accelerations.
    EomOk,
}

/// Which harness a run uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Parser and validator.
    Parse,
    /// Parser, validator, `Dynamics` and q̈.
    Dynamics,
}

impl Target {
    /// The share of mutations made on the parsed scene rather than on the
    /// text: half for the parser, more for the dynamics (whose cases must
    /// get through the parser and the validator to reach it).
    pub fn structural_share(self) -> f64 {
        match self {
            Target::Parse => 0.5,
            Target::Dynamics => 0.8,
        }
    }
    /// The name `--target` takes.
    pub fn name(self) -> &'static str {
        match self {
            Target::Parse => "parse",
            Target::Dynamics => "dynamics",
        }
    }
}

/// The elements a scene would make after chain expansion (saturating).
pub fn chain_elements(scene: &Scene) -> usize {
    scene
        .elements
        .iter()
        .map(|e| chain_n(&e.kind))
        .fold(0usize, usize::saturating_add)
}

/// Whether a scene is within the limits. `build` refuses a chain with
/// `n = 0` or `n` over the chain helper's maximum (10⁶) before it expands
/// it, so such a scene is run when the chains before that one are small.
fn within(scene: &Scene, l: &Limits) -> bool {
    if scene.nodes.len() > l.max_nodes {
        return false;
    }
    let mut total = 0usize;
    for e in &scene.elements {
        let n = chain_n(&e.kind);
        if n == 0 || n > 1_000_000 {
            return total <= l.max_elements;
        }
        total = total.saturating_add(n);
    }
    total <= l.max_elements
}

fn chain_n(k: &ElementSpec) -> usize {
    match k {
        ElementSpec::Beam(b) => b.n,
        ElementSpec::Truss { n, .. } => *n,
        _ => 1,
    }
}

/// Target 1: parse and validate; `base_dir` resolves superelement files.
pub fn parse_and_validate(text: &str, l: &Limits, base_dir: Option<&Path>) -> Outcome {
    let Ok(scene) = Scene::from_ron_str(text) else {
        return Outcome::ParseError;
    };
    if !within(&scene, l) {
        return Outcome::TooLarge;
    }
    match scene.build(base_dir) {
        Ok(_) => Outcome::Built,
        Err(_) => Outcome::BuildError,
    }
}

/// Target 2: parse, validate, and evaluate q̈ twice: at t = 0 from q0 with
/// q̇ from the scene's initial velocities, and at a configuration and
/// velocity perturbed by `seed`; the energies at t = 0 too. Panics if an
/// evaluation returns Ok with a non-finite value.
pub fn with_dynamics(text: &str, l: &Limits, base_dir: Option<&Path>, seed: u64) -> Outcome {
    let Ok(scene) = Scene::from_ron_str(text) else {
        return Outcome::ParseError;
    };
    if !within(&scene, l) {
        return Outcome::TooLarge;
    }
    let mech = match scene.build(base_dir) {
        Ok(m) => m,
        Err(_) => return Outcome::BuildError,
    };
    let n = mech.n_dof();
    if n > l.max_dofs {
        return Outcome::Built;
    }
    let q0 = mech.q0();
    let mut dy = Dynamics::new(Arc::new(mech));
    let qd0 = match dy.initial_qd(0.0, &q0) {
        Ok(v) => {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                panic!("initial_qd returned Ok with q̇[{i}] = {}", v[i]);
            }
            v
        }
        Err(_) => vec![0.0; n],
    };
    let mut qdd = vec![0.0; n];
    if dy.accelerations(0.0, &q0, &qd0, &mut qdd).is_err() {
        return Outcome::EomError;
    }
    if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
        panic!("accelerations returned Ok with q̈[{i}] = {}", qdd[i]);
    }
    if let Ok(e) = dy.energies(0.0, &q0, &qd0) {
        let v = [e.kinetic, e.elastic, e.gravitational];
        assert!(
            v.iter().all(|x| x.is_finite()),
            "energies returned Ok with {e:?}"
        );
    }
    let mut rng = Rng::new(seed ^ 0xd1b5_4a32_d192_ed03);
    let scale = *rng.pick(&[1e-6, 1e-3, 0.1, 1.0, 10.0, 1e3]);
    let q: Vec<f64> = q0.iter().map(|v| v + scale * (rng.unit() - 0.5)).collect();
    let qd: Vec<f64> = qd0.iter().map(|v| v + scale * (rng.unit() - 0.5)).collect();
    let t = *rng.pick(&[0.0, 1e-3, 0.3, 2.0, -1.0, 1e9]);
    if dy.accelerations(t, &q, &qd, &mut qdd).is_err() {
        return Outcome::PerturbedError;
    }
    if let Some(i) = qdd.iter().position(|v| !v.is_finite()) {
        panic!(
            "accelerations returned Ok with q̈[{i}] = {} (perturbed state at t = {t})",
            qdd[i]
        );
    }
    Outcome::EomOk
}

/// A run's settings.
#[derive(Clone, Debug)]
pub struct Options {
    /// The run's seed; case k has seed [`case_seed`]`(seed, k)`.
    pub seed: u64,
    /// Stop starting cases after this time.
    pub duration: Duration,
    /// Stop after this many cases (if given).
    pub max_cases: Option<u64>,
    /// A case that takes longer is a hang.
    pub case_timeout: Duration,
    /// Where failing inputs are written.
    pub out_dir: PathBuf,
    /// The harness.
    pub target: Target,
    /// Model size limits.
    pub limits: Limits,
    /// The directory superelement files are resolved in ([`base_dir`]).
    pub base_dir: PathBuf,
}

/// Where the superelement files of the seed scenes are: `fixtures/fuzz/`.
pub fn base_dir(root: &Path) -> PathBuf {
    root.join("fixtures/fuzz")
}

/// Why a case failed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Problem {
    /// It panicked, with this message (location and backtrace).
    Panic(String),
    /// It ran longer than the case timeout.
    Hang(Duration),
}

/// A failing case.
#[derive(Clone, Debug)]
pub struct Failure {
    /// The case (its seed makes it again).
    pub case: Case,
    /// What happened.
    pub problem: Problem,
    /// The file the input was written to.
    pub file: PathBuf,
}

/// What a run did.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// The run's seed.
    pub seed: u64,
    /// Cases run.
    pub cases: u64,
    /// Count of each outcome, in [`Outcome`] order.
    pub outcomes: std::collections::BTreeMap<String, u64>,
    /// Failing cases (the run stops at the first hang).
    pub failures: Vec<Failure>,
    /// Wall time.
    pub elapsed: Duration,
}

impl Report {
    /// Cases with this outcome.
    pub fn count(&self, o: Outcome) -> u64 {
        self.outcomes.get(&format!("{o:?}")).copied().unwrap_or(0)
    }
    /// One line per outcome and per failure.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "seed {:#018x}: {} cases in {:.1} s ({:.0} per second)",
            self.seed,
            self.cases,
            self.elapsed.as_secs_f64(),
            self.cases as f64 / self.elapsed.as_secs_f64().max(1e-9)
        );
        for (k, v) in &self.outcomes {
            s.push_str(&format!("\n  {k:<11} {v:>7}"));
        }
        for f in &self.failures {
            s.push_str(&format!(
                "\nFAILED case {:#018x} ({}): {}\n  input written to {}",
                f.case.seed,
                match &f.problem {
                    Problem::Panic(_) => "panic".to_string(),
                    Problem::Hang(d) => format!("no result after {:.1} s", d.as_secs_f64()),
                },
                first_line(&f.problem),
                f.file.display()
            ));
        }
        s
    }
}

fn first_line(p: &Problem) -> String {
    match p {
        Problem::Panic(m) => m.lines().take(2).collect::<Vec<_>>().join(" "),
        Problem::Hang(_) => "a hang".into(),
    }
}

thread_local! {
    /// Set while a case runs: the panic hook then records the message here
    /// instead of printing it.
    static CAPTURE: RefCell<Option<String>> = const { RefCell::new(None) };
    static IN_CASE: RefCell<bool> = const { RefCell::new(false) };
}

/// Installs (once) a panic hook that records the panics of cases with their
/// location and backtrace, and leaves every other panic to the previous hook.
fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if IN_CASE.with(|c| *c.borrow()) {
                let bt = std::backtrace::Backtrace::force_capture();
                CAPTURE.with(|c| *c.borrow_mut() = Some(format!("{info}\n{bt}")));
            } else {
                previous(info)
            }
        }));
    });
}

/// Runs `f` on this thread, catching a panic with its message.
pub fn catching<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    IN_CASE.with(|c| *c.borrow_mut() = true);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    IN_CASE.with(|c| *c.borrow_mut() = false);
    r.map_err(|payload| {
        CAPTURE.with(|c| c.borrow_mut().take()).unwrap_or_else(|| {
            payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "a panic without a message".into())
        })
    })
}

/// Writes a failing input: a comment header (seed, source, mutations, what
/// happened) and the text, so that the file itself reproduces the failure
/// (`cargo xtask fuzz --input FILE`) as the seed does (`--case SEED`).
pub fn write_failure(dir: &Path, target: Target, case: &Case, problem: &Problem) -> PathBuf {
    let kind = match problem {
        Problem::Panic(_) => "panic",
        Problem::Hang(_) => "hang",
    };
    let file = dir.join(format!("{kind}-{:016x}.ron", case.seed));
    let mut head = format!(
        "// cargo xtask fuzz --target {} --case {:#018x}\n// from {}\n",
        target.name(),
        case.seed,
        case.source
    );
    for m in &case.mutations {
        head.push_str(&format!("// {}\n", m.replace('\n', " ")));
    }
    match problem {
        Problem::Panic(m) => {
            for l in m.lines().take(12) {
                head.push_str(&format!("// {l}\n"));
            }
        }
        Problem::Hang(d) => {
            head.push_str(&format!("// no result after {:.1} s\n", d.as_secs_f64()))
        }
    }
    let _ = std::fs::create_dir_all(dir);
    let _ = std::fs::write(&file, format!("{head}{}", case.text));
    file
}

/// Runs one text through a target, catching a panic.
pub fn run_text(
    text: &str,
    target: Target,
    l: &Limits,
    base_dir: &Path,
    seed: u64,
) -> Result<Outcome, String> {
    catching(|| match target {
        Target::Parse => parse_and_validate(text, l, Some(base_dir)),
        Target::Dynamics => with_dynamics(text, l, Some(base_dir), seed),
    })
}

/// The file holding the input of the case that is running (removed at the
/// end of a run; left behind by a case that aborted the process).
pub const CURRENT: &str = "current-case.ron";

enum Msg {
    Done(Case, Result<Outcome, String>),
}

/// Runs cases from the corpus until the duration or case count is reached,
/// with the given target function (the real targets through [`fuzz`]; tests
/// pass others to check that panics and hangs are caught). Cases run one at
/// a time on a worker thread with an 8 MiB stack (the main thread's); a case
/// without a result after the case timeout ends the run as a hang (the
/// thread cannot be stopped, so the caller should exit).
pub fn drive<F>(corpus: Arc<Vec<SeedScene>>, o: &Options, run: F) -> Report
where
    F: Fn(&Case) -> Result<Outcome, String> + Send + 'static,
{
    let start = Instant::now();
    let _ = std::fs::create_dir_all(&o.out_dir);
    let (to_worker, jobs) = mpsc::channel::<Case>();
    let (to_main, results) = mpsc::channel::<Msg>();
    let worker = std::thread::Builder::new()
        .name("fuzz case".into())
        .stack_size(8 << 20)
        .spawn(move || {
            for case in jobs {
                let r = run(&case);
                if to_main.send(Msg::Done(case, r)).is_err() {
                    break;
                }
            }
        })
        .expect("a worker thread");
    let mut report = Report {
        seed: o.seed,
        ..Default::default()
    };
    let mut k = 0u64;
    loop {
        if start.elapsed() >= o.duration || o.max_cases.is_some_and(|m| k >= m) {
            break;
        }
        let case = generate(&corpus, case_seed(o.seed, k), o.target.structural_share());
        k += 1;
        let pending = case.clone();
        // an abort (stack overflow, out of memory) cannot be caught: the
        // input it left is here
        let _ = std::fs::write(o.out_dir.join(CURRENT), &case.text);
        if to_worker.send(case).is_err() {
            break;
        }
        match results.recv_timeout(o.case_timeout) {
            Ok(Msg::Done(case, r)) => {
                report.cases += 1;
                match r {
                    Ok(outcome) => {
                        *report.outcomes.entry(format!("{outcome:?}")).or_default() += 1;
                    }
                    Err(msg) => {
                        *report.outcomes.entry("Panic".into()).or_default() += 1;
                        let problem = Problem::Panic(msg);
                        let file = write_failure(&o.out_dir, o.target, &case, &problem);
                        report.failures.push(Failure {
                            case,
                            problem,
                            file,
                        });
                    }
                }
            }
            Err(_) => {
                report.cases += 1;
                *report.outcomes.entry("Hang".into()).or_default() += 1;
                let problem = Problem::Hang(o.case_timeout);
                let file = write_failure(&o.out_dir, o.target, &pending, &problem);
                report.failures.push(Failure {
                    case: pending,
                    problem,
                    file,
                });
                report.elapsed = start.elapsed();
                // the worker is still in the case: leave it
                return report;
            }
        }
    }
    drop(to_worker);
    let _ = worker.join();
    let _ = std::fs::remove_file(o.out_dir.join(CURRENT));
    report.elapsed = start.elapsed();
    report
}

/// A fuzz run of the real targets.
pub fn fuzz(corpus: Vec<SeedScene>, o: &Options) -> Report {
    let (target, limits, dir) = (o.target, o.limits, o.base_dir.clone());
    drive(Arc::new(corpus), o, move |case| {
        run_text(&case.text, target, &limits, &dir, case.seed)
    })
}
