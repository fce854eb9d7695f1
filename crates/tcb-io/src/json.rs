//! Pieces of the JSON reader that the clip and its skeleton share.

use serde::de::{self, Deserialize, IgnoredAny};

/// `extras`: whatever the user keeps there, not kept by the reader but
/// walked, so that it is nested no deeper than the JSON reader's limit
/// (128 levels) like the rest of the file.
pub(crate) struct Extras;

impl<'de> Deserialize<'de> for Extras {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> de::Visitor<'de> for V {
            type Value = Extras;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("any JSON value")
            }
            fn visit_bool<E>(self, _: bool) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_i64<E>(self, _: i64) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_u64<E>(self, _: u64) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_f64<E>(self, _: f64) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_str<E>(self, _: &str) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_unit<E>(self) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_none<E>(self) -> Result<Extras, E> {
                Ok(Extras)
            }
            fn visit_some<D: de::Deserializer<'de>>(self, d: D) -> Result<Extras, D::Error> {
                Extras::deserialize(d)
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut a: A) -> Result<Extras, A::Error> {
                while a.next_element::<Extras>()?.is_some() {}
                Ok(Extras)
            }
            fn visit_map<A: de::MapAccess<'de>>(self, mut a: A) -> Result<Extras, A::Error> {
                while a.next_entry::<IgnoredAny, Extras>()?.is_some() {}
                Ok(Extras)
            }
        }
        d.deserialize_any(V)
    }
}

/// An f64 as read that must fit an f32 (finite after rounding).
pub(crate) fn finite_f32(x: f64, what: &str) -> Result<f32, String> {
    let y = x as f32;
    if y.is_finite() {
        Ok(y)
    } else {
        // serde_json's shortest form (`1e300`, not 301 digits).
        let text = serde_json::Number::from_f64(x).map_or(x.to_string(), |n| n.to_string());
        Err(format!("{what} {text} is not a finite f32"))
    }
}
