//! Every integration test in one binary: linking one test executable against the release library
//! instead of 36 saves minutes of CI (issue 26). Each file stays where it is, as a module; the
//! helpers they share are `common` (tests/common/). tests/fmu_alloc.rs is its own binary: it
//! installs a counting #[global_allocator] for the whole process.
mod common;

#[path = "accuracy.rs"]
mod accuracy;
#[path = "architecture.rs"]
mod architecture;
#[path = "bad_input.rs"]
mod bad_input;
#[path = "blade.rs"]
mod blade;
#[path = "blade_fold.rs"]
mod blade_fold;
#[path = "blade_margin.rs"]
mod blade_margin;
#[path = "blade_scene.rs"]
mod blade_scene;
#[path = "boundary_stress.rs"]
mod boundary_stress;
#[path = "branch.rs"]
mod branch;
#[path = "capi.rs"]
mod capi;
#[path = "cli.rs"]
mod cli;
#[path = "cold_miss.rs"]
mod cold_miss;
#[path = "continuation.rs"]
mod continuation;
#[path = "convergence.rs"]
mod convergence;
#[path = "event_swap.rs"]
mod event_swap;
#[path = "exact_jacobian.rs"]
mod exact_jacobian;
#[path = "fail_fast.rs"]
mod fail_fast;
#[path = "fast_solver.rs"]
mod fast_solver;
#[path = "fmu_bench.rs"]
mod fmu_bench;
#[path = "fmu_description.rs"]
mod fmu_description;
#[path = "fmu_host.rs"]
mod fmu_host;
#[path = "friction.rs"]
mod friction;
#[path = "friction_coupled.rs"]
mod friction_coupled;
#[path = "friction_frontends.rs"]
mod friction_frontends;
#[path = "friction_polish.rs"]
mod friction_polish;
#[path = "friction_polish_contact.rs"]
mod friction_polish_contact;
#[path = "friction_polish_multi.rs"]
mod friction_polish_multi;
#[path = "friction_shooting.rs"]
mod friction_shooting;
#[path = "frontends.rs"]
mod frontends;
#[path = "hard_cases.rs"]
mod hard_cases;
#[path = "lcp.rs"]
mod lcp;
#[path = "linear.rs"]
mod linear;
#[path = "marching.rs"]
mod marching;
#[path = "massless_polish.rs"]
mod massless_polish;
#[path = "polish.rs"]
mod polish;
#[path = "props.rs"]
mod props;
#[path = "reduction.rs"]
mod reduction;
#[path = "references.rs"]
mod references;
#[path = "results.rs"]
mod results;
#[path = "rigid_blade.rs"]
mod rigid_blade;
#[path = "rigid_branch.rs"]
mod rigid_branch;
#[path = "rigid_jacobian.rs"]
mod rigid_jacobian;
#[path = "rubbing.rs"]
mod rubbing;
#[path = "scheme_auto.rs"]
mod scheme_auto;
#[path = "scheme_limits.rs"]
mod scheme_limits;
#[path = "session.rs"]
mod session;
#[path = "shooting.rs"]
mod shooting;
#[path = "study.rs"]
mod study;
#[path = "sweep.rs"]
mod sweep;
#[path = "sweep_exact.rs"]
mod sweep_exact;
