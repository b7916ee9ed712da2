//! SIGINT (Ctrl-C) and SIGTERM (`kill`, `timeout`, schedulers, containers).
//!
//! What the first signal does depends on the phase the command is in:
//!
//! * in a phase with partial results ([`stoppable`]: the time integration of
//!   `simulate`, the configurations of `sweep`), it sets the stop flag. The
//!   computation reads the flag after every integrator step, every Newton
//!   iteration of an equilibrium and before every sweep configuration, ends
//!   there, and the command writes what it has, then exits with 128 + the
//!   signal number (130 for SIGINT, 143 for SIGTERM). If the computation has
//!   not reached such a check [`GRACE`] after the signal (one very long
//!   step; [`GRACE_VAR`] sets another time), the process exits with that
//!   code without writing;
//! * in any other phase (reading and building the scene, `static`, `eig`,
//!   `reduce`, an equilibrium before a simulation), there is nothing partial
//!   to write: the process exits at once with that code;
//! * while the results are written ([`Stoppable::finish`]) it lets the
//!   writing end; the exit code is still the signal's.
//!
//! A second signal exits at once with its code, in the signal handler itself.
//!
//! signal-hook (pure Rust over the libc crate) and not ctrlc: ctrlc's
//! "termination" feature folds SIGINT, SIGTERM and SIGHUP into one callback
//! that does not say which signal came, so it cannot give 130 and 143; and
//! ctrlc runs its callback on a thread of its own, while signal-hook lets
//! the handler itself exit on the second signal, whatever the threads are
//! doing.

use crate::out::errln;
use signal_hook::consts::{SIGINT, SIGTERM};
use std::sync::atomic::{AtomicBool, AtomicI32, AtomicU32, AtomicU64, AtomicU8, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// How long a stoppable phase has to reach its next check after a signal,
/// unless [`GRACE_VAR`] says otherwise.
pub(crate) const GRACE: Duration = Duration::from_secs(1);

/// The environment variable that sets the grace time, in seconds (a
/// positive number, at most an hour): a scheduler that kills after a few
/// seconds wants a shorter one, the tests of the backstop a short one so
/// that any long computation triggers it.
pub(crate) const GRACE_VAR: &str = "FLEXMB_STOP_GRACE";

/// The grace time in force: [`GRACE`] or [`GRACE_VAR`]'s, in ns.
static GRACE_NS: AtomicU64 = AtomicU64::new(GRACE.as_nanos() as u64);

/// The grace time in force.
fn grace() -> Duration {
    Duration::from_nanos(GRACE_NS.load(Ordering::Relaxed))
}

/// Reads the grace time from [`GRACE_VAR`], if it is set; an error names
/// the variable and its value.
pub(crate) fn grace_from_env() -> Result<(), String> {
    let Some(value) = std::env::var_os(GRACE_VAR) else {
        return Ok(());
    };
    let text = value.to_string_lossy();
    let seconds: f64 = text.trim().parse().map_err(|_| {
        format!("{GRACE_VAR}={text:?} is not a number of seconds (e.g. {GRACE_VAR}=0.5)")
    })?;
    if !(seconds > 0.0 && seconds <= 3600.0) {
        return Err(format!(
            "{GRACE_VAR}={text:?}: the grace time must be more than 0 s and at most 3600 s"
        ));
    }
    let ns = Duration::from_secs_f64(seconds).as_nanos().max(1);
    GRACE_NS.store(u64::try_from(ns).unwrap_or(u64::MAX), Ordering::Relaxed);
    Ok(())
}

/// The phase: exit at once on the first signal.
const EXIT_AT_ONCE: u8 = 0;
/// The phase: set the stop flag and wait for the computation to stop.
const STOP_AT_CHECK: u8 = 1;
/// The phase: results are written; let it end.
const FINISHING: u8 = 2;

/// The current phase.
static PHASE: AtomicU8 = AtomicU8::new(EXIT_AT_ONCE);
/// The watcher has acted on the first signal.
static HANDLED: AtomicBool = AtomicBool::new(false);
/// Signals received so far, counted by the handler.
static COUNT: AtomicU32 = AtomicU32::new(0);
/// The first signal received (0: none), stored by the handler.
static SIGNAL: AtomicI32 = AtomicI32::new(0);
/// When the handlers were installed: the origin of [`SIGNALLED_NS`].
static INSTALLED: OnceLock<Instant> = OnceLock::new();
/// When the first signal came, in ns after [`INSTALLED`] (0: none), stored
/// by the handler.
static SIGNALLED_NS: AtomicU64 = AtomicU64::new(0);
/// How long after the signal the stoppable phase ended.
static STOPPED_AFTER: OnceLock<Duration> = OnceLock::new();

/// The stop flag, set by the first SIGINT or SIGTERM (in the handler).
static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The stop flag.
fn flag() -> &'static Arc<AtomicBool> {
    FLAG.get_or_init(|| Arc::new(AtomicBool::new(false)))
}

