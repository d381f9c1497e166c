//! `cargo xtask vivid`: prove the capture path against a real kernel V4L2 driver.
//!
//! The host kernel cannot load modules, so this boots Debian's own kernel under qemu (TCG) with
//! an initramfs holding busybox, the media modules, the `vivid` test driver and a statically
//! linked guest program, runs a list of capture cases inside the VM and checks what the guest
//! printed on the serial console.
//!
//! Steps (everything cached under `target/vivid/`, nothing committed):
//!
//! 1. Host packages: `qemu-system-x86`, `busybox-static`, `libclang-dev` (the `v4l` crate's
//!    bindgen needs libclang). Missing ones are installed with apt-get when running as root
//!    (fresh machine), or in CI (`CI` set) through passwordless `sudo`; otherwise the command
//!    stops and says what to install.
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

use crate::paths::{target_dir, workspace_root};

/// Options of `cargo xtask vivid`.
#[derive(clap::Args, Debug)]
pub struct VividArgs {
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

impl Default for VividArgs {
    /// What `cargo xtask vivid` without flags does (for calling [`run`] from the test gate).
    fn default() -> Self {
        Self {
            guest_bin: None,
            timeout_secs: 240,
            cases: Vec::new(),
            verbose: false,
        }
    }
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

/// Common guest arguments: vivid's S-Video input, NTSC, 320×240.
const BASE: &str = "--device /dev/video0 --input-name S-Video --std ntsc --size 320x240 --json";

/// nav-app's exit codes (see `crates/nav-app/src/bin/nav-app/lane.rs`).
const EXIT_ERROR: i64 = 1;
const EXIT_DEVICE_GONE: i64 = 3;
const EXIT_TIMEOUTS: i64 = 4;

/// What a case requires of the guest's output.
#[derive(Clone, Copy)]
enum Expect {
    /// `frames` frames of 320×240 in `fourcc`, strictly increasing sequence and timestamps,
    /// NTSC-M set, exit 0. `optional`: a driver lacking the format skips instead of failing.
    Stream {
        fourcc: &'static str,
        frames: u64,
        optional: bool,
    },
    /// Exit 0 with `frames` frames and the given standard bits set.
    Std { mask: u64, frames: u64 },
    /// Exit 0 on input `index`.
    Input { index: u64 },
    /// A clean typed error mentioning `text`, exit 1.
    CleanError { text: &'static str },
    /// Injected `V4L2_BUF_FLAG_ERROR` buffers: errored_dropped ≥ 1, all frames delivered, exit 0.
    BufError { frames: u64 },
    /// Dropped buffers: sequence_gaps ≥ 1 equal to the sum of per-frame `missed`, exit 0.
    Dropped { frames: u64 },
    /// No signal: some frames flagged signal_lost, and the last ones not (restored), exit 0.
    NoSignal { frames: u64 },
    /// All buffers dropped → timeout → restart → frames again, exit 0.
    TimeoutRestart { frames: u64 },
    /// All buffers dropped and never restored → `timeouts` timeouts in a row → exit 4
    /// (`timeout`), at least `at_least` frames before, no panic.
    TimeoutLimit { at_least: u64, timeouts: u64 },
    /// Without `--json`: exit 0 and nav-app's stderr device line reporting `frames` frames,
    /// frames/s, errored and dropped frames.
    Human { frames: u64 },
    /// vivid Disconnect → device-gone, exit 3, fewer frames than asked, no panic.
    Disconnect { at_least: u64, max_frames: u64 },
}

struct Case {
    name: &'static str,
    args: String,
    expect: Expect,
}

fn cases() -> Vec<Case> {
    let stream = |name, fourcc: &'static str, optional| Case {
        name,
        args: format!("{BASE} --format {fourcc} --max-frames 60"),
        expect: Expect::Stream {
            fourcc,
            frames: 60,
            optional,
        },
    };
    vec![
        // The issue's command verbatim: no --format, no --size (GREY and 320×240 are defaults).
        Case {
            name: "nav-app-default",
            args: "--device /dev/video0 --input-name S-Video --std ntsc --max-frames 60 --json"
                .into(),
            expect: Expect::Stream {
                fourcc: "GREY",
                frames: 60,
                optional: false,
            },
        },
        stream("stream-grey", "GREY", false),
        stream("stream-yuyv", "YUYV", false),
        stream("stream-yu12", "YU12", false),
        stream("stream-uyvy", "UYVY", true),
        stream("stream-bgr24", "BGR3", true),
        stream("stream-rgb565", "RGBP", true),
        stream("stream-bgr32", "BGR4", true),
        Case {
            name: "std-pal",
            args: "--device /dev/video0 --input-name S-Video --std pal --size 320x240 --json --max-frames 10"
                .into(),
            expect: Expect::Std { mask: 0xff, frames: 10 },
        },
        Case {
            name: "input-index-0-tv",
            args: "--device /dev/video0 --input-index 0 --std ntsc --size 320x240 --json --max-frames 5"
                .into(),
            expect: Expect::Input { index: 0 },
        },
        Case {
            name: "bad-input-name",
            args: "--device /dev/video0 --input-name Composite7 --std ntsc --json --max-frames 5".into(),
            expect: Expect::CleanError { text: "no input named" },
        },
        Case {
            name: "fault-buf-error",
            args: format!(
                "{BASE} --max-frames 40 --ctrl 'Inject V4L2_BUF_FLAG_ERROR=1@10' \
                 --ctrl 'Inject V4L2_BUF_FLAG_ERROR=1@20'"
            ),
            expect: Expect::BufError { frames: 40 },
        },
        Case {
            name: "fault-dropped",
            args: format!(
                "{BASE} --max-frames 40 --ctrl 'Percentage of Dropped Buffers=50@5' \
                 --ctrl 'Percentage of Dropped Buffers=0@35'"
            ),
            expect: Expect::Dropped { frames: 40 },
        },
        Case {
            name: "fault-no-signal",
            args: format!(
                "{BASE} --max-frames 30 --ctrl 'Standard Signal Mode=1@5' \
                 --ctrl 'Standard Signal Mode=0@20'"
            ),
            expect: Expect::NoSignal { frames: 30 },
        },
        Case {
            name: "fault-timeout-restart",
            args: format!(
                "{BASE} --max-frames 20 --timeout-ms 1000 \
                 --ctrl 'Percentage of Dropped Buffers=100@5' \
                 --ctrl-on-timeout 'Percentage of Dropped Buffers=0'"
            ),
            expect: Expect::TimeoutRestart { frames: 20 },
        },
        Case {
            name: "human-stderr",
            args: "--device /dev/video0 --input-name S-Video --std ntsc --max-frames 10".into(),
            expect: Expect::Human { frames: 10 },
        },
        // Leaves vivid dropping every buffer: the next case restores it first.
        Case {
            name: "fault-timeout-limit",
            args: format!(
                "{BASE} --max-frames 40 --timeout-ms 500 --max-timeouts 2 \
                 --ctrl 'Percentage of Dropped Buffers=100@5'"
            ),
            expect: Expect::TimeoutLimit {
                at_least: 5,
                timeouts: 2,
            },
        },
        // Last: vivid stays disconnected until every handle is closed.
        Case {
            name: "fault-disconnect",
            args: format!(
                "{BASE} --max-frames 60 --ctrl 'Percentage of Dropped Buffers=0@0' \
                 --ctrl 'Disconnect=1@10'"
            ),
            expect: Expect::Disconnect { at_least: 10, max_frames: 60 },
        },
    ]
}

/// Run `cargo xtask vivid`.
pub fn run(args: VividArgs) -> Result<()> {
    let started = Instant::now();
    let root = workspace_root();
    let work = target_dir(&root).join("vivid");
    std::fs::create_dir_all(&work).with_context(|| format!("creating {}", work.display()))?;

    ensure_host_packages(&["qemu-system-x86", "busybox-static", "libclang-dev"])?;

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

/// The cargo target directory (`CARGO_TARGET_DIR` or `<root>/target`).
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
/// [`ensure_libclang`] for just that one.
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

/// Make sure libclang (Debian `libclang-dev`) is present for the `v4l` crate's bindgen build.
/// Meant to be called by the test gate before building the workspace.
pub fn ensure_libclang() -> Result<()> {
    ensure_host_packages(&["libclang-dev"])
}

fn cargo() -> String {
    std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned())
}

/// Build `nav-app` (feature `capture`) statically in the `vivid-guest` profile; returns its path.
fn build_nav_app(root: &Path) -> Result<PathBuf> {
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
fn is_static_elf(path: &Path) -> Result<bool> {
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

struct Kernel {
    version: String,
    vmlinuz: PathBuf,
    modules: PathBuf,
}

/// Fetch and unpack (once) the kernel package `linux-image-amd64` depends on.
fn fetch_kernel(work: &Path) -> Result<Kernel> {
    let pkg = match kernel_package_name() {
        Ok(p) => p,
        Err(_) => {
            let _ = Command::new("apt-get").args(["update", "-q"]).status();
            kernel_package_name()?
        }
    };
    let unpacked = work.join("kernel").join(&pkg);
    let boot = unpacked.join("boot");
    if !boot.is_dir() {
        let dl = work.join("dl");
        std::fs::create_dir_all(&dl)?;
        eprintln!("vivid: apt-get download {pkg}…");
        let status = Command::new("apt-get")
            .current_dir(&dl)
            .args(["download", "-q", &pkg])
            .status()
            .context("running apt-get download")?;
        ensure!(status.success(), "apt-get download {pkg} failed");
        let deb = std::fs::read_dir(&dl)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| {
                p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with(&format!("{pkg}_")))
                    && p.extension().is_some_and(|e| e == "deb")
            })
            .with_context(|| format!("no {pkg}_*.deb in {}", dl.display()))?;
        let tmp = work.join("kernel").join(format!("{pkg}.partial"));
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir_all(&tmp)?;
        let status = Command::new("dpkg")
            .arg("-x")
            .arg(&deb)
            .arg(&tmp)
            .status()
            .context("running dpkg -x")?;
        ensure!(status.success(), "dpkg -x {} failed", deb.display());
        std::fs::rename(&tmp, &unpacked)?;
        let _ = std::fs::remove_file(&deb);
    }
    let vmlinuz = std::fs::read_dir(&boot)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("vmlinuz-"))
        })
        .with_context(|| format!("no vmlinuz in {}", boot.display()))?;
    let version = vmlinuz
        .file_name()
        .map(|n| {
            n.to_string_lossy()
                .trim_start_matches("vmlinuz-")
                .to_owned()
        })
        .unwrap_or_default();
    let modules = unpacked.join("lib/modules").join(&version).join("kernel");
    ensure!(modules.is_dir(), "no module tree at {}", modules.display());
    Ok(Kernel {
        version,
        vmlinuz,
        modules,
    })
}

