//! `cargo run --release -p fluidbed-tests --example http-fuzz -- [CASES] [SEED]`: CASES fuzzed
//! case submissions (default 10,000) to a real server on loopback; the first failures, then one
//! JSON line `{"fuzz":"http","cases":…,"status_5xx":…,"panics":…,"unnamed_4xx":…, …}`.
//! Exit 1 when anything failed.

fn main() {
    let mut args = std::env::args().skip(1);
    let n = args.next().and_then(|a| a.parse().ok()).unwrap_or(10_000);
    let seed = args.next().and_then(|a| a.parse().ok()).unwrap_or(22);
    let rt = tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build().expect("runtime");
    let report = rt.block_on(fluidbed_tests::fuzz::run(n, seed));
    for f in &report.failures {
        eprintln!("FAIL {f}");
    }
    println!("{}", report.json_line());
    std::process::exit(if report.clean() { 0 } else { 1 });
}
