//! Random mutations of bytes, text, JSON/TOML documents, arguments, safetensors and PNG files.

use base64::Engine;
use rand::seq::IndexedRandom;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

pub(crate) const INTERESTING_BYTES: [u8; 4] = [0x00, 0xff, 0x7f, 0x80];
pub(crate) const INTERESTING_INTS: [u64; 12] = [
    0,
    1,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_fff0,
    0xffff_ffff,
    1 << 32,
    0xffff,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    0xffff_ffff_ffff_fff0,
    u64::MAX,
];
pub(crate) const INTERESTING_NUMBERS: [&str; 10] =
    ["1e308", "-1", "0", "NaN", "1e11", "1e-308", "inf", "18446744073709551615", "4294967296", "-0"];
pub(crate) const CONTROL_CHARS: [&[u8]; 10] = [
    b"\0",
    b"\x1b[2J",
    b"\r",
    b"\x7f",
    b"\x08",
    b"\x0c",
    "\u{feff}".as_bytes(),
    "\u{2028}".as_bytes(),
    b"\xff\xfe",
    b"\xc3",
];

/// One to four stacked mutations (mostly one, so that most mutants are near-valid).
pub(crate) fn stacked(
    rng: &mut ChaCha8Rng,
    data: &mut Vec<u8>,
    mutate: fn(&mut ChaCha8Rng, &mut Vec<u8>) -> String,
) -> String {
    let n = if rng.random_bool(0.7) { 1 } else { rng.random_range(2..=4) };
    (0..n).map(|_| mutate(rng, data)).collect::<Vec<_>>().join("; ")
}

/// A structure-blind mutation: bit flips, interesting bytes or integers, truncation, slice insertion or removal.
pub(crate) fn mutate_bytes(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    if data.is_empty() {
        data.push(rng.random());
        return "insert a byte into the empty input".into();
    }
    let len = data.len();
    match rng.random_range(0..7) {
        0 => {
            let bits: Vec<usize> = (0..rng.random_range(1..=8)).map(|_| rng.random_range(0..len * 8)).collect();
            bits.iter().for_each(|b| data[b / 8] ^= 1 << (b % 8));
            format!("flip bits {bits:?}")
        }
        1 => {
            let at: Vec<usize> = (0..rng.random_range(1..=4)).map(|_| rng.random_range(0..len)).collect();
            let value = *INTERESTING_BYTES.choose(rng).unwrap();
            at.iter().for_each(|&i| data[i] = value);
            format!("bytes {at:?} = {value:#04x}")
        }
        2 | 3 => {
            // An aligned window is where binary formats keep their lengths, counts and offsets.
            let width = if rng.random_bool(0.5) && len >= 8 { 8 } else { 4.min(len) };
            let at = rng.random_range(0..len / width) * width;
            let value = *INTERESTING_INTS.choose(rng).unwrap();
            let big_endian = rng.random_bool(0.25);
            let bytes = match (width, big_endian) {
                (8, false) => value.to_le_bytes().to_vec(),
                (8, true) => value.to_be_bytes().to_vec(),
                (_, false) => (value as u32).to_le_bytes()[..width].to_vec(),
                (_, true) => (value as u32).to_be_bytes()[..width].to_vec(),
            };
            data[at..at + width].copy_from_slice(&bytes);
            format!("{width} bytes at {at} = {value:#x} ({})", if big_endian { "BE" } else { "LE" })
        }
        4 => {
            let at = rng.random_range(0..len);
            data.truncate(at);
            format!("truncate to {at} bytes")
        }
        5 => {
            let start = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - start).min(512));
            let at = rng.random_range(0..=len);
            let slice = if rng.random_bool(0.5) {
                data[start..start + n].to_vec()
            } else {
                (0..n).map(|_| rng.random()).collect()
            };
            data.splice(at..at, slice);
            format!("insert {n} bytes at {at}")
        }
        _ => {
            let start = rng.random_range(0..len);
            let n = rng.random_range(1..=(len - start).min(512));
            data.drain(start..start + n);
            format!("delete {n} bytes at {start}")
        }
    }
}

