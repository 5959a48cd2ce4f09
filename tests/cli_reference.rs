//! `docs/cli.md` is generated from the binary's own `--help` (clap) and the hand-written
//! notes in `docs/cli-notes/`, so the option reference cannot drift from the code. This
//! test rebuilds the file and fails when the committed one differs; with
//! `TINSMITH_BLESS=1` it writes the file instead:
//!
//! ```sh
//! TINSMITH_BLESS=1 cargo test --test integration -- cli_reference
//! ```

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `tinsmith ARGS`'s standard output, asserting success.
fn help(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_tinsmith"))
        .args(args)
        .env_remove("COLUMNS")
        .env("NO_COLOR", "1")
        .output()
        .expect("tinsmith runs");
    assert!(o.status.success(), "tinsmith {args:?} failed");
    String::from_utf8(o.stdout).expect("help is UTF-8")
}

/// The subcommands `tinsmith --help` lists, `help` left out.
fn commands(top: &str) -> Vec<String> {
    top.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_owned)
        .collect()
}

/// `docs/cli-notes/NAME.md`, when there is one.
fn notes(name: &str) -> Option<String> {
    let path = repo().join("docs/cli-notes").join(format!("{name}.md"));
    std::fs::read_to_string(path).ok()
}

fn section(out: &mut String, title: &str, help: &str, notes: Option<String>) {
    out.push_str(&format!(
        "## {title}\n\n```text\n{}\n```\n",
        help.trim_end()
    ));
    if let Some(notes) = notes {
        out.push('\n');
        out.push_str(notes.trim_end());
        out.push('\n');
    }
    out.push('\n');
}

/// The whole of `docs/cli.md`.
fn reference() -> String {
    let top = help(&["--help"]);
    let commands = commands(&top);
    assert!(
        commands.len() >= 6,
        "too few commands in --help: {commands:?}"
    );
    let mut out = String::from(
        "# Command-line reference\n\n\
         <!-- Generated: do not edit. -->\n\
         This file is generated from `tinsmith --help`, `tinsmith <command> --help` and the \
         notes in [cli-notes/](cli-notes/); `cargo test` fails when it is stale. Edit the \
         notes (or the help text in the code), then regenerate it with\n\n\
         ```sh\nTINSMITH_BLESS=1 cargo test --test integration -- cli_reference\n```\n\n\
         The guarantee every command keeps is stated in [guarantee.md](guarantee.md).\n\n",
    );
    out.push_str("Commands:");
    for c in std::iter::once("tinsmith").chain(commands.iter().map(String::as_str)) {
        let anchor = if c == "tinsmith" {
            "tinsmith".to_owned()
        } else {
            format!("tinsmith-{c}")
        };
        let title = if c == "tinsmith" {
            "tinsmith".to_owned()
        } else {
            format!("tinsmith {c}")
        };
        out.push_str(&format!(" [`{title}`](#{anchor})"));
    }
    out.push_str("\n\n");
    section(&mut out, "tinsmith", &top, notes("tinsmith"));
    for c in &commands {
        section(
            &mut out,
            &format!("tinsmith {c}"),
            &help(&[c, "--help"]),
            notes(c),
        );
    }
    out.truncate(out.trim_end().len());
    out.push('\n');
    out
}

#[test]
fn cli_reference_is_generated_from_the_help() {
    let path: PathBuf = repo().join("docs/cli.md");
    let wanted = reference();
    if std::env::var("TINSMITH_BLESS").as_deref() == Ok("1") {
        std::fs::write(&path, &wanted).expect("write docs/cli.md");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != wanted {
        let line = committed
            .lines()
            .zip(wanted.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| committed.lines().count().min(wanted.lines().count()))
            + 1;
        panic!(
            "docs/cli.md is stale (first difference at line {line}): regenerate it with \
             `TINSMITH_BLESS=1 cargo test --test integration -- cli_reference`"
        );
    }
}

#[test]
fn every_command_has_notes() {
    for c in commands(&help(&["--help"])) {
        assert!(
            notes(&c).is_some(),
            "docs/cli-notes/{c}.md is missing: every command gets its notes"
        );
    }
}
