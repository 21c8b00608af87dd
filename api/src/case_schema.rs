//! The case's JSON Schema (generated in fluidbed-core by schemars, also docs/case.schema.json)
//! made part of an OpenAPI document: the case becomes `#/components/schemas/Case` and each of its
//! definitions a component of its own, so that every `$ref` resolves inside the document.

use serde_json::Value;

/// Where the POST body's schema lives in the document.
pub const CASE_REF: &str = "#/components/schemas/Case";

/// Add the case schema to `doc`'s components. Panics if a case definition's name is already a
/// component (a programming error, caught by the server's OpenAPI tests).
pub fn merge_into(doc: &mut Value) {
    let mut case = fluidbed_core::case::Case::json_schema();
    let definitions = match case.as_object_mut() {
        Some(o) => {
            o.remove("$schema");
            o.remove("definitions")
        }
        None => None,
    };
    let schemas = doc
        .pointer_mut("/components/schemas")
        .and_then(Value::as_object_mut)
        .expect("the OpenAPI document has components.schemas");
    let mut add = |name: &str, mut schema: Value| {
        rewrite_refs(&mut schema);
        let old = schemas.insert(name.to_string(), schema);
        // `Case` itself may stand there as the placeholder the routes name.
        assert!(old.is_none() || name == "Case", "the case schema's `{name}` clashes with an API schema");
    };
    if let Some(Value::Object(defs)) = definitions {
        for (name, schema) in defs {
            add(&name, schema);
        }
    }
    add("Case", case);
}

/// `#/definitions/X` (draft 7, as schemars writes it) → `#/components/schemas/X`.
fn rewrite_refs(v: &mut Value) {
    match v {
        Value::Object(o) => {
            if let Some(Value::String(r)) = o.get_mut("$ref") {
                if let Some(name) = r.strip_prefix("#/definitions/") {
                    *r = format!("#/components/schemas/{name}");
                }
            }
            o.values_mut().for_each(rewrite_refs);
        }
        Value::Array(a) => a.iter_mut().for_each(rewrite_refs),
        _ => {}
    }
}

/// Every `$ref` in `doc` that does not point at something inside it (empty when all resolve).
pub fn unresolved_refs(doc: &Value) -> Vec<String> {
    let mut out = Vec::new();
    collect(doc, doc, &mut out);
    out
}

fn collect(root: &Value, v: &Value, out: &mut Vec<String>) {
    match v {
        Value::Object(o) => {
            if let Some(Value::String(r)) = o.get("$ref") {
                let found = r.strip_prefix('#').and_then(|p| root.pointer(p));
                if found.is_none() {
                    out.push(r.clone());
                }
            }
            o.values().for_each(|x| collect(root, x, out));
        }
        Value::Array(a) => a.iter().for_each(|x| collect(root, x, out)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_case_and_its_definitions_become_components_with_local_refs() {
        let mut doc = json!({"openapi": "3.1.0", "components": {"schemas": {"Job": {"type": "object"}}}});
        merge_into(&mut doc);
        let schemas = doc["components"]["schemas"].as_object().unwrap();
        assert!(schemas.contains_key("Job"));
        assert_eq!(schemas["Case"]["title"], "Case");
        assert!(schemas["Case"].get("definitions").is_none() && schemas["Case"].get("$schema").is_none());
        // every definition of the published schema is a component now
        let published = fluidbed_core::case::Case::json_schema();
        for name in published["definitions"].as_object().unwrap().keys() {
            assert!(schemas.contains_key(name), "{name}");
        }
        assert_eq!(unresolved_refs(&doc), Vec::<String>::new());
        assert!(!doc.to_string().contains("#/definitions/"));
    }

    #[test]
    fn an_unresolvable_reference_is_reported() {
        let doc =
            json!({"a": {"$ref": "#/components/schemas/Nope"}, "b": {"$ref": "/v1/schema/case"}, "c": {"$ref": "#/a"}});
        assert_eq!(unresolved_refs(&doc), vec!["#/components/schemas/Nope".to_string(), "/v1/schema/case".to_string()]);
    }

    #[test]
    fn a_clash_with_an_api_schema_is_refused() {
        let mut doc = json!({"components": {"schemas": {"Column": {}}}});
        let r = std::panic::catch_unwind(move || merge_into(&mut doc));
        assert!(r.is_err());
    }
}
