//! `primm generate`, `primm track` and `primm eval` as a user runs them.

use std::path::Path;
use std::process::Command;

fn primm(args: &[&str]) -> std::process::Output {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(
        output.status.success(),
        "primm {args:?} failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

fn generate(dir: &Path) {
    primm(&["generate", "--output", dir.to_str().unwrap(), "--split", "evaluation", "--sequences", "2", "--duration-s", "3"]);
}

#[test]
fn track_writes_one_row_per_measurement_with_consistent_columns() {
    let dir = tempdir("track");
    generate(&dir);
    let input = dir.join("evaluation/evaluation_0000.csv");
    let output = dir.join("tracks.csv");
    primm(&["track", "--input", input.to_str().unwrap(), "--output", output.to_str().unwrap(), "--method", "imm"]);
    let sequence = primm::io::read_sequence_file(&input).unwrap();
    let text = std::fs::read_to_string(&output).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(primm::io::track_csv::TRACK_CSV_HEADER));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // Every measurement updated or started exactly one track.
    assert_eq!(rows.len(), sequence.measurement_count());
    for row in &rows {
        assert_eq!(row.len(), 13);
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
    for table in ["Table II", "Table III", "Table IV", "Table V"] {
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
    }
    assert!(plots.join("trajectories.svg").exists());
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("primm-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