/// Byte ranges of numbers: a digit (or a sign or point before one) not inside a word, and what follows of
/// `[0-9.eE+-]`.
pub(crate) fn number_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let is_word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let starts = data[i].is_ascii_digit()
            || (matches!(data[i], b'-' | b'+' | b'.') && data.get(i + 1).is_some_and(u8::is_ascii_digit));
        if starts && (i == 0 || !is_word(data[i - 1])) {
            let mut end = i + 1;
            while end < data.len() && (data[end].is_ascii_digit() || b".eE+-".contains(&data[end])) {
                end += 1;
            }
            spans.push((i, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of tokens: runs of word characters (with `.+-`), or single punctuation bytes.
pub(crate) fn token_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let is_word = |b: u8| b.is_ascii_alphanumeric() || b"_.+-".contains(&b);
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if data[i].is_ascii_whitespace() {
            i += 1;
            continue;
        }
        let mut end = i + 1;
        if is_word(data[i]) {
            while end < data.len() && is_word(data[end]) {
                end += 1;
            }
        }
        spans.push((i, end));
        i = end;
    }
    spans
}

/// Byte ranges of lines, each with its newline.
pub(crate) fn line_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &b) in data.iter().enumerate() {
        if b == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < data.len() {
        spans.push((start, data.len()));
    }
    spans
}

/// A token-aware mutation of text: a number replaced by an extreme one, a token or line deleted or duplicated,
/// control characters inserted, or (rarely) a byte-level mutation.
pub(crate) fn mutate_text(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let show = |bytes: &[u8]| String::from_utf8_lossy(&bytes[..bytes.len().min(40)]).escape_debug().to_string();
    match rng.random_range(0..9) {
        0..=2 => {
            let spans = number_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let new = *INTERESTING_NUMBERS.choose(rng).unwrap();
            let old = show(&data[start..end]);
            data.splice(start..end, new.bytes());
            format!("number '{old}' at {start} -> {new}")
        }
        3 | 4 => {
            let spans = token_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let token = data[start..end].to_vec();
            if rng.random_bool(0.5) {
                data.drain(start..end);
                format!("delete token '{}' at {start}", show(&token))
            } else {
                data.splice(end..end, token.iter().copied());
                format!("duplicate token '{}' at {start}", show(&token))
            }
        }
        5 | 6 => {
            let spans = line_spans(data);
            let Some(&(start, end)) = spans.choose(rng) else { return mutate_bytes(rng, data) };
            let line = data[start..end].to_vec();
            if rng.random_bool(0.5) {
                data.drain(start..end);
                format!("delete line '{}'", show(&line))
            } else {
                data.splice(end..end, line.iter().copied());
                format!("duplicate line '{}'", show(&line))
            }
        }
        7 => {
            let at = rng.random_range(0..=data.len());
            let chars = *CONTROL_CHARS.choose(rng).unwrap();
            data.splice(at..at, chars.iter().copied());
            format!("insert {} at {at}", show(chars))
        }
        _ => mutate_bytes(rng, data),
    }
}

/// Text that parses (JSON, JSON lines, TOML) is half the time changed as a document and written back valid, so
/// that odd values reach the checks behind the parser (shapes, lengths, ranges); otherwise `mutate_text`.
pub(crate) fn mutate_document(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    if rng.random_bool(0.5) {
        if let Some(what) = mutate_parsed(rng, data) {
            return what;
        }
    }
    stacked(rng, data, mutate_text)
}

