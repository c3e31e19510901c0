//! Every protocol ends in a serde summary: `summary.json` beside the report holds everything report.md, the CSVs
//! and the PNGs are drawn from, tagged with its protocol, so `mbrl eval render DIR` can redraw the report
//! without the models or the simulators; `config.json` holds the protocol's typed settings and provenance,
//! so `mbrl eval <protocol> --config DIR/config.json` can rerun it.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::ball::{BallConfig, BallEvalSummary};
use super::boards::{BoardsConfig, BoardsSummary, EmbodiedConfig, EmbodiedSummary};
use super::context::{ContextEvalConfig, ContextEvalSummary};
use super::dataset_report::{DatasetConfig, DatasetSummary};
use super::dlgpd::{DlgpdEvalConfig, DlgpdEvalSummary};
use super::quick::{QuickConfig, QuickSummary};
use super::seads::{SeadsComparison, SeadsEvalConfig, SeadsEvalSummary};
use super::swingup::{SwingupConfig, SwingupSummary};
use super::tradyn::{TradynEvalConfig, TradynEvalSummary};
use crate::error::{Error, Result};
use crate::run::dir::{Provenance, CONFIG_FILE};
use crate::util::atomic::write_json;

pub const SUMMARY_FILE: &str = "summary.json";

/// A report's summary, as `summary.json` holds it.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(tag = "protocol", rename_all = "kebab-case")]
#[allow(clippy::large_enum_variant)] // one per command, read once
pub enum Summary {
    PendulumSwingup(SwingupSummary),
    Dataset(DatasetSummary),
    Boards(BoardsSummary),
    Embodied(EmbodiedSummary),
    Ball(BallEvalSummary),
    Context(ContextEvalSummary),
    Tradyn(TradynEvalSummary),
    Seads(SeadsEvalSummary),
    SeadsCompare(SeadsComparison),
    Dlgpd(DlgpdEvalSummary),
    Quick(QuickSummary),
}

impl Summary {
    pub fn protocol(&self) -> &'static str {
        match self {
            Summary::PendulumSwingup(_) => "pendulum-swingup",
            Summary::Dataset(_) => "dataset",
            Summary::Boards(_) => "boards",
            Summary::Embodied(_) => "embodied",
            Summary::Ball(_) => "ball",
            Summary::Context(_) => "context",
            Summary::Tradyn(_) => "tradyn",
            Summary::Seads(_) => "seads",
            Summary::SeadsCompare(_) => "seads-compare",
            Summary::Dlgpd(_) => "dlgpd",
            Summary::Quick(_) => "quick",
        }
    }

    /// Writes report.md, the CSVs and the PNGs of this summary into `dir`.
    pub fn render(&self, dir: &Path) -> Result<()> {
        match self {
            Summary::PendulumSwingup(s) => super::swingup::render(s, dir),
            Summary::Dataset(s) => super::dataset_report::render(s, dir),
            Summary::Boards(s) => super::boards::render_depths(s, dir),
            Summary::Embodied(s) => super::boards::render_embodied(s, dir),
            Summary::Ball(s) => super::ball::render(s, dir),
            Summary::Context(s) => super::context::render(s, dir),
            Summary::Tradyn(s) => super::tradyn::render(s, dir),
            Summary::Seads(s) => super::seads::render(s, dir),
            Summary::SeadsCompare(s) => super::seads::render_comparison(s, dir),
            Summary::Dlgpd(s) => super::dlgpd::render(s, dir),
            Summary::Quick(s) => super::quick_report::render(s, dir),
        }
    }

    /// Reads `dir/summary.json`; a bad file is an error naming the file and, where it can, the field.
    pub fn load(dir: &Path) -> Result<Summary> {
        let path = dir.join(SUMMARY_FILE);
        let (text, protocol) = read_protocol(&path, "summary")?;
        // Each body is read on its own, not through the tagged enum, so that an error keeps its line and
        // column (and so the field it is in).
        Ok(match protocol.as_str() {
            "pendulum-swingup" => Summary::PendulumSwingup(body(&path, &text)?),
            "dataset" => Summary::Dataset(body(&path, &text)?),
            "boards" => Summary::Boards(body(&path, &text)?),
            "embodied" => Summary::Embodied(body(&path, &text)?),
            "ball" => Summary::Ball(body(&path, &text)?),
            "context" => Summary::Context(body(&path, &text)?),
            "tradyn" => Summary::Tradyn(body(&path, &text)?),
            "seads" => Summary::Seads(body(&path, &text)?),
            "seads-compare" => Summary::SeadsCompare(body(&path, &text)?),
            "dlgpd" => Summary::Dlgpd(body(&path, &text)?),
            "quick" => Summary::Quick(body(&path, &text)?),
            other => return Err(unknown(&path, other, &KNOWN)),
        })
    }
}

/// What `mbrl eval render` prints: the summary's result lines, as the protocol's own command printed them.
impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Summary::PendulumSwingup(s) => s.fmt(f),
            Summary::Dataset(s) => s.fmt(f),
            Summary::Boards(s) => s.fmt(f),
            Summary::Embodied(s) => s.fmt(f),
            Summary::Ball(s) => s.fmt(f),
            Summary::Context(s) => s.fmt(f),
            Summary::Tradyn(s) => s.fmt(f),
            Summary::Seads(s) => s.fmt(f),
            Summary::SeadsCompare(s) => s.fmt(f),
            Summary::Dlgpd(s) => s.fmt(f),
            Summary::Quick(s) => s.fmt(f),
        }
    }
}

