//! Stress cases of the solver (issue 22): `cargo run --release -p fluidbed-core --example stress -- NAME`.
//! `extremes [CASES] [SEED]`: seeded random cases inside and beyond the schema's ranges; prints a
//! line per case, the outcome table, one stop message per kind, and last one JSON line.
//! `dt-sweep`: the largest stable DEM and gas steps by bisection, beside the theoretical limits.
//! `packed-100k`: the packed bed, particles free, 100,000 steps per voidage method: jumps and
//! temporal fluctuation of the gas velocity.
//! `gas-artefacts`: the freeboard's odd–even pressure ripple and the outlet's pressure offset.
//! `bubbling-1m`: the 44-mm bubbling bed for 1,000,000 DEM steps: gas mass and particle momentum
//! budgets, no watchdog stop.

mod bubbling_1m;
mod dt_sweep;
mod extremes;
mod gas_artefacts;
mod packed_100k;

use std::time::Duration;

/// Wall-time bound of one case: beyond it the case counts as a hang.
const CASE_LIMIT: Duration = Duration::from_secs(20);

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("extremes") => {
            let n = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(300);
            let seed = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(22_000);
            let sum = extremes::run_all(n, seed, CASE_LIMIT, true);
            println!("\n{}", sum.table());
            for (seed, m) in &sum.stop_examples {
                println!("- case {seed}: \"{m}\"");
            }
            println!("{}", sum.json());
            if sum.panics + sum.hangs + sum.nan_snapshots + sum.unexplained > 0 {
                std::process::exit(1);
            }
        }
        Some("dt-sweep") => dt_sweep::run(),
        Some("packed-100k") => packed_100k::run(),
        Some("gas-artefacts") => gas_artefacts::run(),
        Some("bubbling-1m") => bubbling_1m::run(),
        other => {
            eprintln!("usage: stress extremes [CASES] [SEED] | dt-sweep | packed-100k | gas-artefacts | bubbling-1m (got {other:?})");
            std::process::exit(2);
        }
    }
}
