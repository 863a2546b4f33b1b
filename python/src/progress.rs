//! Long calls (`sample`, `simulate`, `check_derivatives`): the library works on a worker thread without the GIL
//! while the calling thread waits, wakes every [`POLL`] to poll Python's signal handlers (`py.check_signals()`:
//! Ctrl-C raises `KeyboardInterrupt`) and to call the `progress` callback with the latest counts, GIL held. An
//! exception from either sets the run's cancel flag, which the library's loops poll (`run_plan_until`,
//! `run_until`, between harness functions): the work stops cleanly after the unit in flight (a sample, a time
//! step, a function), and the exception is raised.

use crate::errors::{panic_message, HyResult, InternalError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Duration;

/// How often the waiting thread polls the signal handlers (Ctrl-C is noticed within this time).
const POLL: Duration = Duration::from_millis(50);

/// What the worker tells the waiting thread.
#[derive(Default)]
struct State {
    /// The latest (done, total) not yet passed to the callback.
    latest: Option<(usize, usize)>,
    finished: bool,
}

/// Shared by the worker (which reports and polls `cancelled`) and the waiting thread.
#[derive(Default)]
pub struct Monitor {
    cancel: AtomicBool,
    state: Mutex<State>,
    wake: Condvar,
}

impl Monitor {
    /// Report progress: `done` of `total` units (from any worker thread; cheap).
    pub fn report(&self, done: usize, total: usize) {
        if let Ok(mut s) = self.state.lock() {
            s.latest = Some((done, total));
        }
    }

    /// Whether the caller asked the work to stop (Ctrl-C, or an exception in the callback).
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// The flag itself, for library loops that poll an `AtomicBool`.
    pub fn cancel_flag(&self) -> &AtomicBool {
        &self.cancel
    }

    fn finish(&self) {
        if let Ok(mut s) = self.state.lock() {
            s.finished = true;
        }
        self.wake.notify_all();
    }

    /// Wait up to [`POLL`] for the end of the work; the latest unreported progress and whether the work ended.
    fn wait(&self) -> (Option<(usize, usize)>, bool) {
        let Ok(guard) = self.state.lock() else {
            return (None, true);
        };
        let (mut s, _) = match self.wake.wait_timeout_while(guard, POLL, |s| !s.finished) {
            Ok(r) => r,
            Err(_) => return (None, true),
        };
        (s.latest.take(), s.finished)
    }
}

/// The callback of the progress argument: `None` or a callable taking (done, total).
pub fn callback<'py>(progress: Option<Bound<'py, PyAny>>) -> PyResult<Option<Bound<'py, PyAny>>> {
    match progress {
        Some(p) if p.is_none() => Ok(None),
        Some(p) if !p.is_callable() => Err(pyo3::exceptions::PyTypeError::new_err(
            "progress: expected a callable taking (done, total), or None",
        )),
        p => Ok(p),
    }
}

/// Run `work` on a worker thread (no GIL), polling signals and calling `progress(done, total)` from this thread
/// until it ends; see the module. A panic in `work` becomes `InternalError`, a library error its exception; a
/// `KeyboardInterrupt` (or the callback's exception) wins over the result of the stopped work.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Monitor) -> HyResult<T> + Send,
) -> PyResult<T> {
    let monitor = Monitor::default();
    let mut raised: Option<PyErr> = None;
    let outcome = std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let out = catch_unwind(AssertUnwindSafe(|| work(&monitor)));
            monitor.finish();
            out
        });
        loop {
            let (latest, finished) = py.detach(|| monitor.wait());
            if raised.is_none() {
                if let (Some((done, total)), Some(f)) = (latest, progress) {
                    if let Err(e) = f.call1((done, total)) {
                        raised = Some(e);
                    }
                }
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    raised = Some(e);
                }
            }
            if raised.is_some() {
                monitor.cancel.store(true, Ordering::Relaxed);
            }
            if finished {
                break;
            }
        }
        py.detach(|| worker.join())
    });
    if let Some(e) = raised {
        return Err(e);
    }
    match outcome {
        Ok(Ok(r)) => r.map_err(PyErr::from),
        Ok(Err(payload)) | Err(payload) => Err(InternalError::new_err(format!(
            "internal error: {}",
            panic_message(&*payload)
        ))),
    }
}
