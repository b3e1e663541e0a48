//! The chunks' two stages on a few worker threads: a chunk's first-grid pass (each point
//! warm-started from the one before) and its points' estimates and refinements (the chunk's
//! coarser and refined sessions, warm-started along the chunk, and `predicted`), each stage
//! one point at a time in the chunk's order. Why: the refinements of the real blade's folds
//! (issue 23) sat on one chunk while the other chunk's thread idled; a stage's next point can
//! run on whichever thread is free, so the two stages of the costliest chunk overlap.
//! Each stage keeps its state and its order, so the answers are those of the inline loop.
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::Instant;

/// Which stage of which chunk a worker runs next, or the job run once every first stage is done.
enum Job<P> {
    First(usize),
    Second(usize, P),
    AfterFirsts,
}

/// The job run once every chunk's first stage is done, if any.
#[derive(Clone, Copy, PartialEq, Eq)]
enum AfterFirsts {
    None,
    Waiting,
    Running,
    Done,
}

struct Chunk<P> {
    /// Points left to the first stage, and points through the second.
    first_left: usize,
    second_done: usize,
    first_busy: bool,
    second_busy: bool,
    /// The first stage's answers waiting for the second, in order.
    queue: VecDeque<P>,
    /// Seconds spent in each stage and the points, for the expected remaining work.
    first_s: f64,
    second_s: f64,
    len: usize,
}

impl<P> Chunk<P> {
    /// Expected seconds left in both stages, by this chunk's mean cost per point so far
    /// (1 s per point before any: the chunks start even).
    fn remaining(&self) -> f64 {
        let done_first = self.len - self.first_left;
        let mean = |s: f64, n: usize| if n == 0 { 1.0 } else { s / n as f64 };
        self.first_left as f64 * mean(self.first_s, done_first) + (self.len - self.second_done) as f64 * mean(self.second_s, self.second_done)
    }
}

