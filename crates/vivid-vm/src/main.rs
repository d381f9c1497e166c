//! `vivid-vm`: prove the capture path against a real kernel V4L2 driver.
//!
//! Run it as `cargo xtask vivid [ARGS]` (a gate step; it installs the host packages first and
//! then runs `cargo run -p vivid-vm -- ARGS`), or directly with `cargo run -p vivid-vm -- ARGS`.
//!
//! The host kernel cannot load modules, so this boots Debian's own kernel under qemu (TCG) with
//! an initramfs holding busybox, the media modules, the `vivid` test driver and a statically
//! linked guest program, runs a list of capture cases inside the VM and checks what the guest
//! printed on the serial console.
//!
//! Steps (everything cached under `target/vivid/`, nothing committed):
//!
//! 1. Host packages: `qemu-system-x86`, `busybox-static`, `libclang-dev` (the `v4l` crate's
//!    bindgen needs libclang). `cargo xtask vivid` installs missing ones with apt-get when
//!    running as root (fresh machine), or in CI (`CI` set) through passwordless `sudo`.
//! 2. Guest program: the real `nav-app` (lane tracker with its `capture` feature), built
//!    with `-C target-feature=+crt-static` for `x86_64-unknown-linux-gnu` in the cargo profile
//!    `vivid-guest` (release settings at opt-level 1: the guest tracks 60-frame streams, so build
//!    time matters more than speed; `target/x86_64-unknown-linux-gnu/vivid-guest/nav-app`; the
//!    cold build compiles nav-app's whole dependency tree for that target once). `--guest-bin PATH` runs another static build of
//!    nav-app instead. The guest runs e.g. `nav-app --device /dev/video0 --input-name S-Video
//!    --std ntsc --max-frames 60 --json` and prints one JSON object per tracked frame (with its
//!    `"capture"` device fields) and a last `{"schema": 1, "summary": {…}}` line, plus its hidden test flags
//!    (`--format --timeout-ms --ctrl NAME=VALUE@FRAME --ctrl-on-timeout NAME=VALUE`) for the
//!    fault cases; see `crates/nav-app/src/bin/nav-app/lane.rs`.
//! 3. Kernel: the package `linux-image-amd64` depends on, fetched with `apt-get download` and
//!    unpacked with `dpkg -x` (not installed).
//! 4. Initramfs (newc cpio written here): busybox, `/init`, the modules rc-core, cec, mc,
//!    videodev, v4l2-dv-timings, v4l2-tpg, videobuf2-{common,memops,v4l2,vmalloc,dma-contig},
//!    vivid (`n_devs=1 node_types=0x1 num_inputs=2 input_types=0x9`: input 0 "TV", 1 "S-Video").
//! 5. `qemu-system-x86_64 -accel tcg -cpu max -m 512 -nographic` (KVM hung at the BIOS on this
//!    kind of machine), killed if it outlives `--timeout-secs` (default 240 s); each case is
//!    bounded in the guest by busybox `timeout`.
//! 6. Verdict: the serial log is split at `VIVID-CASE-BEGIN/END` markers and each case's JSON
//!    lines are checked; a table is printed and `target/vivid/verdict.json` written. Any failed
//!    case fails the command.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Write as _};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail, ensure};
use serde_json::Value;

use clap::Parser;

/// Options of `vivid-vm` (and `cargo xtask vivid`).
#[derive(Parser, Debug)]
#[command(
    name = "vivid-vm",
    about = "Boot Debian's kernel under qemu with the vivid V4L2 driver and run nav-app's capture cases."
)]
struct VividArgs {
    /// Static nav-app binary to test instead of building it.
    #[arg(long)]
    guest_bin: Option<PathBuf>,
    /// Kill qemu after this many seconds.
    #[arg(long, default_value_t = 240)]
    timeout_secs: u64,
    /// Run only the cases whose names contain this text (repeatable).
    #[arg(long = "case")]
    cases: Vec<String>,
    /// Print the whole serial log, not just the verdict.
    #[arg(long)]
    verbose: bool,
}

