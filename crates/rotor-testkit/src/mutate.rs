//! Edits of fixture files for the fuzz tests of the parameter reader (rotor-model) and the
//! scenario reader (rotor_model::scenario): deleted, duplicated and swapped lines, swapped values,
//! random TOML values, random bytes, truncation.

use proptest::prelude::*;

/// TOML values of every type, and the numbers that break naive range checks.
pub fn toml_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("+inf".to_string()),
        Just("-inf".to_string()),
        Just("-0.0".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("-1e308".to_string()),
        Just("1e-320".to_string()),
        Just("1e999".to_string()),
        Just("true".to_string()),
        Just("\"\"".to_string()),
        Just("\"stribeck\"".to_string()),
        Just("'../params/table1.toml'".to_string()),
        Just("[]".to_string()),
        Just("[1.0, 2.0]".to_string()),
        Just("[0.0, 0.0, 0.0, 0.0]".to_string()),
        Just("{ a = 1 }".to_string()),
        Just("1979-05-27T07:32:00Z".to_string()),
        Just("\"\"\"two\nlines\"\"\"".to_string()),
        Just("0x10".to_string()),
        any::<i64>().prop_map(|v| v.to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        (-1e3..1e3f64).prop_map(|v| format!("{v}")),
        "[a-z_]{0,8}".prop_map(|s| format!("\"{s}\"")),
    ]
}

/// One edit of a file's lines or bytes.
#[derive(Debug, Clone)]
pub enum Mutation {
    /// Delete the line at this index (modulo the line count).
    DeleteLine(usize),
    /// Insert a copy of the line at this index before it.
    DuplicateLine(usize),
    /// Swap two lines.
    SwapLines(usize, usize),
    /// Swap the values of two `key = value` lines.
    SwapValues(usize, usize),
    /// Replace the value of a `key = value` line.
    SetValue(usize, String),
    /// Insert a `key = value` line with a random key.
    InsertKey(usize, String, String),
    /// Insert these bytes at this byte offset (modulo the length + 1).
    InsertBytes(usize, Vec<u8>),
    /// Keep only the bytes before this offset (modulo the length + 1).
    Truncate(usize),
}

/// Any [`Mutation`], uniformly over its kinds, with indices below 2¹⁶ that [`apply`] wraps
/// to the file.
pub fn mutation() -> impl Strategy<Value = Mutation> {
    let i = || any::<prop::sample::Index>();
    prop_oneof![
        i().prop_map(|i| Mutation::DeleteLine(i.index(1 << 16))),
        i().prop_map(|i| Mutation::DuplicateLine(i.index(1 << 16))),
        (i(), i()).prop_map(|(a, b)| Mutation::SwapLines(a.index(1 << 16), b.index(1 << 16))),
        (i(), i()).prop_map(|(a, b)| Mutation::SwapValues(a.index(1 << 16), b.index(1 << 16))),
        (i(), toml_value()).prop_map(|(a, v)| Mutation::SetValue(a.index(1 << 16), v)),
        (i(), "[a-z_]{1,8}", toml_value()).prop_map(|(a, k, v)| Mutation::InsertKey(
            a.index(1 << 16),
            k,
            v
        )),
        (i(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(a, b)| Mutation::InsertBytes(a.index(1 << 16), b)),
        i().prop_map(|i| Mutation::Truncate(i.index(1 << 16))),
    ]
}

/// Splits `key = value # comment` into (key part, value); `None` for other lines.
fn split_kv(line: &str) -> Option<(&str, &str)> {
    let (k, rest) = line.split_once('=')?;
    let v = rest.split('#').next().unwrap_or(rest).trim();
    Some((k, v))
}

/// `bytes` with the edit `m` made (an index past the end wraps around).
pub fn apply(bytes: Vec<u8>, m: &Mutation) -> Vec<u8> {
    if let Mutation::InsertBytes(at, b) = m {
        let at = at % (bytes.len() + 1);
        let mut out = bytes[..at].to_vec();
        out.extend_from_slice(b);
        out.extend_from_slice(&bytes[at..]);
        return out;
    }
    if let Mutation::Truncate(at) = m {
        return bytes[..at % (bytes.len() + 1)].to_vec();
    }
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    if lines.is_empty() {
        return bytes;
    }
    let n = lines.len();
    // Indices of `key = value` lines, for the value mutations.
    let kv: Vec<usize> = (0..n).filter(|&i| split_kv(&lines[i]).is_some()).collect();
    match m {
        Mutation::DeleteLine(i) => {
            lines.remove(i % n);
        }
        Mutation::DuplicateLine(i) => {
            let l = lines[i % n].clone();
            lines.insert(i % n, l);
        }
        Mutation::SwapLines(a, b) => lines.swap(a % n, b % n),
        Mutation::SwapValues(a, b) if !kv.is_empty() => {
            let (a, b) = (kv[a % kv.len()], kv[b % kv.len()]);
            let (ka, va) = split_kv(&lines[a])
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .unwrap();
            let (kb, vb) = split_kv(&lines[b])
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .unwrap();
            lines[a] = format!("{ka}= {vb}");
            lines[b] = format!("{kb}= {va}");
        }
        Mutation::SetValue(a, v) if !kv.is_empty() => {
            let a = kv[a % kv.len()];
            let k = split_kv(&lines[a]).unwrap().0.to_owned();
            lines[a] = format!("{k}= {v}");
        }
        Mutation::InsertKey(a, k, v) => lines.insert(a % (n + 1), format!("{k} = {v}")),
        _ => {}
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out.into_bytes()
}
