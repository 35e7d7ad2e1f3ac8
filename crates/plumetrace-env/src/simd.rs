//! The vector unit the hot loops run on.
//!
//! The filament step and the flow's batch lookup are compiled more than once: for any CPU of the
//! target, and for x86-64 CPUs with AVX2 and FMA (x86-64-v3) and with AVX-512 (x86-64-v4); the
//! widest the CPU has is chosen at run time. The loops are written without branches or bounds
//! checks so that the compiler can run them in vector lanes. Every version does the same
//! floating-point operations in the same order (Rust never fuses a multiply and an add unless
//! told to), so results are the same bits on any CPU; tests run every version this CPU has and
//! compare them. The flow's batch lookup has versions of its own for AVX-512 and for AVX2,
//! written with their instructions (sixteen or eight single-precision cells read as vectors and
//! taken apart into lanes; compiled from the plain loop, AVX2's read each cell's coefficients one
//! at a time, and with it the whole filament step took 1.37-1.42 times as long); the flow's
//! cells are rebuilt with each unit's own version too; the sensor scan's block boxes are written
//! with pulp's vector operations for every unit.
//!
//! AVX2's versions use macros, not closures, for their repeated parts: a closure is compiled
//! without the unit's instructions unless it is inlined, and written with closures, AVX2's
//! lookup called each instruction and ran three times slower than the plain loop.

/// The name of the vector unit the hot loops run on here ([`best`]): `"avx512"` (x86-64-v4),
/// `"avx2"` (x86-64-v3, with FMA) or `"portable"` (the version for any CPU of the target). The
/// benchmarks report it: the same code takes about twice as long a filament-step on AVX2 as on
/// AVX-512 (docs/results/performance.md).
pub fn vector_unit() -> &'static str {
    name(best())
}

/// The name of the version `arch` runs (see [`vector_unit`]).
fn name(arch: pulp::Arch) -> &'static str {
    match arch {
        #[cfg(target_arch = "x86_64")]
        pulp::Arch::V4(_) => "avx512",
        #[cfg(target_arch = "x86_64")]
        pulp::Arch::V3(_) => "avx2",
        _ => "portable",
    }
}

/// The widest vector unit this CPU has (detected once, then cached by the standard library).
#[inline]
pub(crate) fn best() -> pulp::Arch {
    pulp::Arch::new()
}

/// Every version this CPU can run, the portable one first (for tests).
#[cfg(test)]
pub(crate) fn every() -> Vec<pulp::Arch> {
    #[allow(unused_mut)]
    let mut all = vec![pulp::Arch::Scalar];
    #[cfg(target_arch = "x86_64")]
    {
        if let Some(v3) = pulp::x86::V3::try_new() {
            all.push(pulp::Arch::V3(v3));
        }
        if let Some(v4) = pulp::x86::V4::try_new() {
            all.push(pulp::Arch::V4(v4));
        }
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_vector_unit_named_is_the_widest_this_cpu_runs() {
        // `every` lists the versions this CPU can run, widest last; `best` must be that one.
        let widest = every().last().map_or("portable", |&arch| name(arch));
        assert_eq!(vector_unit(), widest);
    }
}
