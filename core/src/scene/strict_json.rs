//! JSON parsed with every object's keys given once: `serde_json::Value` keeps the last of two
//! `"meshes"` silently, so a scene whose first list of meshes is lost would load as if nothing
//! were wrong. A first pass over the text finds a repeated key and names it with its line.

use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use std::collections::HashSet;
use std::fmt;

/// Nothing but the check: every object's keys distinct, at every depth.
struct Distinct;

impl<'de> Deserialize<'de> for Distinct {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(DistinctVisitor)
    }
}

struct DistinctVisitor;

impl<'de> Visitor<'de> for DistinctVisitor {
    type Value = Distinct;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<Distinct, E> {
        Ok(Distinct)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Distinct, E> {
        Ok(Distinct)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Distinct, E> {
        Ok(Distinct)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Distinct, E> {
        Ok(Distinct)
    }
    fn visit_str<E>(self, _: &str) -> Result<Distinct, E> {
        Ok(Distinct)
    }
    fn visit_unit<E>(self) -> Result<Distinct, E> {
        Ok(Distinct)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Distinct, A::Error> {
        while seq.next_element::<Distinct>()?.is_some() {}
        Ok(Distinct)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Distinct, A::Error> {
        let mut keys = HashSet::new();
        while let Some(k) = map.next_key::<String>()? {
            if !keys.insert(k.clone()) {
                return Err(serde::de::Error::custom(format!("the key \"{k}\" is given twice in one object")));
            }
            map.next_value::<Distinct>()?;
        }
        Ok(Distinct)
    }
}

/// `text` as JSON, refused when an object repeats a key (the error names the key and the line).
pub fn parse(text: &str) -> Result<serde_json::Value, serde_json::Error> {
    serde_json::from_str::<Distinct>(text)?;
    serde_json::from_str(text)
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_repeated_key_is_refused_at_any_depth_with_its_line() {
        assert!(super::parse(r#"{"a": [{"b": 1, "c": 2}], "d": {"e": null}}"#).is_ok());
        let e = super::parse("{\"meshes\": [],\n \"meshes\": [1]}").unwrap_err();
        assert!(e.to_string().contains("\"meshes\" is given twice"), "{e}");
        assert_eq!(e.line(), 2);
        assert!(super::parse(r#"{"a": [{"b": 1, "b": 2}]}"#).is_err());
    }
}
