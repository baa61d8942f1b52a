//! The keys a study section accepts, read from its serde types.
//!
//! [`probe`] lists every key of a section as dotted paths
//! (`scene.bodies.flexible.kind`) by running the section's `Deserialize`
//! implementation against a recording deserializer (`Rec`) instead of a
//! TOML document: a struct reports its field names (`deserialize_struct`'s
//! `FIELDS`) and the recorder then feeds every field a value of whatever
//! shape the field asks for, so nested tables and arrays of tables are
//! walked too. Only names are read, never types, so a `String` field that
//! becomes an enum keeps its key. Types that ask for "any" value
//! (`toml::Value`, internally tagged enums such as `[[scene.forces]]`) are
//! probed with small maps, and the error serde raises names what they
//! accept: the tag (`missing_field`), the variants (`unknown_variant`) and
//! each variant's fields (`unknown_field`, since the enum denies unknown
//! fields). A value that fails (a custom `Deserialize` refusing the
//! recorder's stand-in value) is left out on the next pass; the passes repeat
//! until nothing new is learnt.
//!
//! The section registry (`sections::registry::SECTIONS`) gives each
//! section's probe, so the list of accepted keys is generated from the one
//! list of sections (`sections::registry::accepted_keys`).

use serde::de::{self, DeserializeOwned, DeserializeSeed, IntoDeserializer, Visitor};
use std::cell::RefCell;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::fmt;

/// The keys learnt by [`probe`] over one or more sections.
#[derive(Default)]
pub struct KeyProbe(RefCell<Probe>);

impl KeyProbe {
    /// Every key path seen, and the top-level sections probed.
    pub fn into_keys(self) -> (BTreeSet<String>, BTreeSet<String>) {
        let p = self.0.into_inner();
        (p.keys, p.sections)
    }
}

/// Record the keys of one section: passes of `T::deserialize` until a pass
/// learns nothing new (bounded, so a bug here fails instead of hanging).
pub fn probe<T: DeserializeOwned>(keys: &KeyProbe, name: &str) {
    let p = &keys.0;
    p.borrow_mut().sections.insert(name.to_string());
    for _ in 0..10_000 {
        {
            let mut s = p.borrow_mut();
            s.changed = false;
            s.blame = None;
            s.pending = None;
        }
        let result = T::deserialize(Rec {
            path: name.to_string(),
            probe: p,
        });
        let mut s = p.borrow_mut();
        if let Err(err) = &result {
            s.absorb(err);
            if let Some(b) = s.blame.take().filter(|b| !b.is_empty()) {
                if s.skip.insert(b) {
                    s.changed = true;
                }
            }
        }
        if s.advance_enum() {
            s.changed = true;
        }
        if !s.changed {
            return;
        }
    }
    panic!("[{name}]: key probe did not settle");
}

/// What the passes have learnt, shared by the recorders of one run.
#[derive(Default)]
struct Probe {
    /// Top-level sections probed.
    sections: BTreeSet<String>,
    /// Every key path seen.
    keys: BTreeSet<String>,
    /// Paths not fed any more (their value failed in an earlier pass).
    skip: BTreeSet<String>,
    /// Probes still to try where a type asked for "any" value.
    any: BTreeMap<String, VecDeque<AnyProbe>>,
    /// Externally tagged enums: (variant fed now, number of variants).
    enums: BTreeMap<String, (usize, usize)>,
    /// Where the pass failed (empty: failed on purpose, in a probe).
    blame: Option<String>,
    /// A probe whose "any" value was taken as is: an internally tagged
    /// enum reads its variant from the buffered value after
    /// `deserialize_any` returns, so the error to read comes later.
    pending: Option<(String, Read)>,
    /// Did this pass learn anything?
    changed: bool,
}

impl Probe {
    fn key(&mut self, path: String) {
        if self.keys.insert(path) {
            self.changed = true;
        }
    }

