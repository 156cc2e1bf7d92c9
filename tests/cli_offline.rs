//! `primm generate`, `primm track` and `primm eval` as a user runs them.

use std::path::Path;
use std::process::Command;

fn primm(args: &[&str]) -> std::process::Output {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(output.status.success(), "primm {args:?} failed:\n{}", String::from_utf8_lossy(&output.stderr));
    output
}

fn generate(dir: &Path) {
    primm(&[
        "generate",
        "--output",
        dir.to_str().unwrap(),
        "--split",
        "evaluation",
        "--sequences",
        "2",
        "--duration-s",
        "3",
    ]);
}

#[test]
fn track_writes_one_row_per_measurement_with_consistent_columns() {
    let dir = tempdir("track");
    generate(&dir);
    let input = dir.join("evaluation/evaluation_0000.csv");
    let output = dir.join("tracks.csv");
    primm(&[
        "track",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
        "--method",
        "imm",
    ]);
    let sequence = primm_sim::io::read_sequence_file(&input).unwrap();
    let text = std::fs::read_to_string(&output).unwrap();
    let mut lines = text.lines();
    // The generated sequence carries ego poses: tracked in the world frame, with its columns.
    let header =
        format!("{},{}", primm_sim::io::track_csv::TRACK_CSV_HEADER, primm_sim::io::track_csv::WORLD_COLUMNS);
    assert_eq!(lines.next(), Some(header.as_str()));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // Every measurement updated or started exactly one track.
    assert_eq!(rows.len(), sequence.measurement_count());
    for row in &rows {
        assert_eq!(row.len(), 42);
        assert!(["tentative", "confirmed", "coasting"].contains(&row[13]), "status {}", row[13]);
        let existence: f64 = row[14].parse().unwrap();
        assert!(existence > 0.0 && existence < 1.0, "existence {existence}");
        // vx, vy, age_s, then the upper triangle of the 4x4 covariance: its diagonal positive.
        let numbers: Vec<f64> = row[15..42].iter().map(|v| v.parse::<f64>().unwrap()).collect();
        assert!(numbers.iter().all(|v| v.is_finite()), "{numbers:?}");
        assert!(numbers[2] >= 0.0, "age {}", numbers[2]);
        for diagonal in [3, 7, 10, 12] {
            assert!(numbers[diagonal] > 0.0, "covariance diagonal {diagonal}: {numbers:?}");
        }
        let world = &numbers[13..];
        assert!(world[4] > 0.0 && world[13] > 0.0, "world covariance {world:?}");
        let mu: f64 = row[9..13].iter().map(|v| v.parse::<f64>().unwrap()).sum();
        assert!((mu - 1.0).abs() < 1e-9, "mode probabilities sum to {mu}");
        assert_eq!(row[9], "0", "the IMM method has no PR mode");
    }
}

#[test]
fn eval_prints_the_tables_and_writes_json_and_figures() {
    let dir = tempdir("eval");
    generate(&dir);
    let json = dir.join("eval.json");
    let plots = dir.join("plots");
    let output = primm(&[
        "eval",
        "--data",
        dir.join("evaluation").to_str().unwrap(),
        "--methods",
        "cv,imm",
        "--json",
        json.to_str().unwrap(),
        "--plots",
        plots.to_str().unwrap(),
    ]);
    let text = String::from_utf8(output.stdout).unwrap();
    for table in ["Table II", "Table III", "Table IV", "Table V", "Confirmed tracks ("] {
        assert!(text.contains(table), "{table} missing:\n{text}");
    }
    let value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    for method in ["cv", "imm"] {
        let result = &value["methods"][method];
        let rmse = result["rmse_xy"].as_f64().unwrap();
        assert!(rmse > 0.0 && rmse < 10.0, "{method} rmse_xy {rmse}");
        let idf1 = result["idf1"].as_f64().unwrap();
        assert!(idf1 > 0.5 && idf1 <= 1.0, "{method} idf1 {idf1}");
        assert!(result["idsw"].as_u64().is_some());
        // Confirmed tracks only: fewer estimated frames and matches, the same ground truth.
        let confirmed = &result["confirmed_tracks"];
        let count =
            |key: &str| confirmed[key].as_u64().unwrap_or_else(|| panic!("{method} {key}: {confirmed}"));
        let paper = |key: &str| result["counts"][key].as_u64().unwrap();
        assert_eq!(count("gt_object_frames"), paper("gt_object_frames"));
        assert!(count("estimated_object_frames") < paper("estimated_object_frames"), "{confirmed}");
        assert!(count("idtp") <= paper("idtp"), "{confirmed}");
        assert_eq!(count("idtp") + count("idfp"), count("estimated_object_frames"));
        assert!(count("tracks") > 0 && count("false_tracks") <= count("tracks"), "{confirmed}");
        assert!(count("clutter_rows_in_confirmed_tracks") <= count("clutter_rows"));
        assert_eq!(count("sequences"), 2);
        let _ = count("fragmentations");
        let _ = count("idsw");
        assert!(confirmed["duration_s"].as_f64().unwrap() > 0.0);
        assert!(confirmed["false_tracks_per_minute"].as_f64().unwrap() >= 0.0);
        let idf1 = confirmed["idf1"].as_f64().unwrap();
        assert!(idf1 > 0.5 && idf1 <= 1.0, "{method} confirmed idf1 {idf1}");
    }
    assert!(plots.join("trajectories.svg").exists());
}

