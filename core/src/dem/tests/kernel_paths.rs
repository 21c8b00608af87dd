//! Every kernel path this CPU has (`Kernel::available`) follows the portable path's trajectory
//! bit for bit (the stated tolerance is zero: the paths do the same IEEE operations in the same
//! order, see `kernel`), on the busy system (friction, walls and lid, list rebuilds and
//! re-sorts), through the start-up and the multistep steps. A path the CPU lacks is reported as
//! skipped.

use super::checkpoint::{busy_system, same_state};
use crate::dem::{DemSystem, Kernel};

fn run_on(kernel: Kernel, steps: usize) -> DemSystem {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    pool.install(|| {
        let mut s = busy_system();
        s.set_kernel(kernel).expect("an available kernel");
        for _ in 0..steps {
            s.step();
        }
        assert_eq!(s.kernel(), kernel);
        s
    })
}

#[test]
fn every_kernel_path_follows_the_portable_trajectory() {
    let steps = 1500;
    let reference = run_on(Kernel::Portable, steps);
    assert!(reference.list_builds().0 > 1, "no list rebuild exercised");
    for kernel in [Kernel::Avx2, Kernel::Avx512] {
        if !kernel.is_available() {
            super::skip(&format!("every_kernel_path_follows_the_portable_trajectory ({kernel})"), "the CPU lacks it");
            continue;
        }
        let got = run_on(kernel, steps);
        let worst = got
            .positions()
            .iter()
            .zip(reference.positions())
            .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
            .fold(0.0, f64::max);
        assert!(same_state(&got, &reference), "{kernel} path left the portable trajectory (largest |Δx| {worst:e} m)");
    }
}

#[test]
fn an_unavailable_kernel_is_refused() {
    let mut s = busy_system();
    for kernel in Kernel::ALL {
        assert_eq!(s.set_kernel(kernel).is_ok(), kernel.is_available(), "{kernel}");
    }
}
