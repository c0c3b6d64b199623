//! JSON pose files to the common table: an array of objects with named
//! fields (the keys act as a header), an array of 4x4 matrices (nested or 16
//! numbers), or an array of number arrays; optionally wrapped as
//! `{"poses": [...]}`.

use serde_json::Value;

use super::pose_table::{Origin, Row, Table};
use crate::error::{Error, Result};

pub(crate) fn json_error(e: &serde_json::Error) -> Error {
    let text = e.to_string();
    let message = text
        .find(" at line ")
        .map_or(text.as_str(), |i| &text[..i])
        .to_string();
    Error::parse(e.line(), e.column(), format!("invalid JSON: {message}"))
}

/// A JSON scalar as a table field (numbers print back exactly).
fn field_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Number(n) => n.to_string(),
        other => other.to_string(),
    }
}

/// The 16 or n numbers of an array element: flat numbers, or a 4x4 matrix.
fn array_fields(items: &[Value], index: usize) -> Result<Vec<String>> {
    if items.iter().all(|v| !v.is_array()) {
        return Ok(items.iter().map(field_text).collect());
    }
    let rows: Option<Vec<&Vec<Value>>> = items.iter().map(|v| v.as_array()).collect();
    match rows {
        Some(rows) if rows.len() == 4 && rows.iter().all(|r| r.len() == 4 && r.iter().all(|v| !v.is_array())) => {
            Ok(rows.iter().flat_map(|r| r.iter().map(field_text)).collect())
        }
        _ => Err(Origin::JsonElement(index).error(
            0,
            format!(
                "expected numbers or one 4x4 matrix, found a list of {} lists (for [robot, camera] pairs, pass the robot matrices alone)",
                items.len()
            ),
        )),
    }
}

/// Keys in a stable order, with `qw` after `qz` so that a quaternion reads
/// as `xyzw` (serde_json sorts keys).
fn ordered_keys(object: &serde_json::Map<String, Value>) -> Vec<String> {
    let mut keys: Vec<String> = object.keys().cloned().collect();
    if let Some(w) = keys.iter().position(|k| k.eq_ignore_ascii_case("qw")) {
        let qw = keys.remove(w);
        keys.push(qw);
    }
    keys
}

/// Parses JSON text into a table; each element's origin is its 1-based index.
pub(crate) fn table_from_json(text: &str) -> Result<Table> {
    let value: Value = serde_json::from_str(text).map_err(|e| json_error(&e))?;
    let items =
        match &value {
            Value::Array(items) => items,
            Value::Object(o) => match o.get("poses") {
                Some(Value::Array(items)) => items,
                _ => return Err(Error::parse(
                    0,
                    0,
                    "a JSON pose file is an array of poses, or an object with a \"poses\" array",
                )),
            },
            _ => return Err(Error::parse(0, 0, "a JSON pose file is an array of poses")),
        };
    let mut header: Option<Vec<String>> = None;
    let mut rows = Vec::with_capacity(items.len());
    for (i, item) in items.iter().enumerate() {
        let origin = Origin::JsonElement(i + 1);
        let fields = match item {
            Value::Array(a) => {
                if header.is_some() {
                    return Err(origin.error(0, "mixes arrays and objects"));
                }
                array_fields(a, i + 1)?
            }
            Value::Object(o) => {
                if i > 0 && header.is_none() {
                    return Err(origin.error(0, "mixes arrays and objects"));
                }
                let keys = header.get_or_insert_with(|| ordered_keys(o));
                let mut fields = Vec::with_capacity(keys.len());
                for k in keys.iter() {
                    match o.get(k) {
                        Some(v) => fields.push(field_text(v)),
                        None => return Err(origin.error(0, format!("no field '{k}'"))),
                    }
                }
                fields
            }
            other => {
                return Err(origin.error(
                    0,
                    format!("expected an object or an array, found {}", kind(other)),
                ))
            }
        };
        rows.push(Row {
            origin,
            fields,
            field_lines: Vec::new(),
        });
    }
    Ok(Table {
        header: header.map(|h| (h, 0)),
        rows,
    })
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}
