//! The host side: Debian packages (installed when missing), the static nav-app build for the guest.

use super::*;

/// The cargo target directory (`CARGO_TARGET_DIR` or `<root>/target`).
pub(super) fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

pub(super) fn dpkg_installed(pkg: &str) -> bool {
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

pub(super) fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned())
}

/// Build `nav-app` (feature `capture`) statically in the `vivid-guest` profile; returns its path.
pub(super) fn build_nav_app(root: &Path) -> Result<PathBuf> {
    const TARGET: &str = "x86_64-unknown-linux-gnu";
    eprintln!(
        "vivid: building the static guest program (nav-app --features capture, profile vivid-guest)…"
    );
    let started = Instant::now();
    let status = Command::new(cargo())
        .current_dir(root)
        .args([
            "build",
            "--profile",
            "vivid-guest",
            "-p",
            "nav-app",
            "--bin",
            "nav-app",
            "--features",
            "capture",
            "--target",
            TARGET,
        ])
        .env("RUSTFLAGS", "-C target-feature=+crt-static")
        .status()
        .context("starting cargo build for the guest program")?;
    ensure!(status.success(), "building the static nav-app failed");
    eprintln!(
        "vivid: guest build took {:.0} s",
        started.elapsed().as_secs_f64()
    );
    Ok(target_dir(root)
        .join(TARGET)
        .join("vivid-guest")
        .join("nav-app"))
}

/// An ELF64 executable without a PT_INTERP program header (i.e. not dynamically linked).
pub(super) fn is_static_elf(path: &Path) -> Result<bool> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if bytes.len() < 64 || &bytes[..4] != b"\x7fELF" || bytes[4] != 2 {
        return Ok(false);
    }
    let u64_at = |o: usize| {
        bytes
            .get(o..o + 8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8])))
    };
    let u16_at = |o: usize| {
        bytes
            .get(o..o + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let (Some(phoff), Some(phentsize), Some(phnum)) = (u64_at(0x20), u16_at(0x36), u16_at(0x38))
    else {
        return Ok(false);
    };
    for i in 0..usize::from(phnum) {
        let off = phoff as usize + i * usize::from(phentsize);
        let Some(p_type) = bytes.get(off..off + 4) else {
            return Ok(false);
        };
        if u32::from_le_bytes([p_type[0], p_type[1], p_type[2], p_type[3]]) == 3 {
            return Ok(false); // PT_INTERP
        }
    }
    Ok(true)
}