fn kernel_package_name() -> Result<String> {
    let out = Command::new("apt-cache")
        .args(["depends", "linux-image-amd64"])
        .output()
        .context("running apt-cache")?;
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.trim().strip_prefix("Depends:"))
        .map(|s| s.trim().to_owned())
        .find(|s| s.starts_with("linux-image-"))
        .context("apt-cache depends linux-image-amd64 names no linux-image-* package")
}

/// Find `name.ko` (or `.ko.xz` / `.ko.zst`, decompressed) under the module tree.
fn module_bytes(tree: &Path, name: &str) -> Result<Vec<u8>> {
    fn walk(dir: &Path, name: &str) -> Option<PathBuf> {
        let entries = std::fs::read_dir(dir).ok()?;
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                if let Some(found) = walk(&p, name) {
                    return Some(found);
                }
            } else if let Some(f) = p.file_name().and_then(|f| f.to_str())
                && [".ko", ".ko.xz", ".ko.zst"]
                    .iter()
                    .any(|ext| f == format!("{name}{ext}"))
            {
                return Some(p);
            }
        }
        None
    }
    let path = walk(tree, name)
        .with_context(|| format!("module {name} not found under {}", tree.display()))?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let tool = match ext {
        "xz" => Some("xz"),
        "zst" => Some("zstd"),
        _ => None,
    };
    match tool {
        None => Ok(std::fs::read(&path)?),
        Some(tool) => {
            let out = Command::new(tool)
                .arg("-dc")
                .arg(&path)
                .output()
                .with_context(|| format!("running {tool}"))?;
            ensure!(out.status.success(), "{tool} -dc {} failed", path.display());
            Ok(out.stdout)
        }
    }
}

