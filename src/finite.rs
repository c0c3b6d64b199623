//! The report boundary's check that no number is NaN or infinite (issue
//! 35, item 4): serde_json writes a non-finite number as `null`, so a
//! report that held one would read as a missing value (`[null, null,
//! null]` for a pose). [`check_finite`] walks any `Serialize` value and
//! names the first non-finite field, e.g. `report.per_view[3].translation_mm`.

use crate::error::{Error, Result};
use serde::ser::{self, Serialize};
use std::fmt;

/// Err naming `what` + the path of the first NaN or infinite number in
/// `value`; Ok when every number is finite.
pub fn check_finite<T: Serialize + ?Sized>(what: &str, value: &T) -> Result<()> {
    let mut walker = Walker {
        path: what.to_string(),
    };
    match value.serialize(&mut walker) {
        Ok(()) => Ok(()),
        Err(Found::NonFinite(path, v)) => Err(Error::invalid(
            path,
            format!(
                "is {v}: a result must be finite numbers; the input holds a pose or point \
                 beyond what the solver can represent: check it for typos and units"
            ),
        )),
        // Values that do not serialise are the JSON writer's to report.
        Err(Found::Other(_)) => Ok(()),
    }
}

/// Why the walk stopped.
#[derive(Debug)]
enum Found {
    NonFinite(String, f64),
    Other(String),
}

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Found::NonFinite(path, v) => write!(f, "{path} is {v}"),
            Found::Other(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Found {}

impl ser::Error for Found {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Found::Other(msg.to_string())
    }
}

/// The path so far (`report.per_view[3]`); each compound appends and
/// truncates its own segments.
struct Walker {
    path: String,
}

impl Walker {
    fn number(&self, v: f64) -> std::result::Result<(), Found> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(Found::NonFinite(self.path.clone(), v))
        }
    }

    fn child<T: Serialize + ?Sized>(
        &mut self,
        segment: &str,
        value: &T,
    ) -> std::result::Result<(), Found> {
        let len = self.path.len();
        self.path.push_str(segment);
        let r = value.serialize(&mut *self);
        self.path.truncate(len);
        r
    }
}

/// A sequence's walker: the index of the next element.
struct Seq<'a> {
    walker: &'a mut Walker,
    index: usize,
}

impl Seq<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> std::result::Result<(), Found> {
        let segment = format!("[{}]", self.index);
        self.index += 1;
        self.walker.child(&segment, value)
    }
}

/// A map's walker: the segment of the last key.
struct Map<'a> {
    walker: &'a mut Walker,
    key: String,
}

macro_rules! ok_primitives {
    ($($name:ident: $t:ty),*) => {
        $(fn $name(self, _v: $t) -> std::result::Result<(), Found> { Ok(()) })*
    };
}

impl<'a> ser::Serializer for &'a mut Walker {
    type Ok = ();
    type Error = Found;
    type SerializeSeq = Seq<'a>;
    type SerializeTuple = Seq<'a>;
    type SerializeTupleStruct = Seq<'a>;
    type SerializeTupleVariant = Seq<'a>;
    type SerializeMap = Map<'a>;
    type SerializeStruct = Map<'a>;
    type SerializeStructVariant = Map<'a>;

    ok_primitives!(serialize_bool: bool, serialize_i8: i8, serialize_i16: i16,
        serialize_i32: i32, serialize_i64: i64, serialize_u8: u8, serialize_u16: u16,
        serialize_u32: u32, serialize_u64: u64, serialize_char: char,
        serialize_str: &str, serialize_bytes: &[u8]);

