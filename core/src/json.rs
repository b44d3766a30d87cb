//! JSON as every file bvhscope reads takes it (scene files, rubrics, BVH dumps): strict, with
//! every object's keys given once, and read field by field with errors that name the field.
//!
//! `serde_json::Value` keeps the last of two `"meshes"` silently, so a scene whose first list of
//! meshes is lost would load as if nothing were wrong: `check` goes over the text first, finds a
//! repeated key at any depth and names it with its line, keeping nothing (a dump of 20 MB is
//! never made a tree of maps to be checked). `Fields` reads a `Value`'s members as numbers,
//! vectors, sizes, names and lists, each error naming the file and the field
//! (`camera.transform.position`) in the reader's own error type.

use glam::Vec3;
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::{Map, Value};
use std::collections::HashSet;
use std::fmt;
use std::path::Path;

/// What a JSON value is, as errors name it ("expected an object, found an array").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Null,
    Bool,
    Number,
    String,
    Array,
    Object,
}

impl Kind {
    pub fn of(v: &Value) -> Kind {
        match v {
            Value::Null => Kind::Null,
            Value::Bool(_) => Kind::Bool,
            Value::Number(_) => Kind::Number,
            Value::String(_) => Kind::String,
            Value::Array(_) => Kind::Array,
            Value::Object(_) => Kind::Object,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Kind::Null => "null",
            Kind::Bool => "a boolean",
            Kind::Number => "a number",
            Kind::String => "a string",
            Kind::Array => "an array",
            Kind::Object => "an object",
        }
    }
}

/// `v`'s kind in words ("an array").
pub fn kind(v: &Value) -> &'static str {
    Kind::of(v).name()
}

/// A value in an error: a number as written, anything else by its kind.
pub fn shown(v: &Value) -> String {
    match v {
        Value::Number(n) => n.to_string(),
        other => kind(other).to_string(),
    }
}

/// `parent.key`, or `key` at the top level.
pub fn join(parent: &str, key: &str) -> String {
    if parent.is_empty() {
        key.to_string()
    } else {
        format!("{parent}.{key}")
    }
}

/// Whether `text` is JSON whose objects each give their keys once, at every depth, and if so
/// the kind of its top value; nothing of it is kept. A repeated key is an error naming the key
/// and its line (`Error::is_data`; broken JSON is `is_syntax` or `is_eof`).
pub fn check(text: &str) -> Result<Kind, serde_json::Error> {
    serde_json::from_str::<Distinct>(text).map(|d| d.0)
}

/// `text` as JSON, refused when an object repeats a key (the error names the key and the line).
pub fn parse(text: &str) -> Result<Value, serde_json::Error> {
    check(text)?;
    serde_json::from_str(text)
}

/// The check alone: every object's keys distinct, at every depth; the top value's kind.
struct Distinct(Kind);

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
        Ok(Distinct(Kind::Bool))
    }
    fn visit_i64<E>(self, _: i64) -> Result<Distinct, E> {
        Ok(Distinct(Kind::Number))
    }
    fn visit_u64<E>(self, _: u64) -> Result<Distinct, E> {
        Ok(Distinct(Kind::Number))
    }
    fn visit_f64<E>(self, _: f64) -> Result<Distinct, E> {
        Ok(Distinct(Kind::Number))
    }
    fn visit_str<E>(self, _: &str) -> Result<Distinct, E> {
        Ok(Distinct(Kind::String))
    }
    fn visit_unit<E>(self) -> Result<Distinct, E> {
        Ok(Distinct(Kind::Null))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Distinct, A::Error> {
        while seq.next_element::<Distinct>()?.is_some() {}
        Ok(Distinct(Kind::Array))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Distinct, A::Error> {
        let mut keys = HashSet::new();
        while let Some(k) = map.next_key::<String>()? {
            if !keys.insert(k.clone()) {
                return Err(serde::de::Error::custom(format!("the key \"{k}\" is given twice in one object")));
            }
            map.next_value::<Distinct>()?;
        }
        Ok(Distinct(Kind::Object))
    }
}

/// Typed reading of a file's JSON values; every error names the file and the field, made by the
/// reader's own constructor (`make(path, field, message)`).
pub struct Fields<'a, E> {
    pub path: &'a Path,
    make: fn(&Path, &str, String) -> E,
}

impl<'a, E> Fields<'a, E> {
    pub fn new(path: &'a Path, make: fn(&Path, &str, String) -> E) -> Self {
        Fields { path, make }
    }

    pub fn err(&self, field: &str, message: impl Into<String>) -> E {
        (self.make)(self.path, field, message.into())
    }

