//! Progress bars for the long steps (hidden in tests and when stderr is not a
//! terminal).

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A set of progress bars.
pub struct Progress {
    mp: Option<MultiProgress>,
    /// Without a terminal, one line per finished step instead of bars.
    lines: bool,
}

/// One bar.
pub struct Bar {
    bar: ProgressBar,
    /// Label and start, for the line printed at the end without a terminal.
    line: Option<(String, std::time::Instant)>,
}

impl Progress {
    /// Bars on stderr.
    pub fn visible() -> Self {
        use std::io::IsTerminal;
        Self {
            mp: Some(MultiProgress::with_draw_target(ProgressDrawTarget::stderr())),
            lines: !std::io::stderr().is_terminal(),
        }
    }
    /// No output.
    pub fn hidden() -> Self {
        Self {
            mp: None,
            lines: false,
        }
    }
    /// A new bar of `len` steps.
    pub fn bar(&self, label: &str, len: u64) -> Bar {
        let line = self
            .lines
            .then(|| (label.to_string(), std::time::Instant::now()));
        match &self.mp {
            None => Bar {
                bar: ProgressBar::hidden(),
                line,
            },
            Some(mp) => {
                let b = mp.add(ProgressBar::new(len));
                b.set_style(
                    ProgressStyle::with_template("{msg:44} [{bar:30}] {pos}/{len} {elapsed}")
                        .unwrap_or_else(|_| ProgressStyle::default_bar())
                        .progress_chars("=> "),
                );
                b.set_message(label.to_string());
                Bar { bar: b, line }
            }
        }
    }
    /// Prints a line above the bars.
    pub fn println(&self, s: &str) {
        if let Some(mp) = &self.mp {
            let _ = mp.println(s);
        }
    }
}

impl Bar {
    /// Sets the position.
    pub fn set(&self, v: u64) {
        self.bar.set_position(v);
    }
    /// Advances by one.
    pub fn inc(&self) {
        self.bar.inc(1);
    }
    /// Advances by one for a finished item: without a terminal a line names
    /// it (`what`), so that long runs show progress in logs too.
    pub fn item_done(&self, what: &str) {
        self.bar.inc(1);
        if let Some((label, start)) = &self.line {
            eprintln!(
                "{label}: {what} ({}/{}, {:.1} s)",
                self.bar.position(),
                self.bar.length().unwrap_or(0),
                start.elapsed().as_secs_f64()
            );
        }
    }
    /// Finishes the bar (it stays visible; without a terminal a line says
    /// what finished and how long it took).
    pub fn finish(&self) {
        self.bar.finish();
        if let Some((label, start)) = &self.line {
            eprintln!("{label}: done in {:.1} s", start.elapsed().as_secs_f64());
        }
    }
}