    /// Learn from the error `err` that the probe `read` at `path` raised,
    /// queue the probes it calls for, and mark the pass as failed on
    /// purpose (nothing to skip).
    fn read(&mut self, path: &str, read: &Read, err: &PErr) {
        self.blame = Some(String::new());
        let mut learnt = Vec::new();
        let queue = self.any.entry(path.to_string()).or_default();
        match (read, err) {
            (Read::Tag, PErr::MissingField(tag)) => {
                learnt.push(format!("{path}.{tag}"));
                queue.push_back(AnyProbe::map(
                    vec![(tag.to_string(), PVal::Str(PROBE.into()))],
                    Read::Variants(tag.to_string()),
                ));
            }
            (Read::Tag, PErr::UnknownField(fields)) => {
                learnt.extend(fields.iter().map(|f| format!("{path}.{f}")));
            }
            (Read::Variants(tag), PErr::UnknownVariant(variants)) => {
                for variant in variants {
                    queue.push_back(AnyProbe::map(
                        vec![
                            (tag.clone(), PVal::Str(variant.to_string())),
                            (PROBE.into(), PVal::Unit),
                        ],
                        Read::Fields {
                            tag: tag.clone(),
                            variant: variant.to_string(),
                        },
                    ));
                }
            }
            (Read::Fields { tag, variant }, PErr::UnknownField(fields)) => {
                for f in fields.iter().filter(|f| **f != tag) {
                    learnt.push(format!("{path}.{f}"));
                    let nested = Read::Nested(format!("{path}.{f}"));
                    let tagged = |value: PVal| {
                        vec![
                            (tag.clone(), PVal::Str(variant.clone())),
                            (f.to_string(), value),
                        ]
                    };
                    // A table, or an array of tables, under the field.
                    queue.push_back(AnyProbe::map(tagged(AnyProbe::unknown()), nested.clone()));
                    queue.push_back(AnyProbe::map(
                        tagged(PVal::Seq(vec![AnyProbe::unknown()])),
                        nested,
                    ));
                }
            }
            (Read::Nested(prefix), PErr::UnknownField(fields)) => {
                learnt.extend(fields.iter().map(|f| format!("{prefix}.{f}")));
            }
            _ => {}
        }
        for k in learnt {
            self.key(k);
        }
    }

    /// An error that reached a field or the section: if a probe was taken
    /// as is before it, the error is that probe's answer.
    fn absorb(&mut self, err: &PErr) {
        if let Some((path, read)) = self.pending.take() {
            self.read(&path, &read, err);
        }
    }

    /// Feed the next variant of the first enum with variants left.
    fn advance_enum(&mut self) -> bool {
        for (chosen, count) in self.enums.values_mut() {
            if *chosen + 1 < *count {
                *chosen += 1;
                return true;
            }
        }
        false
    }
}

/// One probe of an "any" value, with how to read the error it raises.
#[derive(Clone)]
struct AnyProbe {
    value: PVal,
    read: Read,
}

#[derive(Clone)]
enum Read {
    /// Looking for an internal tag: `missing_field` names it.
    Tag,
    /// `unknown_variant` lists the variants of this tag.
    Variants(String),
    /// `unknown_field` lists the fields of this variant.
    Fields { tag: String, variant: String },
    /// `unknown_field` lists the fields of the table under this key path.
    Nested(String),
}

/// The unknown key the probes feed.
const PROBE: &str = "\u{0}probe";

impl AnyProbe {
    fn map(entries: Vec<(String, PVal)>, read: Read) -> AnyProbe {
        AnyProbe {
            value: PVal::Map(entries),
            read,
        }
    }
    fn unknown() -> PVal {
        PVal::Map(vec![(PROBE.to_string(), PVal::Unit)])
    }
}

/// The error of the recorder: what serde said, kept as data.
#[derive(Debug)]
enum PErr {
    UnknownField(Vec<&'static str>),
    UnknownVariant(Vec<&'static str>),
    MissingField(&'static str),
    Other(String),
}

impl fmt::Display for PErr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PErr::UnknownField(fields) => write!(f, "unknown field, expected one of {fields:?}"),
            PErr::UnknownVariant(variants) => {
                write!(f, "unknown variant, expected one of {variants:?}")
            }
            PErr::MissingField(field) => write!(f, "missing field `{field}`"),
            PErr::Other(msg) => f.write_str(msg),
        }
    }
}
impl std::error::Error for PErr {}
impl de::Error for PErr {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        PErr::Other(msg.to_string())
    }
    fn unknown_field(_: &str, expected: &'static [&'static str]) -> Self {
        PErr::UnknownField(expected.to_vec())
    }
    fn unknown_variant(_: &str, expected: &'static [&'static str]) -> Self {
        PErr::UnknownVariant(expected.to_vec())
    }
    fn missing_field(field: &'static str) -> Self {
        PErr::MissingField(field)
    }
}

/// A small document fed where a type asks for "any" value.
#[derive(Clone, Debug)]
enum PVal {
    Unit,
    Str(String),
    Seq(Vec<PVal>),
    Map(Vec<(String, PVal)>),
}

impl<'de> IntoDeserializer<'de, PErr> for PVal {
    type Deserializer = PVal;
    fn into_deserializer(self) -> PVal {
        self
    }
}

