//! `plumetrace-fuzz`: mutated scenario and campaign files against `check`, short runs and
//! campaign parsing.

fn main() {}