pub(crate) fn mutate_parsed(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> Option<String> {
    use serde_json::Value;
    let text = std::str::from_utf8(data).ok()?;
    if let Ok(mut value) = serde_json::from_str::<Value>(text) {
        let what = mutate_value(rng, &mut value);
        let mut out =
            if text.contains("\n ") { serde_json::to_vec_pretty(&value) } else { serde_json::to_vec(&value) }.ok()?;
        if text.ends_with('\n') {
            out.push(b'\n');
        }
        *data = out;
        return Some(format!("JSON {what}"));
    }
    let lines: Vec<&str> = text.lines().collect();
    if lines.len() > 1 && lines.iter().all(|l| serde_json::from_str::<Value>(l).is_ok()) {
        let i = rng.random_range(0..lines.len());
        let mut value: Value = serde_json::from_str(lines[i]).unwrap();
        let what = mutate_value(rng, &mut value);
        let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        out[i] = serde_json::to_string(&value).ok()?;
        *data = (out.join("\n") + "\n").into_bytes();
        return Some(format!("JSON line {}: {what}", i + 1));
    }
    // TOML goes through the same value tree; what TOML cannot hold (null, integers beyond i64) fails to write and
    // falls back to a text mutation.
    let table: toml::Table = toml::from_str(text).ok()?;
    let mut value = serde_json::to_value(&table).ok()?;
    let what = mutate_value(rng, &mut value);
    *data = toml::to_string(&value).ok()?.into_bytes();
    Some(format!("TOML {what}"))
}

/// The `n`-th node of a value tree in pre-order, with its path.
pub(crate) fn nth_node<'a>(
    value: &'a mut serde_json::Value,
    n: &mut usize,
    path: String,
) -> Option<(String, &'a mut serde_json::Value)> {
    if *n == 0 {
        return Some((path, value));
    }
    *n -= 1;
    match value {
        serde_json::Value::Array(items) => {
            for (i, item) in items.iter_mut().enumerate() {
                if let Some(found) = nth_node(item, n, format!("{path}[{i}]")) {
                    return Some(found);
                }
            }
        }
        serde_json::Value::Object(map) => {
            for (key, item) in map.iter_mut() {
                if let Some(found) = nth_node(item, n, format!("{path}.{key}")) {
                    return Some(found);
                }
            }
        }
        _ => {}
    }
    None
}

pub(crate) fn count_nodes(value: &serde_json::Value) -> usize {
    1 + match value {
        serde_json::Value::Array(items) => items.iter().map(count_nodes).sum(),
        serde_json::Value::Object(map) => map.values().map(count_nodes).sum(),
        _ => 0,
    }
}

/// Changes one node of a value tree: a number to an extreme, an array shortened, emptied or grown, a key removed
/// or added, a string or flag changed, or any node replaced by a value of another type.
pub(crate) fn mutate_value(rng: &mut ChaCha8Rng, root: &mut serde_json::Value) -> String {
    use serde_json::{json, Value};
    let mut n = rng.random_range(0..count_nodes(root));
    let (path, node) = nth_node(root, &mut n, String::new()).unwrap();
    let old: String = node.to_string().chars().take(40).collect();
    let numbers = [
        json!(1e308),
        json!(-1e308),
        json!(-1),
        json!(0),
        json!(-0.0),
        json!(0.5),
        json!(1e11),
        json!(1e-308),
        json!(u64::MAX),
        json!(1u64 << 32),
        json!(1u64 << 31),
        json!(1_000_000),
    ];
    let what = match node {
        _ if rng.random_bool(0.15) => {
            *node = [json!(null), json!("x"), json!([]), json!({}), json!(true), json!(0)].choose(rng).unwrap().clone();
            "replaced".to_string()
        }
        Value::Number(_) | Value::Null => {
            *node = numbers.choose(rng).unwrap().clone();
            "number".into()
        }
        Value::Bool(b) => {
            *b = !*b;
            "flipped".into()
        }
        Value::String(text) => {
            let mut bytes = std::mem::take(text).into_bytes();
            let what = mutate_text(rng, &mut bytes);
            *text = String::from_utf8_lossy(&bytes).into_owned();
            what
        }
        Value::Array(items) if !items.is_empty() => {
            let i = rng.random_range(0..items.len());
            match rng.random_range(0..4) {
                0 => {
                    items.remove(i);
                    format!("remove element {i}")
                }
                1 => {
                    let copy = items[i].clone();
                    items.insert(i, copy);
                    format!("duplicate element {i}")
                }
                2 => {
                    items.truncate(i);
                    format!("truncate to {i} elements")
                }
                _ => {
                    let copy = items.clone();
                    items.extend(copy);
                    "double".into()
                }
            }
        }
        Value::Object(map) if !map.is_empty() && rng.random_bool(0.7) => {
            let key = map.keys().nth(rng.random_range(0..map.len())).unwrap().clone();
            map.remove(&key);
            format!("remove key '{key}'")
        }
        Value::Object(map) => {
            map.insert("fuzz".into(), json!(1));
            "add key 'fuzz'".into()
        }
        Value::Array(items) => {
            items.push(json!(0));
            "push 0".into()
        }
    };
    let new: String = node.to_string().chars().take(40).collect();
    format!("at '{path}': {old} -> {new} ({what})")
}

