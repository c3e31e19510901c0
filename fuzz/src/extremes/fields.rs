//! The numeric fields of each format the CLI reads, and one extreme written into one of them with everything
//! else kept well-formed (JSON re-serialized, TOML re-written, MCAP re-encoded with CRCs, the safetensors
//! header length recomputed).

use serde_json::Value;

use super::{Extreme, ARRAYS};
use crate::mcap_doc::McapDoc;

/// The formats with numbers in them, by file extension.
#[derive(Clone, Copy, PartialEq, Debug)]
pub(crate) enum Format {
    Json,
    Jsonl,
    Toml,
    Csv,
    Mcap,
    Safetensors,
    /// A comma-separated argument (a board, a state).
    List,
}

impl Format {
    pub(crate) fn of(name: &str) -> Option<Format> {
        let ext = name.rsplit('.').next()?;
        Some(match ext {
            "json" => Format::Json,
            "jsonl" => Format::Jsonl,
            "toml" => Format::Toml,
            "csv" => Format::Csv,
            "mcap" => Format::Mcap,
            "safetensors" => Format::Safetensors,
            _ => return None,
        })
    }
}

/// Where a number (or an array of numbers) sits in a document.
#[derive(Clone, Debug)]
pub(crate) enum Place {
    /// A JSON node, by JSON pointer, in document `doc` (a JSON line, an MCAP message, a metadata value; 0 for a
    /// whole JSON or TOML file or the safetensors header).
    Json { doc: Doc, pointer: String },
    /// A CSV cell or an item of a comma-separated argument.
    Cell { line: usize, column: usize },
    /// A comma-separated argument as a whole (its length changed).
    List,
    /// One element of a safetensors tensor: its byte offset in the file and its width.
    Element { offset: usize, dtype: &'static str },
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Doc {
    Whole,
    Line(usize),
    Message(usize),
    Metadata(usize, String),
}

#[derive(Clone, Debug)]
pub(crate) struct Field {
    pub(crate) place: Place,
    /// The field's path as a reader names it (`messages[3].state[1]`, `metadata.instances[0].mass`).
    pub(crate) shown: String,
    /// An array of numbers: it gets the array extremes, not the scalar ones.
    pub(crate) array: bool,
}

/// Every numeric field of `bytes` in `format`, in a fixed order.
pub(crate) fn fields(format: Format, bytes: &[u8]) -> Vec<Field> {
    let mut out = Vec::new();
    let text = || std::str::from_utf8(bytes).ok();
    match format {
        Format::Json => {
            if let Some(v) = text().and_then(|t| serde_json::from_str(t).ok()) {
                json_fields(&v, Doc::Whole, "", "", &mut out);
            }
        }
        Format::Toml => {
            if let Some(v) = text().and_then(|t| toml::from_str::<toml::Table>(t).ok()) {
                json_fields(&serde_json::to_value(v).unwrap(), Doc::Whole, "", "", &mut out);
            }
        }
        Format::Jsonl => {
            for (i, line) in text().unwrap_or("").lines().enumerate() {
                if let Ok(v) = serde_json::from_str(line) {
                    json_fields(&v, Doc::Line(i), "", &format!("line {}", i + 1), &mut out);
                }
            }
        }
        Format::Csv | Format::List => {
            let lines: Vec<&str> = text().unwrap_or("").lines().collect();
            let header: Vec<&str> = if format == Format::Csv { lines[0].split(',').collect() } else { vec![] };
            for (line, cells) in lines.iter().enumerate().skip((format == Format::Csv) as usize) {
                for (column, cell) in cells.split(',').enumerate() {
                    if cell.trim().parse::<f64>().is_ok() {
                        let name = header.get(column).map_or(format!("[{column}]"), |h| format!(".{h}"));
                        let shown = format!("row {line}{name}");
                        out.push(Field { place: Place::Cell { line, column }, shown, array: false });
                    }
                }
            }
            if format == Format::List {
                out.push(Field { place: Place::List, shown: "the list".into(), array: true });
            }
        }
        Format::Mcap => {
            let doc = McapDoc::decode(bytes);
            for (r, record) in doc.metadata.iter().enumerate() {
                for (key, value) in &record.metadata {
                    if let Ok(v) = serde_json::from_str::<Value>(value) {
                        let doc = Doc::Metadata(r, key.clone());
                        json_fields(&v, doc, "", &format!("metadata.{key}"), &mut out);
                    }
                }
            }
            for (i, (_, data)) in doc.messages.iter().enumerate() {
                if let Ok(v) = serde_json::from_slice::<Value>(data) {
                    json_fields(&v, Doc::Message(i), "", &format!("messages[{i}]"), &mut out);
                }
            }
        }
        Format::Safetensors => safetensors_fields(bytes, &mut out),
    }
    out
}

/// The numbers and numeric arrays under `v` (an array of numbers is one array field and one field per element).
fn json_fields(v: &Value, doc: Doc, pointer: &str, shown: &str, out: &mut Vec<Field>) {
    let push = |out: &mut Vec<Field>, array| {
        let place = Place::Json { doc: doc.clone(), pointer: pointer.to_string() };
        out.push(Field { place, shown: shown.trim_start_matches('.').to_string(), array });
    };
    match v {
        Value::Number(_) => push(out, false),
        Value::Array(items) => {
            if !items.is_empty() && items.iter().all(Value::is_number) {
                push(out, true);
            }
            for (i, item) in items.iter().enumerate() {
                json_fields(item, doc.clone(), &format!("{pointer}/{i}"), &format!("{shown}[{i}]"), out);
            }
        }
        Value::Object(map) => {
            for (key, item) in map {
                let escaped = key.replace('~', "~0").replace('/', "~1");
                json_fields(item, doc.clone(), &format!("{pointer}/{escaped}"), &format!("{shown}.{key}"), out);
            }
        }
        _ => {}
    }
}

/// The header's numbers (shapes, offsets), and the first, middle and last element of every float tensor.
fn safetensors_fields(bytes: &[u8], out: &mut Vec<Field>) {
    let Some((header, start)) = safetensors_header(bytes) else { return };
    let mut header_fields = Vec::new();
    json_fields(&header, Doc::Whole, "", "header", &mut header_fields);
    out.extend(header_fields);
    let Value::Object(map) = &header else { return };
    for (name, info) in map {
        let (Some(dtype), Some(offsets)) = (info["dtype"].as_str(), info["data_offsets"].as_array()) else { continue };
        let (dtype, width) = match dtype {
            "F32" => ("F32", 4),
            "F64" => ("F64", 8),
            _ => continue,
        };
        let (Some(a), Some(b)) = (offsets[0].as_u64(), offsets.get(1).and_then(Value::as_u64)) else { continue };
        let n = (b.saturating_sub(a) as usize) / width;
        let mut picks = vec![0, n / 2, n.saturating_sub(1)];
        picks.dedup();
        for i in picks.into_iter().filter(|&i| i < n) {
            let offset = start + a as usize + i * width;
            let shown = format!("tensor {name}[{i}]");
            out.push(Field { place: Place::Element { offset, dtype }, shown, array: false });
        }
    }
}

fn safetensors_header(bytes: &[u8]) -> Option<(Value, usize)> {
    let n = u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?) as usize;
    let header = serde_json::from_slice(bytes.get(8..8usize.checked_add(n)?)?).ok()?;
    Some((header, 8 + n))
}

/// Writes `extreme` into `field` of `bytes`; `None` when the format cannot hold it (NaN in JSON).
pub(crate) fn apply(format: Format, bytes: &[u8], field: &Field, extreme: Extreme) -> Option<Vec<u8>> {
    match (&field.place, format) {
        (Place::Json { doc, pointer }, Format::Json | Format::Toml | Format::Jsonl) => {
            let text = std::str::from_utf8(bytes).ok()?;
            match doc {
                Doc::Whole if format == Format::Toml => {
                    let value = serde_json::to_value(toml::from_str::<toml::Table>(text).ok()?).ok()?;
                    write_toml(value, pointer, extreme)
                }
                Doc::Whole => {
                    let pretty = text.contains("\n ");
                    let mut out = write_json(serde_json::from_str(text).ok()?, pointer, extreme, pretty)?;
                    if text.ends_with('\n') {
                        out.push(b'\n');
                    }
                    Some(out)
                }
                Doc::Line(i) => {
                    let mut lines: Vec<String> = text.lines().map(String::from).collect();
                    let value = serde_json::from_str(lines.get(*i)?).ok()?;
                    lines[*i] = String::from_utf8(write_json(value, pointer, extreme, false)?).ok()?;
                    Some((lines.join("\n") + "\n").into_bytes())
                }
                _ => None,
            }
        }
        (Place::Json { doc, pointer }, Format::Mcap) => {
            let mut mcap = McapDoc::decode(bytes);
            match doc {
                Doc::Message(i) => {
                    let data = &mut mcap.messages.get_mut(*i)?.1;
                    *data = write_json(serde_json::from_slice(data).ok()?, pointer, extreme, false)?;
                }
                Doc::Metadata(r, key) => {
                    let value = mcap.metadata.get_mut(*r)?.metadata.get_mut(key)?;
                    let json = write_json(serde_json::from_str(value).ok()?, pointer, extreme, false)?;
                    *value = String::from_utf8(json).ok()?;
                }
                _ => return None,
            }
            mcap.encode(true, true, true)
        }
        (Place::Json { pointer, .. }, Format::Safetensors) => {
            let (header, start) = safetensors_header(bytes)?;
            let header = write_json(header, pointer, extreme, false)?;
            let mut out = (header.len() as u64).to_le_bytes().to_vec();
            out.extend_from_slice(&header);
            out.extend_from_slice(&bytes[start..]);
            Some(out)
        }
        (Place::Element { offset, dtype }, _) => {
            let value = extreme.scalar()?.text.parse::<f64>().ok()?;
            let mut out = bytes.to_vec();
            match *dtype {
                "F32" => out[*offset..*offset + 4].copy_from_slice(&(value as f32).to_le_bytes()),
                _ => out[*offset..*offset + 8].copy_from_slice(&value.to_le_bytes()),
            }
            Some(out)
        }
        (Place::Cell { line, column }, _) => {
            let text = std::str::from_utf8(bytes).ok()?;
            let mut lines: Vec<String> = text.lines().map(String::from).collect();
            let mut cells: Vec<&str> = lines.get(*line)?.split(',').collect();
            let new = extreme.scalar()?.text;
            *cells.get_mut(*column)? = new;
            lines[*line] = cells.join(",");
            let end = if text.ends_with('\n') { "\n" } else { "" };
            Some((lines.join("\n") + end).into_bytes())
        }
        (Place::List, _) => {
            let items: Vec<&str> = std::str::from_utf8(bytes).ok()?.split(',').collect();
            let mut text = resized(items, extreme.array()?).join(",");
            // One argument holds at most 128 KiB (MAX_ARG_STRLEN): a million items stop where it is full.
            if text.len() > 120_000 {
                text.truncate(text[..120_000].rfind(',').unwrap_or(0));
            }
            Some(text.into_bytes())
        }
        _ => None,
    }
}

/// An array with its length changed as `which` of [`ARRAYS`] says.
fn resized<T: Clone>(mut items: Vec<T>, which: usize) -> Vec<T> {
    match ARRAYS[which] {
        "empty" => items.clear(),
        "a million elements" => items = items.iter().cycle().take(1_000_000).cloned().collect(),
        "one element more" => {
            if let Some(last) = items.last().cloned() {
                items.push(last);
            }
        }
        _ => {
            items.pop();
        }
    }
    items
}

/// A placeholder string that serializes unescaped in JSON and TOML, replaced by the extreme's raw text (which
/// may be no valid `f64`, e.g. 1.8e308).
const PLACEHOLDER: &str = "@@mbrl-fuzz-extreme@@";

fn put(mut root: Value, pointer: &str, extreme: Extreme) -> Option<(Value, Option<&'static str>)> {
    let node = root.pointer_mut(pointer)?;
    match extreme {
        Extreme::Array(which) => {
            let Value::Array(items) = std::mem::take(node) else { return None };
            *node = Value::Array(resized(items, which));
            Some((root, None))
        }
        Extreme::Scalar(_) => {
            *node = Value::String(PLACEHOLDER.into());
            Some((root, Some(extreme.scalar()?.text)))
        }
    }
}

fn write_json(root: Value, pointer: &str, extreme: Extreme, pretty: bool) -> Option<Vec<u8>> {
    if extreme.scalar().is_some_and(|s| !s.in_json) {
        return None;
    }
    let (root, raw) = put(root, pointer, extreme)?;
    let text = if pretty { serde_json::to_string_pretty(&root) } else { serde_json::to_string(&root) }.ok()?;
    Some(match raw {
        Some(raw) => text.replace(&format!("\"{PLACEHOLDER}\""), raw).into_bytes(),
        None => text.into_bytes(),
    })
}

fn write_toml(root: Value, pointer: &str, extreme: Extreme) -> Option<Vec<u8>> {
    let (root, raw) = put(root, pointer, extreme)?;
    let text = toml::to_string(&root).ok()?;
    Some(match raw {
        Some(raw) => text.replace(&format!("\"{PLACEHOLDER}\""), &raw.to_lowercase()).into_bytes(),
        None => text.into_bytes(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extremes::SCALARS;

    fn scalar(text: &str) -> Extreme {
        Extreme::Scalar(SCALARS.iter().position(|s| s.text == text).unwrap())
    }

    /// One number changed, written as the raw extreme; every other byte of the document as it was.
    #[test]
    fn json_field_gets_the_raw_extreme() {
        let doc = br#"{"dt":0.05,"instances":[{"mass":1.0},{"mass":2}],"name":"x"}"#;
        let fields = fields(Format::Json, doc);
        let shown: Vec<&str> = fields.iter().map(|f| f.shown.as_str()).collect();
        assert_eq!(shown, ["dt", "instances[0].mass", "instances[1].mass"]);
        let out = apply(Format::Json, doc, &fields[2], scalar("1.8e308")).unwrap();
        assert_eq!(out, br#"{"dt":0.05,"instances":[{"mass":1.0},{"mass":1.8e308}],"name":"x"}"#);
        assert!(apply(Format::Json, doc, &fields[0], scalar("NaN")).is_none(), "JSON has no NaN");
    }

    #[test]
    fn toml_takes_nan_and_arrays_change_length() {
        let doc = b"lr = 0.001\nhidden = [8, 8]\n";
        let fields = fields(Format::Toml, doc);
        let array = fields.iter().find(|f| f.array).unwrap();
        let out = String::from_utf8(apply(Format::Toml, doc, array, Extreme::Array(0)).unwrap()).unwrap();
        assert!(out.contains("hidden = []"), "{out}");
        let lr = fields.iter().find(|f| f.shown == "lr").unwrap();
        let out = String::from_utf8(apply(Format::Toml, doc, lr, scalar("NaN")).unwrap()).unwrap();
        assert!(out.contains("lr = nan"), "{out}");
    }

    /// The header length prefix follows the header; tensor elements are written in the tensor's dtype.
    #[test]
    fn safetensors_stay_well_formed() {
        let header = br#"{"w":{"dtype":"F32","shape":[2],"data_offsets":[0,8]}}"#;
        let mut file = (header.len() as u64).to_le_bytes().to_vec();
        file.extend_from_slice(header);
        file.extend_from_slice(&[0; 8]);
        let fields = fields(Format::Safetensors, &file);
        let element = fields.iter().find(|f| f.shown == "tensor w[1]").unwrap();
        let out = apply(Format::Safetensors, &file, element, scalar("NaN")).unwrap();
        assert!(f32::from_le_bytes(out[out.len() - 4..].try_into().unwrap()).is_nan());
        let offset = fields.iter().find(|f| f.shown == "header.w.data_offsets[1]").unwrap();
        let out = apply(Format::Safetensors, &file, offset, scalar("1e19")).unwrap();
        let n = u64::from_le_bytes(out[..8].try_into().unwrap()) as usize;
        assert!(std::str::from_utf8(&out[8..8 + n]).unwrap().contains("\"data_offsets\":[0,1e19]"));
    }
}
