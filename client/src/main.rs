//! fluidbed: the command-line client (see `fluidbed --help`).
fn main() {
    std::process::exit(fluidbed::cli::main_with(std::env::args_os()));
}
