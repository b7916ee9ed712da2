//! `cargo xtask reproduce ch5|ch6|all` and `cargo xtask regress`.

use clap::{Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use xtask::progress::Progress;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Regenerate the thesis benchmarks (chapters 5 and 6) and check the stored eigenfrequency curves"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Chapter {
    Ch5,
    Ch6,
    All,
}

#[derive(Subcommand)]
enum Cmd {
    /// Regenerate a chapter's results into OUT/chN (CSV, SVG, report.md).
    Reproduce {
        /// ch5, ch6 or all.
        chapter: Chapter,
        /// Output directory.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Recompute the eigenfrequency curves and compare them with fixtures/curves.
    Regress {
        /// Store the recomputed curves as the new fixtures instead of comparing.
        #[arg(long)]
        update: bool,
    },
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
        Cmd::Regress { update } => regress(&root, update, &pg),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn reproduce(
    root: &std::path::Path,
    out: &std::path::Path,
    ch: Chapter,
    pg: &Progress,
) -> Result<(), String> {
    let mut summary = vec![];
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
    for l in summary {
        println!("{l}");
    }
    Ok(())
}

fn regress(root: &std::path::Path, update: bool, pg: &Progress) -> Result<(), String> {
    let sets = [
        xtask::regress::recompute_ch5(root, pg)?,
        xtask::regress::recompute_ch6(root, pg)?,
    ];
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
