//! The fast version of `stress -- extremes`: 30 seeded random cases, each refused with a named
//! field, finished, or stopped by the watchdog with a message; no panic, hang or NaN snapshot.

#[path = "../examples/stress/extremes.rs"]
#[allow(dead_code)]
mod extremes;

#[test]
fn thirty_extreme_cases_are_refused_finished_or_stopped_with_a_message() {
    let sum = extremes::run_all(30, 22_140, std::time::Duration::from_secs(20), false);
    println!("{}\n{}", sum.table(), sum.json());
    assert_eq!(sum.cases, 30);
    assert_eq!((sum.panics, sum.hangs, sum.nan_snapshots, sum.unexplained), (0, 0, 0, 0), "{}", sum.table());
    // The draw reaches all three ends: refusals, finished runs and watchdog stops.
    let has = |p: &str| sum.by_cause.keys().any(|k| k.starts_with(p));
    assert!(has("refused") && has("finished") && has("stopped"), "{}", sum.table());
}
