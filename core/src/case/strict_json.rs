//! JSON text to a `serde_json::Value`, refusing duplicate object keys (serde_json keeps the last
//! one silently: `{"end_time_s": 0.05, "end_time_s": 7}` would run for 7 s).

use serde::de::{DeserializeSeed, Deserializer, Error as _, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::cell::RefCell;
use std::fmt;

/// Why a text is refused.
#[derive(Debug)]
pub enum StrictJsonError {
    /// Not JSON at all (serde_json's message, with line and column).
    Syntax(serde_json::Error),
    /// A key given twice in one object, at this JSON pointer.
    DuplicateKey { pointer: String, message: String },
}

/// Parse `text`; duplicate keys are an error naming the key's JSON pointer.
pub fn parse(text: &str) -> Result<Value, StrictJsonError> {
    let dup = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed = Seed { path: String::new(), dup: &dup }.deserialize(&mut de).and_then(|v| de.end().map(|_| v));
    match (parsed, dup.into_inner()) {
        (Ok(v), _) => Ok(v),
        (Err(e), Some(pointer)) => Err(StrictJsonError::DuplicateKey {
            message: format!("the key `{}` is given twice ({e})", pointer.rsplit('/').next().unwrap_or("")),
            pointer,
        }),
        (Err(e), None) => Err(StrictJsonError::Syntax(e)),
    }
}

/// Deserializes one value at `path`; records the pointer of the first duplicate key in `dup`.
struct Seed<'a> {
    path: String,
    dup: &'a RefCell<Option<String>>,
}

impl<'de> DeserializeSeed<'de> for Seed<'_> {
    type Value = Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

/// RFC 6901 escaping of one pointer segment.
fn segment(key: &str) -> String {
    key.replace('~', "~0").replace('/', "~1")
}

impl<'de> Visitor<'de> for Seed<'_> {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(v.into())
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::new();
        while let Some(v) =
            seq.next_element_seed(Seed { path: format!("{}/{}", self.path, out.len()), dup: self.dup })?
        {
            out.push(v);
        }
        Ok(Value::Array(out))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            let path = format!("{}/{}", self.path, segment(&key));
            if out.contains_key(&key) {
                *self.dup.borrow_mut() = Some(path);
                return Err(A::Error::custom("duplicate key"));
            }
            let v = map.next_value_seed(Seed { path, dup: self.dup })?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_keys_are_refused_with_their_pointer() {
        match parse(r#"{"a": {"b": 1, "c": [{"d": 1, "d": 2}]}}"#) {
            Err(StrictJsonError::DuplicateKey { pointer, .. }) => assert_eq!(pointer, "/a/c/0/d"),
            other => panic!("{other:?}"),
        }
        let v = parse(r#"{"a": [1, 2.5, "x", null, true], "a~b/": {}}"#).unwrap();
        assert_eq!(v, serde_json::json!({"a": [1, 2.5, "x", null, true], "a~b/": {}}));
        assert!(matches!(parse("{\"a\": 1} x"), Err(StrictJsonError::Syntax(_))));
    }
}
