//! What an answer to a fuzzed submission must be: no 5xx; every 4xx an RFC 9457 problem
//! document (`application/problem+json` with type, title, status, detail); a 422's `errors`
//! each naming a JSON pointer; an accepted case a job with a Location.

use serde_json::Value;

/// How an answer fails, if it does.
#[derive(Debug, PartialEq)]
pub enum Verdict {
    Fine,
    /// A 5xx status.
    ServerError(String),
    /// A 4xx that is not a complete problem document, or a 422 without pointers.
    Unnamed(String),
    /// Neither an error nor 201.
    Unexpected(String),
}

/// RFC 6901: "" or "/" segments, `~` only as `~0` or `~1`.
pub fn is_json_pointer(p: &str) -> bool {
    (p.is_empty() || p.starts_with('/')) && {
        let b = p.as_bytes();
        b.iter().enumerate().all(|(i, &c)| c != b'~' || matches!(b.get(i + 1), Some(b'0' | b'1')))
    }
}

/// A JSON media type: `application/json` or `*/*+json`, any parameters, any case.
pub fn is_json_media_type(ct: &str) -> bool {
    let t = ct.split(';').next().unwrap_or("").trim().to_ascii_lowercase();
    t == "application/json" || (t.starts_with("application/") && t.ends_with("+json"))
}

/// Judge one answer to a body sent as `sent_type` (None: no header). `submitted` is the body
/// as JSON when it is one: the root pointer "" is a name only for a body that is not an object.
pub fn judge(
    sent_type: Option<&str>,
    status: u16,
    content_type: Option<&str>,
    body: &[u8],
    submitted: Option<&Value>,
) -> Verdict {
    let text = String::from_utf8_lossy(body);
    let short: String = text.chars().take(300).collect();
    if status >= 500 {
        return Verdict::ServerError(format!("{status}: {short}"));
    }
    if status == 201 {
        let doc: Value = serde_json::from_slice(body).unwrap_or(Value::Null);
        return if !sent_type.is_none_or(is_json_media_type) {
            Verdict::Unexpected(format!("201 for a body sent as {sent_type:?}"))
        } else if doc["id"].is_string() {
            Verdict::Fine
        } else {
            Verdict::Unexpected(format!("201 without a job id: {short}"))
        };
    }
    if !(400..500).contains(&status) {
        return Verdict::Unexpected(format!("{status}: {short}"));
    }
    if content_type != Some("application/problem+json") {
        return Verdict::Unnamed(format!("{status} with content type {content_type:?}: {short}"));
    }
    let Ok(doc) = serde_json::from_slice::<Value>(body) else {
        return Verdict::Unnamed(format!("{status}: body is not JSON: {short}"));
    };
    let has = |k: &str| doc[k].as_str().is_some_and(|s| !s.is_empty());
    if !(has("type") && has("title") && has("detail") && doc["status"].as_u64() == Some(status as u64)) {
        return Verdict::Unnamed(format!("{status}: not a complete problem document: {short}"));
    }
    if status == 422 {
        let Some(errors) = doc["errors"].as_array().filter(|e| !e.is_empty()) else {
            return Verdict::Unnamed(format!("422 without errors: {short}"));
        };
        let root_ok = submitted.is_some_and(|v| !v.is_object());
        for e in errors {
            let p = e["pointer"].as_str();
            let named = p.is_some_and(|p| is_json_pointer(p) && (!p.is_empty() || root_ok));
            if !named {
                return Verdict::Unnamed(format!("422 error without a JSON pointer: {e}"));
            }
        }
    }
    Verdict::Fine
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn pointers_follow_rfc_6901() {
        for ok in ["", "/a", "/a~0b/~1", "/0/"] {
            assert!(is_json_pointer(ok), "{ok}");
        }
        for bad in ["a", "/a~", "/a~2", "column"] {
            assert!(!is_json_pointer(bad), "{bad}");
        }
    }

    #[test]
    fn a_422_must_name_each_field() {
        let ct = Some("application/problem+json");
        let doc = |errors: Value| {
            json!({"type": "about:blank", "title": "Invalid case", "status": 422, "detail": "d", "errors": errors})
                .to_string()
        };
        let case = json!({"column": {}});
        let named = doc(json!([{"pointer": "/column/diameter_m"}]));
        assert_eq!(judge(None, 422, ct, named.as_bytes(), Some(&case)), Verdict::Fine);
        let root = doc(json!([{"pointer": ""}]));
        assert!(matches!(judge(None, 422, ct, root.as_bytes(), Some(&case)), Verdict::Unnamed(_)));
        assert_eq!(judge(None, 422, ct, root.as_bytes(), Some(&json!([]))), Verdict::Fine);
        assert!(matches!(judge(None, 422, ct, doc(json!([])).as_bytes(), None), Verdict::Unnamed(_)));
        assert!(matches!(judge(None, 400, Some("text/plain"), b"bad", None), Verdict::Unnamed(_)));
        assert!(matches!(judge(None, 500, ct, b"{}", None), Verdict::ServerError(_)));
        let job = br#"{"id": "0123456789abcdef"}"#;
        assert_eq!(judge(Some("application/json; charset=utf-8"), 201, None, job, None), Verdict::Fine);
        assert!(matches!(judge(Some("text/plain"), 201, None, job, None), Verdict::Unexpected(_)));
    }
}
