//! The Debian packages the gate needs, installed when missing: the one place xtask calls apt-get.

use std::process::{Command, Stdio};

use anyhow::{Context, Result, bail, ensure};

/// Whether this process runs as root (`id -u` is 0).
fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

fn dpkg_installed(pkg: &str) -> bool {
    Command::new("dpkg-query")
        .args(["-W", "-f=${Status}", pkg])
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("install ok installed"))
}

/// Install the Debian packages that are missing (as root), or fail saying which are.
///
/// `libclang-dev` is what the `v4l` crate's bindgen build script needs; the test gate can call
/// [`ensure_test_packages`] for the workspace's.
pub fn ensure_host_packages(pkgs: &[&str]) -> Result<()> {
    let missing: Vec<&str> = pkgs
        .iter()
        .copied()
        .filter(|p| !dpkg_installed(p))
        .collect();
    if missing.is_empty() {
        return Ok(());
    }
    // Root installs directly; in CI (env CI set) a passwordless sudo is used if there is one.
    let sudo = !is_root();
    if sudo {
        let ci = std::env::var_os("CI").is_some();
        let passwordless = Command::new("sudo")
            .args(["-n", "true"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if !(ci && passwordless) {
            bail!(
                "missing Debian packages {missing:?}; install them with \
                 `sudo apt-get install -y {}`",
                missing.join(" ")
            );
        }
    }
    let apt = |args: &[&str]| -> Result<bool> {
        let mut cmd = if sudo {
            let mut c = Command::new("sudo");
            c.args(["-n", "env", "DEBIAN_FRONTEND=noninteractive", "apt-get"]);
            c
        } else {
            let mut c = Command::new("apt-get");
            c.env("DEBIAN_FRONTEND", "noninteractive");
            c
        };
        Ok(cmd
            .args(args)
            .status()
            .context("running apt-get")?
            .success())
    };
    eprintln!("xtask: installing {missing:?} with apt-get");
    ensure!(apt(&["update", "-q"])?, "apt-get update failed");
    let mut install = vec!["install", "-y", "-q", "--no-install-recommends"];
    install.extend(missing.iter().copied());
    ensure!(apt(&install)?, "apt-get install {missing:?} failed");
    Ok(())
}

/// The system packages the workspace's tests need: `libclang-dev` (the `v4l` crate's bindgen
/// step) and `ffmpeg` (video inputs, `lane_io::video`).
pub fn ensure_test_packages() -> Result<()> {
    ensure_host_packages(&["libclang-dev", "ffmpeg"])
}

/// The packages the vivid VM test (`vivid-vm`) needs: qemu, a static busybox for the
/// initramfs, and `libclang-dev` for the guest build's `capture` feature.
pub fn ensure_vivid_packages() -> Result<()> {
    ensure_host_packages(&["qemu-system-x86", "busybox-static", "libclang-dev"])
}