/// A newc ("070701") cpio archive, built in memory.
struct Cpio {
    buf: Vec<u8>,
    ino: u32,
}

impl Cpio {
    fn new() -> Self {
        Self {
            buf: Vec::new(),
            ino: 1,
        }
    }

    fn entry(&mut self, name: &str, mode: u32, data: &[u8], rdev: (u32, u32)) {
        let namesize = name.len() + 1;
        let fields = [
            self.ino,
            mode,
            0,
            0,
            1,
            0,
            data.len() as u32,
            0,
            0,
            rdev.0,
            rdev.1,
            namesize as u32,
            0,
        ];
        self.ino += 1;
        self.buf.extend_from_slice(b"070701");
        for f in fields {
            self.buf.extend_from_slice(format!("{f:08x}").as_bytes());
        }
        self.buf.extend_from_slice(name.as_bytes());
        self.buf.push(0);
        self.pad();
        self.buf.extend_from_slice(data);
        self.pad();
    }

    fn pad(&mut self) {
        while !self.buf.len().is_multiple_of(4) {
            self.buf.push(0);
        }
    }

    fn dir(&mut self, name: &str) {
        self.entry(name, 0o040_755, &[], (0, 0));
    }

    fn file(&mut self, name: &str, data: &[u8], exec: bool) {
        self.entry(name, if exec { 0o100_755 } else { 0o100_644 }, data, (0, 0));
    }

    fn finish(mut self) -> Vec<u8> {
        self.entry("TRAILER!!!", 0, &[], (0, 0));
        self.buf
    }
}

