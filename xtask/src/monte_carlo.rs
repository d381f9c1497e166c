//! `cargo xtask monte-carlo …`: the README's one-command main job. It builds the product binary
//! (`nav-app`, release, without live capture so that no libclang is needed) and runs
//! `nav-app monte-carlo …` with the workspace's files as defaults: `--config
//! configs/paper.toml` (and for `scenarios`, `--dir configs/mismatch --matched
//! configs/paper.toml`) and `--out-root target/monte-carlo`, each only where the arguments do
//! not name it. Everything else is passed through unchanged; the Monte Carlo itself (driver,
//! statistics, reports, figures) is the library `ins_monte_carlo` (crate `ins-monte-carlo`).

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

/// The command line given to `nav-app`: `monte-carlo`, the user's arguments, then the workspace
/// defaults for the options the user did not give.
pub fn nav_app_args(user: &[OsString]) -> Vec<OsString> {
    let root = workspace_root();
    let has = |flag: &str| {
        user.iter().any(|a| {
            a.to_str()
                .is_some_and(|a| a == flag || a.starts_with(&format!("{flag}=")))
        })
    };
    let help = has("--help") || has("-h");
    let sub = user.first().and_then(|a| a.to_str()).unwrap_or("");
    let mut defaults: Vec<(&str, OsString)> = vec![(
        "--out-root",
        target_dir(&root).join("monte-carlo").into_os_string(),
    )];
    let paper = root.join("configs/paper.toml").into_os_string();
    match sub {
        "merge" => {}
        "scenarios" => {
            defaults.push(("--dir", root.join("configs/mismatch").into_os_string()));
            defaults.push(("--matched", paper));
        }
        _ => defaults.push(("--config", paper)),
    }
    let mut out: Vec<OsString> = vec!["monte-carlo".into()];
    out.extend(user.iter().cloned());
    if !help {
        for (flag, value) in defaults {
            if !has(flag) {
                out.push(flag.into());
                out.push(value);
            }
        }
    }
    out
}

/// Builds `nav-app` and runs it.
pub fn run(args: MonteCarloArgs) -> Result<()> {
    let root = workspace_root();
    let exe = build_nav_app_release(&root)?;
    let status = Command::new(&exe)
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
    fn workspace_defaults_are_added_only_where_the_user_gave_none() {
        let plain = strs(&nav_app_args(&["--runs".into(), "3".into()]));
        assert_eq!(&plain[..3], ["monte-carlo", "--runs", "3"]);
        assert!(plain.iter().any(|a| a.ends_with("configs/paper.toml")));
        assert!(plain.iter().any(|a| a == "--out-root"));
        let own = strs(&nav_app_args(&["--config=x.toml".into()]));
        assert_eq!(own.iter().filter(|a| a.contains("config")).count(), 1);
        let merge = strs(&nav_app_args(&["merge".into(), "a".into()]));
        assert!(!merge.iter().any(|a| a == "--config"));
        let sc = strs(&nav_app_args(&["scenarios".into()]));
        assert!(sc.iter().any(|a| a == "--matched") && sc.iter().any(|a| a == "--dir"));
        let help = strs(&nav_app_args(&["--help".into()]));
        assert_eq!(help, ["monte-carlo", "--help"]);
    }
}
