//! Every message mbrl writes under a Foxglove schema name validates against Foxglove's published JSON schema
//! (tests/fixtures/foxglove): ball recordings and filter estimates as `foxglove.SceneUpdate` (3D panel),
//! rendered frames as `foxglove.CompressedImage` (Image panel). Read with the official Python MCAP reader and
//! checked with the `jsonschema` package when both are installed.

use crate::common::mbrl;

const CHECK: &str = r#"
import json, sys
from mcap.reader import make_reader
import jsonschema

fixtures = sys.argv[1]
def validator(name):
    schema = json.load(open(f"{fixtures}/{name.split('.')[1]}.json"))
    return jsonschema.validators.validator_for(schema)(schema)
schemas = {name: validator(name) for name in ["foxglove.SceneUpdate", "foxglove.CompressedImage"]}
counts = {}
for path in sys.argv[2:]:
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if schema.name in schemas:
                schemas[schema.name].validate(json.loads(message.data))
                key = f"{path}:{channel.topic}:{schema.name}"
                counts[key] = counts.get(key, 0) + 1
for key in sorted(counts):
    print(key, counts[key])
"#;

#[test]
fn foxglove_messages_validate_against_the_published_schemas() {
    let python_ready = std::process::Command::new("python3").args(["-c", "import mcap, jsonschema"]).output();
    if !python_ready.is_ok_and(|o| o.status.success()) {
        eprintln!("python3 with the mcap and jsonschema packages is not installed; skipped");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    mbrl(d).args(["collect", "--env", "ball", "--trajectories", "2", "--out", "ball.mcap", "-q"]).assert().success();
    mbrl(d)
        .args(["filter", "--model", "thesis", "--input", "ball.mcap", "--out", "est.csv", "--mcap", "est.mcap", "-q"])
        .assert()
        .success();
    mbrl(d)
        .args([
            "collect",
            "--env",
            "pendulum",
            "--images",
            "--rollouts",
            "2",
            "--steps",
            "3",
            "--out",
            "img.mcap",
            "-q",
        ])
        .assert()
        .success();
    let fixtures = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/foxglove");
    let out = std::process::Command::new("python3")
        .args(["-c", CHECK, fixtures, "ball.mcap", "est.mcap", "img.mcap"])
        .current_dir(d)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}\n{}", text, String::from_utf8_lossy(&out.stderr));
    let count = |key: &str| -> usize {
        text.lines().find(|l| l.starts_with(key)).and_then(|l| l.rsplit(' ').next()?.parse().ok()).unwrap_or(0)
    };
    let recordings = mbrl::data::ball_io::read_ball_dataset(&d.join("ball.mcap")).unwrap();
    let measured: usize = recordings.recordings.iter().map(|r| r.measured()).sum();
    // One update per measured frame, plus one for a trajectory that opens with a lost frame.
    let scene = count("ball.mcap:/ball/scene:foxglove.SceneUpdate");
    assert!((measured..=measured + 2).contains(&scene), "{scene} updates for {measured} measured frames\n{text}");
    assert!(count("est.mcap:/ball/estimates/scene:foxglove.SceneUpdate") > 300, "{text}");
    assert_eq!(count("img.mcap:/frames:foxglove.CompressedImage"), 8, "{text}");
}
