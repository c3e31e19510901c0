//! The MCAP container shared by every mbrl file: one metadata record, one JSON channel with a JSON Schema,
//! zstd chunks, written atomically.

use std::collections::BTreeMap;
use std::path::Path;

use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::error::{Error, Result};
use crate::util::atomic::write_atomic_seekable;

const PROFILE: &str = "mbrl";

/// What a file holds besides its messages.
pub struct Layout<'a> {
    pub metadata_name: &'a str,
    pub topic: &'a str,
    pub schema_name: &'a str,
    pub schema: &'a str,
    /// Log-clock nanoseconds between messages (viewers play messages back on this clock).
    pub tick_ns: u64,
}

fn mcap_err(path: &Path, e: mcap::McapError) -> Error {
    Error::bad_file(path, format!("MCAP write failed: {e}"))
}

/// A second channel written beside the main one (a dataset's camera frames): pre-encoded messages, each with
/// its log-clock time, merged into the file in time order.
pub struct ExtraChannel<'a> {
    pub topic: &'a str,
    pub schema_name: &'a str,
    pub schema: &'a str,
    pub messages: Vec<(u64, Vec<u8>)>,
}

pub fn write_messages<T: Serialize>(
    path: &Path,
    layout: &Layout,
    metadata: BTreeMap<String, String>,
    messages: &[T],
) -> Result<()> {
    write_messages_with(path, layout, metadata, messages, None)
}

/// The log-clock time of main message `sequence`.
pub fn message_clock(layout: &Layout, sequence: usize) -> u64 {
    (sequence as u64 + 1) * layout.tick_ns.max(1)
}

pub fn write_messages_with<T: Serialize>(
    path: &Path,
    layout: &Layout,
    metadata: BTreeMap<String, String>,
    messages: &[T],
    extra: Option<&ExtraChannel>,
) -> Result<()> {
    write_atomic_seekable(path, |file| {
        let options = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            .profile(PROFILE)
            .library(format!("mbrl {}", crate::VERSION));
        let mut writer = options.create(std::io::BufWriter::new(file)).map_err(|e| mcap_err(path, e))?;
        writer
            .write_metadata(&mcap::records::Metadata { name: layout.metadata_name.to_string(), metadata })
            .map_err(|e| mcap_err(path, e))?;
        let schema = writer
            .add_schema(layout.schema_name, "jsonschema", layout.schema.as_bytes())
            .map_err(|e| mcap_err(path, e))?;
        let channel =
            writer.add_channel(schema, layout.topic, "json", &BTreeMap::new()).map_err(|e| mcap_err(path, e))?;
        let extra_channel = match extra {
            Some(x) => {
                let schema = writer
                    .add_schema(x.schema_name, "jsonschema", x.schema.as_bytes())
                    .map_err(|e| mcap_err(path, e))?;
                Some(writer.add_channel(schema, x.topic, "json", &BTreeMap::new()).map_err(|e| mcap_err(path, e))?)
            }
            None => None,
        };
        let extra_messages: &[(u64, Vec<u8>)] = extra.map_or(&[], |x| &x.messages);
        let mut next_extra = 0;
        let mut write_extra_until = |writer: &mut mcap::Writer<_>, clock: u64| -> Result<()> {
            while let (Some(id), Some((time, data))) = (extra_channel, extra_messages.get(next_extra)) {
                if *time > clock {
                    break;
                }
                let header = mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: next_extra as u32,
                    log_time: *time,
                    publish_time: *time,
                };
                writer.write_to_known_channel(&header, data).map_err(|e| mcap_err(path, e))?;
                next_extra += 1;
            }
            Ok(())
        };
        for (sequence, message) in messages.iter().enumerate() {
            let clock = message_clock(layout, sequence);
            write_extra_until(&mut writer, clock)?;
            let data = serde_json::to_vec(message).map_err(|e| Error::bad_file(path, e.to_string()))?;
            let header = mcap::records::MessageHeader {
                channel_id: channel,
                sequence: sequence as u32,
                log_time: clock,
                publish_time: clock,
            };
            writer.write_to_known_channel(&header, &data).map_err(|e| mcap_err(path, e))?;
        }
        write_extra_until(&mut writer, u64::MAX)?;
        writer.finish().map_err(|e| mcap_err(path, e))?;
        Ok(())
    })
}

