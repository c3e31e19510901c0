//! End to end: board sets, solving boards of every depth optimally, embodied play, bad boards.

use crate::common::*;
use mbrl::data::boardset::read_board_set;
use mbrl::envs::boards::{gf2, BoardGame, LightsOut, Split};

fn plan_length(stdout: &str) -> usize {
    let line = stdout.lines().find(|l| l.starts_with("plan (")).expect("a plan line");
    line["plan (".len()..].split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn random_boards_of_every_depth_get_optimal_plans() {
    let dir = tempfile::tempdir().unwrap();
    let lightsout = LightsOut::new(5).unwrap();
    for depth in 1..=15 {
        let out = mbrl(dir.path())
            .args(["solve-board", "--game", "lightsout", "--model", "true", "-q", "--random-depth"])
            .arg(depth.to_string())
            .arg("--seed")
            .arg(depth.to_string())
            .output()
            .unwrap();
        assert!(out.status.success(), "depth {depth}: {}", stderr_of(&out));
        let stdout = stdout_of(&out);
        assert_eq!(plan_length(&stdout), depth, "{stdout}");
        assert!(stdout.contains("solved: yes"));
        // Independent check of optimality by linear algebra over GF(2).
        let board_line = stdout.lines().next().unwrap();
        let board = lightsout.parse(board_line.split(' ').nth(1).unwrap()).unwrap();
        assert_eq!(gf2::solve(&lightsout, board).unwrap().len(), depth);
    }
    for depth in 1..=16 {
        let out = mbrl(dir.path())
            .args(["solve-board", "--game", "tileswap", "--model", "true", "-q", "--random-depth"])
            .arg(depth.to_string())
            .output()
            .unwrap();
        assert!(out.status.success(), "depth {depth}: {}", stderr_of(&out));
        assert_eq!(plan_length(&stdout_of(&out)), depth);
    }
}

#[test]
fn both_search_algorithms_agree() {
    let dir = tempfile::tempdir().unwrap();
    let board = "1,1,0,0,0,1,0,1,0,0,0,1,1,1,0,0,0,1,0,0,0,0,0,0,0";
    let lengths: Vec<usize> = ["bfs", "bidirectional"]
        .iter()
        .map(|search| {
            let out = mbrl(dir.path())
                .args([
                    "solve-board",
                    "--game",
                    "lightsout",
                    "--model",
                    "true",
                    "-q",
                    "--board",
                    board,
                    "--search",
                    search,
                ])
                .output()
                .unwrap();
            assert!(out.status.success(), "{}", stderr_of(&out));
            plan_length(&stdout_of(&out))
        })
        .collect();
    assert_eq!(lengths[0], lengths[1]);
}

#[test]
fn embodied_play_reaches_the_goal() {
    let dir = tempfile::tempdir().unwrap();
    for (game, embodiment) in [("lightsout", "cursor"), ("tileswap", "reacher")] {
        let out = mbrl(dir.path())
            .args(["solve-board", "--game", game, "--model", "true", "-q", "--random-depth", "4", "--split", "test"])
            .args(["--embodiment", embodiment])
            .output()
            .unwrap();
        assert!(out.status.success(), "{game}/{embodiment}: {}", stderr_of(&out));
        assert!(stdout_of(&out).contains("4 of 4 moves performed"), "{}", stdout_of(&out));
    }
}

#[test]
fn scripted_controllers_solve_at_least_99_percent_of_test_boards() {
    let dir = tempfile::tempdir().unwrap();
    for (game, embodiment) in
        [("lightsout", "cursor"), ("tileswap", "cursor"), ("lightsout", "reacher"), ("tileswap", "reacher")]
    {
        let out = mbrl(dir.path())
            .args([
                "eval",
                "embodied",
                "--game",
                game,
                "--embodiment",
                embodiment,
                "--max-depth",
                "5",
                "--boards",
                "40",
            ])
            .args(["-q", "--out", &format!("{game}-{embodiment}")])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", stderr_of(&out));
        let csv = std::fs::read_to_string(dir.path().join(format!("{game}-{embodiment}/embodied.csv"))).unwrap();
        let (mut boards, mut solved) = (0, 0);
        for line in csv.lines().skip(1) {
            let cols: Vec<&str> = line.split(',').collect();
            boards += cols[1].parse::<usize>().unwrap();
            solved += cols[2].parse::<usize>().unwrap();
        }
        assert!(boards >= 150, "{csv}");
        assert!(solved as f64 >= 0.99 * boards as f64, "{game}/{embodiment}: {solved}/{boards}");
    }
}

#[test]
fn board_sets_hold_every_board_with_its_split() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["collect", "--env", "lightsout", "--boards", "--max-depth", "3", "--out", "lo.mcap", "-q"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let set = read_board_set(&dir.path().join("lo.mcap")).unwrap();
    assert_eq!(set.boards.len(), 25 + 300 + 2300);
    let train_depth_1 = set.boards.iter().filter(|b| b.depth == 1 && b.split == Split::Train).count();
    assert_eq!(train_depth_1, 7, "thesis Table 7.2");
    assert!(set.boards.iter().all(|b| b.symbolic.len() == 25));
    mbrl(dir.path())
        .args([
            "collect",
            "--env",
            "tileswap",
            "--boards",
            "--max-depth",
            "2",
            "--split",
            "test",
            "--out",
            "ts.mcap",
            "-q",
        ])
        .assert()
        .success();
    let ts = read_board_set(&dir.path().join("ts.mcap")).unwrap();
    assert_eq!(ts.boards.len(), 5 + 57);
}

#[test]
fn eval_boards_reproduces_table_7_1() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path()).args(["eval", "boards", "--out", "rep", "-q"]).output().unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    let report = std::fs::read_to_string(dir.path().join("rep/report.md")).unwrap();
    assert!(report.contains("Rows differing from Table 7.1: 0."), "{report}");
    assert!(report.contains("| lightsout-5x5 | 15 | 7350 |"), "{report}");
}

