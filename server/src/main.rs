//! fluidbed-server: serve fluidbed jobs over HTTP until interrupted (flags in cli.rs).

fn main() -> anyhow::Result<()> {
    fluidbed_server::cli::main()
}