/// Runs `chunks` (their lengths) on `threads` workers: `first(c)` is chunk c's next first-stage
/// point, `second(c, p)` that point's second stage (the callers keep the results in their
/// stages' states). A free worker takes the ready stage of the chunk with the
/// most expected work left (the critical path first), the second stage before the first.
/// `after_firsts` runs once, as soon as every first stage is done, before any stage still waiting
/// (a guarded sweep's refill: else a serial tail after the second stages, issue 23).
pub(super) fn run<P: Send>(
    lengths: &[usize],
    threads: usize,
    first: &(dyn Fn(usize) -> P + Sync),
    second: &(dyn Fn(usize, P) + Sync),
    after_firsts: Option<&(dyn Fn() + Sync)>,
) {
    let after = Mutex::new(if after_firsts.is_some() { AfterFirsts::Waiting } else { AfterFirsts::None });
    let state = Mutex::new(
        lengths
            .iter()
            .map(|&len| Chunk {
                first_left: len,
                second_done: 0,
                first_busy: false,
                second_busy: false,
                queue: VecDeque::new(),
                first_s: 0.0,
                second_s: 0.0,
                len,
            })
            .collect::<Vec<Chunk<P>>>(),
    );
    let ready = Condvar::new();
    // Set when a stage panics: the other workers stop waiting for its chunk (else they would wait
    // forever on a stage marked busy), and the scope carries the panic to the caller.
    let aborted = AtomicBool::new(false);
    // `PERIODIC_CONTACT_PROFILE`: each job's wall span and thread CPU (the two-thread wall's idle time).
    let profile = std::env::var_os("PERIODIC_CONTACT_PROFILE").is_some().then(Instant::now);
    let pick = |chunks: &mut Vec<Chunk<P>>| -> Option<Job<P>> {
        // Under the state's lock, so that `after` changes with the stages it waits for.
        let mut after = after.lock().unwrap();
        if *after == AfterFirsts::Waiting && chunks.iter().all(|c| c.first_left == 0 && !c.first_busy) {
            *after = AfterFirsts::Running;
            return Some(Job::AfterFirsts);
        }
        let mut order: Vec<usize> = (0..chunks.len()).collect();
        order.sort_by(|&a, &b| chunks[b].remaining().total_cmp(&chunks[a].remaining()));
        for c in order {
            let ch = &mut chunks[c];
            if !ch.second_busy && !ch.queue.is_empty() {
                ch.second_busy = true;
                return ch.queue.pop_front().map(|p| Job::Second(c, p));
            }
            if !ch.first_busy && ch.first_left > 0 {
                ch.first_busy = true;
                return Some(Job::First(c));
            }
        }
        None
    };
    let worker = || {
        // Seconds this worker waited for a ready stage and its thread CPU in stages (`profile`).
        let (mut waited, mut worked) = (0.0, 0.0);
        loop {
            let job = {
                let mut chunks = state.lock().unwrap();
                loop {
                    if aborted.load(Ordering::SeqCst) {
                        return;
                    }
                    if let Some(job) = pick(&mut chunks) {
                        break Some(job);
                    }
                    if chunks.iter().all(|c| c.second_done == c.len) && matches!(*after.lock().unwrap(), AfterFirsts::None | AfterFirsts::Done) {
                        break None;
                    }
                    let since = Instant::now();
                    chunks = ready.wait(chunks).unwrap();
                    waited += since.elapsed().as_secs_f64();
                }
            };
            let Some(job) = job else {
                if let Some(t0) = profile {
                    eprintln!(
                        "stage profile: a worker ends at {:.3} s wall: {worked:.3} s CPU in stages, {waited:.3} s waiting for a ready stage",
                        t0.elapsed().as_secs_f64()
                    );
                }
                return;
            };
            let t = Instant::now();
            let cpu = profile.and(crate::analysis::polish::thread_cpu());
            let _guard = AbortOnPanic { state: &state, ready: &ready, aborted: &aborted };
            let what = profile.map(|_| match &job {
                Job::First(c) => format!("chunk {c} first"),
                Job::Second(c, _) => format!("chunk {c} second"),
                Job::AfterFirsts => "the job after the first stages".to_string(),
            });
            match job {
                Job::First(c) => {
                    let p = first(c);
                    let mut chunks = state.lock().unwrap();
                    let ch = &mut chunks[c];
                    (ch.first_busy, ch.first_left, ch.first_s) = (false, ch.first_left - 1, ch.first_s + t.elapsed().as_secs_f64());
                    ch.queue.push_back(p);
                }
                Job::Second(c, p) => {
                    second(c, p);
                    let mut chunks = state.lock().unwrap();
                    let ch = &mut chunks[c];
                    (ch.second_busy, ch.second_done, ch.second_s) = (false, ch.second_done + 1, ch.second_s + t.elapsed().as_secs_f64());
                }
                Job::AfterFirsts => {
                    if let Some(job) = after_firsts {
                        job();
                    }
                    let _held = state.lock().unwrap();
                    *after.lock().unwrap() = AfterFirsts::Done;
                }
            }
            if let (Some(t0), Some(cpu), Some(what)) = (profile, cpu, what) {
                let spent = crate::analysis::polish::thread_cpu().unwrap_or(f64::NAN) - cpu;
                worked += spent;
                eprintln!("stage profile: {what} from {:.3} to {:.3} s wall, {spent:.3} s CPU", (t - t0).as_secs_f64(), t0.elapsed().as_secs_f64());
            }
            ready.notify_all();
        }
    };
    // On the caller's rayon pool (a solve's own parallel parts stay there); a worker that waits
    // for a stage only waits for another worker, so more workers than threads cannot lock.
    rayon::scope(|s| {
        for _ in 1..threads.max(1) {
            s.spawn(|_| worker());
        }
        worker();
    });
}