    /// `v` as an object (`field` names it).
    pub fn object<'v>(&self, v: &'v Value, field: &str) -> Result<&'v Map<String, Value>, E> {
        v.as_object().ok_or_else(|| self.err(field, format!("expected an object, found {}", kind(v))))
    }

    /// `v` as an array.
    pub fn array<'v>(&self, v: &'v Value, field: &str) -> Result<&'v Vec<Value>, E> {
        v.as_array().ok_or_else(|| self.err(field, format!("expected an array, found {}", kind(v))))
    }

    /// A required member of an object.
    pub fn get<'v>(&self, v: &'v Value, parent: &str, key: &str) -> Result<&'v Value, E> {
        self.object(v, parent)?.get(key).ok_or_else(|| self.err(&join(parent, key), "missing"))
    }

    /// Every key of `o` one of `keys`; an unknown one is named with those accepted.
    pub fn known(&self, o: &Map<String, Value>, parent: &str, keys: &[&str]) -> Result<(), E> {
        match o.keys().find(|k| !keys.contains(&k.as_str())) {
            None => Ok(()),
            Some(k) => Err(self.err(&join(parent, k), format!("unknown field (expected {})", keys.join(", ")))),
        }
    }

    pub fn text(&self, v: &Value, field: &str) -> Result<String, E> {
        v.as_str().map(str::to_string).ok_or_else(|| self.err(field, format!("expected a string, found {}", kind(v))))
    }

    /// Any finite number.
    pub fn number(&self, v: &Value, field: &str) -> Result<f32, E> {
        match v.as_f64() {
            Some(x) if (x as f32).is_finite() => Ok(x as f32),
            _ => Err(self.err(field, format!("expected a number, found {}", shown(v)))),
        }
    }

    /// A number from `lo` to `hi`.
    pub fn number_in(&self, v: &Value, field: &str, lo: f64, hi: f64) -> Result<f64, E> {
        match v.as_f64() {
            Some(x) if (lo..=hi).contains(&x) => Ok(x),
            _ => Err(self.err(field, format!("expected a number from {lo} to {hi}, found {}", shown(v)))),
        }
    }

    /// A whole number from `lo` to `hi`.
    pub fn whole(&self, v: &Value, field: &str, lo: u64, hi: u64) -> Result<u64, E> {
        match v.as_u64() {
            Some(x) if (lo..=hi).contains(&x) => Ok(x),
            _ => Err(self.err(field, format!("expected a whole number from {lo} to {hi}, found {}", shown(v)))),
        }
    }

    /// `[x, y, z]`, each a finite number (a bad one is named by its index: `field[1]`).
    pub fn vec3(&self, v: &Value, field: &str) -> Result<Vec3, E> {
        match v.as_array() {
            Some(a) if a.len() == 3 => {
                let c: Result<Vec<f32>, E> =
                    a.iter().enumerate().map(|(i, x)| self.number(x, &format!("{field}[{i}]"))).collect();
                let c = c?;
                Ok(Vec3::new(c[0], c[1], c[2]))
            }
            _ => Err(self.err(field, format!("expected [x, y, z], found {}", kind(v)))),
        }
    }

    /// An image size `[width, height]`, whole numbers 1..=16384.
    pub fn size(&self, v: &Value, field: &str) -> Result<(u32, u32), E> {
        let dims: Option<Vec<u64>> = v.as_array().and_then(|a| a.iter().map(|x| x.as_u64()).collect());
        match dims.as_deref() {
            Some(&[w, h]) if (1..=16384).contains(&w) && (1..=16384).contains(&h) => Ok((w as u32, h as u32)),
            _ => Err(self.err(field, "expected [width, height], whole numbers 1..=16384")),
        }
    }

    /// A list of names, each read by `from`, none twice; an unknown one is named with what is
    /// accepted.
    pub fn list<T: PartialEq>(
        &self,
        v: &Value,
        field: &str,
        from: impl Fn(&str) -> Option<T>,
        accepted: &str,
    ) -> Result<Vec<T>, E> {
        let items = v.as_array().ok_or_else(|| self.err(field, format!("expected a list, found {}", kind(v))))?;
        let mut out = Vec::new();
        for (i, item) in items.iter().enumerate() {
            let at = format!("{field}[{i}]");
            let name = item.as_str().ok_or_else(|| self.err(&at, format!("expected a name, found {}", kind(item))))?;
            let value = from(name).ok_or_else(|| self.err(&at, format!("\"{name}\" is not one of {accepted}")))?;
            if out.contains(&value) {
                return Err(self.err(&at, format!("\"{name}\" is given twice")));
            }
            out.push(value);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_repeated_key_is_refused_at_any_depth_with_its_line() {
        assert!(parse(r#"{"a": [{"b": 1, "c": 2}], "d": {"e": null}}"#).is_ok());
        let e = parse("{\"meshes\": [],\n \"meshes\": [1]}").unwrap_err();
        assert!(e.to_string().contains("\"meshes\" is given twice"), "{e}");
        assert!(e.is_data());
        assert_eq!(e.line(), 2);
        assert!(parse(r#"{"a": [{"b": 1, "b": 2}]}"#).is_err());
    }

    #[test]
    fn the_check_names_the_top_kind_and_tells_broken_json_from_a_repeated_key() {
        assert_eq!(check("[1, {\"a\": 2}]").unwrap(), Kind::Array);
        assert_eq!(check(" null").unwrap(), Kind::Null);
        assert_eq!(check("{}").unwrap(), Kind::Object);
        assert!(check("{\"a\": ").unwrap_err().is_eof());
        assert!(check("{\"a\" 1}").unwrap_err().is_syntax());
    }
}
