//! Board sets on disk: MCAP with one `mbrl.Board` message per board and an `mbrl.boardset` metadata
//! record (datasets/README.md).

use std::collections::BTreeMap;
use std::path::Path;

use super::mcap_io::{check_version, metadata_field, metadata_seed, read_messages, write_messages, Layout};
use crate::envs::boards::sets::BoardRecord;
use crate::error::Result;

pub const BOARDSET_VERSION: u32 = 1;
pub const METADATA_NAME: &str = "mbrl.boardset";
pub const TOPIC: &str = "/boards";
const SCHEMA_NAME: &str = "mbrl.Board";
const SCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "mbrl.Board",
  "description": "A board configuration with its optimal solution depth and train/test split.",
  "type": "object",
  "required": ["board", "depth", "split", "symbolic"],
  "properties": {
    "board": {"type": "string", "description": "canonical comma-separated board (field values row-major)"},
    "depth": {"type": "integer", "minimum": 0, "description": "moves in a shortest solution"},
    "split": {"enum": ["train", "test"], "description": "CRC32(board) mod 3 == 0 -> train"},
    "symbolic": {"type": "array", "items": {"enum": [0, 1]}, "description": "symbolic observation"}
  }
}"#;

#[derive(Clone, Debug, PartialEq)]
pub struct BoardSet {
    pub game: String,
    pub seed: u64,
    pub command_line: String,
    pub mbrl_version: String,
    pub boards: Vec<BoardRecord>,
}

const LAYOUT: Layout<'static> =
    Layout { metadata_name: METADATA_NAME, topic: TOPIC, schema_name: SCHEMA_NAME, schema: SCHEMA, tick_ns: 1_000_000 };

pub fn write_board_set(path: &Path, set: &BoardSet) -> Result<()> {
    let metadata = BTreeMap::from([
        ("format_version".to_string(), BOARDSET_VERSION.to_string()),
        ("game".to_string(), set.game.clone()),
        ("seed".to_string(), set.seed.to_string()),
        ("mbrl_version".to_string(), set.mbrl_version.clone()),
        ("command_line".to_string(), set.command_line.clone()),
    ]);
    write_messages(path, &LAYOUT, metadata, &set.boards)
}

pub fn read_board_set(path: &Path) -> Result<BoardSet> {
    let (meta, messages) = read_messages::<BoardRecord>(path, METADATA_NAME, TOPIC)?;
    check_version(path, &meta, BOARDSET_VERSION)?;
    let field = |key: &str| metadata_field(path, &meta, key);
    Ok(BoardSet {
        game: field("game")?,
        seed: metadata_seed(path, &meta)?,
        command_line: field("command_line")?,
        mbrl_version: field("mbrl_version")?,
        boards: messages.into_iter().map(|(_, b)| b).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::boards::Split;

    #[test]
    fn board_sets_round_trip_and_are_not_rollout_datasets() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.mcap");
        let set = BoardSet {
            game: "tileswap".into(),
            seed: 0,
            command_line: "mbrl collect".into(),
            mbrl_version: crate::VERSION.into(),
            boards: vec![BoardRecord {
                board: "1,0,2,3,4,5,6,7,8".into(),
                depth: 1,
                split: Split::Test,
                symbolic: vec![0, 1],
            }],
        };
        write_board_set(&path, &set).unwrap();
        assert_eq!(read_board_set(&path).unwrap(), set);
        let err = crate::data::read_dataset(&path).unwrap_err().to_string();
        assert!(err.contains("expected a 'mbrl.dataset' metadata record, found mbrl.boardset"), "{err}");
    }
}