/// Runs `part` of a sweep; under `PERIODIC_CONTACT_PROFILE` prints its wall and this thread's CPU
/// (the seams and the refill run on one thread: the two-thread wall's serial tail).
pub(super) fn profiled<T>(what: &str, part: impl FnOnce() -> T) -> T {
    if std::env::var_os("PERIODIC_CONTACT_PROFILE").is_none() {
        return part();
    }
    let (clock, cpu) = (Instant::now(), crate::analysis::polish::thread_cpu());
    let out = part();
    let spent = crate::analysis::polish::thread_cpu().zip(cpu).map_or(f64::NAN, |(b, a)| b - a);
    eprintln!("sweep profile: {what} {:.3} s wall, {spent:.3} s CPU on the calling thread", clock.elapsed().as_secs_f64());
    out
}

/// Marks the run aborted (under the lock, so that no waiter misses it) when a stage unwinds.
struct AbortOnPanic<'a, T> {
    state: &'a Mutex<T>,
    ready: &'a Condvar,
    aborted: &'a AtomicBool,
}

impl<T> Drop for AbortOnPanic<'_, T> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            let _held = self.state.lock().unwrap_or_else(|e| e.into_inner());
            self.aborted.store(true, Ordering::SeqCst);
            self.ready.notify_all();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every point passes both stages once, in its chunk's order, the second after the first,
    /// whatever the threads (a shuffled order or a lost point would show in the log).
    #[test]
    fn stages_keep_each_chunks_order() {
        for threads in [1, 2, 3] {
            let lengths = [5, 0, 7, 1];
            let next: Vec<Mutex<usize>> = lengths.iter().map(|_| Mutex::new(0)).collect();
            let log: Vec<Mutex<Vec<usize>>> = lengths.iter().map(|_| Mutex::new(Vec::new())).collect();
            let first = |c: usize| {
                let mut n = next[c].lock().unwrap();
                *n += 1;
                *n - 1
            };
            let second = |c: usize, i: usize| log[c].lock().unwrap().push(i);
            run(&lengths, threads, &first, &second, None);
            for (c, &len) in lengths.iter().enumerate() {
                assert_eq!(*log[c].lock().unwrap(), (0..len).collect::<Vec<_>>(), "chunk {c}, {threads} threads");
            }
        }
    }

    /// The job after the first stages runs once, when every first stage is done and before `run`
    /// returns, whatever the threads; the stages still keep their order.
    #[test]
    fn the_job_after_the_first_stages_runs_once_after_all_of_them() {
        for threads in [1, 2, 3] {
            let lengths = [5, 0, 7, 1];
            let firsts = std::sync::atomic::AtomicUsize::new(0);
            let seen: Mutex<Vec<usize>> = Mutex::new(Vec::new());
            let log: Vec<Mutex<Vec<usize>>> = lengths.iter().map(|_| Mutex::new(Vec::new())).collect();
            let next: Vec<Mutex<usize>> = lengths.iter().map(|_| Mutex::new(0)).collect();
            let first = |c: usize| {
                firsts.fetch_add(1, Ordering::SeqCst);
                let mut n = next[c].lock().unwrap();
                *n += 1;
                *n - 1
            };
            let second = |c: usize, i: usize| log[c].lock().unwrap().push(i);
            let after = || seen.lock().unwrap().push(firsts.load(Ordering::SeqCst));
            run(&lengths, threads, &first, &second, Some(&after));
            assert_eq!(*seen.lock().unwrap(), vec![13], "{threads} threads");
            for (c, &len) in lengths.iter().enumerate() {
                assert_eq!(*log[c].lock().unwrap(), (0..len).collect::<Vec<_>>(), "chunk {c}, {threads} threads");
            }
        }
    }

    /// A stage that panics reaches the caller; the other workers do not wait for its chunk
    /// forever (its stage stays marked busy).
    #[test]
    fn a_panicking_stage_reaches_the_caller() {
        for threads in [1, 2, 3] {
            let first = |c: usize| {
                assert!(c != 1, "stage failure");
                c
            };
            let second = |_: usize, _: usize| std::thread::sleep(std::time::Duration::from_millis(1));
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| pool.install(|| run(&[3, 2, 4], threads, &first, &second, None))));
            assert!(outcome.is_err(), "{threads} threads");
        }
    }
}