#[test]
fn eval_with_the_displacement_oracle_gives_pr_the_true_motion_and_refuses_what_it_cannot_do() {
    let dir = tempdir("oracle");
    generate(&dir);
    let data = dir.join("evaluation");
    let pr_rmse = |extra: &[&str]| {
        let json = dir.join("oracle.json");
        let mut args = vec![
            "eval",
            "--data",
            data.to_str().unwrap(),
            "--methods",
            "pr",
            "--json",
            json.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let output = primm(&args);
        let value: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (value, output)
    };
    let (exact, output) = pr_rmse(&["--displacement-oracle"]);
    assert!(String::from_utf8_lossy(&output.stdout).contains("replaced by the true displacement"));
    assert_eq!(exact["displacement_oracle"], serde_json::json!(true));
    // Every request whose track's latest measurement belongs to an object is answered.
    let stderr = String::from_utf8_lossy(&output.stderr);
    let counts = stderr
        .lines()
        .find_map(|line| line.strip_prefix("pr: displacement oracle: "))
        .expect("oracle counts");
    let numbers: Vec<u64> = counts.split(' ').filter_map(|word| word.parse().ok()).collect();
    assert!(numbers[0] > 0 && numbers[0] * 10 >= numbers[1] * 9, "{counts}");
    // A perfect displacement beats a 1 m noisy one and the model, which it replaced.
    let (noisy, _) = pr_rmse(&["--displacement-oracle", "--displacement-oracle-noise-m", "1.0"]);
    let (model, _) = pr_rmse(&[]);
    let rmse = |value: &serde_json::Value| value["methods"]["pr"]["rmse_xy"].as_f64().unwrap();
    assert!(
        rmse(&exact) < rmse(&noisy) && rmse(&exact) < rmse(&model),
        "{} {} {}",
        rmse(&exact),
        rmse(&noisy),
        rmse(&model)
    );
    assert_eq!(model["displacement_oracle"], serde_json::json!(false));

    let refused = |args: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().unwrap();
        assert!(!output.status.success(), "{args:?} ran");
        String::from_utf8_lossy(&output.stderr).into_owned()
    };
    let data = data.to_str().unwrap();
    let stderr =
        refused(&["eval", "--data", data, "--methods", "pr", "--displacement-oracle-noise-m", "0.1"]);
    assert!(stderr.contains("--displacement-oracle"), "{stderr}");
    let stderr = refused(&[
        "eval",
        "--data",
        data,
        "--methods",
        "pr",
        "--displacement-oracle",
        "--tracking-frame",
        "vehicle",
    ]);
    assert!(stderr.contains("needs the world frame"), "{stderr}");
    let stderr =
        refused(&["eval", "--data", data, "--displacement-oracle", "--displacement-oracle-noise-m=-1"]);
    assert!(stderr.contains("standard deviation"), "{stderr}");
}

