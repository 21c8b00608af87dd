//! `fluidbed validate`: the case checked locally, every problem with its JSON path.

use crate::exit;
use crate::outcome::fail;
use serde_json::json;
use std::path::Path;

/// Local validation: (exit code, case JSON text when valid).
pub(crate) fn validate(path: &Path, json_out: bool) -> (i32, Option<(String, String)>) {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) => return (fail(exit::INVALID_CASE, &format!("cannot read {}: {e}", path.display())), None),
    };
    match fluidbed_core::case::Case::parse_str(&text) {
        Ok((case, report)) => {
            if json_out {
                println!("{}", json!({ "valid": true, "warnings": report.warnings }));
            }
            for w in &report.warnings {
                eprintln!("warning: {w}");
            }
            (exit::OK, Some((text, case.name)))
        }
        Err(report) => {
            if json_out {
                println!("{}", json!({ "valid": false, "errors": report.errors, "warnings": report.warnings }));
            }
            for e in &report.errors {
                eprintln!("error: {e}");
            }
            (exit::INVALID_CASE, None)
        }
    }
}
