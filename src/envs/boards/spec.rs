//! Board game names on the command line: `lightsout` (5×5), `lightsout:<n>x<n>`, `tileswap`.

use super::lightsout::MAX_SIDE;
use crate::error::{Error, Result};
use crate::util::suggest::did_you_mean;

pub const GAME_HELP: &str = "lightsout (5x5), lightsout:<n>x<n> (n = 2..13), tileswap";

/// The games by their default names (LightsOut's other sizes are `lightsout:<n>x<n>`).
pub const GAME_NAMES: [&str; 2] = ["lightsout", "tileswap"];

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GameSpec {
    LightsOut(usize),
    TileSwap,
}

impl GameSpec {
    pub fn parse(name: &str) -> Result<Self> {
        let bad = || {
            let sizes: Vec<String> = (2..=MAX_SIDE).map(|n| format!("lightsout:{n}x{n}")).collect();
            let hint = did_you_mean(name, GAME_NAMES.into_iter().chain(sizes.iter().map(String::as_str)));
            Error::config(format!("unknown board game '{name}'{hint}; supported: {GAME_HELP}"))
        };
        let (family, size) = name.split_once(':').unwrap_or((name, ""));
        match family {
            "lightsout" if size.is_empty() => Ok(GameSpec::LightsOut(5)),
            "lightsout" => {
                let (a, b) = size.split_once('x').ok_or_else(bad)?;
                let n: usize = a.parse().map_err(|_| bad())?;
                if a != b || !(2..=MAX_SIDE).contains(&n) {
                    return Err(bad());
                }
                Ok(GameSpec::LightsOut(n))
            }
            "tileswap" if size.is_empty() || size == "3x3" => Ok(GameSpec::TileSwap),
            _ => Err(bad()),
        }
    }

    pub fn name(&self) -> String {
        match self {
            GameSpec::LightsOut(5) => "lightsout".into(),
            GameSpec::LightsOut(n) => format!("lightsout:{n}x{n}"),
            GameSpec::TileSwap => "tileswap".into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_sizes_and_rejects_the_rest() {
        assert_eq!(GameSpec::parse("lightsout").unwrap(), GameSpec::LightsOut(5));
        assert_eq!(GameSpec::parse("lightsout:7x7").unwrap(), GameSpec::LightsOut(7));
        assert_eq!(GameSpec::parse("tileswap").unwrap(), GameSpec::TileSwap);
        for bad in ["lightsout:7x8", "lightsout:14x14", "tileswap:4x4", "chess"] {
            let err = GameSpec::parse(bad).unwrap_err().to_string();
            assert!(err.contains(bad) && err.contains("tileswap"), "{err}");
        }
    }
}