    fn serialize_f32(self, v: f32) -> std::result::Result<(), Found> {
        self.number(v as f64)
    }
    fn serialize_f64(self, v: f64) -> std::result::Result<(), Found> {
        self.number(v)
    }
    fn serialize_none(self) -> std::result::Result<(), Found> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> std::result::Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> std::result::Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> std::result::Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
    ) -> std::result::Result<(), Found> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> std::result::Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> std::result::Result<(), Found> {
        self.child(&format!(".{variant}"), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> std::result::Result<Seq<'a>, Found> {
        Ok(Seq {
            walker: self,
            index: 0,
        })
    }
    fn serialize_tuple(self, _: usize) -> std::result::Result<Seq<'a>, Found> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Seq<'a>, Found> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Seq<'a>, Found> {
        self.serialize_seq(None)
    }
    fn serialize_map(self, _: Option<usize>) -> std::result::Result<Map<'a>, Found> {
        Ok(Map {
            walker: self,
            key: String::new(),
        })
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> std::result::Result<Map<'a>, Found> {
        self.serialize_map(None)
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> std::result::Result<Map<'a>, Found> {
        self.serialize_map(None)
    }
}

macro_rules! seq_impl {
    ($($trait:ident :: $method:ident),*) => {
        $(impl ser::$trait for Seq<'_> {
            type Ok = ();
            type Error = Found;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> std::result::Result<(), Found> {
                self.element(value)
            }
            fn end(self) -> std::result::Result<(), Found> {
                Ok(())
            }
        })*
    };
}

seq_impl!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

impl ser::SerializeMap for Map<'_> {
    type Ok = ();
    type Error = Found;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> std::result::Result<(), Found> {
        self.key = match serde_json::to_value(key) {
            Ok(serde_json::Value::String(s)) => format!(".{s}"),
            Ok(other) => format!("[{other}]"),
            Err(_) => "[?]".to_string(),
        };
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(
        &mut self,
        value: &T,
    ) -> std::result::Result<(), Found> {
        let key = std::mem::take(&mut self.key);
        self.walker.child(&key, value)
    }
    fn end(self) -> std::result::Result<(), Found> {
        Ok(())
    }
}

macro_rules! struct_impl {
    ($($trait:ident),*) => {
        $(impl ser::$trait for Map<'_> {
            type Ok = ();
            type Error = Found;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> std::result::Result<(), Found> {
                self.walker.child(&format!(".{key}"), value)
            }
            fn end(self) -> std::result::Result<(), Found> {
                Ok(())
            }
        })*
    };
}

struct_impl!(SerializeStruct, SerializeStructVariant);

#[cfg(test)]
mod tests {
    use super::check_finite;
    use serde::Serialize;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Inner {
        translation_m: [f64; 3],
    }

    #[derive(Serialize)]
    struct Outer {
        name: String,
        poses: Vec<Inner>,
        std: BTreeMap<String, f64>,
        maybe: Option<f64>,
    }

    #[test]
    fn the_first_non_finite_number_is_named_by_its_path() {
        let mut value = Outer {
            name: "x".into(),
            poses: vec![
                Inner {
                    translation_m: [0.0, 1.0, 2.0],
                },
                Inner {
                    translation_m: [0.0, 1.0, 2.0],
                },
            ],
            std: BTreeMap::from([("fx".to_string(), 1.0)]),
            maybe: None,
        };
        assert_eq!(check_finite("report", &value), Ok(()));
        value.poses[1].translation_m[2] = f64::INFINITY;
        assert_eq!(
            check_finite("report", &value).unwrap_err().to_string(),
            "report.poses[1].translation_m[2]: is inf: a result must be finite numbers; the \
             input holds a pose or point beyond what the solver can represent: check it for \
             typos and units"
        );
        value.poses[1].translation_m[2] = 0.0;
        value.std.insert("fy".into(), f64::NAN);
        let e = check_finite("report", &value).unwrap_err().to_string();
        assert!(e.starts_with("report.std.fy: is NaN"), "{e}");
        value.std.insert("fy".into(), 0.0);
        value.maybe = Some(f64::NEG_INFINITY);
        let e = check_finite("report", &value).unwrap_err().to_string();
        assert!(e.starts_with("report.maybe: is -inf"), "{e}");
    }
}
