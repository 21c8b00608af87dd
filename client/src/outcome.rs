//! How a verb ends: its exit code and what it prints (a failure, the server's problem document,
//! a job's final status).

use crate::api::ApiError;
use crate::exit;
use serde_json::json;

pub(crate) fn fail(code: i32, msg: &str) -> i32 {
    eprintln!("fluidbed: {msg}");
    code
}

pub(crate) fn api_fail(e: ApiError, json_out: bool) -> i32 {
    match &e {
        ApiError::Invalid(p) => {
            if json_out {
                println!("{p}");
            } else {
                for err in p["errors"].as_array().into_iter().flatten() {
                    eprintln!(
                        "error: {}: {} (got {}; allowed: {})",
                        err["pointer"].as_str().unwrap_or(""),
                        err["message"].as_str().unwrap_or(""),
                        err["value"],
                        err["allowed"].as_str().unwrap_or("")
                    );
                }
            }
            exit::INVALID_CASE
        }
        ApiError::Server(m) => fail(exit::SERVER, m),
    }
}

pub(crate) fn outcome_code(status: &str) -> i32 {
    if status == "succeeded" {
        exit::OK
    } else {
        exit::JOB_FAILED
    }
}

pub(crate) fn report_outcome(id: &str, status: &str, message: Option<&str>, json_out: bool) {
    if json_out {
        println!("{}", json!({ "id": id, "status": status, "message": message }));
    } else {
        let m = message.map(|m| format!(": {m}")).unwrap_or_default();
        eprintln!("job {id} {status}{m}");
    }
}
