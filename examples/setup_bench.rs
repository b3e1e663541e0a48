//! The real blade's set-up (read the CalculiX matrices, reduce) timed in process CPU, and the reduced
//! model written to a file, to compare two builds of the reader and the reduction (issue 23).
//!
//! `cargo run --release --example setup_bench -- SCENE DUMP [REPEATS]` writes the reduced M, K, C
//! (dense, row-major, f64) and the basis to DUMP; `setup_bench --compare A B` prints the largest
//! difference of each, relative to that matrix's largest entry.
use periodic_contact::model::Matrix;
use periodic_contact::scene::Scene;
use std::io::{Read, Write};
use std::path::Path;
use std::time::Instant;

/// Process CPU time (all threads, user + system) [s], from /proc/self/stat (clock ticks of 10 ms).
fn cpu_s() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    let after = &stat[stat.rfind(')').expect("stat format") + 2..];
    let f: Vec<&str> = after.split_whitespace().collect();
    // Fields 14 and 15 of proc(5) are utime and stime; `after` starts at field 3.
    (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / 100.0
}

const NAMES: [&str; 4] = ["mass", "stiffness", "damping", "basis"];

fn dense(m: &Matrix) -> Vec<f64> {
    let d = m.to_dense();
    (0..d.nrows()).flat_map(|i| (0..d.ncols()).map(move |j| (i, j))).map(|(i, j)| d[(i, j)]).collect()
}

fn read_dump(path: &str) -> Vec<Vec<f64>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path).unwrap().read_to_end(&mut bytes).unwrap();
    let mut words = bytes.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().unwrap()));
    (0..NAMES.len())
        .map(|_| {
            let len = words.next().unwrap() as usize;
            words.by_ref().take(len).map(f64::from_bits).collect()
        })
        .collect()
}

#[path = "../src/bin/periodic-contact/malloc.rs"]
mod malloc;

fn main() {
    // Before any allocation of the set-up: the CLI's allocator settings, so the timings are the CLI's.
    malloc::keep_freed_memory();
    let a: Vec<String> = std::env::args().collect();
    if a.len() == 4 && a[1] == "--compare" {
        for (name, (x, y)) in NAMES.iter().zip(read_dump(&a[2]).iter().zip(&read_dump(&a[3]))) {
            assert_eq!(x.len(), y.len(), "{name}: sizes differ");
            let top = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = x.iter().zip(y).fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
            println!("{name}: {} entries, max |difference| / max |entry| = {:.2e}", x.len(), if top > 0.0 { diff / top } else { diff });
        }
        return;
    }
    if std::env::var_os("SETUP_SEQ").is_some() {
        faer::set_global_parallelism(faer::Par::Seq);
    }
    let repeats: usize = a.get(3).map_or(1, |s| s.parse().unwrap());
    let mut built = None;
    for _ in 0..repeats {
        let (c0, t0) = (cpu_s(), Instant::now());
        let (scene, dir) = Scene::load(Path::new(&a[1])).unwrap();
        let b = scene.build_in(&a[1], &dir).unwrap();
        let tm = &b.timings;
        eprintln!(
            "set-up: cpu {:.2} s, wall {:.2} s (wall: structure read {:.2} s, reduction {:.2} s)",
            cpu_s() - c0,
            t0.elapsed().as_secs_f64(),
            tm.structure,
            tm.reduction
        );
        built = Some(b);
    }
    let b = built.unwrap();
    let s = &b.problem.model().structure;
    let red = b.reduction.as_ref().expect("a scene with [reduction]");
    eprintln!("reduction (wall): {:?}", red.timings);
    let basis = Matrix::Dense(red.basis().to_owned());
    let zero = Matrix::Dense(faer::Mat::zeros(0, 0));
    let mut out = std::io::BufWriter::new(std::fs::File::create(&a[2]).unwrap());
    for m in [&s.mass, &s.stiffness, s.damping.as_ref().unwrap_or(&zero), &basis] {
        let v = dense(m);
        out.write_all(&(v.len() as u64).to_le_bytes()).unwrap();
        for x in v {
            out.write_all(&x.to_bits().to_le_bytes()).unwrap();
        }
    }
}
