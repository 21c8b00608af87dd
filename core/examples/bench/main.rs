//! Benchmarks: `cargo run --release -p fluidbed-core --example bench -- <dem|cfd|voidage|coupled|scaling|halo|…>`.
//! Each prints JSON lines; the last line of each is the figure the issues quote.

mod adaptive;
mod cfd;
mod checkpoint;
mod coupled;
mod dem;
mod dp_probe;
mod halo;
mod plan;
mod restitution;
mod scaling;
mod tradeoff;
mod voidage;

fn main() {
    let what = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    // Every benchmark runs as the server runs a job: on a solver pool (its own team lock), the
    // stepping thread one of the pool's workers, so a team step starts without waking it.
    let pool = fluidbed_core::dem::solver_pool().build().expect("solver pool");
    pool.install(|| run(&what));
}

fn run(what: &str) {
    match what {
        "adaptive-step" => adaptive::run(),
        "cfd" => cfd::run(),
        "coupled" => coupled::run(),
        "coupled-parts" => coupled::parts(),
        "checkpoint" => checkpoint::run(),
        "gas-context" => coupled::gas_context(),
        "gas-team" => coupled::gas_team(),
        "coupled-micro" => coupled::micro(),
        "gas-dt" => coupled::gas_dt(fluidbed_core::cfd::TimeScheme::Ab3),
        "gas-dt-fb" => coupled::gas_dt(fluidbed_core::cfd::TimeScheme::ForwardBackward),
        "tradeoff" => tradeoff::run(),
        "scaling" => scaling::run(),
        "restitution" => restitution::run(),
        "dem" => dem::run(),
        "dp-probe" => dp_probe::run(),
        "halo" => halo::run(),
        "plan" => plan::run(),
        "voidage" => voidage::run(),
        other => {
            eprintln!("unknown benchmark {other:?}; choose dem, cfd, voidage, coupled, scaling");
            std::process::exit(2);
        }
    }
}
