//! `serde_json::to_string_pretty` for a [`Value`], written by hand: the same
//! text (two-space indent, `"key": value`, `[]` / `{}` when empty), but the
//! leaves go through `Value`'s compact `Display`, so the wasm module carries
//! one JSON serializer instead of a second, pretty-printing one.

use serde_json::Value;

/// The pretty-printed text of `value`, byte for byte what
/// `serde_json::to_string_pretty(value)` returns.
pub fn to_string_pretty(value: &Value) -> String {
    let mut out = String::new();
    write_value(&mut out, value, 0);
    out
}

fn newline(out: &mut String, depth: usize) {
    out.push('\n');
    for _ in 0..depth {
        out.push_str("  ");
    }
}

fn write_value(out: &mut String, value: &Value, depth: usize) {
    match value {
        Value::Array(items) if !items.is_empty() => {
            out.push('[');
            for (i, item) in items.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                newline(out, depth + 1);
                write_value(out, item, depth + 1);
            }
            newline(out, depth);
            out.push(']');
        }
        Value::Object(map) if !map.is_empty() => {
            out.push('{');
            for (i, (key, item)) in map.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                newline(out, depth + 1);
                // A string leaf: quoted and escaped as serde_json does.
                out.push_str(&Value::String(key.clone()).to_string());
                out.push_str(": ");
                write_value(out, item, depth + 1);
            }
            newline(out, depth);
            out.push('}');
        }
        leaf => out.push_str(&leaf.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wasm_bindgen_test::wasm_bindgen_test;

    #[wasm_bindgen_test(unsupported = test)]
    fn same_text_as_serde_json() {
        let samples = [
            r#"{"a": [1, 2.5, -3e-7, {"b": []}, {}], "c\"\n": "x\u0001y", "d": null, "e": true}"#,
            r#"[]"#,
            r#"{}"#,
            r#"[[], [[1]], {"k": {"l": [false]}}]"#,
            r#""text""#,
            r#"1.0e300"#,
        ];
        for text in samples {
            let v: Value = serde_json::from_str(text).unwrap();
            assert_eq!(
                to_string_pretty(&v),
                serde_json::to_string_pretty(&v).unwrap(),
                "{text}"
            );
        }
    }
}
