//! What a release of `primm` carries: its version everywhere, the licence, shell completions, the
//! manual page and examples in the main commands' help.

use std::path::Path;
use std::process::Command;

fn primm(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_primm")).args(args).output().expect("primm runs");
    assert!(output.status.success(), "primm {args:?} failed:\n{}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8(output.stdout).expect("UTF-8 output")
}

/// The workspace's version, from the root `Cargo.toml`.
fn workspace_version() -> String {
    let manifest = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml")).unwrap();
    let manifest: toml::Table = manifest.parse().unwrap();
    manifest["workspace"]["package"]["version"].as_str().unwrap().to_owned()
}

#[test]
fn the_binary_reports_the_workspace_version_which_every_member_crate_inherits() {
    let version = workspace_version();
    assert_eq!(primm(&["--version"]).trim(), format!("primm {version}"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest: toml::Table = std::fs::read_to_string(root.join("Cargo.toml")).unwrap().parse().unwrap();
    let members = manifest["workspace"]["members"].as_array().unwrap();
    let mut checked = 0;
    for member in members.iter().map(|member| member.as_str().unwrap()) {
        let dirs: Vec<std::path::PathBuf> = match member.strip_suffix("/*") {
            Some(parent) => {
                std::fs::read_dir(root.join(parent)).unwrap().map(|entry| entry.unwrap().path()).collect()
            }
            None => vec![root.join(member)],
        };
        for dir in dirs.into_iter().filter(|dir| dir.join("Cargo.toml").is_file()) {
            let text = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
            let package: toml::Table = text.parse().unwrap();
            let package = package["package"].as_table().unwrap();
            assert_eq!(package["version"]["workspace"].as_bool(), Some(true), "{}", dir.display());
            assert_eq!(package["license"]["workspace"].as_bool(), Some(true), "{}", dir.display());
            assert!(!text.contains("example.invalid"), "{}", dir.display());
            checked += 1;
        }
    }
    assert!(checked >= 12, "{checked} member crates");
    let license = std::fs::read_to_string(root.join("LICENSE")).unwrap();
    assert!(license.contains("Apache License") && license.contains("Version 2.0, January 2004"));
    assert!(license.contains("END OF TERMS AND CONDITIONS"));
    assert_eq!(manifest["workspace"]["package"]["license"].as_str(), Some("Apache-2.0"));
}

#[test]
fn completions_for_bash_name_every_subcommand_and_an_unknown_shell_is_refused() {
    let script = primm(&["completions", "bash"]);
    assert!(script.contains("_primm()"), "{script}");
    assert!(script.contains("complete -F _primm"), "{script}");
    for subcommand in ["demo", "serve", "track", "eval", "generate", "completions", "man"] {
        assert!(script.contains(subcommand), "{subcommand} missing");
    }
    // Options of a subcommand complete too.
    assert!(script.contains("--associations"));
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        assert!(primm(&["completions", shell]).contains("track"), "{shell}");
    }
    let refused = Command::new(env!("CARGO_BIN_EXE_primm")).args(["completions", "tcsh"]).output().unwrap();
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("tcsh"));
}

#[test]
fn the_manual_page_is_roff_with_the_version_and_one_page_per_subcommand_is_written_on_request() {
    let page = primm(&["man"]);
    assert!(page.contains(".TH primm 1"), "{}", &page[..page.len().min(400)]);
    assert!(page.contains(&workspace_version()));
    assert!(page.contains("track"));
    let dir = std::env::temp_dir().join(format!("primm-man-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    primm(&["man", "--output", dir.to_str().unwrap()]);
    for name in ["primm.1", "primm-track.1", "primm-serve.1", "primm-completions.1"] {
        let text = std::fs::read_to_string(dir.join(name)).unwrap_or_else(|error| panic!("{name}: {error}"));
        assert!(text.contains(".TH"), "{name}");
    }
    let track = std::fs::read_to_string(dir.join("primm-track.1")).unwrap();
    assert!(track.contains("associations"), "the track page lists its options");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_main_commands_show_examples_in_their_help() {
    for command in ["demo", "serve", "track", "eval", "generate"] {
        let help = primm(&[command, "--help"]);
        let examples = help.split("Examples:").nth(1).unwrap_or_else(|| panic!("primm {command}: {help}"));
        let lines: Vec<&str> =
            examples.lines().filter(|line| line.trim_start().starts_with("primm ")).collect();
        assert!(lines.len() >= 3, "primm {command}: {examples}");
        assert!(
            lines.iter().all(|line| line.contains(&format!("primm {command}"))),
            "primm {command}: {lines:?}"
        );
    }
}
