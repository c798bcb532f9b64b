//! The vector registers' upper halves, left clean for the kernels' SSE code.
//!
//! The crate is compiled for the x86-64 baseline: its kernels (the bodies' mass and forces, the
//! LU solves of the implicit methods, the UK correction) are legacy-SSE code. faer dispatches
//! at run time to AVX2 / AVX-512 kernels, and some of them return with the upper halves of the
//! vector registers still in use (no `vzeroupper`): measured, faer's symmetric eigensolver from
//! order 33 (auto's modal analysis of a model with 33 degrees of freedom) leaves `XINUSE`'s AVX
//! and ZMM_Hi256 bits set. Every legacy-SSE instruction after that pays for a merge with the
//! dirty upper state, until something clears it: on this project's machine (AMD EPYC) the
//! RADAU5M run that followed auto's analysis of an ANCF beam of 8 elements took 2.0x its time
//! (1.42 against 0.70 ms, the same steps, iterations and bits; round i26-simd,
//! docs/integrators.md).
//!
//! [`after_wide`] runs a faer decomposition and then [`clean_upper`]; a run
//! (`integrate::integrate_observed`) and every call of the Python `System` into its workspace
//! (`with_ws`) call [`clean_upper`] first, whatever ran before them (faer, or another library in
//! the user's process). `vzeroupper` costs a cycle; without AVX it is not run.

/// Clear the upper halves of the vector registers (`vzeroupper`) where the CPU has AVX; nothing
/// elsewhere.
#[inline]
pub fn clean_upper() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above)
            unsafe { zeroupper() }
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn zeroupper() {
    std::arch::x86_64::_mm256_zeroupper();
}

/// `f()` (a faer decomposition, which may run AVX / AVX-512 kernels), then [`clean_upper`].
#[inline]
pub fn after_wide<R>(f: impl FnOnce() -> R) -> R {
    let r = f();
    clean_upper();
    r
}

/// `XINUSE` (`xgetbv` with `ecx = 1`): which state components are not in their initial state;
/// bit 2 the upper halves of `ymm0-15`, bit 6 those of `zmm0-15`. `None` where the CPU cannot
/// tell (no `XGETBV` with `ecx = 1`) or off x86-64. For the tests.
pub fn upper_in_use() -> Option<bool> {
    #[cfg(target_arch = "x86_64")]
    {
        if !std::arch::is_x86_feature_detected!("xsave") {
            return None;
        }
        let leaf = std::arch::x86_64::__cpuid_count(0xD, 1);
        if leaf.eax & (1 << 2) == 0 {
            return None;
        }
        let (lo, _hi): (u32, u32);
        // SAFETY: XGETBV with ecx = 1 is supported (CPUID.(EAX=0DH,ECX=1):EAX[2]) and the OS
        // enabled XSAVE (the "xsave" feature is reported only then: OSXSAVE)
        unsafe { std::arch::asm!("xgetbv", in("ecx") 1u32, out("eax") lo, out("edx") _hi, options(nomem, nostack, preserves_flags)) };
        Some(lo & ((1 << 2) | (1 << 6)) != 0)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::{Mat, Side};

    /// faer's eigensolver at order 33 left the upper state in use on this machine; after
    /// `after_wide` it is clean. (Where the CPU cannot tell, or faer took a path that left it
    /// clean, the first assertion has nothing to show: it is printed.)
    #[test]
    fn after_wide_leaves_the_upper_halves_clean() {
        let k = 40;
        let c = Mat::<f64>::from_fn(k, k, |i, j| if i == j { 1.0 + i as f64 } else { 0.01 / (1.0 + (i + j) as f64) });
        clean_upper();
        let _ = c.self_adjoint_eigen(Side::Lower).unwrap();
        eprintln!("after faer's eigensolver alone: upper state in use {:?}", upper_in_use());
        let _ = after_wide(|| c.self_adjoint_eigen(Side::Lower).unwrap());
        assert_ne!(upper_in_use(), Some(true));
    }
}