/// Modules to insert, in dependency order (vivid last, with its parameters).
const MODULES: &[&str] = &[
    "rc-core",
    "cec",
    "mc",
    "videodev",
    "v4l2-dv-timings",
    "v4l2-tpg",
    "videobuf2-common",
    "videobuf2-memops",
    "videobuf2-v4l2",
    "videobuf2-vmalloc",
    "videobuf2-dma-contig",
    "vivid",
];
const VIVID_PARAMS: &str = "n_devs=1 node_types=0x1 num_inputs=2 input_types=0x9";

mod cases;
mod guest;
mod host;
mod judge;
#[cfg(test)]
mod tests;

use cases::*;
use guest::*;
use host::*;
use judge::*;

/// The workspace root: two levels above this crate's manifest directory.
fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

/// Cargo's target directory: `CARGO_TARGET_DIR`, or `target/` in the workspace root.
fn target_dir(root: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from)
}

fn main() -> Result<()> {
    run(VividArgs::parse())
}

/// Build the guest, boot the VM, judge the cases.
fn run(args: VividArgs) -> Result<()> {
    let started = Instant::now();
    let root = workspace_root();
    let work = target_dir(&root).join("vivid");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;

    let guest = match &args.guest_bin {
        Some(p) => p.clone(),
        None => build_nav_app(&root)?,
    };
    ensure!(
        is_static_elf(&guest)?,
        "{} is not a statically linked ELF executable",
        guest.display()
    );

    let kernel = fetch_kernel(&work)?;
    let selected: Vec<Case> = cases()
        .into_iter()
        .filter(|c| args.cases.is_empty() || args.cases.iter().any(|f| c.name.contains(f.as_str())))
        .collect();
    ensure!(!selected.is_empty(), "no case matches {:?}", args.cases);

    let initrd = work.join("initrd.cpio");
    write_initramfs(&initrd, &kernel, &guest, &selected)?;

    let vm_started = Instant::now();
    eprintln!("vivid: booting {} under qemu (TCG)…", kernel.version);
    let log = run_qemu(
        &kernel.vmlinuz,
        &initrd,
        Duration::from_secs(args.timeout_secs),
        args.verbose,
    )?;
    std::fs::write(work.join("serial.log"), log.lines.join("\n"))?;
    let vm_secs = vm_started.elapsed().as_secs_f64();

    let verdicts = judge(&selected, &log);
    let mut table = String::new();
    let mut json = serde_json::Map::new();
    let mut failed = 0;
    for (case, v) in selected.iter().zip(&verdicts) {
        let status = match v {
            Verdict::Pass(_) => "PASS",
            Verdict::Skip(_) => "SKIP",
            Verdict::Fail(_) => {
                failed += 1;
                "FAIL"
            }
        };
        let _ = writeln!(table, "  {status:4}  {:24} {}", case.name, v.detail());
        json.insert(
            case.name.to_owned(),
            serde_json::json!({ "status": status, "detail": v.detail(), "args": case.args }),
        );
    }
    let boot_ok = log.lines.iter().any(|l| l.starts_with("VIVID-READY"));
    json.insert(
        "_run".into(),
        serde_json::json!({
            "kernel": kernel.version, "booted": boot_ok, "qemu_killed": log.killed,
            "seconds": started.elapsed().as_secs_f64(), "vm_seconds": vm_secs,
        }),
    );
    std::fs::write(
        work.join("verdict.json"),
        serde_json::to_string_pretty(&Value::Object(json))?,
    )?;
    println!(
        "vivid: kernel {}, {:.0} s in all, {vm_secs:.0} s in the VM",
        kernel.version,
        started.elapsed().as_secs_f64()
    );
    print!("{table}");
    println!(
        "vivid: serial log {}, verdict {}",
        work.join("serial.log").display(),
        work.join("verdict.json").display()
    );
    if log.killed {
        bail!(
            "qemu did not finish within {} s and was killed",
            args.timeout_secs
        );
    }
    if !boot_ok {
        bail!("the guest never reached VIVID-READY (see serial.log)");
    }
    if failed > 0 {
        bail!("{failed} vivid case(s) failed");
    }
    Ok(())
}