impl<'de> de::Deserializer<'de> for PVal {
    type Error = PErr;
    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        match self {
            PVal::Unit => v.visit_unit(),
            PVal::Str(s) => v.visit_string(s),
            PVal::Seq(items) => {
                let mut d = de::value::SeqDeserializer::new(items.into_iter());
                let out = v.visit_seq(&mut d)?;
                d.end()?;
                Ok(out)
            }
            PVal::Map(entries) => {
                let mut d = de::value::MapDeserializer::new(entries.into_iter());
                let out = v.visit_map(&mut d)?;
                d.end()?;
                Ok(out)
            }
        }
    }
    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

/// The recording deserializer at one key path.
struct Rec<'p> {
    path: String,
    probe: &'p RefCell<Probe>,
}

impl<'p> Rec<'p> {
    fn at(&self, path: String) -> Rec<'p> {
        Rec {
            path,
            probe: self.probe,
        }
    }

    /// A struct (or struct variant) at `self.path` with these fields.
    fn fields<'de, V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, PErr> {
        let mut s = self.probe.borrow_mut();
        let mut keys = Vec::new();
        for f in fields {
            let path = format!("{}.{f}", self.path);
            s.key(path.clone());
            if !s.skip.contains(&path) {
                keys.push((*f, path));
            }
        }
        drop(s);
        v.visit_map(Fields {
            keys: keys.into_iter(),
            next: None,
            probe: self.probe,
        })
    }

    /// A type that asks for any value: feed the next probe and read the
    /// error, or take it as a value of free form.
    fn any<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        let next = {
            let mut s = self.probe.borrow_mut();
            let queue = s.any.entry(self.path.clone()).or_insert_with(|| {
                VecDeque::from([AnyProbe::map(vec![(PROBE.into(), PVal::Unit)], Read::Tag)])
            });
            queue.pop_front()
        };
        let Some(probe) = next else {
            // Probed to the end: leave the key out from now on.
            let mut s = self.probe.borrow_mut();
            if s.skip.insert(self.path.clone()) {
                s.changed = true;
            }
            s.blame = Some(String::new());
            return Err(PErr::Other("probed".into()));
        };
        self.probe.borrow_mut().changed = true;
        let result = v.visit_map(de::value::MapDeserializer::new(
            match probe.value {
                PVal::Map(entries) => entries,
                other => vec![(PROBE.into(), other)],
            }
            .into_iter(),
        ));
        let Err(err) = result else {
            self.probe.borrow_mut().pending = Some((self.path, probe.read));
            return result;
        };
        self.probe.borrow_mut().read(&self.path, &probe.read, &err);
        Err(err)
    }
}

/// The map a struct is fed: each (not skipped) field once, its value
/// recorded at the field's path.
struct Fields<'p> {
    keys: std::vec::IntoIter<(&'static str, String)>,
    next: Option<String>,
    probe: &'p RefCell<Probe>,
}

impl<'de> de::MapAccess<'de> for Fields<'_> {
    type Error = PErr;
    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, PErr> {
        match self.keys.next() {
            None => Ok(None),
            Some((name, path)) => {
                self.next = Some(path);
                seed.deserialize(de::value::StrDeserializer::<PErr>::new(name))
                    .map(Some)
            }
        }
    }
    fn next_value_seed<S: DeserializeSeed<'de>>(&mut self, seed: S) -> Result<S::Value, PErr> {
        let path = self.next.take().expect("a key before its value");
        let rec = Rec {
            path: path.clone(),
            probe: self.probe,
        };
        let result = seed.deserialize(rec);
        let mut s = self.probe.borrow_mut();
        match &result {
            // The value took the probe: nothing to read.
            Ok(_) => s.pending = None,
            Err(err) => {
                s.absorb(err);
                if s.blame.is_none() {
                    s.blame = Some(path);
                }
            }
        }
        result
    }
}

/// An array fed to a sequence or a tuple: `len` elements at one path.
struct Elements<'p> {
    rec: Rec<'p>,
    left: usize,
}

impl<'de> de::SeqAccess<'de> for Elements<'_> {
    type Error = PErr;
    fn next_element_seed<S: DeserializeSeed<'de>>(
        &mut self,
        seed: S,
    ) -> Result<Option<S::Value>, PErr> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        let result = seed.deserialize(self.rec.at(self.rec.path.clone()));
        if result.is_ok() {
            self.rec.probe.borrow_mut().pending = None;
        }
        result.map(Some)
    }
}

/// An externally tagged enum: the variant chosen for this pass.
struct Variant<'p> {
    rec: Rec<'p>,
    name: &'static str,
}

impl<'de, 'p> de::EnumAccess<'de> for Variant<'p> {
    type Error = PErr;
    type Variant = Variant<'p>;
    fn variant_seed<S: DeserializeSeed<'de>>(self, seed: S) -> Result<(S::Value, Self), PErr> {
        let v = seed.deserialize(de::value::StrDeserializer::<PErr>::new(self.name))?;
        Ok((v, self))
    }
}

