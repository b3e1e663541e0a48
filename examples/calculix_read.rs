//! Times `fe::read_calculix` on a job and writes its matrices' exact structure and bits to a file,
//! to compare two builds of the reader (issue 23's set-up).
//!
//! `cargo run --release --example calculix_read -- examples/real-blade/job/blade DUMP [REPEATS]`
//! then `cmp DUMP_before DUMP_after`.
use periodic_contact::fe::read_calculix;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let repeats: usize = a.get(3).map_or(3, |s| s.parse().unwrap());
    let mut model = None;
    for _ in 0..repeats {
        let t = Instant::now();
        model = Some(read_calculix(Path::new(&a[1])).unwrap());
        eprintln!("read_calculix {:.3} s wall", t.elapsed().as_secs_f64());
    }
    let model = model.unwrap();
    let mut out = std::io::BufWriter::new(std::fs::File::create(&a[2]).unwrap());
    for m in [&model.stiffness, &model.mass] {
        let s = m.symbolic();
        for &p in s.col_ptr() {
            out.write_all(&(p as u64).to_le_bytes()).unwrap();
        }
        for &r in s.row_idx() {
            out.write_all(&(r as u64).to_le_bytes()).unwrap();
        }
        for &v in m.val() {
            out.write_all(&v.to_bits().to_le_bytes()).unwrap();
        }
    }
}