/// The guest's `/init`: mount, insert the modules, run the cases with markers, power off.
fn init_script(cases: &[Case]) -> String {
    let mut s = String::from(
        "#!/bin/busybox sh\n\
         /bin/busybox --install -s /bin\n\
         export PATH=/bin\n\
         mount -t proc proc /proc\n\
         mount -t sysfs sysfs /sys\n\
         mount -t devtmpfs devtmpfs /dev\n\
         echo 3 > /proc/sys/kernel/printk\n\
         echo \"VIVID-BOOT $(uname -r)\"\n",
    );
    for m in MODULES {
        let params = if *m == "vivid" { VIVID_PARAMS } else { "" };
        let _ = writeln!(
            s,
            "insmod /lib/modules/{m}.ko {params} || echo 'VIVID-INSMOD-FAIL {m}'"
        );
    }
    s.push_str(
        "i=0\n\
         while [ ! -e /dev/video0 ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i+1)); done\n\
         if [ -e /dev/video0 ]; then echo VIVID-READY; else echo VIVID-NO-DEVICE; fi\n",
    );
    for c in cases {
        let _ = writeln!(s, "echo 'VIVID-CASE-BEGIN {}'", c.name);
        let _ = writeln!(s, "timeout 60 /bin/guest {} 2>&1", c.args);
        let _ = writeln!(s, "echo \"VIVID-CASE-END {} rc=$?\"", c.name);
    }
    s.push_str("echo VIVID-DONE\nsync\npoweroff -f || reboot -f\n");
    s
}