/// A comma-separated argument (a board, a state): half the time its fields are swapped or one is copied over
/// another, which keeps it well-formed (a scrambled or unsolvable board, a chip twice); otherwise `mutate_text`.
pub(crate) fn mutate_argument(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let mut fields: Vec<Vec<u8>> = data.split(|&b| b == b',').map(<[u8]>::to_vec).collect();
    if fields.len() < 2 || rng.random_bool(0.5) {
        return mutate_text(rng, data);
    }
    let (i, j) = (rng.random_range(0..fields.len()), rng.random_range(0..fields.len()));
    let what = if rng.random_bool(0.5) {
        fields.swap(i, j);
        format!("swap fields {i} and {j}")
    } else {
        fields[i] = fields[j].clone();
        format!("copy field {j} to {i}")
    };
    *data = fields.join(&b',');
    what
}

/// safetensors is an 8-byte little-endian header length, a JSON header (names, dtypes, shapes, offsets) and
/// the tensor bytes. Half the mutants change the header as text and keep the length prefix consistent, so that
/// the header parser and the shape and offset checks behind it are reached.
pub(crate) fn mutate_safetensors(rng: &mut ChaCha8Rng, data: &mut Vec<u8>) -> String {
    let header_len = data.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap()) as usize);
    match header_len {
        Some(n) if n <= data.len() - 8 && rng.random_bool(0.5) => {
            let mut header = data[8..8 + n].to_vec();
            let what = mutate_document(rng, &mut header);
            let mut out = (header.len() as u64).to_le_bytes().to_vec();
            out.extend_from_slice(&header);
            out.extend_from_slice(&data[8 + n..]);
            *data = out;
            format!("safetensors header: {what}")
        }
        _ => stacked(rng, data, mutate_bytes),
    }
}

/// A camera frame message (JSON with base64 PNG `data`), its PNG mutated as [`mutate_png`] does.
pub(crate) fn mutate_frame_png(rng: &mut ChaCha8Rng, message: &[u8]) -> Option<(Vec<u8>, String)> {
    let mut json: serde_json::Value = serde_json::from_slice(message).ok()?;
    let engine = base64::engine::general_purpose::STANDARD;
    let mut png = engine.decode(json.get("data")?.as_str()?).ok()?;
    let what = mutate_png(rng, &mut png);
    json["data"] = engine.encode(&png).into();
    Some((serde_json::to_vec(&json).ok()?, what))
}

/// A PNG mutated as bytes, and mostly with its chunk CRCs recomputed so that damaged dimensions or chunk lengths
/// get past the CRC check to the decoder.
pub(crate) fn mutate_png(rng: &mut ChaCha8Rng, png: &mut Vec<u8>) -> String {
    let mut what = stacked(rng, png, mutate_bytes);
    if rng.random_bool(0.8) {
        fix_png_crcs(png);
        what += " (chunk CRCs fixed)";
    }
    what
}

pub(crate) fn fix_png_crcs(png: &mut [u8]) {
    let mut at = 8;
    while at + 12 <= png.len() {
        let len = u32::from_be_bytes(png[at..at + 4].try_into().unwrap()) as usize;
        let Some(end) = (at + 8).checked_add(len).filter(|end| end + 4 <= png.len()) else { break };
        let crc = crc32fast::hash(&png[at + 4..end]);
        png[end..end + 4].copy_from_slice(&crc.to_be_bytes());
        at = end + 4;
    }
}
