//! The guest: Debian's kernel and the vivid modules, a busybox initramfs that runs the cases, and
//! qemu with its serial log.

use super::*;

pub(super) struct Kernel {
    pub(super) version: String,
    pub(super) vmlinuz: PathBuf,
    pub(super) modules: PathBuf,
}

/// Fetch and unpack (once) the kernel package `linux-image-amd64` depends on.
pub(super) fn fetch_kernel(work: &Path) -> Result<Kernel> {
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

pub(super) fn kernel_package_name() -> Result<String> {
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
pub(super) fn module_bytes(tree: &Path, name: &str) -> Result<Vec<u8>> {
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
pub(super) struct Cpio {
    pub(super) buf: Vec<u8>,
    pub(super) ino: u32,
}

impl Cpio {
    pub(super) fn new() -> Self {
        Self {
            buf: Vec::new(),
            ino: 1,
        }
    }

    pub(super) fn entry(&mut self, name: &str, mode: u32, data: &[u8], rdev: (u32, u32)) {
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

    pub(super) fn pad(&mut self) {
        while !self.buf.len().is_multiple_of(4) {
            self.buf.push(0);
        }
    }

    pub(super) fn dir(&mut self, name: &str) {
        self.entry(name, 0o040_755, &[], (0, 0));
    }

    pub(super) fn file(&mut self, name: &str, data: &[u8], exec: bool) {
        self.entry(name, if exec { 0o100_755 } else { 0o100_644 }, data, (0, 0));
    }

    pub(super) fn finish(mut self) -> Vec<u8> {
        self.entry("TRAILER!!!", 0, &[], (0, 0));
        self.buf
    }
}

/// The guest's `/init`: mount, insert the modules, run the cases with markers, power off.
pub(super) fn init_script(cases: &[Case]) -> String {
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

pub(super) fn write_initramfs(
    path: &Path,
    kernel: &Kernel,
    guest: &Path,
    cases: &[Case],
) -> Result<()> {
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

pub(super) struct SerialLog {
    pub(super) lines: Vec<String>,
    pub(super) killed: bool,
}

pub(super) fn run_qemu(
    vmlinuz: &Path,
    initrd: &Path,
    limit: Duration,
    verbose: bool,
) -> Result<SerialLog> {
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
        .context("starting qemu-system-x86_64 (Debian package qemu-system-x86)")?;
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
