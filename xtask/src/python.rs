//! `cargo xtask python`: build the `ita_nav` wheel (crates/ita-nav-py, maturin) into the virtual
//! environment `target/py-venv` and run its pytest suite against the `nav-app` binary.
//!
//! Everything it needs comes from PyPI into the venv on first use (maturin, pytest, numpy, and
//! the independent peers of the interop tests: mcap, jsonschema, pillow, evo, websockets): a
//! fresh machine needs only `python3` with its `venv` module (Debian `python3-venv`, installed with
//! apt-get when missing and running as root or under CI with passwordless sudo).

use std::path::{Path, PathBuf};

use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::paths::workspace_root;

/// Requirements installed into the venv.
const REQUIREMENTS: &[&str] = &[
    "maturin>=1.9,<2",
    "pytest>=7",
    "numpy>=1.21",
    // The independent implementations the interop tests check nav-app against (robot bags,
    // JSON schemas, JPEG).
    "mcap>=1.1",
    "mcap-ros2-support>=0.5",
    "jsonschema>=4",
    "pillow>=9",
    // The field's usual trajectory evaluator: `evo_ape` reads nav-app's --tum-out (test_evo.py).
    "evo>=1.28",
    // An independent client of Foxglove's WebSocket protocol for nav-app --foxglove
    // (test_foxglove_live.py).
    "websockets>=13",
];

/// Arguments of `cargo xtask python`.
#[derive(clap::Args, Debug)]
pub struct PythonArgs {
    /// Extra arguments for pytest (e.g. `-k rgb`).
    #[arg(trailing_var_arg = true)]
    pytest_args: Vec<String>,
}

fn run_checked(cmd: &mut Command, what: &str) -> Result<()> {
    eprintln!("xtask python: {what}");
    let status = cmd
        .status()
        .with_context(|| format!("could not start: {what}"))?;
    if !status.success() {
        bail!("{what}: {status}");
    }
    Ok(())
}

/// `python -m pip install --quiet --disable-pip-version-check`, to be completed by the caller.
fn pip_install(python: &Path) -> Command {
    let mut c = Command::new(python);
    c.args([
        "-m",
        "pip",
        "install",
        "--quiet",
        "--disable-pip-version-check",
    ]);
    c
}

/// Make `target/py-venv` with the requirements; returns its python.
fn ensure_venv(root: &Path) -> Result<PathBuf> {
    ensure_venv_with(
        root,
        "py-venv",
        REQUIREMENTS,
        "import numpy, pytest, mcap, mcap_ros2, jsonschema, PIL, evo, websockets",
        Some("bin/maturin"),
    )
}

/// Make (once) the virtual environment `target/NAME` holding `requirements` from PyPI, checked
/// by running `import_check` in it (and, if given, by `marker` existing in it); returns its
/// python. Debian's `python3-venv` is installed when `python3 -m venv` is missing.
pub fn ensure_venv_with(
    root: &Path,
    name: &str,
    requirements: &[&str],
    import_check: &str,
    marker: Option<&str>,
) -> Result<PathBuf> {
    let venv = root.join("target").join(name);
    let python = venv.join("bin/python");
    if !python.exists() {
        let made = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .context("python3 is needed (cannot start python3)")?;
        if !made.success() {
            // Debian splits the venv module out (python3-venv).
            crate::packages::ensure_host_packages(&["python3-venv"])?;
            let _ = std::fs::remove_dir_all(&venv);
            run_checked(
                Command::new("python3").args(["-m", "venv"]).arg(&venv),
                &format!("python3 -m venv target/{name}"),
            )?;
        }
    }
    let have = Command::new(&python)
        .args(["-c", import_check])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false)
        && marker.is_none_or(|m| venv.join(m).exists());
    if !have {
        run_checked(
            pip_install(&python).args(requirements),
            &format!("pip install {}", requirements.join(" ")),
        )?;
    }
    Ok(python)
}

/// Run `cargo xtask python`.
pub fn run(args: PythonArgs) -> Result<()> {
    let root = workspace_root();
    let python = ensure_venv(&root)?;
    let venv_bin = python
        .parent()
        .map(Path::to_owned)
        .context("venv without bin/")?;
    let wheels = root.join("target/py-wheels");
    let _ = std::fs::remove_dir_all(&wheels);
    run_checked(
        Command::new(venv_bin.join("maturin"))
            .args(["build", "--release", "--quiet", "--manifest-path"])
            .arg(root.join("crates/ita-nav-py/Cargo.toml"))
            .arg("--interpreter")
            .arg(&python)
            .arg("--out")
            .arg(&wheels),
        "maturin build --release (crates/ita-nav-py)",
    )?;
    let wheel = std::fs::read_dir(&wheels)
        .with_context(|| format!("cannot read {}", wheels.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| p.extension().is_some_and(|x| x == "whl"))
        .context("maturin wrote no wheel")?;
    run_checked(
        pip_install(&python)
            .args(["--force-reinstall", "--no-deps"])
            .arg(&wheel),
        &format!("pip install {}", wheel.display()),
    )?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    run_checked(
        Command::new(&cargo).current_dir(&root).args([
            "build",
            "-p",
            "nav-app",
            "--no-default-features",
        ]),
        "cargo build -p nav-app (the binary the Python results are compared with)",
    )?;
    let nav_app = crate::paths::target_dir(&root).join("debug/nav-app");
    // The rendered sequences the suite compares on (only their truth is committed).
    let synthetic = crate::paths::target_dir(&root).join("fixtures/synthetic");
    crate::fixtures::run(crate::fixtures::FixturesArgs {
        out: synthetic.clone(),
        width: 320,
        height: 240,
    })?;
    run_checked(
        Command::new(&python)
            .current_dir(&root)
            .env("NAV_APP_BIN", &nav_app)
            .env("ITA_NAV_SYNTHETIC", &synthetic)
            .args(["-m", "pytest", "-q", "crates/ita-nav-py/tests"])
            .args(&args.pytest_args),
        "pytest crates/ita-nav-py/tests",
    )
}
