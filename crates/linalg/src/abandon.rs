//! Work without stop checks inside (faer's dense eigendecomposition and
//! Cholesky factorization) that a stop request can still end at once: it
//! runs on a thread of its own while the caller waits and reads the stop
//! flag (issue 14: a sweep with more modes than the partial eigensolver
//! takes stopped only after its decomposition, up to seconds on a large
//! model).
//!
//! On a stop request the caller returns at once and the thread is left to
//! finish: it is told to stop at its own checks (its `abandoned` flag), and
//! where it has none it runs to the end of its current factorization and
//! drops its result. So after a stop, up to one decomposition's worth of
//! computation goes on in the background, for at most as long as it would
//! have delayed the caller. On Linux its thread is set to the lowest
//! priority (nice 19) first, so that it does not slow down what the caller
//! still has to do before it stops (the other workers of a sweep, on a
//! 2-core machine: without this, a stop of the 1440-DOF chain's sweep took
//! 0.9 s instead of 0.2 s while two abandoned decompositions ran on).

use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

/// How often the caller reads the stop flag while it waits.
const POLL: Duration = Duration::from_millis(1);

/// The outcome of [`abandonable`].
#[derive(Debug, PartialEq)]
pub(crate) enum Outcome<T> {
    /// The work ended: its result.
    Done(T),
    /// A stop was requested first.
    Stopped,
}

/// Runs `work(abandoned)` on a thread of its own and waits for it, reading
/// `stop` every millisecond; returns [`Outcome::Stopped`] at once when
/// `stop` is set (having lowered the thread's priority, and set `abandoned`
/// for `work`'s own checks). A panic of
/// `work` is resumed on the caller's thread, as if it had run there. If no
/// thread can be started, `work` runs on the caller's thread with `stop`
/// as its flag.
pub(crate) fn abandonable<T: Send + 'static, F: FnOnce(&AtomicBool) -> T + Send + 'static>(
    stop: &AtomicBool,
    work: F,
) -> Outcome<T> {
    if stop.load(Ordering::Relaxed) {
        return Outcome::Stopped;
    }
    let abandoned = Arc::new(AtomicBool::new(false));
    let flag = abandoned.clone();
    let thread_id = Arc::new(std::sync::atomic::AtomicI64::new(0));
    let id = thread_id.clone();
    let slot: Arc<Mutex<Option<F>>> = Arc::new(Mutex::new(Some(work)));
    let theirs = slot.clone();
    let (send, receive) = mpsc::sync_channel(1);
    let spawned = std::thread::Builder::new()
        .name("flexmb-dense".into())
        .spawn(move || {
            id.store(priority::current_thread(), Ordering::SeqCst);
            let work = theirs.lock().ok().and_then(|mut w| w.take());
            if let Some(work) = work {
                let result = catch_unwind(AssertUnwindSafe(|| work(&flag)));
                // the caller may be gone: then nobody wants the result
                let _ = send.send(result);
            }
        });
    if spawned.is_err() {
        let work = slot.lock().ok().and_then(|mut w| w.take());
        return match work {
            Some(work) => Outcome::Done(work(stop)),
            None => Outcome::Stopped,
        };
    }
    loop {
        match receive.recv_timeout(POLL) {
            Ok(Ok(result)) => return Outcome::Done(result),
            Ok(Err(panic)) => resume_unwind(panic),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if stop.load(Ordering::Relaxed) {
                    priority::lower(thread_id.load(Ordering::SeqCst));
                    abandoned.store(true, Ordering::SeqCst);
                    return Outcome::Stopped;
                }
            }
            // only if the thread ended without sending, which it does not
            Err(mpsc::RecvTimeoutError::Disconnected) => return Outcome::Stopped,
        }
    }
}

/// The priority of an abandoned thread.
#[cfg(target_os = "linux")]
mod priority {
    /// The kernel's id of the calling thread.
    pub(super) fn current_thread() -> i64 {
        // SAFETY: gettid takes no argument and cannot fail
        unsafe { libc::syscall(libc::SYS_gettid) }
    }

    /// Sets thread `id` (0: not known yet, nothing done) to nice 19, the
    /// lowest priority; a failure leaves it as it is.
    pub(super) fn lower(id: i64) {
        if let Ok(id) = libc::id_t::try_from(id) {
            if id > 0 {
                // SAFETY: a system call on integers; on Linux PRIO_PROCESS
                // with a thread id sets that thread's nice value
                unsafe { libc::setpriority(libc::PRIO_PROCESS, id, 19) };
            }
        }
    }

    /// The nice value of the calling thread.
    #[cfg(test)]
    pub(super) fn current_nice() -> i32 {
        // SAFETY: a system call on integers (0: the calling thread)
        unsafe { libc::getpriority(libc::PRIO_PROCESS, 0) }
    }
}

/// Elsewhere the abandoned thread keeps its priority.
#[cfg(not(target_os = "linux"))]
mod priority {
    pub(super) fn current_thread() -> i64 {
        0
    }
    pub(super) fn lower(_: i64) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    #[test]
    fn the_result_of_work_that_ends_is_returned() {
        let stop = AtomicBool::new(false);
        assert_eq!(abandonable(&stop, |_| 6 * 7), Outcome::Done(42));
    }

    #[test]
    fn a_stop_before_the_start_runs_nothing() {
        let stop = AtomicBool::new(true);
        let ran = Arc::new(AtomicBool::new(false));
        let r = ran.clone();
        assert_eq!(
            abandonable(&stop, move |_| r.store(true, Ordering::SeqCst)),
            Outcome::Stopped
        );
        std::thread::sleep(Duration::from_millis(20));
        assert!(!ran.load(Ordering::SeqCst));
    }

    /// Work that never reaches a check of its own (it only ends when told
    /// through its flag, 2 s at the latest) is left at once on a stop
    /// request, and is told to stop.
    #[test]
    fn a_stop_request_returns_at_once_and_tells_the_work() {
        let stop = Arc::new(AtomicBool::new(false));
        let told = Arc::new(AtomicBool::new(false));
        let t = told.clone();
        let s = stop.clone();
        let setter = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(50));
            s.store(true, Ordering::SeqCst);
            Instant::now()
        });
        let nice = Arc::new(std::sync::atomic::AtomicI32::new(i32::MIN));
        let n = nice.clone();
        let outcome = abandonable(&stop, move |abandoned| {
            let start = Instant::now();
            while !abandoned.load(Ordering::SeqCst) && start.elapsed() < Duration::from_secs(2) {
                std::thread::sleep(Duration::from_millis(1));
            }
            #[cfg(target_os = "linux")]
            n.store(priority::current_nice(), Ordering::SeqCst);
            t.store(abandoned.load(Ordering::SeqCst), Ordering::SeqCst);
        });
        let returned = Instant::now();
        let requested = setter.join().unwrap();
        assert_eq!(outcome, Outcome::Stopped);
        let latency = returned.saturating_duration_since(requested);
        assert!(latency < Duration::from_millis(500), "{latency:?}");
        std::thread::sleep(Duration::from_millis(50));
        assert!(told.load(Ordering::SeqCst), "the work was not told to stop");
        #[cfg(target_os = "linux")]
        assert_eq!(
            nice.load(Ordering::SeqCst),
            19,
            "the abandoned work keeps its priority"
        );
        let _ = nice;
    }

    #[test]
    #[should_panic(expected = "inside the work")]
    fn a_panic_of_the_work_reaches_the_caller() {
        let stop = AtomicBool::new(false);
        let _ = abandonable(&stop, |_| -> u8 { panic!("inside the work") });
    }
}
