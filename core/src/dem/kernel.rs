//! The code paths of the DEM's inner loops (pair pass, particle pass) and which one runs: the
//! best the CPU has, or the one `FLUIDBED_KERNEL=portable|avx2|avx512` asks for. Every path does
//! the same IEEE operations in the same order (Rust never fuses a multiply and an add), so all
//! give the same bits; the switch exists so that each path is tested on a CPU that has a better one.
//!
//! `Isa<true>` is the proof that the CPU has the AVX-512 features the vector kernels are compiled
//! for: it can only be made by `Isa::avx512`, which checks, so the functions that take it are safe.

use std::sync::OnceLock;

/// A code path of the DEM kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// Baseline x86-64 (or any other target): what the compiler vectorises by itself.
    Portable,
    /// The portable code compiled for AVX2.
    Avx2,
    /// AVX-512 intrinsics for the pair scan, gathers, force scatter and position update.
    Avx512,
}

/// The environment variable that forces a kernel.
pub const KERNEL_ENV: &str = "FLUIDBED_KERNEL";

impl Kernel {
    pub const ALL: [Kernel; 3] = [Kernel::Portable, Kernel::Avx2, Kernel::Avx512];

    /// The name used by `FLUIDBED_KERNEL` and the benchmarks (`portable`, `avx2`, `avx512`).
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Portable => "portable",
            Kernel::Avx2 => "avx2",
            Kernel::Avx512 => "avx512",
        }
    }

    pub fn from_name(name: &str) -> Option<Kernel> {
        Kernel::ALL.into_iter().find(|k| k.name() == name.trim().to_ascii_lowercase())
    }

    /// Whether this CPU can run the path.
    pub fn is_available(self) -> bool {
        match self {
            Kernel::Portable => true,
            Kernel::Avx2 => has_avx2(),
            Kernel::Avx512 => Isa::avx512().is_some(),
        }
    }

    /// The paths this CPU can run, portable first.
    pub fn available() -> Vec<Kernel> {
        Kernel::ALL.into_iter().filter(|k| k.is_available()).collect()
    }

    /// The fastest path this CPU can run.
    pub fn best() -> Kernel {
        *Kernel::available().last().expect("the portable path is always available")
    }

    /// The kernel a `FLUIDBED_KERNEL` value asks for: `None` or empty → the best; an unknown
    /// name or a path this CPU lacks → an error that says which paths it has.
    pub fn requested(value: Option<&str>) -> Result<Kernel, String> {
        let Some(v) = value.filter(|v| !v.trim().is_empty()) else { return Ok(Kernel::best()) };
        let names = || Kernel::available().iter().map(|k| k.name()).collect::<Vec<_>>().join(", ");
        match Kernel::from_name(v) {
            Some(k) if k.is_available() => Ok(k),
            Some(k) => Err(format!("{KERNEL_ENV}={v}: this CPU lacks the {} path (it has: {})", k.name(), names())),
            None => Err(format!(
                "{KERNEL_ENV}={v}: unknown kernel (choose portable, avx2 or avx512; this CPU has: {})",
                names()
            )),
        }
    }

    /// The kernel new systems use: `FLUIDBED_KERNEL` if it names a path this CPU has, else the
    /// best, with a warning on stderr (once per process) saying what was asked and what runs.
    pub fn from_env() -> Kernel {
        static CHOSEN: OnceLock<Kernel> = OnceLock::new();
        *CHOSEN.get_or_init(|| {
            let value = std::env::var(KERNEL_ENV).ok();
            Kernel::requested(value.as_deref()).unwrap_or_else(|e| {
                let best = Kernel::best();
                eprintln!("fluidbed: {e}; running the {} path instead", best.name());
                best
            })
        })
    }
}

impl std::fmt::Display for Kernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Proof of the CPU features of the vector kernels when `AVX512` (avx512f, avx512vl, bmi2);
/// `Isa<false>` proves nothing and is free to make. The field is private: only `avx512`, which
/// checks the CPU, makes an `Isa<true>`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Isa<const AVX512: bool>(());

impl<const AVX512: bool> Isa<AVX512> {
    /// The proof of the AVX-512 features, if this is one (a constant for the compiler).
    #[inline(always)]
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) fn as_avx512(self) -> Option<Isa<true>> {
        AVX512.then_some(Isa(()))
    }
}

impl Isa<false> {
    pub(crate) const PORTABLE: Isa<false> = Isa(());
}

impl Isa<true> {
    pub(crate) fn avx512() -> Option<Isa<true>> {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            (has!("avx512f") && has!("avx512vl") && has!("bmi2")).then_some(Isa(()))
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_requests_name_the_path_or_say_why_not() {
        assert_eq!(Kernel::requested(None), Ok(Kernel::best()));
        assert_eq!(Kernel::requested(Some(" ")), Ok(Kernel::best()));
        assert_eq!(Kernel::requested(Some("Portable")), Ok(Kernel::Portable));
        let err = Kernel::requested(Some("sse9")).unwrap_err();
        assert!(err.contains("unknown kernel") && err.contains("portable"), "{err}");
        for k in Kernel::ALL {
            match Kernel::requested(Some(k.name())) {
                Ok(got) => assert!(got == k && k.is_available()),
                Err(e) => assert!(!k.is_available() && e.contains("lacks"), "{e}"),
            }
        }
        assert_eq!(Kernel::available()[0], Kernel::Portable);
    }
}
