//! The `fluidbed-server` command line, built in this package so that the cluster test can start
//! real server processes (and kill them with SIGKILL).

fn main() {
    if let Err(e) = fluidbed_server::cli::main() {
        eprintln!("fluidbed-node: {e:#}");
        std::process::exit(1);
    }
}
