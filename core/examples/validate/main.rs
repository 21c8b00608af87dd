//! Validation runs: `cargo run --release -p fluidbed-core --example validate -- <name>`.
//! Each prints its figures and, last, one JSON line {"name","figure","reference","rel_err",...}.

mod table3;

fn main() {
    let what = std::env::args().nth(1).unwrap_or_default();
    match what.as_str() {
        "table3" => table3::run(),
        other => {
            eprintln!("unknown validation {other:?}; choose table3, packed-bed, fluidized, umf, fig3 or bubbling");
            std::process::exit(2);
        }
    }
}
