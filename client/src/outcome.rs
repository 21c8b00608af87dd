//! How a verb ends: its exit code and what it prints (a failure, the server's problem document,
//! a job's final status).

use crate::api::ApiError;
use crate::exit;
use fluidbed_api::JobStatus;
use serde_json::json;

pub(crate) fn fail(code: i32, msg: &str) -> i32 {
    eprintln!("fluidbed: {msg}");
    code
}

pub(crate) fn api_fail(e: ApiError, json_out: bool) -> i32 {
    match &e {
        ApiError::Invalid(p) => {
            if json_out {
                println!("{}", serde_json::to_string(p).unwrap_or_default());
            } else {
                for err in p.errors.iter().flatten() {
                    eprintln!("error: {}: {} (got {}; allowed: {})", err.pointer, err.message, err.value, err.allowed);
                }
            }
            exit::INVALID_CASE
        }
        ApiError::Server(m) => fail(exit::SERVER, m),
    }
}

pub(crate) fn outcome_code(status: JobStatus) -> i32 {
    if status == JobStatus::Succeeded {
        exit::OK
    } else {
        exit::JOB_FAILED
    }
}

pub(crate) fn report_outcome(id: &str, status: JobStatus, message: Option<&str>, json_out: bool) {
    if json_out {
        println!("{}", json!({ "id": id, "status": status, "message": message }));
    } else {
        let m = message.map(|m| format!(": {m}")).unwrap_or_default();
        eprintln!("job {id} {status}{m}");
    }
}