/// A protocol's typed settings, as its report's `config.json` records them beside the provenance.
pub trait ProtocolConfig: Serialize + serde::de::DeserializeOwned {
    const PROTOCOL: &'static str;
}

impl ProtocolConfig for SwingupConfig {
    const PROTOCOL: &'static str = super::swingup::PROTOCOL;
}
impl ProtocolConfig for DatasetConfig {
    const PROTOCOL: &'static str = super::dataset_report::PROTOCOL;
}
impl ProtocolConfig for BoardsConfig {
    const PROTOCOL: &'static str = super::boards::BOARDS_PROTOCOL;
}
impl ProtocolConfig for EmbodiedConfig {
    const PROTOCOL: &'static str = super::boards::EMBODIED_PROTOCOL;
}
impl ProtocolConfig for BallConfig {
    const PROTOCOL: &'static str = super::ball::PROTOCOL;
}
impl ProtocolConfig for ContextEvalConfig {
    const PROTOCOL: &'static str = super::context::PROTOCOL;
}
impl ProtocolConfig for TradynEvalConfig {
    const PROTOCOL: &'static str = super::tradyn::PROTOCOL;
}
impl ProtocolConfig for SeadsEvalConfig {
    const PROTOCOL: &'static str = super::seads::PROTOCOL;
}
impl ProtocolConfig for DlgpdEvalConfig {
    const PROTOCOL: &'static str = super::dlgpd::PROTOCOL;
}
impl ProtocolConfig for QuickConfig {
    const PROTOCOL: &'static str = super::quick::PROTOCOL;
}

/// The settings and provenance a `config.json` of protocol `T` recorded; a config of another protocol is an
/// error that names the protocol it records.
pub fn read_config<T: ProtocolConfig>(path: &Path) -> Result<(T, Provenance)> {
    let (text, protocol) = read_protocol(path, "config")?;
    if protocol != T::PROTOCOL {
        if !KNOWN.contains(&protocol.as_str()) {
            return Err(unknown(path, &protocol, &KNOWN[..KNOWN.len() - 1]));
        }
        return Err(Error::bad_file(
            path,
            format!(
                "records `eval {protocol}`, not `eval {}`; rerun it with `mbrl eval {protocol} --config {}`",
                T::PROTOCOL,
                path.display()
            ),
        ));
    }
    let record: ConfigBody<T> = body(path, &text)?;
    Ok((record.settings, record.provenance))
}

#[derive(Serialize)]
struct Tagged<'a, T> {
    protocol: &'a str,
    #[serde(flatten)]
    body: &'a T,
}

#[derive(Serialize)]
struct ConfigRecord<'a, T> {
    protocol: &'a str,
    settings: &'a T,
    provenance: &'a Provenance,
}

/// Writes `dir/summary.json` (atomically) and renders the report from that same summary.
pub(crate) fn publish<T: Serialize>(
    protocol: &str,
    summary: &T,
    dir: &Path,
    render: impl FnOnce(&T, &Path) -> Result<()>,
) -> Result<()> {
    write_json(&dir.join(SUMMARY_FILE), &Tagged { protocol, body: summary })?;
    render(summary, dir)
}

/// Writes `dir/config.json`: what `--config` reads back.
pub(crate) fn write_config<T: ProtocolConfig>(settings: &T, provenance: &Provenance, dir: &Path) -> Result<()> {
    write_json(&dir.join(CONFIG_FILE), &ConfigRecord { protocol: T::PROTOCOL, settings, provenance })
}

/// A config.json without its `protocol` (dispatched on before).
#[derive(Deserialize)]
struct ConfigBody<T> {
    settings: T,
    provenance: Provenance,
}

/// The file's text and the protocol it names.
fn read_protocol(path: &Path, what: &str) -> Result<(String, String)> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| Error::bad_file(path, format!("not JSON ({e}); expected a report's {what} file")))?;
    let protocol = value.get("protocol").and_then(|p| p.as_str()).ok_or_else(|| {
        Error::bad_file(path, format!("no \"protocol\" field; expected a {what} written by `mbrl eval`"))
    })?;
    let protocol = protocol.to_string();
    Ok((text, protocol))
}

fn unknown(path: &Path, protocol: &str, known: &[&str]) -> Error {
    Error::bad_file(path, format!("field `protocol`: unknown protocol '{protocol}'; known: {}", known.join(", ")))
}

fn body<T: serde::de::DeserializeOwned>(path: &Path, text: &str) -> Result<T> {
    serde_json::from_str(text).map_err(|e| {
        let field = field_at(text, e.line(), e.column()).map(|f| format!("field `{f}`: ")).unwrap_or_default();
        Error::bad_file(path, format!("{field}{e}"))
    })
}

/// The protocols a summary can name; a config names all but `seads-compare`.
const KNOWN: [&str; 11] = [
    "pendulum-swingup",
    "dataset",
    "boards",
    "embodied",
    "ball",
    "context",
    "tradyn",
    "seads",
    "dlgpd",
    "quick",
    "seads-compare",
];

/// The key on the line where a pretty-printed JSON value failed to read (serde reports a position, not a path).
fn field_at(text: &str, line: usize, column: usize) -> Option<String> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let before = &row[..row.char_indices().map(|(i, _)| i).find(|&i| i >= column).unwrap_or(row.len())];
    let end = before.rfind("\":")?;
    let start = before[..end].rfind('"')?;
    Some(before[start + 1..end].to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_failing_field_is_named_from_its_line() {
        let text = "{\n  \"protocol\": \"boards\",\n  \"median\": null\n}";
        assert_eq!(field_at(text, 3, 17).as_deref(), Some("median"));
        assert_eq!(field_at(text, 9, 1), None);
    }
}
