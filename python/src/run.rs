//! Long computations off the interpreter: the work runs on a worker thread
//! while the calling thread waits with the GIL released, waking every few
//! milliseconds to run Python's signal handlers (`Python::check_signals`,
//! so Ctrl-C raises `KeyboardInterrupt` promptly) and to report progress.
//! A signal or a failing progress callback sets the stop flag, which the
//! computation reads after every integrator step, Newton iteration and
//! sweep configuration; the worker then returns what it has.

use crate::errors;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How often the waiting thread wakes to check for signals.
const POLL: Duration = Duration::from_millis(10);

/// What a running computation shares with the thread that waits for it.
pub struct Watch {
    /// Set to ask the computation to stop at its next check.
    pub stop: Arc<AtomicBool>,
    /// The fraction done, in [0, 1], as f64 bits.
    done: AtomicU64,
    /// Set by the worker when it has returned.
    finished: AtomicBool,
}

impl Watch {
    /// Reports the fraction of the work done.
    pub fn progress(&self, fraction: f64) {
        self.done
            .store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
    }
    /// True if a stop was requested.
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
    fn fraction(&self) -> f64 {
        f64::from_bits(self.done.load(Ordering::Relaxed))
    }
}

/// A progress display: a callable taking the fraction done, or a tqdm bar
/// (made by `flexmb._progress.make`).
struct Progress<'py>(Option<Bound<'py, PyAny>>);

impl<'py> Progress<'py> {
    fn new(py: Python<'py>, progress: Option<&Bound<'py, PyAny>>, what: &str) -> PyResult<Self> {
        let Some(p) = progress else {
            return Ok(Self(None));
        };
        let bar = py
            .import("flexmb._progress")?
            .call_method1("make", (p, what))?;
        Ok(Self((!bar.is_none()).then_some(bar)))
    }
    fn update(&self, fraction: f64) -> PyResult<()> {
        match &self.0 {
            Some(b) => b.call_method1("update", (fraction,)).map(|_| ()),
            None => Ok(()),
        }
    }
    fn close(&self) -> PyResult<()> {
        match &self.0 {
            Some(b) => b.call_method0("close").map(|_| ()),
            None => Ok(()),
        }
    }
}

/// Runs `work` on a worker thread with the GIL released (see the module
/// documentation). Returns its result and, if the run was interrupted by a
/// signal, the exception the signal handler raised (`KeyboardInterrupt`),
/// for the caller to raise with the partial result attached. A progress
/// callback that raises stops the run and its exception is returned as an
/// error; a panic of the computation becomes a `FlexmbError`.
pub fn long<'py, T: Send>(
    py: Python<'py>,
    what: &str,
    progress: Option<&Bound<'py, PyAny>>,
    work: impl FnOnce(&Watch) -> T + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let bar = Progress::new(py, progress, what)?;
    let watch = Watch {
        stop: Arc::new(AtomicBool::new(false)),
        done: AtomicU64::new(0f64.to_bits()),
        finished: AtomicBool::new(false),
    };
    let mut interrupt: Option<PyErr> = None;
    let mut failure: Option<PyErr> = None;
    let joined = std::thread::scope(|s| {
        let w = &watch;
        let handle = s.spawn(move || {
            let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(w)));
            w.finished.store(true, Ordering::SeqCst);
            r
        });
        loop {
            let finished = py.detach(|| {
                std::thread::sleep(POLL);
                watch.finished.load(Ordering::SeqCst)
            });
            if failure.is_none() {
                if let Err(e) = bar.update(watch.fraction()) {
                    watch.stop.store(true, Ordering::SeqCst);
                    failure = Some(e);
                }
            }
            if finished {
                break;
            }
            if interrupt.is_none() {
                if let Err(e) = py.check_signals() {
                    watch.stop.store(true, Ordering::SeqCst);
                    interrupt = Some(e);
                }
            }
        }
        handle.join()
    });
    let closed = bar.close();
    if let Some(e) = failure {
        return Err(e);
    }
    closed?;
    let result = match joined {
        Ok(Ok(r)) => r,
        Ok(Err(payload)) | Err(payload) => return Err(errors::internal(what, payload)),
    };
    Ok((result, interrupt))
}

/// [`long`] for computations without partial results: an interrupt is
/// raised as it is.
pub fn whole<'py, T: Send>(
    py: Python<'py>,
    what: &str,
    work: impl FnOnce(&Watch) -> T + Send,
) -> PyResult<T> {
    let (r, interrupt) = long(py, what, None, work)?;
    match interrupt {
        Some(e) => Err(e),
        None => Ok(r),
    }
}

/// The result of an interruptible run and its interrupt: a run that failed
/// after the interrupt raises the interrupt (its failure is the stop's
/// consequence, e.g. an equilibrium abandoned), one that failed without
/// raises its error.
pub fn settle<T>(result: PyResult<T>, interrupt: Option<PyErr>) -> PyResult<(T, Option<PyErr>)> {
    match (result, interrupt) {
        (Ok(r), i) => Ok((r, i)),
        (Err(_), Some(i)) => Err(i),
        (Err(e), None) => Err(e),
    }
}
