//! The local file system as the destination: temporaries beside their targets, locked
//! with `flock` while the run holds them, published by `rename(2)`, and the stale ones of
//! killed runs swept. Everything that knows outputs are paths in a local directory lives
//! here; another destination (an object store) would sit beside this module.

pub(crate) mod atomic;
pub(crate) mod check;
pub(crate) mod report;
pub(crate) mod scratch;
pub(crate) mod staging;
pub(crate) mod stale;
