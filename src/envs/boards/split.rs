//! Train/test split of board configurations by hash (thesis appendix D.1.4): CRC32 of the canonical
//! comma-separated board string; train when the remainder mod 3 is 0, test otherwise.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Split {
    Train,
    Test,
}

impl Split {
    pub fn as_str(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Test => "test",
        }
    }
}

pub fn split_of(canonical: &str) -> Split {
    if crc32fast::hash(canonical.as_bytes()).is_multiple_of(3) {
        Split::Train
    } else {
        Split::Test
    }
}
