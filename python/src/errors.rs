//! Errors at the boundary: the exception classes of the module, the one conversion of every library error into a
//! Python exception (with the message the command line prints after `error: `), and [`detached`], which runs
//! library code without the GIL and turns a panic into a `hylc.Error` instead of letting it reach Python.

use pyo3::exceptions::{PyException, PyFileNotFoundError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    _hylc,
    Error,
    PyException,
    "Base class of the errors hylc raises."
);
pyo3::create_exception!(
    _hylc,
    PatternError,
    Error,
    "A pattern file or generated pattern is not valid."
);
pyo3::create_exception!(
    _hylc,
    MicroError,
    Error,
    "A micro solve could not run, or a quantity needs an equilibrium."
);
pyo3::create_exception!(
    _hylc,
    MaterialError,
    Error,
    "A material file or strain is not valid."
);
pyo3::create_exception!(
    _hylc,
    FitError,
    Error,
    "Fitting a material to samples failed."
);
pyo3::create_exception!(
    _hylc,
    SimulationError,
    Error,
    "A cloth scene is not valid or its simulation failed."
);
pyo3::create_exception!(
    _hylc,
    SampleError,
    Error,
    "A sample file or plan is not valid."
);
pyo3::create_exception!(
    _hylc,
    InternalError,
    Error,
    "A bug in hylc (a Rust panic caught at the boundary)."
);

/// Which exception class an error becomes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `ValueError`: a bad argument (shape, dtype, NaN, unknown name).
    Value,
    /// `FileNotFoundError`: a file that does not exist.
    NotFound,
    Pattern,
    Micro,
    Material,
    Fit,
    Simulation,
    Sample,
    Internal,
}

/// An error on its way to Python: its class and its one-line message.
#[derive(Debug)]
pub struct HyError {
    pub kind: Kind,
    pub message: String,
}

pub type HyResult<T> = Result<T, HyError>;

impl HyError {
    pub fn new(kind: Kind, message: impl Into<String>) -> Self {
        HyError {
            kind,
            message: message.into(),
        }
    }

    /// A bad argument (`ValueError`); the message names the argument.
    pub fn value(message: impl Into<String>) -> Self {
        Self::new(Kind::Value, message)
    }

    /// The error with `prefix` before its message.
    pub fn with_prefix(mut self, prefix: &str) -> Self {
        self.message = format!("{prefix}{}", self.message);
        self
    }

    /// An error about `file` of class `kind`, or `FileNotFoundError` when it is about the whole file
    /// (`whole_file`: no line or field) and the file does not exist (the readers keep only the I/O error's text).
    pub fn about_file(file: &str, whole_file: bool, kind: Kind, message: String) -> Self {
        let missing = whole_file && !std::path::Path::new(file).exists();
        Self::new(if missing { Kind::NotFound } else { kind }, message)
    }

    /// A library error of class `kind`, or `FileNotFoundError` when its cause is a missing file.
    pub fn from_library(kind: Kind, e: &(dyn std::error::Error + 'static)) -> Self {
        let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(e);
        let mut kind = kind;
        while let Some(c) = cause {
            if let Some(io) = c.downcast_ref::<std::io::Error>() {
                if io.kind() == std::io::ErrorKind::NotFound {
                    kind = Kind::NotFound;
                }
            }
            cause = c.source();
        }
        Self::new(kind, e.to_string())
    }
}

/// `impl From<E> for HyError` mapping a library error type to its exception class.
macro_rules! library_errors {
    ($($ty:ty => $kind:ident),* $(,)?) => {$(
        impl From<$ty> for HyError {
            fn from(e: $ty) -> Self {
                HyError::from_library(Kind::$kind, &e)
            }
        }
    )*};
}

library_errors! {
    hylc::generate::GenerateError => Pattern,
    hylc::micro::StrainError => Value,
    hylc::micro::solver::NotConverged => Micro,
    hylc::micro::reference::ReferenceError => Micro,
    hylc::rod::YarnFileError => Value,
    hylc::shell::ShellError => Simulation,
    hylc::sample::SampleError => Sample,
    hylc::sample::PlanError => Sample,
}

impl From<hylc::pattern::PatternError> for HyError {
    /// A pattern error without a block or line about a file that does not exist is a missing file.
    fn from(e: hylc::pattern::PatternError) -> Self {
        let whole_file = e.block.is_none() && e.line.is_none();
        HyError::about_file(&e.file, whole_file, Kind::Pattern, e.to_string())
    }
}

impl From<hylc::micro::MicroError> for HyError {
    /// An inadmissible strain is a bad argument; everything else is a `MicroError`.
    fn from(e: hylc::micro::MicroError) -> Self {
        let kind = match e {
            hylc::micro::MicroError::Strain(_) => Kind::Value,
            _ => Kind::Micro,
        };
        HyError::from_library(kind, &e)
    }
}

impl From<hylc::material::MaterialError> for HyError {
    /// A material file that cannot be read because it does not exist is a missing file.
    fn from(e: hylc::material::MaterialError) -> Self {
        HyError::about_file(&e.file, e.field == "(file)", Kind::Material, e.to_string())
    }
}

impl From<hylc::workflow::WorkflowError> for HyError {
    fn from(e: hylc::workflow::WorkflowError) -> Self {
        use hylc::workflow::WorkflowError as W;
        let kind = match &e {
            W::Pattern(p) => return p.clone().into(),
            W::Generate(_) => Kind::Pattern,
            W::Plan(_) | W::Sample(_) => Kind::Sample,
            W::Material(m) => return m.clone().into(),
            W::Shell(_) => Kind::Simulation,
            W::Reference { .. } => Kind::Micro,
            W::Fit { .. } => Kind::Fit,
            W::Input(_) => Kind::Value,
            W::NoGradient(_) => Kind::Simulation,
            W::Io { .. } => Kind::Value,
        };
        HyError::from_library(kind, &e)
    }
}

impl From<HyError> for PyErr {
    fn from(e: HyError) -> PyErr {
        let m = e.message;
        match e.kind {
            Kind::Value => PyValueError::new_err(m),
            Kind::NotFound => PyFileNotFoundError::new_err(m),
            Kind::Pattern => PatternError::new_err(m),
            Kind::Micro => MicroError::new_err(m),
            Kind::Material => MaterialError::new_err(m),
            Kind::Fit => FitError::new_err(m),
            Kind::Simulation => SimulationError::new_err(m),
            Kind::Sample => SampleError::new_err(m),
            Kind::Internal => InternalError::new_err(m),
        }
    }
}

/// Run `f` with the GIL released (other Python threads run meanwhile); a panic inside becomes an
/// `InternalError` with the panic's message instead of unwinding into Python.
pub fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> HyResult<T> + Send) -> PyResult<T> {
    let out = py.detach(|| catch_unwind(AssertUnwindSafe(f)));
    match out {
        Ok(r) => r.map_err(PyErr::from),
        Err(payload) => Err(InternalError::new_err(format!(
            "internal error: {}",
            panic_message(&*payload)
        ))),
    }
}

/// The message of a caught panic's payload.
pub fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".into())
}

/// Add the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("PatternError", py.get_type::<PatternError>())?;
    m.add("MicroError", py.get_type::<MicroError>())?;
    m.add("MaterialError", py.get_type::<MaterialError>())?;
    m.add("FitError", py.get_type::<FitError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("SampleError", py.get_type::<SampleError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    Ok(())
}
