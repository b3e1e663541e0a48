//! Fail fast and say what to do (issue 11, item 8): every command checks that its outputs can be
//! written before it solves anything, a failed raw LCP names a remedy, and every flag of every
//! command is documented in the README.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

const BIN: &str = env!("CARGO_BIN_EXE_periodic-contact");

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("pc-fail-fast-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run the CLI")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path).display().to_string()
}

/// A sweep of the blade would take minutes: refused in well under a second when its output
/// folder is missing, before the reduction or any point is solved, and nothing is created.
#[test]
fn a_sweep_into_a_missing_folder_is_refused_before_solving() {
    let dir = scratch("sweep");
    let out = dir.join("no-such-folder").join("sweep.csv");
    let t = Instant::now();
    let o = run(&["sweep", &repo("fmu/scenes/blade-casing-coarse.toml"), "--from", "2200", "--to", "2400", "--points", "41", "-o", out.to_str().unwrap()]);
    let elapsed = t.elapsed().as_secs_f64();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("does not exist") && e.contains("mkdir -p") && e.contains("--output"), "{e}");
    assert!(!e.contains("reduced to"), "the scene was built before the check: {e}");
    // The coarse blade's reduction alone takes longer than this.
    assert!(elapsed < 1.0, "refused after {elapsed:.2} s");
    assert!(!dir.join("no-such-folder").exists());
}

#[test]
fn every_command_checks_its_output_first() {
    let dir = scratch("outputs");
    let missing = dir.join("missing").join("out");
    let m = missing.to_str().unwrap();
    let scene = repo("fmu/scenes/rigid-stop.toml");
    let dat = dir.join("tiny.dat");
    std::fs::write(&dat, "2\n0\n2\n2\n2 2\n2 1\n1 2\n-1 -1\n").unwrap();
    for args in [vec!["solve", scene.as_str(), "-o", m], vec!["lcp", dat.to_str().unwrap(), "-o", m], vec!["fmu", scene.as_str(), "-o", m]] {
        let o = run(&args);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert!(e.contains("does not exist") && e.contains("mkdir -p"), "{args:?}: {e}");
    }
    // A folder named as the output file is refused with the remedy, not overwritten.
    let o = run(&["solve", &scene, "-o", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("is a folder"), "{}", stderr(&o));
}

#[cfg(unix)]
#[test]
fn a_read_only_folder_is_refused_with_the_reason() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("readonly");
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    // root ignores permissions: then there is nothing to check.
    let writable = std::fs::write(dir.join("x"), "").is_ok();
    if !writable {
        let out = dir.join("r.json");
        let o = run(&["solve", &repo("fmu/scenes/rigid-stop.toml"), "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains("cannot write into the folder"), "{}", stderr(&o));
    }
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// An LCP without solution ends on Lemke's secondary ray (Cottle–Pang–Stone, Thm 4.4.13: for a
/// copositive-plus M, ray termination proves infeasibility), and the message says what to try.
#[test]
fn a_failed_lcp_names_the_outcome_and_a_remedy() {
    let dir = scratch("lcp");
    let dat = dir.join("infeasible.dat");
    // M = [[0, 0], [0, 0]] is copositive-plus; q = (−1, −1) then has no solution: w = q < 0.
    std::fs::write(&dat, "2\n0\n2\n2\n2 2\n0 0\n0 0\n-1 -1\n").unwrap();
    let o = run(&["lcp", dat.to_str().unwrap(), "-o", dir.join("out.json").to_str().unwrap()]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(e.contains("ray termination") && e.contains("no solution") && e.contains("--method"), "{e}");
}

/// The long flags of every command, read from its --help.
fn flags(args: &[&str]) -> Vec<String> {
    let o = run(&[args, &["--help"]].concat());
    assert!(o.status.success(), "{args:?} --help failed");
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    // Option lines only ("  -o, --output <OUTPUT>  …", "      --cold  …"), not flags quoted in help texts.
    let mut out: Vec<String> = text
        .lines()
        .filter_map(|l| {
            let l = l.trim_start();
            let l = if l.len() > 4 && l.starts_with('-') && l.as_bytes()[1] != b'-' && l[2..].starts_with(", ") { &l[4..] } else { l };
            l.strip_prefix("--").map(|r| format!("--{}", r.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).next().unwrap_or("")))
        })
        .filter(|w| w.len() > 2 && w != "--help" && w != "--version")
        .collect();
    out.sort();
    out.dedup();
    out
}

#[test]
fn every_flag_is_in_the_readme() {
    let readme = std::fs::read_to_string(repo("README.md")).unwrap();
    let commands: [&[&str]; 9] =
        [&["solve"], &["fmu"], &["export"], &["modes"], &["sweep"], &["bench"], &["lcp"], &["study", "accuracy"], &["study", "warmstart"]];
    let mut missing = Vec::new();
    let mut total = 0;
    for c in commands {
        for f in flags(c) {
            total += 1;
            // The README's flag reference has one line per flag: `command` … `--flag`.
            let cmd = format!("`{}`", c.join(" "));
            let flag = format!("`{f}");
            if !readme.lines().any(|l| l.contains(&cmd) && l.contains(&flag)) {
                missing.push(format!("{} {f}", c.join(" ")));
            }
        }
    }
    assert!(total > 30, "only {total} flags found: the --help parsing broke");
    assert!(missing.is_empty(), "flags missing from README.md: {missing:?}");
}

/// Flags used only after the sweep (spectra, marches) are checked before its first point.
#[test]
fn a_bad_spectrum_or_march_value_is_refused_before_the_sweep() {
    let dir = scratch("late-flags");
    let out = dir.join("s.csv");
    let scene = repo("fmu/scenes/blade-casing-coarse.toml");
    for extra in [["--spectrum-at", "0"], ["--march-at", "-3"], ["--march-tol", "0"]] {
        let t = Instant::now();
        let o = run(&[&["sweep", scene.as_str(), "--from", "2200", "--to", "2400", "--points", "41", "-o", out.to_str().unwrap()][..], &extra[..]].concat());
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {e}");
        assert!(e.contains(extra[0]) && !e.contains("sweep:"), "{extra:?}: {e}");
        assert!(!out.exists(), "{extra:?}: a CSV was written");
        // Refused after the set-up (the reduction, well under a few seconds), not after 41 points.
        assert!(t.elapsed().as_secs_f64() < 20.0);
    }
}
