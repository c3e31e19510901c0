//! MCAP files as records: decoded once, mutated record by record and re-encoded valid.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use rand::seq::{IndexedMutRandom, IndexedRandom};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use crate::mutators::{mutate_bytes, mutate_document, mutate_frame_png, mutate_text, stacked, INTERESTING_INTS};

/// An MCAP file as records, for structural mutation and re-encoding.
#[derive(Clone)]
pub(crate) struct McapDoc {
    pub(crate) metadata: Vec<mcap::records::Metadata>,
    pub(crate) schemas: Vec<(u16, String, String, Vec<u8>)>,
    pub(crate) channels: Vec<mcap::records::Channel>,
    pub(crate) messages: Vec<(mcap::records::MessageHeader, Vec<u8>)>,
}

impl McapDoc {
    /// Reads every record, chunks flattened; the summary repeats schemas and channels, kept once.
    pub(crate) fn decode(bytes: &[u8]) -> McapDoc {
        use mcap::records::Record;
        let mut doc = McapDoc { metadata: vec![], schemas: vec![], channels: vec![], messages: vec![] };
        for record in mcap::read::ChunkFlattener::new(bytes).unwrap() {
            match record.unwrap() {
                Record::Metadata(m) => doc.metadata.push(m),
                Record::Schema { header, data } if !doc.schemas.iter().any(|s| s.0 == header.id) => {
                    doc.schemas.push((header.id, header.name, header.encoding, data.into_owned()))
                }
                Record::Channel(c) if !doc.channels.iter().any(|k| k.id == c.id) => doc.channels.push(c),
                Record::Message { header, data } => doc.messages.push((header, data.into_owned())),
                _ => {}
            }
        }
        doc
    }

    /// Writes a valid MCAP file (CRCs included unless `checksums` is off); `None` when the mutated records are
    /// something the writer refuses (the byte-level mutators cover invalid containers).
    pub(crate) fn encode(&self, compress: bool, chunked: bool, checksums: bool) -> Option<Vec<u8>> {
        let options = mcap::WriteOptions::new()
            .compression(compress.then_some(mcap::Compression::Zstd))
            .use_chunks(chunked)
            .calculate_chunk_crcs(checksums)
            .calculate_data_section_crc(checksums)
            .calculate_summary_section_crc(checksums)
            .profile("mbrl");
        let mut out = std::io::Cursor::new(Vec::new());
        let mut writer = options.create(&mut out).ok()?;
        for m in &self.metadata {
            writer.write_metadata(m).ok()?;
        }
        for (id, name, encoding, data) in &self.schemas {
            writer.add_schema_with_id(*id, name, encoding, data).ok()?;
        }
        for c in &self.channels {
            writer.add_channel_with_id(c.id, c.schema_id, &c.topic, &c.message_encoding, &c.metadata).ok()?;
        }
        for (header, data) in &self.messages {
            writer.write_to_known_channel(header, data).ok()?;
        }
        writer.finish().ok()?;
        drop(writer);
        Some(out.into_inner())
    }
}

/// The seed MCAP files, decoded once per process: structural mutants start from these.
pub(crate) fn decoded(path: &Path) -> McapDoc {
    static CACHE: OnceLock<Mutex<BTreeMap<PathBuf, McapDoc>>> = OnceLock::new();
    let mut cache = CACHE.get_or_init(Default::default).lock().unwrap();
    cache.entry(path.to_path_buf()).or_insert_with(|| McapDoc::decode(&fs::read(path).unwrap())).clone()
}

pub(crate) fn mutate_mcap(rng: &mut ChaCha8Rng, seed: &Path) -> (Vec<u8>, String) {
    let doc = decoded(seed);
    match rng.random_range(0..4) {
        0 => {
            let mut data = fs::read(seed).unwrap();
            let what = stacked(rng, &mut data, mutate_bytes);
            (data, format!("raw bytes: {what}"))
        }
        1 => {
            // Without compression or CRCs a damaged length or opcode reaches the record parser itself.
            let mut data = doc.encode(false, rng.random_bool(0.5), false).unwrap();
            let what = stacked(rng, &mut data, mutate_bytes);
            (data, format!("raw bytes of the uncompressed copy without CRCs: {what}"))
        }
        _ => {
            let mut doc = doc;
            let what =
                (0..rng.random_range(1..=2)).map(|_| mutate_records(rng, &mut doc)).collect::<Vec<_>>().join("; ");
            let (compress, chunked) = (rng.random_bool(0.5), rng.random_bool(0.8));
            match doc.encode(compress, chunked, true) {
                Some(data) => (data, format!("records: {what}")),
                None => {
                    let mut data = fs::read(seed).unwrap();
                    let what = stacked(rng, &mut data, mutate_bytes);
                    (data, format!("raw bytes (records unwritable): {what}"))
                }
            }
        }
    }
}