/// A file's metadata record and its messages with their sequence numbers.
pub type MetadataAndMessages<T> = (BTreeMap<String, String>, Vec<(u32, T)>);

/// The named metadata record and the decoded messages of `topic`, each with its sequence number.
pub fn read_messages<T: DeserializeOwned>(
    path: &Path,
    metadata_name: &str,
    topic: &str,
) -> Result<MetadataAndMessages<T>> {
    let (metadata, mut topics) = read_raw(path, metadata_name, &[topic])?;
    let messages = decode(path, topic, topics.remove(0))?;
    Ok((metadata, messages))
}

/// A file's metadata, its decoded messages (with channel ids) and a second topic's raw payloads.
pub type MessagesAndRaw<T> = (BTreeMap<String, String>, Vec<(u32, T)>, Vec<Vec<u8>>);

/// Like [`read_messages`], plus the raw payloads of a second topic (in file order).
pub fn read_messages_and_raw<T: DeserializeOwned>(
    path: &Path,
    metadata_name: &str,
    topic: &str,
    raw_topic: &str,
) -> Result<MessagesAndRaw<T>> {
    let (metadata, mut topics) = read_raw(path, metadata_name, &[topic, raw_topic])?;
    let raw = topics.pop().unwrap_or_default().into_iter().map(|(_, data)| data).collect();
    let messages = decode(path, topic, topics.pop().unwrap_or_default())?;
    Ok((metadata, messages, raw))
}

fn decode<T: DeserializeOwned>(path: &Path, topic: &str, raw: Vec<(u32, Vec<u8>)>) -> Result<Vec<(u32, T)>> {
    raw.into_iter()
        .map(|(sequence, data)| {
            serde_json::from_slice(&data)
                .map(|value| (sequence, value))
                .map_err(|e| Error::bad_file(path, format!("message {sequence} on {topic}: {e}")))
        })
        .collect()
}

type RawTopics = (BTreeMap<String, String>, Vec<Vec<(u32, Vec<u8>)>>);

/// Largest MCAP file read (the whole file is held in memory).
pub const MAX_MCAP_BYTES: u64 = 8 << 30;
/// A record inside a chunk may be longer than the compressed file, but not by more than this factor (and never
/// beyond 1 GiB): a flipped length field is refused before anything is reserved for it.
const RECORD_EXPANSION: usize = 16;
const MIN_RECORD_LIMIT: usize = 1 << 20;
const MAX_RECORD_LIMIT: usize = 1 << 30;
const MESSAGE_ENCODING: &str = "json";
const SCHEMA_ENCODING: &str = "jsonschema";

/// The named metadata record and the payloads of each of `topics`, with their sequence numbers. The file is
/// read through the MCAP library's sans-io reader with every declared length bounded by the bytes present,
/// chunk and data-section CRCs checked, and each wanted topic's channel checked to be JSON with a JSON Schema.
fn read_raw(path: &Path, metadata_name: &str, topics: &[&str]) -> Result<RawTopics> {
    let scan = scan(path, metadata_name, topics)?;
    let metadata = scan.metadata.ok_or_else(|| {
        let found = if scan.other_names.is_empty() { "none".to_string() } else { scan.other_names.join(", ") };
        Error::bad_file(path, format!("expected a '{metadata_name}' metadata record, found {found}"))
    })?;
    Ok((metadata, scan.payloads))
}

/// The names of every metadata record in the file, in file order: what kind of mbrl file it is.
pub fn metadata_names(path: &Path) -> Result<Vec<String>> {
    Ok(scan(path, "", &[])?.other_names)
}

struct Scan {
    metadata: Option<BTreeMap<String, String>>,
    other_names: Vec<String>,
    payloads: Vec<Vec<(u32, Vec<u8>)>>,
}

