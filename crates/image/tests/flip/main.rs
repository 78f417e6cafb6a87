//! ꟻLIP against the published reference implementation's values, its properties, and
//! an ignored timing run.

mod bench;
mod common;
mod properties;
mod reference;
