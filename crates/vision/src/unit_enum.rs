//! Unit-variant enums read from their JSON names through one visitor.
//!
//! serde's derived `Deserialize` for an enum instantiates the deserializer's
//! whole enum machinery (variant access, identifier visitor) per enum: about
//! 2 KB of wasm each. [`deserialize_by_name!`](crate::deserialize_by_name)
//! reads the name as a string instead, with the same "unknown variant"
//! message as the derived code.

use serde::de::{Deserializer, Error, Visitor};
use std::fmt;

/// The index in `names` of the string `d` holds; `what` names the type in
/// "invalid type" errors (as serde's derive does: "enum Setup").
pub fn variant_index<'de, D: Deserializer<'de>>(
    d: D,
    names: &'static [&'static str],
    what: &'static str,
) -> Result<usize, D::Error> {
    struct Names(&'static [&'static str], &'static str);
    impl Visitor<'_> for Names {
        type Value = usize;
        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str(self.1)
        }
        fn visit_str<E: Error>(self, v: &str) -> Result<usize, E> {
            self.0
                .iter()
                .position(|n| *n == v)
                .ok_or_else(|| E::unknown_variant(v, self.0))
        }
    }
    d.deserialize_str(Names(names, what))
}

/// `impl Deserialize` for a unit-variant enum from `Variant => "name"`
/// pairs (the names serde's derive would use).
#[macro_export]
#[doc(hidden)]
macro_rules! deserialize_by_name {
    ($ty:ident { $($variant:ident => $name:literal),+ $(,)? }) => {
        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> ::core::result::Result<Self, D::Error> {
                const NAMES: &[&str] = &[$($name),+];
                const ALL: &[$ty] = &[$($ty::$variant),+];
                let what = concat!("enum ", stringify!($ty));
                Ok(ALL[$crate::unit_enum::variant_index(d, NAMES, what)?])
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use wasm_bindgen_test::wasm_bindgen_test;

    #[derive(Debug, PartialEq, Clone, Copy, serde::Deserialize)]
    #[serde(rename_all = "kebab-case")]
    enum Derived {
        EyeInHand,
        EyeToHand,
    }

    #[derive(Debug, PartialEq, Clone, Copy)]
    enum ByName {
        EyeInHand,
        EyeToHand,
    }
    crate::deserialize_by_name!(ByName { EyeInHand => "eye-in-hand", EyeToHand => "eye-to-hand" });

    #[wasm_bindgen_test(unsupported = test)]
    fn same_values_and_messages_as_the_derive() {
        let ours: Vec<ByName> = serde_json::from_str(r#"["eye-to-hand", "eye-in-hand"]"#).unwrap();
        assert_eq!(ours, [ByName::EyeToHand, ByName::EyeInHand]);
        for bad in [r#""eye-on-hand""#, r#"  "EyeInHand""#] {
            let theirs = serde_json::from_str::<Derived>(bad)
                .unwrap_err()
                .to_string();
            let ours = serde_json::from_str::<ByName>(bad).unwrap_err().to_string();
            assert_eq!(ours, theirs.replace("Derived", "ByName"));
        }
        let ours = serde_json::from_str::<ByName>("5").unwrap_err().to_string();
        assert_eq!(
            ours,
            "invalid type: integer `5`, expected enum ByName at line 1 column 1"
        );
    }
}