/// One pass over the file: the metadata record named `metadata_name` (an empty name matches none), the
/// names of the others, and the payloads of `topics`.
fn scan(path: &Path, metadata_name: &str, topics: &[&str]) -> Result<Scan> {
    use mcap::records::Record;
    use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
    let bytes = crate::util::bounded_read::read_bounded(path, MAX_MCAP_BYTES)?;
    let corrupt =
        |e: mcap::McapError| Error::bad_file(path, format!("not a readable MCAP file (truncated or corrupt?): {e}"));
    let limit = bytes.len().saturating_mul(RECORD_EXPANSION).clamp(MIN_RECORD_LIMIT, MAX_RECORD_LIMIT);
    let options = LinearReaderOptions::default()
        .with_validate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_record_length_limit(limit);
    let mut reader = LinearReader::new_with_options(options);
    let mut metadata = None;
    let mut other_names = Vec::new();
    let mut schema_encodings: BTreeMap<u16, String> = BTreeMap::new();
    // Channel id → index into `topics`, for the wanted topics only.
    let mut wanted: BTreeMap<u16, usize> = BTreeMap::new();
    let mut out = vec![Vec::new(); topics.len()];
    let mut offset = 0;
    loop {
        let request = match reader.next_event() {
            None => break,
            Some(Err(e)) => return Err(corrupt(e)),
            Some(Ok(LinearReadEvent::ReadRequest(n))) => n,
            Some(Ok(LinearReadEvent::Record { data, opcode })) => {
                // Only the records mbrl uses are decoded, and only once every length inside them fits the
                // record: the mcap crate allocates a string's declared length before reading it.
                if !RECORDS_READ.contains(&opcode) {
                    continue;
                }
                check_inner_lengths(opcode, data).map_err(|why| {
                    Error::bad_file(path, format!("not a readable MCAP file (corrupt record 0x{opcode:02x}): {why}"))
                })?;
                match mcap::parse_record(opcode, data).map_err(corrupt)? {
                    Record::Metadata(m) if !metadata_name.is_empty() && m.name == metadata_name => {
                        metadata = Some(m.metadata)
                    }
                    Record::Metadata(m) => other_names.push(m.name),
                    Record::Schema { header, .. } => {
                        schema_encodings.insert(header.id, header.encoding);
                    }
                    Record::Channel(channel) => {
                        if let Some(k) = topics.iter().position(|t| *t == channel.topic) {
                            let schema = schema_encodings.get(&channel.schema_id).map(String::as_str);
                            if channel.message_encoding != MESSAGE_ENCODING || schema != Some(SCHEMA_ENCODING) {
                                return Err(Error::bad_file(
                                    path,
                                    format!(
                                        "channel '{}' has message encoding '{}' and schema encoding '{}'; mbrl \
                                         reads '{MESSAGE_ENCODING}' messages with a '{SCHEMA_ENCODING}' schema",
                                        channel.topic,
                                        channel.message_encoding,
                                        schema.unwrap_or("none")
                                    ),
                                ));
                            }
                            wanted.insert(channel.id, k);
                        }
                    }
                    Record::Message { header, data } => {
                        if let Some(&k) = wanted.get(&header.channel_id) {
                            out[k].push((header.sequence, data.into_owned()));
                        }
                    }
                    _ => {}
                }
                continue;
            }
        };
        let n = request.min(bytes.len() - offset);
        reader.insert(n).copy_from_slice(&bytes[offset..offset + n]);
        reader.notify_read(n);
        offset += n;
    }
    Ok(Scan { metadata, other_names, payloads: out })
}

/// Schema, Channel, Message and Metadata: the record opcodes `read_raw` decodes.
const RECORDS_READ: [u8; 4] = [0x03, 0x04, 0x05, 0x0C];

/// Walks the length-prefixed fields of a record of `RECORDS_READ` (MCAP spec layouts) and fails when a
/// declared length runs past the record's end.
fn check_inner_lengths(opcode: u8, body: &[u8]) -> std::result::Result<(), String> {
    #[derive(Clone, Copy)]
    enum Field {
        Fixed(usize),
        Str,
        Bytes,
        StringMap,
    }
    use Field::*;
    let layout: &[Field] = match opcode {
        0x03 => &[Fixed(2), Str, Str, Bytes],
        0x04 => &[Fixed(4), Str, Str, StringMap],
        0x05 => &[Fixed(22)],
        0x0C => &[Str, StringMap],
        _ => &[],
    };
    fn prefixed(rest: &[u8]) -> std::result::Result<(&[u8], &[u8]), String> {
        let len_bytes: [u8; 4] =
            rest.get(..4).and_then(|b| b.try_into().ok()).ok_or("a length past the record's end")?;
        let len = u32::from_le_bytes(len_bytes) as usize;
        let after = &rest[4..];
        if len > after.len() {
            return Err(format!("a field claims {len} bytes, {} remain in the record", after.len()));
        }
        Ok(after.split_at(len))
    }
    let mut rest = body;
    for field in layout {
        rest = match *field {
            Fixed(n) => rest.get(n..).ok_or("the record is shorter than its fixed fields")?,
            Str | Bytes => prefixed(rest)?.1,
            StringMap => {
                let (mut map, after) = prefixed(rest)?;
                while !map.is_empty() {
                    map = prefixed(prefixed(map)?.1)?.1;
                }
                after
            }
        };
    }
    Ok(())
}

