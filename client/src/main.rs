//! fluidbed: the command-line client.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() == 3 && args[1] == "validate" {
        let text = std::fs::read_to_string(&args[2]).expect("read case");
        match fluidbed_core::case::Case::parse_str(&text) {
            Ok((_, rep)) => {
                for w in rep.warnings { eprintln!("warning: {w}"); }
                println!("ok");
            }
            Err(rep) => {
                for e in rep.errors { eprintln!("error: {e}"); }
                std::process::exit(2);
            }
        }
    } else {
        eprintln!("usage: fluidbed validate CASE.json");
        std::process::exit(64);
    }
}