fn write_initramfs(path: &Path, kernel: &Kernel, guest: &Path, cases: &[Case]) -> Result<()> {
    let busybox = ["/bin/busybox", "/usr/bin/busybox"]
        .iter()
        .map(Path::new)
        .find(|p| p.exists())
        .context("busybox not found (Debian package busybox-static)")?;
    ensure!(
        is_static_elf(busybox)?,
        "{} is not static: install busybox-static",
        busybox.display()
    );
    let mut cpio = Cpio::new();
    for d in ["bin", "dev", "proc", "sys", "tmp", "lib", "lib/modules"] {
        cpio.dir(d);
    }
    cpio.entry("dev/console", 0o020_600, &[], (5, 1));
    cpio.file("init", init_script(cases).as_bytes(), true);
    cpio.file("bin/busybox", &std::fs::read(busybox)?, true);
    cpio.file(
        "bin/guest",
        &std::fs::read(guest).with_context(|| format!("reading {}", guest.display()))?,
        true,
    );
    for m in MODULES {
        cpio.file(
            &format!("lib/modules/{m}.ko"),
            &module_bytes(&kernel.modules, m)?,
            false,
        );
    }
    std::fs::write(path, cpio.finish()).with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

struct SerialLog {
    lines: Vec<String>,
    killed: bool,
}

fn run_qemu(vmlinuz: &Path, initrd: &Path, limit: Duration, verbose: bool) -> Result<SerialLog> {
    let mut child = Command::new("qemu-system-x86_64")
        .args([
            "-accel",
            "tcg",
            "-cpu",
            "max",
            "-m",
            "512",
            "-smp",
            "1",
            "-nographic",
            "-no-reboot",
        ])
        .arg("-kernel")
        .arg(vmlinuz)
        .arg("-initrd")
        .arg(initrd)
        .args(["-append", "console=ttyS0 panic=-1 quiet loglevel=3"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("starting qemu-system-x86_64")?;
    let stdout = child.stdout.take().context("qemu stdout")?;
    let reader = std::thread::spawn(move || {
        let mut lines = Vec::new();
        for line in BufReader::new(stdout)
            .split(b'\n')
            .map_while(std::result::Result::ok)
        {
            let line = String::from_utf8_lossy(&line)
                .trim_end_matches('\r')
                .to_owned();
            if verbose {
                println!("  | {line}");
            } else if line.starts_with("VIVID-") {
                eprintln!("  {line}");
            }
            let _ = std::io::stdout().flush();
            lines.push(line);
        }
        lines
    });
    let deadline = Instant::now() + limit;
    let mut killed = false;
    loop {
        if child.try_wait()?.is_some() {
            break;
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            killed = true;
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let lines = reader
        .join()
        .map_err(|_| anyhow::anyhow!("serial reader thread panicked"))?;
    Ok(SerialLog { lines, killed })
}

enum Verdict {
    Pass(String),
    Skip(String),
    Fail(String),
}

impl Verdict {
    fn detail(&self) -> &str {
        match self {
            Verdict::Pass(s) | Verdict::Skip(s) | Verdict::Fail(s) => s,
        }
    }
}

/// One case's guest output, from nav-app's JSON lines (frames flattened by [`flatten_frame`];
/// `open` is the summary's `device` object).
#[derive(Default)]
struct CaseOutput {
    rc: Option<i64>,
    open: Option<Value>,
    frames: Vec<Value>,
    /// nav-app's stderr warnings about frame timeouts.
    timeouts: usize,
    /// nav-app's human-mode device line (`nav-app: device …: N frames in …`).
    human: Option<String>,
    summary: Option<Value>,
    panicked: bool,
}

/// A nav-app `--json` frame object as the flat record the checks read: `seq`, `ts_us`, `w`, `h`,
/// `fourcc`, `missed`, `signal_lost`, `mean` from its `"capture"` object, and `lanes`, the
/// number of lane reports (2 when the tracker ran on the frame).
fn flatten_frame(v: &Value) -> Value {
    let c = &v["capture"];
    serde_json::json!({
        "seq": c["sequence"], "ts_us": c["timestamp_us"], "w": c["width_px"], "h": c["height_px"],
        "fourcc": c["format"], "missed": c["missed"], "signal_lost": c["signal_lost"],
        "mean": c["mean_grey"], "lanes": v["lanes"].as_array().map_or(0, Vec::len),
    })
}

fn split_cases(log: &SerialLog) -> BTreeMap<String, CaseOutput> {
    let mut out: BTreeMap<String, CaseOutput> = BTreeMap::new();
    let mut current: Option<String> = None;
    for line in &log.lines {
        if let Some(name) = line.strip_prefix("VIVID-CASE-BEGIN ") {
            current = Some(name.trim().to_owned());
            out.entry(name.trim().to_owned()).or_default();
            continue;
        }
        if let Some(rest) = line.strip_prefix("VIVID-CASE-END ") {
            let mut parts = rest.split_whitespace();
            let name = parts.next().unwrap_or_default().to_owned();
            let rc = parts
                .next()
                .and_then(|p| p.strip_prefix("rc="))
                .and_then(|r| r.parse().ok());
            out.entry(name).or_default().rc = rc;
            current = None;
            continue;
        }
        let Some(name) = &current else { continue };
        let o = out.entry(name.clone()).or_default();
        if line.contains("panicked") {
            o.panicked = true;
        }
        if line.contains("nav-app: warning:") && line.contains("no frame within") {
            o.timeouts += 1;
            continue;
        }
        if line.contains("nav-app: device ") {
            o.human = Some(line.clone());
            continue;
        }
        // Kernel messages may share the console: only parse what starts like nav-app's JSON.
        let parse = |key: &str| {
            line.find(key)
                .and_then(|start| serde_json::from_str::<Value>(&line[start..]).ok())
        };
        // Objects start with `"schema"` (JSON schema 1) or, before it, with their first field.
        let Some(v) = parse("{\"schema\"")
            .or_else(|| parse("{\"frame\""))
            .or_else(|| parse("{\"summary\""))
        else {
            continue;
        };
        if let Some(s) = v.get("summary") {
            o.open = s.get("device").filter(|d| !d.is_null()).cloned();
            o.summary = Some(s.clone());
        } else if v.get("frame").is_some() {
            o.frames.push(flatten_frame(&v));
        }
    }
    out
}

fn num(v: Option<&Value>, key: &str) -> u64 {
    v.and_then(|v| v.get(key))
        .and_then(Value::as_u64)
        .unwrap_or(0)
}

fn text<'a>(v: Option<&'a Value>, key: &str) -> &'a str {
    v.and_then(|v| v.get(key))
        .and_then(Value::as_str)
        .unwrap_or("")
}

/// Frames are 320×240, tracked (two lane reports each), with strictly increasing sequence
/// numbers and timestamps.
fn check_frames(o: &CaseOutput, fourcc: Option<&str>) -> Result<(), String> {
    let mut last: Option<(u64, i64)> = None;
    for f in &o.frames {
        let (w, h) = (num(Some(f), "w"), num(Some(f), "h"));
        if (w, h) != (320, 240) {
            return Err(format!("frame {w}x{h}, expected 320x240"));
        }
        if num(Some(f), "lanes") != 2 {
            return Err(format!("frame without the tracker's two lane reports: {f}"));
        }
        if let Some(fc) = fourcc
            && text(Some(f), "fourcc") != fc
        {
            return Err(format!(
                "frame fourcc {}, expected {fc}",
                text(Some(f), "fourcc")
            ));
        }
        let seq = num(Some(f), "seq");
        let ts = f.get("ts_us").and_then(Value::as_i64).unwrap_or(0);
        if let Some((ls, lt)) = last
            && (seq <= ls || ts <= lt)
        {
            return Err(format!(
                "sequence/timestamp not increasing: ({ls},{lt}) then ({seq},{ts})"
            ));
        }
        last = Some((seq, ts));
    }
    Ok(())
}

/// Mean of the per-frame mean grey levels of a case.
fn mean_level(o: &CaseOutput) -> Option<f64> {
    let levels: Vec<f64> = o
        .frames
        .iter()
        .filter_map(|f| f.get("mean").and_then(Value::as_f64))
        .collect();
    (!levels.is_empty()).then(|| levels.iter().sum::<f64>() / levels.len() as f64)
}

/// Largest difference, grey levels, allowed between a format's mean frame level and GREY's.
/// vivid draws the same test pattern in every format; Y'CbCr formats carry studio-range luma
/// (16–235, ≈ +8 here) and RGB ones the pattern's R'G'B' through our BT.601 weights (≈ +2), while
/// reading a wrong byte (a chroma sample, a padding byte) moves the mean by tens of levels.
const MEAN_TOLERANCE: f64 = 12.0;

fn judge(cases: &[Case], log: &SerialLog) -> Vec<Verdict> {
    let outputs = split_cases(log);
    let grey_mean = outputs.get("stream-grey").and_then(mean_level);
    cases
        .iter()
        .map(|c| match outputs.get(c.name) {
            None => Verdict::Fail("case never started (VM died or timed out?)".into()),
            Some(o) if o.rc.is_none() => Verdict::Fail("case never finished".into()),
            Some(o) if o.panicked => Verdict::Fail("guest panicked".into()),
            Some(o) => judge_one(
                c.expect,
                o,
                grey_mean,
                c.args.matches("--ctrl").count() as u64,
            ),
        })
        .collect()
}

/// `controls`: how many test-hook controls the case sets (`--ctrl` and `--ctrl-on-timeout`).
fn judge_one(expect: Expect, o: &CaseOutput, grey_mean: Option<f64>, controls: u64) -> Verdict {
    let rc = o.rc.unwrap_or(-1);
    let s = o.summary.as_ref();
    let frames = num(s, "frames");
    let exit = text(s, "exit");
    let counters = format!(
        "rc={rc} exit={exit} frames={frames} errored={} gaps={} timeouts={} restarts={} no_signal={} fps={}",
        num(s, "errored_dropped"),
        num(s, "sequence_gaps"),
        num(s, "timeouts"),
        num(s, "restarts"),
        num(s, "signal_lost_frames"),
        s.and_then(|s| s.get("fps"))
            .map_or("?".into(), Value::to_string),
    );
    let fail = |why: String| Verdict::Fail(format!("{why}; {counters}"));
    let ok_run = |want: u64| -> Result<(), String> {
        let restarted = matches!(expect, Expect::TimeoutRestart { .. });
        if rc != 0 || exit != "max-frames" {
            return Err(format!(
                "expected exit max-frames rc=0 ({})",
                text(s, "error")
            ));
        }
        if frames != want || o.frames.len() as u64 != want {
            return Err(format!(
                "expected {want} frames, summary {frames}, lines {}",
                o.frames.len()
            ));
        }
        if num(s, "controls_set") != controls {
            return Err(format!(
                "{} of {controls} test controls set",
                num(s, "controls_set")
            ));
        }
        // After a stream restart the driver numbers frames from 0 again.
        if restarted {
            Ok(())
        } else {
            check_frames(o, None)
        }
    };
    let result: Result<String, String> = match expect {
        Expect::Stream {
            fourcc,
            frames: want,
            optional,
        } => {
            if optional
                && exit == "error"
                && text(s, "error").contains("none of the wanted formats")
            {
                return Verdict::Skip(format!("driver lacks {fourcc}"));
            }
            ok_run(want)
                .and_then(|()| check_frames(o, Some(fourcc)))
                .and_then(|()| {
                    let std = num(o.open.as_ref(), "std_id");
                    if std & 0x1000 == 0 {
                        return Err(format!("std_id {std:#x} lacks NTSC-M"));
                    }
                    if num(o.open.as_ref(), "input_index") != 1 {
                        return Err("S-Video is input 1".into());
                    }
                    let mean = mean_level(o).unwrap_or(-1.0);
                    let level = match grey_mean {
                        Some(g) if (mean - g).abs() > MEAN_TOLERANCE => {
                            return Err(format!(
                                "mean grey {mean:.1} vs GREY's {g:.1}: wrong bytes read?"
                            ));
                        }
                        Some(g) => format!(", mean grey {mean:.1} (GREY {g:.1})"),
                        None => format!(", mean grey {mean:.1}"),
                    };
                    Ok(format!(
                        "{want} frames {fourcc} 320x240, seq increasing, NTSC-M{level}"
                    ))
                })
        }
        Expect::Std { mask, frames: want } => ok_run(want).and_then(|()| {
            let std = num(o.open.as_ref(), "std_id");
            if std & mask == 0 || std & 0x1000 != 0 {
                Err(format!("std_id {std:#x} is not within {mask:#x}"))
            } else {
                Ok(format!("std_id {std:#x}"))
            }
        }),
        Expect::Input { index } => ok_run(num(s, "frames")).and_then(|()| {
            let got = num(o.open.as_ref(), "input_index");
            if got == index && frames > 0 {
                Ok(format!("input {got}"))
            } else {
                Err(format!("input {got}"))
            }
        }),
        Expect::CleanError { text: needle } => {
            if rc == EXIT_ERROR && exit == "error" && text(s, "error").contains(needle) {
                Ok(format!("error: {}", text(s, "error")))
            } else {
                Err(format!("expected a clean error containing {needle:?}"))
            }
        }
        Expect::BufError { frames: want } => ok_run(want).and_then(|()| {
            if num(s, "errored_dropped") >= 1 {
                Ok("ERROR-flagged buffers dropped and counted".into())
            } else {
                Err("no errored buffer counted".into())
            }
        }),
        Expect::Dropped { frames: want } => ok_run(want).and_then(|()| {
            let gaps = num(s, "sequence_gaps");
            let missed: u64 = o.frames.iter().map(|f| num(Some(f), "missed")).sum();
            if gaps >= 1 && gaps == missed {
                Ok(format!("{gaps} dropped frames counted from sequence gaps"))
            } else {
                Err(format!("gaps {gaps}, per-frame missed sum {missed}"))
            }
        }),
        Expect::NoSignal { frames: want } => ok_run(want).and_then(|()| {
            let lost = num(s, "signal_lost_frames");
            let last_ok =
                o.frames.last().and_then(|f| f.get("signal_lost")) == Some(&Value::Bool(false));
            if lost >= 1 && last_ok {
                Ok(format!(
                    "{lost} frames flagged signal-lost, signal back at the end"
                ))
            } else {
                Err(format!(
                    "signal_lost_frames {lost}, last frame restored: {last_ok}"
                ))
            }
        }),
        Expect::TimeoutRestart { frames: want } => ok_run(want).and_then(|()| {
            if num(s, "timeouts") >= 1 && num(s, "restarts") >= 1 && o.timeouts >= 1 {
                Ok("timeout reported, stream restarted, frames resumed".into())
            } else {
                Err("no timeout/restart seen".into())
            }
        }),
        Expect::TimeoutLimit { at_least, timeouts } => {
            if rc == EXIT_TIMEOUTS
                && exit == "timeout"
                && frames >= at_least
                && num(s, "timeouts") == timeouts
                && num(s, "restarts") >= timeouts - 1
            {
                Ok(format!(
                    "{timeouts} timeouts in a row after {frames} frames: exit 4 (timeout)"
                ))
            } else {
                Err(format!(
                    "expected exit timeout rc={EXIT_TIMEOUTS} after {timeouts} timeouts"
                ))
            }
        }
        Expect::Human { frames: want } => {
            let line = o.human.as_deref().unwrap_or("");
            let ok = rc == 0
                && line.contains(&format!(" {want} frames in "))
                && line.contains("frames/s")
                && line.contains("errored buffers")
                && line.contains("sequence gaps");
            if ok {
                Ok(format!("stderr: {}", line.trim()))
            } else {
                Err(format!("rc={rc}, stderr device line {line:?}"))
            }
        }
        Expect::Disconnect {
            at_least,
            max_frames,
        } => {
            if rc == EXIT_DEVICE_GONE
                && exit == "device-gone"
                && frames >= at_least
                && frames < max_frames
            {
                Ok(format!(
                    "ENODEV after {frames} frames: clean device-gone exit"
                ))
            } else {
                Err("expected exit device-gone rc=3".into())
            }
        }
    };
    match result {
        Ok(msg) => Verdict::Pass(format!("{msg}; {counters}")),
        Err(why) => fail(why),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log_of(lines: &[&str]) -> SerialLog {
        SerialLog {
            lines: lines.iter().map(|l| (*l).to_owned()).collect(),
            killed: false,
        }
    }

    /// A nav-app `--json` frame line (lanes abridged to what the checks read).
    fn frame(n: u64, seq: u64, ts: u64) -> String {
        format!(
            r#"{{"schema":1,"frame":{n},"t_s":0.0,"lanes":[{{"side":"left","state":"lost"}},{{"side":"right","state":"lost"}}],"track_us":900.0,"capture":{{"sequence":{seq},"timestamp_us":{ts},"format":"GREY","width_px":320,"height_px":240,"missed":0,"signal_lost":false,"mean_grey":65.0}}}}"#
        )
    }

    fn stream_log(seqs: &[u64], rc: i32) -> SerialLog {
        let mut lines = vec!["VIVID-CASE-BEGIN s".to_owned()];
        for (i, s) in seqs.iter().enumerate() {
            // Kernel noise on the console must not confuse the parser.
            lines.push(format!(
                "[    1.0] some kernel line {}",
                frame(i as u64, *s, 1000 + *s)
            ));
        }
        lines.push(format!(
            r#"{{"schema":1,"summary":{{"device":{{"device":"/dev/video0","input_index":1,"std_id":4096,"width_px":320,"height_px":240,"format":"GREY","stride_bytes":320,"buffers":4}},"frames":{},"errored_dropped":0,"sequence_gaps":0,"controls_set":0,"exit":"max-frames","exit_code":0,"error":null}}}}"#,
            seqs.len()
        ));
        lines.push(format!("VIVID-CASE-END s rc={rc}"));
        SerialLog {
            lines,
            killed: false,
        }
    }

    fn verdict(log: &SerialLog, expect: Expect) -> Verdict {
        let cases = [Case {
            name: "s",
            args: String::new(),
            expect,
        }];
        judge(&cases, log).remove(0)
    }

    const GREY3: Expect = Expect::Stream {
        fourcc: "GREY",
        frames: 3,
        optional: false,
    };

    #[test]
    fn stream_case_passes_only_with_increasing_sequence_and_exit_zero() {
        assert!(matches!(
            verdict(&stream_log(&[0, 1, 2], 0), GREY3),
            Verdict::Pass(_)
        ));
        assert!(matches!(
            verdict(&stream_log(&[0, 2, 1], 0), GREY3),
            Verdict::Fail(_)
        ));
        assert!(matches!(
            verdict(&stream_log(&[0, 1, 2], 1), GREY3),
            Verdict::Fail(_)
        ));
        // Too few frames.
        assert!(matches!(
            verdict(&stream_log(&[0, 1], 0), GREY3),
            Verdict::Fail(_)
        ));
    }

    #[test]
    fn frames_must_be_tracked_and_test_controls_all_set() {
        // A frame object without the tracker's two lane reports fails the case.
        let mut log = stream_log(&[0, 1, 2], 0);
        log.lines[2] = log.lines[2].replace(r#"{"side":"left","state":"lost"},"#, "");
        assert!(matches!(verdict(&log, GREY3), Verdict::Fail(_)));
        // A case that sets one control passes only if the summary counts it.
        let cases = [Case {
            name: "s",
            args: "--ctrl 'Disconnect=1@1'".into(),
            expect: GREY3,
        }];
        let log = stream_log(&[0, 1, 2], 0);
        assert!(matches!(judge(&cases, &log)[0], Verdict::Fail(_)));
        let mut log = stream_log(&[0, 1, 2], 0);
        let n = log.lines.len();
        log.lines[n - 2] = log.lines[n - 2].replace(r#""controls_set":0"#, r#""controls_set":1"#);
        assert!(matches!(judge(&cases, &log)[0], Verdict::Pass(_)));
    }

    #[test]
    fn unfinished_or_missing_case_fails() {
        let mut log = stream_log(&[0, 1, 2], 0);
        log.lines.pop(); // no END marker: the guest hung or the VM died
        assert!(matches!(verdict(&log, GREY3), Verdict::Fail(_)));
        assert!(matches!(
            verdict(&log_of(&["VIVID-READY"]), GREY3),
            Verdict::Fail(_)
        ));
    }

    #[test]
    fn disconnect_requires_device_gone_exit() {
        let expect = Expect::Disconnect {
            at_least: 1,
            max_frames: 60,
        };
        let gone = log_of(&[
            "VIVID-CASE-BEGIN s",
            r#"{"summary":{"device":null,"frames":10,"controls_set":0,"exit":"device-gone","exit_code":3,"error":"gone"}}"#,
            "VIVID-CASE-END s rc=3",
        ]);
        assert!(matches!(verdict(&gone, expect), Verdict::Pass(_)));
        let panicked = log_of(&[
            "VIVID-CASE-BEGIN s",
            "thread 'main' panicked at src/x.rs:1:1",
            r#"{"summary":{"device":null,"frames":10,"controls_set":0,"exit":"device-gone","exit_code":3,"error":"gone"}}"#,
            "VIVID-CASE-END s rc=3",
        ]);
        assert!(matches!(verdict(&panicked, expect), Verdict::Fail(_)));
    }

    #[test]
    fn timeout_limit_requires_exit_4_after_the_given_timeouts() {
        let expect = Expect::TimeoutLimit {
            at_least: 5,
            timeouts: 2,
        };
        fn log(rc: i32, timeouts: u32) -> SerialLog {
            let summary = format!(
                r#"{{"summary":{{"frames":5,"timeouts":{timeouts},"restarts":{timeouts},"exit":"timeout","exit_code":{rc}}}}}"#
            );
            let end = format!("VIVID-CASE-END s rc={rc}");
            log_of(&["VIVID-CASE-BEGIN s", &summary, &end])
        }
        assert!(matches!(verdict(&log(4, 2), expect), Verdict::Pass(_)));
        assert!(matches!(verdict(&log(1, 2), expect), Verdict::Fail(_)));
        assert!(matches!(verdict(&log(4, 1), expect), Verdict::Fail(_)));
    }

    #[test]
    fn cpio_newc_entries_are_aligned_and_terminated() {
        let mut c = Cpio::new();
        c.file("init", b"abc", true);
        let buf = c.finish();
        assert_eq!(&buf[..6], b"070701");
        // Header 110 bytes + "init\0" (5) = 115 → padded to 116, then 3 data bytes → 120.
        let mode = u32::from_str_radix(std::str::from_utf8(&buf[14..22]).unwrap(), 16).unwrap();
        assert_eq!(mode, 0o100_755);
        assert_eq!(&buf[110..115], b"init\0");
        assert_eq!(&buf[116..119], b"abc");
        assert_eq!(&buf[120..126], b"070701");
        assert!(buf.windows(11).any(|w| w == b"TRAILER!!!\0"));
        assert_eq!(buf.len() % 4, 0);
    }

    #[test]
    fn init_script_runs_every_case_between_markers() {
        let script = init_script(&cases());
        for c in cases() {
            assert!(script.contains(&format!("echo 'VIVID-CASE-BEGIN {}'", c.name)));
            assert!(script.contains(&format!("VIVID-CASE-END {} rc=$?", c.name)));
        }
        assert!(script.contains(VIVID_PARAMS));
        // Disconnect must be the last case: vivid stays gone while any handle is open.
        assert_eq!(cases().last().map(|c| c.name), Some("fault-disconnect"));
    }
}
