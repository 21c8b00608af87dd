//! Validation runs: `cargo run --release -p fluidbed-core --example validate -- <name>`.
//! Each prints its figures and, last, one JSON line {"name","figure","reference","rel_err",...}.

mod analysis_signals;
mod bubbling;
mod bubbling_stats;
mod common;
mod fig3;
mod fluidized;
mod packed_bed;
mod plots;
mod pressure_oscillation;
mod slug_rise;
mod table3;
mod umf;

/// Print the validation's one-line JSON result (the last line, read by the checks).
fn report(v: serde_json::Value) {
    println!("{v}");
}

fn main() {
    let what = std::env::args().nth(1).unwrap_or_default();
    match what.as_str() {
        "table3" => table3::run(),
        "packed-bed" => report(packed_bed::run(false)),
        "fluidized" => report(fluidized::run()),
        "fig3" => report(fig3::run()),
        "umf" => report(umf::run()),
        "umf-paper-cells" => report(umf::run_paper_cells()),
        "bubbling" => report(bubbling::run()),
        "bubbling-stats" => report(bubbling_stats::run()),
        "analysis-signals" => report(analysis_signals::run()),
        "slug-rise" => report(slug_rise::run()),
        "pressure-oscillation" => report(pressure_oscillation::run()),
        // Any case file, with the per-stage wall times: `-- case cases/quickstart.json`
        "case" => report(common::timed_case(&std::env::args().nth(2).expect("case file"))),
        other => {
            eprintln!("unknown validation {other:?}; choose table3, packed-bed, fluidized, umf, umf-paper-cells, fig3, bubbling, bubbling-stats, slug-rise, pressure-oscillation or analysis-signals");
            std::process::exit(2);
        }
    }
}
