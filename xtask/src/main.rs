//! `cargo xtask reproduce ch2|ch3|ch4|ch5|ch6|ch7|ch7xy|all`, `cargo xtask regress` and `cargo xtask fuzz`.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use xtask::fuzz::harness as fuzz;
use xtask::progress::Progress;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Regenerate the thesis benchmarks (chapters 2, 5 and 6), check the stored eigenfrequency curves, fuzz the scene input"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Chapter {
    Ch2,
    Ch3,
    Ch4,
    Ch5,
    Ch6,
    Ch7,
    /// Beyond the thesis: the two-coordinate basis over the workspace.
    Ch7xy,
    All,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum FuzzTarget {
    /// Parser and validator (`Scene::from_ron_str`, `Scene::build`).
    Parse,
    /// Also `Dynamics::new` and q̈ from `accelerations`.
    Dynamics,
    /// Half the time each.
    Both,
}

#[derive(Subcommand)]
enum Cmd {
    /// Regenerate a chapter's results into OUT/chN (CSV, SVG, report.md).
    Reproduce {
        /// ch2, ch3, ch4, ch5, ch6, ch7, ch7xy or all.
        chapter: Chapter,
        /// Output directory.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Build the chapter-4 mechanism's part superelements from their FE
    /// models and write them with its scene and skeletons to
    /// fixtures/scenes (two_dof_mechanism.ron, two_dof_mechanism/*.se.ron).
    Mechanism4 {
        /// Write into this directory instead of fixtures/scenes.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// The chapter-4 base cross-hinge against its stored CalculiX solid
    /// (issue 17): report.md, hinge.csv, figures and the models' scenes in
    /// OUT.
    Hinge4 {
        /// Output directory.
        #[arg(long, default_value = "results/ch4_hinge")]
        out: PathBuf,
    },
    /// Recompute the eigenfrequency curves and compare them with fixtures/curves.
    Regress {
        /// Store the recomputed curves as the new fixtures instead of comparing.
        #[arg(long)]
        update: bool,
        /// Only this chapter's curves (ch2, ch3, ch4, ch5, ch6, ch7 or ch7xy; default all).
        #[arg(long, value_enum)]
        chapter: Option<Chapter>,
    },
    /// Fuzz the scene parser, the validator and one evaluation of the
    /// equations of motion with mutated fixture scenes, for a bounded time.
    /// A panic or hang is written to OUT/{panic,hang}-SEED.ron (exit code 1).
    Fuzz {
        /// Run for this long (seconds).
        #[arg(long, default_value_t = 60.0)]
        seconds: f64,
        /// The run's seed (decimal or 0x hex); default from the clock.
        #[arg(long, value_parser = parse_seed)]
        seed: Option<u64>,
        /// Stop after this many cases per target.
        #[arg(long)]
        cases: Option<u64>,
        /// parse, dynamics or both.
        #[arg(long, value_enum, default_value = "both")]
        target: FuzzTarget,
        /// A case without a result after this many seconds is a hang.
        #[arg(long, default_value_t = 10.0)]
        case_timeout: f64,
        /// Run only the case of this seed (as printed for a failure), printing it.
        #[arg(long, value_parser = parse_seed, conflicts_with = "input")]
        case: Option<u64>,
        /// Run only this scene file (e.g. a written failure).
        #[arg(long)]
        input: Option<PathBuf>,
        /// Where failing inputs are written (default: the target directory's fuzz/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn parse_seed(s: &str) -> Result<u64, String> {
    let r = match s.strip_prefix("0x") {
        Some(h) => u64::from_str_radix(h, 16),
        None => s.parse(),
    };
    r.map_err(|e| format!("{s}: {e}"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let root = xtask::workspace_root();
    let pg = Progress::visible();
    let result = match cli.cmd {
        Cmd::Reproduce { chapter, out } => {
            let out = if out.is_absolute() {
                out
            } else {
                root.join(out)
            };
            reproduce(&root, &out, chapter, &pg)
        }
        Cmd::Mechanism4 { out } => mechanism4(out.unwrap_or_else(xtask::ch4::fixture_dir)),
        Cmd::Hinge4 { out } => {
            let out = if out.is_absolute() {
                out
            } else {
                root.join(out)
            };
            xtask::ch4::hinge_check::write_report(&root, &out)
        }
        Cmd::Regress { update, chapter } => {
            regress(&root, update, chapter.unwrap_or(Chapter::All), &pg)
        }
        Cmd::Fuzz {
            seconds,
            seed,
            cases,
            target,
            case_timeout,
            case,
            input,
            out,
        } => {
            let out = out.unwrap_or_else(|| {
                std::env::var_os("CARGO_TARGET_DIR")
                    .map(PathBuf::from)
                    .unwrap_or_else(|| root.join("target"))
                    .join("fuzz")
            });
            let o = FuzzArgs {
                seconds,
                seed,
                cases,
                target,
                case_timeout,
                out,
            };
            match (case, input) {
                (Some(c), _) => fuzz_one_case(&root, c, target),
                (_, Some(p)) => fuzz_one_file(&root, &p, target),
                _ => fuzz(&root, &o),
            }
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn mechanism4(dir: PathBuf) -> Result<(), String> {
    let t = std::time::Instant::now();
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let builds = xtask::ch4::write_model(&dir, &|name| eprintln!("  built {name}"))?;
    for b in &builds {
        println!(
            "{:<48} {:>6} elements {:>8.4} kg {:>6.1} s  {}",
            b.what, b.elements, b.mass, b.seconds, b.file
        );
    }
    println!(
        "wrote {} and its skeletons in {:.0} s",
        dir.join(xtask::ch4::SCENE_FILE).display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

fn reproduce(
    root: &std::path::Path,
    out: &std::path::Path,
    ch: Chapter,
    pg: &Progress,
) -> Result<(), String> {
    let mut summary = vec![];
    if matches!(ch, Chapter::Ch2 | Chapter::All) {
        let t = std::time::Instant::now();
        let rows = xtask::ch2::reproduce(&out.join("ch2"), pg)?;
        summary.push(format!(
            "chapter 2 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch2/report.md").display()
        ));
        summary.extend(rows.iter().map(xtask::reproduce6::summary_line));
    }
    if matches!(ch, Chapter::Ch3 | Chapter::All) {
        let t = std::time::Instant::now();
        xtask::reproduce3::reproduce(root, &out.join("ch3"), pg)?;
        summary.push(format!(
            "chapter 3 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch3/report.md").display()
        ));
    }
    if matches!(ch, Chapter::Ch4 | Chapter::All) {
        let t = std::time::Instant::now();
        xtask::reproduce4::reproduce(root, &out.join("ch4"), pg)?;
        summary.push(format!(
            "chapter 4 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch4/report.md").display()
        ));
    }
    if matches!(ch, Chapter::Ch5 | Chapter::All) {
        let t = std::time::Instant::now();
        let rows = xtask::ch5::reproduce(root, &out.join("ch5"), pg)?;
        summary.push(format!(
            "chapter 5 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch5/report.md").display()
        ));
        summary.extend(rows.iter().map(xtask::reproduce6::summary_line));
    }
    if matches!(ch, Chapter::Ch6 | Chapter::All) {
        let t = std::time::Instant::now();
        let o = xtask::ch6::Ch6Options::default();
        let rows = xtask::reproduce6::reproduce(root, &out.join("ch6"), &o, pg)?;
        summary.push(format!(
            "chapter 6 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch6/report.md").display()
        ));
        summary.extend(rows.iter().map(xtask::reproduce6::summary_line));
    }
    if matches!(ch, Chapter::Ch7 | Chapter::All) {
        let t = std::time::Instant::now();
        xtask::reproduce7::reproduce(root, &out.join("ch7"), pg)?;
        summary.push(format!(
            "chapter 7 in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch7/report.md").display()
        ));
    }
    if matches!(ch, Chapter::Ch7xy | Chapter::All) {
        let t = std::time::Instant::now();
        xtask::reproduce7xy::reproduce(root, &out.join("ch7xy"), pg)?;
        summary.push(format!(
            "chapter 7, two coordinates, in {:.0} s: {}",
            t.elapsed().as_secs_f64(),
            out.join("ch7xy/report.md").display()
        ));
    }
    for l in summary {
        println!("{l}");
    }
    Ok(())
}

fn regress(
    root: &std::path::Path,
    update: bool,
    only: Chapter,
    pg: &Progress,
) -> Result<(), String> {
    type Recompute = fn(&std::path::Path, &Progress) -> Result<xtask::regress::Recomputed, String>;
    let chapters: [(Chapter, Recompute); 7] = [
        (Chapter::Ch2, xtask::regress::recompute_ch2),
        (Chapter::Ch3, xtask::ch3::recompute),
        (Chapter::Ch4, xtask::reproduce4::recompute),
        (Chapter::Ch5, xtask::regress::recompute_ch5),
        (Chapter::Ch6, xtask::regress::recompute_ch6),
        (Chapter::Ch7, xtask::reproduce7::recompute),
        (Chapter::Ch7xy, xtask::reproduce7xy::recompute),
    ];
    let sets = chapters
        .iter()
        .filter(|(c, _)| only == Chapter::All || *c == only)
        .map(|(_, f)| f(root, pg))
        .collect::<Result<Vec<_>, String>>()?;
    if update {
        for s in &sets {
            xtask::regress::update(s)?;
            println!("stored {} curves in {}", s.curves.len(), s.dir.display());
        }
        return Ok(());
    }
    let diffs: Vec<String> = sets.iter().flat_map(xtask::regress::check).collect();
    if diffs.is_empty() {
        let n: usize = sets.iter().map(|s| s.curves.len()).sum();
        println!(
            "{n} eigenfrequency curves agree with fixtures/curves (relative tolerance {:.0e})",
            xtask::regress::RTOL
        );
        Ok(())
    } else {
        for d in &diffs {
            eprintln!("{d}");
        }
        Err(format!(
            "{} differences from the stored curves",
            diffs.len()
        ))
    }
}

struct FuzzArgs {
    seconds: f64,
    seed: Option<u64>,
    cases: Option<u64>,
    target: FuzzTarget,
    case_timeout: f64,
    out: PathBuf,
}

fn targets(t: FuzzTarget) -> Vec<fuzz::Target> {
    match t {
        FuzzTarget::Parse => vec![fuzz::Target::Parse],
        FuzzTarget::Dynamics => vec![fuzz::Target::Dynamics],
        FuzzTarget::Both => vec![fuzz::Target::Parse, fuzz::Target::Dynamics],
    }
}

fn fuzz(root: &std::path::Path, a: &FuzzArgs) -> Result<(), String> {
    if !(a.seconds.is_finite() && a.seconds >= 0.0) {
        return Err(format!(
            "--seconds {} must be a non-negative number",
            a.seconds
        ));
    }
    if !(a.case_timeout.is_finite() && a.case_timeout > 0.0) {
        return Err(format!(
            "--case-timeout {} must be positive",
            a.case_timeout
        ));
    }
    let corpus = xtask::fuzz::corpus(root)?;
    let seed = a.seed.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos() as u64)
            .unwrap_or(1)
    });
    let ts = targets(a.target);
    println!(
        "fuzzing {} scenes, seed {seed:#018x}, {:.0} s; failures and an aborted case go to {}",
        corpus.len(),
        a.seconds,
        a.out.display()
    );
    let mut failed = 0;
    for (i, t) in ts.iter().enumerate() {
        let o = fuzz::Options {
            // a different stream of cases for each target
            seed: seed.wrapping_add(i as u64),
            duration: std::time::Duration::from_secs_f64(a.seconds / ts.len() as f64),
            max_cases: a.cases,
            case_timeout: std::time::Duration::from_secs_f64(a.case_timeout),
            out_dir: a.out.clone(),
            target: *t,
            limits: fuzz::Limits::default(),
            base_dir: fuzz::base_dir(root),
        };
        let r = fuzz::fuzz(corpus.clone(), &o);
        println!("target {t:?}, {}", r.summary());
        for f in &r.failures {
            eprintln!(
                "\ncase {:#018x} from {}, mutations:\n  {}\n{}\n--- input:\n{}\n---",
                f.case.seed,
                f.case.source,
                f.case.mutations.join("\n  "),
                match &f.problem {
                    fuzz::Problem::Panic(m) => m.clone(),
                    fuzz::Problem::Hang(d) => format!("no result after {:.1} s", d.as_secs_f64()),
                },
                f.case.text
            );
            if matches!(f.problem, fuzz::Problem::Hang(_)) {
                // the case is still running on its thread: stop here
                eprintln!("error: a hang; its input is in {}", f.file.display());
                std::process::exit(1);
            }
        }
        failed += r.failures.len();
    }
    if failed > 0 {
        return Err(format!(
            "{failed} failing case(s); inputs in {}",
            a.out.display()
        ));
    }
    Ok(())
}

fn fuzz_one_case(root: &std::path::Path, seed: u64, t: FuzzTarget) -> Result<(), String> {
    let corpus = xtask::fuzz::corpus(root)?;
    for t in targets(t) {
        // each target makes its own case from the seed
        let case = xtask::fuzz::generate(&corpus, seed, t.structural_share());
        println!(
            "target {t:?}: case {seed:#018x} from {}, mutations:\n  {}\n--- input:\n{}\n---",
            case.source,
            case.mutations.join("\n  "),
            case.text
        );
        let dir = fuzz::base_dir(root);
        match fuzz::run_text(&case.text, t, &fuzz::Limits::default(), &dir, seed) {
            Ok(o) => println!("target {t:?}: {o:?}"),
            Err(m) => return Err(format!("target {t:?} panicked: {m}")),
        }
    }
    Ok(())
}

fn fuzz_one_file(
    root: &std::path::Path,
    path: &std::path::Path,
    t: FuzzTarget,
) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    // the seed of the perturbed evaluation, from the header a failure has
    let seed = text
        .lines()
        .find_map(|l| l.split_once(" --case ").map(|(_, s)| s.trim().to_string()))
        .and_then(|s| parse_seed(&s).ok())
        .unwrap_or(0);
    // superelement files as in a run: from fixtures/fuzz
    let dir = fuzz::base_dir(root);
    for t in targets(t) {
        match fuzz::run_text(&text, t, &fuzz::Limits::default(), &dir, seed) {
            Ok(o) => println!("target {t:?}: {o:?}"),
            Err(m) => return Err(format!("target {t:?} panicked: {m}")),
        }
    }
    Ok(())
}