/// The stop flag to hand to the computations (`SimulationOptions::stop`,
/// `sweep_until`).
pub(crate) fn stop_flag() -> Arc<AtomicBool> {
    flag().clone()
}

/// True if a stop was requested.
pub(crate) fn requested() -> bool {
    flag().load(Ordering::Relaxed)
}

/// The signal's name.
fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        _ => "a signal",
    }
}

/// The exit code for `signal`: 128 + its number.
fn code_of(signal: i32) -> u8 {
    u8::try_from(128 + signal).unwrap_or(130)
}

/// The signal received, if one was.
fn received() -> Option<i32> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// When the first signal came, if one did.
fn signalled_at() -> Option<Instant> {
    let ns = SIGNALLED_NS.load(Ordering::SeqCst);
    let origin = INSTALLED.get()?;
    (ns > 0).then(|| *origin + Duration::from_nanos(ns))
}

/// The signal handler: a second signal ends the process at once (`_exit`,
/// whichever thread each signal is delivered to: the count is one atomic
/// step); the first sets the stop flag and is recorded, which one and when.
/// It only counts, reads the monotonic clock (clock_gettime) and
/// initialized `OnceLock`s, and stores to atomics: all async-signal-safe.
fn handle(sig: i32) {
    if COUNT.fetch_add(1, Ordering::SeqCst) > 0 {
        signal_hook::low_level::exit(i32::from(code_of(sig)));
    }
    if let Some(f) = FLAG.get() {
        f.store(true, Ordering::SeqCst);
    }
    if let Some(origin) = INSTALLED.get() {
        let ns = u64::try_from(origin.elapsed().as_nanos())
            .unwrap_or(u64::MAX)
            .max(1);
        let _ = SIGNALLED_NS.compare_exchange(0, ns, Ordering::SeqCst, Ordering::SeqCst);
    }
    let _ = SIGNAL.compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst);
}

/// The exit code of the signal received, if one was: 130 or 143.
pub(crate) fn exit_code() -> Option<u8> {
    received().map(code_of)
}

/// A line for stderr on the way out: which signal, and how long after it
/// the computation stopped.
pub(crate) fn report(partial: &str) -> String {
    let signal = received().map_or("a signal", name);
    match STOPPED_AFTER.get() {
        Some(d) => format!(
            "interrupted by {signal}: the computation stopped {:.1} ms after the signal; {partial}",
            1e3 * d.as_secs_f64()
        ),
        None => format!("interrupted by {signal}; {partial}"),
    }
}

/// Installs the handlers: the second signal exits from the handler, the
/// first sets the stop flag and wakes the watcher thread, which acts on the
/// phase. Fails only if the handlers cannot be registered.
pub(crate) fn install() -> std::io::Result<()> {
    INSTALLED.get_or_init(Instant::now);
    flag();
    // the watcher's pipe first: a signal that comes before `handle` is
    // registered still reaches the watcher, which exits (nothing is
    // stoppable yet); a signal before both has its default action
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])?;
    for sig in [SIGINT, SIGTERM] {
        // SAFETY: `handle` is async-signal-safe (see there)
        unsafe { signal_hook::low_level::register(sig, move || handle(sig)) }?;
    }
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            for sig in signals.forever() {
                on_signal(sig);
            }
        })?;
    Ok(())
}

/// The watcher's response to a signal (the first one: a second one has
/// already ended the process in the handler).
fn on_signal(sig: i32) {
    if HANDLED.swap(true, Ordering::SeqCst) {
        return;
    }
    let at = signalled_at().unwrap_or_else(Instant::now);
    match PHASE.load(Ordering::SeqCst) {
        EXIT_AT_ONCE => leave(sig, "nothing partial to write"),
        STOP_AT_CHECK => {
            while PHASE.load(Ordering::SeqCst) == STOP_AT_CHECK {
                if at.elapsed() > grace() {
                    leave(
                        sig,
                        &format!(
                            "the computation reached no point to stop at within {} s; nothing written",
                            grace().as_secs_f64()
                        ),
                    );
                }
                std::thread::sleep(Duration::from_millis(5));
            }
        }
        _ => {}
    }
}

/// Ends the process with the signal's exit code.
fn leave(sig: i32, why: &str) -> ! {
    errln(&format!("\ninterrupted by {}: {why}", name(sig)));
    signal_hook::low_level::exit(i32::from(code_of(sig)))
}

/// A phase whose computation stops at its checks of [`stop_flag`]; ends
/// with [`finish`](Self::finish) (or when dropped), after which the results
/// are written.
pub(crate) struct Stoppable(());

/// Enters a phase with partial results.
pub(crate) fn stoppable() -> Stoppable {
    PHASE.store(STOP_AT_CHECK, Ordering::SeqCst);
    Stoppable(())
}

impl Stoppable {
    /// The computation has returned: results are being written.
    pub(crate) fn finish(self) {}
}

impl Drop for Stoppable {
    fn drop(&mut self) {
        if let Some(at) = signalled_at() {
            let _ = STOPPED_AFTER.set(at.elapsed());
        }
        PHASE.store(FINISHING, Ordering::SeqCst);
    }
}
