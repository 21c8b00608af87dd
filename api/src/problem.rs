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
            value: echo(&p.value, 0),
            allowed: p.allowed.clone(),
            message: p.message.clone(),
        }
    }
}

/// Deepest nesting of a given value echoed back: below any JSON parser's recursion limit
/// (serde_json's is 128), so that a 422 for a deeply nested value is still readable (issue 22).
const MAX_ECHO_DEPTH: usize = 16;
/// Longest array echoed back as is.
const MAX_ECHO_ITEMS: usize = 100;

/// The value as given, with what is nested too deep or too long summarised in a string.
fn echo(v: &Value, depth: usize) -> Value {
    match v {
        Value::Array(a) if a.len() > MAX_ECHO_ITEMS => Value::String(format!("(an array of {} values)", a.len())),
        Value::Array(_) | Value::Object(_) if depth >= MAX_ECHO_DEPTH => {
            Value::String(format!("(nested deeper than {MAX_ECHO_DEPTH} levels)"))
        }
        Value::Array(a) => Value::Array(a.iter().map(|x| echo(x, depth + 1)).collect()),
        Value::Object(m) => Value::Object(m.iter().map(|(k, x)| (k.clone(), echo(x, depth + 1))).collect()),
        _ => v.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_and_long_values_are_echoed_in_summary() {
        let mut deep = Value::from(1);
        for _ in 0..200 {
            deep = Value::Array(vec![deep]);
        }
        let shown = echo(&deep, 0);
        assert!(serde_json::from_str::<Value>(&shown.to_string()).is_ok(), "parses again");
        assert_eq!(shown.pointer(&"/0".repeat(MAX_ECHO_DEPTH)), Some(&Value::from("(nested deeper than 16 levels)")));
        assert_eq!(echo(&Value::Array(vec![Value::Null; 1000]), 0), Value::from("(an array of 1000 values)"));
        let plain = serde_json::json!({"a": [1, 2, {"b": "c"}]});
        assert_eq!(echo(&plain, 0), plain);
    }
}
