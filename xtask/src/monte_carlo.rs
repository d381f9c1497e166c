//! `cargo xtask monte-carlo …`: the README's one-command main job. It builds the product binary
//! (`nav-app`, release, without live capture so that no libclang is needed) and runs
//! `nav-app monte-carlo …` in the workspace root, so that the binary's own defaults (its clap
//! definitions: `configs/paper.toml`, `configs/mismatch`, the runs, the filters …) are the
//! workspace's files; relative paths given here are from the workspace root, as in every xtask
//! command. xtask adds only what differs from a user's run: outputs under
//! `target/monte-carlo` (`--out-root`) and the scenario named by its absolute path (`--config`,
//! so that summaries name the file as before), both put before the user's arguments, where a
//! user's own `--out-root` or `--config` overrides them (the binary lets an option's last
//! occurrence win). It reads no other option; the Monte Carlo itself (driver, statistics,
//! reports, figures) is the library `ins_monte_carlo` (crate `ins-monte-carlo`).

use std::ffi::OsString;
use std::process::Command;

use anyhow::{Context, Result, bail};
use clap::Args;

use crate::paths::{build_nav_app_release, target_dir, workspace_root};

/// Arguments of `cargo xtask monte-carlo`: those of `nav-app monte-carlo`, passed through.
#[derive(Args, Debug)]
#[command(disable_help_flag = true)]
pub struct MonteCarloArgs {
    /// Arguments of `nav-app monte-carlo` (see `cargo xtask monte-carlo --help`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<OsString>,
}

/// The command line given to `nav-app` (run in the workspace root): `monte-carlo`, the
/// subcommand if the user gave one, xtask's two settings (`--out-root`, and `--config` for a
/// simulation), then the user's arguments, which override them.
pub fn nav_app_args(user: &[OsString]) -> Vec<OsString> {
    let root = workspace_root();
    let mut out: Vec<OsString> = vec!["monte-carlo".into()];
    let sub = user.first().and_then(|a| a.to_str());
    let rest = match sub {
        Some("merge" | "scenarios" | "help") => {
            out.push(user[0].clone());
            &user[1..]
        }
        _ => user,
    };
    if sub != Some("help") {
        out.push("--out-root".into());
        out.push(target_dir(&root).join("monte-carlo").into_os_string());
        if !matches!(sub, Some("merge" | "scenarios")) {
            out.push("--config".into());
            out.push(root.join("configs/paper.toml").into_os_string());
        }
    }
    out.extend(rest.iter().cloned());
    out
}

/// Builds `nav-app` and runs it.
pub fn run(args: MonteCarloArgs) -> Result<()> {
    let root = workspace_root();
    let exe = build_nav_app_release(&root)?;
    let status = Command::new(&exe)
        .current_dir(&root)
        .args(nav_app_args(&args.args))
        .status()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    if !status.success() {
        bail!("nav-app monte-carlo failed ({status})");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn strs(v: &[OsString]) -> Vec<String> {
        v.iter().map(|a| a.to_string_lossy().into_owned()).collect()
    }

    #[test]
    fn xtask_puts_its_two_settings_before_the_users_arguments() {
        let plain = strs(&nav_app_args(&["--runs".into(), "3".into()]));
        assert_eq!(plain[0], "monte-carlo");
        assert_eq!(plain[1], "--out-root");
        assert!(plain[2].ends_with("monte-carlo"));
        assert_eq!(plain[3], "--config");
        assert!(plain[4].ends_with("configs/paper.toml"));
        assert_eq!(&plain[5..], ["--runs", "3"]);
        // The user's own --config comes last and wins (the binary's last occurrence).
        let own = strs(&nav_app_args(&["--config=x.toml".into()]));
        assert_eq!(own.last().map(String::as_str), Some("--config=x.toml"));
        // Subcommands first; merge and scenarios take their files from the binary's defaults.
        let merge = strs(&nav_app_args(&["merge".into(), "a".into()]));
        assert_eq!(merge[..3], ["monte-carlo", "merge", "--out-root"]);
        assert!(!merge.iter().any(|a| a == "--config"));
        assert_eq!(merge.last().map(String::as_str), Some("a"));
        let sc = strs(&nav_app_args(&["scenarios".into()]));
        assert_eq!(sc[..3], ["monte-carlo", "scenarios", "--out-root"]);
        assert!(!sc.iter().any(|a| a == "--matched" || a == "--dir"));
        let help = strs(&nav_app_args(&["help".into()]));
        assert_eq!(help, ["monte-carlo", "help"]);
    }
}