/// Reads the `format_version` field and rejects versions this build does not know.
pub fn check_version(path: &Path, metadata: &BTreeMap<String, String>, supported: u32) -> Result<u32> {
    let version: u32 = metadata
        .get("format_version")
        .ok_or_else(|| Error::bad_file(path, "metadata lacks the field 'format_version'"))?
        .parse()
        .map_err(|_| Error::bad_file(path, "metadata field 'format_version': expected an integer"))?;
    if version != supported {
        return Err(Error::bad_file(
            path,
            format!(
                "format version {version} is not supported (this mbrl {} reads version {supported})",
                crate::VERSION
            ),
        ));
    }
    Ok(version)
}

/// A required metadata field, with an error naming the file and the field.
pub fn metadata_field(path: &Path, metadata: &BTreeMap<String, String>, key: &str) -> Result<String> {
    metadata.get(key).cloned().ok_or_else(|| Error::bad_file(path, format!("metadata lacks the field '{key}'")))
}

/// The `seed` field every mbrl file records.
pub fn metadata_seed(path: &Path, metadata: &BTreeMap<String, String>) -> Result<u64> {
    metadata_field(path, metadata, "seed")?
        .parse()
        .map_err(|_| Error::bad_file(path, "metadata field 'seed': expected an integer"))
}

#[cfg(test)]
mod tests {
    use super::*;

    type FileWriter = mcap::Writer<std::io::BufWriter<std::fs::File>>;

    /// A file holding the metadata record `meta` and whatever `more` writes after it.
    fn write_with_meta(path: &Path, more: impl FnOnce(&mut FileWriter)) {
        let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
        let mut writer = mcap::WriteOptions::new().create(file).unwrap();
        let metadata = BTreeMap::from([("format_version".to_string(), "1".to_string())]);
        writer.write_metadata(&mcap::records::Metadata { name: "meta".into(), metadata }).unwrap();
        more(&mut writer);
        writer.finish().unwrap();
    }

    /// A string inside a record that claims gigabytes (found by the fuzz harness: the mcap crate reserved the
    /// declared length and aborted) is a clean error.
    #[test]
    fn a_string_length_past_its_record_is_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.mcap");
        write_with_meta(&path, |_| {});
        let mut bytes = std::fs::read(&path).unwrap();
        // Records after the 8-byte magic: opcode, u64 length, body; the metadata body opens with its name.
        let mut at = 8;
        while bytes[at] != 0x0C {
            at += 9 + u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        }
        bytes[at + 9..at + 13].copy_from_slice(&0xFF00_0005u32.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read_raw(&path, "meta", &[]).unwrap_err().to_string();
        assert!(err.contains("corrupt record 0x0c") && err.contains("claims 4278190085 bytes"), "{err}");
        assert!(check_inner_lengths(0x04, &[0; 4]).is_err());
        assert!(check_inner_lengths(0x05, &[0; 22]).is_ok());
    }

    /// A file whose wanted topic is not JSON with a JSON Schema is refused before any payload is decoded.
    #[test]
    fn a_topic_in_another_encoding_is_named_and_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("cbor.mcap");
        write_with_meta(&path, |writer| {
            let schema = writer.add_schema("s", "protobuf", b"").unwrap();
            let channel = writer.add_channel(schema, "/steps", "cbor", &BTreeMap::new()).unwrap();
            let header =
                mcap::records::MessageHeader { channel_id: channel, sequence: 0, log_time: 0, publish_time: 0 };
            writer.write_to_known_channel(&header, b"\xa0").unwrap();
        });
        let e = read_raw(&path, "meta", &["/steps"]).unwrap_err().to_string();
        assert!(e.contains("cbor.mcap") && e.contains("'/steps'") && e.contains("'cbor'"), "{e}");
        // Another topic's encoding is none of the reader's business.
        assert!(read_raw(&path, "meta", &["/other"]).is_ok());
    }
}
