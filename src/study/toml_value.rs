//! Parsed TOML values of a study file as data: the value at a dotted path
//! ([`lookup`], [`insert`], [`remove`]) and a canonical hash.
//!
//! The hash is canonical: a value is encoded as tagged bytes ([`encode`]:
//! tables with their keys sorted and their lengths, arrays and strings
//! with their lengths, numbers as the bits of their `f64`, an integer that
//! a float represents exactly as that float), so comments, key order,
//! whitespace and the spelling of a number (`1e-6` or `0.000001`, `2000` or
//! `2000.0`) do not change it; any value does. [`hex`] is the 64-bit FNV-1a
//! of those bytes ([`fnv1a`]) as 16 hex digits: it detects accidental
//! change, it is no cryptographic seal.

/// The value at a dotted path (`None`: absent).
pub fn lookup<'t>(table: &'t toml::Table, path: &str) -> Option<&'t toml::Value> {
    let mut parts = path.split('.');
    let mut at = table.get(parts.next()?)?;
    for p in parts {
        at = at.as_table()?.get(p)?;
    }
    Some(at)
}

/// Put `v` at the dotted `path` of `t`, creating the tables above it.
pub fn insert(t: &mut toml::Table, path: &str, v: toml::Value) {
    match path.split_once('.') {
        None => {
            t.insert(path.to_string(), v);
        }
        Some((head, rest)) => {
            let sub = t
                .entry(head.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if let toml::Value::Table(sub) = sub {
                insert(sub, rest, v);
            }
        }
    }
}

/// Remove the dotted `path` from `t` (absent: nothing).
pub fn remove(t: &mut toml::Table, path: &str) {
    match path.split_once('.') {
        None => {
            t.remove(path);
        }
        Some((head, rest)) => {
            if let Some(toml::Value::Table(sub)) = t.get_mut(head) {
                remove(sub, rest);
            }
        }
    }
}

/// The canonical bytes of a TOML value (see the module doc).
pub fn encode(v: &toml::Value, out: &mut Vec<u8>) {
    let len = |out: &mut Vec<u8>, n: usize| out.extend((n as u64).to_le_bytes());
    match v {
        toml::Value::Table(t) => {
            out.push(b'T');
            len(out, t.len());
            let mut keys: Vec<&String> = t.keys().collect();
            keys.sort();
            for k in keys {
                len(out, k.len());
                out.extend(k.as_bytes());
                encode(&t[k.as_str()], out);
            }
        }
        toml::Value::Array(a) => {
            out.push(b'A');
            len(out, a.len());
            for x in a {
                encode(x, out);
            }
        }
        toml::Value::String(s) => {
            out.push(b'S');
            len(out, s.len());
            out.extend(s.as_bytes());
        }
        // An integer that a float represents exactly is that float:
        // `2000` and `2000.0` are one value.
        toml::Value::Integer(i) if i.unsigned_abs() <= 1 << 53 => {
            out.push(b'F');
            out.extend((*i as f64).to_bits().to_le_bytes());
        }
        toml::Value::Integer(i) => {
            out.push(b'I');
            out.extend(i.to_le_bytes());
        }
        toml::Value::Float(x) => {
            out.push(b'F');
            let x = if x.is_nan() { f64::NAN } else { *x };
            out.extend(x.to_bits().to_le_bytes());
        }
        toml::Value::Boolean(b) => out.extend([b'B', u8::from(*b)]),
        toml::Value::Datetime(d) => {
            let s = d.to_string();
            out.push(b'D');
            len(out, s.len());
            out.extend(s.as_bytes());
        }
    }
}

/// 64-bit FNV-1a (Fowler, Noll, Vo; offset basis 0xcbf29ce484222325,
/// prime 0x100000001b3).
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The hash of a part's view, as 16 hex digits.
pub fn hex(t: &toml::Table) -> String {
    let mut bytes = Vec::new();
    encode(&toml::Value::Table(t.clone()), &mut bytes);
    format!("{:016x}", fnv1a(&bytes))
}

/// Equal as the fingerprint sees them.
pub fn same(a: &toml::Value, b: &toml::Value) -> bool {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    encode(a, &mut x);
    encode(b, &mut y);
    x == y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_known_values_and_a_canonical_encoding() {
        // FNV-1a 64 of the empty input is its offset basis; of "a", the
        // published test vector.
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        let a: toml::Table = toml::from_str(
            "x = 2000
y = [1e-6]",
        )
        .unwrap();
        let b: toml::Table = toml::from_str(
            "y = [0.000001]
x = 2000.0",
        )
        .unwrap();
        assert_eq!(hex(&a), hex(&b));
        let mut c = a.clone();
        insert(&mut c, "z.w", toml::Value::Boolean(true));
        assert_eq!(lookup(&c, "z.w"), Some(&toml::Value::Boolean(true)));
        assert_ne!(hex(&c), hex(&a));
        remove(&mut c, "z.w");
        assert!(lookup(&c, "z.w").is_none() && same(&c["x"], &b["x"]));
    }
}
