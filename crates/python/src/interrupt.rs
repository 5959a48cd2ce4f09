//! Ctrl-C during a long call: the engine's progress callback, on the calling thread, briefly
//! re-attaches to the interpreter and runs Python's signal handlers
//! (`Python::check_signals`); when they raise (`KeyboardInterrupt` by default), the engine
//! is left by unwinding from inside the callback (`resume_unwind`, which runs no panic
//! hook and prints nothing), caught at the call, and the handler's exception is raised.
//! Nothing the engine built survives the unwind: its inputs are borrowed, its results
//! dropped.

use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::Mutex;

use pyo3::prelude::*;

/// The payload of the unwind out of an interrupted engine.
struct Interrupted;

/// One interruptible engine call.
pub struct Interruptible {
    raised: Mutex<Option<PyErr>>,
}

impl Interruptible {
    pub fn new() -> Interruptible {
        Interruptible {
            raised: Mutex::new(None),
        }
    }

    /// From the engine's progress callback: runs Python's signal handlers and leaves the
    /// engine if one raised.
    pub fn check(&self) {
        if let Err(e) = Python::attach(|py| py.check_signals()) {
            *self.raised.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
            resume_unwind(Box::new(Interrupted));
        }
    }

    /// Runs `f`, turning an interruption into `Failure::Interrupted`; any other panic goes
    /// on unwinding.
    pub fn run<T>(&self, f: impl FnOnce() -> T) -> Result<T, crate::Failure> {
        match catch_unwind(AssertUnwindSafe(f)) {
            Ok(v) => Ok(v),
            Err(payload) if payload.is::<Interrupted>() => Err(crate::Failure::Interrupted),
            Err(payload) => resume_unwind(payload),
        }
    }

    /// The call's result as Python sees it: the handler's exception after an interruption.
    pub fn finish<T>(&self, py: Python<'_>, result: Result<T, crate::Failure>) -> PyResult<T> {
        match result {
            Ok(v) => Ok(v),
            Err(crate::Failure::Interrupted) => {
                let raised = self.raised.lock().unwrap_or_else(|p| p.into_inner()).take();
                Err(raised.unwrap_or_else(|| {
                    pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted")
                }))
            }
            Err(other) => Err(other.into_py_err(py)),
        }
    }
}
