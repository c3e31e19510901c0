//! TRADYN's world from the command line: terrain map sets, unicycle datasets on one split of them, replays of
//! given actions on a user's map, and the errors bad maps and start states give.

use std::path::Path;
use std::sync::Arc;

use crate::common::*;
use mbrl::data::{instance_pairs, read_dataset};
use mbrl::envs::terrain::TerrainMap;
use mbrl::envs::unicycle::UnicycleTerrain;
use mbrl::envs::{instance_env, EnvName};

fn collect(dir: &Path, args: &[&str]) -> std::process::Output {
    mbrl(dir).arg("collect").args(args).arg("-q").output().unwrap()
}

fn succeed(dir: &Path, args: &[&str]) {
    let out = collect(dir, args);
    assert!(out.status.success(), "{}", stderr_of(&out));
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    names
}

fn write_png(path: &Path, width: u32, height: u32, color: png::ColorType, pixels: &[u8]) {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer.write_image_data(pixels).unwrap();
    writer.finish().unwrap();
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn map_sets_split_and_unicycle_pairs_are_drawn_on_the_chosen_split() {
    let dir = tempfile::tempdir().unwrap();
    succeed(dir.path(), &["--env", "terrain", "--maps", "4", "--out", "maps", "--seed", "3"]);
    assert_eq!(
        names_in(&dir.path().join("maps")),
        ["map000.png", "map001.png", "map002.png", "map003.png", "terrain.json"]
    );

    let args = ["--env", "unicycle", "--maps", "maps", "--split", "test", "--instances", "12", "--steps", "40"];
    succeed(dir.path(), &[&args[..], &["--out", "a.mcap"]].concat());
    succeed(dir.path(), &[&args[..], &["--out", "b.mcap"]].concat());
    let data = read_dataset(&dir.path().join("a.mcap")).unwrap();
    let again = read_dataset(&dir.path().join("b.mcap")).unwrap();
    assert!(data.steps == again.steps && data.meta.instances == again.meta.instances, "same seed, same data");
    assert_eq!(data.meta.env, "unicycle");
    let maps: std::collections::BTreeSet<&str> =
        data.meta.instances.iter().map(|p| p["map"].as_str().unwrap()).collect();
    assert_eq!(maps.into_iter().collect::<Vec<_>>(), ["map002.png", "map003.png"], "test split only, both used");
    let pairs = instance_pairs(&data).unwrap();
    assert_eq!(pairs.len(), 12);
    for step in &data.steps {
        let obs = step.next_obs.as_ref().unwrap();
        assert_eq!(obs.len(), 8);
        assert!((0.0..=1.0).contains(&obs[0]) && (0.0..=1.0).contains(&obs[1]) && obs[2].abs() <= 1.0);
        assert!(step.action.iter().all(|a| a.abs() <= 1.0));
    }
    // Colored noise (β 0.5): neighbouring actions are correlated, unlike uniform exploration.
    let throttle: Vec<f64> = data.steps.iter().map(|s| s.action[0]).collect();
    let (mut num, mut den) = (0.0, 0.0);
    for w in throttle.windows(2) {
        num += w[0] * w[1];
        den += w[0] * w[0];
    }
    assert!(num / den > 0.2, "lag-1 correlation {}", num / den);
}

#[test]
fn a_replay_on_a_user_map_steps_the_simulator_with_the_given_actions() {
    let dir = tempfile::tempdir().unwrap();
    // A user's map at another size: left half (small x: top rows) white, bottom half black.
    let (w, h) = (100u32, 80u32);
    let pixels: Vec<u8> = (0..h).flat_map(|row| [if row < h / 2 { 255u8 } else { 0 }; 3].repeat(w as usize)).collect();
    write_png(&dir.path().join("user.png"), w, h, png::ColorType::Rgb, &pixels);
    std::fs::write(dir.path().join("a.csv"), "throttle,steer\n1,0\n0.5,0.3\n-2,1\n0,0\n0,-0.5\n").unwrap();
    succeed(
        dir.path(),
        &[
            "--env",
            "unicycle",
            "--map",
            "user.png",
            "--actions",
            "a.csv",
            "--init-state",
            "0.2,0.3,0,1.57",
            "--instance-seed",
            "5",
            "--out",
            "r.mcap",
        ],
    );
    let data = read_dataset(&dir.path().join("r.mcap")).unwrap();
    let map = TerrainMap::read_png(&dir.path().join("user.png")).unwrap();
    assert_eq!(map.friction_at(0.2, 0.5), 0.1, "white: lowest friction");
    assert!((map.friction_at(0.8, 0.5) - 10.0).abs() < 1e-9, "black: highest");
    let env = EnvName::Unicycle(Some(Arc::new(UnicycleTerrain::new(vec![map]))));
    let mut sim = instance_env(&env, 5).unwrap();
    sim.set_state(&[0.2, 0.3, 0.0, 1.57]);
    assert_eq!(data.meta.instances, vec![sim.params()]);
    for step in &data.steps {
        assert_eq!(step.state, sim.state());
        let next = sim.step(&step.action);
        assert_eq!((step.next_state.clone(), step.reward), (sim.state(), next.reward));
        assert_eq!(step.next_obs.as_ref(), Some(&next.obs));
    }
    assert_eq!(data.steps[2].reward, -0.5, "the throttle −2 is clipped to −1 before it costs energy");
}

#[test]
fn bad_maps_sets_and_start_states_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.csv"), "0.5,0\n").unwrap();
    std::fs::write(d.join("notes.png"), "not an image").unwrap();
    write_png(&d.join("rgba.png"), 2, 2, png::ColorType::Rgba, &[9; 16]);
    write_png(&d.join("gray.png"), 2, 2, png::ColorType::Grayscale, &[9; 4]);
    write_png(&d.join("ok.png"), 2, 2, png::ColorType::Rgb, &[9; 12]);
    std::fs::create_dir(d.join("empty")).unwrap();
    // A header that declares 16000 × 16000 pixels over a few bytes of data.
    let mut huge = std::fs::read(d.join("ok.png")).unwrap();
    huge[16..24].copy_from_slice(&[0, 0, 0x3e, 0x80, 0, 0, 0x3e, 0x80]);
    let crc = crc32fast::hash(&huge[12..29]);
    huge[29..33].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(d.join("huge.png"), huge).unwrap();
    let replay =
        |map: &str| ["--env", "unicycle", "--map", map, "--actions", "a.csv", "--out", "bad.mcap"].map(String::from);
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (replay("notes.png").to_vec(), vec!["notes.png", "not a readable PNG"]),
        (replay("rgba.png").to_vec(), vec!["rgba.png", "Rgba", "expected 8-bit RGB"]),
        (replay("gray.png").to_vec(), vec!["gray.png", "Grayscale", "expected 8-bit RGB"]),
        (replay("missing.png").to_vec(), vec!["missing.png"]),
        (replay("huge.png").to_vec(), vec!["huge.png", "16000 × 16000", "bytes can hold"]),
        (
            [&replay("ok.png")[..], &["--init-state".into(), "1.5,0.5,0,0".into()]].concat(),
            vec!["--init-state", "outside the map"],
        ),
        (
            [&replay("ok.png")[..], &["--init-state".into(), "0.5,0.5,7,0".into()]].concat(),
            vec!["--init-state", "speed 7"],
        ),
        (
            ["--env", "unicycle", "--instances", "2", "--out", "bad.mcap"].map(String::from).to_vec(),
            vec!["--map", "--maps"],
        ),
        (
            ["--env", "unicycle", "--maps", "empty", "--split", "train", "--out", "bad.mcap"]
                .map(String::from)
                .to_vec(),
            vec!["empty", "terrain.json"],
        ),
        (["--env", "unicycle", "--maps", "empty", "--out", "bad.mcap"].map(String::from).to_vec(), vec!["--split"]),
        (["--env", "terrain", "--maps", "many"].map(String::from).to_vec(), vec!["--maps", "'many'"]),
        (["--env", "terrain", "--maps", "0"].map(String::from).to_vec(), vec!["--maps", "1..="]),
        (["--env", "pendulum", "--map", "ok.png"].map(String::from).to_vec(), vec!["--map", "unicycle"]),
    ];
    for (args, needles) in cases {
        let out = collect(d, &args.iter().map(String::as_str).collect::<Vec<_>>());
        assert_one_line_error(&out, &needles);
        assert!(!d.join("bad.mcap").exists(), "{args:?} wrote output");
    }
    // A map set is never written into a directory that holds something else.
    std::fs::write(d.join("empty/keep.txt"), "x").unwrap();
    let out = collect(d, &["--env", "terrain", "--maps", "2", "--out", "empty"]);
    assert_one_line_error(&out, &["empty", "not empty"]);
    assert_eq!(names_in(&d.join("empty")), ["keep.txt"]);
    assert_eq!(names_in(d).iter().filter(|n| n.starts_with('.')).count(), 0, "no staging directory left");
}