#[test]
fn score_of_the_association_files_written_by_track_equals_the_eval_metrics() {
    let dir = tempdir("score");
    generate(&dir);
    let data = dir.join("evaluation");
    let associations = dir.join("associations");
    std::fs::create_dir_all(&associations).unwrap();
    let mut timed_frames = 0;
    for file in primm_sim::io::dataset_files(&data).unwrap() {
        let name = file.file_name().unwrap();
        let output = primm(&[
            "track",
            "--input",
            file.to_str().unwrap(),
            "--output",
            dir.join("tracks.csv").to_str().unwrap(),
            "--method",
            "imm",
            "--associations",
            associations.join(name).to_str().unwrap(),
            "--timing",
            dir.join("steps.txt").to_str().unwrap(),
        ]);
        let timing: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let sequence = primm_sim::io::read_sequence_file(&file).unwrap();
        assert_eq!(timing["frames"].as_u64().unwrap() as usize, sequence.frames.len());
        assert!(timing["frames_per_second"].as_f64().unwrap() > 0.0);
        timed_frames += sequence.frames.len();
    }
    assert!(timed_frames > 0);
    let lines = std::fs::read_to_string(dir.join("steps.txt")).unwrap();
    assert_eq!(lines.lines().count(), timed_frames, "one step time per frame, appended over the files");
    assert!(lines.lines().all(|line| line.parse::<u64>().is_ok()));
    let score = primm(&[
        "score",
        "--data",
        data.to_str().unwrap(),
        "--associations",
        associations.to_str().unwrap(),
        "--name",
        "imm",
    ]);
    let score: serde_json::Value = serde_json::from_slice(&score.stdout).unwrap();
    let json = dir.join("eval.json");
    primm(&["eval", "--data", data.to_str().unwrap(), "--methods", "imm", "--json", json.to_str().unwrap()]);
    let eval: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let eval = &eval["methods"]["imm"];
    assert_eq!(score["idsw"], eval["idsw"]);
    for (scored, evaluated) in
        [("rmse_xy_m", "rmse_xy"), ("rmse_x_m", "rmse_x"), ("rmse_y_m", "rmse_y"), ("idf1", "idf1")]
    {
        let (a, b) = (score[scored].as_f64().unwrap(), eval[evaluated].as_f64().unwrap());
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1.0), "{scored}: score {a} vs eval {b}");
    }
    assert!(score["confirmed_tracks"].is_object(), "{score}");
    assert_eq!(score["confirmed_tracks"], eval["confirmed_tracks"]);

    // The same files without the `confirmed` column: the paper's metrics as before, the metrics
    // on confirmed tracks skipped with a message.
    for file in primm_sim::io::dataset_files(&associations).unwrap() {
        let text = std::fs::read_to_string(&file).unwrap();
        let legacy: String =
            text.lines().map(|line| format!("{}\n", &line[..line.rfind(',').unwrap()])).collect();
        assert!(legacy.starts_with(primm_sim::io::association_csv::LEGACY_ASSOCIATION_CSV_HEADER));
        std::fs::write(&file, legacy).unwrap();
    }
    let legacy =
        primm(&["score", "--data", data.to_str().unwrap(), "--associations", associations.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&legacy.stderr);
    assert!(stderr.contains("metrics on confirmed tracks skipped"), "{stderr}");
    let legacy: serde_json::Value = serde_json::from_slice(&legacy.stdout).unwrap();
    assert!(legacy["confirmed_tracks"].is_null(), "{legacy}");
    assert_eq!((&legacy["idsw"], &legacy["idf1"]), (&score["idsw"], &score["idf1"]));
}

#[test]
fn score_refuses_an_association_file_that_names_a_missing_measurement() {
    let dir = tempdir("score-bad");
    generate(&dir);
    let data = dir.join("evaluation");
    let associations = dir.join("associations");
    std::fs::create_dir_all(&associations).unwrap();
    for file in primm_sim::io::dataset_files(&data).unwrap() {
        let text = format!("{}\n0,9999,1,,,1\n", primm_sim::io::association_csv::ASSOCIATION_CSV_HEADER);
        std::fs::write(associations.join(file.file_name().unwrap()), text).unwrap();
    }
    let output = Command::new(env!("CARGO_BIN_EXE_primm"))
        .args(["score", "--data", data.to_str().unwrap(), "--associations", associations.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("no such measurement"), "{stderr}");
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
