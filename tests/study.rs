//! `periodic-contact study accuracy --quick` and `study warmstart --quick`: the files are written,
//! the numbers are consistent with the references, the exported LCPs read back.
use periodic_contact::lcp::{BlockCirculant, dat};
use periodic_contact::study::{Case, accuracy, warmstart};
use std::process::Command;

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_periodic-contact"))
}

#[test]
fn quick_accuracy_study_writes_csv_markdown_png_and_lcps() {
    let dir = std::env::temp_dir().join(format!("pc-study-{}", std::process::id()));
    let lcps = dir.join("lcp");
    let o = cli().args(["study", "accuracy", "--quick", "-o"]).arg(&dir).arg("--export-lcp").arg(&lcps).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.join("accuracy.csv")).unwrap();
    let md = std::fs::read_to_string(dir.join("accuracy.md")).unwrap();
    assert!(dir.join("accuracy.png").exists());
    // Header + per case (3 k × (methods + marcher)).
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].starts_with("case,method,kind,steps"));
    for case in Case::ALL {
        let n = lines.iter().filter(|l| l.starts_with(&format!("{},", case.name()))).count();
        assert_eq!(n, 3 * (case.methods().len() + 1), "{}", case.name());
        assert!(md.contains(case.title()));
    }
    assert!(md.contains("Cheapest for the accuracy targets reached"));
    // Every exported file is an engine LCP: block-circulant, k × 1.
    let files: Vec<_> = std::fs::read_dir(&lcps).unwrap().map(|e| e.unwrap().path()).collect();
    assert!(files.len() >= 3 * 10, "{} files", files.len());
    let (a, q) = dat::read_dat(&lcps.join("rigid-cds-forward-k64.dat")).unwrap();
    let c = BlockCirculant::detect(&a, 8).expect("block-circulant");
    assert_eq!((c.k(), c.m(), q.len()), (64, 1, 64));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn accuracy_rows_match_the_references_and_marching_matches_cds_forward() {
    let mut s = accuracy::AccuracySettings::quick();
    s.cases = vec![Case::Rigid, Case::Linear];
    let study = accuracy::run(&s, &mut |_| {}).unwrap();
    let row = |case: Case, method: &str, k: usize| study.rows.iter().find(|r| r.case == case && r.method == method && r.steps == k).unwrap();
    // Numbers of tests/convergence.rs at k = 128: cds/forward second order on the rigid stop.
    let r = row(Case::Rigid, "cds/forward", 128);
    assert!(r.ok() && r.error_x.unwrap() < 1e-3 && r.error_impulse.unwrap() < 1e-3, "{r:?}");
    // The marcher's steady state is the cds/forward periodic solution: same error.
    let m = row(Case::Rigid, "march cds", 128);
    assert!((m.error_x.unwrap() - r.error_x.unwrap()).abs() < 1e-9, "{m:?} vs {r:?}");
    // fourier reproduces the linear response to round-off.
    assert!(row(Case::Linear, "fourier", 32).error_x.unwrap() < 1e-12);
    // The cost split adds up.
    let t = r.t_assembly.unwrap() + r.t_lcp.unwrap() + r.t_recovery.unwrap();
    assert!(t <= r.t_total.unwrap() * 1.0001 + 1e-6);
    // Cheapest for 1e-2 on the linear case is a periodic solve, not the marcher.
    assert_eq!(study.cheapest(Case::Linear, 1e-2, |_| true).unwrap().kind, "periodic");
}

#[test]
fn quick_warmstart_study_reuses_the_active_set() {
    let study = warmstart::run(&warmstart::WarmSettings::quick(), &mut |_| {}).unwrap();
    assert!(study.rows.iter().all(|r| r.status == "ok"));
    // Warm and cold solutions agree.
    assert!(study.rows.iter().all(|r| r.same_solution < 1e-8), "{:?}", study.rows.iter().map(|r| r.same_solution).collect::<Vec<_>>());
    // On the fast path (k = 512 > 256) warm starts take fewer pivots over the sweep.
    let sweep: Vec<_> = study.rows.iter().filter(|r| r.kind == "sweep" && r.k == 512 && r.method.name() == "auto").collect();
    let (cold, warm): (usize, usize) = (sweep.iter().map(|r| r.cold_pivots).sum(), sweep.iter().map(|r| r.warm_pivots).sum());
    assert!(warm < cold, "warm {warm} vs cold {cold} pivots");
    assert!(study.markdown().contains("Re-solve after a small frequency change"));
}
