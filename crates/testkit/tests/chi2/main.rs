//! Tests of the chi-square harness: correct samplers pass, wrong ones are caught, and
//! the checks beside the statistic fire.

mod checks;
mod common;
mod correct_samplers;
mod wrong_samplers;