#[test]
fn bad_boards_get_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let run = |game: &str, board: &str| {
        mbrl(dir.path()).args(["solve-board", "--game", game, "--model", "true", "--board", board]).output().unwrap()
    };
    assert_one_line_error(&run("lightsout", "0,1,1"), &["expected 25", "got 3"]);
    let non_binary = ["0"; 24].join(",") + ",2";
    assert_one_line_error(&run("lightsout", &non_binary), &["field 24 is '2'"]);
    assert_one_line_error(&run("tileswap", "0,1,2,3,4,5,6,8,8"), &["chip 8 appears on fields 7 and 8"]);
    let corner = "1,".to_string() + &["0"; 24].join(",");
    assert_one_line_error(&run("lightsout", &corner), &["cannot be solved"]);
    let out =
        mbrl(dir.path()).args(["solve-board", "--game", "chess", "--model", "true", "--board", "0"]).output().unwrap();
    assert_one_line_error(&out, &["chess", "lightsout", "tileswap"]);
    let out = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsout", "--model", "true", "--random-depth", "16"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["depth 16", "15"]);
}

#[test]
fn search_budget_stops_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let out = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsout", "--model", "true", "--random-depth", "12", "--search", "bfs"])
        .args(["--max-nodes", "10000", "-q"])
        .output()
        .unwrap();
    assert_one_line_error(&out, &["node budget of 10000"]);
}

#[test]
fn larger_lightsout_boards_are_solved_from_given_boards() {
    let dir = tempfile::tempdir().unwrap();
    let game = LightsOut::new(7).unwrap();
    let board = game.pressed(&[0, 10, 24, 40, 48]);
    let out = mbrl(dir.path())
        .args(["solve-board", "--game", "lightsout:7x7", "--model", "true", "-q", "--board"])
        .arg(game.canonical_string(board))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr_of(&out));
    assert_eq!(plan_length(&stdout_of(&out)), gf2::solve(&game, board).unwrap().len());
}
