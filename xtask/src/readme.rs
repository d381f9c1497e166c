//! `cargo xtask readme`: every command the README shows, run as written.
//!
//! The commands are the lines of the README's ```` ```sh ```` blocks (a line ending in `\`
//! continues on the next; `#` starts a comment). Each runs with `bash -c` from the workspace
//! root, in the README's order (a later command may read what an earlier one wrote), and must
//! exit 0. Two are not run here, each for the reason [`NOT_RUN`] gives; a reason whose command
//! is no longer in the README is an error, so the list cannot go stale.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, Result, bail};

use crate::paths::workspace_root;

/// README commands this step does not run, and why.
pub(crate) const NOT_RUN: &[(&str, &str)] = &[
    ("cargo xtask test", "the gate itself, which runs this step"),
    (
        "pip install ./crates/ita-nav-py",
        "installs into the user's Python; the gate's `python` step builds and installs the same \
         package from the same path into its own virtual environment and runs its tests",
    ),
];

/// The commands of `readme`'s ```` ```sh ```` blocks, in order: continuation lines joined,
/// comments and blank lines dropped.
pub(crate) fn commands(readme: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut in_sh = false;
    let mut pending = String::new();
    for line in readme.lines() {
        let trimmed = line.trim();
        if !in_sh {
            in_sh = trimmed == "```sh";
            continue;
        }
        if trimmed.starts_with("```") {
            in_sh = false;
            continue;
        }
        let code = trimmed.split(" #").next().unwrap_or("").trim();
        if code.is_empty() || code.starts_with('#') {
            continue;
        }
        match code.strip_suffix('\\') {
            Some(head) => {
                pending.push_str(head.trim_end());
                pending.push(' ');
            }
            None => {
                pending.push_str(code);
                out.push(std::mem::take(&mut pending));
            }
        }
    }
    out
}

/// The reason a command is not run, if it is one of [`NOT_RUN`].
fn not_run(command: &str) -> Option<&'static str> {
    NOT_RUN
        .iter()
        .find(|(c, _)| *c == command)
        .map(|(_, why)| *why)
}

/// Run `cargo xtask readme`.
pub fn run() -> Result<()> {
    let root = workspace_root();
    let path = root.join("README.md");
    let readme = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let commands = commands(&readme);
    if commands.is_empty() {
        bail!("{}: no command in a ```sh block", path.display());
    }
    for (listed, _) in NOT_RUN {
        if !commands.iter().any(|c| c == listed) {
            bail!("xtask readme: `{listed}` is listed as not run but is not in the README");
        }
    }
    let mut failed = Vec::new();
    for command in &commands {
        if let Some(why) = not_run(command) {
            eprintln!("readme: not run: {command} ({why})");
            continue;
        }
        eprintln!("readme: $ {command}");
        let start = Instant::now();
        let ok = run_one(&root, command)?;
        let took = start.elapsed().as_secs_f64();
        if ok {
            eprintln!("readme: passed in {took:.0} s");
        } else {
            eprintln!("readme: FAILED after {took:.0} s: {command}");
            failed.push(command.as_str());
        }
    }
    if !failed.is_empty() {
        bail!("README commands failed:\n  {}", failed.join("\n  "));
    }
    eprintln!(
        "readme: {} commands ran as written",
        commands.len() - NOT_RUN.len()
    );
    Ok(())
}

/// One command with `bash -c` from `root`, its output discarded (the command's own errors on
/// stderr); whether it exited 0.
fn run_one(root: &Path, command: &str) -> Result<bool> {
    let status = Command::new("bash")
        .arg("-c")
        .arg(command)
        .current_dir(root)
        .stdout(std::process::Stdio::null())
        .status()
        .with_context(|| format!("cannot start bash for `{command}`"))?;
    Ok(status.success())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commands_are_the_sh_blocks_lines_with_continuations_joined_and_comments_dropped() {
        let readme = "text\n```sh\ncargo a   # the main job\n\n# a comment\ncargo b \\\n  --flag x\n```\n\
                      ```python\nimport x\n```\n```sh\ncargo c\n```\n";
        assert_eq!(commands(readme), ["cargo a", "cargo b --flag x", "cargo c"]);
    }

    #[test]
    fn every_command_not_run_is_in_the_readme_and_the_readme_shows_more() {
        let readme = std::fs::read_to_string(workspace_root().join("README.md"))
            .expect("the workspace's README");
        let commands = commands(&readme);
        for (listed, _) in NOT_RUN {
            assert!(commands.iter().any(|c| c == listed), "{listed}");
        }
        // The README shows the main job, and at least five commands this step runs.
        assert!(commands.iter().any(|c| c == "cargo xtask monte-carlo"));
        assert!(commands.iter().filter(|c| not_run(c).is_none()).count() >= 5);
    }
}
