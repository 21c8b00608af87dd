//! The vector paths of the hot loops: a loop is written once, portable, and `per_isa!` compiles
//! it again for AVX-512 and AVX2; the best path the CPU has within `FLUIDBED_KERNEL` runs. No
//! fused multiply-add is enabled, so every path does the same IEEE operations in the same order
//! and gives the same bits. Written by hand because the override matters: the checks and tests
//! force each path by `FLUIDBED_KERNEL` at run time, which CPU-feature dispatch crates
//! (`multiversion`) do not offer.

/// The code path of the `per_isa!` loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) enum SimdPath {
    Portable,
    Avx2,
    Avx512,
}

/// The best path this CPU has within the one `FLUIDBED_KERNEL` asks for (once per process).
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
pub(crate) fn simd_path() -> SimdPath {
    static PATH: std::sync::OnceLock<SimdPath> = std::sync::OnceLock::new();
    *PATH.get_or_init(|| {
        #[cfg(target_arch = "x86_64")]
        {
            use crate::dem::Kernel;
            use std::arch::is_x86_feature_detected as has;
            let kernel = Kernel::from_env();
            if kernel == Kernel::Avx512 && has!("avx512f") && has!("avx512vl") && has!("avx512dq") {
                return SimdPath::Avx512;
            }
            if kernel != Kernel::Portable && has!("avx2") {
                return SimdPath::Avx2;
            }
        }
        SimdPath::Portable
    })
}

/// `fn $name` running `$body` on the best path (`simd_path`), and the module `$paths` with
/// `$body` compiled for each path (`avx512`, `avx2`: for the tests that they agree). The body
/// returns nothing; one generic parameter with a bound is allowed.
macro_rules! per_isa {
    ($(#[$doc:meta])* $vis:vis fn $name:ident $(<$g:ident: $bound:path>)?, $paths:ident, $body:ident,
     ($($arg:ident: $ty:ty),*)) => {
        $(#[$doc])*
        #[allow(clippy::too_many_arguments)]
        $vis fn $name $(<$g: $bound>)? ($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            match $crate::simd::simd_path() {
                // SAFETY: `simd_path` found the features each function is compiled for.
                $crate::simd::SimdPath::Avx512 => return unsafe { $paths::avx512 $(::<$g>)? ($($arg),*) },
                $crate::simd::SimdPath::Avx2 => return unsafe { $paths::avx2 $(::<$g>)? ($($arg),*) },
                $crate::simd::SimdPath::Portable => {}
            }
            $body $(::<$g>)? ($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[allow(clippy::too_many_arguments)]
        mod $paths {
            use super::*;
            /// # Safety
            /// The CPU has avx512f, avx512vl and avx512dq.
            #[target_feature(enable = "avx512f,avx512vl,avx512dq")]
            pub(super) unsafe fn avx512 $(<$g: $bound>)? ($($arg: $ty),*) {
                $body $(::<$g>)? ($($arg),*)
            }
            /// # Safety
            /// The CPU has avx2.
            #[target_feature(enable = "avx2")]
            pub(super) unsafe fn avx2 $(<$g: $bound>)? ($($arg: $ty),*) {
                $body $(::<$g>)? ($($arg),*)
            }
        }
    };
}
pub(crate) use per_isa;