impl<'de> de::VariantAccess<'de> for Variant<'_> {
    type Error = PErr;
    fn unit_variant(self) -> Result<(), PErr> {
        Ok(())
    }
    fn newtype_variant_seed<S: DeserializeSeed<'de>>(self, seed: S) -> Result<S::Value, PErr> {
        let path = format!("{}.{}", self.rec.path, self.name);
        self.rec.probe.borrow_mut().key(path.clone());
        seed.deserialize(self.rec.at(path))
    }
    fn tuple_variant<V: Visitor<'de>>(self, len: usize, v: V) -> Result<V::Value, PErr> {
        let path = format!("{}.{}", self.rec.path, self.name);
        self.rec.probe.borrow_mut().key(path.clone());
        v.visit_seq(Elements {
            rec: self.rec.at(path),
            left: len,
        })
    }
    fn struct_variant<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, PErr> {
        let path = format!("{}.{}", self.rec.path, self.name);
        self.rec.probe.borrow_mut().key(path.clone());
        self.rec.at(path).fields(fields, v)
    }
}

impl<'de> de::Deserializer<'de> for Rec<'_> {
    type Error = PErr;
    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        self.any(v)
    }
    fn deserialize_bool<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_bool(false)
    }
    fn deserialize_i8<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_i64(1)
    }
    fn deserialize_i16<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_i64(1)
    }
    fn deserialize_i32<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_i64(1)
    }
    fn deserialize_i64<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_i64(1)
    }
    fn deserialize_u8<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_u64(1)
    }
    fn deserialize_u16<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_u64(1)
    }
    fn deserialize_u32<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_u64(1)
    }
    fn deserialize_u64<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_u64(1)
    }
    fn deserialize_f32<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_f64(1.0)
    }
    fn deserialize_f64<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_f64(1.0)
    }
    fn deserialize_char<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_char('a')
    }
    fn deserialize_str<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_str("")
    }
    fn deserialize_string<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_str("")
    }
    fn deserialize_bytes<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_bytes(&[])
    }
    fn deserialize_byte_buf<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_bytes(&[])
    }
    fn deserialize_option<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_some(self)
    }
    fn deserialize_unit<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_unit()
    }
    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, PErr> {
        v.visit_unit()
    }
    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, PErr> {
        v.visit_newtype_struct(self)
    }
    fn deserialize_seq<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_seq(Elements { rec: self, left: 1 })
    }
    fn deserialize_tuple<V: Visitor<'de>>(self, len: usize, v: V) -> Result<V::Value, PErr> {
        v.visit_seq(Elements {
            rec: self,
            left: len,
        })
    }
    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        len: usize,
        v: V,
    ) -> Result<V::Value, PErr> {
        self.deserialize_tuple(len, v)
    }
    /// A table of free keys (e.g. per panel name): a leaf of the reference.
    fn deserialize_map<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_map(de::value::MapDeserializer::new(std::iter::empty::<(
            String,
            PVal,
        )>()))
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, PErr> {
        self.fields(fields, v)
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _: &'static str,
        variants: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, PErr> {
        let chosen = {
            let mut s = self.probe.borrow_mut();
            s.enums
                .entry(self.path.clone())
                .or_insert((0, variants.len()))
                .0
        };
        match variants.get(chosen) {
            Some(&name) => v.visit_enum(Variant { rec: self, name }),
            None => Err(PErr::Other(format!("{}: no variants", self.path))),
        }
    }
    fn deserialize_identifier<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_str("")
    }
    fn deserialize_ignored_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, PErr> {
        v.visit_unit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Inner {
        a: f64,
        b: Option<Vec<String>>,
    }

    #[derive(Deserialize)]
    #[serde(tag = "type", deny_unknown_fields)]
    #[allow(dead_code)]
    enum Tagged {
        #[serde(rename = "one")]
        One { x: f64 },
        #[serde(rename = "two")]
        Two { y: Inner },
    }

    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Section {
        name: String,
        inner: Inner,
        items: Vec<Tagged>,
        free: BTreeMap<String, f64>,
    }

    #[test]
    fn probe_finds_nested_tagged_and_free_keys() {
        let p = KeyProbe::default();
        probe::<Section>(&p, "s");
        let (keys, sections) = p.into_keys();
        let want: BTreeSet<String> = [
            "s.name",
            "s.inner",
            "s.inner.a",
            "s.inner.b",
            "s.items",
            "s.items.type",
            "s.items.x",
            "s.items.y",
            "s.items.y.a",
            "s.items.y.b",
            "s.free",
        ]
        .map(String::from)
        .into();
        assert_eq!(keys, want);
        assert_eq!(sections, BTreeSet::from(["s".to_string()]));
    }
}
