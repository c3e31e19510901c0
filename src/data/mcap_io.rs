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

/// Like [`read_messages`], plus the raw payloads of a second topic (in file order).
pub fn read_messages_and_raw<T: DeserializeOwned>(
    path: &Path,
    metadata_name: &str,
    topic: &str,
    raw_topic: &str,
) -> Result<(BTreeMap<String, String>, Vec<(u32, T)>, Vec<Vec<u8>>)> {
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

/// The named metadata record and the payloads of each of `topics`, with their sequence numbers.
fn read_raw(path: &Path, metadata_name: &str, topics: &[&str]) -> Result<RawTopics> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let corrupt =
        |e: mcap::McapError| Error::bad_file(path, format!("not a readable MCAP file (truncated or corrupt?): {e}"));
    let mut metadata = None;
    let mut other_names = Vec::new();
    for record in mcap::read::LinearReader::new(&bytes).map_err(corrupt)? {
        if let mcap::records::Record::Metadata(m) = record.map_err(corrupt)? {
            if m.name == metadata_name {
                metadata = Some(m.metadata);
            } else {
                other_names.push(m.name);
            }
        }
    }
    let metadata = metadata.ok_or_else(|| {
        let found = if other_names.is_empty() { "none".to_string() } else { other_names.join(", ") };
        Error::bad_file(path, format!("expected a '{metadata_name}' metadata record, found {found}"))
    })?;
    let mut out = vec![Vec::new(); topics.len()];
    for message in mcap::MessageStream::new(&bytes).map_err(corrupt)? {
        let message = message.map_err(corrupt)?;
        if let Some(k) = topics.iter().position(|t| *t == message.channel.topic) {
            out[k].push((message.sequence, message.data.into_owned()));
        }
    }
    Ok((metadata, out))
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
