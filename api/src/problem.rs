//! RFC 9457 problem details, the body of every error answer (`application/problem+json`).

use crate::job::CaseProblem;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

/// A problem document. An invalid case (422) adds `errors` (each field at fault) and `warnings`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct Problem {
    /// Always `about:blank`: the status and title say what went wrong.
    #[serde(rename = "type")]
    #[schema(example = "about:blank")]
    pub type_: String,
    pub title: String,
    /// The HTTP status code.
    pub status: u16,
    pub detail: String,
    /// 422: every problem with the case, by JSON pointer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub errors: Option<Vec<FieldError>>,
    /// 422: the case's warnings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warnings: Option<Vec<CaseProblem>>,
}

impl Problem {
    pub fn new(status: u16, title: &str, detail: &str) -> Problem {
        Problem {
            type_: "about:blank".into(),
            title: title.into(),
            status,
            detail: detail.into(),
            errors: None,
            warnings: None,
        }
    }
}

/// One field of a refused case.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct FieldError {
    /// JSON pointer (RFC 6901), e.g. `/particles/diameter_m`.
    pub pointer: String,
    /// The value given (null when missing).
    pub value: Value,
    /// The allowed range or form.
    pub allowed: String,
    pub message: String,
}

impl From<&fluidbed_core::case::Problem> for FieldError {
    fn from(p: &fluidbed_core::case::Problem) -> FieldError {
        FieldError {
            pointer: p.path.clone(),
            value: p.value.clone(),
            allowed: p.allowed.clone(),
            message: p.message.clone(),
        }
    }
}
