//! The host side: the static nav-app build for the guest. The Debian packages the VM needs
//! (`qemu-system-x86`, `busybox-static`, `libclang-dev`) are installed by `cargo xtask vivid`;
//! run alone, a missing one shows as the step that needs it failing, with the package named.

use super::*;

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
    ensure!(
        status.success(),
        "building the static nav-app failed (the `capture` feature needs libclang-dev)"
    );
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
