//! The Slurm example (`examples/slurm/compress-library.sbatch`) as a real job array: munge,
//! slurmctld and slurmd (Debian's slurm-wlm) started by the test on one node on loopback, in a
//! temporary folder, `sbatch --array=0-2 --wait`, then the outputs checked against one unsharded
//! run. Prints `skipped: slurm could not start` with the reason where Slurm is not installed or
//! does not come up. Every wait is bounded; the daemons are stopped when the test ends.

use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Daemons to stop however the test ends.
struct Daemons(Vec<Child>, Option<PathBuf>);

impl Drop for Daemons {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
        // munged daemonises itself: stop it by its pid file.
        if let Some(pid) = self.1.as_ref().and_then(|p| std::fs::read_to_string(p).ok()) {
            let _ = Command::new("kill").arg(pid.trim()).status();
        }
    }
}

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn which(name: &str) -> Option<PathBuf> {
    ["/usr/sbin", "/usr/bin", "/sbin", "/bin", "/usr/local/bin", "/usr/local/sbin"]
        .iter()
        .map(|d| Path::new(d).join(name))
        .find(|p| p.is_file())
}

fn skip(why: &str) {
    println!("skipped: slurm could not start ({why})");
}

/// Starts munge, slurmctld and slurmd in `dir`; `Err` says why not.
fn start(dir: &Path) -> Result<(Daemons, PathBuf), String> {
    let bins: Vec<PathBuf> = ["munged", "slurmctld", "slurmd", "sbatch", "sinfo"]
        .iter()
        .map(|b| which(b).ok_or_else(|| format!("no {b}; apt-get install slurmd slurmctld slurm-client munge")))
        .collect::<Result<_, _>>()?;
    let (munged, slurmctld, slurmd, _, sinfo) = (&bins[0], &bins[1], &bins[2], &bins[3], &bins[4]);
    for sub in ["state", "spool"] {
        std::fs::create_dir_all(dir.join(sub)).map_err(|e| e.to_string())?;
    }
    let key = dir.join("munge.key");
    let bytes: Vec<u8> = (0..1024u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
    std::fs::write(&key, bytes).map_err(|e| e.to_string())?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&key, std::fs::Permissions::from_mode(0o400)).map_err(|e| e.to_string())?;
    }
    let p = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let mut daemons = Daemons(Vec::new(), Some(dir.join("munged.pid")));
    let o = Command::new(munged)
        .args(["--force", &format!("--key-file={}", p("munge.key")), &format!("--socket={}", p("munge.sock"))])
        .args([&format!("--pid-file={}", p("munged.pid")), &format!("--log-file={}", p("munged.log"))])
        .arg(format!("--seed-file={}", p("munge.seed")))
        .output()
        .map_err(|e| format!("munged: {e}"))?;
    if !o.status.success() {
        return Err(format!("munged: {}", String::from_utf8_lossy(&o.stderr).trim()));
    }
    let conf = dir.join("slurm.conf");
    let memory_mb = 4000;
    let text = format!(
        "ClusterName=inbetweentest\nSlurmctldHost=localhost(127.0.0.1)\nSlurmUser=root\nSlurmdUser=root\n\
         SlurmctldPort={}\nSlurmdPort={}\nAuthType=auth/munge\nAuthInfo=socket={}\nCredType=cred/munge\n\
         StateSaveLocation={}\nSlurmdSpoolDir={}\nSlurmctldPidFile={}\nSlurmdPidFile={}\n\
         SlurmctldLogFile={}\nSlurmdLogFile={}\nProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n\
         SwitchType=switch/none\nMpiDefault=none\nReturnToService=2\nSchedulerType=sched/builtin\n\
         SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nJobCompType=jobcomp/none\n\
         AccountingStorageType=accounting_storage/none\nJobAcctGatherType=jobacct_gather/none\n\
         NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 RealMemory={memory_mb} State=UNKNOWN\n\
         PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n",
        free_port(),
        free_port(),
        p("munge.sock"),
        p("state"),
        p("spool"),
        p("slurmctld.pid"),
        p("slurmd.pid"),
        p("slurmctld.log"),
        p("slurmd.log"),
    );
    std::fs::write(&conf, text).map_err(|e| e.to_string())?;
    let spawn = |bin: &Path, args: &[&str], log: &str| {
        Command::new(bin)
            .args(args)
            .env("SLURM_CONF", &conf)
            .stdout(std::fs::File::create(dir.join(log)).unwrap())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| format!("{}: {e}", bin.display()))
    };
    let c = conf.to_string_lossy().into_owned();
    daemons.0.push(spawn(slurmctld, &["-D", "-f", &c], "slurmctld.out")?);
    daemons.0.push(spawn(slurmd, &["-D", "-N", "localhost", "-f", &c], "slurmd.out")?);
    let t = Instant::now();
    loop {
        let o = Command::new(sinfo).args(["-h", "-o", "%T"]).env("SLURM_CONF", &conf).output();
        if o.as_ref().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle") {
            return Ok((daemons, conf));
        }
        if t.elapsed() > Duration::from_secs(30) {
            let log = std::fs::read_to_string(dir.join("slurmctld.log")).unwrap_or_default();
            let last = log.lines().last().unwrap_or("no log").to_string();
            return Err(format!("the node did not become idle within 30 s; slurmctld: {last}"));
        }
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn the_example_job_array_compresses_the_corpus_like_one_run() {
    inbetween_io::data::with_shared_data("the Slurm example on the CMU corpus", |data| {
        let tmp = tempfile::tempdir().unwrap();
        let (_daemons, conf) = match start(tmp.path()) {
            Ok(d) => d,
            Err(why) => return skip(&why),
        };
        let cmu = data.join("mocap/cmu");
        let out = tmp.path().join("out");
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/slurm/compress-library.sbatch");
        let bin = env!("CARGO_BIN_EXE_inbetween");
        let mut child = Command::new(which("sbatch").unwrap())
            .args(["--array=0-2", "--wait", "--chdir"])
            .arg(tmp.path())
            .arg(format!("--export=ALL,INBETWEEN={bin}"))
            .arg(&script)
            .arg(&cmu)
            .arg(&out)
            .env("SLURM_CONF", &conf)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let t = Instant::now();
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            assert!(t.elapsed() < Duration::from_secs(300), "the job array took over 5 minutes");
            std::thread::sleep(Duration::from_millis(200));
        };
        let logs: String = std::fs::read_dir(tmp.path())
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("inbetween-compress-"))
            .map(|p| std::fs::read_to_string(p).unwrap_or_default())
            .collect();
        assert!(status.success(), "sbatch --wait: {status}; task logs:\n{logs}");
        for i in 0..3 {
            assert!(out.join(format!("results-{i}.jsonl")).is_file(), "array task {i} ran its shard:\n{logs}");
        }
        // The summary counts every take once, all ok, and the outputs equal one unsharded run's.
        let summary = Command::new(bin).args(["batch", "summary"]).arg(&out).output().unwrap();
        let text = String::from_utf8_lossy(&summary.stdout);
        assert!(text.contains("failed") && text.contains(" 0 failed"), "{text}");
        let one = tmp.path().join("one");
        let o = Command::new(bin)
            .args(["batch", "mocap-compress"])
            .arg(&cmu)
            .arg("-o")
            .arg(&one)
            .args(["--max-error", "1cm"])
            .env("INBETWEEN_NO_PROGRESS", "1")
            .output()
            .unwrap();
        assert!(o.status.success());
        let files = |d: &Path| -> Vec<(PathBuf, Vec<u8>)> {
            let mut v: Vec<_> = walk(d)
                .into_iter()
                .map(|p| (p.strip_prefix(d).unwrap().to_path_buf(), std::fs::read(&p).unwrap()))
                .collect();
            v.sort();
            v
        };
        assert_eq!(files(&out), files(&one), "the array's outputs are one run's, byte for byte");
    });
}

fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            v.extend(walk(&p));
        } else if p.extension().is_some_and(|e| e == "ibk") {
            v.push(p);
        }
    }
    v
}
