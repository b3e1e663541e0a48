//! `modes`: eigenfrequencies of the full model and of its Craig–Bampton reduction.
use crate::Failure;
use periodic_contact::reduction::{ModeTable, modes};
use periodic_contact::scene::Scene;
use std::f64::consts::PI;
use std::path::Path;
use std::time::Instant;

pub fn run(scene: &Path, count: usize) -> Result<(), Failure> {
    if count == 0 {
        return Err(Failure::input("--count: is 0, ask for at least one mode"));
    }
    let (s, dir) = Scene::load(scene).map_err(|e| Failure::input(e.to_string()))?;
    let built = s.build_in(&scene.display().to_string(), &dir).map_err(|e| Failure::input(e.to_string()))?;
    let full = &built.full;
    println!("{}: full model {} DOFs (set-up {:.3} s)", scene.display(), full.n(), built.timings.structure);
    match &built.reduction {
        Some(red) => {
            println!(
                "Craig–Bampton: {} boundary DOFs + {} fixed-interface modes = {} DOFs (reduction {:.3} s)",
                red.n_boundary(),
                red.n_modes(),
                red.n(),
                built.timings.reduction
            );
            let t = Instant::now();
            let table = ModeTable::compare(&full.stiffness, &full.mass, red, count).map_err(|e| Failure::solver(format!("modes: {e}")))?;
            print!("{table}");
            println!("(eigen-solutions {:.3} s)", t.elapsed().as_secs_f64());
        }
        None => {
            let count = count.min(full.n());
            let m = modes(&full.stiffness, &full.mass, count).map_err(|e| Failure::solver(format!("modes: {e}")))?;
            println!("no [reduction]: full model only");
            println!("mode  full [Hz] ({} DOFs)   full [rad/s]", full.n());
            for (i, w) in m.omega.iter().enumerate() {
                println!("{:>4}  {:>22.6}   {:>13.4}", i + 1, w / (2.0 * PI), w);
            }
        }
    }
    Ok(())
}