/// One structural change: a message's JSON, a camera frame's PNG, a metadata value or key, the messages' order,
/// count or headers, a channel or schema field.
pub(crate) fn mutate_records(rng: &mut ChaCha8Rng, doc: &mut McapDoc) -> String {
    let n = doc.messages.len();
    match rng.random_range(0..10) {
        0..=2 if n > 0 => {
            let i = rng.random_range(0..n);
            format!("message {i} JSON: {}", mutate_document(rng, &mut doc.messages[i].1))
        }
        3 if n > 0 => {
            let i = rng.random_range(0..n);
            match mutate_frame_png(rng, &doc.messages[i].1) {
                Some((data, what)) => {
                    doc.messages[i].1 = data;
                    format!("message {i} PNG: {what}")
                }
                None => format!("message {i} JSON: {}", mutate_document(rng, &mut doc.messages[i].1)),
            }
        }
        4 | 5 if !doc.metadata.is_empty() => {
            let record = doc.metadata.choose_mut(rng).unwrap();
            let key = record.metadata.keys().cloned().collect::<Vec<_>>().choose(rng).cloned();
            let Some(key) = key else { return "metadata: empty".into() };
            if rng.random_bool(0.15) {
                record.metadata.remove(&key);
                return format!("metadata: remove '{key}'");
            }
            let mut value = record.metadata[&key].clone().into_bytes();
            let what = mutate_document(rng, &mut value);
            // Metadata strings are UTF-8 in MCAP; the writer takes Rust strings.
            record.metadata.insert(key.clone(), String::from_utf8_lossy(&value).into_owned());
            format!("metadata '{key}': {what}")
        }
        6 if n > 0 => {
            let i = rng.random_range(0..n);
            match rng.random_range(0..3) {
                0 => {
                    doc.messages.remove(i);
                    format!("remove message {i}")
                }
                1 => {
                    let copy = doc.messages[i].clone();
                    doc.messages.insert(rng.random_range(0..=n), copy);
                    format!("duplicate message {i}")
                }
                _ => {
                    let j = rng.random_range(0..n);
                    doc.messages.swap(i, j);
                    format!("swap messages {i} and {j}")
                }
            }
        }
        7 if n > 0 => {
            let i = rng.random_range(0..n);
            let value = *INTERESTING_INTS.choose(rng).unwrap();
            let header = &mut doc.messages[i].0;
            match rng.random_range(0..3) {
                0 => header.sequence = value as u32,
                1 => header.log_time = value,
                _ => header.channel_id = doc.channels.choose(rng).map_or(0, |c| c.id),
            }
            format!("message {i} header: {header:?}")
        }
        8 if !doc.channels.is_empty() => {
            let channel = doc.channels.choose_mut(rng).unwrap();
            let field = if rng.random_bool(0.5) { &mut channel.topic } else { &mut channel.message_encoding };
            let mut bytes = std::mem::take(field).into_bytes();
            let what = mutate_text(rng, &mut bytes);
            *field = String::from_utf8_lossy(&bytes).into_owned();
            format!("channel {}: {what}", channel.id)
        }
        _ if !doc.schemas.is_empty() => {
            let schema = doc.schemas.choose_mut(rng).unwrap();
            if rng.random_bool(0.5) {
                let mut bytes = std::mem::take(&mut schema.2).into_bytes();
                let what = mutate_text(rng, &mut bytes);
                schema.2 = String::from_utf8_lossy(&bytes).into_owned();
                format!("schema {} encoding: {what}", schema.0)
            } else {
                format!("schema {} text: {}", schema.0, mutate_text(rng, &mut schema.3))
            }
        }
        _ => "no change".into(),
    }
}
